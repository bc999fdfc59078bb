#pragma once
// One level of the occlusion maps' pyramids from the level below: covered-sample counts summed
// over 2 x 2 cells, the two depth maps' minimum. A plain reference for one output row, and a
// SIMD kernel (opacity_pyramid_simd.cpp) for the cells with four children; sums and minima are
// exact, so every instruction set gives the reference's bits.
#include <cstdint>

namespace homcull::detail {

// One row of the level above, from the rows r0 and r1 of the level below (r1 = r0 at an odd
// bottom edge, counted once). The reduce kernels do the output cells [0, pairs), whose two
// children columns both exist.
struct PyramidRows {
    const std::uint32_t *covered0, *covered1;
    const float *far0, *far1, *near0, *near1;
    bool second_row;
    std::uint32_t* covered_out;
    float *far_out, *near_out;
};

// Output cells [begin, end) of a row; below_width is the row length of the level below.
void reduce_pyramid_row_reference(const PyramidRows& rows, int begin, int end, int below_width);

// The SIMD kernel for the selected instruction set: does cells [0, pairs) and returns how
// many it did (a multiple of its vector length); the caller finishes the row with the
// reference. Null when the scalar reference is selected.
using PyramidRowKernel = int (*)(const PyramidRows& rows, int pairs);
PyramidRowKernel selected_pyramid_row_kernel();

}  // namespace homcull::detail
