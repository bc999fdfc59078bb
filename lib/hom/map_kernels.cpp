// The occlusion maps' kernel table (map_kernels.hpp).
#include "hom/map_kernels.hpp"

namespace homcull::detail {

const MapKernels& map_kernels(const IsaChoice& choice) { return kernel_table<MapKernels, &resolve_map_kernels>(choice); }

}  // namespace homcull::detail
