// The covered samples of a row of subtiles, a vector of coverage masks at a time (population
// counts of 32-bit lanes), for the summed-area table of the lazy maps (covered_sums.cpp). The
// library's baseline target has no popcount instruction, and the table's scalar loop counted
// bits with a dozen operations per subtile. Integer counts: every instruction set gives the
// reference's.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "hom/covered_counts_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "hom/map_kernels.hpp"
#include "raster/rasterize.hpp"

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Whole vectors: reads and writes up to a vector past `count` (the buffer's rows and the
// counts are padded for kMaxSimdLanes).
void CoveredCounts(const std::uint32_t* masks, int count, std::uint32_t* counts) {
    const hn::CappedTag<std::uint32_t, kMaxSimdLanes> d;
    const int lanes = int(hn::Lanes(d));
    for (int k = 0; k < count; k += lanes) hn::StoreU(hn::PopulationCount(hn::LoadU(d, masks + k)), d, counts + k);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace homcull::detail {

HWY_EXPORT(CoveredCounts);

void resolve_covered_counts_kernel(const IsaChoice& choice, MapKernels& kernels) {
    kernels.covered_counts = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, CoveredCounts);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
