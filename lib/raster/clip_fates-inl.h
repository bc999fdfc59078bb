// unclipped_fate's tests of triangles in clip space, a triangle per double lane, shared by the
// setup's classification (ClassifyBatch, triangle_batch_simd.cpp) and the draw order's notes
// for the reference cells (draw_order_simd.cpp), so that both decide every triangle alike.
// Highway "-inl.h" style, as lane_bits-inl.h.
#if defined(HOMCULL_RASTER_CLIP_FATES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HOMCULL_RASTER_CLIP_FATES_INL_H_
#undef HOMCULL_RASTER_CLIP_FATES_INL_H_
#else
#define HOMCULL_RASTER_CLIP_FATES_INL_H_
#endif

#include <hwy/highway.h>

#include "raster/triangle_setup.hpp"

#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {

// finite_clip and outside_side_plane, corner by corner: each corner (x, y, w) keeps, of the
// lanes set in `finite` and in the four planes' masks, those where it is finite and beyond that
// plane (start them all true). Shared by ClipFates and the occludee tests' pass-over
// (BeyondSidePlane). (Masks as arguments: SVE masks cannot be members of a struct.)
template <class D>
HWY_INLINE void AddSidePlaneCorner(D d, hwy::HWY_NAMESPACE::Vec<D> x, hwy::HWY_NAMESPACE::Vec<D> y, hwy::HWY_NAMESPACE::Vec<D> w,
                                   hwy::HWY_NAMESPACE::Mask<D>& finite, hwy::HWY_NAMESPACE::Mask<D>& right, hwy::HWY_NAMESPACE::Mask<D>& left,
                                   hwy::HWY_NAMESPACE::Mask<D>& above, hwy::HWY_NAMESPACE::Mask<D>& below) {
    namespace hn = hwy::HWY_NAMESPACE;
    const auto infinity = hn::Set(d, HUGE_VAL);
    finite = hn::And(finite, hn::And(hn::And(hn::Lt(hn::Abs(x), infinity), hn::Lt(hn::Abs(y), infinity)), hn::Lt(hn::Abs(w), infinity)));
    right = hn::And(right, hn::Gt(x, w));
    left = hn::And(left, hn::Lt(x, hn::Neg(w)));
    above = hn::And(above, hn::Gt(y, w));
    below = hn::And(below, hn::Lt(y, hn::Neg(w)));
}

// For corners (x_k, y_k, w_k): finite (x, y and w of every corner), outside_frustum (behind
// near_w or beyond one side plane), too_large_to_clip or needs_clipping (`unsettled`: the
// one-triangle setup's), homogeneous_det plus 0.0 as setup_clip_triangle sums it, and
// facing_away for `backface`. Every operation is exact but the determinant's, which is
// computed in the reference's order. (Corners as arguments: SVE vectors cannot be array
// elements.)
template <class D>
HWY_INLINE void ClipFates(D d, Backface backface, double near_w, hwy::HWY_NAMESPACE::Vec<D> x0, hwy::HWY_NAMESPACE::Vec<D> y0,
                          hwy::HWY_NAMESPACE::Vec<D> w0, hwy::HWY_NAMESPACE::Vec<D> x1, hwy::HWY_NAMESPACE::Vec<D> y1,
                          hwy::HWY_NAMESPACE::Vec<D> w1, hwy::HWY_NAMESPACE::Vec<D> x2, hwy::HWY_NAMESPACE::Vec<D> y2,
                          hwy::HWY_NAMESPACE::Vec<D> w2, hwy::HWY_NAMESPACE::Mask<D>& finite, hwy::HWY_NAMESPACE::Mask<D>& outside,
                          hwy::HWY_NAMESPACE::Mask<D>& unsettled, hwy::HWY_NAMESPACE::Vec<D>& det, hwy::HWY_NAMESPACE::Mask<D>& away) {
    namespace hn = hwy::HWY_NAMESPACE;
    using V = hn::Vec<D>;
    using M = hn::Mask<D>;
    const V near = hn::Set(d, near_w), guard = hn::Set(d, kGuardBand), infinity = hn::Set(d, HUGE_VAL);
    const V zero = hn::Zero(d), limit = hn::Set(d, 0x1.0p28);
    finite = hn::FirstN(d, hn::Lanes(d));
    M behind = finite, right = finite, left = finite, above = finite, below = finite, needs_clip = hn::Not(finite);
    V extent = zero, min_w = infinity;
    const auto corner = [&](V x, V y, V w) {
        const V ax = hn::Abs(x), ay = hn::Abs(y), aw = hn::Abs(w);
        AddSidePlaneCorner(d, x, y, w, finite, right, left, above, below);  // finite_clip, outside_side_plane
        behind = hn::And(behind, hn::Lt(w, near));                          // outside_frustum
        extent = hn::Max(extent, hn::Max(hn::Max(ax, ay), aw));  // too_large_to_clip (max and min are exact)
        min_w = hn::Min(min_w, w);
        const V band = hn::Mul(guard, w);  // needs_clipping
        needs_clip = hn::Or(needs_clip, hn::Or(hn::Lt(w, near), hn::Or(hn::Gt(ax, band), hn::Gt(ay, band))));
    };
    corner(x0, y0, w0);
    corner(x1, y1, w1);
    corner(x2, y2, w2);
    outside = hn::Or(behind, hn::Or(hn::Or(right, left), hn::Or(above, below)));
    unsettled = hn::Or(hn::Gt(extent, hn::Mul(limit, hn::Max(near, min_w))), needs_clip);
    det = hn::Add(zero, hn::Add(hn::Sub(hn::Mul(x0, hn::Sub(hn::Mul(y1, w2), hn::Mul(w1, y2))), hn::Mul(y0, hn::Sub(hn::Mul(x1, w2), hn::Mul(w1, x2)))),
                                hn::Mul(w0, hn::Sub(hn::Mul(x1, y2), hn::Mul(y1, x2)))));
    const M ccw = hn::Gt(det, zero);
    away = hn::FirstN(d, 0);  // facing_away: nothing with Backface::none
    if (backface == Backface::cw) away = hn::Not(ccw);
    else if (backface == Backface::ccw) away = ccw;
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HOMCULL_RASTER_CLIP_FATES_INL_H_
