#pragma once
// The raster layer's kernels for one instruction set, resolved once per choice
// (common/isa_choice.hpp): the plain scalar references for the scalar choice, else the SIMD
// kernels of the chosen Highway target. Every kernel gives the same bits on every choice.
// The buffer holds a pointer to its table (buffer/buffer_kernels.hpp) and hands it down.
#include "common/isa_choice.hpp"
#include "raster/draw_order.hpp"
#include "raster/rasterize.hpp"
#include "raster/reference_cells.hpp"
#include "raster/sample_depth_tiles.hpp"
#include "raster/triangle_batch.hpp"

namespace homcull::detail {

// The draw order's first pass (draw_order.cpp) for an input without indices whose vertices are
// packed 3 or 4 floats: the bucket of each triangle of [begin, end) into bucket[t], counted into
// count[]. In float lanes, the same on every instruction set (no scalar reference: the scalar
// choice runs the best target's); row is the matrix's last row (m[3], m[7], m[11], m[15]).
// With `notes` (and its spec; the matrix must then be the identity), also the cell note
// of each triangle into notes[t] (reference_cells.hpp).
using BucketPackedSoupKernel = void (*)(const float* positions, int components, std::size_t begin, std::size_t end, const float* row,
                                        float near_w, std::uint16_t* bucket, std::uint32_t* count, const CellNoteSpec* spec,
                                        CellNote* notes);
// The same for an indexed input, its positions gathered `stride` floats apart (stride *
// vertex_count <= 2^31, vertex_count > 0); a triangle with an index out of range takes the
// last bucket.
using BucketIndexedKernel = void (*)(const float* positions, std::size_t stride, int components, const void* indices, bool indices_16bit,
                                     std::size_t vertex_count, std::size_t begin, std::size_t end, const float* row, float near_w,
                                     std::uint16_t* bucket, std::uint32_t* count);

struct RasterKernels {
    FrontEndKernels front_end;         // transform, classify, set up (triangle_batch.hpp)
    TriangleRowsKernel rows;           // the row loop (rasterize.hpp)
    HiddenTestKernel hidden_test;      // hidden_behind_reference_layer
    RowIntervalsKernel row_intervals;  // null for the scalar reference
    FillDepthUnitKernel fill_depth_unit;  // sample_depth_tiles.hpp
    RefreshCellsKernel refresh_cells;  // null for the scalar reference (reference_cells.hpp)
    DropHiddenKernel drop_hidden;
    BucketPackedSoupKernel bucket_packed_soup;
    BucketIndexedKernel bucket_indexed;
};

// The table for a choice: resolved on first use, then the same object for the whole process.
const RasterKernels& raster_kernels(const IsaChoice& choice);

// Each SIMD translation unit's part of the table (they hold the HWY_EXPORTs).
void resolve_rasterize_kernels(const IsaChoice& choice, RasterKernels& kernels);
void resolve_front_end_kernels(const IsaChoice& choice, RasterKernels& kernels);
MarginFreeKernel margin_free_kernel_for(const IsaChoice& choice);  // shared_edge_rule_simd.cpp; null for the scalar choice
void resolve_reference_cells_kernels(const IsaChoice& choice, RasterKernels& kernels);
void resolve_draw_order_kernels(const IsaChoice& choice, RasterKernels& kernels);

}  // namespace homcull::detail
