// The occludee triangle test of one subtile row, a subtile per SIMD lane (occludee_depth.hpp):
// the coverage mask from the row intervals, the corner of the covered samples where each depth
// bound is largest, the two bounds (the plane's in float, the raised vertices' in double, both
// with occludee_depth.hpp's operations in its order, no fused multiply-add) and the layers'
// test. Every lane computes what occludee_row_reference computes for its subtile.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "buffer/occludee_rows_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "buffer/occludee_depth.hpp"
#include "common/float_outward-inl.h"

#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET != HWY_SCALAR
// OccludeeDepth's bound, lane by lane: the plane's (plane_bound) at samples (plane_column,
// plane_row) in float, and the raised vertices' (raised_bound) at (vertex_column, vertex_row) in
// double, rounded up to float; the smaller, as OccludeeDepth::over and ::at take it (each at its
// own corner of the covered samples, or both at one sample). The same operations in the same
// order as the scalar functions.
template <class DF>
HWY_INLINE hn::Vec<DF> OccludeeBound(DF df, const OccludeeDepth& depth, hn::Vec<hn::RebindToSigned<DF>> plane_column,
                                     hn::Vec<hn::RebindToSigned<DF>> plane_row, hn::Vec<hn::RebindToSigned<DF>> vertex_column,
                                     hn::Vec<hn::RebindToSigned<DF>> vertex_row) {
    using VF = hn::Vec<DF>;
    const hn::Half<DF> dfh;
    const hn::Rebind<double, decltype(dfh)> dd;  // half the float lanes, for the raised bound
    const hn::Half<hn::RebindToSigned<DF>> dih;
    using VD = hn::Vec<decltype(dd)>;
    const PreparedTriangle& p = depth.plane;
    const RaisedVertexPlane& r = depth.raised;
    VF bound = hn::Set(df, depth.z_vertex_max);
    if (p.has_plane) {
        const VF half = hn::Set(df, 0.5f);
        const VF x = hn::Add(hn::ConvertTo(df, plane_column), half), y = hn::Add(hn::ConvertTo(df, plane_row), half);
        const VF on_plane = hn::Mul(hn::Add(hn::Add(hn::Add(hn::Set(df, p.a), hn::Mul(hn::Set(df, p.dzdy), y)), hn::Mul(hn::Set(df, p.dzdx), x)),
                                            hn::Set(df, depth.error)),
                                    hn::Set(df, depth.plane_raise));
        bound = hn::IfThenElse(hn::Lt(on_plane, bound), on_plane, bound);  // std::min(bound, on_plane)
    }
    const VF by_plane = hn::Mul(bound, hn::Set(df, depth.raise));
    VF by_vertices = hn::Set(df, HUGE_VALF);
    if (r.usable) {
        const auto bound_of = [&](auto c, auto rr) {
            const VD cd = hn::PromoteTo(dd, c), rd = hn::PromoteTo(dd, rr), h = hn::Set(dd, 0.5);
            const VD at = hn::Add(hn::Add(hn::Add(hn::Set(dd, r.d0), hn::Mul(hn::Set(dd, r.dzdx), hn::Sub(hn::Add(cd, h), hn::Set(dd, r.x0)))),
                                          hn::Mul(hn::Set(dd, r.dzdy), hn::Sub(hn::Add(rd, h), hn::Set(dd, r.y0)))),
                                  hn::Set(dd, r.outside));
            return FloatOutward<true>(dd, hn::Mul(at, hn::Set(dd, 1.0 + 0x1.0p-20)));
        };
        by_vertices = hn::Combine(df, bound_of(hn::UpperHalf(dih, vertex_column), hn::UpperHalf(dih, vertex_row)),
                                  bound_of(hn::LowerHalf(dih, vertex_column), hn::LowerHalf(dih, vertex_row)));
    }
    return hn::IfThenElse(hn::Lt(by_vertices, by_plane), by_vertices, by_plane);  // std::min(by_plane, by_vertices)
}
#endif

OccludeeRowSummary OccludeeRow(const SubtileView& view, int ty, const std::int32_t first[4], const std::int32_t last[4], int tx_begin,
                               int count, const OccludeeDepth& depth, std::uint32_t* masks, std::uint32_t* unhidden) {
#if HWY_TARGET == HWY_SCALAR
    return occludee_row_reference(view, ty, first, last, tx_begin, count, depth, masks, unhidden);
#else
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    static_assert(kW == 8 && kH == 4, "a subtile's mask is 4 bytes of 8 columns");
    const hn::CappedTag<float, kMaxSimdLanes> df;  // rows are padded for this many
    const hn::RebindToSigned<decltype(df)> di;
    const hn::RebindToUnsigned<decltype(df)> du;
    const int lanes = int(hn::Lanes(df));
    using VI = hn::Vec<decltype(di)>;
    using VF = hn::Vec<decltype(df)>;

    const PreparedTriangle& p = depth.plane;
    const bool far_is_left = p.has_plane && p.far_is_left, far_is_top = p.has_plane && p.far_is_top;
    const RaisedVertexPlane& r = depth.raised;
    const VI lane = hn::Iota(di, 0), zero = hn::Zero(di), seven = hn::Set(di, kW - 1);
    const hn::Vec<decltype(du)> byte = hn::Set(du, 0xFFu);
    const std::size_t row = std::size_t(ty) * view.stride;
    // The summary: the masks' bits summed lane by lane (at most 64 x 32 a lane), any unhidden.
    auto samples = hn::Zero(du);
    auto any_shown = hn::Zero(du);
    for (int base = 0; base < count; base += lanes) {
        const auto live = hn::FirstN(di, std::size_t(count - base));
        const VI x0 = hn::ShiftLeft<3>(hn::Add(lane, hn::Set(di, tx_begin + base)));  // tx * 8
        // subtile_coverage, lane by lane.
        hn::Vec<decltype(du)> mask = hn::Zero(du);
        VI column_lo = hn::Set(di, kW), column_hi = hn::Set(di, -1), row_lo = hn::Set(di, kH), row_hi = hn::Set(di, -1);
        for (int j = 0; j < kH; ++j) {
            const VI lo = hn::Max(hn::Sub(hn::Set(di, first[j]), x0), zero), hi = hn::Min(hn::Sub(hn::Set(di, last[j]), x0), seven);
            const auto filled = hn::And(live, hn::Not(hn::Gt(lo, hi)));
            // (0xFF >> (7 - hi)) & (0xFF << lo), shift counts kept within [0, 7] whatever the
            // interval (empty lanes get no bits), placed at byte j.
            const auto bits = hn::And(hn::Shr(byte, hn::BitCast(du, hn::Sub(seven, hn::Max(hi, zero)))),
                                      hn::Shl(byte, hn::BitCast(du, hn::Min(lo, seven))));
            mask = hn::Or(mask, hn::IfThenElseZero(hn::RebindMask(du, filled), hn::Shl(bits, hn::Set(du, std::uint32_t(j * kW)))));
            column_lo = hn::IfThenElse(filled, hn::Min(column_lo, lo), column_lo);
            column_hi = hn::IfThenElse(filled, hn::Max(column_hi, hi), column_hi);
            row_lo = hn::IfThenElse(hn::And(filled, hn::Eq(row_lo, hn::Set(di, kH))), hn::Set(di, j), row_lo);
            row_hi = hn::IfThenElse(filled, hn::Set(di, j), row_hi);
        }
        // OccludeeDepth::over: the plane's bound at its corner, the raised vertices' at theirs.
        const VI y0 = hn::Set(di, ty * kH);
        const VF d_near = OccludeeBound(df, depth, hn::Add(x0, far_is_left ? column_hi : column_lo), hn::Add(y0, far_is_top ? row_hi : row_lo),
                                        hn::Add(x0, r.dzdx > 0.0 ? column_hi : column_lo), hn::Add(y0, r.dzdy > 0.0 ? row_hi : row_lo));
        // subtile_unhidden_samples, lane by lane.
        const std::size_t at = row + std::size_t(tx_begin + base);
        const VF d0 = hn::LoadU(df, view.d0 + at), d1 = hn::LoadU(df, view.d1 + at);
        const auto layer = hn::LoadU(du, view.mask + at);
        const VF layered = hn::IfThenElse(hn::Lt(d0, d1), d1, d0);  // std::max(d0, d1)
        auto shown = hn::AndNot(layer, mask);
        shown = hn::Or(shown, hn::IfThenElseZero(hn::RebindMask(du, hn::Not(hn::Lt(d_near, layered))), hn::And(mask, layer)));
        shown = hn::IfThenZeroElse(hn::RebindMask(du, hn::Lt(d_near, d0)), shown);
        hn::StoreU(mask, du, masks + base);
        hn::StoreU(shown, du, unhidden + base);
        samples = hn::Add(samples, hn::PopulationCount(mask));
        any_shown = hn::Or(any_shown, shown);
    }
    OccludeeRowSummary summary;
    summary.samples = hn::GetLane(hn::SumOfLanes(du, samples));
    summary.any_unhidden = !hn::AllTrue(du, hn::Eq(any_shown, hn::Zero(du)));
    return summary;
#endif
}

// sample_depth_unhidden_reference with a sample per lane: a sample row's 8 samples at a time (in
// two steps on 4-lane targets), each lane evaluating depth.at with occludee_depth.hpp's
// operations in its order (the plane's bound in float, the raised vertices' in double rounded up
// to float, as OccludeeRow takes them at its corners).
std::uint32_t SampleDepthUnhidden(const SubtileView& view, int tx, int ty, std::uint32_t unhidden, const OccludeeDepth& depth) {
#if HWY_TARGET == HWY_SCALAR
    return sample_depth_unhidden_reference(view, tx, ty, unhidden, depth);
#else
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    const hn::CappedTag<float, kW> df;
    const hn::RebindToSigned<decltype(df)> di;
    const int lanes = int(hn::Lanes(df));
    const auto lane = hn::Iota(di, 0);
    std::uint32_t left = 0;
    for (int j = 0; j < kH; ++j) {
        if (((unhidden >> (j * kW)) & 0xFFu) == 0) continue;
        const int row = ty * kH + j;
        const float* occluders = view.sample_depth + std::size_t(row) * view.sample_stride + std::size_t(tx) * kW;
        for (int c = 0; c < kW; c += lanes) {
            const int shift = j * kW + c;
            const std::uint32_t wanted = (unhidden >> shift) & ((1u << lanes) - 1u);
            if (wanted == 0) continue;
            const auto column = hn::Add(lane, hn::Set(di, tx * kW + c));
            // OccludeeDepth::at: both bounds at the sample itself.
            const auto row_of = hn::Set(di, row);
            const auto at = OccludeeBound(df, depth, column, row_of, column, row_of);
            std::uint8_t shown[8] = {};
            hn::StoreMaskBits(df, hn::Not(hn::Lt(at, hn::LoadU(df, occluders + c))), shown);
            left |= (std::uint32_t(shown[0]) & wanted) << shift;
        }
    }
    return left;
#endif
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "buffer/buffer_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(OccludeeRow);
HWY_EXPORT(SampleDepthUnhidden);

void resolve_occludee_row_kernels(const IsaChoice& choice, BufferKernels& k) {
    k.occludee_row = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, OccludeeRow);
    k.sample_depth_unhidden = choice.scalar ? &sample_depth_unhidden_reference : HOMCULL_KERNEL_FOR(choice, SampleDepthUnhidden);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
