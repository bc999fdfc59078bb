// OcclusionBuffer::test_triangles: occludee triangles tested sample by sample. Hand-built
// cases for each answer, a hole counted sample by sample, bad input, and a brute-force check on
// random triangles that the test never hides a triangle seen at a sample of the buffer.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
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

    Soup degenerate;  // all three corners on one line: covers nothing
    degenerate.add_flat(-0.5f, -0.5f, 0.0f, 0.0f, 0.5f, 0.5f, 5.0f);
    EXPECT_EQ(answer(buffer, degenerate), Visibility::occluded);

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

long double edge(long double ax, long double ay, long double bx, long double by, long double px, long double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

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
                const std::vector<float>& v = occludee.xyw;
                long double sx[3], sy[3], w[3];
                for (int k = 0; k < 3; ++k) {
                    w[k] = v[std::size_t(3 * k + 2)];
                    sx[k] = ((long double)v[std::size_t(3 * k)] / w[k] + 1) * 0.5L * sw;
                    sy[k] = (1 - (long double)v[std::size_t(3 * k + 1)] / w[k]) * 0.5L * sh;
                }
                const long double area = edge(sx[0], sy[0], sx[1], sy[1], sx[2], sy[2]);
                if (area == 0) continue;
                // Room: within a sample of its bounding box, every sample has an occluder 1 %
                // nearer than the triangle's nearest vertex.
                const long double nearest_w = std::min({w[0], w[1], w[2]});
                const long double box_x0 = std::min({sx[0], sx[1], sx[2]}) - 1, box_x1 = std::max({sx[0], sx[1], sx[2]}) + 1;
                const long double box_y0 = std::min({sy[0], sy[1], sy[2]}) - 1, box_y1 = std::max({sy[0], sy[1], sy[2]}) + 1;
                bool seen = false, hidden_with_room = true, any_sample = false;
                for (int j = 0; j < sh; ++j)
                    for (int i = 0; i < sw; ++i) {
                        const long double px = i + 0.5L, py = j + 0.5L;
                        const long double l0 = edge(sx[1], sy[1], sx[2], sy[2], px, py) / area;
                        const long double l1 = edge(sx[2], sy[2], sx[0], sy[0], px, py) / area;
                        const long double l2 = 1 - l0 - l1;
                        const long double occluder_w = bound_w[std::size_t(j) * std::size_t(sw) + std::size_t(i)];
                        if (px >= box_x0 && px <= box_x1 && py >= box_y0 && py <= box_y1)
                            hidden_with_room = hidden_with_room && occluder_w * 1.01L < nearest_w;
                        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
                        any_sample = true;
                        const long double occludee_w = 1 / (l0 / w[0] + l1 / w[1] + l2 / w[2]);
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

}  // namespace
}  // namespace homcull
