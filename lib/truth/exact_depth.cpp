#include <homcull/error.hpp>
#include <homcull/truth/exact_depth.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace homcull {

namespace {

std::size_t checked_sample_count(int width, int height) {
    if (width < 1 || height < 1) throw Error("exact depth: the sample grid must be at least 1x1");
    return std::size_t(width) * std::size_t(height);
}

// The samples of a grid of `count` whose centres lie in [lo, hi]. This rule is written out
// here again on purpose rather than shared with the rasterizer: this is the oracle, and a
// shared helper would hide a shared bug. lo and hi are clamped to [-1, count + 1] first, so
// that the conversions to int are defined for any finite input.
void centre_span(double lo, double hi, int count, int& first, int& last) {
    lo = std::clamp(lo, -1.0, double(count) + 1.0);
    hi = std::clamp(hi, -1.0, double(count) + 1.0);
    first = std::max(0, int(std::ceil(lo - 0.5)));
    last = std::min(count - 1, int(std::floor(hi - 0.5)));
}

}  // namespace

ExactDepth::ExactDepth(int sample_width, int sample_height)
    : width_(sample_width), height_(sample_height),
      depth_(checked_sample_count(sample_width, sample_height), std::numeric_limits<float>::infinity()) {}

void ExactDepth::add_triangle(const float* a, const float* b, const float* c, bool cull_clockwise) {
    const float* v[3] = {a, b, c};
    double x[3], y[3], inv_w[3];
    for (int k = 0; k < 3; ++k) {
        if (!(v[k][3] > 0.0f) || !std::isfinite(v[k][0]) || !std::isfinite(v[k][1]) || !std::isfinite(v[k][3]))
            throw Error("exact depth: a vertex is not finite or has w <= 0 (this reference does not clip)");
        inv_w[k] = 1.0 / double(v[k][3]);
        x[k] = (double(v[k][0]) * inv_w[k] + 1.0) * 0.5 * width_;
        y[k] = (1.0 - double(v[k][1]) * inv_w[k]) * 0.5 * height_;
    }
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);  // sample space, y down
    if (area == 0.0) return;
    if (cull_clockwise && area > 0.0) return;  // clockwise in NDC (y up)
    const double s = area > 0.0 ? 1.0 : -1.0;
    area *= s;
    int i0, i1, j0, j1;
    centre_span(std::min({x[0], x[1], x[2]}), std::max({x[0], x[1], x[2]}), width_, i0, i1);
    centre_span(std::min({y[0], y[1], y[2]}), std::max({y[0], y[1], y[2]}), height_, j0, j1);
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const double px = i + 0.5, py = j + 0.5;
            // Barycentric weights (sign-normalized edge functions over the area).
            const double l0 = s * ((x[2] - x[1]) * (py - y[1]) - (y[2] - y[1]) * (px - x[1]));
            const double l1 = s * ((x[0] - x[2]) * (py - y[2]) - (y[0] - y[2]) * (px - x[2]));
            const double l2 = s * ((x[1] - x[0]) * (py - y[0]) - (y[1] - y[0]) * (px - x[0]));
            if (l0 < 0.0 || l1 < 0.0 || l2 < 0.0) continue;
            const double w = area / (l0 * inv_w[0] + l1 * inv_w[1] + l2 * inv_w[2]);
            float f = float(w);
            if (double(f) < w) f = std::nextafter(f, std::numeric_limits<float>::infinity());
            float& d = depth_[std::size_t(j) * std::size_t(width_) + std::size_t(i)];
            d = std::min(d, f);
        }
}

void ExactDepth::finish() {
    levels_ = 1;
    while ((1 << levels_) <= width_) ++levels_;
    row_max_.assign(std::size_t(levels_) * depth_.size(), 0.0f);
    std::copy(depth_.begin(), depth_.end(), row_max_.begin());
    for (int level = 1; level < levels_; ++level) {
        const std::size_t here = std::size_t(level) * depth_.size(), below = std::size_t(level - 1) * depth_.size();
        const int half = 1 << (level - 1);
        for (int j = 0; j < height_; ++j)
            for (int i = 0; i + (1 << level) <= width_; ++i) {
                const std::size_t at = std::size_t(j) * std::size_t(width_) + std::size_t(i);
                row_max_[here + at] = std::max(row_max_[below + at], row_max_[below + at + std::size_t(half)]);
            }
    }
}

bool ExactDepth::hidden(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    if (!std::isfinite(ndc_min_x) || !std::isfinite(ndc_min_y) || !std::isfinite(ndc_max_x) || !std::isfinite(ndc_max_y) ||
        !(ndc_min_x <= ndc_max_x) || !(ndc_min_y <= ndc_max_y) || !(w_min == w_min))
        return false;  // nothing to reason with: not known to be hidden
    const double sx0 = (double(ndc_min_x) + 1.0) * 0.5 * width_, sx1 = (double(ndc_max_x) + 1.0) * 0.5 * width_;
    const double sy0 = (1.0 - double(ndc_max_y)) * 0.5 * height_, sy1 = (1.0 - double(ndc_min_y)) * 0.5 * height_;
    int i0, i1, j0, j1;
    centre_span(sx0, sx1, width_, i0, i1);
    centre_span(sy0, sy1, height_, j0, j1);
    if (i0 > i1 || j0 > j1) return true;
    int level = 0;
    while ((2 << level) <= i1 - i0 + 1) ++level;
    const std::size_t base = std::size_t(level) * depth_.size();
    for (int j = j0; j <= j1; ++j) {
        const std::size_t row = std::size_t(j) * std::size_t(width_);
        const float m = std::max(row_max_[base + row + std::size_t(i0)], row_max_[base + row + std::size_t(i1 + 1 - (1 << level))]);
        if (!(m < w_min)) return false;
    }
    return true;
}

ExactDepth exact_depth_of_triangles(const float* xyzw, std::size_t triangle_count, int sample_width, int sample_height,
                                    bool cull_clockwise) {
    ExactDepth exact(sample_width, sample_height);
    for (std::size_t t = 0; t < triangle_count; ++t) exact.add_triangle(xyzw + 12 * t, xyzw + 12 * t + 4, xyzw + 12 * t + 8, cull_clockwise);
    exact.finish();
    return exact;
}

RectAccuracy count_rect_accuracy(const OcclusionBuffer& buffer, const ExactDepth& exact, const float* r, std::size_t count) {
    RectAccuracy a;
    a.rects = count;
    for (std::size_t k = 0; k < count; ++k, r += 5) {
        const bool truly = exact.hidden(r[0], r[1], r[2], r[3], r[4]);
        const bool said = buffer.test_rect(r[0], r[1], r[2], r[3], r[4]) != Visibility::visible;
        a.truly_hidden += truly;
        a.culled += said;
        a.false_culls += said && !truly;
        a.missed_culls += truly && !said;
    }
    return a;
}

}  // namespace homcull
