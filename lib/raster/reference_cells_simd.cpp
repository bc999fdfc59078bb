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

// drop_hidden_noted over `count` positions, a vector of notes at a time: the four corner
// cells of each note's box gathered (hidden_by_record's 2 x 2 path, the boxes of nearly every
// S1 triangle), the kept triangles' numbers compressed into undecided[]; a lane whose box
// spans more cells is decided by hidden_by_record itself. Min and >= are exact: the same
// answers as the scalar loop. (The scalar loop took about 17 cycles a note on S1: the fast
// path's branch and the dependent loads.)
std::size_t DropHiddenNoted(const ReferenceCells& cells, const ListedNote* notes, std::size_t count, std::uint32_t* undecided) {
    const hn::ScalableTag<std::uint32_t> du;
    const hn::RebindToSigned<decltype(du)> di;
    const hn::RebindToFloat<decltype(du)> df;
    const std::size_t lanes = hn::Lanes(du);
    const auto byte = hn::Set(du, 0xFFu);
    const auto width = hn::Set(du, std::uint32_t(cells.width));
    std::size_t kept = 0, k = 0;
    for (; k + lanes <= count; k += lanes) {
        hn::Vec<decltype(du)> box, nearest_bits, triangle;
        hn::LoadInterleaved3(du, reinterpret_cast<const std::uint32_t*>(notes + k), box, nearest_bits, triangle);
        const auto cx0 = hn::And(box, byte), cx1 = hn::And(hn::ShiftRight<8>(box), byte);
        const auto cy0 = hn::And(hn::ShiftRight<16>(box), byte), cy1 = hn::ShiftRight<24>(box);
        // The box's cells (cx0 + dx, cy0 + dy), dx and dy up to the vector's largest span, each
        // clamped to the lane's own box (a cell read twice changes no minimum).
        const auto span_x = hn::Sub(cx1, cx0), span_y = hn::Sub(cy1, cy0);
        const int max_dx = int(hn::GetLane(hn::MaxOfLanes(du, span_x))), max_dy = int(hn::GetLane(hn::MaxOfLanes(du, span_y)));
        auto visible = hn::Lt(hn::Zero(df), hn::Zero(df));  // no lane yet
        const auto nearest = hn::BitCast(df, nearest_bits);
        for (int dy = 0; dy <= max_dy; ++dy) {
            const auto row = hn::Mul(hn::Min(hn::Add(cy0, hn::Set(du, std::uint32_t(dy))), cy1), width);
            for (int dx = 0; dx <= max_dx; ++dx) {
                const auto cell = hn::Add(row, hn::Min(hn::Add(cx0, hn::Set(du, std::uint32_t(dx))), cx1));
                visible = hn::Or(visible, hn::Lt(hn::GatherIndex(df, cells.min_d0, hn::BitCast(di, cell)), nearest));
            }
        }
        // NaN (no note): never hidden.
        const auto hidden = hn::RebindMask(du, hn::AndNot(visible, hn::Eq(nearest, nearest)));
        kept += hn::CompressStore(triangle, hn::Not(hidden), du, undecided + kept);
    }
    return kept + drop_hidden_noted(cells, notes + k, count - k, undecided + kept);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/resolved_kernel.hpp"

namespace homcull::detail {

HWY_EXPORT(RefreshReferenceCells);
HWY_EXPORT(DropHiddenNoted);

// Only the setup's hidden test reads the cells, and the scalar reference sets triangles up one
// by one without it: no cells then.
RefreshCellsKernel selected_refresh_cells() {
    return scalar_reference_selected() ? nullptr : HOMCULL_RESOLVED_KERNEL(RefreshReferenceCells);
}

DropHiddenKernel selected_drop_hidden() { return HOMCULL_RESOLVED_KERNEL(DropHiddenNoted); }

}  // namespace homcull::detail
#endif  // HWY_ONCE
