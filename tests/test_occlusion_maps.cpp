// Hierarchical occlusion maps on hand-built buffers: the opacity pyramid, every early
// termination of the overlap test, approximate culling's hole size, the depth tests (and the
// one that is not conservative), and a property test of the conservative overlap test against
// brute-force coverage.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/occlusion_maps.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

namespace homcull {
namespace {

// Axis-aligned occluder rectangles given in buffer pixels (fractions reach single samples),
// each two triangles whose diagonal is flagged as shared, so the pixels it crosses stay covered.
struct Occluders {
    int width, height;  // buffer pixels
    std::vector<float> xyzw;
    std::vector<std::uint8_t> shared;
    std::vector<std::uint32_t> apexes;
    void add(double x0, double y0, double x1, double y1, float w) {
        auto vertex = [&](double px, double py) {
            const float x = float(px / width * 2.0 - 1.0), y = float(1.0 - py / height * 2.0);
            xyzw.insert(xyzw.end(), {x * w, y * w, 0.0f, w});
        };
        vertex(x0, y0), vertex(x1, y0), vertex(x1, y1);  // edge 2 (x1,y1 -> x0,y0) is the diagonal
        vertex(x0, y0), vertex(x1, y1), vertex(x0, y1);  // edge 0 (x0,y0 -> x1,y1) is the diagonal
        shared.push_back(4u);
        shared.push_back(1u);
        const auto base = std::uint32_t(xyzw.size() / 4 - 6);  // across each diagonal: the other triangle's third vertex
        apexes.insert(apexes.end(), {kNoApex, kNoApex, base + 5, base + 1, kNoApex, kNoApex});
    }
    TriangleInput input() const {
        TriangleInput in = test::clip_space_input(xyzw);
        in.clip_space = false;  // shared edges: drawn through the identity matrix
        in.shared_edges = shared.data();
        in.edge_apexes = apexes.data();
        return in;
    }
};

// A screen rectangle over buffer pixels [x0, x1) x [y0, y1) (fractions: samples) at depth w.
ScreenRect pixel_rect(int width, int height, double x0, double y0, double x1, double y1, float w) {
    return {float(x0 / width * 2.0 - 1.0), float(1.0 - y1 / height * 2.0), float(x1 / width * 2.0 - 1.0),
            float(1.0 - y0 / height * 2.0), w};
}

OcclusionBuffer buffer_of(int width, int height, int samples, const Occluders& occluders, DrawOrder order = DrawOrder::nearest_first) {
    OcclusionBuffer buffer(test::buffer_config(width, height, samples, 0.5f));
    TriangleInput in = occluders.input();
    in.order = order;
    if (!occluders.xyzw.empty()) buffer.render(in);
    return buffer;
}

// The tests below study the pyramids and the overlap test: they make them whatever the mode
// (PyramidBuild::always); LazyMaps... checks what lazy maps answer instead.
OcclusionMapsConfig maps_config(const OcclusionBuffer& b, DepthTest depth = DepthTest::masked, double hole = 0.0,
                                PyramidBuild pyramid = PyramidBuild::always) {
    OcclusionMapsConfig c;
    c.display_width = b.sample_width();
    c.display_height = b.sample_height();
    c.depth = depth;
    c.hole_pixels = hole;
    c.pyramid = pyramid;
    return c;
}

// Boxes given in clip space as (x, y, w): (x, y, z) -> (x, y, 0, z), column-major.
const std::array<float, 16> kXyw = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0};

OverlapExit exit_of(const OccludeeAnswer& a) { return OverlapExit(a.overlap_exit); }

TEST(OcclusionMaps, OpacityPyramidCountsCoveredSamplesOnOddSizes) {
    for (int s : {1, 2, 4}) {
        const int width = 37, height = 23;  // odd at every level
        Occluders o{width, height, {}, {}, {}};
        o.add(3.25, 2.5, 30.0, 9.75, 5.0f);
        o.add(10.0, 12.0, 36.5, 22.0, 7.0f);
        const OcclusionBuffer buffer = buffer_of(width, height, s, o);
        OcclusionMaps maps(buffer, maps_config(buffer));
        maps.build(buffer);
        std::vector<std::uint8_t> covered;
        buffer.read_coverage(covered);
        for (int k = 0; k < maps.levels(); ++k)
            for (int y = 0; y < maps.level_height(k); ++y)
                for (int x = 0; x < maps.level_width(k); ++x) {
                    std::uint32_t count = 0, samples = 0;
                    for (int sy = (y << k) * s; sy < std::min((y + 1) << k, height) * s; ++sy)
                        for (int sx = (x << k) * s; sx < std::min((x + 1) << k, width) * s; ++sx) {
                            count += covered[std::size_t(sy) * std::size_t(width * s) + std::size_t(sx)];
                            ++samples;
                        }
                    ASSERT_EQ(maps.covered_samples(k)[y * maps.level_width(k) + x], count) << "S " << s << " level " << k;
                    ASSERT_EQ(maps.cell_samples(k, x, y), samples);
                }
        const int last = maps.levels() - 1;
        EXPECT_LE(maps.level_width(last), 4);
        EXPECT_LE(maps.level_height(last), 4);
    }
}

// The pyramid reduction runs in SIMD: every instruction set builds the scalar reference's bits.
TEST(OcclusionMaps, EveryIsaBuildsTheSamePyramids) {
    const std::vector<float> tris = test::random_clip_triangles(5, 800, 0.4f);
    for (int s : {1, 4}) {
        std::vector<std::uint32_t> reference_covered;
        std::vector<float> reference_far, reference_near;
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            BufferConfig c;
            c.width = 203;  // odd widths at several levels, and rows longer than a vector
            c.height = 77;
            c.samples = s;
            c.near_w = 0.5f;
            OcclusionBuffer buffer(c);
            buffer.render(test::clip_space_input(tris));
            OcclusionMapsConfig config = maps_config(buffer);
            config.depth_pyramids = DepthPyramids::both;
            OcclusionMaps maps(buffer, config);
            maps.build(buffer);
            std::vector<std::uint32_t> covered;
            std::vector<float> far, near;
            for (int k = 0; k < maps.levels(); ++k) {
                const std::size_t n = std::size_t(maps.level_width(k)) * std::size_t(maps.level_height(k));
                covered.insert(covered.end(), maps.covered_samples(k), maps.covered_samples(k) + n);
                far.insert(far.end(), maps.farthest_depth(k), maps.farthest_depth(k) + n);
                near.insert(near.end(), maps.nearest_depth(k), maps.nearest_depth(k) + n);
            }
            if (isa == "scalar") {
                reference_covered = covered, reference_far = far, reference_near = near;
                continue;
            }
            EXPECT_EQ(covered, reference_covered) << isa << " S " << s;
            EXPECT_EQ(far, reference_far) << isa << " S " << s;
            EXPECT_EQ(near, reference_near) << isa << " S " << s;
        }
    }
}

// By default the maps make only the depth pyramid their depth test reads: the same opacity
// pyramid, the same bits in the pyramid made, null for the others, and the same answers as
// maps making both, for every depth test, with and without holes, on every instruction set.
TEST(OcclusionMaps, MakeOnlyTheDepthPyramidTheirTestReads) {
    const std::vector<float> tris = test::random_clip_triangles(9, 400, 0.3f);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> ndc(-1.1f, 1.0f), size(0.0f, 0.5f), w(0.5f, 30.0f);
    std::vector<ScreenRect> rects;
    for (int k = 0; k < 400; ++k) {
        const float x = ndc(rng), y = ndc(rng);
        rects.push_back({x, y, x + size(rng), y + size(rng), w(rng)});
    }
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        for (int s : {1, 4}) {
            OcclusionBuffer buffer(test::buffer_config(101, 67, s, 0.5f));
            buffer.render(test::clip_space_input(tris));
            for (DepthTest depth : {DepthTest::masked, DepthTest::hzb, DepthTest::deb, DepthTest::nbz, DepthTest::plane})
                for (double hole : {0.0, 6.0}) {
                    OcclusionMapsConfig config = maps_config(buffer, depth, hole);
                    OcclusionMaps needed(buffer, config);
                    config.depth_pyramids = DepthPyramids::both;
                    OcclusionMaps both(buffer, config);
                    for (OcclusionMaps* maps : {&needed, &both}) {
                        maps->add_occluder_box({{-0.5f, -0.5f, 4.0f}, {0.3f, 0.4f, 6.0f}}, kXyw);
                        maps->build(buffer);
                    }
                    const std::string what = isa + " S " + std::to_string(s) + " depth " + std::to_string(int(depth)) + " hole " +
                                             std::to_string(hole);
                    const bool far_made = depth == DepthTest::hzb || depth == DepthTest::plane, near_made = depth == DepthTest::nbz;
                    for (int k = 0; k < both.levels(); ++k) {
                        const std::size_t n = std::size_t(both.level_width(k)) * std::size_t(both.level_height(k));
                        ASSERT_TRUE(std::equal(both.covered_samples(k), both.covered_samples(k) + n, needed.covered_samples(k))) << what;
                        ASSERT_EQ(needed.farthest_depth(k) != nullptr, far_made) << what;
                        ASSERT_EQ(needed.nearest_depth(k) != nullptr, near_made) << what;
                        if (far_made) {
                            ASSERT_TRUE(std::equal(both.farthest_depth(k), both.farthest_depth(k) + n, needed.farthest_depth(k))) << what;
                        }
                        if (near_made) {
                            ASSERT_TRUE(std::equal(both.nearest_depth(k), both.nearest_depth(k) + n, needed.nearest_depth(k))) << what;
                        }
                    }
                    EXPECT_EQ(needed.plane_depth(), far_made ? both.plane_depth() : INFINITY) << what;
                    int occluded = 0;
                    for (const ScreenRect& r : rects) {
                        const OccludeeAnswer a = needed.test_rect(r), b = both.test_rect(r);
                        ASSERT_EQ(a.visibility, b.visibility) << what;
                        ASSERT_EQ(a.level_of_visibility, b.level_of_visibility) << what;
                        ASSERT_EQ(a.overlap_exit, b.overlap_exit) << what;
                        occluded += a.visibility == Visibility::occluded;
                    }
                    EXPECT_GT(occluded, 0) << what;  // the answers compared include hidden ones
                }
        }
    }
}

TEST(OcclusionMaps, ThresholdsFollowZhang) {
    const OcclusionBuffer buffer = buffer_of(64, 64, 1, Occluders{64, 64, {}, {}, {}});
    OcclusionMapsConfig c = maps_config(buffer);
    const OcclusionMaps conservative(buffer, c);
    for (int k = 0; k < conservative.levels(); ++k) {
        EXPECT_EQ(conservative.opacity_threshold(k), 1.0);
        EXPECT_EQ(conservative.transparency_threshold(k), 0.0);
    }
    c.display_width = c.display_height = 128;  // m0 = 2 display pixels per buffer pixel
    c.hole_pixels = 2.0;
    c.distribution = 2.0;
    c.transparency = 0.4;
    const OcclusionMaps approximate(buffer, c);
    double t = 1.0 - 2.0 * 2.0 / (4.0 * 4.0), tt = 0.4;  // T0 = 1 - D L / (4 m0^2)
    for (int k = 0; k < approximate.levels(); ++k) {
        EXPECT_DOUBLE_EQ(approximate.opacity_threshold(k), t);
        EXPECT_DOUBLE_EQ(approximate.transparency_threshold(k), tt);
        t = 1.0 - 2.0 * (1.0 - t) / 4.0;
        tt = 2.0 * tt / 4.0;
    }
}

// 64 x 64 pixels, everything covered at w = 4 except pixel (10, 10).
TEST(OcclusionMaps, OverlapPassesAndConservativeRejection) {
    Occluders o{64, 64, {}, {}, {}};
    o.add(0, 0, 64, 10, 4.0f);
    o.add(0, 11, 64, 64, 4.0f);
    o.add(0, 10, 10, 11, 4.0f);
    o.add(11, 10, 64, 11, 4.0f);
    const OcclusionBuffer buffer = buffer_of(64, 64, 1, o);
    OcclusionMaps maps(buffer, maps_config(buffer));
    maps.build(buffer);
    // Inside the covered part, behind it: passes, occluded.
    OccludeeAnswer a = maps.test_rect(pixel_rect(64, 64, 32, 32, 64, 64, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::passed);
    EXPECT_EQ(a.visibility, Visibility::occluded);
    EXPECT_EQ(a.level_of_visibility, 0.0f);
    // In front of it: the overlap passes, the depth test does not.
    a = maps.test_rect(pixel_rect(64, 64, 32, 32, 64, 64, 2.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::passed);
    EXPECT_EQ(a.visibility, Visibility::visible);
    // The 32 x 32 cell holding the hole, whole: conservative rejection at the start level.
    a = maps.test_rect(pixel_rect(64, 64, 0, 0, 32, 32, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::conservative_rejection);
    EXPECT_EQ(a.visibility, Visibility::visible);
    EXPECT_NEAR(a.level_of_visibility, 1.0 / 1024.0, 1e-7);
    // Partly over the hole's cell but not over the hole: descends and passes.
    a = maps.test_rect(pixel_rect(64, 64, 12, 12, 44, 44, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::passed);
    EXPECT_EQ(a.visibility, Visibility::occluded);
}

TEST(OcclusionMaps, PredictiveRejectionAndTransparentCells) {
    Occluders o{64, 64, {}, {}, {}};
    o.add(0, 0, 10, 10, 4.0f);  // 100 of the 256 pixels of the 16 x 16 cell (0, 0)
    const OcclusionBuffer buffer = buffer_of(64, 64, 1, o);
    OcclusionMaps maps(buffer, maps_config(buffer));
    maps.build(buffer);
    // 144 pixels of that cell in the rectangle, only 100 covered: some hole must be inside.
    OccludeeAnswer a = maps.test_rect(pixel_rect(64, 64, 4, 4, 20, 20, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::predictive_rejection);
    // Nothing covered at all where the rectangle is.
    a = maps.test_rect(pixel_rect(64, 64, 40, 40, 50, 50, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::transparent_cell);
    EXPECT_EQ(a.level_of_visibility, 1.0f);
    // Inside the covered square: passes after descending.
    a = maps.test_rect(pixel_rect(64, 64, 1, 1, 9, 9, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::passed);
    EXPECT_EQ(a.visibility, Visibility::occluded);
}

TEST(OcclusionMaps, SamplesDecideWithinAPixel) {
    // S = 4: the sample rows above 22 are covered, so pixel row 5 is half covered (its top two
    // sample rows).
    Occluders o{16, 16, {}, {}, {}};
    o.add(0, 0, 16, 5.5, 4.0f);
    const OcclusionBuffer buffer = buffer_of(16, 16, 4, o);
    OcclusionMaps maps(buffer, maps_config(buffer));
    maps.build(buffer);
    // The covered half of pixel (5, 5): passes by its samples.
    OccludeeAnswer a = maps.test_rect(pixel_rect(16, 16, 5.0, 5.0, 6.0, 5.5, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::passed);
    EXPECT_EQ(a.visibility, Visibility::occluded);
    // Its left half, rows of both halves: 8 samples as many as are covered, 4 of them not.
    a = maps.test_rect(pixel_rect(16, 16, 5.0, 5.0, 5.5, 6.0, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::samples);
    EXPECT_EQ(a.visibility, Visibility::visible);
}

TEST(OcclusionMaps, FinestActiveLevelChargesItsHoles) {
    Occluders o{64, 64, {}, {}, {}};
    o.add(0, 0, 10, 64, 4.0f);  // columns 0..9 covered
    const OcclusionBuffer buffer = buffer_of(64, 64, 1, o);
    OcclusionMapsConfig c = maps_config(buffer);
    c.finest_level = 3;  // cells of 8 x 8 pixels: column 8..15 is a half-covered cell
    OcclusionMaps maps(buffer, c);
    maps.build(buffer);
    const OccludeeAnswer a = maps.test_rect(pixel_rect(64, 64, 0, 0, 10, 8, 8.0f));
    EXPECT_EQ(exit_of(a), OverlapExit::finest_level);
    EXPECT_EQ(a.visibility, Visibility::visible);
    // With every level active the same rectangle is found covered.
    OcclusionMaps all(buffer, maps_config(buffer));
    all.build(buffer);
    EXPECT_EQ(all.test_rect(pixel_rect(64, 64, 0, 0, 10, 8, 8.0f)).visibility, Visibility::occluded);
}

// A wall at w = 4 with a square hole of side `hole` pixels, and an occludee at w = 8 whose
// rectangle holds the hole: approximate culling with L = 16 pixels hides it behind a hole of
// 16 pixels and keeps it behind one of 25; conservative mode keeps it behind any hole.
TEST(OcclusionMaps, ApproximateCullingToleratesHolesUpToL) {
    for (DepthTest depth : {DepthTest::masked, DepthTest::hzb, DepthTest::nbz, DepthTest::plane, DepthTest::deb})
        for (int hole : {0, 1, 4, 5, 8}) {
            Occluders o{128, 128, {}, {}, {}};
            const int h0 = 50, h1 = 50 + hole;
            o.add(0, 0, 128, h0, 4.0f);
            o.add(0, h1, 128, 128, 4.0f);
            o.add(0, h0, h0, h1, 4.0f);
            o.add(h1, h0, 128, h1, 4.0f);
            const OcclusionBuffer buffer = buffer_of(128, 128, 1, o);
            const ScreenRect behind = pixel_rect(128, 128, 30, 30, 90, 90, 8.0f);
            for (double L : {0.0, 16.0}) {
                OcclusionMaps maps(buffer, maps_config(buffer, depth, L));
                maps.clear();
                maps.add_occluder_box({glm::vec3(-4.0f, -4.0f, 4.0f), glm::vec3(4.0f, 4.0f, 4.0f)}, kXyw);  // the wall's box
                maps.build(buffer);
                const OccludeeAnswer a = maps.test_rect(behind);
                const bool hidden = hole == 0 || (L > 0.0 && hole * hole <= L);
                EXPECT_EQ(a.visibility, hidden ? Visibility::occluded : Visibility::visible)
                    << "depth " << int(depth) << ", hole " << hole << "x" << hole << ", L " << L;
                if (hidden) {
                    EXPECT_NEAR(a.level_of_visibility, double(hole * hole) / 3600.0, 1e-6);
                }
                // In front of the wall nothing is hidden, holes or not.
                EXPECT_EQ(maps.test_rect(pixel_rect(128, 128, 30, 30, 90, 90, 3.0f)).visibility, Visibility::visible);
            }
        }
}

// One occludee tested as several rectangles (SceneCuller tests an object's triangles) shares one
// hole budget: two holes of 16 pixels hide it with L = 32, not with L = 16, however it is cut.
TEST(OcclusionMaps, RectanglesOfOneOccludeeShareTheHoleBudget) {
    Occluders o{128, 128, {}, {}, {}};
    o.add(0, 0, 128, 40, 4.0f);  // a wall at w = 4 with 4 x 4 holes at (40, 40) and (80, 40)
    o.add(0, 44, 128, 128, 4.0f);
    o.add(0, 40, 40, 44, 4.0f);
    o.add(44, 40, 80, 44, 4.0f);
    o.add(84, 40, 128, 44, 4.0f);
    const OcclusionBuffer buffer = buffer_of(128, 128, 1, o);
    const ScreenRect left = pixel_rect(128, 128, 20, 20, 60, 60, 8.0f), right = pixel_rect(128, 128, 64, 20, 100, 60, 8.0f);
    for (double L : {16.0, 32.0}) {
        OcclusionMaps maps(buffer, maps_config(buffer, DepthTest::masked, L));
        maps.build(buffer);
        EXPECT_EQ(maps.test_rect(left).visibility, Visibility::occluded);  // alone, each is within L
        EXPECT_EQ(maps.test_rect(right).visibility, Visibility::occluded);
        double budget = maps.hole_budget();
        EXPECT_EQ(budget, L);
        EXPECT_EQ(maps.test_rect_within(left, budget).visibility, Visibility::occluded);
        EXPECT_EQ(budget, L - 16.0);
        EXPECT_EQ(maps.test_rect_within(right, budget).visibility, L == 32.0 ? Visibility::occluded : Visibility::visible);
    }
}

// Two occluders share each pixel of a column: a wall at w = 10 behind everything, and in front
// of it, at w = 2, a panel over the left half of the column's samples. An occludee at w = 5
// over that column is visible through the right halves. The no-background Z-buffer keeps each
// pixel's nearest depth and hides it: it is not conservative. Every other depth test keeps it
// visible. The wall is drawn first (DrawOrder::as_given), so that the buffer keeps the panel as
// a working layer in front of it; drawn nearest first, the wall fills the panel's layer and it
// becomes one layer at the wall's depth, which no depth test could misread.
TEST(OcclusionMaps, NearestDepthZBufferIsNotConservativeWithPartialCoverage) {
    Occluders o{16, 16, {}, {}, {}};
    o.add(0, 0, 16, 16, 10.0f);
    o.add(0, 0, 8.5, 16, 2.0f);
    const OcclusionBuffer buffer = buffer_of(16, 16, 4, o, DrawOrder::as_given);
    const ScreenRect column = pixel_rect(16, 16, 8, 0, 9, 16, 5.0f);
    for (DepthTest depth : {DepthTest::masked, DepthTest::hzb, DepthTest::nbz, DepthTest::plane, DepthTest::deb}) {
        OcclusionMaps maps(buffer, maps_config(buffer, depth));
        maps.clear();
        maps.add_occluder_box({glm::vec3(-2.0f, -2.0f, 2.0f), glm::vec3(2.0f * (8.5f / 8.0f - 1.0f), 2.0f, 2.0f)}, kXyw);
        maps.add_occluder_box({glm::vec3(-10.0f, -10.0f, 10.0f), glm::vec3(10.0f, 10.0f, 10.0f)}, kXyw);
        maps.build(buffer);
        const OccludeeAnswer a = maps.test_rect(column);
        EXPECT_EQ(exit_of(a), OverlapExit::passed);
        EXPECT_EQ(a.visibility, depth == DepthTest::nbz ? Visibility::occluded : Visibility::visible) << "depth " << int(depth);
    }
}

// Conservative mode: the overlap test passes exactly when every sample in the rectangle is
// covered, on random triangles, rectangles and sample counts.
TEST(OcclusionMaps, ConservativeOverlapIsExactOnRandomInput) {
    std::mt19937 rng(11);
    for (int s : {1, 2, 4}) {
        const int width = 97, height = 61;
        BufferConfig c;
        c.width = width;
        c.height = height;
        c.samples = s;
        c.near_w = 0.5f;
        OcclusionBuffer buffer(c);
        const std::vector<float> tris = test::random_clip_triangles(std::uint64_t(s), 600, 0.5f);
        buffer.render(test::clip_space_input(tris));
        OcclusionMaps maps(buffer, maps_config(buffer));
        maps.build(buffer);
        std::vector<std::uint8_t> covered;
        buffer.read_coverage(covered);
        const int sw = buffer.sample_width(), sh = buffer.sample_height();
        std::uniform_int_distribution<int> x_of(0, sw - 1), y_of(0, sh - 1), size_of(0, 40);
        int passed = 0;
        for (int t = 0; t < 3000; ++t) {
            const int i0 = x_of(rng), j0 = y_of(rng), i1 = std::min(sw - 1, i0 + size_of(rng)), j1 = std::min(sh - 1, j0 + size_of(rng));
            bool all = true;
            for (int j = j0; j <= j1 && all; ++j)
                for (int i = i0; i <= i1 && all; ++i) all = covered[std::size_t(j) * std::size_t(sw) + std::size_t(i)] != 0;
            // The rectangle through the samples' centres, well inside their cells.
            const ScreenRect r = pixel_rect(sw, sh, i0 + 0.25, j0 + 0.25, i1 + 0.75, j1 + 0.75, 1000.0f);
            const OccludeeAnswer a = maps.test_rect(r);
            ASSERT_EQ(exit_of(a) == OverlapExit::passed, all) << "S " << s << " samples [" << i0 << ", " << i1 << "] x [" << j0 << ", " << j1 << "]";
            passed += all;
        }
        EXPECT_GT(passed, 100) << "too few covered rectangles to mean anything";
    }
}

// Lazy maps (conservative, masked depth) leave the pyramids out: the buffer's depth test gives
// the same visibility as the overlap-then-depth test of maps that make them, and a visible
// rectangle's level of visibility is its exact uncovered share (1 when all its samples are
// covered). build_pyramid() then gives the full maps' answers, exits and estimates included.
// On random triangles and rectangles, odd sizes, every sample count and every instruction set
// (the table's covered counts come from a kernel).
TEST(OcclusionMaps, LazyMapsAnswerAsTheFullMapsWithoutThePyramids) {
    for (const std::string& isa : available_isas())
    for (int s : {1, 2, 4}) {
        const test::ScopedIsa selected(isa);
        std::mt19937 rng(5);
        const int width = 93, height = 67;
        OcclusionBuffer buffer(test::buffer_config(width, height, s, 0.5f));
        buffer.render(test::clip_space_input(test::random_clip_triangles(std::uint64_t(s) + 20, 500, 0.5f)));
        OcclusionMaps full(buffer, maps_config(buffer));
        OcclusionMaps lazy(buffer, maps_config(buffer, DepthTest::masked, 0.0, PyramidBuild::lazy));
        full.build(buffer);
        lazy.build(buffer);
        ASSERT_TRUE(full.pyramid_built());
        ASSERT_FALSE(lazy.pyramid_built());
        EXPECT_THROW(lazy.opacity(0, 0, 0), Error);
        EXPECT_THROW(lazy.covered_samples(0), Error);
        std::vector<std::uint8_t> covered;
        buffer.read_coverage(covered);
        const int sw = buffer.sample_width(), sh = buffer.sample_height();
        // Small rectangles (to be hidden) and large ones (partly covered), in front of the
        // occluders (w 1 to 80) and behind them.
        std::uniform_int_distribution<int> x_of(0, sw - 1), y_of(0, sh - 1), size_of(0, 150), small_size_of(0, 6);
        std::uniform_real_distribution<float> w_of(0.6f, 400.0f);
        int hidden = 0, partly_covered = 0;
        std::vector<ScreenRect> rects;
        for (int t = 0; t < 3000; ++t) {
            const bool small = t % 2 == 0;
            const int i0 = x_of(rng), j0 = y_of(rng);
            const int i1 = std::min(sw - 1, i0 + (small ? small_size_of(rng) : size_of(rng)));
            const int j1 = std::min(sh - 1, j0 + (small ? small_size_of(rng) : size_of(rng)));
            int uncovered = 0;
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) uncovered += covered[std::size_t(j) * std::size_t(sw) + std::size_t(i)] == 0;
            const ScreenRect r = pixel_rect(sw, sh, i0 + 0.25, j0 + 0.25, i1 + 0.75, j1 + 0.75, w_of(rng));
            rects.push_back(r);
            const OccludeeAnswer a = lazy.test_rect(r), b = full.test_rect(r);
            const std::string what = isa + " S " + std::to_string(s) + " samples [" + std::to_string(i0) + ", " + std::to_string(i1) + "] x [" +
                                     std::to_string(j0) + ", " + std::to_string(j1) + "]";
            ASSERT_EQ(a.visibility, b.visibility) << what;
            ASSERT_EQ(exit_of(a), OverlapExit::not_run) << what;
            const double share = double(uncovered) / (double(i1 - i0 + 1) * double(j1 - j0 + 1));
            if (a.visibility == Visibility::occluded) {
                ASSERT_EQ(a.level_of_visibility, 0.0f) << what;
                ++hidden;
            } else {
                ASSERT_EQ(a.level_of_visibility, uncovered == 0 ? 1.0f : float(share)) << what;
                partly_covered += uncovered > 0 && share < 1.0;
            }
        }
        EXPECT_GT(hidden, 100) << "too few hidden rectangles to mean anything";
        EXPECT_GT(partly_covered, 100) << "too few partly covered rectangles to mean anything";
        // With its pyramids, the lazy maps are the full maps.
        lazy.build_pyramid();
        ASSERT_TRUE(lazy.pyramid_built());
        for (const ScreenRect& r : rects) {
            const OccludeeAnswer a = lazy.test_rect(r), b = full.test_rect(r);
            ASSERT_EQ(a.visibility, b.visibility);
            ASSERT_EQ(a.level_of_visibility, b.level_of_visibility);
            ASSERT_EQ(a.overlap_exit, b.overlap_exit);
        }
        for (int k = 0; k < full.levels(); ++k)
            ASSERT_TRUE(std::equal(full.covered_samples(k), full.covered_samples(k) + full.level_width(k) * full.level_height(k),
                                   lazy.covered_samples(k)));
        // The next build leaves them out again.
        lazy.build(buffer);
        EXPECT_FALSE(lazy.pyramid_built());
    }
    // Lazy means always where the overlap test can hide what the buffer alone does not
    // (approximate mode) or the depth test is not the buffer's.
    OcclusionBuffer buffer(test::buffer_config(16, 16, 2, 0.5f));
    for (auto [depth, hole] : {std::pair{DepthTest::masked, 1.0}, std::pair{DepthTest::hzb, 0.0}, std::pair{DepthTest::deb, 0.0}}) {
        OcclusionMaps maps(buffer, maps_config(buffer, depth, hole, PyramidBuild::lazy));
        maps.build(buffer);
        EXPECT_TRUE(maps.pyramid_built()) << "depth " << int(depth) << ", hole " << hole;
    }
}

TEST(OcclusionMaps, InvalidConfigurationsAreErrors) {
    const OcclusionBuffer buffer = buffer_of(32, 32, 1, Occluders{32, 32, {}, {}, {}});
    auto make = [&](auto change) {
        OcclusionMapsConfig c = maps_config(buffer);
        change(c);
        OcclusionMaps maps(buffer, c);
    };
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.display_width = 0; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.hole_pixels = -1.0; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.hole_pixels = NAN; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.distribution = 5.0; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.transparency = 1.0; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.finest_level = 40; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.coarsest_level = 40; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.deb_width = 0; }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.depth_pyramids = DepthPyramids(7); }), Error);
    EXPECT_THROW(make([](OcclusionMapsConfig& c) { c.pyramid = PyramidBuild(7); }), Error);
    EXPECT_NO_THROW(make([](OcclusionMapsConfig&) {}));
    // Tests need a built map.
    {
        OcclusionMaps unbuilt(buffer, maps_config(buffer, DepthTest::masked, 0.0, PyramidBuild::lazy));
        EXPECT_THROW(unbuilt.test_rect({-1, -1, 1, 1, 5.0f}), Error);
        EXPECT_THROW(unbuilt.build_pyramid(), Error);
        EXPECT_THROW(unbuilt.opacity(0, 0, 0), Error);
    }
    // A near plane must be finite and positive; a refused one changes nothing.
    {
        OcclusionMaps maps(buffer, maps_config(buffer));
        for (const float near_w : {0.0f, -1.0f, NAN, INFINITY}) EXPECT_THROW(maps.set_near_w(near_w), Error) << near_w;
        EXPECT_NO_THROW(maps.set_near_w(0.5f));
    }
    // A 1 x 1 buffer is a one-level pyramid.
    const OcclusionBuffer tiny = buffer_of(1, 1, 4, Occluders{1, 1, {}, {}, {}});
    OcclusionMaps maps(tiny, maps_config(tiny));
    maps.build(tiny);
    EXPECT_EQ(maps.levels(), 1);
    EXPECT_EQ(maps.test_rect({-1, -1, 1, 1, 5.0f}).visibility, Visibility::visible);
    // NaN rectangles are visible, off-screen ones view-culled.
    EXPECT_EQ(maps.test_rect({NAN, -1, 1, 1, 5.0f}).visibility, Visibility::visible);
    EXPECT_EQ(maps.test_rect({2, 2, 3, 3, 5.0f}).visibility, Visibility::view_culled);
}

}  // namespace
}  // namespace homcull
