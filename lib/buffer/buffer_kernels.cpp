// The occlusion buffer's kernel table (buffer_kernels.hpp), assembled from the raster layer's
// and its own SIMD units' parts.
#include "buffer/buffer_kernels.hpp"

namespace homcull::detail {

namespace {
BufferKernels resolve_buffer_kernels(const IsaChoice& choice) {
    BufferKernels k{};
    k.raster = raster_kernels(choice);
    resolve_occludee_row_kernels(choice, k);
    resolve_rect_query_kernels(choice, k);
    resolve_box_rectangle_kernel(choice, k);
    resolve_occludee_rectangle_kernel(choice, k);
    return k;
}
}  // namespace

const BufferKernels& buffer_kernels(const IsaChoice& choice) { return kernel_table<BufferKernels, &resolve_buffer_kernels>(choice); }

}  // namespace homcull::detail
