// SIMD kernels of the row loop (coverage intervals of a subtile row's 4 sample rows as lanes)
// and of the subtile-row update (subtiles as lanes), compiled once per instruction set with
// Google Highway and chosen at run time. Each lane computes exactly what the reference
// (rasterize_rows_reference, update_subtile_row_reference) computes for it: the same double and float operations in the
// same order (no fused multiply-add), so every target gives the reference's bits. Subtiles go
// in blocks of as many lanes as a double vector has (2 on SSE4, 4 on AVX2, 8 on AVX-512), with
// the int32 and float vectors rebound to that lane count.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/rasterize_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/rasterize.hpp"

#include <algorithm>
#include <cstring>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kMaxLanes = 16;  // the tail buffer below; CappedTag keeps wide (SVE) vectors within it

std::uint64_t UpdateSubtileRow(OcclusionBuffer::Subtile* row, int ty, int tx_begin, int tx_end, const std::int32_t first[4],
                               const std::int32_t last[4], const PreparedTriangle& tri, int sample_width, int sample_height) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    const hn::CappedTag<double, kMaxLanes> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<std::int32_t, decltype(dd)> di;
    const hn::Rebind<std::uint32_t, decltype(dd)> du;
    const int lanes = int(hn::Lanes(dd));
    using VI = hn::Vec<decltype(di)>;
    using VU = hn::Vec<decltype(du)>;

    // The valid-sample mask of this subtile row's subtiles: all ones but in the last column
    // and the last row of subtiles (see valid_sample_mask).
    const int rows = std::min(kH, sample_height - ty * kH);
    std::uint32_t replicate = 0;
    for (int j = 0; j < rows; ++j) replicate |= 1u << (j * kW);

    std::uint64_t touched = 0;
    OcclusionBuffer::Subtile tail[kMaxLanes];  // partial blocks at the end of the range
    for (int tx = tx_begin; tx <= tx_end; tx += lanes) {
        const int n = std::min(lanes, tx_end - tx + 1);
        OcclusionBuffer::Subtile* block = row + tx;
        if (n < lanes) {
            std::memcpy(tail, block, sizeof(OcclusionBuffer::Subtile) * std::size_t(n));
            block = tail;
        }
        const VI column0 = hn::ShiftLeft<3>(hn::Iota(di, tx));  // tx * 8 per lane

        // Masks and the bounding rectangle of the covered samples, as the reference.
        VU m = hn::Zero(du);
        VI col_min = hn::Set(di, kW), col_max = hn::Set(di, -1), row_min = hn::Set(di, kH), row_max = hn::Set(di, -1);
        for (int j = 0; j < kH; ++j) {
            const VI lo = hn::Max(hn::Sub(hn::Set(di, first[j]), column0), hn::Zero(di));
            const VI hi = hn::Min(hn::Sub(hn::Set(di, last[j]), column0), hn::Set(di, kW - 1));
            const auto empty = hn::Gt(lo, hi);
            // Shift counts clamped to [0, 8]: only lanes with lo <= hi (both in [0, 7]) are kept.
            const VU lo_u = hn::BitCast(du, hn::Min(lo, hn::Set(di, kW)));
            const VU right = hn::BitCast(du, hn::Min(hn::Max(hn::Sub(hn::Set(di, kW - 1), hi), hn::Zero(di)), hn::Set(di, kW)));
            const VU bits = hn::And(hn::Shr(hn::Set(du, 0xFFu), right), hn::Shl(hn::Set(du, 0xFFu), lo_u));
            m = hn::Or(m, hn::ShiftLeftSame(hn::IfThenZeroElse(hn::RebindMask(du, empty), bits), j * kW));
            col_min = hn::IfThenElse(empty, col_min, hn::Min(col_min, lo));
            col_max = hn::IfThenElse(empty, col_max, hn::Max(col_max, hi));
            row_min = hn::IfThenElse(hn::AndNot(empty, hn::Eq(row_min, hn::Set(di, kH))), hn::Set(di, j), row_min);
            row_max = hn::IfThenElse(empty, row_max, hn::Set(di, j));
        }
        const auto active = hn::Ne(m, hn::Zero(du));
        if (hn::AllFalse(du, active)) {
            if (block == tail) std::memcpy(row + tx, tail, sizeof(OcclusionBuffer::Subtile) * std::size_t(n));
            continue;
        }
        touched += hn::CountTrue(du, active);

        hn::Vec<decltype(df)> d0, d1, mask_f, covered_f;
        hn::LoadInterleaved4(df, reinterpret_cast<const float*>(block), d0, d1, mask_f, covered_f);
        VU mask = hn::BitCast(du, mask_f);
        const VU covered = hn::Or(hn::BitCast(du, covered_f), m);

        // Depth bound, in double.
        const VI x_far_i = hn::Add(column0, tri.dzdx > 0.0 ? col_min : col_max);
        const VI y_far_i = hn::Add(hn::Set(di, ty * kH), tri.dzdy > 0.0 ? row_min : row_max);
        const auto half = hn::Set(dd, 0.5);
        const auto x_far = hn::Add(hn::PromoteTo(dd, x_far_i), half);
        const auto y_far = hn::Add(hn::PromoteTo(dd, y_far_i), half);
        const auto plane_min = hn::Add(hn::Add(hn::Set(dd, tri.z0), hn::Mul(hn::Set(dd, tri.dzdx), hn::Sub(x_far, hn::Set(dd, tri.x0)))),
                                       hn::Mul(hn::Set(dd, tri.dzdy), hn::Sub(y_far, hn::Set(dd, tri.y0))));
        // std::max(plane_min, z_vertex_min): plane_min unless it is smaller.
        const auto zv = hn::Set(dd, tri.z_vertex_min);
        const auto bound = hn::IfThenElse(hn::Lt(plane_min, zv), zv, plane_min);
        // conservative_far: round to float, step down one ulp if that rounded up, lower by 2^-20.
        // (The reference skips bound <= 0; here such lanes get d_tri <= 0, which never passes
        // d_tri > d0 >= 0 below. The double comparison reaches the float lanes as a demoted 0/1.)
        auto f = hn::DemoteTo(df, bound);
        const auto rounded_up_d = hn::Gt(hn::PromoteTo(dd, f), bound);
        const auto rounded_up = hn::Gt(hn::DemoteTo(df, hn::IfThenElseZero(rounded_up_d, hn::Set(dd, 1.0))), hn::Zero(df));
        f = hn::IfThenElse(rounded_up, hn::BitCast(df, hn::Sub(hn::BitCast(du, f), hn::Set(du, 1u))), f);
        const auto d_tri = hn::Mul(f, hn::Set(df, 1.0f - 0x1.0p-20f));

        const auto update = hn::And(hn::RebindMask(df, active), hn::Gt(d_tri, d0));
        // Quick mask, lane by lane as the reference.
        const auto mask_nonzero = hn::RebindMask(df, hn::Ne(mask, hn::Zero(du)));
        const auto discard = hn::And(mask_nonzero, hn::Lt(hn::Sub(hn::Mul(hn::Set(df, 2.0f), d1), hn::Add(d_tri, d0)), hn::Zero(df)));
        const VU kept = hn::IfThenZeroElse(hn::RebindMask(du, discard), mask);
        const auto kept_empty = hn::RebindMask(df, hn::Eq(kept, hn::Zero(du)));
        auto d1_new = hn::IfThenElse(kept_empty, d_tri, hn::Min(d1, d_tri));
        VU mask_new = hn::Or(kept, m);
        // Full mask per lane: all ones, or the valid samples in the last column or row.
        const VI columns = hn::Min(hn::Sub(hn::Set(di, sample_width), column0), hn::Set(di, kW));
        const VU row_bits = hn::Shr(hn::Set(du, 0xFFu), hn::BitCast(du, hn::Max(hn::Sub(hn::Set(di, kW), columns), hn::Zero(di))));
        const VU full = hn::Mul(row_bits, hn::Set(du, replicate));
        const auto promote = hn::RebindMask(df, hn::Eq(mask_new, full));
        const auto d0_new = hn::IfThenElse(promote, d1_new, d0);
        mask_new = hn::IfThenZeroElse(hn::RebindMask(du, promote), mask_new);
        d1_new = hn::IfThenZeroElse(promote, d1_new);

        d0 = hn::IfThenElse(update, d0_new, d0);
        d1 = hn::IfThenElse(update, d1_new, d1);
        mask = hn::IfThenElse(hn::RebindMask(du, update), mask_new, mask);
        hn::StoreInterleaved4(d0, d1, hn::BitCast(df, mask), hn::BitCast(df, covered), df, reinterpret_cast<float*>(block));
        if (block == tail) std::memcpy(row + tx, tail, sizeof(OcclusionBuffer::Subtile) * std::size_t(n));
    }
    return touched;
}

// The reference's row loop with the 4 sample rows of a subtile row as vector lanes (2 at a
// time on SSE4): each lane evaluates rasterize_rows_reference's formula for its row.
std::uint64_t RasterizeRows(const RasterTarget& t, const TriangleEdges& e, const PreparedTriangle& tri, int i0, int i1, int j0,
                            int j1) {
    constexpr int kH = OcclusionBuffer::kSubtileHeight;
    const hn::CappedTag<double, kH> d4;
    const hn::Rebind<std::int32_t, decltype(d4)> di4;
    const int lanes = int(hn::Lanes(d4));
    const auto lo_clamp = hn::Set(d4, double(i0) - 2.0), hi_clamp = hn::Set(d4, double(i1) + 2.0);
    const auto half = hn::Set(d4, 0.5), one = hn::Set(d4, 1.0), zero = hn::Zero(d4);
    std::uint64_t touched = 0;
    for (int ty = std::max(j0 / kH, t.row_begin); ty <= std::min(j1 / kH, t.row_end - 1); ++ty) {
        HWY_ALIGN std::int32_t first[kH], last[kH];
        for (int j = 0; j < kH; j += lanes) {
            const auto sy = hn::Iota(d4, double(ty * kH + j));
            const auto py = hn::Add(sy, half);
            auto lo = hn::Set(d4, double(i0)), hi = hn::Set(d4, double(i1));
            auto empty = hn::Or(hn::Lt(sy, hn::Set(d4, double(j0))), hn::Gt(sy, hn::Set(d4, double(j1))));
            for (int k = 0; k < 3; ++k) {
                const auto c = hn::Sub(hn::Set(d4, e.threshold[k]), hn::Mul(hn::Set(d4, e.sb[k]), hn::Sub(py, hn::Set(d4, e.oy[k]))));
                if (e.sa[k] == 0.0) {
                    empty = hn::Or(empty, e.shared[k] ? hn::Gt(c, zero) : hn::Ge(c, zero));
                    continue;
                }
                const auto x = hn::Add(hn::Set(d4, e.ox[k]), hn::Mul(c, hn::Set(d4, e.inverse_sa[k])));
                const auto v = hn::Sub(x, half);
                const auto xs = hn::IfThenElse(hn::Lt(v, lo_clamp), lo_clamp, hn::IfThenElse(hn::Lt(hi_clamp, v), hi_clamp, v));
                if (e.sa[k] > 0.0) lo = hn::Max(lo, e.shared[k] ? hn::Ceil(xs) : hn::Add(hn::Floor(xs), one));
                else hi = hn::Min(hi, e.shared[k] ? hn::Floor(xs) : hn::Sub(hn::Ceil(xs), one));
            }
            hi = hn::IfThenElse(empty, hn::Sub(lo, one), hi);
            hn::Store(hn::DemoteTo(di4, lo), di4, first + j);
            hn::Store(hn::DemoteTo(di4, hi), di4, last + j);
        }
        int tx_begin, tx_end;
        if (!reached_subtile_columns(first, last, i0, i1, tx_begin, tx_end)) continue;
        touched += UpdateSubtileRow(t.subtiles + std::size_t(ty) * std::size_t(t.subtiles_x), ty, tx_begin, tx_end, first, last, tri,
                                    t.sample_width, t.sample_height);
    }
    return touched;
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <homcull/error.hpp>

#include <atomic>
#include <string>

namespace homcull {
namespace detail {

HWY_EXPORT(RasterizeRows);

namespace {

// The selected kernel: the reference, or Highway's choice among the allowed targets.
std::atomic<bool> use_reference{false};

std::uint64_t dispatch(const RasterTarget& t, const TriangleEdges& e, const PreparedTriangle& tri, int i0, int i1, int j0, int j1) {
    return HWY_DYNAMIC_DISPATCH(RasterizeRows)(t, e, tri, i0, i1, j0, j1);
}

struct NamedTarget {
    const char* name;
    std::int64_t bits;
};
const NamedTarget kTargets[] = {{"avx512", HWY_AVX3}, {"avx2", HWY_AVX2}, {"sse4", HWY_SSE4}, {"emu128", HWY_EMU128}};

}  // namespace

TriangleRowsKernel selected_rows_kernel() { return use_reference ? &rasterize_rows_reference : &dispatch; }

}  // namespace detail

std::vector<std::string> available_isas() {
    std::vector<std::string> names = {"scalar"};
    const std::int64_t supported = hwy::SupportedTargets();
    for (const auto& t : detail::kTargets)
        if ((HWY_TARGETS & t.bits) && (supported & t.bits)) names.push_back(t.name);
    return names;
}

void select_isa(const std::string& name) {
    if (name == "scalar") {
        detail::use_reference = true;
        return;
    }
    detail::use_reference = false;
    if (name == "best") {
        hwy::SetSupportedTargetsForTest(0);  // back to what the CPU supports
        return;
    }
    for (const auto& t : detail::kTargets)
        if (name == t.name) {
            hwy::SetSupportedTargetsForTest(0);
            if (!(HWY_TARGETS & t.bits) || !(hwy::SupportedTargets() & t.bits))
                throw Error("instruction set '" + name + "' is not available on this machine or in this build");
            hwy::SetSupportedTargetsForTest(t.bits);
            return;
        }
    std::string known;
    for (const std::string& n : available_isas()) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown instruction set '" + name + "' (available: best, " + known + ")");
}

std::string selected_isa() {
    if (detail::use_reference) return "scalar";
    const std::int64_t target = hwy::SupportedTargets() & HWY_TARGETS;
    for (const auto& t : detail::kTargets)
        if (target & t.bits) return t.name;  // the best one Highway will dispatch to
    return "unknown";
}

}  // namespace homcull
#endif  // HWY_ONCE
