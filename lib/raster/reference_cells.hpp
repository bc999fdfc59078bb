#pragma once
// A coarse lower bound of the reference layer while a render draws: the smallest d0 of each
// cell of 8 x 8 subtiles (64 x 32 samples; 30 x 34 cells, 4 KB, at 1080p). With the notes the
// draw order takes of a clip-space soup (CellNote below), the render drops most hidden
// triangles from their note and a few cells in L1, without reading the triangle, setting it up
// or reading some ten rows of d0 (BufferState::draw_noted_part, on one thread for the whole
// buffer, with a job system for each part of its rows): on S1 at 1080p about 80,000 of 100,000
// triangles.
//
// Why a cell read long after it was computed is still safe: a subtile's d0 never decreases
// while a render draws (the merge takes the least of bounds none of which is below the old d0:
// layer_merge.hpp), so a cell's minimum, taken at any earlier point of the render, bounds
// every d0 of the cell from below. The render zeroes the cells when it clears the buffer
// first, else computes them from d0, and refreshes those of the rows it drew into every 4,096
// triangles (each part of the rows its own copy of the cells). The cells
// are the render's scratch: nothing reads them outside a render, and they change no bit (see
// CellNote).
//
// Greene, Kass and Miller's hierarchical Z-buffer (SIGGRAPH 1993) keeps such a pyramid exact
// after every update; refreshing a stale but safe level in batches costs less here, where nine
// in ten triangles are tests and only one in ten draws. (Asking the cells before the setup's
// own box test as well, for the triangles that reach it, gained nothing measurable: see
// docs/occlusion-buffer.md, "Reference cells".)
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace homcull::detail {

constexpr int kReferenceCellShift = 3;  // a cell spans 2^3 x 2^3 subtiles

struct ReferenceCells {
    float* min_d0 = nullptr;  // null: no cells
    int width = 0;            // cells per row; rows follow each other
    int height = 0;           // rows; min_d0 is the first of kCellTables tables of width x height (cell_table_offset)
};

// Block minima for the drop (DropHiddenKernel): table (kx, ky) holds at each cell the smallest
// of the 2^kx x 2^ky cells from it rightwards and downwards (those within the grid), so that
// four reads answer any box of up to 8 x 8 cells, two blocks a side, as a sparse
// table answers range minima (Bender and Farach-Colton, "The LCA Problem Revisited", LATIN
// 2000). Table (0, 0) is the cells themselves. S1's boxes span up to 6 x 9 cells; the drop
// gathered every cell of the vector's largest box before, about nine reads a note.
constexpr int kCellBlockLevels = 3;  // blocks of 1, 2 and 4 cells a side
constexpr int kCellTables = kCellBlockLevels * kCellBlockLevels;
inline std::size_t cell_table_offset(const ReferenceCells& cells, int kx, int ky) {
    return std::size_t(ky * kCellBlockLevels + kx) * std::size_t(cells.width) * std::size_t(cells.height);
}
// Recomputes the tables above (0, 0) where cell rows [cell_row_begin, cell_row_end) changed
// (and the three rows above, whose blocks reach into them).
void update_cell_blocks(const ReferenceCells& cells, int cell_row_begin, int cell_row_end);

// The cells needed for subtiles_x x subtiles_y subtiles.
inline int reference_cells_width(int subtiles_x) { return (subtiles_x + (1 << kReferenceCellShift) - 1) >> kReferenceCellShift; }
inline int reference_cells_height(int subtiles_y) { return (subtiles_y + (1 << kReferenceCellShift) - 1) >> kReferenceCellShift; }

// What the draw order's first pass notes of a triangle for the cells (draw_order.hpp), so that
// the render can drop most hidden triangles of a clip-space soup without reading them again:
// the cells that hold its box, and a depth no sample of it is drawn nearer than. A NaN depth:
// no note (the triangle takes the setup's path).
//
// Why the depth is the nearest vertex's 1/w: every depth the row loop writes for a triangle is
// conservative_depth at a sample of a rectangle of covered samples. The float plane minus its
// error lies below the exact plane through the vertices wherever it is evaluated (rasterize.cpp),
// by more than 2^-21 of the plane's magnitude; the rectangle's corner where the plane is
// smallest lies no higher than a covered sample; a covered sample lies within the triangle up
// to the edge rule's rounding, far less than that margin; and over the triangle the plane is at
// most its largest vertex value. The clamp to the farthest vertex and the factor 1 - 2^-20 only
// lower it. So if every subtile's d0 is at least that depth (and positive), drawing the
// triangle changes no d0, d1 or mask, nor a covered mask (full wherever d0 > 0) or a sample
// depth (at least d0 wherever d0 > 0).
struct CellNote {
    std::uint8_t cx0, cx1, cy0, cy1;  // cells [cx0, cx1] x [cy0, cy1]
    float nearest;                    // at least the largest 1/w of its vertices and 2^-64; NaN: no note
};
static_assert(sizeof(CellNote) == 8, "a note is 8 bytes");

// A buffer with more cells than this a side takes no notes: a note holds cell numbers in bytes.
constexpr int kMaxNotedCellsPerSide = 256;

// What the first pass needs to note a triangle: the buffer's samples and cells (at most
// kMaxNotedCellsPerSide a side), and the setup's near plane and backface mode, to note only the
// triangles whose setup would surely count them as rasterized (not invalid, outside, clipped,
// degenerate or backfacing), so that dropping them keeps the statistics.
struct CellNoteSpec {
    int sample_width, sample_height;
    int cells_width, cells_height;
    float near_w;
    Backface backface;
};

// Whether a noted triangle is hidden behind the cells: every cell holding its box bounds d0
// at or above its depth (positive, or NaN for no note). Cell by cell: the reference of the drop
// kernel (which reads block minima), and its answer for boxes wider than 8 cells.
inline bool hidden_by_note(const ReferenceCells& cells, const CellNote& r) {
    const float* row0 = cells.min_d0 + std::size_t(r.cy0) * std::size_t(cells.width);
    for (int cy = r.cy0; cy <= r.cy1; ++cy, row0 += cells.width)
        for (int cx = r.cx0; cx <= r.cx1; ++cx)
            if (!(row0[cx] >= r.nearest)) return false;
    return true;
}

// A triangle's note in the draw order's list (sort_nearest_first): what the render reads of a
// noted soup before it decides to read the triangle itself.
struct TriangleNote {
    CellNote note;
    std::uint32_t triangle;  // its number in the input
};
static_assert(sizeof(TriangleNote) == 12, "a listed note is 12 bytes");

// Writes the triangles of notes [0, count) not hidden behind the cells (hidden_by_note) to
// undecided[], in order, and returns how many it kept. The reference of the vector kernel below.
inline std::size_t drop_hidden_noted(const ReferenceCells& cells, const TriangleNote* notes, std::size_t count, std::uint32_t* undecided) {
    std::size_t kept = 0;
    for (std::size_t k = 0; k < count; ++k) {
        undecided[kept] = notes[k].triangle;
        kept += !hidden_by_note(cells, notes[k].note);
    }
    return kept;
}

// Sets the cells of cell rows [cell_row_begin, cell_row_end) to the smallest d0 of their
// subtiles (those of the subtiles_x x subtiles_y grid: a cell at the right or bottom edge
// takes only its subtiles within it). Min is exact: every target gives the same cells.
using RefreshCellsKernel = void (*)(const SubtilePlanes& planes, int subtiles_x, int subtiles_y, int cell_row_begin, int cell_row_end,
                                    const ReferenceCells& cells);

// drop_hidden_noted in vectors: the same triangles kept, the same count.
using DropHiddenKernel = std::size_t (*)(const ReferenceCells& cells, const TriangleNote* notes, std::size_t count, std::uint32_t* undecided);

}  // namespace homcull::detail
