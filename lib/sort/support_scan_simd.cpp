// The support scan (support_scan.hpp) in SIMD: each lane keeps its best dot product and that
// point's index; the lanes' winners are compared at the end, ties to the lowest index.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "sort/support_scan_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "sort/support_scan.hpp"

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
        auto lane_dot = hn::Set(df, -3.4e38f);
        auto lane_index = hn::Zero(di);
        auto index = hn::Iota(di, 0);
        const auto step = hn::Set(di, std::int32_t(lanes));
        for (; i + lanes <= count; i += lanes) {
            const auto dot = hn::Add(hn::Add(hn::Mul(hn::LoadU(df, x + i), vx), hn::Mul(hn::LoadU(df, y + i), vy)),
                                     hn::Mul(hn::LoadU(df, z + i), vz));
            const auto better = hn::Gt(dot, lane_dot);
            lane_dot = hn::IfThenElse(better, dot, lane_dot);
            lane_index = hn::IfThenElse(hn::RebindMask(di, better), index, lane_index);
            index = hn::Add(index, step);
        }
        HWY_ALIGN float dots[hn::MaxLanes(df)];
        HWY_ALIGN std::int32_t indices[hn::MaxLanes(di)];
        hn::Store(lane_dot, df, dots);
        hn::Store(lane_index, di, indices);
        best_dot = dots[0], best = std::uint32_t(indices[0]);
        for (std::uint32_t j = 1; j < lanes; ++j) {
            const std::uint32_t at = std::uint32_t(indices[j]);
            if (dots[j] > best_dot || (dots[j] == best_dot && at < best)) best_dot = dots[j], best = at;
        }
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
