// The screen rectangle of a box under a perspective matrix (box_rectangle in
// occludee_queries.cpp) with its eight corners in SIMD lanes, compiled per instruction set with
// Google Highway and chosen at run time. Every box test of the scene culler, the buffer's
// test_aabb(s) and the clustered render's cluster boxes start here; in scalar code the
// sixteen divisions x/w and y/w and the corner loop were about 110 ns a box, most of the box
// tests' time on the castle views.
//
// Each lane computes its corner with the scalar code's operations in the same order (the base
// corner plus the edge vectors or +0.0, one addition at a time; the divisions), so the corners
// and their quotients are the same bits. The reductions take the lanes in another order than
// clip_bounds' loop, which only matters for the sign of a zero extreme: such boxes, and every
// box with a corner that is not finite or before the near plane, go to the scalar function.
// Either way the rectangle is box_rectangle's to the bit (test BoxRectangle.*).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "buffer/box_rectangle_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "buffer/rect_queries.hpp"

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

bool BoxRectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& m, float near_w, ScreenRect& rect,
                  Visibility& decided) {
#if HWY_TARGET == HWY_SCALAR  // one lane: the scalar function
    return box_rectangle(box_min, box_max, m, near_w, false, rect, decided);
#else
    // box_corners' base corner, edge vectors and error bound.
    const BoxEdges box = box_edges(box_min, box_max, m);
    const glm::dvec4 &base = box.base, *edge = box.edge;
    const double error = box.error;

    // Corner k = base + (k & 1 ? ex : 0) + (k & 2 ? ey : 0) + (k & 4 ? ez : 0), k in lanes;
    // fewer than 8 lanes take the corners in chunks.
    const hn::CappedTag<double, 8> d;
    const hn::RebindToSigned<decltype(d)> di;
    const int lanes = int(hn::Lanes(d));
    const auto infinity = hn::Set(d, HUGE_VAL), near = hn::Set(d, double(near_w));
    auto min_x = infinity, min_y = infinity, min_w = infinity;
    auto max_x = hn::Neg(infinity), max_y = max_x;
    bool all_finite = true, none_behind = true;
    const auto corner = hn::Iota(di, 0);  // once: Highway's Iota goes through memory
    for (int first = 0; first < 8; first += lanes) {
        const auto k = hn::Add(corner, hn::Set(di, first));
        const auto has_x = hn::RebindMask(d, hn::Ne(hn::And(k, hn::Set(di, 1)), hn::Zero(di)));
        const auto has_y = hn::RebindMask(d, hn::Ne(hn::And(k, hn::Set(di, 2)), hn::Zero(di)));
        const auto has_z = hn::RebindMask(d, hn::Ne(hn::And(k, hn::Set(di, 4)), hn::Zero(di)));
        const auto coordinate = [&](int row) {
            auto v = hn::Add(hn::Set(d, base[row]), hn::IfThenElseZero(has_x, hn::Set(d, edge[0][row])));
            v = hn::Add(v, hn::IfThenElseZero(has_y, hn::Set(d, edge[1][row])));
            return hn::Add(v, hn::IfThenElseZero(has_z, hn::Set(d, edge[2][row])));
        };
        const auto x = coordinate(0), y = coordinate(1), w = coordinate(3);
        const auto finite = hn::And(hn::And(hn::Lt(hn::Abs(x), infinity), hn::Lt(hn::Abs(y), infinity)), hn::Lt(hn::Abs(w), infinity));
        all_finite = all_finite && hn::AllTrue(d, finite);
        none_behind = none_behind && hn::AllFalse(d, hn::Lt(w, near));
        const auto ndc_x = hn::Div(x, w), ndc_y = hn::Div(y, w);
        min_x = hn::Min(min_x, ndc_x), max_x = hn::Max(max_x, ndc_x);
        min_y = hn::Min(min_y, ndc_y), max_y = hn::Max(max_y, ndc_y);
        min_w = hn::Min(min_w, w);
    }
    // Corners that are not finite or lie before the near plane decide the box without a
    // rectangle; the scalar function tells which answer.
    if (!all_finite || !none_behind) return box_rectangle(box_min, box_max, m, near_w, false, rect, decided);
    const double x0 = hn::GetLane(hn::MinOfLanes(d, min_x)), x1 = hn::GetLane(hn::MaxOfLanes(d, max_x));
    const double y0 = hn::GetLane(hn::MinOfLanes(d, min_y)), y1 = hn::GetLane(hn::MaxOfLanes(d, max_y));
    if (x0 == 0.0 || x1 == 0.0 || y0 == 0.0 || y1 == 0.0)  // which zero clip_bounds keeps depends on its order
        return box_rectangle(box_min, box_max, m, near_w, false, rect, decided);
    const double w0 = hn::GetLane(hn::MinOfLanes(d, min_w));
    return rectangle_from_bounds(x0, x1, y0, y1, w0, error, rect, decided);
#endif
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "buffer/buffer_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(BoxRectangle);

void resolve_box_rectangle_kernel(const IsaChoice& choice, BufferKernels& k) {
    k.box_rectangle = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, BoxRectangle);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
