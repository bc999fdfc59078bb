// float_up and float_down (rasterize.hpp) of double lanes, in Highway's "-inl.h" style: included
// by a kernel file after <hwy/highway.h>, once per target that hwy/foreach_target.h compiles
// (the guard flips with HWY_TARGET_TOGGLE). Shared by the batch setup (triangle_batch_simd.cpp)
// and the occludee tests (occludee_rows_simd.cpp).
#if defined(HOMCULL_RASTER_FLOAT_OUTWARD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HOMCULL_RASTER_FLOAT_OUTWARD_INL_H_
#undef HOMCULL_RASTER_FLOAT_OUTWARD_INL_H_
#else
#define HOMCULL_RASTER_FLOAT_OUTWARD_INL_H_
#endif

#include <hwy/highway.h>

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {

// A mask of double lanes as a mask of the float lanes they demote to.
template <class D>
HWY_INLINE hwy::HWY_NAMESPACE::Mask<hwy::HWY_NAMESPACE::Rebind<float, D>> FloatLaneMask(D d, hwy::HWY_NAMESPACE::Mask<D> m) {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::Rebind<std::int32_t, D> di;
    return hn::RebindMask(hn::Rebind<float, D>(), hn::Lt(hn::DemoteTo(di, hn::IfThenElseZero(m, hn::Set(d, -1.0))), hn::Zero(di)));
}

// float_up (kUp) or float_down of finite doubles, lane by lane: the nearest float, then one step
// of its bits towards the safe side when it lies on the other. Beyond the float range the
// nearest float is the largest one or infinity, and that step gives float_up's and float_down's
// answers there too (the largest float or infinity on the safe side); NaN stays NaN. An infinite
// input on the safe side's opposite differs: FloatOutward<true>(-inf) is -inf where float_up
// gives the lowest float (and FloatOutward<false>(+inf) +inf): both callers pass finite values.
template <bool kUp, class D>
HWY_INLINE hwy::HWY_NAMESPACE::Vec<hwy::HWY_NAMESPACE::Rebind<float, D>> FloatOutward(D d, hwy::HWY_NAMESPACE::Vec<D> v) {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::Rebind<float, D> df;
    const hn::Rebind<std::int32_t, D> di;
    const auto f = hn::DemoteTo(df, v);
    const auto wrong_side = FloatLaneMask(d, kUp ? hn::Lt(hn::PromoteTo(d, f), v) : hn::Gt(hn::PromoteTo(d, f), v));
    // float_step: away from zero when the step and the sign agree, else towards it; from zero
    // to the smallest denormal of the step's sign.
    const auto bits = hn::BitCast(di, f);
    const auto zero = hn::Zero(df);
    const auto away = hn::RebindMask(di, kUp ? hn::Gt(f, zero) : hn::Lt(f, zero));
    auto stepped = hn::IfThenElse(away, hn::Add(bits, hn::Set(di, 1)), hn::Sub(bits, hn::Set(di, 1)));
    stepped = hn::IfThenElse(hn::RebindMask(di, hn::Eq(f, zero)), hn::Set(di, kUp ? 1 : std::int32_t(0x80000001u)), stepped);
    return hn::IfThenElse(wrong_side, hn::BitCast(df, stepped), f);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HOMCULL_RASTER_FLOAT_OUTWARD_INL_H_
