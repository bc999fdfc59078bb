// OcclusionBuffer::test_triangles: occludee triangles tested sample by sample. Hand-built
// cases for each answer, a hole counted sample by sample, bad input, and a brute-force check on
// random triangles that the test never hides a triangle seen at a sample of the buffer.
#include "buffer/buffer_kernels.hpp"
#include "buffer/occludee_depth.hpp"
#include "buffer/occludee_rectangles.hpp"
#include "common/isa_choice.hpp"
#include "raster/triangle_batch.hpp"
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/isa.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <utility>

namespace homcull {
namespace {

// Triangles given by NDC corners and one w each: positions (x w, y w, w) under a matrix that
// maps (x, y, z) to clip (x, y, 0, z).
struct Soup {
    std::vector<float> xyw;
    void add(float x0, float y0, float w0, float x1, float y1, float w1, float x2, float y2, float w2) {
        xyw.insert(xyw.end(), {x0 * w0, y0 * w0, w0, x1 * w1, y1 * w1, w1, x2 * w2, y2 * w2, w2});
    }
    void add_flat(float x0, float y0, float x1, float y1, float x2, float y2, float w) { add(x0, y0, w, x1, y1, w, x2, y2, w); }
    // An axis-aligned NDC rectangle at depth w, as two triangles.
    void add_rect(float x0, float y0, float x1, float y1, float w) {
        add_flat(x0, y0, x1, y0, x1, y1, w);
        add_flat(x0, y0, x1, y1, x0, y1, w);
    }
    TriangleInput input() const {
        TriangleInput in;
        in.positions = xyw.data();
        in.vertex_count = xyw.size() / 3;
        in.triangle_count = xyw.size() / 9;
        in.model_to_clip[0] = 1;
        in.model_to_clip[5] = 1;
        in.model_to_clip[11] = 1;
        in.backface = Backface::none;
        return in;
    }
};

// Model-space triangles (xyz, 9 floats each) under clip_from_model, rounded to float as an
// engine gives it; no backface culling.
TriangleInput model_space_input(const std::vector<float>& xyz, const glm::dmat4& clip_from_model) {
    TriangleInput in;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) in.model_to_clip[std::size_t(4 * c + r)] = float(clip_from_model[c][r]);
    in.positions = xyz.data();
    in.vertex_count = xyz.size() / 3;
    in.triangle_count = in.vertex_count / 3;
    in.backface = Backface::none;
    return in;
}

OcclusionBuffer make_buffer(int w, int h, int s = 1, bool sample_depth = false) {
    return OcclusionBuffer(test::buffer_config(w, h, s, 0.5f, sample_depth));
}

OcclusionBuffer wall_at(float w) {
    OcclusionBuffer buffer = make_buffer(64, 36);
    Soup wall;
    wall.add_rect(-1.5f, -1.5f, 1.5f, 1.5f, w);
    buffer.render(wall.input());
    return buffer;
}

Visibility answer(const OcclusionBuffer& buffer, const Soup& occludee, std::uint64_t tolerated = 0) {
    return buffer.test_triangles(occludee.input(), tolerated).visibility;
}

TEST(OccludeeTriangles, EachAnswerOnAWall) {
    const OcclusionBuffer buffer = wall_at(10.0f);
    Soup behind, in_front, crossing, before_near, outside, partly_outside, touching;
    behind.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 20.0f);
    in_front.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 5.0f);
    crossing.add(-0.5f, -0.5f, 20.0f, 0.5f, -0.5f, 20.0f, 0.0f, 0.5f, 5.0f);  // pierces the wall
    before_near.add(-0.5f, -0.5f, 20.0f, 0.5f, -0.5f, 20.0f, 0.0f, 0.5f, 0.3f);
    outside.add_flat(1.2f, -0.5f, 1.5f, -0.5f, 1.3f, 0.5f, 20.0f);
    partly_outside.add_flat(0.9f, -0.5f, 1.5f, -0.5f, 1.3f, 0.5f, 20.0f);
    touching.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 10.0f);  // on the wall: not hidden
    EXPECT_EQ(answer(buffer, behind), Visibility::occluded);
    EXPECT_EQ(answer(buffer, in_front), Visibility::visible);
    EXPECT_EQ(answer(buffer, crossing), Visibility::visible);
    EXPECT_EQ(answer(buffer, before_near), Visibility::visible);
    EXPECT_EQ(answer(buffer, outside), Visibility::view_culled);
    EXPECT_EQ(answer(buffer, partly_outside), Visibility::occluded);
    EXPECT_EQ(answer(buffer, touching), Visibility::visible);

    // A triangle crossing the wall beyond the right edge of the display: 1/w is affine on
    // screen, so at the edge (x = 1) its w is 1 / (0.05 + (0.8 / 2.8) 0.15) = 10.8, behind the
    // wall. With its third corner at w = 2 it is 5.6 there, in front.
    Soup crossing_off_screen, crossing_on_screen;
    crossing_off_screen.add(0.2f, -0.5f, 20.0f, 0.2f, 0.5f, 20.0f, 3.0f, 0.0f, 5.0f);
    crossing_on_screen.add(0.2f, -0.5f, 20.0f, 0.2f, 0.5f, 20.0f, 3.0f, 0.0f, 2.0f);
    EXPECT_EQ(answer(buffer, crossing_off_screen), Visibility::occluded);
    EXPECT_EQ(answer(buffer, crossing_on_screen), Visibility::visible);

    // Crossing the near plane (ground truth sees from it on): a floor under the eye whose part
    // on screen lies behind the wall is hidden; raised into view, it is not. Its corner at
    // w = 0.2 has NDC y = -200 (clip y = -40): the edge to (-5, -5, 20) enters the screen at
    // w = 14.6; with NDC y = -50 (clip y = -10) at w = 8.0, before the wall.
    Soup floor_hidden, floor_seen;
    floor_hidden.add(0.0f, -200.0f, 0.2f, -0.25f, -0.25f, 20.0f, 0.25f, -0.25f, 20.0f);
    floor_seen.add(0.0f, -50.0f, 0.2f, -0.25f, -0.25f, 20.0f, 0.25f, -0.25f, 20.0f);
    EXPECT_EQ(answer(buffer, floor_hidden), Visibility::occluded);
    EXPECT_EQ(answer(buffer, floor_seen), Visibility::visible);

    // Behind the eye entirely: nothing of it can be seen.
    Soup behind_eye;
    behind_eye.xyw = {0.0f, 0.0f, -1.0f, 1.0f, 0.0f, -2.0f, 0.0f, 1.0f, -1.0f};
    EXPECT_EQ(answer(buffer, behind_eye), Visibility::view_culled);

    // One visible triangle among hidden ones.
    Soup mixed = behind;
    mixed.add_flat(-0.2f, -0.2f, 0.2f, -0.2f, 0.0f, 0.2f, 5.0f);
    EXPECT_EQ(answer(buffer, mixed), Visibility::visible);
}

TEST(OccludeeTriangles, NothingIsHiddenWithoutOccluders) {
    OcclusionBuffer buffer = make_buffer(37, 23, 2);
    Soup occludee;
    occludee.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 20.0f);
    const OcclusionBuffer::TriangleTest r = buffer.test_triangles(occludee.input(), std::numeric_limits<std::uint64_t>::max());
    EXPECT_EQ(r.visibility, Visibility::occluded);  // everything tolerated
    EXPECT_GT(r.samples, 0u);
    EXPECT_EQ(r.samples, r.visible_samples);
    EXPECT_EQ(answer(buffer, occludee), Visibility::visible);
}

// A wall at w = 10 with a square hole of 4 x 4 pixels; the occludee behind it is seen through
// the hole's 16 samples (plus the samples its outer margin reaches around the hole's edge).
TEST(OccludeeTriangles, ToleratedSamplesCountAHole) {
    OcclusionBuffer buffer = make_buffer(64, 64);
    const float px = 2.0f / 64.0f;  // one pixel in NDC
    const float h0 = -2.0f * px, h1 = 2.0f * px;
    Soup wall;
    wall.add_rect(-1.5f, -1.5f, 1.5f, h0, 10.0f);
    wall.add_rect(-1.5f, h1, 1.5f, 1.5f, 10.0f);
    wall.add_rect(-1.5f, h0, h0, h1, 10.0f);
    wall.add_rect(h1, h0, 1.5f, h1, 10.0f);
    buffer.render(wall.input());
    Soup occludee;
    occludee.add_rect(-0.5f, -0.5f, 0.5f, 0.5f, 20.0f);
    const auto full = buffer.test_triangles(occludee.input(), std::numeric_limits<std::uint64_t>::max());
    // The hole's samples lie in both triangles' outer coverage along the diagonal only: at
    // least 16, at most 16 plus the diagonal's 4 counted twice; the wall's edges fall between
    // samples, so no sample around the hole is counted.
    EXPECT_GE(full.visible_samples, 16u);
    EXPECT_LE(full.visible_samples, 20u);
    EXPECT_EQ(buffer.test_triangles(occludee.input(), full.visible_samples).visibility, Visibility::occluded);
    EXPECT_EQ(buffer.test_triangles(occludee.input(), full.visible_samples - 1).visibility, Visibility::visible);

    // A small occludee seen only through the hole.
    Soup small;
    small.add_rect(-px, -px, px, px, 20.0f);
    EXPECT_EQ(answer(buffer, small), Visibility::visible);
    Soup beside;  // the same, behind the wall beside the hole
    beside.add_rect(10 * px, 10 * px, 12 * px, 12 * px, 20.0f);
    EXPECT_EQ(answer(buffer, beside), Visibility::occluded);
}

TEST(OccludeeTriangles, BadInputIsVisibleOrRejected) {
    const OcclusionBuffer buffer = wall_at(10.0f);
    Soup nan_vertex;
    nan_vertex.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 20.0f);
    nan_vertex.xyw[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(answer(buffer, nan_vertex), Visibility::visible);
    Soup inf_vertex = nan_vertex;
    inf_vertex.xyw[4] = std::numeric_limits<float>::infinity();
    EXPECT_EQ(answer(buffer, inf_vertex), Visibility::visible);

    Soup hidden;
    hidden.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 20.0f);
    TriangleInput in = hidden.input();
    const std::uint32_t bad_indices[3] = {0, 1, 3};
    in.indices = bad_indices;
    EXPECT_EQ(buffer.test_triangles(in).visibility, Visibility::visible);
    const std::uint16_t good16[3] = {0, 1, 2};
    in.indices = good16;
    in.indices_16bit = true;
    EXPECT_EQ(buffer.test_triangles(in).visibility, Visibility::occluded);

    // All three corners on one line (in double): the exact triangle may still be a sliver that
    // its rounding made collinear, through sample centres, so it is tested as its padded
    // bounding box: seen in front of the wall, hidden behind it.
    Soup degenerate;
    degenerate.add_flat(-0.5f, -0.5f, 0.0f, 0.0f, 0.5f, 0.5f, 5.0f);
    EXPECT_EQ(answer(buffer, degenerate), Visibility::visible);
    Soup degenerate_behind;
    degenerate_behind.add_flat(-0.5f, -0.5f, 0.0f, 0.0f, 0.5f, 0.5f, 20.0f);
    EXPECT_EQ(answer(buffer, degenerate_behind), Visibility::occluded);

    Soup huge;  // far beyond the guard band, behind the wall
    huge.add_flat(-1e6f, -1e6f, 1e6f, -1e6f, 0.0f, 1e6f, 20.0f);
    EXPECT_EQ(answer(buffer, huge), Visibility::occluded);

    TriangleInput empty = hidden.input();
    empty.triangle_count = 0;
    EXPECT_EQ(buffer.test_triangles(empty).visibility, Visibility::view_culled);
    TriangleInput no_positions = hidden.input();
    no_positions.positions = nullptr;
    EXPECT_THROW(buffer.test_triangles(no_positions), Error);
    TriangleInput short_stride = hidden.input();
    short_stride.position_stride = 8;
    EXPECT_THROW(buffer.test_triangles(short_stride), Error);
    TriangleInput too_few = hidden.input();
    too_few.triangle_count = 2;
    EXPECT_THROW(buffer.test_triangles(too_few), Error);
}

// A non-finite coordinate in a batch of hidden triangles makes the occludee visible on every
// instruction set, whichever triangle, vertex and coordinate holds it: for a clip-space input
// (the identity matrix) and for a model-space one. The batch's rectangles are made in SIMD
// lanes, where the Max and Min of a NaN give either operand depending on the instruction set.
TEST(OccludeeTriangles, ANonFiniteCoordinateInABatchIsVisibleOnEveryIsa) {
    const float bad_values[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                                -std::numeric_limits<float>::infinity()};
    Soup hidden;  // 17 triangles behind the wall: the first alone, then a batch of 16
    for (int t = 0; t < 17; ++t) hidden.add_flat(-0.5f + 0.05f * t, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 20.0f);
    std::vector<float> clip_xyzw;  // the same triangles as clip-space positions
    for (std::size_t v = 0; v < hidden.xyw.size(); v += 3)
        clip_xyzw.insert(clip_xyzw.end(), {hidden.xyw[v], hidden.xyw[v + 1], 0.0f, hidden.xyw[v + 2]});
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        const OcclusionBuffer buffer = wall_at(10.0f);
        ASSERT_EQ(answer(buffer, hidden), Visibility::occluded) << isa;
        for (const int t : {1, 6, 16})
            for (int k = 0; k < 3; ++k)
                for (const float bad : bad_values) {
                    for (int c = 0; c < 4; ++c) {  // clip space: x, y, z, w
                        std::vector<float> positions = clip_xyzw;
                        positions[std::size_t(12 * t + 4 * k + c)] = bad;
                        EXPECT_EQ(buffer.test_triangles(test::clip_space_input(positions)).visibility, Visibility::visible)
                            << isa << ", clip space, triangle " << t << ", vertex " << k << ", coordinate " << c << ", " << bad;
                    }
                    for (int c = 0; c < 3; ++c) {  // model space
                        Soup occludee = hidden;
                        occludee.xyw[std::size_t(9 * t + 3 * k + c)] = bad;
                        EXPECT_EQ(answer(buffer, occludee), Visibility::visible)
                            << isa << ", model space, triangle " << t << ", vertex " << k << ", coordinate " << c << ", " << bad;
                    }
                }
    }
}

// Where the transform's rounding bound of w reaches the near plane (error.w >= near_w (1 - 2^-20)), the
// test cannot place that plane and answers visible: on every instruction set, also for the
// triangles of a batch hidden behind a wall by their rectangles. Under the soup's matrix
// error.w is 2^-22 w: about 0.95 at w = 4e6, above the near plane's 0.5.
TEST(OccludeeTriangles, ATriangleTooFarToPlaceTheNearPlaneIsVisibleOnEveryIsa) {
    Soup far;
    far.add_flat(-0.5f, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 20.0f);  // the first, alone: hidden
    for (int t = 0; t < 16; ++t) far.add_flat(-0.5f + 0.05f * t, -0.5f, 0.5f, -0.5f, 0.0f, 0.5f, 4e6f);
    Soup near_enough = far;  // at w = 1e6 (error.w about 0.24): hidden
    for (std::size_t v = 9; v < near_enough.xyw.size(); ++v) near_enough.xyw[v] *= 0.25f;
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        const OcclusionBuffer buffer = wall_at(10.0f);
        EXPECT_EQ(answer(buffer, far), Visibility::visible) << isa;
        EXPECT_EQ(answer(buffer, near_enough), Visibility::occluded) << isa;
    }
}

// A closed solid's triangles seen from behind, passed over in a batch on their rectangles, leave
// the occludee out of the view as shows() does. Under ClosedSolid's precondition (the occludee
// beyond the near plane) a solid with back faces in the view has front faces there too, so the
// difference shows only outside it: a box whose only face towards the eye lies before the near
// plane, from depth 0.3 to 20, four times as wide as the view at depth 10 is (x, y in [-5, 5],
// the side planes at x = +-w/2). Its side faces, seen from behind, reach the view beyond depth
// 10, where a wall at depth 8 hides them. Without the solid the answer is occluded; with it
// the reference's view_culled (no front face in the view), on every instruction set.
TEST(OccludeeTriangles, AClosedSolidsHiddenBackFacesAreNotInTheViewOnEveryIsa) {
    std::vector<float> xyz;
    const auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {  // counter-clockwise seen from outside
        for (const glm::vec3& p : {a, b, c, a, c, d}) xyz.insert(xyz.end(), {p.x, p.y, p.z});
    };
    constexpr float kHalf = 5.0f, kFront = -0.3f, kBack = -20.0f;
    quad({-kHalf, -kHalf, kFront}, {kHalf, -kHalf, kFront}, {kHalf, kHalf, kFront}, {-kHalf, kHalf, kFront});  // the face towards the eye
    quad({-kHalf, -kHalf, kBack}, {-kHalf, kHalf, kBack}, {kHalf, kHalf, kBack}, {kHalf, -kHalf, kBack});
    const float slices[] = {kFront, -1, -2, -3, -4, -5, -6, -7, -8, -9, -10, -11, -12, -13, -14, -15, -16, -17, -18, -19, kBack};
    for (std::size_t i = 0; i + 1 < std::size(slices); ++i) {
        const float z0 = slices[i], z1 = slices[i + 1];  // z1 farther
        quad({kHalf, -kHalf, z0}, {kHalf, -kHalf, z1}, {kHalf, kHalf, z1}, {kHalf, kHalf, z0});      // +x
        quad({-kHalf, -kHalf, z0}, {-kHalf, kHalf, z0}, {-kHalf, kHalf, z1}, {-kHalf, -kHalf, z1});  // -x
        quad({-kHalf, kHalf, z0}, {kHalf, kHalf, z0}, {kHalf, kHalf, z1}, {-kHalf, kHalf, z1});      // +y
        quad({-kHalf, -kHalf, z0}, {-kHalf, -kHalf, z1}, {kHalf, -kHalf, z1}, {kHalf, -kHalf, z0});  // -y
    }
    const TriangleInput in = model_space_input(xyz, glm::perspective(2.0 * std::atan(0.5), 1.0, 0.5, 100.0));
    const OcclusionBuffer::ClosedSolid outside{{0.0, 0.0, 0.0}, 1};
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        const OcclusionBuffer buffer = wall_at(8.0f);  // (a 64 x 36 buffer: samples off its diagonal)
        EXPECT_EQ(buffer.test_triangles(in).visibility, Visibility::occluded) << isa;
        EXPECT_EQ(buffer.test_triangles(in, 0, 0, outside).visibility, Visibility::view_culled) << isa;
        EXPECT_EQ(buffer.test_triangles(in, 0, 5, outside).visibility, Visibility::view_culled) << isa << ", from triangle 5";
        const OcclusionBuffer empty = make_buffer(64, 36);  // nothing hides the back faces: seen without the solid
        EXPECT_EQ(empty.test_triangles(in).visibility, Visibility::visible) << isa;
        EXPECT_EQ(empty.test_triangles(in, 0, 0, outside).visibility, Visibility::view_culled) << isa;
    }
}

long double edge(long double ax, long double ay, long double bx, long double by, long double px, long double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// The barycentric coordinates of (px, py) in the screen triangle (sx, sy), twice whose signed
// area is `area`.
void barycentrics(const long double sx[3], const long double sy[3], long double area, long double px, long double py, long double& l0,
                  long double& l1, long double& l2) {
    l0 = edge(sx[1], sy[1], sx[2], sy[2], px, py) / area;
    l1 = edge(sx[2], sy[2], sx[0], sy[0], px, py) / area;
    l2 = 1 - l0 - l1;
}

// An occludee given as one triangle of a Soup, on a sample grid of sw x sh: its corners in
// samples and their w, in long double from the floats given, and its w at a sample's centre.
struct ScreenOccludee {
    long double sx[3], sy[3], w[3], area;
    ScreenOccludee(const Soup& occludee, int sw, int sh) {
        const std::vector<float>& v = occludee.xyw;
        for (int k = 0; k < 3; ++k) {
            w[k] = v[std::size_t(3 * k + 2)];
            sx[k] = ((long double)v[std::size_t(3 * k)] / w[k] + 1) * 0.5L * sw;
            sy[k] = (1 - (long double)v[std::size_t(3 * k + 1)] / w[k]) * 0.5L * sh;
        }
        area = edge(sx[0], sy[0], sx[1], sy[1], sx[2], sy[2]);
    }
    // Whether sample (i, j)'s centre lies inside (area != 0), and the occludee's w there.
    bool w_at(int i, int j, long double& occludee_w) const {
        long double l0, l1, l2;
        barycentrics(sx, sy, area, i + 0.5L, j + 0.5L, l0, l1, l2);
        if (l0 < 0 || l1 < 0 || l2 < 0) return false;
        occludee_w = 1 / (l0 / w[0] + l1 / w[1] + l2 / w[2]);
        return true;
    }
};

// Random occluders and random occludee triangles: whenever the occludee is at or in front of
// the buffer's conservative depth at a sample centre inside it (exact, in long double, from the
// floats given), test_triangles must not hide it. And it should hide most of those the buffer
// hides with some room to spare.
TEST(OccludeeTriangles, NeverHidesATriangleSeenAtASample) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> pos(-1.3f, 1.3f), size(0.02f, 0.4f), far_depth(2.0f, 40.0f);
    int hidden_by_buffer = 0, hidden_by_test = 0, trials = 0;
    for (const auto& [samples, sample_depth] : {std::pair{1, false}, {2, false}, {4, false}, {1, true}, {2, true}}) {
        OcclusionBuffer buffer = make_buffer(37, 23, samples, sample_depth);  // odd sizes: partial subtiles
        const int sw = buffer.sample_width(), sh = buffer.sample_height();
        for (int scene = 0; scene < 20; ++scene) {
            buffer.clear();
            Soup occluders;
            for (int k = 0; k < 6; ++k)
                occluders.add(pos(rng) * 2, pos(rng) * 2, far_depth(rng), pos(rng) * 2, pos(rng) * 2, far_depth(rng), pos(rng) * 2,
                              pos(rng) * 2, far_depth(rng));
            buffer.render(occluders.input());
            std::vector<float> bound_w;
            buffer.read_depth(bound_w);
            for (int t = 0; t < 60; ++t) {
                const float cx = pos(rng), cy = pos(rng), r = size(rng);
                Soup occludee;
                occludee.add(cx + r * (pos(rng) / 1.3f), cy + r * (pos(rng) / 1.3f), far_depth(rng) + 10.0f, cx + r * (pos(rng) / 1.3f),
                             cy + r * (pos(rng) / 1.3f), far_depth(rng) + 10.0f, cx + r * (pos(rng) / 1.3f), cy + r * (pos(rng) / 1.3f),
                             far_depth(rng) + 10.0f);
                const ScreenOccludee o(occludee, sw, sh);
                const long double* sx = o.sx;
                const long double* sy = o.sy;
                if (o.area == 0) continue;
                // Room: within a sample of its bounding box, every sample has an occluder 1 %
                // nearer than the triangle's nearest vertex.
                const long double nearest_w = std::min({o.w[0], o.w[1], o.w[2]});
                const long double box_x0 = std::min({sx[0], sx[1], sx[2]}) - 1, box_x1 = std::max({sx[0], sx[1], sx[2]}) + 1;
                const long double box_y0 = std::min({sy[0], sy[1], sy[2]}) - 1, box_y1 = std::max({sy[0], sy[1], sy[2]}) + 1;
                bool seen = false, hidden_with_room = true, any_sample = false;
                for (int j = 0; j < sh; ++j)
                    for (int i = 0; i < sw; ++i) {
                        const long double px = i + 0.5L, py = j + 0.5L;
                        const long double occluder_w = bound_w[std::size_t(j) * std::size_t(sw) + std::size_t(i)];
                        if (px >= box_x0 && px <= box_x1 && py >= box_y0 && py <= box_y1)
                            hidden_with_room = hidden_with_room && occluder_w * 1.01L < nearest_w;
                        long double occludee_w;
                        if (!o.w_at(i, j, occludee_w)) continue;
                        any_sample = true;
                        seen = seen || !(occluder_w < occludee_w);
                    }
                const Visibility v_test = buffer.test_triangles(occludee.input()).visibility;
                if (seen) {
                    ASSERT_EQ(v_test, Visibility::visible) << "hid a triangle seen at a sample (S = " << samples << ", per-sample depth "
                                                           << sample_depth << ")";
                }
                if (any_sample && hidden_with_room) {
                    ++hidden_by_buffer;
                    hidden_by_test += v_test == Visibility::occluded;
                }
                ++trials;
            }
        }
    }
    std::printf("occludee triangles: %d trials, %d hidden with room by the buffer, %d of them hidden by the test\n", trials,
                hidden_by_buffer, hidden_by_test);
    ASSERT_GT(hidden_by_buffer, 50);
    EXPECT_EQ(hidden_by_test, hidden_by_buffer);
}

// Large occludee triangles reaching far beyond a side of the view, whose part in it spans fewer
// rows than their box (the occludee tests then pass over the rest: rows_reaching_columns), among
// random occluders: whenever one is seen at a sample, test_triangles answers visible.
TEST(OccludeeTriangles, NeverHidesALargeTriangleReachingBeyondTheView) {
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<float> pos(-1.3f, 1.3f), far_pos(-8.0f, 8.0f), beyond(1.5f, 9.0f), depth(2.0f, 40.0f);
    int seen_count = 0, trials = 0;
    for (bool sample_depth : {false, true}) {
        OcclusionBuffer buffer = make_buffer(61, 47, 1, sample_depth);
        const int sw = buffer.sample_width(), sh = buffer.sample_height();
        for (int scene = 0; scene < 20; ++scene) {
            buffer.clear();
            Soup occluders;
            for (int k = 0; k < 6; ++k)
                occluders.add(pos(rng) * 2, pos(rng) * 2, depth(rng), pos(rng) * 2, pos(rng) * 2, depth(rng), pos(rng) * 2, pos(rng) * 2,
                              depth(rng));
            buffer.render(occluders.input());
            std::vector<float> bound_w;
            buffer.read_depth(bound_w);
            for (int t = 0; t < 60; ++t) {
                // Two corners beyond the left or the right side, one in the view.
                const float side = (rng() & 1u) ? 1.0f : -1.0f;
                Soup occludee;
                occludee.add(side * beyond(rng), far_pos(rng), depth(rng) + 10.0f, side * beyond(rng), far_pos(rng), depth(rng) + 10.0f,
                             pos(rng), pos(rng), depth(rng) + 10.0f);
                const ScreenOccludee o(occludee, sw, sh);
                if (o.area == 0) continue;
                bool seen = false;
                for (int j = 0; j < sh && !seen; ++j)
                    for (int i = 0; i < sw && !seen; ++i) {
                        long double occludee_w;
                        seen = o.w_at(i, j, occludee_w) && !(bound_w[std::size_t(j) * std::size_t(sw) + std::size_t(i)] < occludee_w);
                    }
                ++trials;
                if (!seen) continue;
                ++seen_count;
                ASSERT_EQ(buffer.test_triangles(occludee.input()).visibility, Visibility::visible)
                    << "hid a triangle seen at a sample (per-sample depth " << sample_depth << ", scene " << scene << ", trial " << t << ")";
            }
        }
    }
    std::printf("large occludee triangles: %d trials, %d seen somewhere\n", trials, seen_count);
    EXPECT_GT(seen_count, 200);
}

// Every instruction set gives the scalar reference's answers and counts: the row intervals of
// occludee triangles come from the row loop's SIMD kernel (tall triangles span several of its
// chunks of 64 sample rows), the rest is shared code. Occluders near and far, occludees
// behind, in front, straddling and beyond the near plane, some taller than the buffer; per-sample
// depth on and off; tolerated samples 0 and 7.
// Random occludees of 1 to 55 triangles (past the first 16 they go in batches, whose lanes
// beyond a side plane are passed over in SIMD lanes), some with a bad vertex in a batch, and 16
// occluders nearer on the whole: occludees behind, in front, straddling and beyond the near
// plane, some taller than the buffer.
struct RandomOccludees {
    std::vector<Soup> occludees;
    Soup occluders;
};

RandomOccludees random_occludees(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> pos(-1.4f, 1.4f), size(0.01f, 1.5f), depth(0.3f, 40.0f), tilt(0.8f, 1.25f);
    RandomOccludees r;
    for (int k = 0; k < 150; ++k) {
        Soup o;
        const float cx = pos(rng), cy = pos(rng), extent = size(rng), w = depth(rng);
        for (int t = 0; t < 1 + (k % 7) * 9; ++t)
            o.add(cx + extent * pos(rng), cy + extent * pos(rng), w * tilt(rng), cx + extent * pos(rng), cy + extent * pos(rng),
                  w * tilt(rng), cx + extent * pos(rng), cy + extent * pos(rng), w * tilt(rng));
        if (k % 13 == 12 && o.xyw.size() > 9 * 20) o.xyw[o.xyw.size() - 9 * std::size_t(k % 3 + 1)] = k % 2 ? NAN : INFINITY;  // a bad vertex in a batch
        r.occludees.push_back(o);
    }
    for (int k = 0; k < 16; ++k) {
        const float cx = pos(rng), cy = pos(rng), extent = size(rng), w = depth(rng) * 0.5f;
        r.occluders.add(cx - extent, cy - extent, w, cx + extent, cy - extent * 0.5f, w * tilt(rng), cx, cy + extent, w * tilt(rng));
    }
    return r;
}

TEST(OccludeeTriangles, EveryIsaGivesTheReferenceAnswersAndCounts) {
    const RandomOccludees random = random_occludees(11);
    const std::vector<Soup>& occludees = random.occludees;
    const Soup& occluders = random.occluders;
    // Triangles beyond the right plane, taken one at a time and then in batches, all passed
    // over; but one of them (in a batch) with an infinite or NaN coordinate makes the occludee
    // visible, as it does one triangle at a time: the pass-over needs finite vertices. Under
    // clip = (x, y, 0, z - x) an infinite model x gives clip x = +inf, w = -inf: beyond the
    // right plane by the comparisons alone.
    for (int bad = -1; bad < 3; ++bad) {
        std::vector<float> xyz;
        for (int t = 0; t < 30; ++t) xyz.insert(xyz.end(), {12.0f, 0.0f, 20.0f, 16.0f, 0.8f, 24.0f, 13.6f, -1.6f, 21.6f});
        if (bad >= 0) xyz[9 * 20 + 3 + std::size_t(bad)] = bad == 1 ? NAN : INFINITY;  // x, y or z of triangle 20's vertex 1
        TriangleInput in;
        in.positions = xyz.data();
        in.vertex_count = xyz.size() / 3;
        in.triangle_count = xyz.size() / 9;
        in.model_to_clip = {1, 0, 0, -1, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0};
        in.backface = Backface::none;
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            const OcclusionBuffer empty = make_buffer(64, 36);
            EXPECT_EQ(empty.test_triangles(in).visibility, bad < 0 ? Visibility::view_culled : Visibility::visible)
                << isa << ", bad coordinate " << bad;
        }
    }
    for (const auto& [samples, sample_depth] : {std::pair{1, false}, {4, false}, {1, true}}) {
        std::vector<OcclusionBuffer::TriangleTest> reference;
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            OcclusionBuffer buffer = make_buffer(149, 301, samples, sample_depth);  // more rows than a chunk of the row loop
            buffer.render(occluders.input());
            std::vector<OcclusionBuffer::TriangleTest> answers;
            for (const Soup& o : occludees)
                for (std::uint64_t tolerated : {0u, 7u}) answers.push_back(buffer.test_triangles(o.input(), tolerated));
            if (isa == "scalar") {
                reference = answers;
                int occluded = 0, visible = 0;
                for (const auto& a : answers) occluded += a.visibility == Visibility::occluded, visible += a.visibility == Visibility::visible;
                EXPECT_GT(occluded, 20) << "S " << samples;  // both answers are compared
                EXPECT_GT(visible, 20) << "S " << samples;
                continue;
            }
            ASSERT_EQ(answers.size(), reference.size());
            for (std::size_t k = 0; k < answers.size(); ++k) {
                SCOPED_TRACE(isa + ", S " + std::to_string(samples) + ", sample depth " + std::to_string(sample_depth) + ", occludee " +
                             std::to_string(k / 2));
                ASSERT_EQ(answers[k].visibility, reference[k].visibility);
                ASSERT_EQ(answers[k].samples, reference[k].samples);
                ASSERT_EQ(answers[k].visible_samples, reference[k].visible_samples);
                ASSERT_EQ(answers[k].deciding_triangle, reference[k].deciding_triangle);
            }
        }
    }
}

// With no tolerance, a triangle whose bounding rectangle of samples is hidden at its nearest
// depth is passed over without its samples counted. The answer must be the one every sample
// gives: occluded exactly when, counting every sample (a tolerance of all of them), none is
// visible. Checked on every instruction set, with and without the per-sample depth (which hides
// samples the rectangle's layer test cannot), for occludees of one triangle and of many.
TEST(OccludeeTriangles, PassingOverHiddenRectanglesKeepsEveryAnswer) {
    RandomOccludees random = random_occludees(29);
    // The occluders made flat (each at its corners' mean w), and occludees where a depth
    // rounding decides: each occluder shrunk about its centre and moved back by a little, from
    // nothing to a tenth.
    std::vector<float>& o = random.occluders.xyw;
    for (std::size_t t = 0; t + 9 <= o.size(); t += 9) {
        float x[3], y[3], w = 0.0f, cx = 0.0f, cy = 0.0f;
        for (int k = 0; k < 3; ++k) {
            const float wk = o[t + std::size_t(3 * k + 2)];
            x[k] = o[t + std::size_t(3 * k)] / wk, y[k] = o[t + std::size_t(3 * k + 1)] / wk;
            w += wk / 3.0f, cx += x[k] / 3.0f, cy += y[k] / 3.0f;
        }
        for (int k = 0; k < 3; ++k)
            o[t + std::size_t(3 * k)] = x[k] * w, o[t + std::size_t(3 * k + 1)] = y[k] * w, o[t + std::size_t(3 * k + 2)] = w;
        for (const float back : {1.0f, 1.0f + 0x1.0p-20f, 1.0f + 0x1.0p-16f, 1.0f + 0x1.0p-12f, 1.001f, 1.01f, 1.1f})
            for (const float shrink : {0.5f, 0.9f}) {
                Soup near_miss;
                near_miss.add_flat(cx + (x[0] - cx) * shrink, cy + (y[0] - cy) * shrink, cx + (x[1] - cx) * shrink, cy + (y[1] - cy) * shrink,
                                   cx + (x[2] - cx) * shrink, cy + (y[2] - cy) * shrink, w * back);
                random.occludees.push_back(near_miss);
            }
    }
    for (const std::string& isa : available_isas())
        for (const auto& [samples, sample_depth] : {std::pair{1, false}, {2, false}, {1, true}}) {
            SCOPED_TRACE(isa + ", S " + std::to_string(samples) + ", sample depth " + std::to_string(sample_depth));
            const test::ScopedIsa selected(isa);
            OcclusionBuffer buffer = make_buffer(149, 301, samples, sample_depth);
            buffer.render(random.occluders.input());
            int fewer_counted = 0, occluded = 0, visible = 0;
            for (std::size_t k = 0; k < random.occludees.size(); ++k) {
                const TriangleInput in = random.occludees[k].input();
                const OcclusionBuffer::TriangleTest quick = buffer.test_triangles(in), every = buffer.test_triangles(in, ~std::uint64_t(0));
                Visibility expected = every.visibility;
                if (expected == Visibility::occluded && every.visible_samples > 0) expected = Visibility::visible;
                ASSERT_EQ(quick.visibility, expected) << "occludee " << k;
                if (quick.visibility == Visibility::occluded) {
                    EXPECT_LE(quick.samples, every.samples) << "occludee " << k;
                    fewer_counted += quick.samples < every.samples;
                }
                occluded += quick.visibility == Visibility::occluded, visible += quick.visibility == Visibility::visible;
            }
            EXPECT_GT(fewer_counted, 10);  // the pass-over ran
            EXPECT_GT(occluded, 20);
            EXPECT_GT(visible, 20);
        }
}

// The batch kernel's rectangles against the one-triangle rectangle
// (occludee_bounding_rectangle), on triangles of a perspective view near and far, tiny and
// huge, crossing the near plane and the guard band, far from the origin, some with a NaN: every
// lane the kernel takes is one the one-triangle test sets up without clipping, and its
// rectangle holds that one's samples at a depth no farther.
TEST(OccludeeTriangles, BatchRectanglesHoldTheOneTriangleRectangles) {
    std::mt19937_64 random(23);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), exponent(-3.0, 3.0);
    constexpr int kWidth = 317, kHeight = 181;
    constexpr double kNear = 0.5, kMargin = 1.0 / 1024.0;
    std::size_t taken = 0, unclipped = 0, compared = 0;
    for (const std::string& name : available_isas()) {
        const detail::IsaChoice* choice = detail::find_isa_choice(name.c_str());
        ASSERT_NE(choice, nullptr) << name;
        const detail::BufferKernels& kernels = detail::buffer_kernels(*choice);
        if (!kernels.occludee_rectangles) continue;  // the scalar choice
        for (int trial = 0; trial < 400; ++trial) {
            // Far from the origin; and farther, where the rounding bound of w reaches the near plane
            // (the one-triangle test answers visible: no lane may be taken).
            const glm::dvec3 offset = trial % 8 == 7   ? glm::dvec3(3e6, -2e6, 5e6)
                                      : trial % 4 == 3 ? glm::dvec3(3e4, -2e4, 5e4)
                                                       : glm::dvec3(0.0);
            const glm::dmat4 clip_from_world = glm::perspective(glm::radians(50.0), double(kWidth) / kHeight, kNear, 1e4) *
                                               glm::lookAt(offset, offset + glm::dvec3(unit(random), unit(random), -1.0), glm::dvec3(0, 1, 0));
            std::vector<float> xyz;
            for (int t = 0; t < detail::TriangleBatch::kSize; ++t) {
                const double distance = std::pow(10.0, exponent(random) * 0.8 + 0.5), size = std::pow(10.0, exponent(random));
                const glm::dvec3 centre = offset + glm::dvec3(unit(random) * distance, unit(random) * distance, -distance + unit(random) * 2.0);
                for (int k = 0; k < 3; ++k)
                    for (int i = 0; i < 3; ++i) xyz.push_back(float(centre[i] + unit(random) * size));
            }
            if (trial % 9 == 4) xyz[std::size_t(random() % xyz.size())] = std::numeric_limits<float>::quiet_NaN();
            const TriangleInput in = model_space_input(xyz, clip_from_world);
            const std::array<float, 16>& m = in.model_to_clip;
            detail::TriangleBatch batch;
            batch.count = int(in.triangle_count);
            detail::gather_triangle_batch(in, 0, batch.count, batch);
            kernels.raster.front_end.transform_batch_plain(in, batch);
            const detail::OccludeeRectangleParams params{m.data(), kNear, kMargin, kWidth, kHeight};
            detail::RectQuery rects[detail::TriangleBatch::kSize];
            const std::uint32_t ready = kernels.occludee_rectangles(batch, batch.count, params, rects);
            for (int t = 0; t < batch.count; ++t) {
                glm::dvec4 model[3], clip[3];
                for (int k = 0; k < 3; ++k) model[k] = {batch.px[k][t], batch.py[k][t], batch.pz[k][t], batch.pw[k][t]}, clip[k] = batch.clip(t, k);
                detail::RectQuery one{};
                bool finite = true;
                for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(clip[k].x) && std::isfinite(clip[k].y) && std::isfinite(clip[k].w);
                const bool set_up = finite && detail::occludee_bounding_rectangle(m, model, clip, kNear, kMargin, kWidth, kHeight, one);
                unclipped += set_up;
                if (!((ready >> t) & 1u)) continue;
                ++taken;
                SCOPED_TRACE(name + ", trial " + std::to_string(trial) + ", lane " + std::to_string(t));
                ASSERT_TRUE(set_up);
                const detail::RectQuery& r = rects[t];
                if (one.i0 > one.i1 || one.j0 > one.j1) continue;  // no samples: any rectangle holds them
                ASSERT_LE(r.i0, one.i0);
                ASSERT_GE(r.i1, one.i1);
                ASSERT_LE(r.j0, one.j0);
                ASSERT_GE(r.j1, one.j1);
                ASSERT_GE(r.d_near, one.d_near);
                ASSERT_LE(r.d_near, one.d_near * (1.0f + 0x1.0p-16f));  // no farther, and hardly nearer
                ++compared;
            }
        }
    }
    if (taken == 0) GTEST_SKIP() << "no instruction set with the kernel";
    EXPECT_GT(taken, unclipped * 9 / 10) << "lanes the kernel takes, of those set up without clipping";
    EXPECT_GT(compared, taken / 4) << "lanes with samples";
}

// The row kernel against its reference, on depths placed where a rounding decides: each
// subtile's d0 (or the larger of d0 and d1) is the reference's own bound at that subtile, one
// float step above or below it. Random intervals (empty rows and rows past the subtiles
// included), planes of every corner, raised-vertex planes usable or not.
TEST(OccludeeTriangles, TheRowKernelAnswersAsItsReference) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kColumns = 70, kStride = 96;
    std::vector<float> d0(kStride), d1(kStride);
    std::vector<std::uint32_t> layer(kStride);
    int checked = 0, unhidden_seen = 0, runs_without_unhidden = 0;
    for (const std::string& isa : available_isas()) {
        if (isa == "scalar") continue;
        const detail::OccludeeRowKernel kernel = detail::buffer_kernels(detail::isa_choice(isa)).occludee_row;
        ASSERT_NE(kernel, nullptr);
        for (int trial = 0; trial < 400; ++trial) {
            detail::OccludeeDepth depth;
            depth.z_vertex_max = float(0.05 + unit(rng));
            depth.raise = 1.0f + 0x1.0p-20f;
            depth.plane.has_plane = trial % 5 != 0;
            depth.plane.a = float(0.2 * unit(rng)), depth.plane.dzdx = float((unit(rng) - 0.5) * 1e-3);
            depth.plane.dzdy = float((unit(rng) - 0.5) * 1e-2);
            depth.plane.far_is_left = depth.plane.dzdx > 0.0f, depth.plane.far_is_top = depth.plane.dzdy > 0.0f;
            depth.error = float(1e-6 * unit(rng)), depth.plane_raise = float(1.0 + 1e-5 * unit(rng));
            depth.raised.usable = trial % 3 != 0;
            depth.raised.d0 = 0.3 * unit(rng), depth.raised.x0 = 300 * unit(rng), depth.raised.y0 = 50 * unit(rng);
            depth.raised.dzdx = (unit(rng) - 0.5) * 1e-3, depth.raised.dzdy = (unit(rng) - 0.5) * 1e-2, depth.raised.outside = 1e-6 * unit(rng);
            const int ty = int(20 * unit(rng));
            std::int32_t first[4], last[4];
            for (int j = 0; j < 4; ++j) {
                first[j] = int(kColumns * kW * unit(rng)) - 20;
                last[j] = trial % 7 == 0 && j == 2 ? first[j] - 1 : first[j] + int(300 * unit(rng));
            }
            const int tx_begin = int(20 * unit(rng)), count = 1 + int((kColumns - tx_begin - 1) * unit(rng));
            // The reference's bound per subtile, and the planes placed about it.
            for (int k = 0; k < count; ++k) {
                const detail::SubtileCoverage c = detail::subtile_coverage(first, last, tx_begin + k);
                const float bound = c.mask ? depth.over(tx_begin + k, ty, c) : 0.5f;
                const int place = int(6 * unit(rng));
                const float near_it = place % 3 == 0 ? bound : place % 3 == 1 ? std::nextafter(bound, 2.0f) : std::nextafter(bound, 0.0f);
                d0[std::size_t(tx_begin + k)] = place < 3 ? near_it : float(0.5 * unit(rng)) * bound;
                d1[std::size_t(tx_begin + k)] = place < 3 ? float(unit(rng)) : near_it;
                layer[std::size_t(tx_begin + k)] = std::uint32_t(rng());
            }
            // Rows ty of a view whose row stride is 0: every row is these arrays.
            const detail::SubtileView view{d0.data(), d1.data(), layer.data(), 0, nullptr, 0, nullptr, nullptr, 0};
            std::uint32_t masks[kColumns + 16], unhidden[kColumns + 16], want_masks[kColumns], want_unhidden[kColumns];
            const detail::OccludeeRowSummary summary = kernel(view, ty, first, last, tx_begin, count, depth, masks, unhidden);
            const detail::OccludeeRowSummary want = detail::occludee_row_reference(view, ty, first, last, tx_begin, count, depth, want_masks, want_unhidden);
            ASSERT_EQ(summary.samples, want.samples) << isa << " trial " << trial;
            ASSERT_EQ(summary.any_unhidden, want.any_unhidden) << isa << " trial " << trial;
            runs_without_unhidden += !want.any_unhidden;
            for (int k = 0; k < count; ++k) {
                ASSERT_EQ(masks[k], want_masks[k]) << isa << " trial " << trial << " subtile " << k;
                ASSERT_EQ(unhidden[k], want_unhidden[k]) << isa << " trial " << trial << " subtile " << k;
                unhidden_seen += want_unhidden[k] != 0;
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_GT(unhidden_seen, checked / 10);  // both answers compared
    EXPECT_GT(runs_without_unhidden, 0);      // and both summaries
}

// The per-sample depth's test of a subtile (BufferKernels::sample_depth_unhidden) gives its
// reference's bits on every instruction set: occluder depths placed at each sample's bound,
// one float step either side, or far from it, with and without the plane and the raised
// vertices' bound, some samples not asked about.
TEST(OccludeeTriangles, TheSampleDepthKernelAnswersAsItsReference) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight, kStride = 24 * kW;
    std::vector<float> sample_depth(std::size_t(kStride) * 24 * kH);
    int checked = 0, shown_seen = 0, hidden_seen = 0;
    for (const std::string& isa : available_isas()) {
        const detail::SampleDepthUnhiddenKernel kernel = detail::buffer_kernels(detail::isa_choice(isa)).sample_depth_unhidden;
        ASSERT_NE(kernel, nullptr);
        for (int trial = 0; trial < 600; ++trial) {
            detail::OccludeeDepth depth;
            depth.z_vertex_max = float(0.05 + unit(rng));
            depth.raise = float(1.0 + 0x1.0p-20 + 1e-7 * unit(rng));
            depth.plane.has_plane = trial % 5 != 0;
            depth.plane.a = float(0.2 * unit(rng)), depth.plane.dzdx = float((unit(rng) - 0.5) * 1e-3);
            depth.plane.dzdy = float((unit(rng) - 0.5) * 1e-2);
            depth.error = float(1e-6 * unit(rng)), depth.plane_raise = float(1.0 + 1e-5 * unit(rng));
            depth.raised.usable = trial % 3 != 0;
            depth.raised.d0 = 0.3 * unit(rng), depth.raised.x0 = 150 * unit(rng), depth.raised.y0 = 80 * unit(rng);
            depth.raised.dzdx = (unit(rng) - 0.5) * 1e-3, depth.raised.dzdy = (unit(rng) - 0.5) * 1e-2, depth.raised.outside = 1e-6 * unit(rng);
            const int tx = int(20 * unit(rng)), ty = int(20 * unit(rng));
            for (int j = 0; j < kH; ++j)
                for (int i = 0; i < kW; ++i) {
                    const int x = tx * kW + i, y = ty * kH + j;
                    const float bound = depth.at(x, y);
                    const int place = int(5 * unit(rng));
                    sample_depth[std::size_t(y) * kStride + std::size_t(x)] = place == 0   ? bound
                                                                              : place == 1 ? std::nextafter(bound, 2.0f)
                                                                              : place == 2 ? std::nextafter(bound, 0.0f)
                                                                              : place == 3 ? float(2.0 * unit(rng))
                                                                                           : 0.0f;
                }
            const std::uint32_t asked = trial % 4 == 0 ? ~0u : std::uint32_t(rng());
            const detail::SubtileView view{nullptr, nullptr, nullptr, 0, sample_depth.data(), std::size_t(kStride), nullptr, nullptr, 0};
            const std::uint32_t want = detail::sample_depth_unhidden_reference(view, tx, ty, asked, depth);
            ASSERT_EQ(kernel(view, tx, ty, asked, depth), want) << isa << " trial " << trial;
            ASSERT_EQ(want & ~asked, 0u);
            shown_seen += __builtin_popcount(want);
            hidden_seen += __builtin_popcount(asked & ~want);
            ++checked;
        }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_GT(shown_seen, checked);  // both answers compared, many times
    EXPECT_GT(hidden_seen, checked);
}

// Past its first 16 triangles an occludee is fetched and transformed 16 at a time: the
// answers and counts must not depend on where the scan starts (it wraps at the end, batches
// stop there), and a bad index or a non-finite vertex anywhere makes it visible.
TEST(OccludeeTriangles, LongOccludeesGiveTheSameAnswerFromEveryStart) {
    const OcclusionBuffer buffer = wall_at(10.0f);
    Soup hidden, partly_seen;
    for (int k = 0; k < 45; ++k) {  // a strip of small triangles behind the wall, a few outside the view
        const float x = -1.4f + 0.06f * float(k);
        hidden.add_flat(x, -0.3f, x + 0.05f, -0.3f, x + 0.02f, 0.3f, 20.0f);
        partly_seen.add_flat(x, -0.3f, x + 0.05f, -0.3f, x + 0.02f, 0.3f, k == 37 ? 5.0f : 20.0f);  // one in front
    }
    const OcclusionBuffer::TriangleTest reference = buffer.test_triangles(hidden.input());
    ASSERT_EQ(reference.visibility, Visibility::occluded);
    for (std::size_t start = 0; start < 45; ++start) {
        const OcclusionBuffer::TriangleTest r = buffer.test_triangles(hidden.input(), 0, start);
        EXPECT_EQ(r.visibility, Visibility::occluded) << start;
        EXPECT_EQ(r.samples, reference.samples) << start;
        const OcclusionBuffer::TriangleTest seen = buffer.test_triangles(partly_seen.input(), 0, start);
        EXPECT_EQ(seen.visibility, Visibility::visible) << start;
        EXPECT_EQ(seen.deciding_triangle, 37u) << start;
    }
    for (std::size_t bad = 0; bad < 45; bad += 11) {
        Soup with_nan = hidden;
        with_nan.xyw[9 * bad + 4] = std::numeric_limits<float>::quiet_NaN();
        EXPECT_EQ(buffer.test_triangles(with_nan.input(), 0, 3).visibility, Visibility::visible) << bad;
        std::vector<std::uint32_t> indices(3 * 45);
        for (std::uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
        indices[3 * bad + 1] = 1000;  // out of range
        TriangleInput in = hidden.input();
        in.indices = indices.data();
        EXPECT_EQ(buffer.test_triangles(in, 0, 3).visibility, Visibility::visible) << bad;
    }
}

// A floor seen at a grazing angle, d = 1/w = -y / 2 on screen (NDC y), and a long thin
// triangle running away from the eye at a relative depth `gap` behind it (w scaled by 1 + gap;
// negative: in front): a wall's top face flush with a floor, as in the FZK house. The bound
// through the plane's error tilts the whole plane and cannot tell 3 10^-4 behind from flush;
// the raised-vertex bound (raised_vertex_plane.hpp) hides it from about 3 10^-5 on.
TEST(OccludeeTriangles, ThinTriangleJustBehindAGrazingFloorIsHidden) {
    auto floor_w = [](float y) { return 1.0f / (-0.5f * y); };
    OcclusionBuffer buffer = make_buffer(64, 36, 1, true);
    Soup floor;
    floor.add(-1.2f, -1.2f, floor_w(-1.2f), 1.2f, -1.2f, floor_w(-1.2f), 1.2f, -0.05f, floor_w(-0.05f));
    floor.add(-1.2f, -1.2f, floor_w(-1.2f), 1.2f, -0.05f, floor_w(-0.05f), -1.2f, -0.05f, floor_w(-0.05f));
    buffer.render(floor.input());
    auto sliver = [&](double gap) {
        const float k = float(1.0 + gap);
        Soup s;
        s.add(0.0f, -0.95f, floor_w(-0.95f) * k, 0.05f, -0.1f, floor_w(-0.1f) * k, 0.1f, -0.1f, floor_w(-0.1f) * k);
        return answer(buffer, s);
    };
    EXPECT_EQ(sliver(1e-4), Visibility::occluded);
    EXPECT_EQ(sliver(1e-3), Visibility::occluded);
    EXPECT_EQ(sliver(0.0), Visibility::visible);  // flush: a tie, never hidden
    EXPECT_EQ(sliver(-1e-5), Visibility::visible);
    EXPECT_EQ(sliver(-1e-4), Visibility::visible);
    // A wide sliver across the floor, wide side up: its rows, the first included, reach many
    // subtiles (tested a subtile per SIMD lane), and it needs the raised-vertex bound from its
    // first subtile on (the rest of that row is then taken again with it), on every ISA.
    auto wide_sliver = [&](double gap) {
        const float k = float(1.0 + gap);
        Soup s;
        s.add(-0.9f, -0.45f, floor_w(-0.45f) * k, 0.9f, -0.45f, floor_w(-0.45f) * k, 0.9f, -0.5f, floor_w(-0.5f) * k);
        return answer(buffer, s);
    };
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        buffer = make_buffer(64, 36, 1, true);  // a buffer takes its instruction set when it is made
        buffer.render(floor.input());
        EXPECT_EQ(wide_sliver(1e-4), Visibility::occluded) << isa;
        EXPECT_EQ(wide_sliver(0.0), Visibility::visible) << isa;
        EXPECT_EQ(wide_sliver(-1e-5), Visibility::visible) << isa;
    }
}

// A wide sliver behind a wall, without per-sample depth (the layers alone decide): two of its
// vertices just behind the wall, the third 300 times farther. The plane's error bound cannot
// hide any of its subtiles; the raised-vertex bound hides them all. It is made when the first
// subtile needs it, and the SIMD lanes' answers for the rest of that row, computed before it
// existed, must be computed again with it (without that, the sliver shows in the next subtile).
TEST(OccludeeTriangles, RaisedBoundRetestsTheRestOfItsRow) {
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        const OcclusionBuffer buffer = wall_at(4.0f);  // made under the instruction set it tests
        auto sliver = [&](double gap) {
            const float near_w = float(4.0 * (1.0 + gap));
            Soup s;
            s.add(-0.9f, -0.45f, 300.0f * near_w, 0.9f, -0.45f, near_w, -0.9f, -0.5f, near_w);
            return buffer.test_triangles(s.input());
        };
        const OcclusionBuffer::TriangleTest hidden = sliver(1e-5);
        EXPECT_EQ(hidden.visibility, Visibility::occluded) << isa;
        EXPECT_GT(hidden.samples, 8u) << isa;  // rows across several subtiles
        // Its samples lie inside, where it is already farther than at its near edge: flush with
        // the wall it is still behind at every sample. Brought to half the distance, it shows.
        EXPECT_EQ(sliver(0.0).visibility, Visibility::occluded) << isa;
        EXPECT_EQ(sliver(-0.5).visibility, Visibility::visible) << isa;
    }
}

// The occludee's input rounding, as test_triangles models it (ClipError in
// occludee_triangles.cpp): with a float matrix within 2^-24 per entry of an exact one, each
// clip coordinate of each vertex may be off by 2^-23 sum_i |m_ri p_i|, independently. Random
// cameras just above a large floor (grazing angles) and long thin triangles from near the
// eye's foot running away from it. Each is scaled about the eye to a few relative distances
// around where, in exact arithmetic with the float matrix, it touches the buffer's
// conservative depth at a sample it covers; whenever, with its clip coordinates so
// perturbed, it is at or in front of that depth at a covered sample, test_triangles must not
// hide it. (Raising the vertices by their own depth error alone, without the gradient times
// their screen slack, fails this.)
TEST(OccludeeTriangles, NeverHidesWhatTheExactMatrixShows) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int seen_count = 0, hidden_count = 0, trials = 0;
    OcclusionBuffer buffer = make_buffer(64, 36, 1, true);
    const int sw = buffer.sample_width(), sh = buffer.sample_height();
    for (int view = 0; view < 10; ++view) {
        const glm::dvec3 eye(20.0 * unit(rng) - 10.0, 0.3 + 2.0 * unit(rng), 20.0 * unit(rng) - 10.0);
        const double heading = 6.283185307179586 * unit(rng);
        const glm::dvec3 target = eye + glm::dvec3(std::cos(heading), -0.05 - 0.3 * unit(rng), std::sin(heading));
        const glm::dmat4 camera = glm::perspective(glm::radians(60.0), 16.0 / 9.0, 0.1, 1000.0) * glm::lookAt(eye, target, glm::dvec3(0, 1, 0));
        std::array<float, 16> m{};
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[std::size_t(4 * c + r)] = float(camera[c][r]);
        buffer.clear();
        const std::vector<float> floor = {-200.0f, 0.0f, -200.0f, 200.0f, 0.0f, -200.0f, 200.0f, 0.0f, 200.0f,
                                          -200.0f, 0.0f, -200.0f, 200.0f, 0.0f, 200.0f,  -200.0f, 0.0f, 200.0f};
        TriangleInput floor_in;
        floor_in.positions = floor.data();
        floor_in.vertex_count = 6;
        floor_in.triangle_count = 2;
        floor_in.model_to_clip = m;
        floor_in.backface = Backface::none;
        buffer.render(floor_in);
        std::vector<float> bound_w;
        buffer.read_depth(bound_w);
        // The smallest occludee w / buffer w over the samples the triangle covers, its clip
        // coordinates moved by `moves` (in units of their rounding bound; infinity: no sample,
        // or a corner before the near plane).
        auto closest_ratio = [&](const std::vector<float>& tri, const long double moves[3][4]) {
            long double sx[3], sy[3], d[3];
            for (int k = 0; k < 3; ++k) {
                long double c[4];
                for (int r = 0; r < 4; ++r) {
                    long double magnitude = std::abs((long double)m[std::size_t(12 + r)]);
                    c[r] = m[std::size_t(12 + r)];
                    for (int i = 0; i < 3; ++i) {
                        const long double term = (long double)m[std::size_t(4 * i + r)] * tri[std::size_t(3 * k + i)];
                        c[r] += term;
                        magnitude += std::abs(term);
                    }
                    c[r] += moves[k][r] * 0x1.0p-23L * magnitude;
                }
                if (c[3] < 0.5L) return HUGE_VALL;  // only what lies beyond the buffer's near plane
                d[k] = 1 / c[3];
                sx[k] = (c[0] * d[k] + 1) * 0.5L * sw;
                sy[k] = (1 - c[1] * d[k]) * 0.5L * sh;
            }
            const long double area = edge(sx[0], sy[0], sx[1], sy[1], sx[2], sy[2]);
            long double closest = HUGE_VALL;
            if (area == 0) return closest;
            for (int j = 0; j < sh; ++j)
                for (int i = 0; i < sw; ++i) {
                    long double l0, l1, l2;
                    barycentrics(sx, sy, area, i + 0.5L, j + 0.5L, l0, l1, l2);
                    if (l0 < 0 || l1 < 0 || l2 < 0) continue;
                    const long double occludee_w = 1 / (l0 * d[0] + l1 * d[1] + l2 * d[2]);
                    closest = std::min(closest, occludee_w / (long double)bound_w[std::size_t(j) * std::size_t(sw) + std::size_t(i)]);
                }
            return closest;
        };
        const long double unmoved[3][4] = {};
        for (int t = 0; t < 8; ++t) {
            const double along = heading + 0.6 * (unit(rng) - 0.5), length = 2.0 + 28.0 * unit(rng);
            const double width = 0.02 + 0.3 * unit(rng), start = 0.2 + unit(rng);
            const glm::dvec3 dir(std::cos(along), 0.0, std::sin(along)), side(-dir.z, 0.0, dir.x);
            const glm::dvec3 p0 = glm::dvec3(eye.x, 0.0, eye.z) + start * dir, p1 = p0 + length * dir, p2 = p1 + width * side;
            const std::vector<float> base = {float(p0.x), float(p0.y), float(p0.z), float(p1.x), float(p1.y),
                                             float(p1.z), float(p2.x), float(p2.y), float(p2.z)};
            const long double touch = closest_ratio(base, unmoved);
            if (!(touch < HUGE_VALL)) continue;
            for (double offset : {-1e-6, -2e-7, 0.0, 1e-7, 2e-7, 4e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4, 1e-3}) {
                // Scaled about the eye by s: w scales by s, so it touches at s = 1 / touch.
                const double scale = double(1.0L / touch) * (1.0 + offset);
                std::vector<float> tri(9);
                for (int k = 0; k < 3; ++k) {
                    const glm::dvec3 p(base[std::size_t(3 * k)], base[std::size_t(3 * k + 1)], base[std::size_t(3 * k + 2)]);
                    const glm::dvec3 q = eye + scale * (p - eye);
                    tri[std::size_t(3 * k)] = float(q.x), tri[std::size_t(3 * k + 1)] = float(q.y), tri[std::size_t(3 * k + 2)] = float(q.z);
                }
                TriangleInput in = floor_in;
                in.positions = tri.data();
                in.vertex_count = 3;
                in.triangle_count = 1;
                const Visibility v_test = buffer.test_triangles(in).visibility;
                bool seen = false;
                for (int perturbation = 0; perturbation < 16 && !seen; ++perturbation) {
                    long double moves[3][4];  // the extremes: each coordinate by its whole bound, either way
                    for (auto& vertex : moves)
                        for (long double& move : vertex) move = unit(rng) < 0.5 ? -1.0L : 1.0L;
                    seen = !(closest_ratio(tri, moves) > 1.0L);
                }
                if (seen) {
                    ++seen_count;
                    ASSERT_EQ(v_test, Visibility::visible) << "view " << view << ", triangle " << t << ", offset " << offset;
                }
                hidden_count += v_test == Visibility::occluded;
                ++trials;
            }
        }
    }
    std::printf("thin triangles by a grazing floor: %d trials, %d hidden, %d seen with perturbed clip coordinates\n", trials, hidden_count,
                seen_count);
    EXPECT_GT(seen_count, trials / 5);
    EXPECT_GT(hidden_count, trials / 5);
}

// The batches' side-plane kernel with beyond_side_plane_exactly's margins: every instruction
// set passes over the lanes the scalar reference does, on batches whose corners lie just
// inside, on and just beyond the margin of each side plane (test_triangles skips those lanes
// without another check).
TEST(OccludeeTriangles, SidePlaneKernelsPassOverTheReferencesLanes) {
    std::mt19937_64 random(19);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), magnitude(0.0, 6.0);
    std::size_t passed = 0, lanes = 0;
    for (const std::string& name : available_isas()) {
        const detail::IsaChoice* choice = detail::find_isa_choice(name.c_str());
        ASSERT_NE(choice, nullptr) << name;
        const auto kernel = detail::raster_kernels(*choice).front_end.beyond_side_plane;
        for (int trial = 0; trial < 3000; ++trial) {
            detail::TriangleBatch batch;
            const int count = 1 + int(random() % detail::TriangleBatch::kSize);
            batch.count = count;
            batch.indices_valid = std::uint32_t(random()) | (trial % 2 ? ~0u : 0u);
            const double scale_x = trial % 5 == 0 ? 0.0 : std::ldexp(1.0, -22) * (1.0 + magnitude(random)), scale_y = scale_x * 0.75;
            for (int t = 0; t < count; ++t) {
                const double size = std::pow(10.0, magnitude(random));
                const int plane = int(random() % 4);
                for (int k = 0; k < 3; ++k) {
                    batch.px[k][t] = unit(random) * size, batch.py[k][t] = unit(random) * size;
                    batch.pz[k][t] = unit(random) * size, batch.pw[k][t] = 1.0;
                }
                double p = 0.0;
                for (int k = 0; k < 3; ++k)
                    p = std::max({p, std::abs(batch.px[k][t]), std::abs(batch.py[k][t]), std::abs(batch.pz[k][t]), 1.0});
                for (int k = 0; k < 3; ++k) {
                    const double w = 1.0 + magnitude(random), across = unit(random) * w;
                    // Beyond the plane by the margin, give or take a few of its units (or
                    // nowhere near it), so that lanes fall on both sides.
                    const double margin = (plane < 2 ? scale_x : scale_y) * p, off = margin + std::trunc(unit(random) * 3.0) * margin + unit(random) * 1e-3;
                    double x = across, y = across;
                    if (plane == 0) x = w + off;
                    if (plane == 1) x = -w - off;
                    if (plane == 2) y = w + off;
                    if (plane == 3) y = -w - off;
                    if (trial % 7 == 3 && k == 1) x = std::numeric_limits<double>::quiet_NaN();
                    batch.cx[k][t] = x, batch.cy[k][t] = y, batch.cz[k][t] = 0.0, batch.cw[k][t] = w;
                }
            }
            const std::uint32_t want = detail::beyond_side_plane_reference(batch, count, scale_x, scale_y);
            ASSERT_EQ(kernel(batch, count, scale_x, scale_y), want) << name << ", trial " << trial;
            passed += std::size_t(__builtin_popcount(want)), lanes += std::size_t(count);
        }
    }
    EXPECT_GT(passed, lanes / 20) << "lanes passed over";
    EXPECT_LT(passed, lanes * 7 / 8) << "and lanes kept";
}

}  // namespace
}  // namespace homcull
