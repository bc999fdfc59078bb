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
#include "common/accurate_sum-inl.h"

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
    // box_edges' base corner, edge vectors and error bound, the four clip rows in lanes (two
    // steps on 2-lane targets): each lane repeats transform_to_clip's products and accurate_sum4
    // (AccurateSum4), the edge products and the magnitudes in box_edges' order.
    // The error's maximum over the rows may take them in another order: it only matters for
    // NaN, and then a corner is not finite and the scalar function decides.
    HWY_ALIGN double base[4], edge[3][4], magnitude[4];
    {
        const hn::CappedTag<double, 4> dr;
        const hn::Rebind<float, decltype(dr)> fr;
        const double lengths[3] = {double(box_max[0]) - double(box_min[0]), double(box_max[1]) - double(box_min[1]),
                                   double(box_max[2]) - double(box_min[2])};
        for (std::size_t row = 0; row < 4; row += hn::Lanes(dr)) {
            const auto column = [&](int c) { return hn::PromoteTo(dr, hn::LoadU(fr, m.data() + 4 * c + row)); };
            const auto m0 = column(0), m1 = column(1), m2 = column(2), m3 = column(3);
            const auto p0 = hn::Mul(m0, hn::Set(dr, double(box_min[0]))), p1 = hn::Mul(m1, hn::Set(dr, double(box_min[1])));
            const auto p2 = hn::Mul(m2, hn::Set(dr, double(box_min[2]))), p3 = hn::Mul(m3, hn::Set(dr, 1.0));
            const auto b = AccurateSum4(p0, p1, p2, p3);
            const auto zero = hn::Zero(dr);
            const auto e0 = hn::Add(hn::Mul(m0, hn::Set(dr, lengths[0])), zero), e1 = hn::Add(hn::Mul(m1, hn::Set(dr, lengths[1])), zero);
            const auto e2 = hn::Add(hn::Mul(m2, hn::Set(dr, lengths[2])), zero);
            hn::Store(b, dr, base + row);
            hn::Store(e0, dr, edge[0] + row), hn::Store(e1, dr, edge[1] + row), hn::Store(e2, dr, edge[2] + row);
            hn::Store(hn::Add(hn::Add(hn::Add(hn::Abs(b), hn::Abs(e0)), hn::Abs(e1)), hn::Abs(e2)), dr, magnitude + row);
        }
    }
    const double error = 0x1.0p-50 * std::max({magnitude[0], magnitude[1], magnitude[2], magnitude[3]});

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
