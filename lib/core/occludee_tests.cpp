// Occludee tests against the occlusion buffer: screen rectangles (one at a time, or in batches
// whose first, coarse stage runs in SIMD lanes: rect_tests_simd.cpp) and world boxes.
#include <homcull/occlusion_buffer.hpp>

#include "core/rect_tests.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_setup.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// std::nextafter(f, +infinity) for a non-negative finite float, without a libm call.
float next_float_up(float f) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    ++bits;
    std::memcpy(&f, &bits, sizeof bits);
    return f;
}

}  // namespace

bool OcclusionBuffer::prepare(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min, detail::RectQuery& q,
                              Visibility& decided) const {
    if (!std::isfinite(ndc_min_x) || !std::isfinite(ndc_min_y) || !std::isfinite(ndc_max_x) || !std::isfinite(ndc_max_y) ||
        !std::isfinite(w_min) || !(ndc_min_x <= ndc_max_x) || !(ndc_min_y <= ndc_max_y)) {
        decided = Visibility::visible;  // nothing to reason with: never cull
        return false;
    }
    if (w_min < config_.near_w) {
        decided = Visibility::visible;
        return false;
    }
    if (ndc_max_x < -1.0f || ndc_min_x > 1.0f || ndc_max_y < -1.0f || ndc_min_y > 1.0f) {
        decided = Visibility::view_culled;
        return false;
    }
    // The samples whose centres lie in the rectangle.
    const double sx0 = (double(ndc_min_x) + 1.0) * 0.5 * sample_width_, sx1 = (double(ndc_max_x) + 1.0) * 0.5 * sample_width_;
    const double sy0 = (1.0 - double(ndc_max_y)) * 0.5 * sample_height_, sy1 = (1.0 - double(ndc_min_y)) * 0.5 * sample_height_;
    detail::sample_span(sx0, sx1, sample_width_, q.i0, q.i1);
    detail::sample_span(sy0, sy1, sample_height_, q.j0, q.j1);
    if (q.i0 > q.i1 || q.j0 > q.j1) {
        decided = Visibility::occluded;  // covers no sample: invisible at every sample
        return false;
    }
    // Nearest 1/w of the occludee, rounded up and raised by a relative 2^-20.
    const double d = 1.0 / double(w_min);
    q.d_near = float(d);
    if (double(q.d_near) < d) q.d_near = next_float_up(q.d_near);
    q.d_near *= 1.0f + 0x1.0p-20f;
    return true;
}

detail::SubtileView OcclusionBuffer::subtile_view() const { return {d0_.data(), d1_.data(), mask_.data(), stride_}; }

Visibility OcclusionBuffer::test_rect_exhaustive(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y,
                                                 float w_min) const {
    detail::RectQuery q;
    Visibility decided;
    if (!prepare(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min, q, decided)) return decided;
    const detail::SubtileView view = subtile_view();
    for (int ty = q.j0 / kH; ty <= q.j1 / kH; ++ty)
        for (int tx = q.i0 / kW; tx <= q.i1 / kW; ++tx)
            if (!detail::subtile_hides(view, tx, ty, q)) return Visibility::visible;
    return Visibility::occluded;
}

// Is there a subtile in [x0, x1] x [y0, y1] (subtile units) within the pyramid cell whose d0
// is at or below d_near? Cells whose minimum is above d_near are pruned.
bool OcclusionBuffer::any_farther_or_equal(int level, int x, int y, int x0, int y0, int x1, int y1, float d_near) const {
    const int cx0 = x << level, cy0 = y << level, cx1 = ((x + 1) << level) - 1, cy1 = ((y + 1) << level) - 1;
    if (cx1 < x0 || cx0 > x1 || cy1 < y0 || cy0 > y1) return false;
    if (d_near < min_d0(level, x, y)) return false;
    if (level == 0 || (cx0 >= x0 && cx1 <= x1 && cy0 >= y0 && cy1 <= y1)) return true;
    const Level& below = levels_[std::size_t(level) - 1];
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
            if (2 * x + dx < below.width && 2 * y + dy < below.height &&
                any_farther_or_equal(level - 1, 2 * x + dx, 2 * y + dy, x0, y0, x1, y1, d_near))
                return true;
    return false;
}

Visibility OcclusionBuffer::test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    detail::RectQuery q;
    Visibility decided;
    if (!prepare(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min, q, decided)) return decided;
    return test_prepared_rect(q);
}

Visibility OcclusionBuffer::test_prepared_rect(const detail::RectQuery& q) const {
    const int tx0 = q.i0 / kW, tx1 = q.i1 / kW, ty0 = q.j0 / kH, ty1 = q.j1 / kH;

    // Coarse check: the level where the subtile range spans at most 2 x 2 cells. Their minimum
    // d0 is at most any covered subtile's bound, so d_near below it hides the rectangle.
    int level = 0;
    while ((tx1 >> level) - (tx0 >> level) > 1 || (ty1 >> level) - (ty0 >> level) > 1) ++level;
    float coarse = INFINITY;
    for (int y = ty0 >> level; y <= ty1 >> level; ++y)
        for (int x = tx0 >> level; x <= tx1 >> level; ++x) coarse = std::min(coarse, min_d0(level, x, y));
    if (q.d_near < coarse) return Visibility::occluded;
    if (const detail::RectScanKernel scan = detail::selected_rect_scan_kernel()) return scan(subtile_view(), q, sample_width_);
    // Exact range check on d0 alone: if no subtile in the range has d0 <= d_near, every bound
    // (>= d0) is above d_near and the rectangle is hidden. Most hidden rectangles end here.
    bool any_at_or_behind = false;
    for (int y = ty0 >> level; y <= ty1 >> level && !any_at_or_behind; ++y)
        for (int x = tx0 >> level; x <= tx1 >> level && !any_at_or_behind; ++x)
            any_at_or_behind = any_farther_or_equal(level, x, y, tx0, ty0, tx1, ty1, q.d_near);
    if (!any_at_or_behind) return Visibility::occluded;

    const detail::SubtileView view = subtile_view();
    // Interior subtiles (all their samples in the rectangle): their bound is d0, so the
    // rectangle is visible there iff some d0 <= d_near. Border subtiles: the exact test.
    const bool left_full = q.i0 % kW == 0, right_full = q.i1 % kW == kW - 1 && q.i1 < sample_width_;
    const bool top_full = q.j0 % kH == 0, bottom_full = q.j1 % kH == kH - 1;
    const int ix0 = left_full ? tx0 : tx0 + 1, ix1 = right_full ? tx1 : tx1 - 1;
    const int iy0 = top_full ? ty0 : ty0 + 1, iy1 = bottom_full ? ty1 : ty1 - 1;
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            if (ty >= iy0 && ty <= iy1 && tx >= ix0 && tx <= ix1) {  // skip the interior run
                tx = ix1;
                continue;
            }
            if (!detail::subtile_hides(view, tx, ty, q)) return Visibility::visible;
        }
    if (ix0 <= ix1 && iy0 <= iy1)
        for (int y = ty0 >> level; y <= ty1 >> level; ++y)
            for (int x = tx0 >> level; x <= tx1 >> level; ++x)
                if (any_farther_or_equal(level, x, y, ix0, iy0, ix1, iy1, q.d_near)) return Visibility::visible;
    return Visibility::occluded;
}

namespace detail {

bool box_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& m, float near_w, ScreenRect& rect,
                   Visibility& decided) {
    // Incremental corner transform: the base corner plus the three transformed edge vectors.
    const glm::dvec4 base = detail::transform_to_clip(m, box_min[0], box_min[1], box_min[2], 1.0);
    const glm::dvec4 ex = detail::transform_to_clip(m, double(box_max[0]) - double(box_min[0]), 0, 0, 0);
    const glm::dvec4 ey = detail::transform_to_clip(m, 0, double(box_max[1]) - double(box_min[1]), 0, 0);
    const glm::dvec4 ez = detail::transform_to_clip(m, 0, 0, double(box_max[2]) - double(box_min[2]), 0);
    double min_x = HUGE_VAL, max_x = -HUGE_VAL, min_y = HUGE_VAL, max_y = -HUGE_VAL, min_w = HUGE_VAL;
    int behind = 0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4 c = base + ((k & 1) ? ex : glm::dvec4(0)) + ((k & 2) ? ey : glm::dvec4(0)) + ((k & 4) ? ez : glm::dvec4(0));
        if (!detail::finite_clip(c)) {
            decided = Visibility::visible;
            return false;
        }
        if (c.w < double(near_w)) {
            ++behind;
            continue;
        }
        min_x = std::min(min_x, c.x / c.w), max_x = std::max(max_x, c.x / c.w);
        min_y = std::min(min_y, c.y / c.w), max_y = std::max(max_y, c.y / c.w);
        min_w = std::min(min_w, c.w);
    }
    if (behind > 0) {
        decided = behind == 8 ? Visibility::view_culled : Visibility::visible;
        return false;
    }
    // Round the rectangle outwards and the depth towards the eye when going to float.
    rect = {float_down(min_x), float_down(min_y), float_up(max_x), float_up(max_y), float_down(min_w)};
    return true;
}

}  // namespace detail

Visibility OcclusionBuffer::test_aabb(const float box_min[3], const float box_max[3], const std::array<float, 16>& m) const {
    ScreenRect r;
    Visibility decided;
    if (!detail::box_rectangle(box_min, box_max, m, config_.near_w, r, decided)) return decided;
    return test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min);
}

void OcclusionBuffer::test_rects(const ScreenRect* rects, std::size_t count, Visibility* results) const {
    const detail::CoarseRectKernel coarse = detail::selected_coarse_rect_kernel();
    if (!coarse) {  // the scalar reference
        for (std::size_t k = 0; k < count; ++k)
            results[k] = test_rect(rects[k].ndc_min_x, rects[k].ndc_min_y, rects[k].ndc_max_x, rects[k].ndc_max_y, rects[k].w_min);
        return;
    }
    const detail::CoarseRectView view{pyramid_.data(), level_offset_.data(), level_width_.data(), int(levels_.size()),
                                      sample_width_,   sample_height_,       config_.near_w};
    const detail::RectScanKernel scan = detail::selected_rect_scan_kernel();
    const detail::SubtileView subtiles = subtile_view();
    constexpr std::size_t kBlock = 256;  // on the stack: no allocation
    std::uint8_t codes[kBlock];
    detail::RectQuery queries[kBlock];
    for (std::size_t base = 0; base < count; base += kBlock) {
        const std::size_t n = std::min(kBlock, count - base);
        coarse(view, rects + base, n, codes, queries);
        for (std::size_t k = 0; k < n; ++k)
            results[base + k] = codes[k] != detail::kUndecided ? Visibility(codes[k]) : scan(subtiles, queries[k], sample_width_);
    }
}

void OcclusionBuffer::test_aabbs(const Aabb* boxes, std::size_t count, const std::array<float, 16>& m, Visibility* results) const {
    constexpr std::size_t kBlock = 64;
    ScreenRect rects[kBlock];
    std::size_t index[kBlock];
    Visibility answers[kBlock];
    for (std::size_t base = 0; base < count; base += kBlock) {
        const std::size_t n = std::min(kBlock, count - base);
        std::size_t pending = 0;
        for (std::size_t k = 0; k < n; ++k)
            if (detail::box_rectangle(&boxes[base + k].min.x, &boxes[base + k].max.x, m, config_.near_w, rects[pending], results[base + k]))
                index[pending++] = base + k;
        test_rects(rects, pending, answers);
        for (std::size_t p = 0; p < pending; ++p) results[index[p]] = answers[p];
    }
}

}  // namespace homcull
