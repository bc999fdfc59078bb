#pragma once
// Rounding a double to float on a chosen side, and the bounds of clip-space points: what every
// conservative bound needs, from the rasterizer to the scene culler's occludee rectangles.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace homcull::detail {

// The float next to a finite f towards +infinity (up) or -infinity, by one step of its bits
// (what std::nextafter does, without the library call these hot paths would pay).
inline float float_step(float f, bool up) {
    if (f == 0.0f) return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    bits = (up == (f > 0.0f)) ? bits + 1u : bits - 1u;  // away from zero: larger magnitude
    std::memcpy(&f, &bits, sizeof bits);
    return f;
}

// float_step(f, up) where `step`, else f, for a finite f, chosen without a branch: whether
// float() rounded a value the wrong way is about even odds, and a branch on it was mispredicted
// that often (box rectangles, five roundings each).
inline float float_step_if(float f, bool step, bool up) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    // Masks rather than conditional expressions, which compilers turned back into branches.
    const std::uint32_t positive = (bits >> 31) ^ 1u;
    const std::uint32_t away = up ? positive : positive ^ 1u;  // the step and the sign agree: magnitude up
    const std::uint32_t from_zero = up ? 0x00000001u : 0x80000001u;  // +-denorm_min
    const std::uint32_t zero = 0u - std::uint32_t((bits & 0x7FFFFFFFu) == 0u);
    const std::uint32_t stepped = (from_zero & zero) | ((bits + 2u * away - 1u) & ~zero);
    const std::uint32_t take = 0u - std::uint32_t(step);
    bits = (stepped & take) | (bits & ~take);
    std::memcpy(&f, &bits, sizeof bits);
    return f;
}

// float(v) rounded towards -infinity / +infinity: bounds that must stay on one side of a double
// (rectangles rounded outwards, depths towards the eye). Beyond the float range the result is
// the largest float or infinity on the safe side; NaN stays NaN.
inline float float_down(double v) {
    constexpr double kMax = std::numeric_limits<float>::max();
    if (!(v >= -kMax)) return v > 0.0 || v != v ? float(v) : -std::numeric_limits<float>::infinity();  // NaN, or below the range
    if (v > kMax) return std::numeric_limits<float>::max();
    const float f = float(v);
    return float_step_if(f, double(f) > v, false);
}
inline float float_up(double v) {
    constexpr double kMax = std::numeric_limits<float>::max();
    if (!(v <= kMax)) return v != v ? float(v) : std::numeric_limits<float>::infinity();  // NaN, or above the range
    if (v < -kMax) return -std::numeric_limits<float>::max();
    const float f = float(v);
    return float_step_if(f, double(f) < v, true);
}

// What an occludee test needs of clip-space points: their NDC bounds and nearest w over the
// points at or beyond near_w, their farthest w over all, how many lie before near_w, and
// whether every coordinate is finite (the rest is meaningless when not).
struct ClipBounds {
    bool finite = true;
    int behind = 0;
    double min_x = HUGE_VAL, max_x = -HUGE_VAL, min_y = HUGE_VAL, max_y = -HUGE_VAL, min_w = HUGE_VAL, max_w = -HUGE_VAL;
};
inline ClipBounds clip_bounds(const glm::dvec4* points, int count, double near_w) {
    ClipBounds b;
    for (int k = 0; k < count; ++k) {
        const glm::dvec4& c = points[k];
        if (!(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.w))) {
            b.finite = false;
            return b;
        }
        b.max_w = std::max(b.max_w, c.w);
        if (c.w < near_w) {
            ++b.behind;
            continue;
        }
        b.min_x = std::min(b.min_x, c.x / c.w), b.max_x = std::max(b.max_x, c.x / c.w);
        b.min_y = std::min(b.min_y, c.y / c.w), b.max_y = std::max(b.max_y, c.y / c.w);
        b.min_w = std::min(b.min_w, c.w);
    }
    return b;
}

}  // namespace homcull::detail
