// The refresh of the reference cells (reference_cells.hpp): a cell's 8 subtiles of a row in
// one vector of 8 floats (two of 4 on SSE4 and NEON), the minimum over its 8 rows, then over
// the lanes.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/reference_cells_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/reference_cells.hpp"

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void RefreshReferenceCells(const SubtilePlanes& planes, int subtiles_x, int subtiles_y, int cell_row_begin, int cell_row_end,
                           const ReferenceCells& cells) {
    constexpr int kSpan = 1 << kReferenceCellShift;
    const hn::CappedTag<float, kSpan> d;
    const hn::RebindToSigned<decltype(d)> di;
    const int lanes = int(hn::Lanes(d));
    const auto infinity = hn::Set(d, HUGE_VALF);
    for (int cy = cell_row_begin; cy < cell_row_end; ++cy) {
        const int ty_end = std::min(subtiles_y, (cy + 1) * kSpan);
        float* out = cells.min_d0 + std::size_t(cy) * std::size_t(cells.width);
        for (int cx = 0; cx * kSpan < subtiles_x; ++cx) {
            auto smallest = infinity;
            for (int part = 0; part < kSpan; part += lanes) {
                const int tx = cx * kSpan + part;
                // Lanes past the grid's last column read the rows' padding (planes.stride
                // leaves a whole vector of it) and are left out.
                const auto inside = hn::RebindMask(d, hn::Lt(hn::Iota(di, tx), hn::Set(di, subtiles_x)));
                for (int ty = cy * kSpan; ty < ty_end; ++ty)
                    smallest = hn::Min(smallest, hn::IfThenElse(inside, hn::LoadU(d, planes.d0 + std::size_t(ty) * planes.stride + std::size_t(tx)),
                                                                infinity));
            }
            out[cx] = hn::GetLane(hn::MinOfLanes(d, smallest));
        }
    }
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/resolved_kernel.hpp"

namespace homcull::detail {

HWY_EXPORT(RefreshReferenceCells);

// Only the setup's hidden test reads the cells, and the scalar reference sets triangles up one
// by one without it: no cells then.
RefreshCellsKernel selected_refresh_cells() {
    return scalar_reference_selected() ? nullptr : HOMCULL_RESOLVED_KERNEL(RefreshReferenceCells);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
