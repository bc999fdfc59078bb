// The occludee boxes' corners (detail::box_corners, buffer/occludee_queries.cpp) take their edge
// vectors as plain products instead of the full accurate transform; the two must agree to the
// bit (signed zeros included), since the rectangles feed answers that are the same on every
// instruction set and in the golden images. The SIMD kernels of box_rectangle
// (buffer/box_rectangle_simd.cpp) must give the scalar function's rectangles to the bit.
#include <homcull/isa.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/rect_queries.hpp"
#include "common/isa_choice.hpp"
#include "raster/triangle_setup.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <cmath>
#include <random>
#include <string>

namespace homcull {
namespace {

TEST(BoxCorners, EdgeVectorsAsTheFullTransform) {
    std::mt19937 random(7);
    // Entries and coordinates of every sign and of very different sizes, zeros among them.
    const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -3.25f, 1e-20f, -1e-20f, 1e20f, -1e20f, 3.4e38f, -3.4e38f, 1e-42f, 7.0f};
    std::uniform_int_distribution<int> pick(0, int(std::size(values)) - 1);
    std::uniform_real_distribution<float> uniform(-100.0f, 100.0f);
    int checked = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        std::array<float, 16> m;
        for (float& e : m) e = trial % 2 ? values[pick(random)] : uniform(random);
        float lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
            lo[k] = trial % 3 ? uniform(random) : values[pick(random)];
            hi[k] = trial % 5 ? lo[k] + std::abs(uniform(random)) : values[pick(random)];
        }
        glm::dvec4 corners[8];
        detail::box_corners(lo, hi, m, corners);
        const glm::dvec4 base = detail::transform_to_clip(m, lo[0], lo[1], lo[2], 1.0);
        const glm::dvec4 ex = detail::transform_to_clip(m, double(hi[0]) - double(lo[0]), 0, 0, 0);
        const glm::dvec4 ey = detail::transform_to_clip(m, 0, double(hi[1]) - double(lo[1]), 0, 0);
        const glm::dvec4 ez = detail::transform_to_clip(m, 0, 0, double(hi[2]) - double(lo[2]), 0);
        for (int k = 0; k < 8; ++k) {
            const glm::dvec4 want =
                base + ((k & 1) ? ex : glm::dvec4(0)) + ((k & 2) ? ey : glm::dvec4(0)) + ((k & 4) ? ez : glm::dvec4(0));
            for (int c = 0; c < 4; ++c) {
                const bool same_nan = std::isnan(want[c]) && std::isnan(corners[k][c]);
                if (!same_nan) {
                    ASSERT_EQ(std::memcmp(&want[c], &corners[k][c], sizeof(double)), 0) << "trial " << trial << ", corner " << k;
                }
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 20000 * 32);
}

// Every instruction set's box_rectangle kernel against the scalar function: perspective
// cameras anywhere (boxes in view, beside it, crossing the near plane or behind the eye, far
// from the origin), random matrices, extreme values, zero-width boxes and boxes whose
// rectangle touches NDC 0 (where the sign of a zero extreme depends on the corners' order).
TEST(BoxRectangle, KernelsGiveTheScalarRectangle) {
    std::mt19937 random(11);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f), size(0.0f, 20.0f), angle(0.0f, 6.2831853f);
    const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 1e-20f, -1e-20f, 1e20f, -1e20f, 3.4e38f, 1e-42f, NAN, INFINITY};
    std::uniform_int_distribution<int> pick(0, int(std::size(values)) - 1);
    std::size_t kernels = 0, rectangles = 0, decided_without = 0;
    for (const std::string& name : available_isas()) {
        const detail::IsaChoice* choice = detail::find_isa_choice(name.c_str());
        ASSERT_NE(choice, nullptr) << name;
        const detail::BufferKernels& k = detail::buffer_kernels(*choice);
        if (!k.box_rectangle) continue;  // the scalar choice
        ++kernels;
        for (int trial = 0; trial < 40000; ++trial) {
            std::array<float, 16> m{};
            const int kind = trial % 4;
            if (kind < 3) {  // a perspective camera: rotation about y, translation, projection
                const float a = angle(random), c = std::cos(a), s = std::sin(a), f = 1.0f + 2.0f * std::abs(uniform(random));
                const float scale = kind == 2 ? 1e5f : 50.0f;  // far from the origin
                const float tx = uniform(random) * scale, ty = uniform(random) * scale, tz = uniform(random) * scale;
                // column-major: clip = P * (R x + t), w = -z_view
                m = {f * c, 0, s, s, 0, f, 0, 0, -f * s, 0, c, c, f * (c * tx - s * tz), f * ty, s * tx + c * tz - 0.2f, s * tx + c * tz};
            } else {
                for (float& e : m) e = trial % 8 == 3 ? values[pick(random)] : uniform(random) * 4.0f;
            }
            float lo[3], hi[3];
            for (int axis = 0; axis < 3; ++axis) {
                lo[axis] = uniform(random) * (kind == 2 ? 1e5f : 60.0f);
                hi[axis] = lo[axis] + (trial % 16 == 5 ? 0.0f : size(random));
                if (trial % 32 == 7) lo[axis] = values[pick(random)];
            }
            if (trial % 16 == 9) lo[0] = -(hi[0] = size(random));  // straddles x = 0 in model space
            const float near_w = trial % 3 ? 0.1f : 1.0f;
            ScreenRect want{}, got{};
            Visibility want_decided = Visibility::occluded, got_decided = Visibility::occluded;
            const bool want_rect = detail::box_rectangle(lo, hi, m, near_w, false, want, want_decided);
            const bool got_rect = k.box_rectangle(lo, hi, m, near_w, got, got_decided);
            ASSERT_EQ(got_rect, want_rect) << name << ", trial " << trial;
            if (want_rect) {
                ASSERT_EQ(std::memcmp(&got, &want, sizeof got), 0) << name << ", trial " << trial;
                ++rectangles;
            } else {
                ASSERT_EQ(got_decided, want_decided) << name << ", trial " << trial;
                ++decided_without;
            }
        }
    }
    if (kernels == 0) GTEST_SKIP() << "no SIMD instruction set here";
    EXPECT_GT(rectangles, kernels * 10000) << "the test must produce rectangles";
    EXPECT_GT(decided_without, kernels * 1000) << "and boxes decided without one";
}

// A box crossing the near plane has no screen rectangle; it is view-culled when all its corners
// lie outside one side plane of the view (beside_the_view), and every point of such a box is
// then outside the view: checked on random points of random boxes, with some boxes culled.
TEST(BoxRectangle, BoxesCrossingTheNearPlaneBesideTheViewAreViewCulled) {
    // A camera at the origin looking down -z (column-major; w = -z, x and y scaled by f).
    const float f = 1.7f, near_w = 0.1f;
    const std::array<float, 16> m = {f, 0, 0, 0, 0, f, 0, 0, 0, 0, -1.0f, -1.0f, 0, 0, -0.2f, 0};
    const auto decide = [&](glm::vec3 lo, glm::vec3 hi) {
        ScreenRect rect{};
        Visibility decided = Visibility::occluded;
        const float box_min[3] = {lo.x, lo.y, lo.z}, box_max[3] = {hi.x, hi.y, hi.z};
        return detail::box_rectangle(box_min, box_max, m, near_w, false, rect, decided) ? Visibility::occluded : decided;
    };
    EXPECT_EQ(decide({30, -1, -20}, {31, 3, 20}), Visibility::view_culled);     // a wall beside the eye, reaching behind it
    EXPECT_EQ(decide({-31, -1, -20}, {-30, 3, 20}), Visibility::view_culled);   // on the other side
    EXPECT_EQ(decide({-5, 20, -10}, {5, 21, 10}), Visibility::view_culled);     // a ceiling above it
    EXPECT_EQ(decide({-1, -1, -5}, {1, 1, 5}), Visibility::visible);            // around the eye
    EXPECT_EQ(decide({10, -1, -40}, {11, 3, 20}), Visibility::visible);         // beside it, reaching into the view far ahead
    std::mt19937 random(5);
    std::uniform_real_distribution<float> position(-40.0f, 40.0f), size(0.1f, 40.0f), unit(0.0f, 1.0f);
    int culled = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const glm::vec3 lo(position(random), position(random), position(random));
        const glm::vec3 hi = lo + glm::vec3(size(random), size(random), size(random));
        if (!(lo.z < -0.1f && hi.z > -0.1f)) continue;  // crossing the near plane (w = -z)
        if (decide(lo, hi) != Visibility::view_culled) continue;
        ++culled;
        for (int k = 0; k < 200; ++k) {
            const glm::vec3 p = lo + (hi - lo) * glm::vec3(k < 8 ? float(k & 1) : unit(random), k < 8 ? float((k >> 1) & 1) : unit(random),
                                                         k < 8 ? float((k >> 2) & 1) : unit(random));
            const double w = -double(p.z), x = double(f) * double(p.x), y = double(f) * double(p.y);
            ASSERT_FALSE(w >= double(near_w) && std::abs(x) <= w && std::abs(y) <= w)
                << "trial " << trial << ": a point of a view-culled box is in view";
        }
    }
    EXPECT_GT(culled, 500);

    // An orthographic view 20 wide and high (x and y scaled by 0.1, w = 1, the near plane at z = -1
    // of clip space): a box the eye's plane cuts beside its window is view-culled, one in front of
    // it visible.
    const std::array<float, 16> ortho = {0.1f, 0, 0, 0, 0, 0.1f, 0, 0, 0, 0, -0.01f, 0, 0, 0, -1.0f, 1.0f};
    const auto decide_ortho = [&](glm::vec3 lo, glm::vec3 hi) {
        ScreenRect rect{};
        Visibility decided = Visibility::occluded;
        const float box_min[3] = {lo.x, lo.y, lo.z}, box_max[3] = {hi.x, hi.y, hi.z};
        return detail::box_rectangle(box_min, box_max, ortho, detail::kOrthographicNearW, true, rect, decided) ? Visibility::occluded : decided;
    };
    EXPECT_EQ(decide_ortho({12, -1, -20}, {13, 3, 20}), Visibility::view_culled);
    EXPECT_EQ(decide_ortho({-3, 11, -20}, {3, 12, 20}), Visibility::view_culled);
    EXPECT_EQ(decide_ortho({8, -1, -20}, {9, 3, 20}), Visibility::visible);
}

}  // namespace
}  // namespace homcull
