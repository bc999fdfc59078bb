// two_sum_error and accurate_sum4 (raster/triangle_setup.hpp) of double lanes, in Highway's
// "-inl.h" style: included by a kernel file after <hwy/highway.h>, once per target that
// hwy/foreach_target.h compiles (the guard flips with HWY_TARGET_TOGGLE). Each lane makes the
// scalar functions' operations in their order: the same bits. Shared by the batch transform
// (triangle_batch_simd.cpp) and the box rectangles (box_rectangle_simd.cpp).
#if defined(HOMCULL_COMMON_ACCURATE_SUM_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HOMCULL_COMMON_ACCURATE_SUM_INL_H_
#undef HOMCULL_COMMON_ACCURATE_SUM_INL_H_
#else
#define HOMCULL_COMMON_ACCURATE_SUM_INL_H_
#endif

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {

// The rounding error of s = a + b (Knuth's TwoSum), lane by lane.
template <class V>
HWY_INLINE V TwoSumError(V a, V b, V s) {
    namespace hn = hwy::HWY_NAMESPACE;
    const V b_virtual = hn::Sub(s, a);
    return hn::Add(hn::Sub(a, hn::Sub(s, b_virtual)), hn::Sub(b, b_virtual));
}

// p0 + p1 + p2 + p3 as if in twice the precision, then rounded (accurate_sum4), lane by lane.
template <class V>
HWY_INLINE V AccurateSum4(V p0, V p1, V p2, V p3) {
    namespace hn = hwy::HWY_NAMESPACE;
    const V s1 = hn::Add(p0, p1);
    V error = TwoSumError(p0, p1, s1);
    const V s2 = hn::Add(s1, p2);
    error = hn::Add(error, TwoSumError(s1, p2, s2));
    const V s3 = hn::Add(s2, p3);
    error = hn::Add(error, TwoSumError(s2, p3, s3));
    return hn::Add(s3, error);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HOMCULL_COMMON_ACCURATE_SUM_INL_H_
