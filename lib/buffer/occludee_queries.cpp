// Occludee tests against the occlusion buffer: screen rectangles (one at a time, or in batches
// whose first, coarse stage runs in SIMD lanes: rect_queries_simd.cpp) and world boxes.
#include <homcull/occlusion_buffer.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "buffer/exact_view_test.hpp"
#include "common/float_mode.hpp"
#include "buffer/min_pyramid.hpp"
#include "buffer/rect_queries.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_setup.hpp"

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

}  // namespace

bool detail::BufferState::prepare(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min, detail::RectQuery& q,
                              Visibility& decided) const {
    return detail::prepare_rect(coarse_view(), {ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min}, q, decided);
}

Visibility detail::BufferState::test_rect_exhaustive(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y,
                                                 float w_min) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    detail::RectQuery q;
    Visibility decided;
    if (!prepare(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min, q, decided)) return decided;
    const detail::SubtileView view = subtile_view();
    for (int ty = q.j0 / kH; ty <= q.j1 / kH; ++ty)
        for (int tx = q.i0 / kW; tx <= q.i1 / kW; ++tx)
            if (!detail::subtile_hides(view, tx, ty, q)) return Visibility::visible;
    return Visibility::occluded;
}

Visibility detail::BufferState::test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    // One dispatch for all of it where a SIMD kernel exists: the call's fixed costs are most of
    // a small rectangle's test.
    if (const detail::RectOneKernel one = kernels_->rect_one) return one(*this, {ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min});
    detail::RectQuery q;
    Visibility decided;
    if (!prepare(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min, q, decided)) return decided;
    return test_prepared_rect(q);
}

Visibility detail::BufferState::test_prepared_rect(const detail::RectQuery& q) const {
    if (const detail::RectPreparedKernel prepared = kernels_->rect_prepared) return prepared(*this, q);
    if (detail::coarse_rect_hides(coarse_view(), q)) return Visibility::occluded;
    // Exact range check on d0 alone: if no subtile in the range has d0 <= d_near, every bound
    // (>= d0) is above d_near and the rectangle is hidden. Most hidden rectangles end here.
    const int level_count = int(levels_.size());
    const auto [tx0, tx1, ty0, ty1] = detail::subtile_range(q);
    if (detail::min_pyramid_range_above(pyramid_.data(), levels_.data(), level_count, tx0, ty0, tx1, ty1, q.d_near))
        return Visibility::occluded;

    const detail::SubtileView view = subtile_view();
    // Interior subtiles (all their samples in the rectangle): their bound is d0, so the
    // rectangle is visible there iff some d0 <= d_near. Border subtiles: the exact test.
    const auto [ix0, ix1, iy0, iy1] = detail::interior_subtiles(q);
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            if (ty >= iy0 && ty <= iy1 && tx >= ix0 && tx <= ix1) {  // skip the interior run
                tx = ix1;
                continue;
            }
            if (!detail::subtile_hides(view, tx, ty, q)) return Visibility::visible;
        }
    if (ix0 <= ix1 && iy0 <= iy1 &&
        !detail::min_pyramid_range_above(pyramid_.data(), levels_.data(), level_count, ix0, iy0, ix1, iy1, q.d_near))
        return Visibility::visible;
    return Visibility::occluded;
}

namespace detail {

BoxEdges box_edges(const float box_min[3], const float box_max[3], const std::array<float, 16>& m) {
    BoxEdges b;
    b.base = transform_to_clip(m, box_min[0], box_min[1], box_min[2], 1.0);
    // The edge vectors: transform_to_clip of (length, 0, 0, 0) and so on, whose accurate sum of
    // one product and three zeros is that product (plus 0.0: a zero comes out +0, as there).
    // Products of a float entry and a difference of floats are finite, so the two agree to the
    // bit (test BoxCorners.EdgeVectorsAsTheFullTransform).
    const double lengths[3] = {double(box_max[0]) - double(box_min[0]), double(box_max[1]) - double(box_min[1]),
                               double(box_max[2]) - double(box_min[2])};
    for (int axis = 0; axis < 3; ++axis)
        for (int row = 0; row < 4; ++row) b.edge[axis][row] = double(m[4 * axis + row]) * lengths[axis] + 0.0;
    // 2^-52 for each transform and the edge lengths' subtraction, 3 * 2^-53 for the sums: 2^-50
    // of the terms' magnitude covers both.
    const glm::dvec4 magnitude = glm::abs(b.base) + glm::abs(b.edge[0]) + glm::abs(b.edge[1]) + glm::abs(b.edge[2]);
    b.error = 0x1.0p-50 * std::max({magnitude.x, magnitude.y, magnitude.z, magnitude.w});
    return b;
}

double box_corners(const float box_min[3], const float box_max[3], const std::array<float, 16>& m, glm::dvec4 corners[8]) {
    const BoxEdges b = box_edges(box_min, box_max, m);
    const glm::dvec4 &ex = b.edge[0], &ey = b.edge[1], &ez = b.edge[2];
    for (int k = 0; k < 8; ++k)
        corners[k] = b.base + ((k & 1) ? ex : glm::dvec4(0)) + ((k & 2) ? ey : glm::dvec4(0)) + ((k & 4) ? ez : glm::dvec4(0));
    return b.error;
}

double orthographic_corners(glm::dvec4 corners[8], double error) {
    // Each corner's h = (3w - z) / 2 is off by at most (3 + 1) / 2 of the corners' error, plus
    // its own rounding; representative_error is largest at the smallest h and the largest
    // coordinate.
    double h_min = HUGE_VAL, magnitude = 0.0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4& c = corners[k];
        h_min = std::min(h_min, (3.0 * c.w - c.z) * 0.5);
        magnitude = std::max({magnitude, std::abs(c.x), std::abs(c.y), std::abs(c.z), std::abs(c.w)});
        corners[k] = orthographic_representative(c);
    }
    const double dh = 2.0 * error + 0x1.0p-50 * magnitude;
    if (!(h_min > 2.0 * dh)) return HUGE_VAL;  // no bound to reason with: the box is visible
    return representative_error(magnitude + error, error, h_min, dh);
}

double ndc_error_bound(double error, double max_abs_ndc, double min_w) {
    if (!(min_w > error)) return HUGE_VAL;
    return error * (1.0 + max_abs_ndc) / (min_w - error) + 0x1.0p-52 * max_abs_ndc;
}

bool box_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& m, float near_w, bool orthographic, ScreenRect& rect,
                   Visibility& decided) {
    glm::dvec4 corners[8], clip[8];
    const double clip_error = box_corners(box_min, box_max, m, corners);
    double error = clip_error;
    if (orthographic) {
        std::copy(corners, corners + 8, clip);  // the side planes are the clip corners'
        error = orthographic_corners(corners, error);
    }
    const ClipBounds b = clip_bounds(corners, 8, double(near_w));
    if (!b.finite || b.behind > 0) {  // nothing to reason with, or crossing the near plane: visible unless beside the view
        decided = b.finite && (b.behind == 8 || beside_the_view(orthographic ? clip : corners, clip_error, clip_term_bounds(box_min, box_max, m)))
                      ? Visibility::view_culled
                      : Visibility::visible;
        return false;
    }
    return rectangle_from_bounds(b.min_x, b.max_x, b.min_y, b.max_y, b.min_w, error, rect, decided);
}

bool rectangle_from_bounds(double min_x, double max_x, double min_y, double max_y, double min_w, double error, ScreenRect& rect,
                           Visibility& decided) {
    // Wherever the exact corners are, they lie within the widened rectangle and at or beyond
    // its lowered w; rounded outwards and towards the eye when going to float. A bound that
    // reaches the nearest w leaves no rectangle to reason with: visible.
    const double ndc = ndc_error_bound(error, std::max({-min_x, max_x, -min_y, max_y}), min_w);
    if (!(ndc < HUGE_VAL)) {
        decided = Visibility::visible;
        return false;
    }
    rect = {float_down(min_x - ndc), float_down(min_y - ndc), float_up(max_x + ndc), float_up(max_y + ndc), float_down(min_w - error)};
    return true;
}

// Whether every corner of a box lies outside one side plane of the view (x > w, x < -w, y > w
// or y < -w in clip space), by more than twice the corners' error and 2^-20 of the rows' terms
// (clip_term_bounds): the matrix is a rounding of the caller's (or ground truth's) projection,
// each entry within 2^-24 of it, and terms that cancel in a coordinate still carry their
// rounding. The sides are affine, so the whole box lies outside that side: in front of the eye
// beside the view, behind it where w <= 0 (an orthographic view's w is constant: beside its
// window at every depth). For a box crossing the near plane, whose screen rectangle cannot be
// bounded (a wall beside the eye, reaching behind it), the only test there is.
bool beside_the_view(const glm::dvec4 corners[8], double error, const glm::dvec4& terms) {
    const double margin_x = 2.0 * error + 0x1.0p-20 * (terms.x + terms.w), margin_y = 2.0 * error + 0x1.0p-20 * (terms.y + terms.w);
    bool outside[4] = {true, true, true, true};  // right, left, top, bottom
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4& c = corners[k];
        outside[0] = outside[0] && c.x - c.w > margin_x;
        outside[1] = outside[1] && -c.x - c.w > margin_x;
        outside[2] = outside[2] && c.y - c.w > margin_y;
        outside[3] = outside[3] && -c.y - c.w > margin_y;
    }
    return outside[0] || outside[1] || outside[2] || outside[3];
}

glm::dvec4 clip_term_bounds(const float box_min[3], const float box_max[3], const std::array<float, 16>& m) {
    glm::dvec4 terms(0.0);
    for (int row = 0; row < 4; ++row) {
        double sum = std::abs(double(m[12 + std::size_t(row)]));
        for (int axis = 0; axis < 3; ++axis)
            sum += std::abs(double(m[4 * std::size_t(axis) + std::size_t(row)])) *
                   std::max(std::abs(double(box_min[axis])), std::abs(double(box_max[axis])));
        terms[row] = sum;
    }
    return terms;
}

}  // namespace detail

Visibility detail::BufferState::test_aabb(const float box_min[3], const float box_max[3], const std::array<float, 16>& m) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const Visibility v = test_aabb_by_rectangle(box_min, box_max, m);
    if (v != Visibility::visible) return v;
    return detail::ExactViewTest(m, config_.near_w, config_.orthographic).visible_box(box_min, box_max);
}

Visibility detail::BufferState::test_aabb_by_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& m) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    ScreenRect r;
    Visibility decided;
    if (!detail::box_rectangle(*kernels_, box_min, box_max, m, config_.near_w, config_.orthographic, r, decided)) return decided;
    return test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min);
}

void detail::BufferState::test_rects(const ScreenRect* rects, std::size_t count, Visibility* results) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const detail::RectBlockKernel block = kernels_->rect_block;
    if (!block) {  // the scalar reference
        for (std::size_t k = 0; k < count; ++k)
            results[k] = test_rect(rects[k].ndc_min_x, rects[k].ndc_min_y, rects[k].ndc_max_x, rects[k].ndc_max_y, rects[k].w_min);
        return;
    }
    const detail::CoarseRectView view = coarse_view();
    const detail::SubtileView subtiles = subtile_view();
    for (std::size_t base = 0; base < count; base += detail::kRectBlock)
        block(view, subtiles, rects + base, std::min(detail::kRectBlock, count - base), results + base);
}

void detail::BufferState::test_aabbs(const Aabb* boxes, std::size_t count, const std::array<float, 16>& m, Visibility* results) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    test_aabbs_by_rectangle(boxes, count, m, results);
    detail::ExactViewTest view(m, config_.near_w, config_.orthographic);
    for (std::size_t k = 0; k < count; ++k)
        if (results[k] == Visibility::visible) results[k] = view.visible_box(&boxes[k].min.x, &boxes[k].max.x);
}

void detail::BufferState::test_aabbs_by_rectangle(const Aabb* boxes, std::size_t count, const std::array<float, 16>& m, Visibility* results) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    constexpr std::size_t kBlock = 64;
    ScreenRect rects[kBlock];
    std::size_t index[kBlock];
    Visibility answers[kBlock];
    for (std::size_t base = 0; base < count; base += kBlock) {
        const std::size_t n = std::min(kBlock, count - base);
        std::size_t pending = 0;
        for (std::size_t k = 0; k < n; ++k)
            if (detail::box_rectangle(*kernels_, &boxes[base + k].min.x, &boxes[base + k].max.x, m, config_.near_w, config_.orthographic, rects[pending],
                                      results[base + k]))
                index[pending++] = base + k;
        test_rects(rects, pending, answers);
        for (std::size_t p = 0; p < pending; ++p) results[index[p]] = answers[p];
    }
}

}  // namespace homcull
