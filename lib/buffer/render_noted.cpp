// A clip-space soup drawn nearest first through its cell notes (raster/reference_cells.hpp,
// raster/draw_order.hpp: sort_noting_cells): on one thread as one part of the rows
// (render_noted), with a job system in parts of rows, one task each (render_parts). Each part
// drops the noted triangles hidden behind its reference cells without reading them.
// render_triangles.cpp chooses this path.
#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "buffer/render_bands.hpp"
#include "common/run_tasks.hpp"
#include "raster/rasterize.hpp"
#include "raster/reference_cells.hpp"
#include "raster/triangle_batch.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace homcull {
namespace {

constexpr int kH = OcclusionBuffer::kSubtileHeight;
using detail::kCellRefreshTriangles;

}  // namespace

// One thread: the buffer is one part. Every slice refreshes the cells of the rows it changed,
// so that they hold the buffer's d0 at the end, and the next noted render on one thread starts
// from them.
void detail::BufferState::render_noted(const TriangleInput& in, bool clear_first, detail::DrawList list) {
    if (noted_parts_.empty()) noted_parts_.resize(1);
    if (noted_parts_[0].undecided.size() < kCellRefreshTriangles) noted_parts_[0].undecided.resize(kCellRefreshTriangles);
    // Not current while the cells are being changed (should the render stop half-way).
    const bool cells_current = std::exchange(reference_cells_current_, false);
    draw_noted_part(in, list, clear_first, 0, 0, subtiles_y_, cells_current);
    reference_cells_current_ = true;
    stats_ += noted_parts_[0].stats;
    build_changed_pyramid(clear_first, noted_parts_[0].changed);
}

detail::ReferenceCells detail::BufferState::start_reference_cells(bool clear_first, std::size_t part, int row_begin, int row_end,
                                                               bool cells_current) {
    const int height = detail::reference_cells_height(subtiles_y_);
    const std::size_t size = std::size_t(reference_cells_width_) * std::size_t(height);  // of the cells (table (0, 0))
    float* first = reference_cells_.data() + part * std::size_t(detail::kCellTables) * size;
    const detail::ReferenceCells cells{first, reference_cells_width_, height};
    const std::size_t width = std::size_t(reference_cells_width_);
    const std::size_t own_begin = std::size_t(row_begin >> detail::kReferenceCellShift) * width;
    const std::size_t own_end = std::min(size, std::size_t(((row_end - 1) >> detail::kReferenceCellShift) + 1) * width);
    // One part over every row, and the cells still those the last noted render on one thread
    // left (nothing else drew since): they are this buffer's, as a refresh would compute them.
    if (cells_current && !clear_first && part == 0 && row_begin == 0 && row_end == subtiles_y_) return cells;
    std::fill(first, first + own_begin, std::numeric_limits<float>::infinity());
    std::fill(first + own_end, first + size, std::numeric_limits<float>::infinity());
    if (clear_first) {
        std::fill(first + own_begin, first + own_end, 0.0f);  // d0 >= 0 everywhere
    } else {
        const detail::SubtilePlanes planes{d0_.data(), d1_.data(), mask_.data(), covered_.data(), stride_, nullptr, 0};
        kernels_->raster.refresh_cells(planes, subtiles_x_, subtiles_y_, int(own_begin / width), int(own_end / width), cells);
    }
    detail::update_cell_blocks(cells, 0, height);  // every row: the infinite ones too
    return cells;
}

void detail::BufferState::refresh_reference_cells(const detail::ReferenceCells& cells, int row_begin, int row_end) {
    if (!cells.min_d0 || row_begin >= row_end) return;
    const detail::SubtilePlanes planes{d0_.data(), d1_.data(), mask_.data(), covered_.data(), stride_, nullptr, 0};
    const int cell_row_begin = row_begin >> detail::kReferenceCellShift, cell_row_end = ((row_end - 1) >> detail::kReferenceCellShift) + 1;
    kernels_->raster.refresh_cells(planes, subtiles_x_, subtiles_y_, cell_row_begin, cell_row_end, cells);
    detail::update_cell_blocks(cells, cell_row_begin, cell_row_end);
}

// The list is taken in slices of kCellRefreshTriangles: a noted triangle hidden behind the
// part's cells (every noted triangle outside its rows, whose cells are infinite) is dropped
// unread, the others go through the setup and are drawn into the part's rows, and the cells of
// the rows the slice changed are refreshed after it. Every part counts the triangles it drops
// as the setup counts a hidden one (triangles_in and rasterized), and the setup counts the
// others as it would for the whole buffer (a triangle outside the target's rows is hidden
// there): so each part's statistics are the whole render's, but for subtiles_updated.
void detail::BufferState::draw_noted_part(const TriangleInput& in, detail::DrawList list, bool clear_first, std::size_t part, int row_begin,
                                      int row_end, bool cells_current) {
    NotedPart& scratch = noted_parts_[part];
    scratch.drawn = true;
    scratch.changed = {};
    if (clear_first) clear_rows(row_begin, row_end);
    const detail::RasterTarget target = raster_target(row_begin, row_end);
    const detail::ReferenceCells cells = start_reference_cells(clear_first, part, row_begin, row_end, cells_current);
    RasterStats stats;
    int changed_begin = row_end, changed_end = row_begin;  // the subtile rows changed since the last refresh
    // The triangles drawn per cell row of the part, counted here and copied out at the end: the
    // parts' counts share cache lines of cell_row_load_.
    const int first_cell_row = row_begin >> detail::kReferenceCellShift, cell_row_end = ((row_end - 1) >> detail::kReferenceCellShift) + 1;
    std::uint32_t load[detail::kMaxNotedCellsPerSide] = {};  // a noted render's buffer has at most that many cell rows
    const auto draw = [&](const detail::RasterTriangle& tri) {
        const std::uint64_t n = target.kernel(target, tri);
        stats.subtiles_updated += n;
        const int first_row = std::max(row_begin, tri.j0 / kH);
        ++load[(first_row >> detail::kReferenceCellShift) - first_cell_row];
        if (n != 0) {
            scratch.changed.add(tri, subtiles_x_, subtiles_y_);
            changed_begin = std::min(changed_begin, first_row);
            changed_end = std::max(changed_end, std::min(row_end, tri.j1 / kH + 1));
        }
    };
    for (std::size_t begin = 0; begin < in.triangle_count; begin += kCellRefreshTriangles) {
        const std::size_t end = std::min(in.triangle_count, begin + kCellRefreshTriangles);
        detail::setup_noted_range(in, cells, list, begin, end, scratch.undecided.data(), config_.near_w, config_.edge_margin, sample_width_,
                                  sample_height_, &target, stats, kernels_->raster.front_end, kernels_->raster.drop_hidden, draw);
        refresh_reference_cells(cells, changed_begin, changed_end);
        changed_begin = row_end, changed_end = row_begin;
    }
    std::copy(load, load + (cell_row_end - first_cell_row), cell_row_load_.begin() + first_cell_row);
    scratch.stats = stats;
}

// With a job system and cell notes: the rows split into parts, one task each, every part
// drawing the whole list into its own rows with its own cells (draw_noted_part). Nothing is
// binned and there is one parallel run: the noted triangles outside a part cost it a note
// read, and a triangle reaching two parts is set up by both. The bounds lie on cell rows,
// placed so that each part drew about as many triangles in the last noted render (equal rows
// the first time); they change no bit, only the balance. Part 0's statistics are the render's.
// S1 at 1080p, two threads: 4.30 -> 3.02 ms against render_binned's waves (see
// docs/occlusion-buffer.md, "Threads").
void detail::BufferState::render_parts(const TriangleInput& in, const ParallelFor& parallel, bool clear_first, detail::DrawList list) {
    reference_cells_current_ = false;  // each part's copy has the other parts' rows infinite
    const int cell_rows = detail::reference_cells_height(subtiles_y_);
    const std::size_t parts = std::min(parallel.threads ? parallel.threads : 2, std::size_t(cell_rows));  // cell_rows >= 1
    const std::size_t cells_size = std::size_t(detail::kCellTables) * std::size_t(reference_cells_width_) * std::size_t(cell_rows);
    if (reference_cells_.size() < parts * cells_size) reference_cells_.resize(parts * cells_size);
    if (noted_parts_.size() < parts) noted_parts_.resize(parts);
    for (std::size_t p = 0; p < parts; ++p) {
        NotedPart& part = noted_parts_[p];
        if (part.undecided.size() < kCellRefreshTriangles) part.undecided.resize(kCellRefreshTriangles);
        part.drawn = false;
    }
    // The bounds: part p ends at the first cell row where the load so far reaches (p + 1) / parts
    // of the total, leaving each part at least one row.
    std::uint64_t total = 0;
    for (const std::uint32_t load : cell_row_load_) total += load;
    int cell_row = 0;
    std::uint64_t load_so_far = 0;
    for (std::size_t p = 0; p < parts; ++p) {
        NotedPart& part = noted_parts_[p];
        part.row_begin = cell_row << detail::kReferenceCellShift;
        const int rows_left_for_others = int(parts - p - 1);
        if (p + 1 == parts) {
            cell_row = cell_rows;
        } else if (total == 0) {
            cell_row = int((p + 1) * std::size_t(cell_rows) / parts);
        } else {
            do load_so_far += cell_row_load_[std::size_t(cell_row++)];
            while (cell_row < cell_rows - rows_left_for_others && load_so_far * parts < (p + 1) * total);
        }
        part.row_end = std::min(subtiles_y_, cell_row << detail::kReferenceCellShift);
    }
    std::fill(cell_row_load_.begin(), cell_row_load_.end(), 0u);

    struct Job {
        detail::BufferState* self;
        const TriangleInput* in;
        detail::DrawList list;
        bool clear_first;
    } job{this, &in, list, clear_first};
    try {
        detail::run_tasks(parallel, parts, [](void* data, std::size_t p) {
            const Job& j = *static_cast<Job*>(data);
            detail::BufferState& b = *j.self;
            const NotedPart& part = b.noted_parts_[p];
            b.draw_noted_part(*j.in, j.list, j.clear_first, p, part.row_begin, part.row_end);
            b.build_pyramid_rows(part.row_begin, part.row_end, std::min(detail::kReferenceCellShift, int(b.levels_.size()) - 1));
        }, &job);
    } catch (...) {
        // The job system failed (the tasks themselves allocate nothing and do not throw): the
        // parts it ran are drawn. The rows of the others still hold what was there before; in
        // a render_frame that was the frame before, which must not hide anything of this one:
        // they are cleared. The pyramid is rebuilt to match; the statistics count no part.
        for (std::size_t p = 0; p < parts; ++p)
            if (clear_first && !noted_parts_[p].drawn) clear_rows(noted_parts_[p].row_begin, noted_parts_[p].row_end);
        build_pyramid_rows(0, subtiles_y_, int(levels_.size()) - 1);
        throw;
    }
    // Above the parts' levels (their bounds are multiples of 2^kReferenceCellShift rows).
    for (int level = detail::kReferenceCellShift + 1; level < int(levels_.size()); ++level)
        reduce_pyramid_rows(level, 0, levels_[std::size_t(level)].height);
    stats_ += noted_parts_[0].stats;
    for (std::size_t p = 1; p < parts; ++p) stats_.subtiles_updated += noted_parts_[p].stats.subtiles_updated;
}

}  // namespace homcull
