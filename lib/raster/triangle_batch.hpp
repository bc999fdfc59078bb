#pragma once
// The front of triangle setup, a batch of triangles at a time: index and vertex fetch, the
// model-to-clip transform, and the rejections that need no clipping (invalid input, outside
// the frustum, degenerate, backfacing). Most of an engine's occluder triangles end there
// (30,000 of the castle's 48,700 are outside view C0, 10,000 more face away), so SIMD kernels
// (triangle_batch_simd.cpp) decide them in double lanes, several triangles per instruction,
// as Intel's MOC does for its setup. The triangles left that need no clipping (nearly all) are
// then projected and set up in lanes as well (BatchSetup); those that cross the near plane or
// the guard band go to setup_clip_triangle one by one. Clip coordinates, statistics and the
// rasterized triangles are bit-identical to the one-triangle path's on every target.
//
// Indexed meshes share each vertex among about six triangles, so for them every vertex is
// transformed once per render into a VertexClip cache with its frustum outcode, and a
// triangle is rejected as invalid or outside from its three outcodes before anything is
// fetched (MOC's TransformVertices, and Blinn and Newell's outcodes).
#include "raster/reference_cells.hpp"
#include "raster/shared_edge_rule.hpp"
#include "raster/triangle_setup.hpp"

#include <homcull/parallel_for.hpp>
#include <homcull/triangle_input.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace homcull::detail {

// A batch of triangles in structure-of-arrays form: their input indices, the vertex positions
// as fetched, the clip-space x, y, z, w, and after classification which triangles need the
// one-triangle setup.
struct TriangleBatch {
    static constexpr int kSize = 16;  // a multiple of every target's double lanes (2, 4, 8)
    int count = 0;                    // lanes in use
    std::size_t triangle[kSize];      // lane t holds triangle triangle[t] of the input
    alignas(64) double px[3][kSize], py[3][kSize], pz[3][kSize], pw[3][kSize];  // per vertex k, per lane
    alignas(64) double cx[3][kSize], cy[3][kSize], cz[3][kSize], cw[3][kSize];
    std::uint32_t indices_valid = 0;  // bit t: lane t's three indices are below vertex_count
    std::uint32_t needs_setup = 0;    // bit t: lane t goes on to the one-triangle setup
    std::uint32_t simple = 0;         // bit t: ... and needs no clipping: the SIMD kernels set it up (BatchSetup)

    // Vertex k of lane t in clip space, as fetch_clip_triangle gives it.
    glm::dvec4 clip(int t, int k) const { return {cx[k][t], cy[k][t], cz[k][t], cw[k][t]}; }
};

// Frustum outcode bits of a clip-space vertex: a triangle is outside when its three vertices
// share a plane bit (outside_frustum), and invalid when one is not finite (finite_clip).
enum OutcodeBit : std::uint8_t {
    kNotFinite = 1,
    kBehindNear = 2,   // w < near_w
    kBeyondRight = 4,  // x > w
    kBeyondLeft = 8,   // x < -w
    kBeyondTop = 16,   // y > w
    kBeyondBottom = 32,
};
constexpr std::uint8_t kOutsidePlanes = kBehindNear | kBeyondRight | kBeyondLeft | kBeyondTop | kBeyondBottom;
std::uint8_t outcode(const glm::dvec4& clip, double near_w);

// Every vertex of an input in clip space, as planes of x, y, z, w, and its outcode. Each plane
// has kVertexClipPadding elements past the last vertex, for whole-vector stores.
// TransformVertices writes whole blocks of at most this many vertices (its kBlock and vectors of at
// most 8 doubles): a caller splitting the vertices into tasks keeps task sizes multiples of it.
constexpr std::size_t kVertexClipPadding = 8;
struct VertexClip {
    double *x, *y, *z, *w;
    std::uint8_t* outcode;
};
// Transforms vertices [begin, end) of the input (transform_to_clip) into the cache.
using TransformVerticesKernel = void (*)(const TriangleInput& in, double near_w, std::size_t begin, std::size_t end,
                                         const VertexClip& cache);
void transform_vertices_reference(const TriangleInput& in, double near_w, std::size_t begin, std::size_t end, const VertexClip& cache);

// Whether a render should transform the input's vertices once (indexed, and at most two
// vertices per triangle: then it transforms fewer points than three per triangle).
bool use_vertex_cache(const TriangleInput& in);

// Fetches triangles [first, first + count) (0 < count <= kSize) into the batch's lanes
// [0, count): positions as doubles, (x, y, z, 1) for 3 components. Lanes with an index out of
// range, and lanes past count, get a finite position and no indices_valid bit. With `order`
// (null: none), lane t holds triangle order[first + t] instead (DrawList).
void gather_triangle_batch(const TriangleInput& in, std::size_t first, int count, TriangleBatch& batch,
                           const std::uint32_t* order = nullptr);

// Fills the batch from the cache with the triangles from `first` on that are neither invalid
// nor outside by their outcodes, until it is full or `end` is reached; counts those skipped
// (triangles_in, invalid, outside). Returns the first triangle not looked at.
std::size_t gather_cached_batch(const TriangleInput& in, const VertexClip& cache, std::size_t first, std::size_t end, TriangleBatch& batch,
                                RasterStats& stats);

// Transforms a gathered batch's positions to clip space (transform_to_clip's operations).
using TransformBatchKernel = void (*)(const TriangleInput& in, TriangleBatch& batch);
void transform_batch_reference(const TriangleInput& in, TriangleBatch& batch);

// Decides each lane of a batch in clip space: invalid (an index out of range, or a non-finite
// clip x, y or w), or unclipped_fate. Counts the triangles rejected (invalid, outside,
// degenerate, backfacing) in `stats` and sets needs_setup for the others.
using ClassifyBatchKernel = void (*)(Backface backface, double near_w, TriangleBatch& batch, RasterStats& stats);
void classify_batch_reference(Backface backface, double near_w, TriangleBatch& batch, RasterStats& stats);

// The screen-space setup of a batch's unclipped triangles, lane by lane, as
// setup_clip_triangle (projection to the sample grid) and setup_raster_triangle (orientation,
// sample bounding box, edge functions, depth plane) compute it, before the parts that depend
// on the edge flags (assemble_raster_triangle). In two kernels: SetupPlanes (projection,
// orientation, box, depth plane, and the nearest depth over the box), then SetupEdges for the
// lanes not already found hidden behind what is drawn (setup_triangle_range).
struct BatchSetup {
    static constexpr int kSize = TriangleBatch::kSize;
    alignas(64) double area2[kSize];                 // twice the area; 0: nothing to rasterize
    alignas(64) double x[3][kSize], y[3][kSize];     // the projected vertices, oriented counter-clockwise
    alignas(64) double ox[3][kSize], oy[3][kSize], sa[3][kSize], sb[3][kSize], inverse_sa[3][kSize];
    alignas(64) float plane_a[kSize], plane_dzdx[kSize], plane_dzdy[kSize], plane_error[kSize], z_vertex_min[kSize];  // PreparedTriangle's
    alignas(64) float nearest[kSize];  // nearest_conservative_depth of the plane over the box [i0, i1] x [j0, j1]
    alignas(64) std::int32_t i0[kSize], i1[kSize], j0[kSize], j1[kSize];
    // prepare_float_row_edges' floats for edge k, as if no edge were shared (the thresholds of
    // silhouette edges), and in float_ready, bit t, whether it accepted all three edges.
    alignas(64) float row_origin[3][kSize], y_offset[3][kSize], slope[3][kSize], base[3][kSize];
    alignas(64) float lo_clamp[3][kSize], hi_clamp[3][kSize], column_shift[3][kSize];
    std::uint32_t float_ready = 0;
    std::uint32_t flipped = 0;    // bit t: vertices 1 and 2 were swapped to orient the triangle
    std::uint32_t has_plane = 0;  // bit t: PreparedTriangle::has_plane
};
// Lanes [0, batch.count): everything of BatchSetup but the edges and float_ready.
using SetupPlanesKernel = void (*)(const TriangleBatch& batch, int sample_width, int sample_height, BatchSetup& setup);
// The edges and float_ready of the lanes in `lanes` (bit t: lane t) of [0, count), from
// SetupPlanes' output. silhouette_only, bit t: lane t has no shared edge (only such lanes can
// be float_ready).
using SetupEdgesKernel = void (*)(int count, double edge_margin, std::uint32_t silhouette_only, std::uint32_t lanes, BatchSetup& setup);

// The RasterTriangle of simple lane t, as setup_raster_triangle makes it from the projected
// triangle with edge flags `shared_bits`; false when it has no area or covers no sample's box.
bool assemble_raster_triangle(const BatchSetup& setup, int t, std::uint8_t shared_bits, double edge_margin, RasterTriangle& out);

// The reference or the SIMD kernels of one instruction set (RasterKernels). Every kernel gives the same clip
// coordinates, outcodes, counts and bits.
struct FrontEndKernels {
    TransformVerticesKernel transform_vertices;
    TransformBatchKernel transform_batch;
    ClassifyBatchKernel classify;
    SetupPlanesKernel setup_planes;  // null for the scalar reference, whose classify marks no lane simple
    SetupEdgesKernel setup_edges;    // null for the scalar reference
    // gather_triangle_batch for a full batch of an input that gather_direct_ready accepts
    // (order null), or of the listed triangles of one that gather_listed_ready accepts; null for
    // the scalar reference.
    void (*gather_direct)(const TriangleInput& in, std::size_t first, const std::uint32_t* order, TriangleBatch& batch);
    // The lanes [0, count) of a transformed batch with valid indices, finite clip x, y and w at
    // every vertex (finite_clip) and all three vertices beyond one side plane by more than a
    // margin (outside_side_plane: x - w > scale_x p, ..., with p the largest |model
    // coordinate| of the lane's vertices; scales of 0: beyond the plane), as bits (lane t: bit t).
    std::uint32_t (*beyond_side_plane)(const TriangleBatch& batch, int count, double scale_x, double scale_y);
    // transform_batch with transform_to_clip_plain: the occludee tests' (they bound its error).
    TransformBatchKernel transform_batch_plain;
    // margin_free_edges for a batch's lanes at once (shared_edge_rule.hpp); null for the scalar
    // reference, which decides lane by lane.
    MarginFreeKernel margin_free;
};
void transform_batch_plain_reference(const TriangleInput& in, TriangleBatch& batch);
std::uint32_t beyond_side_plane_reference(const TriangleBatch& batch, int count, double scale_x, double scale_y);

// Whether triangles [first, first + TriangleBatch::kSize) of the input are consecutive
// vertices of 4 floats each (aligned as floats), all within vertex_count:
// FrontEndKernels::gather_direct's input.
inline bool gather_direct_ready(const TriangleInput& in, std::size_t first, std::size_t end) {
    return !in.indices && in.position_components == 4 && in.position_stride >= 16 && in.position_stride % alignof(float) == 0 &&
           reinterpret_cast<std::uintptr_t>(in.positions) % alignof(float) == 0 && end - first >= std::size_t(TriangleBatch::kSize) &&
           3 * (first + std::size_t(TriangleBatch::kSize)) <= in.vertex_count;
}

// The same for the listed triangles order[first, first + kSize) of an input without indices
// (each number below triangle_count, which check_triangle_input keeps within vertex_count).
inline bool gather_listed_ready(const TriangleInput& in, std::size_t first, std::size_t end) {
    return !in.indices && in.position_components == 4 && in.position_stride >= 16 && in.position_stride % alignof(float) == 0 &&
           reinterpret_cast<std::uintptr_t>(in.positions) % alignof(float) == 0 && end - first >= std::size_t(TriangleBatch::kSize);
}

// Triangles to draw in another order than the input's without copying them (the draw order
// of a render on one thread, or of a clip-space soup, draw_order.hpp): position k of the
// sequence is input triangle order[k], or notes[k].triangle. The setup reads them through a
// list of numbers, prefetching the next batch's positions.
struct DrawList {
    const std::uint32_t* order = nullptr;  // null: the input's own order
    // A noted soup (sort_nearest_first): the list is its notes, each with its triangle's number
    // (order is then null).
    const TriangleNote* notes = nullptr;
};

// Whether lane t of SetupPlanes' output is hidden in the target's rows: its box reaches none
// of them, or every subtile of its box there lies behind the reference layer at the nearest
// depth of its plane over the whole box (hidden_behind_reference_layer). The target's row loop
// would then skip every chunk of it (each chunk's nearest depth is at most the box's, over
// fewer subtiles): not drawing it changes no bit. A lane without area or with an empty box is
// never called hidden: assembly rejects it, and its plane may be NaN.
inline bool hidden_in_target(const BatchSetup& setup, int t, const RasterTarget& target, HiddenTestKernel hidden_test) {
    constexpr int kW = kSubtileWidth;
    if (setup.area2[t] == 0.0 || setup.i0[t] > setup.i1[t] || setup.j0[t] > setup.j1[t]) return false;  // assembly rejects it
    int ty0, ty1;
    return !subtile_rows_within(setup.j0[t], setup.j1[t], target.row_begin, target.row_end, ty0, ty1) || hidden_test(target.planes, setup.i0[t] / kW, setup.i1[t] / kW, ty0, ty1, setup.nearest[t]);
}

// Vertex v of the input in clip space, as the setup computes it (from the cache when there is
// one); false when v is not below vertex_count.
inline bool vertex_clip(const TriangleInput& in, const VertexClip* cache, std::uint32_t v, glm::dvec4& out) {
    if (v >= in.vertex_count) return false;
    if (cache) {
        out = {cache->x[v], cache->y[v], cache->z[v], cache->w[v]};
    } else {
        float p[4];
        read_position(in, v, p);
        out = input_to_clip(in, p[0], p[1], p[2], p[3]);
    }
    return true;
}

// Of lane t's shared-edge bits `flags` (input order), those that may go without their margin in
// this view (margin_free_edges, from the apexes of TriangleInput::edge_apexes, read into apex:
// the clipped setup needs them again). The same scalar code on every instruction set, from the
// same clip coordinates: the same bits.
inline std::uint8_t edges_across(const TriangleInput& in, const VertexClip* cache, const TriangleBatch& batch, int t, std::uint8_t flags,
                                 double near_w, double edge_margin, int sample_width, int sample_height, glm::dvec4 (&apex)[3]) {
    const glm::dvec4 own[3] = {batch.clip(t, 0), batch.clip(t, 1), batch.clip(t, 2)};
    const std::uint32_t* apexes = in.edge_apexes + 3 * batch.triangle[t];
    std::uint8_t apex_valid = 0;
    for (int k = 0; k < 3; ++k)
        if (((flags >> k) & 1u) && vertex_clip(in, cache, apexes[k], apex[k])) apex_valid |= std::uint8_t(1u << k);
    return margin_free_edges(own, apex, apex_valid, flags, near_w, edge_margin, sample_width, sample_height);
}

// edges_across for the drawn lanes of a batch, gathered for FrontEndKernels::margin_free: each
// lane's own vertices and, for each flagged edge, its apex (also kept in apex, as edges_across
// keeps it); lanes not drawn, without flags or apexes, get flags 0.
inline void lanes_across(const TriangleInput& in, const VertexClip* cache, const TriangleBatch& batch, std::uint32_t drawn,
                         glm::dvec4 (&apex)[TriangleBatch::kSize][3], MarginFreeLanes& lanes) {
    static_assert(kMarginFreeLanes == TriangleBatch::kSize, "a batch's lanes at once");
    lanes.count = batch.count;
    for (int t = 0; t < TriangleBatch::kSize; ++t) lanes.flags[t] = 0;
    for (std::uint32_t bits = drawn; bits != 0; bits &= bits - 1) {
        const int t = __builtin_ctz(bits);
        const std::uint8_t flags = in.shared_edges[batch.triangle[t]];
        if (flags == 0) continue;
        const std::uint32_t* apexes = in.edge_apexes + 3 * batch.triangle[t];
        std::uint8_t valid = 0;
        for (int k = 0; k < 3; ++k) {
            lanes.ox[k][t] = batch.cx[k][t], lanes.oy[k][t] = batch.cy[k][t], lanes.ow[k][t] = batch.cw[k][t];
            if (((flags >> k) & 1u) && vertex_clip(in, cache, apexes[k], apex[t][k])) {
                valid |= std::uint8_t(1u << k);
                lanes.ax[k][t] = apex[t][k].x, lanes.ay[k][t] = apex[t][k].y, lanes.aw[k][t] = apex[t][k].w;
            } else {
                lanes.ax[k][t] = 0.0, lanes.ay[k][t] = 0.0, lanes.aw[k][t] = 0.0;
            }
        }
        lanes.flags[t] = flags & valid;
    }
}

// Sets up triangles [begin, end) of the input in batches and hands every triangle of their
// clipped fans that covers a sample's bounding box to emit(const RasterTriangle&), in input
// order; the statistics are those of fetch_clip_triangle and setup_clip_triangle, triangle
// by triangle. `cache` (null: none) holds every vertex of the input, transformed.
// `drawn_into` (null: none) is the target the emitted triangles are drawn into right away: an
// unclipped triangle hidden there (hidden_in_target, when the target skips hidden chunks) is
// then neither given its edges nor emitted. On S1, nine in ten triangles end there.
// `list`: [begin, end) are positions in list.order rather than triangles (no cache then).
template <typename Emit>
void setup_triangle_range(const TriangleInput& in, const VertexClip* cache, std::size_t begin, std::size_t end, double near_w,
                          double edge_margin, int sample_width, int sample_height, const RasterTarget* drawn_into, RasterStats& stats,
                          const FrontEndKernels& kernel_table, Emit&& emit, DrawList list = {}) {
    const FrontEndKernels kernels = kernel_table;  // a local copy: the loop's stores cannot alias it
    const HiddenTestKernel hidden_test = drawn_into && drawn_into->skip_hidden ? drawn_into->hidden_test : nullptr;
    TriangleBatch batch{};  // zeroed: the last vector of a batch may read lanes past count
    BatchSetup simple;
    MarginFreeLanes margin_lanes{};  // zeroed, as the batch
    for (std::size_t first = begin; first < end;) {
        if (cache) {
            first = gather_cached_batch(in, *cache, first, end, batch, stats);
        } else {
            batch.count = int(std::min<std::size_t>(TriangleBatch::kSize, end - first));
            if (list.order) {
                // The listed triangles are scattered over the input (one in 32 on S1): the next
                // batch's are fetched while this one is set up (without the prefetch, reading
                // through the list was slower than reading a sorted copy; with it, faster).
                const unsigned char* positions = static_cast<const unsigned char*>(in.positions);
                const std::size_t triangle_bytes = 3 * in.position_stride;
                const std::size_t next_end = std::min(end, first + 2 * std::size_t(TriangleBatch::kSize));
                for (std::size_t k = first + std::size_t(TriangleBatch::kSize); k < next_end; ++k) {
                    const unsigned char* p = positions + std::size_t(list.order[k]) * triangle_bytes;
                    __builtin_prefetch(p);
                    __builtin_prefetch(p + triangle_bytes - 1);
                }
                if (kernels.gather_direct && gather_listed_ready(in, first, end)) kernels.gather_direct(in, first, list.order, batch);
                else gather_triangle_batch(in, first, batch.count, batch, list.order);
            } else if (kernels.gather_direct && gather_direct_ready(in, first, end)) {
                kernels.gather_direct(in, first, nullptr, batch);
            } else {
                gather_triangle_batch(in, first, batch.count, batch);
            }
            kernels.transform_batch(in, batch);
            stats.triangles_in += std::uint64_t(batch.count);
            first += std::size_t(batch.count);
        }
        kernels.classify(in.backface, near_w, batch, stats);
        std::uint32_t emitted = batch.simple;  // the simple lanes that go on to assembly
        if (batch.simple) {
            kernels.setup_planes(batch, sample_width, sample_height, simple);
            if (hidden_test)
                for (std::uint32_t bits = batch.simple; bits != 0; bits &= bits - 1) {
                    const int t = __builtin_ctz(bits);
                    if (hidden_in_target(simple, t, *drawn_into, hidden_test)) emitted &= ~(1u << t);
                }
        }
        // The shared-edge bits of each lane that is drawn, read once and kept only where they may
        // go without their margin in this view (edges_across; not for lanes already found hidden,
        // about two in three of the castle's). The float row rule needs three silhouette edges:
        // the setup skips it for groups of lanes that all have a shared edge (most of a closed
        // mesh's).
        const std::uint32_t drawn = emitted | (batch.needs_setup & ~batch.simple);
        std::uint8_t lane_shared[TriangleBatch::kSize] = {};
        glm::dvec4 lane_apexes[TriangleBatch::kSize][3];  // read where a lane keeps a flag
        std::uint32_t silhouette_only = drawn;
        if (in.shared_edges && kernels.margin_free) {
            lanes_across(in, cache, batch, drawn, lane_apexes, margin_lanes);
            kernels.margin_free(margin_lanes, near_w, edge_margin, sample_width, sample_height, lane_shared);
            for (std::uint32_t bits = drawn; bits != 0; bits &= bits - 1) {
                const int t = __builtin_ctz(bits);
                if (lane_shared[t] != 0) silhouette_only &= ~(1u << t);
            }
        } else if (in.shared_edges) {
            for (std::uint32_t bits = drawn; bits != 0; bits &= bits - 1) {
                const int t = __builtin_ctz(bits);
                const std::uint8_t flags = in.shared_edges[batch.triangle[t]];
                if (flags == 0) continue;
                lane_shared[t] = edges_across(in, cache, batch, t, flags, near_w, edge_margin, sample_width, sample_height, lane_apexes[t]);
                if (lane_shared[t] != 0) silhouette_only &= ~(1u << t);
            }
        }
        if (emitted) kernels.setup_edges(batch.count, edge_margin, silhouette_only & emitted, emitted, simple);
        // Every simple lane counts as rasterized (what setup_clip_triangle counts for it); the
        // loop visits those emitted and the lanes left to the one-triangle setup, in order.
        stats.rasterized += std::uint64_t(__builtin_popcount(batch.simple));
        for (std::uint32_t bits = drawn; bits != 0; bits &= bits - 1) {
            const int t = __builtin_ctz(bits);
            const std::uint8_t shared = lane_shared[t];
            if ((batch.simple >> t) & 1u) {
                RasterTriangle tri;
                if (assemble_raster_triangle(simple, t, shared, edge_margin, tri)) emit(tri);
                continue;
            }
            const glm::dvec4 clip[3] = {batch.clip(t, 0), batch.clip(t, 1), batch.clip(t, 2)};
            const SetupResult setup = setup_clip_triangle(clip, shared, in.backface, near_w, sample_width, sample_height, stats,
                                                          /*occludee=*/false, SetupEdgeRule{lane_apexes[t], edge_margin});
            for (int k = 0; k < setup.count; ++k) {
                RasterTriangle tri;
                if (setup_raster_triangle(setup.triangles[k], edge_margin, sample_width, sample_height, tri)) emit(tri);
            }
        }
    }
}

// setup_triangle_range over positions [begin, end) of a list of notes (sort_nearest_first),
// the reference cells of the target drawn into at hand: the noted triangles hidden behind the
// cells are counted as the setup counts a hidden triangle (triangles_in and rasterized) and
// dropped unread (drop_hidden_noted, in vectors); the others are set up in order.
// `undecided`: room for end - begin triangle numbers. (A noted input has no cache.)
template <typename Emit>
void setup_noted_range(const TriangleInput& in, const ReferenceCells& cells, DrawList list, std::size_t begin, std::size_t end,
                       std::uint32_t* undecided, double near_w, double edge_margin, int sample_width, int sample_height,
                       const RasterTarget* drawn_into, RasterStats& stats, const FrontEndKernels& kernels, DropHiddenKernel drop_hidden,
                       Emit&& emit) {
    const std::uint64_t hidden = std::uint64_t(end - begin) - drop_hidden(cells, list.notes + begin, end - begin, undecided);
    stats.triangles_in += hidden;
    stats.rasterized += hidden;
    setup_triangle_range(in, nullptr, 0, (end - begin) - std::size_t(hidden), near_w, edge_margin, sample_width, sample_height, drawn_into,
                         stats, kernels, std::forward<Emit>(emit), DrawList{undecided, nullptr});
}

}  // namespace homcull::detail
