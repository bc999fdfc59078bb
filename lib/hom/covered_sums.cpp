// The maps without their pyramids (PyramidBuild::lazy, conservative mode, masked depth): the
// buffer's own depth test answers, and the covered samples summed over subtiles give a visible
// occludee's uncovered share. A summed-area table (Crow, "Summed-area tables for texture
// mapping", SIGGRAPH 1984) makes the share of any rectangle cost its border subtiles alone.
#include "hom/maps_state.hpp"

#include "buffer/buffer_state.hpp"
#include "buffer/rect_queries.hpp"
#include "hom/map_kernels.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// The scalar choice's CoveredSumsRowKernel.
void covered_sums_row_reference(const std::uint32_t* masks, int count, const std::uint32_t* above, std::uint32_t* row) {
    detail::covered_sums_row_from(masks, 0, count, above, row, 0u);
}

}  // namespace

// One pass over the subtiles' coverage masks: a fortieth of the pyramids' work at one sample
// per pixel (one 32-bit mask a subtile against a count, and depths, per pixel), a row at a time
// by the instruction set's kernel (map_kernels.hpp).
void detail::MapsState::sum_covered_samples() {
    const detail::BufferState& state = built_->state();
    const int tiles_x = sums_width_ - 1, tiles_y = int(covered_sums_.size() / std::size_t(sums_width_)) - 1;
    const detail::CoveredSumsRowKernel sum_row = built_with_->covered_sums_row ? built_with_->covered_sums_row : &covered_sums_row_reference;
    std::uint32_t* sums = covered_sums_.data();
    for (int ty = 0; ty < tiles_y; ++ty)
        sum_row(state.covered_.data() + state.at(0, ty), tiles_x, sums + std::size_t(ty) * std::size_t(sums_width_),
                sums + std::size_t(ty + 1) * std::size_t(sums_width_));
}

// Uncovered samples of [i0, i1] x [j0, j1] (inside the buffer): the subtiles wholly inside from
// the table, the border ones from their masks.
std::uint64_t detail::MapsState::uncovered_by_sums(int i0, int i1, int j0, int j1) const {
    const detail::BufferState& state = built_->state();
    const detail::RectQuery q{i0, i1, j0, j1, 0.0f};
    const auto [ix0, ix1, iy0, iy1] = detail::interior_subtiles(q);
    std::uint64_t covered = 0;
    const bool interior = ix0 <= ix1 && iy0 <= iy1;
    if (interior) {
        const auto sum = [&](int tx, int ty) { return std::uint64_t(covered_sums_[std::size_t(ty) * std::size_t(sums_width_) + std::size_t(tx)]); };
        covered = sum(ix1 + 1, iy1 + 1) + sum(ix0, iy0) - sum(ix0, iy1 + 1) - sum(ix1 + 1, iy0);
    }
    // A subtile's samples in the rectangle: its columns in the rectangle (repeated on each of its
    // kH rows of kW bits) and its rows in it (kW bits each), as subtile_rect_bits gives them.
    static_assert(kW == 8 && kH == 4, "one byte per subtile row");
    const auto column_bits = [&](int tx) {
        const int c0 = std::max(0, i0 - tx * kW), c1 = std::min(kW - 1, i1 - tx * kW);
        return ((0xFFu >> (kW - 1 - c1)) & (0xFFu << c0)) * 0x01010101u;
    };
    const auto row_bits = [&](int ty) {
        const int r0 = std::max(0, j0 - ty * kH), r1 = std::min(kH - 1, j1 - ty * kH);
        return std::uint32_t(((std::uint64_t(1) << (8 * (r1 - r0 + 1))) - 1u) << (8 * r0));
    };
    const int tx0 = i0 / kW, tx1 = i1 / kW;
    const auto masks_of = [&](int ty) { return state.covered_.data() + state.at(0, ty); };
    for (int ty = j0 / kH; ty <= j1 / kH; ++ty) {
        if (interior && ty == iy0) {
            // The interior's rows hold all their subtiles' rows: only the border subtile left
            // of the interior and the one right of it (when the rectangle cuts them) remain,
            // each with the same columns on every row.
            const std::uint32_t left = ix0 > tx0 ? column_bits(tx0) : 0u, right = ix1 < tx1 ? column_bits(tx1) : 0u;
            if (left | right)
                for (int row = iy0; row <= iy1; ++row) {
                    const std::uint32_t* masks = masks_of(row);
                    covered += detail::bit_count(left & masks[tx0]) + detail::bit_count(right & masks[tx1]);
                }
            ty = iy1;
            continue;
        }
        // A row the rectangle cuts (or any, without an interior): every subtile between the
        // first and the last holds all its columns.
        const std::uint32_t rows = row_bits(ty);
        const std::uint32_t* masks = masks_of(ty);
        covered += detail::bit_count(column_bits(tx0) & rows & masks[tx0]);
        if (tx1 > tx0) covered += detail::bit_count(column_bits(tx1) & rows & masks[tx1]);
        for (int tx = tx0 + 1; tx < tx1; ++tx) covered += detail::bit_count(rows & masks[tx]);
    }
    return std::uint64_t(i1 - i0 + 1) * std::uint64_t(j1 - j0 + 1) - covered;
}

// The buffer's depth test decides (it finds a rectangle hidden only where every sample is
// covered, so an overlap test could add nothing); a visible rectangle's level of visibility is
// its uncovered share, or 1 when it is covered everywhere (then in front of an occluder
// somewhere, as the overlap-then-depth answer has it).
OccludeeAnswer detail::MapsState::buffer_answer(const RectQuery& q) const {
    OccludeeAnswer answer;
    answer.overlap_exit = std::uint8_t(OverlapExit::not_run);
    if (built_->state().test_prepared_rect(q) == Visibility::occluded) {
        answer.visibility = Visibility::occluded;
        answer.level_of_visibility = 0.0f;
        return answer;
    }
    const std::uint64_t uncovered = uncovered_by_sums(q.i0, q.i1, q.j0, q.j1);
    answer.level_of_visibility =
        uncovered == 0 ? 1.0f : float(double(uncovered) / (double(q.i1 - q.i0 + 1) * double(q.j1 - q.j0 + 1)));
    return answer;
}

}  // namespace homcull
