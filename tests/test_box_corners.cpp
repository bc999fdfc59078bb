// The occludee boxes' corners (detail::box_corners, buffer/occludee_queries.cpp) take their edge
// vectors as plain products instead of the full accurate transform; the two must agree to the
// bit (signed zeros included), since the rectangles feed answers that are the same on every
// instruction set and in the golden images.
#include "buffer/rect_queries.hpp"
#include "raster/triangle_setup.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <random>

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

}  // namespace
}  // namespace homcull
