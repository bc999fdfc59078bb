// Per-target helpers shared by the SIMD kernels, in Highway's "-inl.h" style: included by a file
// after <hwy/highway.h>, once per target that hwy/foreach_target.h compiles (the guard flips
// with HWY_TARGET_TOGGLE), so each target gets its own copy in its own namespace.
#if defined(HOMCULL_RASTER_LANE_BITS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HOMCULL_RASTER_LANE_BITS_INL_H_
#undef HOMCULL_RASTER_LANE_BITS_INL_H_
#else
#define HOMCULL_RASTER_LANE_BITS_INL_H_
#endif

#include <hwy/highway.h>

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {

// The lanes of a mask as bits (lane k: bit k), for at most 32 lanes: the set ones can then be
// visited with a count of trailing zeros, or merged into a word of per-triangle flags.
template <class D>
HWY_INLINE std::uint32_t LaneBits(D d, hwy::HWY_NAMESPACE::Mask<D> mask) {
    static_assert(hwy::HWY_NAMESPACE::MaxLanes(D()) <= 32, "one 32-bit word of lane bits");
    HWY_ALIGN std::uint8_t bytes[8] = {};
    hwy::HWY_NAMESPACE::StoreMaskBits(d, mask, bytes);
    return std::uint32_t(bytes[0]) | std::uint32_t(bytes[1]) << 8 | std::uint32_t(bytes[2]) << 16 | std::uint32_t(bytes[3]) << 24;
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HOMCULL_RASTER_LANE_BITS_INL_H_
