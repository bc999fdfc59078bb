#pragma once
// The order one render call draws its triangles in (TriangleInput::order). The buffer keeps
// what it is given first best: a triangle behind a subtile's reference layer is skipped, and
// two layers hold only two depths, so a subtile that has taken a farther triangle first keeps
// either its samples at the farther depth or fewer samples at the nearer one
// (layer_merge.hpp). Drawing the nearest triangles first, as Greene, Kass and Miller
// draw front to back for their hierarchical Z-buffer (SIGGRAPH 1993), leaves more triangles
// hidden before their rows are computed and more samples at a near depth.
//
// The sort is a stable counting sort of the triangles' nearest clip w, bucketed from the bits
// of that w as a float (a logarithmic scale, about 1 % of w per bucket), in tasks of the
// caller's job system. It depends only on the input, so the order, and the bits rendered in
// it, are the same on every instruction set and with any job system.
#include "raster/reference_cells.hpp"
#include "raster/triangle_batch.hpp"

#include <homcull/detail/memory.hpp>
#include <homcull/parallel_for.hpp>
#include <homcull/triangle_input.hpp>

#include <cstdint>
#include <vector>

namespace homcull::detail {

struct RasterKernels;

// Fine buckets of the nearest clip w (64 per doubling of w, draw_order.cpp), the depth classes
// drawn one after the other (about equal counts of triangles, each a run of buckets), and
// triangles per task.
constexpr std::uint32_t kDrawOrderBuckets = 1024;
constexpr int kDrawOrderBucketShift = 17;  // a bucket per 2^17 float bits of w: 64 per doubling
constexpr std::uint32_t kDrawOrderClasses = 32;
constexpr std::size_t kDrawOrderTask = 8192;

// Scratch of sort_nearest_first, kept by the buffer and grown to the largest input, so that a
// render allocates nothing after the first: 2 bytes per triangle, 8 KB and a RasterStats per
// task, 4 bytes per vertex of a vertex cache, and the sorted copy (the indices, 6 or 12 bytes
// per triangle; without indices the positions, 36 or 48; and a byte of shared-edge flags with 12 of apexes) or,
// on one thread for a soup of 4 floats per vertex, the list of numbers (4 bytes per triangle),
// or for a clip-space soup the cell notes (8 bytes per triangle) and the list of notes (12,
// with or without a job system).
struct DrawOrderScratch {
    Vector<std::uint16_t> bucket;  // per triangle
    Vector<std::uint32_t> count;   // per task and bucket
    Vector<std::uint32_t> excluded;  // per task and bucket: of count, the triangles left out
    Vector<RasterStats> skipped;     // per task: the counts of the triangles left out
    Vector<std::uint32_t> vertex_code;  // per vertex of the cache: its bucket and outcode (when leaving triangles out)
    Vector<std::uint32_t> start;   // per task and class: a count, then the next position
    std::uint8_t class_of[kDrawOrderBuckets];
    Vector<std::uint32_t> data;    // the sorted indices or positions (32-bit words), or the list of numbers
    Vector<std::uint8_t> shared_edges;
    Vector<std::uint32_t> edge_apexes;  // 3 per triangle, with the flags
    Vector<std::uint32_t> placed_at;    // a soup's: each input triangle's place in the copy (its apexes are renumbered)
    Vector<CellNote> noted;  // with the list of a clip-space soup: each triangle's cell note
    Vector<TriangleNote> sorted_notes;  // the list of a noted soup: the notes in order, with the triangles' numbers
};
static_assert(kDrawOrderClasses <= 256, "classes are bytes");

// The draw order's three jobs, one function each, on one stable counting sort (draw_order.cpp).
// Each returns false, with nothing computed, for DrawOrder::as_given or no triangle; else true,
// with its result pointing into `scratch`. Each runs in tasks of `parallel` when it has a job
// system, and throws homcull::Error for 2^32 triangles or more (check_draw_order: render checks
// before it changes anything).
//
// 1. sort_nearest_first: sorts the input's triangles into kDrawOrderClasses classes by the
// smallest clip w of their three vertices, each class in input order, into `sorted`: the same
// positions with sorted indices, or without indices sorted copies of each triangle's positions
// (3 or 4 components, packed); shared-edge flags and their apexes follow their triangles (a
// soup's apexes renumbered as its copy numbers its vertices), and `sorted` draws as given.
// Triangles with an index out of range or a coordinate that is not a number come last; those
// reaching in front of near_w (> 0) first.
//
// The clip w is computed in float lanes (RasterKernels' bucket passes) when the positions are
// float-aligned (address and stride) and, without indices, packed; else in double as
// transform_to_clip computes it, or read from `cache` (the vertices transformed: use_vertex_cache)
// when there is one. Which of these an input takes
// depends on the input alone (its layout and address, and use_vertex_cache), never on the
// instruction set or the job system, so neither does the order; but the same triangles at
// another address or stride may be ordered apart at a bucket's edge.
//
// A copy rather than a list of numbers: the setup then reads its input front to back (reading
// S1's triangles through a sorted list of numbers cost a fifth of a render on two threads). But given `list` (a render on one thread), an input without a cache or indices and of 4 floats
// per vertex (gather_listed_ready) is sorted as a list of numbers instead, list->order, and
// `sorted` is the input itself: with the setup prefetching the next batch, less memory traffic
// than copying 48 bytes a triangle. Otherwise list->order is null.
bool sort_nearest_first(const RasterKernels& kernels, const TriangleInput& in, const VertexClip* cache, double near_w,
                        const ParallelFor& parallel, DrawOrderScratch& scratch, TriangleInput& sorted, DrawList* list = nullptr);

// 2. The same sort from a vertex cache (with the vertices' outcodes), leaving out the triangles the setup would skip by their indices and
// outcodes (gather_cached_batch: an index out of range, a vertex not finite, all three vertices
// beyond one frustum plane): `sorted` (a copy) has fewer triangles, and they are counted into
// `skipped` as the setup counts them (triangles_in, invalid, outside); the others keep the
// order they would have with them. The sort reads each vertex's w anyway, and its three
// outcodes decide without a branch per triangle where the setup's loop mispredicted.
bool sort_nearest_first_leaving_out(const RasterKernels& kernels, const TriangleInput& in, const VertexClip& cache, double near_w,
                                    const ParallelFor& parallel, DrawOrderScratch& scratch, TriangleInput& sorted, RasterStats& skipped);

// 3. A clip-space soup (TriangleInput::clip_space) sorted as a list of cell notes: the first
// pass also notes each triangle for the reference cells (bucket_packed_soup with `spec`), the
// second places each note, with its triangle's number, into the list: list.notes, 12 bytes a
// triangle (list.order null), so that the render reads the notes in order and drops most hidden
// triangles without reading them (BufferState::draw_noted_part), with or without a job system.
// `soup` must be clip_space (4 packed floats a vertex, no indices, no shared-edge flags, the
// identity as its matrix).
bool sort_noting_cells(const RasterKernels& kernels, const TriangleInput& soup, double near_w, const ParallelFor& parallel,
                       DrawOrderScratch& scratch, const CellNoteSpec& spec, DrawList& list);

// Throws homcull::Error when the sorts would refuse the input (nearest first, 2^32
// triangles or more), so that render can check before it changes anything.
void check_draw_order(const TriangleInput& in);

}  // namespace homcull::detail
