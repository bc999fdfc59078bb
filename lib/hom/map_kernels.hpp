#pragma once
// The occlusion maps' kernels for one instruction set, resolved once per choice
// (common/isa_choice.hpp). Maps are built from a buffer and run its instruction set.
#include "common/isa_choice.hpp"
#include "hom/opacity_pyramid.hpp"

namespace homcull::detail {

struct MapKernels {
    // Null for the scalar choice: the reference paths then do every cell.
    Level0Kernel level0;
    PyramidRowKernel reduce_row;
};

const MapKernels& map_kernels(const IsaChoice& choice);

// opacity_pyramid_simd.cpp's part (it holds the HWY_EXPORTs).
MapKernels resolve_map_kernels(const IsaChoice& choice);

}  // namespace homcull::detail
