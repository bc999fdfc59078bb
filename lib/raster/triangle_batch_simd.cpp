// The SIMD kernel of the setup front end (triangle_batch.hpp): a batch's triangles as double
// lanes (2 on SSE4 and NEON, 4 on AVX2, 8 on AVX-512), each lane computing exactly what
// classify_triangle_batch_reference computes for it: transform_to_clip's products and sums in
// the same order (no fused multiply-add), then the comparisons of outside_frustum,
// too_large_to_clip, needs_clipping, homogeneous_det and facing_away, which are exact.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/triangle_batch_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/triangle_batch.hpp"

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void ClassifyTriangleBatch(const TriangleInput& in, double near_w, int count, TriangleBatch& batch, RasterStats& stats) {
    const hn::CappedTag<double, 8> d;  // at most 8 lanes: one byte of mask bits per group
    using V = hn::Vec<decltype(d)>;
    using M = hn::Mask<decltype(d)>;
    const int lanes = int(hn::Lanes(d));
    const std::array<float, 16>& m = in.model_to_clip;
    const V near = hn::Set(d, near_w), guard = hn::Set(d, kGuardBand), infinity = hn::Set(d, HUGE_VAL);
    const V zero = hn::Zero(d), limit = hn::Set(d, 0x1.0p28);
    // transform_to_clip's row: ((m[row] x + m[4 + row] y) + m[8 + row] z) + m[12 + row] w.
    auto row = [&](int r, V x, V y, V z, V w) {
        return hn::Add(hn::Add(hn::Add(hn::Mul(hn::Set(d, double(m[r])), x), hn::Mul(hn::Set(d, double(m[4 + r])), y)),
                               hn::Mul(hn::Set(d, double(m[8 + r])), z)),
                       hn::Mul(hn::Set(d, double(m[12 + r])), w));
    };
    batch.needs_setup = 0;
    for (int g = 0; g < count; g += lanes) {
        const M live = hn::FirstN(d, std::size_t(count - g));
        M finite = hn::FirstN(d, std::size_t(lanes)), behind = finite, right = finite, left = finite, above = finite,
          below = finite, needs_clip = hn::Not(finite);
        V extent = zero, min_w = infinity;
        for (int k = 0; k < 3; ++k) {
            const V px = hn::Load(d, batch.px[k] + g), py = hn::Load(d, batch.py[k] + g), pz = hn::Load(d, batch.pz[k] + g),
                    pw = hn::Load(d, batch.pw[k] + g);
            const V x = row(0, px, py, pz, pw), y = row(1, px, py, pz, pw), w = row(3, px, py, pz, pw);
            hn::Store(x, d, batch.cx[k] + g);
            hn::Store(y, d, batch.cy[k] + g);
            hn::Store(row(2, px, py, pz, pw), d, batch.cz[k] + g);
            hn::Store(w, d, batch.cw[k] + g);
            const V ax = hn::Abs(x), ay = hn::Abs(y);
            finite = hn::And(finite, hn::And(hn::And(hn::Lt(ax, infinity), hn::Lt(ay, infinity)), hn::Lt(hn::Abs(w), infinity)));
            behind = hn::And(behind, hn::Lt(w, near));  // outside_frustum
            right = hn::And(right, hn::Gt(x, w));       // outside_side_plane
            left = hn::And(left, hn::Lt(x, hn::Neg(w)));
            above = hn::And(above, hn::Gt(y, w));
            below = hn::And(below, hn::Lt(y, hn::Neg(w)));
            extent = hn::Max(extent, hn::Max(ax, ay));  // too_large_to_clip (max and min are exact)
            min_w = hn::Min(min_w, w);
            const V band = hn::Mul(guard, w);  // needs_clipping
            needs_clip = hn::Or(needs_clip, hn::Or(hn::Lt(w, near), hn::Or(hn::Gt(ax, band), hn::Gt(ay, band))));
        }
        // The clip coordinates back from the batch (SVE vectors cannot be array elements).
        const V x0 = hn::Load(d, batch.cx[0] + g), x1 = hn::Load(d, batch.cx[1] + g), x2 = hn::Load(d, batch.cx[2] + g);
        const V y0 = hn::Load(d, batch.cy[0] + g), y1 = hn::Load(d, batch.cy[1] + g), y2 = hn::Load(d, batch.cy[2] + g);
        const V w0 = hn::Load(d, batch.cw[0] + g), w1 = hn::Load(d, batch.cw[1] + g), w2 = hn::Load(d, batch.cw[2] + g);
        const M outside = hn::Or(behind, hn::Or(hn::Or(right, left), hn::Or(above, below)));
        const M too_large = hn::Gt(extent, hn::Mul(limit, hn::Max(near, min_w)));
        // homogeneous_det(v0, v1, v2), plus 0.0 as setup_clip_triangle sums it.
        const V det = hn::Add(zero, hn::Add(hn::Sub(hn::Mul(x0, hn::Sub(hn::Mul(y1, w2), hn::Mul(w1, y2))),
                                                    hn::Mul(y0, hn::Sub(hn::Mul(x1, w2), hn::Mul(w1, x2)))),
                                            hn::Mul(w0, hn::Sub(hn::Mul(x1, y2), hn::Mul(y1, x2)))));
        const M ccw = hn::Gt(det, zero);
        M away = hn::FirstN(d, 0);  // facing_away: nothing with Backface::none
        if (in.backface == Backface::cw) away = hn::Not(ccw);
        else if (in.backface == Backface::ccw) away = ccw;

        // The fates in unclipped_fate's order of precedence, each live lane in exactly one.
        const std::uint8_t index_bits[8] = {std::uint8_t(batch.indices_valid >> g)};  // lanes <= 8
        const M invalid = hn::And(live, hn::Not(hn::And(finite, hn::LoadMaskBits(d, index_bits))));
        const M valid = hn::AndNot(invalid, live);
        const M out = hn::And(valid, outside);
        const M open = hn::AndNot(hn::Or(outside, hn::Or(too_large, needs_clip)), valid);  // neither decided nor set up
        const M degenerate = hn::And(open, hn::Eq(det, zero));
        const M backfacing = hn::And(hn::AndNot(degenerate, open), away);
        stats.invalid += hn::CountTrue(d, invalid);
        stats.outside += hn::CountTrue(d, out);
        stats.degenerate += hn::CountTrue(d, degenerate);
        stats.backface_culled += hn::CountTrue(d, backfacing);
        std::uint8_t setup_bits[8] = {};
        hn::StoreMaskBits(d, hn::AndNot(hn::Or(hn::Or(invalid, out), hn::Or(degenerate, backfacing)), live), setup_bits);
        batch.needs_setup |= std::uint32_t(setup_bits[0]) << g;
    }
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace homcull::detail {

HWY_EXPORT(ClassifyTriangleBatch);

namespace {
void dispatch_classify(const TriangleInput& in, double near_w, int count, TriangleBatch& batch, RasterStats& stats) {
    HWY_DYNAMIC_DISPATCH(ClassifyTriangleBatch)(in, near_w, count, batch, stats);
}
}  // namespace

ClassifyBatchKernel selected_classify_kernel() {
    return scalar_reference_selected() ? &classify_triangle_batch_reference : &dispatch_classify;
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
