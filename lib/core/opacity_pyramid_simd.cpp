// The pyramid reduction of the occlusion maps in SIMD (opacity_pyramid.hpp): a vector of
// output cells at a time, their children's even and odd columns separated with
// ConcatEven/ConcatOdd. Integer sums and float minima are exact: the reference's bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/opacity_pyramid_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "core/opacity_pyramid.hpp"
#include "raster/rasterize.hpp"

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
        hn::StoreU(hn::Min(min_row(r.far0), min_row(r.far1)), df, r.far_out + x);
        hn::StoreU(hn::Min(min_row(r.near0), min_row(r.near1)), df, r.near_out + x);
    }
    return x;
#endif
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>

namespace homcull::detail {

HWY_EXPORT(ReducePyramidRow);

namespace {
int dispatch_reduce(const PyramidRows& rows, int pairs) { return HWY_DYNAMIC_DISPATCH(ReducePyramidRow)(rows, pairs); }
}  // namespace

PyramidRowKernel selected_pyramid_row_kernel() { return scalar_reference_selected() ? nullptr : &dispatch_reduce; }

void reduce_pyramid_row_reference(const PyramidRows& r, int begin, int end, int below_width) {
    for (int x = begin; x < end; ++x) {
        // A missing right child repeats the left one: the minimum is unaffected, the sum skips it.
        const std::size_t a = std::size_t(2 * x), b = std::size_t(std::min(2 * x + 1, below_width - 1));
        const std::uint32_t second_column = b != a ? 1u : 0u;
        std::uint32_t covered = r.covered0[a] + second_column * r.covered0[b];
        if (r.second_row) covered += r.covered1[a] + second_column * r.covered1[b];
        r.covered_out[x] = covered;
        r.far_out[x] = std::min(std::min(r.far0[a], r.far0[b]), std::min(r.far1[a], r.far1[b]));
        r.near_out[x] = std::min(std::min(r.near0[a], r.near0[b]), std::min(r.near1[a], r.near1[b]));
    }
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
