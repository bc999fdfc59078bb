// margin_free_edges (shared_edge_rule.hpp) in double lanes, one triangle a lane: the same
// products, sums, comparisons and divisions in the same order (no fused multiply-add; the layer
// is built with -ffp-contract=off), so each lane decides exactly what the scalar rule decides.
// The scalar rule was a third of the render of the castle's clustered occluders: about 36 ns a
// triangle of branches and dependent double arithmetic.
//
// The scalar corner loop visits corners 0, 1, 2 in turn and drops both edges at a corner that
// fails, until a pass drops nothing; the lanes run the same passes, corner by corner, each lane
// with its own kept edges, until no lane drops anything. Every pass of a lane that has stopped
// changing leaves it as it is, as another scalar pass would.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/shared_edge_rule_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/shared_edge_rule.hpp"

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<double, 8>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// Vectors live in named variables or in memory (HWY_ALIGN arrays, reloaded where used): SVE's
// sizeless vectors cannot be array elements or members (scripts/check-neon.sh).

// homogeneous_det(a, b, c), its order of operations (w in the place of z).
HWY_INLINE V Det(V ax, V ay, V aw, V bx, V by, V bw, V cx, V cy, V cw) {
    const V t0 = hn::Mul(ax, hn::Sub(hn::Mul(by, cw), hn::Mul(bw, cy)));
    const V t1 = hn::Mul(ay, hn::Sub(hn::Mul(bx, cw), hn::Mul(bw, cx)));
    const V t2 = hn::Mul(aw, hn::Sub(hn::Mul(bx, cy), hn::Mul(by, cx)));
    return hn::Add(hn::Sub(t0, t1), t2);
}

// certain_sign(det, homogeneous_det_magnitude(a, b, c)).
HWY_INLINE M CertainSign(D d, V det, V ax, V ay, V aw, V bx, V by, V bw, V cx, V cy, V cw) {
    V m = hn::Abs(hn::Mul(hn::Mul(ax, by), cw));
    m = hn::Add(m, hn::Abs(hn::Mul(hn::Mul(ax, bw), cy)));
    m = hn::Add(m, hn::Abs(hn::Mul(hn::Mul(ay, bx), cw)));
    m = hn::Add(m, hn::Abs(hn::Mul(hn::Mul(ay, bw), cx)));
    m = hn::Add(m, hn::Abs(hn::Mul(hn::Mul(aw, bx), cy)));
    m = hn::Add(m, hn::Abs(hn::Mul(hn::Mul(aw, by), cx)));
    return hn::Gt(hn::Abs(det), hn::Mul(hn::Set(d, 0x1.0p-40), m));
}

// glm::dot of a 2-vector with itself: the products, then their sum.
HWY_INLINE V Length2(V x, V y) { return hn::Add(hn::Mul(x, x), hn::Mul(y, y)); }

// The rule's `above`: cross(a, b)^2 > bound2 (|a|^2 |b|^2).
HWY_INLINE M Above(V ax, V ay, V a_length2, V bx, V by, V bound2) {
    const V cross = hn::Sub(hn::Mul(ax, by), hn::Mul(ay, bx));
    return hn::Gt(hn::Mul(cross, cross), hn::Mul(bound2, hn::Mul(a_length2, Length2(bx, by))));
}

// std::max(a, b) as the scalar rule takes it: (a < b) ? b : a.
HWY_INLINE V MaxAsStd(V a, V b) { return hn::IfThenElse(hn::Lt(a, b), b, a); }

// Masks kept in memory as 1.0 / 0.0 per lane.
HWY_INLINE void StoreMask(D d, M m, double* to) { hn::Store(hn::IfThenElseZero(m, hn::Set(d, 1.0)), d, to); }
HWY_INLINE M LoadMask(D d, const double* from) { return hn::Gt(hn::Load(d, from), hn::Zero(d)); }

void MarginFreeEdges(const MarginFreeLanes& lanes, double near_w, double edge_margin, int sample_width, int sample_height,
                     std::uint8_t* kept_out) {
    const D d;
    const int N = int(hn::Lanes(d));
    const V width = hn::Set(d, double(sample_width)), height = hn::Set(d, double(sample_height));
    const double delta = 0x1.0p-36 * double(sample_width + sample_height);
    const double thin_end = 4.0 * delta / edge_margin;
    const V thin_bound2 = hn::Set(d, thin_end * thin_end), nine_delta2 = hn::Set(d, 9.0 * delta * delta);
    const V near = hn::Set(d, near_w), guard = hn::Set(d, kGuardBand), half = hn::Set(d, 0.5), one = hn::Set(d, 1.0);
    for (int g = 0; g < lanes.count; g += N) {
        bool asked = false;
        for (int t = 0; t < N; ++t) asked = asked || lanes.flags[g + t] != 0;
        if (!asked) {
            for (int t = 0; t < N && g + t < lanes.count; ++t) kept_out[g + t] = 0;
            continue;
        }
        const auto ox = [&](int k) { return hn::Load(d, lanes.ox[k] + g); };
        const auto oy = [&](int k) { return hn::Load(d, lanes.oy[k] + g); };
        const auto ow = [&](int k) { return hn::Load(d, lanes.ow[k] + g); };
        const auto ax = [&](int k) { return hn::Load(d, lanes.ax[k] + g); };
        const auto ay = [&](int k) { return hn::Load(d, lanes.ay[k] + g); };
        const auto aw = [&](int k) { return hn::Load(d, lanes.aw[k] + g); };
        // Each lane's flags, then its kept edges, as 1.0 / 0.0 per edge k.
        HWY_ALIGN double kept[3][8] = {};
        for (int t = 0; t < N; ++t)
            for (int k = 0; k < 3; ++k) kept[k][t] = (lanes.flags[g + t] >> k) & 1u ? 1.0 : 0.0;
        const V own_det = Det(ox(0), oy(0), ow(0), ox(1), oy(1), ow(1), ox(2), oy(2), ow(2));
        const M own_certain = CertainSign(d, own_det, ox(0), oy(0), ow(0), ox(1), oy(1), ow(1), ox(2), oy(2), ow(2));
        const M own_positive = hn::Gt(own_det, hn::Zero(d));
        for (int k = 0; k < 3; ++k) {
            const int a = k, b = (k + 1) % 3;  // the neighbour runs from own[k + 1] to own[k] to its apex
            const V det = Det(ox(b), oy(b), ow(b), ox(a), oy(a), ow(a), ax(k), ay(k), aw(k));
            const M across = hn::And(hn::Not(hn::Xor(own_positive, hn::Gt(det, hn::Zero(d)))),
                                     CertainSign(d, det, ox(b), oy(b), ow(b), ox(a), oy(a), ow(a), ax(k), ay(k), aw(k)));
            StoreMask(d, hn::And(hn::And(LoadMask(d, kept[k]), own_certain), across), kept[k]);
        }
        // The edges' screen directions (screen_direction(own[k], own[k + 1])) and squared lengths.
        HWY_ALIGN double edge_x[3][8], edge_y[3][8], edge_length2[3][8];
        for (int k = 0; k < 3; ++k) {
            const int b = (k + 1) % 3;
            const V ex = hn::Mul(hn::Sub(hn::Mul(ox(b), ow(k)), hn::Mul(ox(k), ow(b))), width);
            const V ey = hn::Mul(hn::Sub(hn::Mul(oy(b), ow(k)), hn::Mul(oy(k), ow(b))), height);
            hn::Store(ex, d, edge_x[k]), hn::Store(ey, d, edge_y[k]), hn::Store(Length2(ex, ey), d, edge_length2[k]);
        }
        // Per corner: whether it lies inside the near plane and the guard band (else it is
        // skipped), and its bound with two margin-free edges (from its clearance from the
        // nearest sample centre).
        HWY_ALIGN double corner_in[3][8], two_edge_bound2[3][8];
        for (int k = 0; k < 3; ++k) {
            const V vx = ox(k), vy = oy(k), vw = ow(k);
            const V reach = hn::Mul(guard, vw);
            StoreMask(d, hn::And(hn::Ge(vw, near), hn::And(hn::Le(hn::Abs(vx), reach), hn::Le(hn::Abs(vy), reach))), corner_in[k]);
            const V inv_w = hn::Div(one, vw);
            const V x = hn::Mul(hn::Mul(hn::Add(hn::Mul(vx, inv_w), one), half), width);
            const V y = hn::Mul(hn::Mul(hn::Sub(one, hn::Mul(vy, inv_w)), half), height);
            const V cx = hn::Abs(hn::Sub(x, hn::Add(hn::Floor(x), half))), cy = hn::Abs(hn::Sub(y, hn::Add(hn::Floor(y), half)));
            const V clearance = MaxAsStd(cx, cy);
            hn::Store(hn::Div(nine_delta2, hn::Mul(clearance, clearance)), d, two_edge_bound2[k]);
        }
        for (bool changed = true; changed;) {
            changed = false;
            for (int k = 0; k < 3; ++k) {
                const int out = k, in = (k + 2) % 3;
                const M keeps_out = LoadMask(d, kept[out]), keeps_in = LoadMask(d, kept[in]);
                const M active = hn::And(hn::Or(keeps_out, keeps_in), LoadMask(d, corner_in[k]));
                if (hn::AllFalse(d, active)) continue;
                const V bound2 = hn::IfThenElse(hn::And(keeps_out, keeps_in), hn::Load(d, two_edge_bound2[k]), thin_bound2);
                const V out_x = hn::Load(d, edge_x[out]), out_y = hn::Load(d, edge_y[out]), out_length2 = hn::Load(d, edge_length2[out]);
                const V in_x = hn::Load(d, edge_x[in]), in_y = hn::Load(d, edge_y[in]), in_length2 = hn::Load(d, edge_length2[in]);
                M keep = Above(out_x, out_y, out_length2, in_x, in_y, bound2);
                // screen_direction(own[k], apex[out]) and (own[k], apex[in]).
                const V vx = ox(k), vy = oy(k), vw = ow(k);
                const V po_x = hn::Mul(hn::Sub(hn::Mul(ax(out), vw), hn::Mul(vx, aw(out))), width);
                const V po_y = hn::Mul(hn::Sub(hn::Mul(ay(out), vw), hn::Mul(vy, aw(out))), height);
                keep = hn::And(keep, hn::Or(hn::Not(keeps_out), Above(out_x, out_y, out_length2, po_x, po_y, bound2)));
                const V pi_x = hn::Mul(hn::Sub(hn::Mul(ax(in), vw), hn::Mul(vx, aw(in))), width);
                const V pi_y = hn::Mul(hn::Sub(hn::Mul(ay(in), vw), hn::Mul(vy, aw(in))), height);
                keep = hn::And(keep, hn::Or(hn::Not(keeps_in), Above(in_x, in_y, in_length2, pi_x, pi_y, bound2)));
                const M drop = hn::AndNot(keep, active);
                if (hn::AllFalse(d, drop)) continue;
                StoreMask(d, hn::AndNot(drop, keeps_out), kept[out]);
                StoreMask(d, hn::AndNot(drop, LoadMask(d, kept[in])), kept[in]);
                changed = true;
            }
        }
        for (int t = 0; t < N && g + t < lanes.count; ++t)
            kept_out[g + t] = std::uint8_t((kept[0][t] > 0.0 ? 1u : 0u) | (kept[1][t] > 0.0 ? 2u : 0u) | (kept[2][t] > 0.0 ? 4u : 0u));
    }
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/raster_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(MarginFreeEdges);

MarginFreeKernel margin_free_kernel_for(const IsaChoice& choice) {
    return choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, MarginFreeEdges);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
