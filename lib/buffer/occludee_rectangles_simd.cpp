// The bounding rectangles of a batch of occludee triangles, a triangle per double lane, for the
// pass-over of OcclusionBuffer::test_triangles (occludee_rectangles.hpp). Each lane's rectangle
// holds the one count_triangle's outer_bounds would make of its triangle, at a depth no farther:
// the same formulas (the rounding bound of the input, the vertices' slack, the padded bounding
// box, the nearest vertex raised), each widened by far more than the few roundings by which lane
// arithmetic may differ from the one-triangle code.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "buffer/occludee_rectangles_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "buffer/occludee_rectangles.hpp"
#include "common/float_outward-inl.h"
#include "common/lane_bits-inl.h"
#include "raster/triangle_setup.hpp"

#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET != HWY_SCALAR
using D = hn::CappedTag<double, 8>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// sample_span of lanes: [ceil(lo - 0.5), floor(hi - 0.5)] within [0, count - 1], the bounds
// first clamped to [-1, count + 1] (sample_span's clamp, so that the conversions stay in range).
HWY_INLINE void SampleSpans(D d, V lo, V hi, int count, hn::Vec<hn::Rebind<std::int32_t, D>>& first,
                            hn::Vec<hn::Rebind<std::int32_t, D>>& last) {
    const hn::Rebind<std::int32_t, D> di;
    const V low = hn::Set(d, -1.0), top = hn::Set(d, double(count) + 1.0), half = hn::Set(d, 0.5);
    lo = hn::Min(hn::Max(lo, low), top);
    hi = hn::Min(hn::Max(hi, low), top);
    first = hn::Max(hn::DemoteTo(di, hn::Ceil(hn::Sub(lo, half))), hn::Zero(di));
    last = hn::Min(hn::DemoteTo(di, hn::Floor(hn::Sub(hi, half))), hn::Set(di, count - 1));
}

#endif  // HWY_TARGET != HWY_SCALAR

std::uint32_t OccludeeRectangles(const TriangleBatch& batch, int count, const OccludeeRectangleParams& p, RectQuery* rects) {
#if HWY_TARGET == HWY_SCALAR  // one lane: none ready, each triangle goes through the one-triangle pass-over
    (void)batch, (void)count, (void)p, (void)rects;
    return 0;
#else
    const D d;
    const hn::Rebind<std::int32_t, D> di;
    const hn::Rebind<float, D> df;
    const int lanes = int(hn::Lanes(d));
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
    const V infinity = hn::Set(d, HUGE_VAL), guard = hn::Set(d, kGuardBand), near_w = hn::Set(d, p.near_w);
    const V half_width = hn::Set(d, 0.5 * p.sample_width), half_height = hn::Set(d, 0.5 * p.sample_height);
    const V error_scale = hn::Set(d, 0x1.0p-22 * (1.0 + 0x1.0p-30));  // clip_error's 2^-22, widened
    // No arrays of vectors (SVE's are sizeless): the matrix entries and the clip coordinates are
    // broadcast or loaded where used.
    const auto entry = [&](int i) { return hn::Set(d, double(p.matrix[i])); };
    std::uint32_t ready = 0;
    alignas(64) std::int32_t i0[8], i1[8], j0[8], j1[8];
    alignas(64) float d_near[8];
    for (int g = 0; g < count; g += lanes) {
        const std::uint8_t index_bits[8] = {std::uint8_t(batch.indices_valid >> g)};
        M usable = hn::And(hn::FirstN(d, std::size_t(count - g)), hn::LoadMaskBits(d, index_bits));
        const auto cx = [&](int k) { return hn::Load(d, batch.cx[k] + g); };
        const auto cy = [&](int k) { return hn::Load(d, batch.cy[k] + g); };
        const auto cw = [&](int k) { return hn::Load(d, batch.cw[k] + g); };
        // clip_error: per vertex 2^-22 sum_i |m_ri p_i| of rows x, y, w; the largest over the vertices.
        V ex = zero, ey = zero, ew = zero, min_w = infinity, extent = zero;
        for (int k = 0; k < 3; ++k) {
            const V px = hn::Load(d, batch.px[k] + g), py = hn::Load(d, batch.py[k] + g), pz = hn::Load(d, batch.pz[k] + g),
                    pw = hn::Load(d, batch.pw[k] + g);
            const auto magnitude = [&](int row) {
                V s = hn::Abs(hn::Mul(entry(row), px));
                s = hn::Add(s, hn::Abs(hn::Mul(entry(4 + row), py)));
                s = hn::Add(s, hn::Abs(hn::Mul(entry(8 + row), pz)));
                return hn::Add(s, hn::Abs(hn::Mul(entry(12 + row), pw)));
            };
            ex = hn::Max(ex, hn::Mul(error_scale, magnitude(0)));
            ey = hn::Max(ey, hn::Mul(error_scale, magnitude(1)));
            ew = hn::Max(ew, hn::Mul(error_scale, magnitude(3)));
            const V x = cx(k), y = cy(k), w = cw(k);
            // What the one-triangle code sets up without clipping (needs_clipping and
            // too_large_to_clip false at its near plane, which lies below near_w), finite, and
            // with depths far from float's denormals. Finiteness is tested coordinate by
            // coordinate: Max and Min of a NaN give either operand, depending on the instruction
            // set, and every comparison below is one a NaN fails.
            usable = hn::And(usable, hn::And(hn::IsFinite(x), hn::And(hn::IsFinite(y), hn::IsFinite(w))));
            const V vertex_extent = hn::Max(hn::Max(hn::Abs(x), hn::Abs(y)), hn::Abs(w));
            usable = hn::And(usable, hn::Gt(w, near_w));
            usable = hn::And(usable, hn::And(hn::Le(hn::Abs(x), hn::Mul(guard, w)), hn::Le(hn::Abs(y), hn::Mul(guard, w))));
            usable = hn::And(usable, hn::Lt(w, hn::Set(d, 0x1.0p100)));
            min_w = hn::Min(min_w, w);
            extent = hn::Max(extent, vertex_extent);
        }
        usable = hn::And(usable, hn::Le(extent, hn::Mul(hn::Set(d, 0x1.0p28), min_w)));
        // shows() places its near plane at near_w (1 - 2^-20) - error.w and answers visible
        // where that is not above zero (the rounding too large to reason with): such lanes are
        // left to it. The error here is at least error.w; its margin covers the roundings.
        // (A second guard only: Max may drop a NaN term. A non-finite model coordinate makes
        // clip x NaN, which the vertex checks above catch.)
        usable = hn::And(usable, hn::And(hn::IsFinite(ew), hn::And(hn::IsFinite(ex), hn::IsFinite(ey))));
        usable = hn::And(usable, hn::Lt(hn::Mul(ew, hn::Set(d, 1.0 + 0x1.0p-20)), hn::Set(d, p.near_w * (1.0 - 0x1.0p-19))));
        // project_to_samples and vertex_slack, lane by lane.
        V min_x = infinity, max_x = hn::Neg(infinity), min_y = infinity, max_y = hn::Neg(infinity);
        V slack_x = zero, slack_y = zero, w_relative = zero, d_max = zero;
        for (int k = 0; k < 3; ++k) {
            const V inv_w = hn::Div(one, hn::IfThenElse(usable, cw(k), one));
            const V ndc_x = hn::Mul(cx(k), inv_w), ndc_y = hn::Mul(cy(k), inv_w);
            const V sx = hn::Mul(hn::Mul(hn::Add(ndc_x, one), half), hn::Set(d, double(p.sample_width)));
            const V sy = hn::Mul(hn::Mul(hn::Sub(one, ndc_y), half), hn::Set(d, double(p.sample_height)));
            min_x = hn::Min(min_x, sx), max_x = hn::Max(max_x, sx), min_y = hn::Min(min_y, sy), max_y = hn::Max(max_y, sy);
            slack_x = hn::Max(slack_x, hn::Mul(hn::Mul(hn::Add(ex, hn::Mul(hn::Abs(ndc_x), ew)), inv_w), half_width));
            slack_y = hn::Max(slack_y, hn::Mul(hn::Mul(hn::Add(ey, hn::Mul(hn::Abs(ndc_y), ew)), inv_w), half_height));
            w_relative = hn::Max(w_relative, hn::Mul(ew, inv_w));
            d_max = hn::Max(d_max, inv_w);
        }
        // The pads, and a margin for the roundings: 2^-30 of the slack, 2^-40 of the coordinates.
        const V widen = hn::Set(d, 1.0 + 0x1.0p-30), tiny = hn::Set(d, 0x1.0p-40);
        const V pad_x = hn::Add(hn::Mul(slack_x, widen), hn::Set(d, p.edge_margin)), pad_y = hn::Add(hn::Mul(slack_y, widen), hn::Set(d, p.edge_margin));
        const auto outward = [&](V v, V pad, bool up) {
            const V room = hn::Add(pad, hn::Mul(tiny, hn::Add(hn::Add(hn::Abs(v), pad), one)));
            return up ? hn::Add(v, room) : hn::Sub(v, room);
        };
        // Lanes not usable may hold NaN here: zero, so that no conversion sees one.
        const auto bound = [&](V v, V pad, bool up) { return hn::IfThenElseZero(usable, outward(v, pad, up)); };
        hn::Vec<decltype(di)> first_x, last_x, first_y, last_y;
        SampleSpans(d, bound(min_x, pad_x, false), bound(max_x, pad_x, true), p.sample_width, first_x, last_x);
        SampleSpans(d, bound(min_y, pad_y, false), bound(max_y, pad_y, true), p.sample_height, first_y, last_y);
        hn::Store(first_x, di, i0), hn::Store(last_x, di, i1), hn::Store(first_y, di, j0), hn::Store(last_y, di, j1);
        // The nearest vertex raised: float_up(z_vertex_max) * float_up(1 + 2^-20 + w_relative),
        // rounded up, is below this by far more than those three roundings (each 2^-23 at most).
        const V raise = hn::Mul(hn::Add(hn::Add(one, hn::Set(d, 0x1.0p-20)), hn::Mul(w_relative, widen)), hn::Set(d, 1.0 + 0x1.0p-19));
        hn::Store(FloatOutward<true>(d, hn::IfThenElseZero(usable, hn::Mul(d_max, raise))), df, d_near);
        const std::uint32_t bits = LaneBits(d, usable);
        for (int k = 0; k < lanes && g + k < count; ++k)
            if ((bits >> k) & 1u) rects[g + k] = RectQuery{i0[k], i1[k], j0[k], j1[k], d_near[k]};
        ready |= bits << g;
    }
    return ready;
#endif
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "buffer/buffer_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(OccludeeRectangles);

void resolve_occludee_rectangle_kernel(const IsaChoice& choice, BufferKernels& k) {
    k.occludee_rectangles = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, OccludeeRectangles);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
