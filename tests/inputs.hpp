#pragma once
// Inputs shared by the test suite and tests/isa_bits_check.cpp, which needs only homcull::core
// (header-only for that reason): random clip-space triangle soups, as workload S1 gives
// triangles; random screen rectangles to test; a job system that allocates nothing; the
// generated city seen from its street.
#include <homcull/camera.hpp>
#include <homcull/generate.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/world_triangles.hpp>

#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace homcull::test {

// `count` random small triangles as clip-space xyzw (12 floats each): centres uniform in NDC
// [-1.2, 1.2]^2 (or `extent`), sizes up to `max_size` NDC, w uniform in [1, 80] per vertex.
inline std::vector<float> random_clip_triangles(std::uint64_t seed, int count, float max_size, float extent = 1.2f) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> ndc(-extent, extent), w(1.0f, 80.0f), size(0.005f, max_size);
    std::vector<float> xyzw;
    for (int t = 0; t < count; ++t) {
        const float cx = ndc(rng), cy = ndc(rng), r = size(rng);
        for (int k = 0; k < 3; ++k) {
            const float wk = w(rng);
            xyzw.insert(xyzw.end(), {(cx + r * float(k == 1) - r * float(k == 2)) * wk, (cy + r * float(k == 2)) * wk, 0.0f, wk});
        }
    }
    return xyzw;
}

// An identity-matrix TriangleInput over clip-space xyzw triangles, no backface culling.
inline TriangleInput clip_space_input(const std::vector<float>& xyzw) {
    TriangleInput in;
    in.positions = xyzw.data();
    in.position_components = 4;
    in.position_stride = 16;
    in.vertex_count = xyzw.size() / 4;
    in.triangle_count = in.vertex_count / 3;
    in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    in.backface = Backface::none;
    in.clip_space = true;
    return in;
}

// `count` random screen rectangles: lower corners uniform in NDC [-1.1, 1.0]^2, sides in
// [0.005, 0.5] NDC, nearest w in [0.5, 80].
inline std::vector<ScreenRect> random_screen_rects(std::uint64_t seed, int count) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> ndc(-1.1f, 1.0f), size(0.005f, 0.5f), w(0.5f, 80.0f);
    std::vector<ScreenRect> rects;
    for (int k = 0; k < count; ++k) {
        const float x = ndc(rng), y = ndc(rng);
        rects.push_back({x, y, x + size(rng), y + size(rng), w(rng)});
    }
    return rects;
}

// A buffer's answers to rectangles, one test_rect call each (or test_rect_exhaustive's, the
// search without the pyramid), for comparing buffers or the two searches.
inline std::vector<Visibility> rect_answers(const OcclusionBuffer& b, const std::vector<ScreenRect>& rects, bool exhaustive = false) {
    std::vector<Visibility> answers;
    for (const ScreenRect& r : rects)
        answers.push_back(exhaustive ? b.test_rect_exhaustive(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min)
                                     : b.test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min));
    return answers;
}

// A job system (ParallelFor::run) that runs the tasks last to first on the calling thread, and
// allocates nothing itself.
inline void run_backwards(void*, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    for (std::size_t i = count; i-- > 0;) task(data, i);
}

// The generated city (seed 8, 6 blocks), its occluders, and a camera down its street.
struct CityStreet {
    Scene city = generate_scene("city:seed=8,blocks=6");
    WorldTriangles occluders = gather_world_triangles(city, objects_with_role(city, "occluder"));
    Camera camera = [] {
        Camera c;
        c.eye = {-3, 1.7, -40};
        c.target = {10, 3, 20};
        return c;
    }();
    std::array<float, 16> clip(double aspect) const { return clip_from_world(camera, aspect); }
};

}  // namespace homcull::test
