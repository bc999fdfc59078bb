#pragma once
// The inner loop of every hull test: which of a hull's points lies farthest along a direction.
// A scalar reference and a SIMD kernel per instruction set (common/isa_choice.hpp); both
// return the first point (lowest index) of the largest dot product, computed as
// (x * dx + y * dy) + z * dz without fused multiply-adds, so every instruction set gives the
// same answer.
#include "common/isa_choice.hpp"

#include <cstdint>

namespace homcull::sort_detail {

using SupportScan = std::uint32_t (*)(const float* x, const float* y, const float* z, std::uint32_t count, float dx, float dy,
                                      float dz);

std::uint32_t support_scan_reference(const float* x, const float* y, const float* z, std::uint32_t count, float dx, float dy,
                                     float dz);

// The scan for an instruction set choice (the reference for the scalar choice).
SupportScan support_scan_for(const detail::IsaChoice& choice);

}  // namespace homcull::sort_detail
