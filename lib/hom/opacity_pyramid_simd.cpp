// The occlusion maps' level 0 at one sample per pixel, and the pyramid reduction, in SIMD
// (opacity_pyramid.hpp). Reduction: a vector of output cells at a time, their children's even and odd columns separated with
// ConcatEven/ConcatOdd. Integer sums and float minima are exact: the reference's bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "hom/opacity_pyramid_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include <homcull/occlusion_buffer.hpp>

#include "hom/opacity_pyramid.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

int ReducePyramidRow(const PyramidRows& r, int pairs) {
#if HWY_TARGET == HWY_SCALAR
    (void)r;
    (void)pairs;
    return 0;  // one lane: nothing to pair up
#else
    const hn::CappedTag<float, kMaxSimdLanes> df;
    const hn::RebindToUnsigned<decltype(df)> du;
    const int lanes = int(hn::Lanes(df));
    int x = 0;
    for (; x + lanes <= pairs; x += lanes) {
        const std::size_t c = std::size_t(2 * x), h = c + std::size_t(lanes);
        auto sum_row = [&](const std::uint32_t* row) {
            const auto lo = hn::LoadU(du, row + c), hi = hn::LoadU(du, row + h);
            return hn::Add(hn::ConcatEven(du, hi, lo), hn::ConcatOdd(du, hi, lo));
        };
        auto min_row = [&](const float* row) {
            const auto lo = hn::LoadU(df, row + c), hi = hn::LoadU(df, row + h);
            return hn::Min(hn::ConcatEven(df, hi, lo), hn::ConcatOdd(df, hi, lo));
        };
        auto covered = sum_row(r.covered0);
        if (r.second_row) covered = hn::Add(covered, sum_row(r.covered1));
        hn::StoreU(covered, du, r.covered_out + x);
        if (r.far_out) hn::StoreU(hn::Min(min_row(r.far0), min_row(r.far1)), df, r.far_out + x);
        if (r.near_out) hn::StoreU(hn::Min(min_row(r.near0), min_row(r.near1)), df, r.near_out + x);
    }
    return x;
#endif
}

// S = 1: per subtile row, its 8 pixels as lanes (two halves of 4 on SSE4): covered bit, and
// which layer bounds it.
int Level0SingleSample(const Level0Maps& m) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    if (m.samples != 1) return 0;
    const hn::CappedTag<std::uint32_t, kW> du;
    const hn::Rebind<float, decltype(du)> df;
    const int lanes = int(hn::Lanes(du));
    const int full_columns = m.width / kW;
    const auto one = hn::Set(du, 1u);
    const auto infinity = hn::Set(df, HUGE_VALF);
    const auto lane = hn::Iota(du, 0u);  // once: Highway's Iota goes through memory
    for (int ty = 0; ty < m.subtiles_y; ++ty) {
        const int rows = std::min(kH, m.height - ty * kH);
        for (int tx = 0; tx < full_columns; ++tx) {
            const std::size_t i = std::size_t(ty) * m.stride + std::size_t(tx);
            const auto covered = hn::Set(du, m.covered[i]), mask = hn::Set(du, m.mask[i]);
            const auto d0 = hn::Set(df, m.d0[i]), layered = hn::Set(df, std::max(m.d0[i], m.d1[i]));
            for (int r = 0; r < rows; ++r) {
                const std::size_t out = std::size_t(ty * kH + r) * std::size_t(m.width) + std::size_t(tx * kW);
                for (int h = 0; h < kW; h += lanes) {
                    const auto shift = hn::Add(lane, hn::Set(du, std::uint32_t(r * kW + h)));
                    const auto bit = hn::And(hn::Shr(covered, shift), one);
                    const auto in_mask = hn::And(hn::Shr(mask, shift), one);
                    const auto outside = hn::RebindMask(df, hn::Ne(hn::AndNot(in_mask, bit), hn::Zero(du)));
                    const auto inside = hn::RebindMask(df, hn::Ne(hn::And(in_mask, bit), hn::Zero(du)));
                    hn::StoreU(bit, du, m.covered_out + out + std::size_t(h));
                    if (m.far_out)
                        hn::StoreU(hn::IfThenElse(outside, d0, hn::IfThenElse(inside, layered, infinity)), df, m.far_out + out + std::size_t(h));
                    if (m.near_out)
                        hn::StoreU(hn::IfThenElse(inside, layered, hn::IfThenElse(outside, d0, infinity)), df, m.near_out + out + std::size_t(h));
                }
            }
        }
    }
    return full_columns;
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "hom/map_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(ReducePyramidRow);
HWY_EXPORT(Level0SingleSample);

MapKernels resolve_map_kernels(const IsaChoice& choice) {
    MapKernels kernels;
    if (choice.scalar) return kernels;
    kernels.level0 = HOMCULL_KERNEL_FOR(choice, Level0SingleSample);
    kernels.reduce_row = HOMCULL_KERNEL_FOR(choice, ReducePyramidRow);
    return kernels;
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
