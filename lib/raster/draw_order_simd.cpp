// The SIMD kernel of the draw order's first pass (draw_order.cpp) for the common input without
// indices whose vertices are packed 3 or 4 floats (workload S1): each triangle's nearest clip w
// in float lanes, one triangle per lane, and its bucket. Every target makes the same float
// operations in the same order (no fused multiply-add), so every target gives the same buckets;
// the order does not depend on the instruction set.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/draw_order_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/draw_order.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>

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

// Buckets triangles [begin, end) of a packed soup (kComponents floats per vertex, x y z [w]),
// into bucket[t], and counts them into count[]. row: the matrix's last row (m[3], m[7], m[11],
// m[15]).
template <int kComponents>
HWY_INLINE void BucketSoup(const float* positions, std::size_t begin, std::size_t end, const float* row, float near_w, std::uint16_t* bucket,
                           std::uint32_t* count) {
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
        // The clip w of the 3 * lanes vertices in vertex order, then regrouped by corner.
        for (std::size_t k = 0; k < 3; ++k) hn::Store(clip_w(p + k * lanes * kComponents), df, w + k * lanes);
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
                      std::uint16_t* bucket, std::uint32_t* count) {
    if (components == 4) BucketSoup<4>(positions, begin, end, row, near_w, bucket, count);
    else BucketSoup<3>(positions, begin, end, row, near_w, bucket, count);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/resolved_kernel.hpp"

namespace homcull::detail {

HWY_EXPORT(BucketPackedSoup);

void bucket_packed_soup(const float* positions, int components, std::size_t begin, std::size_t end, const float* row, float near_w,
                        std::uint16_t* bucket, std::uint32_t* count) {
    HOMCULL_RESOLVED_KERNEL(BucketPackedSoup)(positions, components, begin, end, row, near_w, bucket, count);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
