// The extent scan (extent_scan.hpp) in SIMD: a lane per extent, the seven comparisons as masks,
// the ids of the lanes that pass compressed into the output in order.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "sort/extent_scan_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "sort/extent_scan.hpp"

HWY_BEFORE_NAMESPACE();
namespace homcull::sort_detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

std::uint32_t ExtentScanKernel(const ExtentColumns& columns, std::uint32_t first, std::uint32_t count, const Extent& box,
                               float farthest, std::uint32_t* out) {
    const hn::ScalableTag<float> df;
    const hn::RebindToUnsigned<decltype(df)> du;
    const std::uint32_t lanes = std::uint32_t(hn::Lanes(df));
    const auto far = hn::Set(df, farthest);
    std::uint32_t written = 0;
    for (std::uint32_t k = 0; k < count; k += lanes) {
        const std::uint32_t i = first + k;
        // As boxes_overlap and the scalar reference: !(hi < box.lo) and !(box.hi < lo), so that
        // a NaN compares the same way here.
        auto keep = hn::Lt(hn::LoadU(df, columns.nearest + i), far);
        for (int a = 0; a < 3; ++a) {
            keep = hn::AndNot(hn::Lt(hn::LoadU(df, columns.hi[a] + i), hn::Set(df, box.lo[a])), keep);
            keep = hn::AndNot(hn::Lt(hn::Set(df, box.hi[a]), hn::LoadU(df, columns.lo[a] + i)), keep);
        }
        if (count - k < lanes) keep = hn::And(keep, hn::FirstN(df, count - k));
        written += std::uint32_t(hn::CompressStore(hn::LoadU(du, columns.ids + i), hn::RebindMask(du, keep), du, out + written));
    }
    return written;
}

}  // namespace homcull::sort_detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace homcull::sort_detail {

HWY_EXPORT(ExtentScanKernel);

std::uint32_t extent_scan_reference(const ExtentColumns& columns, std::uint32_t first, std::uint32_t count, const Extent& box,
                                    float farthest, std::uint32_t* out) {
    std::uint32_t written = 0;
    for (std::uint32_t i = first; i < first + count; ++i) {
        bool keep = columns.nearest[i] < farthest;
        for (int a = 0; a < 3; ++a) keep = keep && !(columns.hi[a][i] < box.lo[a]) && !(box.hi[a] < columns.lo[a][i]);
        if (keep) out[written++] = columns.ids[i];
    }
    return written;
}

ExtentScan extent_scan_for(const detail::IsaChoice& choice) {
    if (choice.scalar) return &extent_scan_reference;
    return HOMCULL_KERNEL_FOR(choice, ExtentScanKernel);
}

}  // namespace homcull::sort_detail
#endif
