// The support scan (support_scan.hpp) in SIMD: each lane keeps its best dot product and that
// point's index; the lanes' winners are compared at the end, ties to the lowest index.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "sort/support_scan_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "sort/support_scan.hpp"

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace homcull::sort_detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

std::uint32_t SupportScanKernel(const float* x, const float* y, const float* z, std::uint32_t count, float dx, float dy, float dz) {
    const hn::ScalableTag<float> df;
    const hn::RebindToSigned<decltype(df)> di;
    const std::uint32_t lanes = std::uint32_t(hn::Lanes(df));
    std::uint32_t i = 0;
    std::uint32_t best = 0;
    float best_dot = -3.4e38f;
    if (count >= lanes) {
        const auto vx = hn::Set(df, dx), vy = hn::Set(df, dy), vz = hn::Set(df, dz);
        const auto step = hn::Set(di, std::int32_t(lanes));
        // Four independent running maxima (each over every fourth vector), so that the
        // compare-and-select chains overlap instead of waiting on one another.
        auto dot0 = hn::Set(df, -3.4e38f), dot1 = dot0, dot2 = dot0, dot3 = dot0;
        auto at0 = hn::Zero(di), at1 = at0, at2 = at0, at3 = at0;
        auto index = hn::Iota(di, 0);
        const auto keep = [&](std::uint32_t k, decltype(dot0)& running, decltype(at0)& at, const decltype(index)& where) {
            const auto dot = hn::Add(hn::Add(hn::Mul(hn::LoadU(df, x + k), vx), hn::Mul(hn::LoadU(df, y + k), vy)),
                                     hn::Mul(hn::LoadU(df, z + k), vz));
            const auto better = hn::Gt(dot, running);
            running = hn::IfThenElse(better, dot, running);
            at = hn::IfThenElse(hn::RebindMask(di, better), where, at);
        };
        for (; i + 4 * lanes <= count; i += 4 * lanes) {
            keep(i, dot0, at0, index);
            keep(i + lanes, dot1, at1, hn::Add(index, step));
            keep(i + 2 * lanes, dot2, at2, hn::Add(index, hn::Add(step, step)));
            keep(i + 3 * lanes, dot3, at3, hn::Add(index, hn::Add(hn::Add(step, step), step)));
            index = hn::Add(index, hn::Add(hn::Add(step, step), hn::Add(step, step)));
        }
        for (; i + lanes <= count; i += lanes) {
            keep(i, dot0, at0, index);
            index = hn::Add(index, step);
        }
        // Merge the four: the larger dot, and on a tie the lower index (the first point).
        const auto merge = [&](decltype(dot0)& running, decltype(at0)& at, const decltype(dot0)& other_dot, const decltype(at0)& other_at) {
            const auto better = hn::Or(hn::Gt(other_dot, running), hn::And(hn::Eq(other_dot, running), hn::RebindMask(df, hn::Lt(other_at, at))));
            running = hn::IfThenElse(better, other_dot, running);
            at = hn::IfThenElse(hn::RebindMask(di, better), other_at, at);
        };
        merge(dot0, at0, dot1, at1);
        merge(dot2, at2, dot3, at3);
        merge(dot0, at0, dot2, at2);
        // Across the lanes: the largest dot, then the lowest index among the lanes holding it.
        const auto largest = hn::MaxOfLanes(df, dot0);
        const auto holders = hn::IfThenElse(hn::RebindMask(di, hn::Eq(dot0, largest)), at0, hn::Set(di, INT32_MAX));
        best_dot = hn::GetLane(largest);
        best = std::uint32_t(hn::GetLane(hn::MinOfLanes(di, holders)));
    }
    for (; i < count; ++i) {  // the tail after the last whole vector: higher indices, strictly better only
        const float dot = (x[i] * dx + y[i] * dy) + z[i] * dz;
        if (dot > best_dot) best_dot = dot, best = i;
    }
    return best;
}

}  // namespace homcull::sort_detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace homcull::sort_detail {

HWY_EXPORT(SupportScanKernel);

std::uint32_t support_scan_reference(const float* x, const float* y, const float* z, std::uint32_t count, float dx, float dy,
                                     float dz) {
    std::uint32_t best = 0;
    float best_dot = -3.4e38f;
    for (std::uint32_t i = 0; i < count; ++i) {
        const float dot = (x[i] * dx + y[i] * dy) + z[i] * dz;
        if (dot > best_dot) best_dot = dot, best = i;
    }
    return best;
}

SupportScan support_scan_for(const detail::IsaChoice& choice) {
    if (choice.scalar) return &support_scan_reference;
    return HOMCULL_KERNEL_FOR(choice, SupportScanKernel);
}

}  // namespace homcull::sort_detail
#endif
