// The reference cells' kernels (reference_cells.hpp): the refresh, a cell's 8 subtiles of a row
// in one vector of 8 floats (two of 4 on SSE4 and NEON), the minimum over its 8 rows, then over
// the lanes; and the drop of noted triangles hidden behind the cells, a note per lane. The block
// tables' update is plain C++ (a few thousand minima per refresh).
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

// drop_hidden_noted over `count` notes, a vector at a time: the smallest cell of each note's
// box from four reads of a block table (kCellTables: blocks of 2^kx x 2^ky cells at the box's
// corners, overlapping), the kept triangles' numbers compressed into undecided[]; a lane whose
// box spans more than 8 cells a side is decided by hidden_by_note itself. Min and >= are
// exact: the same answers as the scalar loop. (The scalar loop took about 17 cycles a note on
// S1, its branch on the box's size mispredicted; gathering every cell of the vector's largest
// box about 12.)
std::size_t DropHiddenNoted(const ReferenceCells& cells, const TriangleNote* notes, std::size_t count, std::uint32_t* undecided) {
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
        // Blocks of 2^k cells a side, k = 0 for one cell, 1 for 2 or 3, 2 for 4 to 8 (two blocks
        // overlapping or meeting cover the side). Wider boxes are decided below.
        const auto span_x = hn::BitCast(di, hn::Sub(cx1, cx0)), span_y = hn::BitCast(di, hn::Sub(cy1, cy0));
        const auto one = hn::Set(di, 1), two = hn::Set(di, 2);
        const auto level = [&](auto span) {  // (span > 0) + (span > 2): masks are -1
            return hn::Neg(hn::Add(hn::VecFromMask(di, hn::Gt(span, hn::Zero(di))), hn::VecFromMask(di, hn::Gt(span, two))));
        };
        const auto kx = level(span_x), ky = level(span_y);
        const auto wide = hn::Or(hn::Gt(span_x, hn::Set(di, 7)), hn::Gt(span_y, hn::Set(di, 7)));
        // The far blocks start 2^k - 1 cells before the box's far edge.
        const auto x0 = hn::BitCast(di, cx0), y0 = hn::BitCast(di, cy0);
        const auto x1 = hn::Add(hn::Sub(hn::BitCast(di, cx1), hn::Shl(one, kx)), one);
        const auto y1 = hn::Add(hn::Sub(hn::BitCast(di, cy1), hn::Shl(one, ky)), one);
        const auto table = hn::Mul(hn::Add(hn::Mul(ky, hn::Set(di, kCellBlockLevels)), kx), hn::Set(di, cells.width * cells.height));
        const auto w = hn::BitCast(di, width);
        const auto read = [&](auto x, auto y) { return hn::GatherIndex(df, cells.min_d0, hn::Add(table, hn::Add(hn::Mul(y, w), x))); };
        const auto smallest = hn::Min(hn::Min(read(x0, y0), read(x1, y0)), hn::Min(read(x0, y1), read(x1, y1)));
        auto hidden = hn::RebindMask(du, hn::Ge(smallest, hn::BitCast(df, nearest_bits)));  // NaN (no note): never hidden
        if (!hn::AllFalse(di, wide)) {
            HWY_ALIGN std::uint32_t hidden_lanes[hn::MaxLanes(du)];
            hn::Store(hn::VecFromMask(du, hidden), du, hidden_lanes);
            HWY_ALIGN std::int32_t wide_lanes[hn::MaxLanes(di)];
            hn::Store(hn::VecFromMask(di, wide), di, wide_lanes);
            for (std::size_t l = 0; l < lanes; ++l)
                if (wide_lanes[l]) hidden_lanes[l] = hidden_by_note(cells, notes[k + l].note) ? ~0u : 0u;
            hidden = hn::MaskFromVec(hn::Load(du, hidden_lanes));
        }
        kept += hn::CompressStore(triangle, hn::Not(hidden), du, undecided + kept);
    }
    return kept + drop_hidden_noted(cells, notes + k, count - k, undecided + kept);
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/raster_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(RefreshReferenceCells);
HWY_EXPORT(DropHiddenNoted);

// Only the setup's hidden test reads the cells, and the scalar reference sets triangles up one
// by one without it: no cells then.
void resolve_reference_cells_kernels(const IsaChoice& choice, RasterKernels& k) {
    k.refresh_cells = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, RefreshReferenceCells);
    k.drop_hidden = HOMCULL_KERNEL_FOR(choice, DropHiddenNoted);  // integer work: one answer everywhere
}

void update_cell_blocks(const ReferenceCells& cells, int cell_row_begin, int cell_row_end) {
    const int width = cells.width, height = cells.height;
    const auto row = [&](int kx, int ky, int cy) {
        return cells.min_d0 + cell_table_offset(cells, kx, ky) + std::size_t(cy) * std::size_t(width);
    };
    // Rows of each level from the level before: wider blocks from two of half the width in the
    // same row, taller ones from two of half the height, the second clamped to the grid.
    for (int cy = cell_row_begin; cy < cell_row_end; ++cy)
        for (int kx = 1; kx < kCellBlockLevels; ++kx) {
            const float* half = row(kx - 1, 0, cy);
            float* out = row(kx, 0, cy);
            const int step = 1 << (kx - 1);
            for (int cx = 0; cx < width; ++cx) out[cx] = std::min(half[cx], half[std::min(cx + step, width - 1)]);
        }
    for (int ky = 1; ky < kCellBlockLevels; ++ky) {
        const int step = 1 << (ky - 1);
        for (int cy = std::max(0, cell_row_begin - ((1 << ky) - 1)); cy < cell_row_end; ++cy)
            for (int kx = 0; kx < kCellBlockLevels; ++kx) {
                const float* top = row(kx, ky - 1, cy);
                const float* bottom = row(kx, ky - 1, std::min(cy + step, height - 1));
                float* out = row(kx, ky, cy);
                for (int cx = 0; cx < width; ++cx) out[cx] = std::min(top[cx], bottom[cx]);
            }
    }
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
