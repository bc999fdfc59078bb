#pragma once
// The occlusion maps' kernels for one instruction set, resolved once per choice
// (common/isa_choice.hpp). Maps are built from a buffer and run its instruction set.
#include "common/isa_choice.hpp"
#include "hom/opacity_pyramid.hpp"
#include "raster/rasterize.hpp"

#include <cstdint>

namespace homcull::detail {

// A row of the summed-area table of covered samples: row[k + 1] = above[k + 1] + the set bits
// of masks[0..k], for k < count (row[0] is left alone). Reads and writes nothing past them.
using CoveredSumsRowKernel = void (*)(const std::uint32_t* masks, int count, const std::uint32_t* above, std::uint32_t* row);
// Its subtiles k from `begin` on, given `run`, the set bits of masks[0..begin): the scalar
// choice's kernel (from 0) and the SIMD kernels' last few subtiles.
inline void covered_sums_row_from(const std::uint32_t* masks, int begin, int count, const std::uint32_t* above, std::uint32_t* row,
                                  std::uint32_t run) {
    for (int k = begin; k < count; ++k) {
        run += bit_count(masks[k]);
        row[k + 1] = above[k + 1] + run;
    }
}

struct MapKernels {
    // Null for the scalar choice: the reference paths then do every cell.
    Level0Kernel level0 = nullptr;
    PyramidRowKernel reduce_row = nullptr;
    CoveredSumsRowKernel covered_sums_row = nullptr;  // covered_sums_simd.cpp
};

const MapKernels& map_kernels(const IsaChoice& choice);

// Each SIMD translation unit's part of the table (they hold the HWY_EXPORTs).
MapKernels resolve_map_kernels(const IsaChoice& choice);  // opacity_pyramid_simd.cpp
void resolve_covered_sums_kernel(const IsaChoice& choice, MapKernels& kernels);

}  // namespace homcull::detail
