// The raster layer's kernel table (raster_kernels.hpp), assembled from its SIMD units' parts.
#include "raster/raster_kernels.hpp"

namespace homcull::detail {

namespace {
RasterKernels resolve_raster_kernels(const IsaChoice& choice) {
    RasterKernels k{};
    resolve_rasterize_kernels(choice, k);
    resolve_front_end_kernels(choice, k);
    resolve_reference_cells_kernels(choice, k);
    resolve_draw_order_kernels(choice, k);
    return k;
}
}  // namespace

const RasterKernels& raster_kernels(const IsaChoice& choice) { return kernel_table<RasterKernels, &resolve_raster_kernels>(choice); }

}  // namespace homcull::detail
