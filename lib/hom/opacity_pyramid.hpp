#pragma once
// Level 0 of the occlusion maps from the buffer's subtiles (per pixel: covered samples, the
// farthest and the nearest bound of the covered samples), and one level of the pyramids from
// the level below: covered-sample counts summed
// over 2 x 2 cells, the two depth maps' minimum. A plain reference for one output row, and a
// SIMD kernel (opacity_pyramid_simd.cpp) for the cells with four children; sums and minima are
// exact, so every instruction set gives the reference's bits.
#include "raster/rasterize.hpp"

#include <cstddef>
#include <cstdint>

namespace homcull::detail {

// The buffer's subtile planes (OcclusionBuffer's layout) and the level-0 maps to fill.
struct Level0Maps {
    const std::uint32_t *covered, *mask;
    const float *d0, *d1;
    std::size_t stride;
    int subtiles_x, subtiles_y;
    int width, height, samples;  // buffer pixels and samples per axis (1, 2 or 4)
    std::uint32_t* covered_out;  // width x height, row-major
    float *far_out, *near_out;   // either may be null: not made (OcclusionMapsConfig::depth_pyramids)
};

// Level 0 for the subtile columns [tx_begin, subtiles_x) of every subtile row: a pixel's
// covered samples; its farthest covered bound (d0 for samples outside the subtile's working
// mask, max(d0, d1) inside it) and its nearest; +inf for both when nothing covers it.
void level0_reference(const Level0Maps& maps, int tx_begin);
// An instruction set's SIMD kernel (S = 1: a subtile row's 8 pixels as lanes): does the
// subtile columns [0, returned) whose pixels all exist (MapKernels::level0).
using Level0Kernel = int (*)(const Level0Maps& maps);

// One row of the level above, from the rows r0 and r1 of the level below (r1 = r0 at an odd
// bottom edge, counted once). The reduce kernels do the output cells [0, pairs), whose two
// children columns both exist.
struct PyramidRows {
    const std::uint32_t *covered0, *covered1;
    const float *far0, *far1, *near0, *near1;  // null with far_out / near_out
    bool second_row;
    std::uint32_t* covered_out;
    float *far_out, *near_out;  // either may be null: that pyramid is not made
};

// Output cells [begin, end) of a row; below_width is the row length of the level below.
void reduce_pyramid_row_reference(const PyramidRows& rows, int begin, int end, int below_width);

// An instruction set's SIMD kernel (MapKernels::reduce_row): does cells [0, pairs) and returns
// how many it did (a multiple of its vector length); the caller finishes the row with the
// reference.
using PyramidRowKernel = int (*)(const PyramidRows& rows, int pairs);

}  // namespace homcull::detail
