// The occlusion buffer on hand-built input: coverage, conservative depth, clipping, input
// formats, bad input, and the occludee tests.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/occlusion_maps.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace homcull {
namespace {

// Positions given as (x, y, w) in clip space: the matrix maps (x, y, z) to (x, y, 0, z).
std::array<float, 16> xyw_to_clip() {
    std::array<float, 16> m{};
    m[0] = 1;   // x -> x
    m[5] = 1;   // y -> y
    m[11] = 1;  // z -> w (column 2, row 3)
    return m;
}

// A TriangleInput over (x, y, w) vertices, three per triangle, no backface culling.
TriangleInput xyw_input(const std::vector<float>& v) {
    TriangleInput in;
    in.positions = v.data();
    in.vertex_count = v.size() / 3;
    in.triangle_count = v.size() / 9;
    in.model_to_clip = xyw_to_clip();
    in.backface = Backface::none;
    return in;
}

struct Soup {
    std::vector<float> xyz;  // (x, y, w) per vertex, three vertices per triangle
    void add(float x0, float y0, float x1, float y1, float x2, float y2, float w) {
        xyz.insert(xyz.end(), {x0 * w, y0 * w, w, x1 * w, y1 * w, w, x2 * w, y2 * w, w});  // NDC corners at depth w
    }
    TriangleInput input(Backface backface = Backface::none) const {
        TriangleInput in = xyw_input(xyz);
        in.backface = backface;
        return in;
    }
};

OcclusionBuffer make_buffer(int w, int h, int s = 1) { return OcclusionBuffer(test::buffer_config(w, h, s, 0.5f)); }

TEST(OcclusionBuffer, FullScreenQuadHidesWhatIsBehindIt) {
    OcclusionBuffer buffer = make_buffer(64, 36);
    Soup quad;
    quad.add(-1.5f, -1.5f, 1.5f, -1.5f, 1.5f, 1.5f, 10.0f);
    quad.add(-1.5f, -1.5f, 1.5f, 1.5f, -1.5f, 1.5f, 10.0f);
    buffer.render(quad.input());
    EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 20.0f), Visibility::occluded);
    EXPECT_EQ(buffer.test_rect(-1.0f, -1.0f, 1.0f, 1.0f, 10.5f), Visibility::occluded);
    EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 9.0f), Visibility::visible);   // in front
    EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 10.0f), Visibility::visible);  // touching: not hidden
    EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 0.4f), Visibility::visible);   // crosses the near plane
    EXPECT_EQ(buffer.test_rect(1.2f, -0.5f, 1.5f, 0.5f, 20.0f), Visibility::view_culled);
    EXPECT_EQ(buffer.test_rect(0.9f, -0.5f, 1.5f, 0.5f, 20.0f), Visibility::occluded);  // partly outside
    std::vector<std::uint8_t> covered;
    buffer.read_coverage(covered);
    for (auto c : covered) ASSERT_EQ(c, 1);
    std::vector<float> depth;
    buffer.read_depth(depth);
    for (float w : depth) {
        ASSERT_GE(w, 10.0f);  // conservative: never nearer than the occluder
        ASSERT_LT(w, 10.001f);
    }
}

TEST(OcclusionBuffer, PartialCoverageDoesNotHide) {
    OcclusionBuffer buffer = make_buffer(64, 64);
    Soup left;  // covers x in [-1, 0]
    left.add(-2, -2, 0, -2, 0, 2, 5);
    left.add(-2, -2, 0, 2, -2, 2, 5);
    buffer.render(left.input());
    EXPECT_EQ(buffer.test_rect(-0.9f, -0.5f, -0.1f, 0.5f, 8.0f), Visibility::occluded);
    EXPECT_EQ(buffer.test_rect(-0.9f, -0.5f, 0.1f, 0.5f, 8.0f), Visibility::visible);  // reaches past the edge
    EXPECT_EQ(buffer.test_rect(0.1f, -0.5f, 0.9f, 0.5f, 8.0f), Visibility::visible);
    // A rectangle between sample centres covers no sample: it cannot be seen at any sample.
    EXPECT_EQ(buffer.test_rect(0.5f + 0.001f, 0.0f, 0.5f + 0.002f, 0.001f, 1.0f), Visibility::occluded);
}

TEST(OcclusionBuffer, FusionOfTwoOccludersAtDifferentDepths) {
    OcclusionBuffer buffer = make_buffer(32, 32);
    Soup halves;  // left half at w = 4, right half at w = 6
    halves.add(-2, -2, 0, -2, 0, 2, 4);
    halves.add(-2, -2, 0, 2, -2, 2, 4);
    halves.add(0, -2, 2, -2, 2, 2, 6);
    halves.add(0, -2, 2, 2, 0, 2, 6);
    buffer.render(halves.input());
    EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 7.0f), Visibility::occluded);  // behind both
    EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 5.0f), Visibility::visible);   // in front of the right half
    EXPECT_EQ(buffer.test_rect(-0.9f, -0.5f, -0.2f, 0.5f, 5.0f), Visibility::occluded); // only the left half
}

// Exact-ish reference: is the sample centre strictly inside the triangle (sample space)?
long double edge(long double ax, long double ay, long double bx, long double by, long double px, long double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

TEST(OcclusionBuffer, CoverageAndDepthAreConservativeOnRandomTriangles) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> pos(-1.3f, 1.3f), depth(1.0f, 50.0f);
    for (int samples : {1, 2, 4}) {
        for (int trial = 0; trial < 200; ++trial) {
            // Odd sizes: partial subtiles; per-sample depth every other trial.
            OcclusionBuffer buffer(test::buffer_config(37, 23, samples, 0.5f, trial % 2 == 1));
            std::vector<float> v;
            float x[3], y[3], w[3];
            for (int k = 0; k < 3; ++k) {
                x[k] = pos(rng), y[k] = pos(rng), w[k] = depth(rng);
                v.insert(v.end(), {x[k] * w[k], y[k] * w[k], w[k]});
            }
            TriangleInput in = xyw_input(v);
            buffer.render(in);
            std::vector<std::uint8_t> covered;
            std::vector<float> stored;
            buffer.read_coverage(covered);
            buffer.read_depth(stored);
            const int sw = buffer.sample_width(), sh = buffer.sample_height();
            long double sx[3], sy[3];  // from the floats the buffer was given
            for (int k = 0; k < 3; ++k) {
                sx[k] = ((long double)v[3 * k] / v[3 * k + 2] + 1) * 0.5L * sw;
                sy[k] = (1 - (long double)v[3 * k + 1] / v[3 * k + 2]) * 0.5L * sh;
            }
            const long double area = edge(sx[0], sy[0], sx[1], sy[1], sx[2], sy[2]);
            const long double sign = area > 0 ? 1 : -1;
            int missed_interior = 0;
            for (int j = 0; j < sh; ++j)
                for (int i = 0; i < sw; ++i) {
                    const long double px = i + 0.5L, py = j + 0.5L;
                    long double e[3], len[3];
                    for (int k = 0; k < 3; ++k) {
                        const int n = (k + 1) % 3;
                        e[k] = sign * edge(sx[k], sy[k], sx[n], sy[n], px, py);
                        len[k] = std::sqrt((sx[n] - sx[k]) * (sx[n] - sx[k]) + (sy[n] - sy[k]) * (sy[n] - sy[k]));
                    }
                    const bool inside = e[0] > 0 && e[1] > 0 && e[2] > 0;
                    const bool deep = e[0] > 0.01L * len[0] && e[1] > 0.01L * len[1] && e[2] > 0.01L * len[2];
                    const std::size_t at = std::size_t(j) * std::size_t(sw) + std::size_t(i);
                    if (covered[at]) {
                        ASSERT_TRUE(inside) << "sample " << i << "," << j << " covered outside the triangle";
                        // True 1/w at the sample, by barycentric interpolation of 1/w.
                        const long double l0 = sign * edge(sx[1], sy[1], sx[2], sy[2], px, py) / (sign * area);
                        const long double l1 = sign * edge(sx[2], sy[2], sx[0], sy[0], px, py) / (sign * area);
                        const long double l2 = 1 - l0 - l1;
                        const long double true_w = 1 / (l0 / w[0] + l1 / w[1] + l2 / w[2]);
                        ASSERT_GE((long double)stored[at], true_w * (1 - 1e-7L)) << "depth nearer than the occluder";
                    }
                    missed_interior += deep && !covered[at];
                }
            EXPECT_EQ(missed_interior, 0) << "samples well inside the triangle left uncovered";
        }
    }
}

TEST(OcclusionBuffer, NearPlaneClippingKeepsOnlyWhatIsInFront) {
    OcclusionBuffer buffer = make_buffer(64, 64);
    // A floor-like triangle from w = 0.1 (behind near = 0.5) to w = 20.
    const std::vector<float> v = {-5.0f, -1.0f, 0.1f, 5.0f, -1.0f, 0.1f, 0.0f, -1.0f, 20.0f};
    TriangleInput in = xyw_input(v);
    buffer.render(in);
    EXPECT_EQ(buffer.stats().near_clipped, 1u);
    EXPECT_EQ(buffer.stats().rasterized, 1u);
    std::vector<float> stored;
    buffer.read_depth(stored);
    for (float w : stored) ASSERT_TRUE(std::isinf(w) || w >= 0.5f);
    // Entirely behind the near plane: nothing.
    OcclusionBuffer behind = make_buffer(16, 16);
    const std::vector<float> b = {-1.0f, -1.0f, 0.2f, 1.0f, -1.0f, 0.2f, 0.0f, 1.0f, 0.3f};
    in.positions = b.data();
    behind.render(in);
    EXPECT_EQ(behind.stats().outside, 1u);
    EXPECT_EQ(behind.stats().rasterized, 0u);
}

TEST(OcclusionBuffer, BadTrianglesAreSkippedAndCounted) {
    OcclusionBuffer buffer = make_buffer(16, 16);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const std::vector<float> v = {
        -1, -1, 5, 1, -1, 5, 0, 1, 5,     // 0-2 a good triangle (NDC +-0.2 at w = 5)
        nan, 0, 5, 1, 0, 5, 0, 1, 5,      // 3-5 NaN
        0, 0, inf, 1, 0, 5, 0, 1, 5,      // 6-8 Inf
        0, 0, 5, 1, 1, 5, 2, 2, 5,        // 9-11 collinear: degenerate
        1e30f, 1e30f, 1, -1e30f, 1e30f, 1, 0, -1e30f, 1,  // 12-14 beyond any precision
    };
    const std::vector<std::uint32_t> indices = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 99, 12, 13, 14};
    TriangleInput in;
    in.positions = v.data();
    in.vertex_count = v.size() / 3;
    in.indices = indices.data();
    in.triangle_count = indices.size() / 3;
    in.model_to_clip = xyw_to_clip();
    in.backface = Backface::none;
    buffer.render(in);
    const RasterStats& s = buffer.stats();
    EXPECT_EQ(s.triangles_in, 6u);
    EXPECT_EQ(s.invalid, 3u);  // NaN, Inf, index 99
    EXPECT_EQ(s.degenerate, 1u);
    EXPECT_EQ(s.too_large, 1u);
    EXPECT_EQ(s.rasterized, 1u);
    EXPECT_EQ(buffer.test_rect(-0.1f, -0.1f, 0.1f, 0.1f, 6.0f), Visibility::occluded);  // behind the good one
    EXPECT_EQ(buffer.test_rect(-0.1f, -0.1f, 0.1f, 0.1f, 2.0f), Visibility::visible);   // the huge one was skipped
}

TEST(OcclusionBuffer, HugeTrianglesAreClippedToTheGuardBand) {
    OcclusionBuffer buffer = make_buffer(40, 30, 2);
    const std::vector<float> v = {1e7f, 1e7f, 1, -1e7f, 1e7f, 1, 0, -1e7f, 1};  // NDC +-1e7 at w = 1
    TriangleInput in = xyw_input(v);
    buffer.render(in);
    EXPECT_EQ(buffer.stats().near_clipped, 1u);
    EXPECT_EQ(buffer.stats().rasterized, 1u);
    std::vector<std::uint8_t> covered;
    buffer.read_coverage(covered);
    for (auto c : covered) ASSERT_EQ(c, 1);  // fan diagonals of the clipped polygon leave no cracks
    EXPECT_EQ(buffer.test_rect(-1, -1, 1, 1, 1.5f), Visibility::occluded);
}

TEST(OcclusionBuffer, BackfaceModesIndicesAndStride) {
    // Interleaved vertices (position + 2 floats of other data), 16-bit indices.
    // A quad at w = 5 covering NDC [-2, 2]^2 (clip x, y = +-10).
    const std::vector<float> interleaved = {-10, -10, 5, 0, 0,  10, -10, 5, 0, 0,  10, 10, 5, 0, 0,  -10, 10, 5, 0, 0};
    const std::vector<std::uint16_t> ccw = {0, 1, 2, 0, 2, 3}, cw = {0, 2, 1, 0, 3, 2};
    for (Backface mode : {Backface::none, Backface::cw, Backface::ccw})
        for (const auto* indices : {&ccw, &cw}) {
            OcclusionBuffer buffer = make_buffer(16, 16);
            TriangleInput in;
            in.positions = interleaved.data();
            in.position_stride = 5 * sizeof(float);
            in.vertex_count = 4;
            in.indices = indices->data();
            in.indices_16bit = true;
            in.triangle_count = 2;
            in.model_to_clip = xyw_to_clip();
            in.backface = mode;
            std::vector<std::uint32_t> indices32(indices->begin(), indices->end());
            std::uint8_t shared[2];
            std::uint32_t apexes[6];
            compute_shared_edges(interleaved.data(), 5 * sizeof(float), 4, indices32.data(), 2, shared, apexes);
            in.shared_edges = shared;
            in.edge_apexes = apexes;
            buffer.render(in);
            const bool culled = (mode == Backface::cw && indices == &cw) || (mode == Backface::ccw && indices == &ccw);
            EXPECT_EQ(buffer.stats().backface_culled, culled ? 2u : 0u);
            EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 9.0f), culled ? Visibility::visible : Visibility::occluded);
        }
}

// A quad whose diagonal runs exactly through sample centres: without shared-edge flags the
// coverage margin leaves those samples to neither triangle (a crack, so nothing behind is
// hidden); with them, the union covers every sample.
TEST(OcclusionBuffer, SharedEdgesLeaveNoCracks) {
    const std::vector<float> quad = {-10, -10, 5, 10, -10, 5, 10, 10, 5, -10, 10, 5};
    const std::vector<std::uint32_t> indices = {0, 1, 2, 0, 2, 3};
    std::uint8_t shared[2];
    std::uint32_t apexes[6];
    compute_shared_edges(quad.data(), 12, 4, indices.data(), 2, shared, apexes);
    EXPECT_EQ(shared[0], 4u);  // edge 2 -> 0 of the first triangle
    EXPECT_EQ(shared[1], 1u);  // edge 0 -> 2 of the second
    for (bool with_flags : {false, true}) {
        OcclusionBuffer buffer = make_buffer(16, 16);
        TriangleInput in;
        in.positions = quad.data();
        in.vertex_count = 4;
        in.indices = indices.data();
        in.triangle_count = 2;
        in.model_to_clip = xyw_to_clip();
        in.shared_edges = with_flags ? shared : nullptr;
        in.edge_apexes = apexes;
        buffer.render(in);
        std::vector<std::uint8_t> covered;
        buffer.read_coverage(covered);
        std::size_t count = 0;
        for (auto c : covered) count += c;
        EXPECT_EQ(count, with_flags ? 256u : 256u - 16u);  // the 16 diagonal samples
        EXPECT_EQ(buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 9.0f), with_flags ? Visibility::occluded : Visibility::visible);
    }
}

TEST(OcclusionBuffer, FineMeshWithSharedEdgesLeavesNoCracksEvenWhenClipped) {
    // A 40 x 40 grid over NDC [-1.2, 1.2]^2 with w = 0.2 + 2 x (column / 40): the near plane
    // (w = 0.5) cuts it exactly along grid column 6, at NDC x = -0.84. Right of that every
    // sample must be covered; left of it, none.
    std::vector<float> grid;
    std::vector<std::uint32_t> indices;
    const int n = 40;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float w = 0.2f + 2.0f * float(i) / n;
            grid.insert(grid.end(), {(-1.2f + 2.4f * float(i) / n) * w, (-1.2f + 2.4f * float(j) / n) * w, w});
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::uint32_t a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n) + 2, d = a + std::uint32_t(n) + 1;
            indices.insert(indices.end(), {a, b, c, a, c, d});
        }
    std::vector<std::uint8_t> shared(indices.size() / 3);
    std::vector<std::uint32_t> apexes(indices.size());
    compute_shared_edges(grid.data(), 12, grid.size() / 3, indices.data(), shared.size(), shared.data(), apexes.data());
    OcclusionBuffer buffer = make_buffer(97, 61, 2);
    TriangleInput in;
    in.positions = grid.data();
    in.vertex_count = grid.size() / 3;
    in.indices = indices.data();
    in.triangle_count = shared.size();
    in.model_to_clip = xyw_to_clip();
    in.shared_edges = shared.data();
    in.edge_apexes = apexes.data();
    buffer.render(in);
    EXPECT_GT(buffer.stats().near_clipped, 0u);
    std::vector<std::uint8_t> covered;
    buffer.read_coverage(covered);
    std::size_t holes = 0, wrong = 0;
    for (int y = 0; y < buffer.sample_height(); ++y)
        for (int x = 0; x < buffer.sample_width(); ++x) {
            const double ndc_x = (x + 0.5) / buffer.sample_width() * 2 - 1;
            const bool c = covered[std::size_t(y) * std::size_t(buffer.sample_width()) + std::size_t(x)] != 0;
            if (ndc_x > -0.84 + 1e-3) holes += !c;
            if (ndc_x < -0.84 - 1e-3) wrong += c;
        }
    EXPECT_EQ(holes, 0u);
    EXPECT_EQ(wrong, 0u);
}

TEST(OcclusionBuffer, AabbTestsUseTheCornersAndTheNearPlane) {
    Camera camera;
    camera.eye = {0, 0, 0};
    camera.target = {0, 0, -1};
    camera.near_plane = 0.5;
    camera.far_plane = 100;
    BufferConfig config;
    config.width = 64;
    config.height = 64;
    config.near_w = 0.5f;
    OcclusionBuffer buffer(config);
    const auto clip = clip_from_world(camera, 1.0);
    // A wall at z = -10 wide enough to fill the view (two triangles, world space).
    const std::vector<float> wall = {-20, -20, -10, 20, -20, -10, 20, 20, -10, -20, -20, -10, 20, 20, -10, -20, 20, -10};
    TriangleInput in;
    in.positions = wall.data();
    in.vertex_count = 6;
    in.triangle_count = 2;
    in.model_to_clip = clip;
    std::uint8_t shared[2];
    std::uint32_t apexes[6];
    compute_shared_edges(wall.data(), 12, 6, nullptr, 2, shared, apexes);
    in.shared_edges = shared;
    in.edge_apexes = apexes;
    buffer.render(in);
    const float behind_min[3] = {-1, -1, -15}, behind_max[3] = {1, 1, -12};
    const float front_min[3] = {-1, -1, -8}, front_max[3] = {1, 1, -6};
    const float crossing_min[3] = {-1, -1, -3}, crossing_max[3] = {1, 1, 1};
    const float back_min[3] = {-1, -1, 2}, back_max[3] = {1, 1, 4};
    const float side_min[3] = {50, -1, -15}, side_max[3] = {52, 1, -12};
    EXPECT_EQ(buffer.test_aabb(behind_min, behind_max, clip), Visibility::occluded);
    EXPECT_EQ(buffer.test_aabb(front_min, front_max, clip), Visibility::visible);
    EXPECT_EQ(buffer.test_aabb(crossing_min, crossing_max, clip), Visibility::visible);
    EXPECT_EQ(buffer.test_aabb(back_min, back_max, clip), Visibility::view_culled);
    EXPECT_EQ(buffer.test_aabb(side_min, side_max, clip), Visibility::view_culled);
}

// Boxes around the view volume's four side edges, within a few units of them on either side:
// those beside a corner of the view (outside two side planes at once, within each alone) keep a
// screen rectangle on the screen, and only test_aabb's exact view test culls them.
TEST(OcclusionBuffer, BoxesBesideACornerOfTheViewAreViewCulled) {
    for (const bool orthographic : {false, true}) {
        Camera camera;
        camera.eye = {0, 0, 0};
        camera.target = {1.0, 0.35, -0.8};
        camera.near_plane = 0.5;
        camera.far_plane = 1000;
        if (orthographic) camera.ortho_height = 20.0;
        const double aspect = 16.0 / 9.0;
        BufferConfig config;
        config.width = 160;
        config.height = 90;
        config.near_w = 0.5f;
        config.orthographic = orthographic;
        const OcclusionBuffer buffer(config);  // empty: every box in view is visible
        const auto clip = clip_from_world(camera, aspect);
        const Frustum frustum = make_frustum(camera, aspect);
        std::uint64_t seed = 777;
        const auto uniform = [&](double lo, double hi) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            return lo + (hi - lo) * double(seed >> 11) * 0x1.0p-53;
        };
        std::vector<Aabb> boxes;
        for (int k = 0; k < 2000; ++k) {
            const std::size_t edge = std::size_t(k % 4);
            const glm::dvec3 along = frustum.corners[edge] + uniform(0.002, 0.05) * (frustum.corners[edge + 4] - frustum.corners[edge]);
            const glm::vec3 lo(float(along.x + uniform(-6, 3)), float(along.y + uniform(-6, 3)), float(along.z + uniform(-6, 3)));
            const glm::vec3 size(float(uniform(0.25, 3)), float(uniform(0.25, 3)), float(uniform(0.25, 3)));
            boxes.push_back({lo, lo + size});
        }
        std::vector<Visibility> batch(boxes.size());
        buffer.test_aabbs(boxes.data(), boxes.size(), clip, batch.data());
        std::size_t apart = 0, beside_a_corner = 0;
        for (std::size_t k = 0; k < boxes.size(); ++k) {
            const Visibility v = buffer.test_aabb(&boxes[k].min.x, &boxes[k].max.x, clip);
            EXPECT_EQ(batch[k], v) << orthographic << ", box " << k;
            if (intersects(frustum, boxes[k])) {
                EXPECT_NE(v, Visibility::view_culled) << orthographic << ", box " << k;
            } else {
                // Occluded when its screen rectangle holds no sample centre: hidden either way.
                EXPECT_NE(v, Visibility::visible) << orthographic << ", box " << k;
            }
            apart += !intersects(frustum, boxes[k]);
            beside_a_corner += v == Visibility::view_culled && may_meet(frustum, boxes[k]);
        }
        EXPECT_GT(apart, boxes.size() / 4) << orthographic;
        EXPECT_GE(beside_a_corner, 3u) << orthographic << ": no box beside a corner of the view, where only the exact test culls";
        if (orthographic) continue;  // the maps take perspective buffers
        // The occlusion maps' box test makes the same view test (with or without pyramids).
        for (const PyramidBuild pyramid : {PyramidBuild::always, PyramidBuild::lazy}) {
            OcclusionMapsConfig mc;
            mc.display_width = buffer.sample_width();
            mc.display_height = buffer.sample_height();
            mc.pyramid = pyramid;
            OcclusionMaps maps(buffer, mc);
            maps.build(buffer);
            for (std::size_t k = 0; k < boxes.size(); ++k) {
                EXPECT_EQ(maps.test_aabb(boxes[k], clip).visibility, batch[k]) << "maps, box " << k;
            }
        }
    }
}

TEST(OcclusionBuffer, InvalidConfigurationsAreRejected) {
    BufferConfig c;
    c.width = 0;
    c.height = 10;
    EXPECT_THROW(OcclusionBuffer{c}, Error);
    c.width = 10;
    c.samples = 3;
    EXPECT_THROW(OcclusionBuffer{c}, Error);
    c.samples = 1;
    c.near_w = 0.0f;
    EXPECT_THROW(OcclusionBuffer{c}, Error);
    // A subnormal near_w: 1/near_w overflows float depths, and threaded renders drew apart from
    // serial ones (fuzz_buffer's find).
    c.near_w = 8.8e-44f;
    EXPECT_THROW(OcclusionBuffer{c}, Error);
    c.near_w = 0x1.0p-126f;
    EXPECT_NO_THROW(OcclusionBuffer{c});
    c.near_w = 0.1f;
    EXPECT_NO_THROW(OcclusionBuffer{c});
    c.width = 1;
    c.height = 1;
    OcclusionBuffer tiny(c);  // 1x1 works
    EXPECT_EQ(tiny.test_rect(-1, -1, 1, 1, 5), Visibility::visible);
}

}  // namespace
}  // namespace homcull
