#pragma once
// The occlusion buffer's kernels for one instruction set: the raster layer's table and the
// queries' own, resolved once per choice (common/isa_choice.hpp). A buffer holds a pointer to
// the table of the instruction set it was made with (BufferConfig::isa) and every render,
// task and query it runs, on any thread, reads its kernels there.
#include "buffer/occludee_depth.hpp"
#include "buffer/occludee_rectangles.hpp"
#include "buffer/rect_queries.hpp"
#include "raster/raster_kernels.hpp"

namespace homcull::detail {

struct BufferKernels {
    RasterKernels raster;
    // The queries' SIMD kernels; null for the scalar choice (the scalar paths answer the same)
    // unless said otherwise.
    OccludeeRowKernel occludee_row;  // occludee_depth.hpp
    SampleDepthUnhiddenKernel sample_depth_unhidden;  // occludee_depth.hpp; the reference for the scalar choice
    RectBlockKernel rect_block;
    RectOneKernel rect_one;
    RectPreparedKernel rect_prepared;
    BoxRectangleKernel box_rectangle;
    OccludeeRectanglesKernel occludee_rectangles;  // occludee_rectangles.hpp
};

// box_rectangle through a kernel table: its SIMD kernel for a perspective matrix, the scalar
// function otherwise; the same rectangle and answer either way.
inline bool box_rectangle(const BufferKernels& kernels, const float box_min[3], const float box_max[3],
                          const std::array<float, 16>& model_to_clip, float near_w, bool orthographic, ScreenRect& rect, Visibility& decided) {
    if (!orthographic && kernels.box_rectangle) return kernels.box_rectangle(box_min, box_max, model_to_clip, near_w, rect, decided);
    return box_rectangle(box_min, box_max, model_to_clip, near_w, orthographic, rect, decided);
}

const BufferKernels& buffer_kernels(const IsaChoice& choice);

// Each SIMD translation unit's part of the table (they hold the HWY_EXPORTs).
void resolve_occludee_row_kernels(const IsaChoice& choice, BufferKernels& kernels);
void resolve_rect_query_kernels(const IsaChoice& choice, BufferKernels& kernels);
void resolve_box_rectangle_kernel(const IsaChoice& choice, BufferKernels& kernels);
void resolve_occludee_rectangle_kernel(const IsaChoice& choice, BufferKernels& kernels);

}  // namespace homcull::detail
