#pragma once
// The occlusion maps' kernels for one instruction set, resolved once per choice
// (common/isa_choice.hpp). Maps are built from a buffer and run its instruction set.
#include "common/isa_choice.hpp"
#include "hom/opacity_pyramid.hpp"

#include <cstdint>

namespace homcull::detail {

// counts[k] = the set bits of masks[k] for k < count; may read and write a whole vector past
// count (rows and counts padded for kMaxSimdLanes).
using CoveredCountsKernel = void (*)(const std::uint32_t* masks, int count, std::uint32_t* counts);

struct MapKernels {
    // Null for the scalar choice: the reference paths then do every cell.
    Level0Kernel level0 = nullptr;
    PyramidRowKernel reduce_row = nullptr;
    CoveredCountsKernel covered_counts = nullptr;  // covered_counts_simd.cpp
};

const MapKernels& map_kernels(const IsaChoice& choice);

// Each SIMD translation unit's part of the table (they hold the HWY_EXPORTs).
MapKernels resolve_map_kernels(const IsaChoice& choice);  // opacity_pyramid_simd.cpp
void resolve_covered_counts_kernel(const IsaChoice& choice, MapKernels& kernels);

}  // namespace homcull::detail
