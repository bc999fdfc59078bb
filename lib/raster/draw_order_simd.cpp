// The SIMD kernels of the draw order's first pass (draw_order.cpp): each triangle's nearest
// clip w in float lanes, one triangle per lane, and its bucket, for inputs without indices whose
// vertices are packed 3 or 4 floats (workload S1), and for indexed inputs (positions gathered). Every target makes the same float
// operations in the same order (no fused multiply-add), so every target gives the same buckets;
// the order does not depend on the instruction set. For a clip-space soup, the same pass also
// notes each triangle for the reference cells (NoteTriangles, reference_cells.hpp).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/draw_order_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/clip_fates-inl.h"
#include "raster/draw_order.hpp"
#include "common/lane_bits-inl.h"
#include "raster/reference_cells.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The buckets of a vector of triangles whose vertices' clip w are w0, w1, w2: as depth_bucket in
// draw_order.cpp, from the float bits of max(nearest w, near_w); NaN: the last bucket.
template <class DF>
HWY_INLINE hn::Vec<hn::RebindToUnsigned<DF>> Buckets(DF /* df */, hn::Vec<DF> w0, hn::Vec<DF> w1, hn::Vec<DF> w2, hn::Vec<DF> near) {
    const hn::RebindToUnsigned<DF> du;
    const auto is_nan = hn::Or(hn::Or(hn::IsNaN(w0), hn::IsNaN(w1)), hn::IsNaN(w2));
    const auto nearest = hn::Max(hn::Min(hn::Min(w0, w1), w2), near);  // no NaN where it is kept
    const auto steps = hn::ShiftRight<kDrawOrderBucketShift>(hn::Sub(hn::BitCast(du, nearest), hn::BitCast(du, near)));
    const auto bucket = hn::Min(steps, hn::Set(du, kDrawOrderBuckets - 2));
    return hn::IfThenElse(hn::RebindMask(du, is_nan), hn::Set(du, kDrawOrderBuckets - 1), bucket);
}

// The cell notes (reference_cells.hpp) of `count` triangles of a clip-space soup, their
// corners' coordinates in corner[c][k][i] (c: x, y, z, w; k: corner; i: triangle). A triangle is
// noted when the setup would surely count it as rasterized: its fate in double lanes exactly as
// ClassifyBatch decides it (its clip coordinates are its positions, exact in double), z finite
// too (TransformBatch makes the triangle invalid otherwise), and w at most 2^64 (depths far
// from float's denormals, where the plane's error bound holds). Its box is rounded out by a
// sample (the float projection below is within a fifth of a sample of the setup's for any
// buffer of at most 256 cells a side), and its depth is 1/(smallest w) rounded up.
template <class DF>
HWY_INLINE void NoteTriangles(DF df, const CellNoteSpec& spec, const float (*corner)[3][16], std::size_t count, CellNote* notes) {
    const hn::CappedTag<double, 8> dd;
    const hn::Rebind<float, decltype(dd)> dh;
    const std::size_t lanes = hn::Lanes(df);
    std::uint32_t surely_drawn = 0;  // bit i: triangle i is noted
    for (std::size_t g = 0; g < lanes; g += hn::Lanes(dd)) {
        const auto load = [&](int c, int k) { return hn::PromoteTo(dd, hn::Load(dh, corner[c][k] + g)); };
        hn::Mask<decltype(dd)> finite, outside, unsettled, away;
        hn::Vec<decltype(dd)> det;
        ClipFates(dd, spec.backface, double(spec.near_w), load(0, 0), load(1, 0), load(3, 0), load(0, 1), load(1, 1), load(3, 1), load(0, 2),
                  load(1, 2), load(3, 2), finite, outside, unsettled, det, away);
        const auto settled = hn::AndNot(hn::Or(hn::Or(outside, unsettled), hn::Or(hn::Eq(det, hn::Zero(dd)), away)), finite);
        surely_drawn |= LaneBits(dd, settled) << g;
    }
    const hn::RebindToSigned<DF> di;
    const auto one = hn::Set(df, 1.0f), half = hn::Set(df, 0.5f), margin = hn::Set(df, 1.0f);
    const auto width = hn::Set(df, float(spec.sample_width)), height = hn::Set(df, float(spec.sample_height));
    auto sane = hn::FirstN(df, lanes);
    auto x_lo = hn::Set(df, HUGE_VALF), x_hi = hn::Neg(x_lo), y_lo = x_lo, y_hi = x_hi, w_min = x_lo;
    for (int k = 0; k < 3; ++k) {
        const auto x = hn::Load(df, corner[0][k]), y = hn::Load(df, corner[1][k]), z = hn::Load(df, corner[2][k]);
        const auto w = hn::Load(df, corner[3][k]);
        sane = hn::And(sane, hn::And(hn::IsFinite(z), hn::Le(w, hn::Set(df, 0x1.0p64f))));
        const auto inv_w = hn::Div(one, w);
        const auto sx = hn::Mul(hn::Mul(hn::Add(hn::Mul(x, inv_w), one), half), width);
        const auto sy = hn::Mul(hn::Mul(hn::Sub(one, hn::Mul(y, inv_w)), half), height);
        x_lo = hn::Min(x_lo, sx), x_hi = hn::Max(x_hi, sx), y_lo = hn::Min(y_lo, sy), y_hi = hn::Max(y_hi, sy);
        w_min = hn::Min(w_min, w);
    }
    surely_drawn &= LaneBits(df, sane);
    // Cells: 64 samples wide (8 subtiles of 8), 32 high (8 subtiles of 4).
    const hn::RebindToUnsigned<DF> du;
    const auto cell = [&](auto v, float samples_per_cell, int cells) {
        const auto c = hn::Floor(hn::Mul(v, hn::Set(df, 1.0f / samples_per_cell)));  // exact scaling by a power of two
        return hn::BitCast(du, hn::ConvertTo(di, hn::Min(hn::Max(c, hn::Zero(df)), hn::Set(df, float(cells - 1)))));
    };
    auto box = hn::Or(hn::Or(cell(hn::Sub(x_lo, margin), 64.0f, spec.cells_width),
                             hn::ShiftLeft<8>(cell(hn::Add(x_hi, margin), 64.0f, spec.cells_width))),
                      hn::Or(hn::ShiftLeft<16>(cell(hn::Sub(y_lo, margin), 32.0f, spec.cells_height)),
                             hn::ShiftLeft<24>(cell(hn::Add(y_hi, margin), 32.0f, spec.cells_height))));
    // 1/w_min to nearest, at most 2^-24 off; times 1 + 2^-20, above the double 1/w_min the
    // setup computes (and at least 2^-64). NaN for a triangle not noted: no cell is at least
    // that. Its box may come from NaNs: cell 0 instead, within the cells.
    const std::uint8_t noted_bits[8] = {std::uint8_t(surely_drawn), std::uint8_t(surely_drawn >> 8)};
    const auto noted = hn::LoadMaskBits(df, noted_bits);
    const auto nearest = hn::IfThenElse(noted, hn::Mul(hn::Div(one, w_min), hn::Set(df, 1.0f + 0x1.0p-20f)),
                                        hn::Set(df, std::numeric_limits<float>::quiet_NaN()));
    box = hn::IfThenElseZero(hn::RebindMask(du, noted), box);
    static_assert(sizeof(CellNote) == 2 * sizeof(std::uint32_t) && offsetof(CellNote, nearest) == sizeof(std::uint32_t),
                  "a note is its four cell bytes (little-endian: cx0 lowest) and its float");
    if (count == lanes) {
        hn::StoreInterleaved2(box, hn::BitCast(du, nearest), du, reinterpret_cast<std::uint32_t*>(notes));
    } else {
        HWY_ALIGN std::uint32_t both[2 * 16];
        hn::StoreInterleaved2(box, hn::BitCast(du, nearest), du, both);
        std::memcpy(notes, both, count * sizeof(CellNote));
    }
}

// Buckets triangles [begin, end) of a packed soup (kComponents floats per vertex, x y z [w]),
// into bucket[t], and counts them into count[]. row: the matrix's last row (m[3], m[7], m[11],
// m[15]).
template <int kComponents>
HWY_INLINE void BucketSoup(const float* positions, std::size_t begin, std::size_t end, const float* row, float near_w, std::uint16_t* bucket,
                           std::uint32_t* count, const CellNoteSpec* spec, CellNote* notes) {
    const hn::CappedTag<float, 16> df;
    const hn::RebindToUnsigned<decltype(df)> du;
    constexpr std::size_t kMaxLanes = 16;
    const std::size_t lanes = hn::Lanes(df);
    const auto m0 = hn::Set(df, row[0]), m1 = hn::Set(df, row[1]), m2 = hn::Set(df, row[2]), m3 = hn::Set(df, row[3]);
    const auto near = hn::Set(df, near_w);
    // Clip w of `lanes` consecutive vertices from p: ((m3 x + m7 y) + m11 z) + m15 w.
    const auto clip_w = [&](const float* p) {
        hn::Vec<decltype(df)> x, y, z, w;
        if constexpr (kComponents == 4) {
            hn::LoadInterleaved4(df, p, x, y, z, w);
        } else {
            hn::LoadInterleaved3(df, p, x, y, z);
            w = hn::Set(df, 1.0f);
        }
        return hn::Add(hn::Add(hn::Add(hn::Mul(m0, x), hn::Mul(m1, y)), hn::Mul(m2, z)), hn::Mul(m3, w));
    };
    // The input is read once, front to back, but the hardware prefetcher did not keep up: its
    // lines are prefetched this many vectors of triangles ahead (S1 at 1080p, one thread: 7.78
    // -> 7.43 ms with 8; 2, 4 and 32 ahead 7.59, 7.65, 7.52; two threads 4.91 -> 4.75 ms).
    constexpr std::size_t kPrefetchVectors = 8;
    const std::size_t vector_bytes = 3 * kComponents * lanes * sizeof(float);
    HWY_ALIGN float w[3 * kMaxLanes];
    HWY_ALIGN float tail[3 * kMaxLanes * kComponents];
    HWY_ALIGN std::uint32_t out[kMaxLanes];
    for (std::size_t t = begin; t < end; t += lanes) {
        const std::size_t n = std::min(lanes, end - t);
        const float* p = positions + 3 * kComponents * t;
        if (n < lanes) {  // the last triangles, copied so that the loads stay within the input
            std::fill_n(tail, 3 * kMaxLanes * kComponents, 0.0f);
            std::memcpy(tail, p, 3 * kComponents * n * sizeof(float));
            p = tail;
        }
        if (t + kPrefetchVectors * lanes < end) {
            const char* ahead = reinterpret_cast<const char*>(p + kPrefetchVectors * 3 * kComponents * lanes);
            for (std::size_t b = 0; b < vector_bytes; b += 64) __builtin_prefetch(ahead + b);
        }
        // The clip w of the 3 * lanes vertices in vertex order, then regrouped by corner.
        for (std::size_t k = 0; k < 3; ++k) hn::Store(clip_w(p + k * lanes * kComponents), df, w + k * lanes);
        if (notes) {  // the positions, by corner (the matrix is the identity)
            HWY_ALIGN float by_vertex[4][3 * kMaxLanes];
            for (std::size_t k = 0; k < 3; ++k) {
                hn::Vec<decltype(df)> x, y, z, v;
                if constexpr (kComponents == 4) {
                    hn::LoadInterleaved4(df, p + k * lanes * kComponents, x, y, z, v);
                } else {
                    hn::LoadInterleaved3(df, p + k * lanes * kComponents, x, y, z);
                    v = hn::Set(df, 1.0f);
                }
                hn::Store(x, df, by_vertex[0] + k * lanes), hn::Store(y, df, by_vertex[1] + k * lanes);
                hn::Store(z, df, by_vertex[2] + k * lanes), hn::Store(v, df, by_vertex[3] + k * lanes);
            }
            HWY_ALIGN float corner[4][3][kMaxLanes];
            for (int c = 0; c < 4; ++c) {
                hn::Vec<decltype(df)> c0, c1, c2;
                hn::LoadInterleaved3(df, by_vertex[c], c0, c1, c2);
                hn::Store(c0, df, corner[c][0]), hn::Store(c1, df, corner[c][1]), hn::Store(c2, df, corner[c][2]);
            }
            NoteTriangles(df, *spec, corner, n, notes + t);
        }
        hn::Vec<decltype(df)> w0, w1, w2;
        hn::LoadInterleaved3(df, w, w0, w1, w2);
        hn::Store(Buckets(df, w0, w1, w2, near), du, out);
        for (std::size_t i = 0; i < n; ++i) {
            bucket[t + i] = std::uint16_t(out[i]);
            ++count[out[i]];
        }
    }
}

void BucketPackedSoup(const float* positions, int components, std::size_t begin, std::size_t end, const float* row, float near_w,
                      std::uint16_t* bucket, std::uint32_t* count, const CellNoteSpec* spec, CellNote* notes) {
    if (components == 4) BucketSoup<4>(positions, begin, end, row, near_w, bucket, count, spec, notes);
    else BucketSoup<3>(positions, begin, end, row, near_w, bucket, count, spec, notes);
}

// Buckets triangles [begin, end) of an indexed input, a triangle per lane: its three vertex
// numbers (a lane with one out of range takes the last bucket and reads vertex 0), their
// positions gathered `stride` floats apart (3 or 4 components; stride * vertex_count < 2^31,
// vertex_count > 0).
template <typename Index>
HWY_INLINE void BucketIndexedTyped(const float* positions, std::size_t stride, int components, const Index* indices, std::size_t vertex_count,
                                   std::size_t begin, std::size_t end, const float* row, float near_w, std::uint16_t* bucket,
                                   std::uint32_t* count) {
    const hn::CappedTag<float, 16> df;
    const hn::RebindToSigned<decltype(df)> di;
    const hn::RebindToUnsigned<decltype(df)> du;
    constexpr std::size_t kMaxLanes = 16;
    const std::size_t lanes = hn::Lanes(df);
    const auto m0 = hn::Set(df, row[0]), m1 = hn::Set(df, row[1]), m2 = hn::Set(df, row[2]), m3 = hn::Set(df, row[3]);
    const auto near = hn::Set(df, near_w), one = hn::Set(df, 1.0f);
    const auto stride_v = hn::Set(di, std::int32_t(stride));
    HWY_ALIGN std::int32_t index[3 * kMaxLanes];
    HWY_ALIGN std::uint32_t valid[kMaxLanes], out[kMaxLanes];
    for (std::size_t t = begin; t < end; t += lanes) {
        const std::size_t n = std::min(lanes, end - t);
        for (std::size_t i = 0; i < lanes; ++i) {
            bool ok = i < n;
            for (std::size_t k = 0; k < 3; ++k) {
                const std::size_t v = ok ? std::size_t(indices[3 * (t + i) + k]) : 0;
                ok = ok && v < vertex_count;
                index[3 * i + k] = std::int32_t(v < vertex_count ? v : 0);
            }
            valid[i] = ok ? ~0u : 0u;
        }
        hn::Vec<decltype(di)> i0, i1, i2;
        hn::LoadInterleaved3(di, index, i0, i1, i2);
        // Clip w of each lane's vertex k: ((m3 x + m7 y) + m11 z) + m15 w.
        const auto clip_w = [&](hn::Vec<decltype(di)> vertex) {
            const auto at = hn::Mul(vertex, stride_v);
            const auto x = hn::GatherIndex(df, positions, at), y = hn::GatherIndex(df, positions + 1, at);
            const auto z = hn::GatherIndex(df, positions + 2, at);
            const auto w = components == 4 ? hn::GatherIndex(df, positions + 3, at) : one;
            return hn::Add(hn::Add(hn::Add(hn::Mul(m0, x), hn::Mul(m1, y)), hn::Mul(m2, z)), hn::Mul(m3, w));
        };
        const auto buckets = Buckets(df, clip_w(i0), clip_w(i1), clip_w(i2), near);
        const auto ok = hn::Ne(hn::Load(du, valid), hn::Zero(du));
        hn::Store(hn::IfThenElse(ok, buckets, hn::Set(du, kDrawOrderBuckets - 1)), du, out);
        for (std::size_t i = 0; i < n; ++i) {
            bucket[t + i] = std::uint16_t(out[i]);
            ++count[out[i]];
        }
    }
}

void BucketIndexed(const float* positions, std::size_t stride, int components, const void* indices, bool indices_16bit,
                   std::size_t vertex_count, std::size_t begin, std::size_t end, const float* row, float near_w, std::uint16_t* bucket,
                   std::uint32_t* count) {
    if (indices_16bit)
        BucketIndexedTyped(positions, stride, components, static_cast<const std::uint16_t*>(indices), vertex_count, begin, end, row, near_w,
                           bucket, count);
    else
        BucketIndexedTyped(positions, stride, components, static_cast<const std::uint32_t*>(indices), vertex_count, begin, end, row, near_w,
                           bucket, count);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/raster_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(BucketPackedSoup);
HWY_EXPORT(BucketIndexed);

void resolve_draw_order_kernels(const IsaChoice& choice, RasterKernels& k) {
    k.bucket_packed_soup = HOMCULL_KERNEL_FOR(choice, BucketPackedSoup);
    k.bucket_indexed = HOMCULL_KERNEL_FOR(choice, BucketIndexed);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
