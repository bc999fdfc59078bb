// Test support that casts rays (Embree, homcull::truth): only the suite that links the truth
// library has it (tests/CMakeLists.txt).
#include "support.hpp"

#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace homcull::test {

std::vector<std::uint32_t> embree_first_hits(const RayScene& rays, const Scene& scene, const Camera& camera, Resolution display) {
    TruthOptions options;
    options.resolution = display;
    options.keep_sample_ids = true;
    return compute_ground_truth(rays, scene, camera, options).sample_ids;
}

long expect_claims_behind_embree_hits(const RayScene& rays, const Camera& camera, const OcclusionBuffer& buffer, const std::string& what) {
    std::vector<float> bound_w;
    buffer.read_depth(bound_w);
    const int sw = buffer.sample_width(), sh = buffer.sample_height();
    const double aspect = double(sw) / double(sh);
    const CameraBasis basis = camera_basis(camera);
    long claimed = 0;
    for (int j = 0; j < sh; ++j)
        for (int i = 0; i < sw; ++i) {
            const float w = bound_w[std::size_t(j) * std::size_t(sw) + std::size_t(i)];
            if (!std::isfinite(w)) continue;
            ++claimed;
            const glm::vec3 direction(ray_direction(camera, basis, aspect, pixel_to_ndc({sw, sh}, i + 0.5, j + 0.5)));
            const RayHit hit = rays.intersect(camera.eye, direction, float(camera.near_plane), float(camera.far_plane));
            if (!hit.hit() || double(hit.t) > double(w) * (1.0 + 1e-5)) {
                ADD_FAILURE() << what << ": sample " << i << "," << j << " claimed at w " << w
                              << (hit.hit() ? ", nearer than the first hit" : " with nothing behind it");
                return claimed;
            }
        }
    return claimed;
}

}  // namespace homcull::test
