#include <homcull/error.hpp>
#include <homcull/truth/exact_depth.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace homcull {

ExactDepth::ExactDepth(int sample_width, int sample_height)
    : width_(sample_width), height_(sample_height),
      depth_(std::size_t(sample_width) * std::size_t(sample_height), std::numeric_limits<float>::infinity()) {
    if (sample_width < 1 || sample_height < 1) throw Error("exact depth: the sample grid must be at least 1x1");
}

// The sample-span rule (centres in [lo, hi]) is written out here again on purpose rather than
// shared with the rasterizer: this is the oracle, and a shared helper would hide a shared bug.
void ExactDepth::add_triangle(const float* a, const float* b, const float* c, bool cull_clockwise) {
    const float* v[3] = {a, b, c};
    double x[3], y[3], inv_w[3];
    for (int k = 0; k < 3; ++k) {
        if (!(v[k][3] > 0.0f)) throw Error("exact depth: a vertex has w <= 0 (this reference does not clip)");
        inv_w[k] = 1.0 / double(v[k][3]);
        x[k] = (double(v[k][0]) * inv_w[k] + 1.0) * 0.5 * width_;
        y[k] = (1.0 - double(v[k][1]) * inv_w[k]) * 0.5 * height_;
    }
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);  // sample space, y down
    if (area == 0.0) return;
    if (cull_clockwise && area > 0.0) return;  // clockwise in NDC (y up)
    const double s = area > 0.0 ? 1.0 : -1.0;
    area *= s;
    const int i0 = std::max(0, int(std::ceil(std::min({x[0], x[1], x[2]}) - 0.5)));
    const int i1 = std::min(width_ - 1, int(std::floor(std::max({x[0], x[1], x[2]}) - 0.5)));
    const int j0 = std::max(0, int(std::ceil(std::min({y[0], y[1], y[2]}) - 0.5)));
    const int j1 = std::min(height_ - 1, int(std::floor(std::max({y[0], y[1], y[2]}) - 0.5)));
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
    const double sx0 = (double(ndc_min_x) + 1.0) * 0.5 * width_, sx1 = (double(ndc_max_x) + 1.0) * 0.5 * width_;
    const double sy0 = (1.0 - double(ndc_max_y)) * 0.5 * height_, sy1 = (1.0 - double(ndc_min_y)) * 0.5 * height_;
    const int i0 = std::max(0, int(std::ceil(sx0 - 0.5))), i1 = std::min(width_ - 1, int(std::floor(sx1 - 0.5)));
    const int j0 = std::max(0, int(std::ceil(sy0 - 0.5))), j1 = std::min(height_ - 1, int(std::floor(sy1 - 0.5)));
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
