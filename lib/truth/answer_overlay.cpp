#include <homcull/error.hpp>
#include <homcull/truth/answer_overlay.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

constexpr std::uint32_t kBlue = 0x3C6EDC, kGrey = 0xC8C8C8, kMagenta = 0xFF00FF;

}  // namespace

AnswerOverlay render_answer_overlay(const RayScene& rays, const Camera& camera, Resolution resolution,
                                    const std::vector<OccludeeAnswer>& answers, const std::vector<std::uint32_t>& drawn) {
    validate_camera(camera);
    validate_resolution(resolution);
    if (answers.size() != rays.object_count()) throw Error("answer overlay: the answers are not for this scene");
    std::vector<std::uint8_t> is_drawn(answers.size(), 0);
    for (std::uint32_t id : drawn) {
        if (id >= answers.size()) throw Error("answer overlay: drawn occluder " + std::to_string(id) + " is not an object");
        is_drawn[id] = 1;
    }
    const int w = resolution.width, h = resolution.height;
    const double aspect = resolution.aspect();
    const CameraBasis basis = camera_basis(camera);
    const glm::vec3 eye(camera.eye);
    std::vector<std::uint32_t> ids(std::size_t(w) * std::size_t(h), kNoObject);
    std::vector<float> shade(ids.size(), 0.0f);
    // The same rays as ground truth: pixel centres, t from the near to the far plane.
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const glm::vec3 d(ray_direction(camera, basis, aspect, pixel_to_ndc(resolution, x + 0.5, y + 0.5)));
                const RayHit hit = rays.intersect(eye, d, float(camera.near_plane), float(camera.far_plane));
                const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                ids[i] = hit.object;
                const float n = glm::length(hit.normal) * glm::length(d);
                if (hit.hit() && n > 0.0f) shade[i] = std::abs(glm::dot(hit.normal, d)) / n;
            }
    });

    AnswerOverlay out;
    out.width = w;
    out.height = h;
    out.rgb.assign(ids.size() * 3, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const std::uint32_t id = ids[i];
            if (id == kNoObject) continue;
            const bool culled = answers[id].visibility != Visibility::visible;
            const std::uint32_t colour = culled ? kMagenta : is_drawn[id] ? kBlue : kGrey;
            float light = culled ? 1.0f : 0.35f + 0.65f * shade[i];
            // Outlines: a neighbour to the right or below showing another object.
            const bool edge = (x + 1 < w && ids[i + 1] != id) || (y + 1 < h && ids[i + std::size_t(w)] != id);
            if (edge && !culled) light *= 0.6f;
            for (int c = 0; c < 3; ++c)
                out.rgb[3 * i + std::size_t(c)] = std::uint8_t(std::lround(float((colour >> (16 - 8 * c)) & 0xFF) * light));
            if (culled) {
                ++out.false_cull_pixels;
                out.false_culls.push_back(id);
            }
        }
    std::sort(out.false_culls.begin(), out.false_culls.end());
    out.false_culls.erase(std::unique(out.false_culls.begin(), out.false_culls.end()), out.false_culls.end());
    return out;
}

}  // namespace homcull
