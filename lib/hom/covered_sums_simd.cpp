// A row of the lazy maps' summed-area table of covered samples (covered_sums.cpp), a vector of
// subtiles at a time: population counts of their 32-bit coverage masks, summed along the row
// within 128-bit blocks of 4 (two shifts and adds), the running total carried from block to
// block, and the row above added. The library's baseline target has no popcount instruction,
// and the scalar loop took about 14 instructions a subtile. Integer sums: every instruction set
// gives the reference's (covered_sums_row_reference).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "hom/covered_sums_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "hom/map_kernels.hpp"

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Blocks of 4 lanes on every target: an inclusive scan across a whole AVX2 or AVX-512 vector
// would need lanes moved across its 128-bit blocks, which these shifts do not do.
void CoveredSumsRow(const std::uint32_t* masks, int count, const std::uint32_t* above, std::uint32_t* row) {
    std::uint32_t run = 0;  // the covered samples left of k
    int k = 0;
#if HWY_TARGET != HWY_SCALAR  // one lane: the loop below does every subtile
    const hn::CappedTag<std::uint32_t, 4> d;
    constexpr int kLanes = 4;
    auto carry = hn::Zero(d);  // run, in every lane
    for (; k + kLanes <= count; k += kLanes) {
        auto v = hn::PopulationCount(hn::LoadU(d, masks + k));
        v = hn::Add(v, hn::ShiftLeftLanes<1>(d, v));
        v = hn::Add(v, hn::ShiftLeftLanes<2>(d, v));
        v = hn::Add(v, carry);
        hn::StoreU(hn::Add(v, hn::LoadU(d, above + k + 1)), d, row + k + 1);
        carry = hn::Broadcast<kLanes - 1>(v);
    }
    run = hn::GetLane(carry);
#endif
    covered_sums_row_from(masks, k, count, above, row, run);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace homcull::detail {

HWY_EXPORT(CoveredSumsRow);

void resolve_covered_sums_kernel(const IsaChoice& choice, MapKernels& kernels) {
    kernels.covered_sums_row = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, CoveredSumsRow);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
