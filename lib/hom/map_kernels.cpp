// The occlusion maps' kernel table (map_kernels.hpp).
#include "hom/map_kernels.hpp"

namespace homcull::detail {
namespace {

MapKernels resolve_all(const IsaChoice& choice) {
    MapKernels kernels = resolve_map_kernels(choice);
    resolve_covered_sums_kernel(choice, kernels);
    return kernels;
}

}  // namespace

const MapKernels& map_kernels(const IsaChoice& choice) { return kernel_table<MapKernels, &resolve_all>(choice); }

}  // namespace homcull::detail
