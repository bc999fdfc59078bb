// Directed rounding of doubles to float (common/float_round.hpp): float_down and float_up,
// which pick their one-step correction without a branch, against the definition: the largest
// float at or below v (the smallest at or above), the range's ends and NaN as documented.
#include "common/float_round.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace homcull {
namespace {

float reference_down(double v) {
    constexpr double kMax = std::numeric_limits<float>::max();
    if (v != v) return float(v);
    if (v < -kMax) return -std::numeric_limits<float>::infinity();
    if (v > kMax) return std::numeric_limits<float>::max();
    const float f = float(v);
    return double(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float reference_up(double v) {
    constexpr double kMax = std::numeric_limits<float>::max();
    if (v != v) return float(v);
    if (v > kMax) return std::numeric_limits<float>::infinity();
    if (v < -kMax) return -std::numeric_limits<float>::max();
    const float f = float(v);
    return double(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

bool same_bits(float a, float b) {
    if (std::isnan(a) && std::isnan(b)) return true;
    return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(FloatRound, DirectedRoundingIsTheNearestFloatOnItsSide) {
    std::mt19937_64 random(5);
    std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 1e-50, -1e-50, 1e-45, -1e-45, 1.4e-45, 1e-40, -1e-40, 1.17549435e-38,
                                  3.4028234663852886e38, -3.4028234663852886e38, 3.4028235e38, 1e39, -1e39, HUGE_VAL, -HUGE_VAL,
                                  std::numeric_limits<double>::quiet_NaN(), 0.1, -0.1, 1.0 / 3.0, -1.0 / 3.0};
    for (int k = 0; k < 400000; ++k) {
        std::uint64_t bits = random();
        double v;
        if (k % 4 == 0) {  // exact floats and their neighbours in double
            const float f = std::ldexp(float(random() % 16777216u), int(random() % 300) - 170) * (random() % 2 ? 1.0f : -1.0f);
            v = std::nextafter(double(f), (k & 8) ? HUGE_VAL : -HUGE_VAL);
            if (k % 16 == 0) v = f;
        } else {
            // doubles of every magnitude a float can hold, and some beyond
            bits = (bits & 0x800FFFFFFFFFFFFFull) | (std::uint64_t(1023 - 160 + random() % 330) << 52);
            std::memcpy(&v, &bits, sizeof v);
        }
        values.push_back(v);
    }
    std::size_t differing = 0;
    for (const double v : values) {
        differing += !same_bits(detail::float_down(v), reference_down(v));
        differing += !same_bits(detail::float_up(v), reference_up(v));
    }
    EXPECT_EQ(differing, 0u) << "of " << 2 * values.size();
}

}  // namespace
}  // namespace homcull
