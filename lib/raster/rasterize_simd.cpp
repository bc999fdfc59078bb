// SIMD kernels of the row loop (coverage intervals of up to 64 sample rows, rows as lanes)
// and of the subtile-row update (subtiles as lanes, 4 on SSE4, 8 on AVX2, 16 on AVX-512),
// compiled once per instruction set with Google Highway and chosen at run time. Each lane
// computes exactly what the reference (rasterize_rows_reference, update_subtile_row_reference)
// computes for it: the same double and float operations in the same order (no fused
// multiply-add), so every target gives the reference's bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/rasterize_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "common/lane_bits-inl.h"
#include "raster/rasterize.hpp"
#include "raster/sample_depth_tiles.hpp"

#include <algorithm>
#include <limits>
#include <type_traits>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Whether this target has vectors of at least 4 lanes: every one but the scalar target, which
// updates subtiles with the reference. (Whether it updates two subtile rows per vector is
// decided at run time, from its float lanes: 16 on AVX-512, and on SVE when that wide.)
#undef HOMCULL_SUBTILE_LANES
#if HWY_TARGET == HWY_SCALAR
#define HOMCULL_SUBTILE_LANES 0
#else
#define HOMCULL_SUBTILE_LANES 1
#endif

#if HOMCULL_SUBTILE_LANES

// A plane's elements of the lanes of UpdateSubtileRows: one vector from row offset row[0],
// or a half vector from each of row[0] and row[1], or a quarter from each of row[0..3].
template <int kRows, class D, typename T>
HWY_INLINE hn::Vec<D> LoadRows(D d, const T* plane, const std::size_t* row, std::size_t tx) {
    if constexpr (kRows == 4) {
        const hn::Half<D> dh;
        const hn::Half<decltype(dh)> dq;
        return hn::Combine(d, hn::Combine(dh, hn::LoadU(dq, plane + row[3] + tx), hn::LoadU(dq, plane + row[2] + tx)),
                           hn::Combine(dh, hn::LoadU(dq, plane + row[1] + tx), hn::LoadU(dq, plane + row[0] + tx)));
    } else if constexpr (kRows == 2) {
        const hn::Half<D> dh;
        return hn::Combine(d, hn::LoadU(dh, plane + row[1] + tx), hn::LoadU(dh, plane + row[0] + tx));
    } else {
        return hn::LoadU(d, plane + row[0] + tx);
    }
}
template <int kRows, class D, typename T>
HWY_INLINE void StoreRows(hn::Vec<D> v, D d, T* plane, const std::size_t* row, std::size_t tx) {
    if constexpr (kRows == 4) {
        const hn::Half<D> dh;
        const hn::Half<decltype(dh)> dq;
        const auto lo = hn::LowerHalf(dh, v), hi = hn::UpperHalf(dh, v);
        hn::StoreU(hn::LowerHalf(dq, lo), dq, plane + row[0] + tx);
        hn::StoreU(hn::UpperHalf(dq, lo), dq, plane + row[1] + tx);
        hn::StoreU(hn::LowerHalf(dq, hi), dq, plane + row[2] + tx);
        hn::StoreU(hn::UpperHalf(dq, hi), dq, plane + row[3] + tx);
    } else if constexpr (kRows == 2) {
        const hn::Half<D> dh;
        hn::StoreU(hn::LowerHalf(dh, v), dh, plane + row[0] + tx);
        hn::StoreU(hn::UpperHalf(dh, v), dh, plane + row[1] + tx);
    } else {
        (void)d;
        hn::StoreU(v, d, plane + row[0] + tx);
    }
}

// The index (0..24) of the highest set bit of each lane of v, for v < 2^25 (as int), from the
// exponent of float(v): exact below 2^24, and rounding in [2^24, 2^25) cannot reach 2^25.
template <class DU>
HWY_INLINE hn::Vec<hn::RebindToSigned<DU>> HighestBitIndex(DU /* du */, hn::Vec<DU> v) {
    const hn::RebindToSigned<DU> di;
    const hn::RebindToFloat<DU> df;
    const auto exponent = hn::ShiftRight<23>(hn::BitCast(di, hn::ConvertTo(df, hn::BitCast(di, v))));
    return hn::Sub(exponent, hn::Set(di, 127));
}

// The index of the lowest set bit (lowest = all ones) or of the highest (lowest = zero) of
// each lane of v < 2^25: the lowest set bit alone is v & ~(v - 1).
template <class DU>
HWY_INLINE hn::Vec<hn::RebindToSigned<DU>> ExtremeBitIndex(DU du, hn::Vec<DU> v, hn::Vec<DU> lowest) {
    return HighestBitIndex(du, hn::AndNot(hn::And(hn::Sub(v, hn::Set(du, 1u)), lowest), v));
}

// The subtile-row update of kRows consecutive subtile rows ty.. (1, 2 or 4) of a triangle with
// sample columns [i0, i1], over the subtile columns its sample rows reach (as
// reached_subtile_columns, or all of the triangle's when one vector spans them; lanes without
// samples change nothing). The subtiles tx..tx + columns - 1 of each row are the vector lanes,
// float and 32-bit integer: at most 8 columns (4 on SSE4 and NEON; rows are padded for
// kMaxSimdLanes). first and last hold the rows' sample-row intervals, 4 per subtile row. Two
// rows at a time suit AVX-512's 16 lanes: S1's triangles reach about 5 subtiles per row, and
// one row in 16 lanes was 10 % slower than in 8. Four rows of 4 subtiles (one 128-bit block per
// row) suit triangles that span at most 4 subtile columns: most of the castle's, which filled
// about 4 of the 16 lanes in two rows of 8 (castle C0 1.405 -> 1.358 ms). Returns the number of
// subtiles updated (covered and in front of the reference layer).
//
// The coverage masks come from sample rows (as Intel's Masked Occlusion Culling computes them):
// before the update, lane l holds sample row l % 4 of one subtile row across 32 samples, 4
// subtiles, one bit per sample, so that each 128-bit block holds 4 sample rows x 4 subtiles,
// a 4 x 4 matrix of bytes. One byte shuffle per block transposes it into the 4 subtiles' masks
// (byte j = sample row j, bit c = column c, as subtile_coverage), in the lanes where the
// update below reads the subtiles' planes. The intervals are those of the reference, so the
// masks are its masks.
template <int kRows>
HWY_INLINE std::uint64_t UpdateSubtileRows(const SubtilePlanes& planes, int ty, const std::int32_t* first, const std::int32_t* last,
                                           int i0, int i1, const PreparedTriangle& tri, int sample_width, int sample_height) {
    static_assert(kRows == 1 || kRows == 2 || kRows == 4, "one, two or four subtile rows");
    constexpr int kW = kSubtileWidth, kH = kSubtileHeight;
    // The byte transpose below takes subtiles of 4 rows of 8 samples (a byte per sample row),
    // 4 of them (32 samples) per 128-bit block.
    static_assert(kW == 8 && kH == 4, "the transpose assumes 8 x 4 subtiles");
    constexpr int kSubtilesPerBlock = 4;
    // Rows of 8 subtiles; four rows take 4 subtiles each (one 128-bit block per row).
    const hn::CappedTag<float, kRows == 4 ? 16 : 8 * kRows> df;
    const hn::RebindToSigned<decltype(df)> di;
    const hn::RebindToUnsigned<decltype(df)> du;
    const hn::Repartition<std::uint8_t, decltype(du)> du8;
    const int row_lanes = int(hn::Lanes(df)) / kRows;
    using VI = hn::Vec<decltype(di)>;
    using VU = hn::Vec<decltype(du)>;
    using VF = hn::Vec<decltype(df)>;

    // Highway's Iota goes through memory (a store-forwarding stall per call): built once.
    const VI lane = hn::Iota(di, 0);
    const VI lane_column = kRows == 1 ? lane : hn::And(lane, hn::Set(di, row_lanes - 1));
    // The lane's subtile row, from ty: lane / row_lanes (row_lanes = 8 with two rows, 4 with four).
    const VI lane_row = kRows == 4 ? hn::ShiftRight<2>(lane) : kRows == 2 ? hn::VecFromMask(di, hn::Gt(lane, hn::Set(di, row_lanes - 1))) : hn::Zero(di);
    const VI row_of_lane = kRows == 2 ? hn::Neg(lane_row) : lane_row;  // VecFromMask gives -1
    const VI row_y = hn::Add(hn::Set(di, ty * kH), hn::ShiftLeft<2>(row_of_lane));  // kH = 4

    // The valid-sample mask of each row's subtiles (see valid_sample_mask): all ones except in
    // the last column and the last row of subtiles, as (row bits of the lane's columns) x
    // (one bit per existing row: 1 to 4, each subtile row has one).
    const VI rows_existing = hn::Min(hn::Sub(hn::Set(di, sample_height), row_y), hn::Set(di, kH));
    const VU replicate_v = hn::Shr(hn::Set(du, 0x01010101u), hn::BitCast(du, hn::ShiftLeft<3>(hn::Sub(hn::Set(di, kH), rows_existing))));

    // Before the transpose, lane l is sample row l % 4 of its subtile row: each subtile row's
    // 4 intervals repeated in every block of its lanes, by 128-bit loads that lie within one
    // store of the row pass (a wider load across two of its stores waited for them to retire:
    // no store forwarding).
    const auto row_intervals = [&](const std::int32_t* rows) {
        if constexpr (kRows == 4) {  // a block per row: its 4 intervals, one 128-bit load each
            const hn::Half<decltype(di)> dh;
            const hn::Half<decltype(dh)> dq;
            return hn::Combine(di, hn::Combine(dh, hn::LoadU(dq, rows + 3 * kH), hn::LoadU(dq, rows + 2 * kH)),
                               hn::Combine(dh, hn::LoadU(dq, rows + kH), hn::LoadU(dq, rows)));
        } else if constexpr (kRows == 2) {
            const hn::Half<decltype(di)> dh;
            return hn::Combine(di, hn::LoadDup128(dh, rows + kH), hn::LoadDup128(dh, rows));
        }
        return hn::LoadDup128(di, rows);
    };
    const VI first_v = row_intervals(first), last_v = row_intervals(last);
    // The subtile columns: the triangle's, when one vector spans them; else those the rows
    // reach (reached_subtile_columns: the intervals lie within the triangle's columns [i0, i1],
    // so their extremes bound its subtiles too).
    const auto row_empty = hn::Gt(first_v, last_v);
    if (hn::AllTrue(di, row_empty)) return 0;
    int tx_begin = i0 / kW, tx_end = i1 / kW;
    if (tx_end - tx_begin >= row_lanes) {
        tx_begin = hn::GetLane(hn::MinOfLanes(di, hn::IfThenElse(row_empty, hn::Set(di, 1 << 30), first_v))) / kW;
        tx_end = hn::GetLane(hn::MaxOfLanes(di, hn::IfThenElse(row_empty, hn::Set(di, -1), last_v))) / kW;
    }
    // The first sample of a lane's 32, relative to tx * 8: its block's first subtile column.
    const VI block_sample = hn::ShiftLeft<3>(hn::AndNot(hn::Set(di, kSubtilesPerBlock - 1), lane_column));
    // Byte 4c + j of a block takes byte 4j + c: dword c = 0x0C080400 + c * 0x01010101.
    const VU transpose = hn::BitCast(
        du, hn::Add(hn::Set(di, 0x0C080400), hn::Mul(hn::And(lane, hn::Set(di, kSubtilesPerBlock - 1)), hn::Set(di, 0x01010101))));

    std::size_t row[kRows];
    for (int r = 0; r < kRows; ++r) row[r] = std::size_t(ty + r) * planes.stride;
    const auto load = [&](auto d, const auto* plane, std::size_t tx) { return LoadRows<kRows>(d, plane, row, tx); };
    const auto store = [&](auto v, auto d, auto* plane, std::size_t tx) { StoreRows<kRows>(v, d, plane, row, tx); };
    const VI zero_i = hn::Zero(di), eight = hn::Set(di, kW), last_bit = hn::Set(di, 31);
    const VU byte = hn::Set(du, 0xFFu), ones = hn::Set(du, ~0u);
    const VU lowest_column = hn::Set(du, tri.far_is_left ? ~0u : 0u), lowest_row = hn::Set(du, tri.far_is_top ? ~0u : 0u);
    const VF a = hn::Set(df, tri.a), dzdx = hn::Set(df, tri.dzdx), dzdy = hn::Set(df, tri.dzdy), error = hn::Set(df, tri.error);
    const VF z_vertex_min = hn::Set(df, tri.z_vertex_min), half = hn::Set(df, 0.5f), lower = hn::Set(df, 1.0f - 0x1.0p-20f);

    std::uint64_t updated = 0;
    for (int tx = tx_begin; tx <= tx_end; tx += row_lanes) {
        const VI column0 = hn::ShiftLeft<3>(hn::Add(lane_column, hn::Set(di, tx)));  // tx * 8 per lane

        // The lane's sample row over its 32 samples, then the transpose (lanes past tx_end and
        // past the interval get no bits). Shift counts stay in [0, 31]; empty rows are zeroed.
        const VI x0 = hn::Add(hn::Set(di, tx * kW), block_sample);
        const VI lo = hn::Max(hn::Sub(first_v, x0), zero_i), hi = hn::Min(hn::Sub(last_v, x0), last_bit);
        const VU from_lo = hn::Shl(ones, hn::BitCast(du, hn::Min(lo, last_bit)));
        const VU to_hi = hn::Shr(ones, hn::BitCast(du, hn::Min(hn::Sub(last_bit, hi), last_bit)));
        const VU row_bits32 = hn::IfThenZeroElse(hn::RebindMask(du, hn::Gt(lo, hi)), hn::And(from_lo, to_hi));
        const VU m = hn::BitCast(du, hn::TableLookupBytes(hn::BitCast(du8, row_bits32), hn::BitCast(du8, transpose)));

        const auto active = hn::Ne(m, hn::Zero(du));
        if (hn::AllFalse(du, active)) continue;

        const std::size_t i = std::size_t(tx);
        VF d0 = load(df, planes.d0, i), d1 = load(df, planes.d1, i);
        VU mask = load(du, planes.mask, i);
        store(hn::Or(load(du, planes.covered, i), m), du, planes.covered, i);

        // The corner of the covered samples' bounding rectangle where the plane is smallest
        // (see subtile_coverage): columns from the OR of the 4 row bytes, rows from bit 8j
        // set when row j has a sample.
        VU columns_present = hn::Or(m, hn::ShiftRight<16>(m));
        columns_present = hn::And(hn::Or(columns_present, hn::ShiftRight<8>(columns_present)), byte);
        VU rows_present = hn::Or(m, hn::ShiftRight<4>(m));
        rows_present = hn::Or(rows_present, hn::ShiftRight<2>(rows_present));
        rows_present = hn::And(hn::Or(rows_present, hn::ShiftRight<1>(rows_present)), hn::Set(du, 0x01010101u));
        const VI far_column = ExtremeBitIndex(du, columns_present, lowest_column);
        const VI far_row = hn::ShiftRight<3>(ExtremeBitIndex(du, rows_present, lowest_row));

        // conservative_depth, lane by lane.
        const VF x = hn::Add(hn::ConvertTo(df, hn::Add(column0, far_column)), half);
        const VF y = hn::Add(hn::ConvertTo(df, hn::Add(row_y, far_row)), half);
        const VF plane = hn::Add(hn::Add(a, hn::Mul(dzdy, y)), hn::Mul(dzdx, x));
        const VF lowered = hn::Sub(plane, error);
        const VF bound = hn::IfThenElse(hn::Lt(lowered, z_vertex_min), z_vertex_min, lowered);  // std::max(lowered, z_vertex_min)
        const VF d_tri = hn::Mul(bound, lower);

        const auto update = hn::And(hn::RebindMask(df, active), hn::Gt(d_tri, d0));
        // No branch on whether any lane updates: on S1 about half the vectors do not, in no
        // pattern a predictor learns, and the mispredictions cost more than computing the update
        // and writing back the unchanged values (S1 14.55 -> 13.87 ms, castle 1.43 -> 1.40 ms).
        updated += hn::CountTrue(df, update);
        // merge_triangle_into_layers (layer_merge.hpp), lane by lane: the same float operations.
        const VI columns = hn::Min(hn::Sub(hn::Set(di, sample_width), column0), eight);
        const VU row_bits = hn::Shr(byte, hn::BitCast(du, hn::Max(hn::Sub(eight, columns), zero_i)));
        const VU valid = hn::Mul(row_bits, replicate_v);
        const VU covered_bits = hn::Or(mask, m), neither = hn::AndNot(covered_bits, valid);
        const VU zero_u = hn::Zero(du);
        const VF zero_f = hn::Zero(df);
        const auto any = [&](VU bits) { return hn::RebindMask(df, hn::Ne(bits, zero_u)); };
        const VF d_near = hn::Max(d1, d_tri);
        const VF d_covered = hn::Min(hn::IfThenElse(any(hn::AndNot(m, mask)), d1, d_near),
                                     hn::IfThenElse(any(hn::AndNot(mask, m)), d_tri, d_near));
        const VF d0_new = hn::IfThenElse(any(neither), d0, d_covered);
        const VU near = hn::IfThenElse(hn::RebindMask(du, hn::Ge(d1, d_tri)), mask, m);
        const VF near_lift = hn::Sub(d_near, d0_new);
        const VF covered_lift = hn::Mul(hn::Set(df, 2.0f), hn::Sub(d_covered, d0_new));
        const auto partial = hn::Eq(d0_new, zero_f);  // some sample without an occluder: every covered one
        const auto take_near = hn::AndNot(partial, hn::And(hn::Gt(near_lift, zero_f), hn::Ge(near_lift, covered_lift)));
        const auto take_covered = hn::Or(partial, hn::AndNot(take_near, hn::Gt(covered_lift, zero_f)));
        const VF d1_new = hn::IfThenElse(take_near, d_near, hn::IfThenElseZero(take_covered, d_covered));
        const VU mask_new = hn::IfThenElse(hn::RebindMask(du, take_near), near,
                                           hn::IfThenElseZero(hn::RebindMask(du, take_covered), covered_bits));

        store(hn::IfThenElse(update, d0_new, d0), df, planes.d0, i);
        store(hn::IfThenElse(update, d1_new, d1), df, planes.d1, i);
        store(hn::IfThenElse(hn::RebindMask(du, update), mask_new, mask), du, planes.mask, i);
    }
    return updated;
}
#endif  // HOMCULL_SUBTILE_LANES

// One vector of a sample row's per-sample depth: conservative_depth at the sample centres xs
// (row_part = a + dzdy y, the row's part), kept where larger than what the samples hold, in the
// lanes of in_interval; the other lanes are written back as read. The float operations of the
// reference's update_sample_depth, so the eager writes and the deferred fills give its bits.
template <class D, class M>
HWY_INLINE void RaiseSampleDepth(D df, float* depth, hn::Vec<D> xs, hn::Vec<D> row_part, hn::Vec<D> dzdx, hn::Vec<D> error,
                                 hn::Vec<D> z_vertex_min, hn::Vec<D> lower, M in_interval) {
    const auto lowered = hn::Sub(hn::Add(row_part, hn::Mul(dzdx, xs)), error);
    const auto bound = hn::Mul(hn::IfThenElse(hn::Lt(lowered, z_vertex_min), z_vertex_min, lowered), lower);
    const auto old = hn::LoadU(df, depth);
    // std::max(old, bound): bound where old < bound.
    hn::StoreU(hn::IfThenElse(hn::And(in_interval, hn::Lt(old, bound)), bound, old), df, depth);
}

// update_sample_depth for one subtile row, the samples of a sample row as lanes: each lane
// evaluates conservative_depth with the same float operations (the row's part, a + dzdy y,
// once per row: the same rounding for every sample) and keeps the larger. Whole vectors are
// loaded and stored; lanes past the interval write back what they read, within the row and
// its padding (BufferState::sample_depth_stride_), which no other band touches.
HWY_INLINE void UpdateSampleDepth(const SubtilePlanes& planes, int ty, const std::int32_t* first, const std::int32_t* last,
                                  const PreparedTriangle& tri, hn::Vec<hn::CappedTag<std::int32_t, kMaxSimdLanes>> lane) {
    constexpr int kH = kSubtileHeight;
    const hn::CappedTag<float, kMaxSimdLanes> df;  // rows are padded for this many (sample_depth_stride_)
    const hn::RebindToSigned<decltype(df)> di;
    const int lanes = int(hn::Lanes(df));
    const auto dzdx = hn::Set(df, tri.dzdx), error = hn::Set(df, tri.error), z_vertex_min = hn::Set(df, tri.z_vertex_min);
    const auto half = hn::Set(df, 0.5f), lower = hn::Set(df, 1.0f - 0x1.0p-20f);
    for (int j = 0; j < kH; ++j) {
        if (first[j] > last[j]) continue;
        const int row = ty * kH + j;
        const float y = float(row) + 0.5f;
        const auto row_part = hn::Set(df, tri.a + tri.dzdy * y);
        float* depth = planes.sample_depth + std::size_t(row) * planes.sample_stride;
        // The sample centres x + 0.5 of the lanes, stepped by whole vectors: every value is an
        // integer plus a half below 2^23, exact in float, so the steps round nothing.
        auto xs = hn::Add(hn::ConvertTo(df, hn::Add(lane, hn::Set(di, first[j]))), half);
        const auto step = hn::Set(df, float(lanes));
        const auto update = [&](int x, auto in_interval) { RaiseSampleDepth(df, depth + x, xs, row_part, dzdx, error, z_vertex_min, lower, in_interval); };
        int x = first[j];
        for (; x + lanes - 1 <= last[j]; x += lanes, xs = hn::Add(xs, step)) update(x, hn::FirstN(df, std::size_t(lanes)));
        if (x <= last[j]) update(x, hn::FirstN(df, std::size_t(last[j] - x + 1)));
    }
}

// The coverage intervals [first[r], last[r]] of sample rows row0 + r, r in [0, rows), by the
// double rule (sample_row_interval), the rows as lanes: 8 on AVX-512, 4 on AVX2, 2 on SSE4.
// Writes up to a vector past `rows`.
HWY_INLINE void DoubleRowIntervals(const TriangleEdges& e, int i0, int i1, int j0, int j1, int row0, int rows, std::int32_t* first,
                                   std::int32_t* last) {
    const hn::CappedTag<double, 8> d;
    const hn::Rebind<std::int32_t, decltype(d)> di;
    const int lanes = int(hn::Lanes(d));
    const auto lo_clamp = hn::Set(d, double(i0) - 2.0), hi_clamp = hn::Set(d, double(i1) + 2.0);
    const auto half = hn::Set(d, 0.5), one = hn::Set(d, 1.0), zero = hn::Zero(d);
    const auto row_min = hn::Set(d, double(j0)), row_max = hn::Set(d, double(j1));
    const auto lane = hn::Iota(d, 0.0);  // once: Highway's Iota goes through memory
    for (int r = 0; r < rows; r += lanes) {
        const auto sy = hn::Add(lane, hn::Set(d, double(row0 + r)));  // exact: small integers
        const auto py = hn::Add(sy, half);
        auto lo = hn::Set(d, double(i0)), hi = hn::Set(d, double(i1));
        auto empty = hn::Or(hn::Lt(sy, row_min), hn::Gt(sy, row_max));
        for (int k = 0; k < 3; ++k) {
            const auto c = hn::Sub(hn::Set(d, e.threshold[k]), hn::Mul(hn::Set(d, e.sb[k]), hn::Sub(py, hn::Set(d, e.oy[k]))));
            if (e.sa[k] == 0.0) {
                empty = hn::Or(empty, e.shared[k] ? hn::Gt(c, zero) : hn::Ge(c, zero));
                continue;
            }
            const auto x = hn::Add(hn::Set(d, e.ox[k]), hn::Mul(c, hn::Set(d, e.inverse_sa[k])));
            const auto v = hn::Sub(x, half);
            // std::clamp: v is finite, and a zero of either sign gives the same integer.
            const auto xs = hn::Min(hn::Max(v, lo_clamp), hi_clamp);
            if (e.sa[k] > 0.0) lo = hn::Max(lo, e.shared[k] ? hn::Ceil(xs) : hn::Add(hn::Floor(xs), one));
            else hi = hn::Min(hi, e.shared[k] ? hn::Floor(xs) : hn::Sub(hn::Ceil(xs), one));
        }
        hi = hn::IfThenElse(empty, hn::Sub(lo, one), hi);
        hn::StoreU(hn::DemoteTo(di, lo), di, first + r);
        hn::StoreU(hn::DemoteTo(di, hi), di, last + r);
    }
}

// The same by the float rule (float_sample_row_interval): twice the rows per vector, 16 on
// AVX-512. Writes up to a vector past `rows`.
HWY_INLINE void FloatRowIntervals(const RasterTriangle& triangle, int row0, int rows, std::int32_t* first, std::int32_t* last) {
    const FloatRowEdges& e = triangle.float_edges;
    const hn::CappedTag<float, kMaxSimdLanes> df;
    const hn::RebindToSigned<decltype(df)> di;
    const int lanes = int(hn::Lanes(df));
    const auto row_min = hn::Set(df, float(triangle.j0)), row_max = hn::Set(df, float(triangle.j1)), one = hn::Set(df, 1.0f);
    const auto lane = hn::Iota(df, 0.0f);
    // The edges in the order lower edges first (a triangle without a horizontal edge has one
    // or two of each), so that the loop below branches once on which kind edge 1 is, not on
    // every edge: lo and hi are a max and a min, the same in any order.
    static constexpr std::int8_t kOrder[8][3] = {{0, 1, 2}, {0, 1, 2}, {1, 0, 2}, {0, 1, 2}, {2, 0, 1}, {0, 2, 1}, {1, 2, 0}, {0, 1, 2}};
    const int pattern = int(e.lower[0]) | int(e.lower[1]) << 1 | int(e.lower[2]) << 2;
    const std::int8_t* order = kOrder[pattern];
    const auto edge_value = [&](int k, auto y) {
        const int o = order[k];
        const auto dy = hn::Sub(hn::Sub(y, hn::Set(df, e.row_origin[o])), hn::Set(df, e.y_offset[o]));
        const auto v = hn::Sub(hn::Set(df, e.base[o]), hn::Mul(hn::Set(df, e.slope[o]), dy));
        return hn::Min(hn::Max(v, hn::Set(df, e.lo_clamp[o])), hn::Set(df, e.hi_clamp[o]));
    };
    const auto shift = [&](int k) { return hn::Set(df, e.column_shift[order[k]]); };
    const auto run = [&](auto two_lower) {
        for (int r = 0; r < rows; r += lanes) {
            const auto y = hn::Add(lane, hn::Set(df, float(row0 + r)));  // exact: small integers
            auto lo = hn::Max(hn::Set(df, float(triangle.i0)), hn::Add(hn::Floor(edge_value(0, y)), shift(0)));
            auto hi = hn::Min(hn::Set(df, float(triangle.i1)), hn::Add(hn::Ceil(edge_value(2, y)), shift(2)));
            if constexpr (decltype(two_lower)::value) lo = hn::Max(lo, hn::Add(hn::Floor(edge_value(1, y)), shift(1)));
            else hi = hn::Min(hi, hn::Add(hn::Ceil(edge_value(1, y)), shift(1)));
            const auto empty = hn::Or(hn::Lt(y, row_min), hn::Gt(y, row_max));
            hi = hn::IfThenElse(empty, hn::Sub(lo, one), hi);
            hn::StoreU(hn::ConvertTo(di, lo), di, first + r);
            hn::StoreU(hn::ConvertTo(di, hi), di, last + r);
        }
    };
    if (pattern == 3 || pattern == 5 || pattern == 6) run(std::true_type{});
    else run(std::false_type{});
}

// hidden_behind_reference_layer with a vector of subtiles per step: the same comparisons, so
// the same answer.
HWY_INLINE bool HiddenBehindReferenceLayer(const SubtilePlanes& planes, int tx0, int tx1, int ty0, int ty1, float nearest) {
    const hn::CappedTag<float, kMaxSimdLanes> df;  // rows are padded for this many
    const int lanes = int(hn::Lanes(df));
    const auto bound = hn::Set(df, std::max(nearest, std::numeric_limits<float>::denorm_min()));
    const std::size_t stride = planes.stride;
    const float* d0 = planes.d0 + tx0;
    const int columns = tx1 - tx0 + 1;
#if HWY_TARGET != HWY_SCALAR
    if (lanes == 16 && columns <= 8) {
        // A narrow box (S1's triangles span about 5 subtile columns): four rows of 8 subtiles
        // per step, in two vectors, the lanes past the box's columns masked out; rows past the
        // box repeat its last. One shape for every narrow box: a choice of shape by width was
        // a branch the predictor missed.
        const hn::Half<decltype(df)> dh;
        const std::uint32_t bits = ((1u << columns) - 1u) * 0x0101u;
        const std::uint8_t bit_bytes[8] = {std::uint8_t(bits), std::uint8_t(bits >> 8)};
        const auto in_box = hn::LoadMaskBits(df, bit_bytes);
        for (int ty = ty0; ty <= ty1; ty += 4) {
            const auto row = [&](int r) { return d0 + std::size_t(std::min(ty + r, ty1)) * stride; };
            const auto v01 = hn::Combine(df, hn::LoadU(dh, row(1)), hn::LoadU(dh, row(0)));
            const auto v23 = hn::Combine(df, hn::LoadU(dh, row(3)), hn::LoadU(dh, row(2)));
            if (!hn::AllFalse(df, hn::And(in_box, hn::Or(hn::Lt(v01, bound), hn::Lt(v23, bound))))) return false;
        }
        return true;
    }
#endif
    for (int ty = ty0; ty <= ty1; ++ty) {
        const float* row = d0 + std::size_t(ty) * stride;
        for (int tx = 0; tx < columns; tx += lanes) {
            const auto in_box = hn::FirstN(df, std::size_t(columns - tx));
            if (!hn::AllFalse(df, hn::And(in_box, hn::Lt(hn::LoadU(df, row + tx), bound)))) return false;
        }
    }
    return true;
}

// The sample rows r < rows (at most 64) whose interval holds a sample (first[r] <= last[r]), as
// bits (row r: bit r). first and last may hold anything past `rows` (up to a vector).
HWY_INLINE std::uint64_t RowsWithSamples(const std::int32_t* first, const std::int32_t* last, int rows) {
    const hn::CappedTag<std::int32_t, 16> di;
    const int lanes = int(hn::Lanes(di));
    std::uint64_t bits = 0;
    for (int r = 0; r < rows; r += lanes) {
        const auto has_samples =
            hn::And(hn::Not(hn::Gt(hn::LoadU(di, first + r), hn::LoadU(di, last + r))), hn::FirstN(di, std::size_t(rows - r)));
        bits |= std::uint64_t(LaneBits(di, has_samples)) << r;
    }
    return bits;
}

// DoubleRowIntervals as a kernel of its own, for the occludee triangle tests.
void RowIntervals(const TriangleEdges& edges, int i0, int i1, int j0, int j1, int row0, int rows, std::int32_t* first, std::int32_t* last) {
    DoubleRowIntervals(edges, i0, i1, j0, j1, row0, rows, first, last);
}

// HiddenBehindReferenceLayer as a kernel of its own, for the clustered render's box tests.
bool HiddenBehindReferenceLayerKernel(const SubtilePlanes& planes, int tx0, int tx1, int ty0, int ty1, float nearest) {
    return HiddenBehindReferenceLayer(planes, tx0, tx1, ty0, ty1, nearest);
}

// apply_depth_record_reference in lanes: each of the record's rows in the unit in whole vectors
// aligned to the unit's columns, so that none reaches past them (another thread may be filling
// the next unit); samples outside the interval are written back as read. Each sample's value is
// UpdateSampleDepth's: its centre x + 0.5 exact in float, the same float operations.
HWY_INLINE void ApplyDepthRecord(const SampleDepthTiles& t, const std::int32_t* record, int ux, int uy) {
    const DepthRowsRecord r = depth_record_header(record);
    const std::int32_t *first = depth_record_first(record), *last = depth_record_last(record, r.rows);
    const int x0 = ux * kDepthUnitWidth, x1 = x0 + kDepthUnitWidth - 1;
    const int begin = std::max(r.row0, uy * kDepthUnitHeight), end = std::min({r.row0 + r.rows, (uy + 1) * kDepthUnitHeight, t.sample_height});
    const PreparedTriangle& tri = r.plane;
    const hn::CappedTag<float, kMaxSimdLanes> df;
    const hn::RebindToSigned<decltype(df)> di;
    const int lanes = int(hn::Lanes(df));
    const auto lane = hn::Iota(di, 0);
    const auto dzdx = hn::Set(df, tri.dzdx), error = hn::Set(df, tri.error), z_vertex_min = hn::Set(df, tri.z_vertex_min);
    const auto half = hn::Set(df, 0.5f), lower = hn::Set(df, 1.0f - 0x1.0p-20f);
    for (int row = begin; row < end; ++row) {
        const int lo = std::max(first[row - r.row0], x0), hi = std::min(last[row - r.row0], x1);
        if (lo > hi) continue;
        const float y = float(row) + 0.5f;
        const auto row_part = hn::Set(df, tri.a + tri.dzdy * y);
        float* depth = t.depth + std::size_t(row) * t.stride;
        const auto lo_v = hn::Set(di, lo), hi_v = hn::Set(di, hi);
        for (int x = x0 + (lo - x0) / lanes * lanes; x <= hi; x += lanes) {
            const auto column = hn::Add(lane, hn::Set(di, x));
            const auto in_interval = hn::RebindMask(df, hn::And(hn::Not(hn::Lt(column, lo_v)), hn::Not(hn::Gt(column, hi_v))));
            RaiseSampleDepth(df, depth + x, hn::Add(hn::ConvertTo(df, column), half), row_part, dzdx, error, z_vertex_min, lower, in_interval);
        }
    }
}

// fill_depth_unit_reference in lanes.
void FillDepthUnit(const SampleDepthTiles& t, int ux, int uy) {
    for_each_in_depth_unit(t, ux, uy, [&](const std::int32_t* record) { ApplyDepthRecord(t, record, ux, uy); });
}

// The reference's row loop, over chunks of up to kChunkSubtileRows subtile rows. A chunk where
// the triangle is hidden behind the reference layer is skipped (HiddenBehindReferenceLayer; on
// S1 that is most of them). Otherwise two passes: first the
// coverage interval of every sample row of the chunk (DoubleRowIntervals, or
// FloatRowIntervals for the triangles set up for it), each lane evaluating
// rasterize_rows_reference's formula for its row; then the subtile-row updates, from the first
// subtile row with a covered sample to the last. (One subtile row at a time, 4 lanes of
// intervals then the update, cost twice as much per row on S1.)
std::uint64_t RasterizeRows(const RasterTarget& t, const RasterTriangle& triangle) {
    const PreparedTriangle& tri = triangle.plane;
    const int i0 = triangle.i0, i1 = triangle.i1, j1 = triangle.j1;
    constexpr int kH = kSubtileHeight;
    // Only the rows that can hold a sample in the triangle's columns (rows_reaching_columns,
    // where rows_worth_bounding; the reference takes them all, and the tests hold the two to
    // the same bits).
    int row_lo = triangle.j0, row_hi = j1, ty_first, ty_last;
    if (rows_worth_bounding(i0, i1, triangle.j0, j1, t.sample_width) && !rows_reaching_columns(triangle, row_lo, row_hi)) return 0;
    if (!subtile_rows_within(row_lo, row_hi, t.row_begin, t.row_end, ty_first, ty_last)) return 0;
    const auto sample_lane = hn::Iota(hn::CappedTag<std::int32_t, kMaxSimdLanes>(), 0);

    constexpr int kChunkRows = kChunkSubtileRows * kH, kW = kSubtileWidth;
#if HOMCULL_SUBTILE_LANES
    // How many subtile rows one update vector takes: rows of 8 subtiles, or of 4 for a triangle
    // that spans at most 4 subtile columns (the castle's small triangles filled 4 of 16 lanes
    // in two rows of 8). 16 lanes (AVX-512): 2 rows of 8 or 4 rows of 4; 8 lanes (AVX2): 1 row
    // of 8 or 2 rows of 4; fewer: 1 row.
    const int vector_lanes = int(hn::Lanes(hn::CappedTag<float, 16>()));
    const bool narrow = i1 / kW - i0 / kW < 4;
    const int rows_per_vector = vector_lanes >= 16 ? (narrow ? 4 : 2) : vector_lanes == 8 && narrow ? 2 : 1;
#endif
    // + kMaxSimdLanes: the last vector may pass the chunk's rows
    HWY_ALIGN std::int32_t first[kChunkRows + kMaxSimdLanes], last[kChunkRows + kMaxSimdLanes];
    std::uint64_t updated = 0;
    // The per-sample depth: written below (the planes'), or when the buffer computes it where
    // read, each chunk's intervals listed, or written below into its zeroed tiles (list_sample_depth).
    SubtilePlanes depth_planes = t.planes;
    const bool listed = t.sample_tiles && list_sample_depth(*t.sample_tiles, triangle, ty_first, ty_last);
    if (t.sample_tiles && !listed) depth_planes.sample_depth = t.sample_tiles->depth;
    for (int ty0 = ty_first; ty0 <= ty_last; ty0 += kChunkSubtileRows) {
        const int ty1 = std::min(ty_last, ty0 + kChunkSubtileRows - 1);
        const int row0 = ty0 * kH, rows = (ty1 - ty0 + 1) * kH;
        if (t.skip_hidden &&
            HiddenBehindReferenceLayer(t.planes, i0 / kW, i1 / kW, ty0, ty1, chunk_nearest_depth(tri, i0, i1, triangle.j0, j1, ty0, ty1)))
            continue;
        if (triangle.plane.float_rows) FloatRowIntervals(triangle, row0, rows, first, last);
        else DoubleRowIntervals(triangle.edges, i0, i1, triangle.j0, j1, row0, rows, first, last);
        // The subtile rows before the chunk's first sample row with samples and after its last
        // take no update and no record (they would change nothing): on the shared walks an eighth
        // to two fifths of the rows of the chunks drawn, mostly those of large triangles whose
        // part beside the view spans rows their part in it does not reach.
        static_assert(kChunkRows <= 64, "a chunk's rows in one 64-bit word");
        const std::uint64_t with_samples = RowsWithSamples(first, last, rows);
        if (with_samples == 0) continue;
        const int row_begin = hwy::Num0BitsBelowLS1Bit_Nonzero64(with_samples);
        const int row_end = 64 - hwy::Num0BitsAboveMS1Bit_Nonzero64(with_samples);
        if (listed)
            record_sample_depth(*t.sample_tiles, tri, i0, i1, row0 + row_begin, row_end - row_begin, first + row_begin, last + row_begin,
                                [&](const std::int32_t* record, int ux, int uy) { ApplyDepthRecord(*t.sample_tiles, record, ux, uy); });
        const int ty_end = ty0 + (row_end - 1) / kH;
        for (int ty = ty0 + row_begin / kH; ty <= ty_end;) {
            const std::int32_t* row_first = first + (ty - ty0) * kH;
            const std::int32_t* row_last = last + (ty - ty0) * kH;
#if HOMCULL_SUBTILE_LANES
            // rows_per_vector where the chunk has that many rows left, else fewer.
            const int rows_now = rows_per_vector == 4 && ty + 3 <= ty_end ? 4 : rows_per_vector >= 2 && ty < ty_end ? 2 : 1;
            if (rows_now == 4) updated += UpdateSubtileRows<4>(t.planes, ty, row_first, row_last, i0, i1, tri, t.sample_width, t.sample_height);
            else if (rows_now == 2) updated += UpdateSubtileRows<2>(t.planes, ty, row_first, row_last, i0, i1, tri, t.sample_width, t.sample_height);
            else updated += UpdateSubtileRows<1>(t.planes, ty, row_first, row_last, i0, i1, tri, t.sample_width, t.sample_height);
#else
            const int rows_now = 1;
            int tx_begin, tx_end;
            if (reached_subtile_columns(row_first, row_last, i0, i1, tx_begin, tx_end))
                updated += update_subtile_row_reference(t.planes, ty, tx_begin, tx_end, row_first, row_last, tri, t.sample_width,
                                                        t.sample_height);
#endif
            if (depth_planes.sample_depth)
                for (int r = 0; r < rows_now; ++r)
                    UpdateSampleDepth(depth_planes, ty + r, row_first + r * kH, row_last + r * kH, tri, sample_lane);
            ty += rows_now;
        }
    }
    return updated;
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <homcull/error.hpp>

#include "raster/raster_kernels.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <iterator>
#include <string>

namespace homcull {
namespace detail {

HWY_EXPORT(RasterizeRows);
HWY_EXPORT(HiddenBehindReferenceLayerKernel);
HWY_EXPORT(RowIntervals);
HWY_EXPORT(FillDepthUnit);

namespace {
std::atomic<bool> skip_hidden{true};
}  // namespace

void resolve_rasterize_kernels(const IsaChoice& choice, RasterKernels& k) {
    k.rows = choice.scalar ? &rasterize_rows_reference : HOMCULL_KERNEL_FOR(choice, RasterizeRows);
    k.hidden_test = choice.scalar ? &hidden_behind_reference_layer : HOMCULL_KERNEL_FOR(choice, HiddenBehindReferenceLayerKernel);
    k.row_intervals = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, RowIntervals);
    k.fill_depth_unit = choice.scalar ? &fill_depth_unit_reference : HOMCULL_KERNEL_FOR(choice, FillDepthUnit);
}
void set_hidden_skip(bool enabled) { skip_hidden = enabled; }
bool hidden_skip_enabled() { return skip_hidden; }

}  // namespace detail
}  // namespace homcull
#endif  // HWY_ONCE
