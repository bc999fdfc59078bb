#pragma once
// The rasterizer: one projected triangle into the subtiles of the buffer. Triangle
// preparation and the per-row coverage intervals are shared; the per-subtile work of a subtile
// row (masks, depth bound, layer update) has a plain scalar reference and SIMD kernels
// (rasterize_simd.cpp) that must give the same bits.
#include <homcull/parallel_for.hpp>
#include <homcull/triangle_input.hpp>

#include <glm/glm.hpp>

#include "common/float_round.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace homcull::detail {

// A subtile: 8 x 4 samples, one 32-bit coverage mask (OcclusionBuffer::kSubtileWidth and
// kSubtileHeight, the buffer's layout).
constexpr int kSubtileWidth = 8, kSubtileHeight = 4;

// A triangle in sample space (x right, y down, in samples) with depth d = 1/w per vertex.
struct ScreenTriangle {
    glm::dvec2 p[3];
    double d[3];
    std::uint8_t shared = 0;  // bit k: the edge p[k] -> p[k + 1] is shared with a drawn triangle
};

struct PreparedTriangle;
struct TriangleEdges;
struct RasterTarget;
struct SampleDepthTiles;

struct RasterTriangle;

// Rasterizes the rows of a set-up triangle: for each subtile row in the target's band and the
// triangle's sample rows [j0, j1], the coverage interval of each sample row (within columns
// [i0, i1]), then the subtile-row update. Returns the number of subtiles updated (those where
// the triangle covers a sample and is in front of the reference layer).
using TriangleRowsKernel = std::uint64_t (*)(const RasterTarget& target, const RasterTriangle& triangle);
struct SubtilePlanes;
// hidden_behind_reference_layer as an instruction set's kernel: the SIMD row loop's test (a
// vector of subtiles per step, the same comparisons, so the same answer), or the scalar one.
using HiddenTestKernel = bool (*)(const SubtilePlanes& planes, int tx0, int tx1, int ty0, int ty1, float nearest);

// The widest SIMD vector the kernels use, in 32-bit lanes: subtile rows are padded so that a
// vector of this many subtiles loads and stores within the row (see BufferState::stride_).
constexpr int kMaxSimdLanes = 16;

// The buffer's subtile planes (OcclusionBuffer's layout): element (tx, ty) at ty * stride + tx.
struct SubtilePlanes {
    float* d0;
    float* d1;
    std::uint32_t* mask;
    std::uint32_t* covered;
    std::size_t stride;
    float* sample_depth;        // per sample, rows sample_stride apart (sample_width padded by kMaxSimdLanes); null when not kept
    std::size_t sample_stride;
};

struct RasterTarget {
    SubtilePlanes planes;
    int sample_width, sample_height;
    int row_begin, row_end;  // the subtile rows [row_begin, row_end) this call may write
    TriangleRowsKernel kernel;
    bool skip_hidden;  // hidden_skip_enabled() when the target was made
    HiddenTestKernel hidden_test;  // the same instruction set's: the setup's test before drawing (triangle_batch.hpp)
    // The per-sample depth computed where queries read it (sample_depth_tiles.hpp): the row
    // loops record each drawn triangle there instead of writing planes.sample_depth (then null).
    const SampleDepthTiles* sample_tiles = nullptr;
};

// The subtile rows [ty0, ty1] that hold sample rows [j0, j1] and lie within subtile rows
// [row_begin, row_end) (a target's, or a band's); false when there are none. The one clamp of
// the row loops, the setup's hidden test and the clustered render's band test.
inline bool subtile_rows_within(int j0, int j1, int row_begin, int row_end, int& ty0, int& ty1) {
    constexpr int kH = kSubtileHeight;
    ty0 = std::max(j0 / kH, row_begin);
    ty1 = std::min(j1 / kH, row_end - 1);
    return ty0 <= ty1;
}

// The three edge functions of a triangle oriented positive inside: for edge k,
// E(P) = sa (P.x - ox) + sb (P.y - oy), (ox, oy) its lower endpoint (by y, then x); covered
// samples have E > threshold, or E >= 0 on a shared edge (threshold 0).
struct TriangleEdges {
    double ox[3], oy[3], sa[3], sb[3], inverse_sa[3], threshold[3];
    bool shared[3];
};

// What the subtile-row kernels need of a triangle: its depth plane in float,
//     d(X, Y) ~ (a + dzdy * Y) + dzdx * X,
// evaluated at sample centres with exactly these float operations, an amount `error` that
// the float evaluation never exceeds, and its smallest vertex depth rounded down. See
// prepare_depth_plane.
struct PreparedTriangle {
    float a, dzdx, dzdy, error, z_vertex_min;
    bool far_is_left, far_is_top;  // where the plane is smallest: towards lower X, lower Y
    bool has_plane;                // false: too steep for float, a, dzdx, dzdy and error are 0
    // Not the plane's: whether a RasterTriangle holds float_edges (its rows by the float rule).
    // Kept here, in the plane's spare byte, so that the binned RasterTriangle stays 192 bytes.
    bool float_rows;
};

// Where a prepared plane is smallest (its far corner), from the signs of its float slopes.
inline void set_far_corner(PreparedTriangle& tri) {
    tri.far_is_left = tri.dzdx > 0.0f;
    tri.far_is_top = tri.dzdy > 0.0f;
}

// The depth plane of a triangle with vertices p[k] and depths d[k] (counter-clockwise,
// twice its area `area2` > 0), for a sample grid of width x height.
PreparedTriangle prepare_depth_plane(const glm::dvec2 p[3], const double d[3], double area2, int width, int height);
// prepare_depth_plane in two steps: the plane's double terms (which the SIMD setup repeats
// lane by lane), then their float form.
struct DepthPlaneTerms {
    double dzdx, dzdy, a, magnitude, error;
};
DepthPlaneTerms depth_plane_terms(const glm::dvec2 p[3], const double d[3], double area2, int width, int height);
PreparedTriangle finish_depth_plane(const DepthPlaneTerms& terms, const double d[3]);

// The conservative depth a triangle enters a subtile with, given the column and row (in
// samples) of the covered samples' corner where the plane is smallest: the plane lowered by
// its error bound, never below the farthest vertex, lowered by a relative 2^-20, as float.
// Values <= 0 mean "no bound": the subtile's depth is left alone. The SIMD kernels evaluate
// the same operations lane by lane.
inline float conservative_depth(const PreparedTriangle& tri, int column, int row) {
    const float x = float(column) + 0.5f, y = float(row) + 0.5f;  // exact: |column|, |row| < 2^23
    const float plane = (tri.a + tri.dzdy * y) + tri.dzdx * x;
    const float bound = std::max(plane - tri.error, tri.z_vertex_min);
    return bound * (1.0f - 0x1.0p-20f);
}

// The largest conservative_depth(tri, column, row) over the samples of the box of columns
// [i0, i1] and rows [r0, r1]: its value at the box's corner where the plane is largest (the
// corner opposite far_is_left / far_is_top). Exact, not only a bound: every operation of
// conservative_depth (the products by x and y, the sums, the max and the product) rounds
// monotonically, so its float value never decreases towards that corner, whatever the
// roundings.
inline float nearest_conservative_depth(const PreparedTriangle& tri, int i0, int i1, int r0, int r1) {
    return conservative_depth(tri, tri.far_is_left ? i1 : i0, tri.far_is_top ? r1 : r0);
}

// Early rejection of hidden triangles, as Greene's hierarchical Z-buffer rejects primitives
// (Greene, Kass and Miller, "Hierarchical Z-Buffer Visibility", SIGGRAPH 1993), here against
// the reference layer: whether every subtile of columns [tx0, tx1] and rows [ty0, ty1] has
// d0 > 0 and d0 >= nearest (nearest_conservative_depth of the triangle over those samples).
// Then rasterizing the triangle there changes nothing, bit for bit: a subtile takes a triangle
// only when its conservative depth is > d0, and `covered` already holds every sample of a
// subtile with d0 > 0 (d0 leaves 0 only when every sample is in the working layer or under the
// triangle merged, and each was added to `covered` as it was: layer_merge.hpp). Nor does it
// change the per-sample depth (planes.sample_depth): every sample's depth is at or in front of
// its subtile's d0, since d0 is the least of the bounds the merge keeps, and each is the
// conservative_depth of a triangle covering the sample at the corner of its covered samples
// that the subtile took (the roundings are monotone, so at most its value at the sample); so
// nearest, which bounds the triangle's depth at every sample of the box, is at or behind what
// each sample holds. The SIMD kernels make the same test with vectors of subtiles (pure
// comparisons: the same answer).
bool hidden_behind_reference_layer(const SubtilePlanes& planes, int tx0, int tx1, int ty0, int ty1, float nearest);

// nearest_conservative_depth of a triangle over its samples in subtile rows [ty0, ty1] (its
// columns [i0, i1], its rows [j0, j1] within those): what the row loops test a chunk with.
inline float chunk_nearest_depth(const PreparedTriangle& tri, int i0, int i1, int j0, int j1, int ty0, int ty1) {
    constexpr int kH = kSubtileHeight;
    return nearest_conservative_depth(tri, i0, i1, std::max(j0, ty0 * kH), std::min(j1, ty1 * kH + kH - 1));
}

// The row rule in float, for triangles whose three edges are silhouette edges (no shared
// edge needs its bits matched by a neighbour) and near enough to the screen: 16 rows per
// AVX-512 vector instead of 8 in double. Each edge k is taken relative to the whole sample
// (ox_int, oy_int) below its lower endpoint, so that every float holds a small number:
//     v = base_k - slope_k * ((row - oy_int) - y_offset_k)
// with slope = sb / sa, y_offset = frac(oy) - 0.5 and base = frac(ox) + threshold / sa - h,
// is x_k - ox_int - h (x_k of the double rule): three roundings per row besides those of
// y_offset, slope and base to float, every other float operation exact. Its error is less
// than `error` = 2^-20 (reach + |slope| + |threshold / sa| + 2), reach bounding |x_k - ox| over
// the rows whose x_k falls near the triangle's columns (the others are clamped away whatever
// the rounding); h = 0.5 -+ error shifts the boundary inwards by that much, so a sample kept
// here is kept by the exact rule (and by the double one: the tests check that every float
// interval lies inside the double interval). Lower edges (sa > 0) keep the samples from
// floor(v) + 1 + ox_int on, upper ones up to ceil(v) - 1 + ox_int, v clamped first to the
// columns [i0 - 2, i1 + 2] - ox_int (integers below 2^24: exact in float).
struct FloatRowEdges {
    float row_origin[3];    // oy_int
    float y_offset[3];      // frac(oy) - 0.5
    float slope[3];         // sb / sa
    float base[3];          // frac(ox) + threshold / sa - h
    float lo_clamp[3];      // i0 - 2 - ox_int
    float hi_clamp[3];      // i1 + 2 - ox_int
    float column_shift[3];  // 1 + ox_int on a lower edge, ox_int - 1 on an upper one
    bool lower[3];          // sa > 0: the edge bounds the row's samples from below
};
// False (use the double rule) when an edge is shared or horizontal, an endpoint lies 2^22
// samples or more from the origin, or the float error would exceed 2^-8 samples.
bool prepare_float_row_edges(const TriangleEdges& edges, int i0, int i1, FloatRowEdges& out);
// The samples [first, last] of sample row `row` within [i0, i1] by the float rule: the
// reference the SIMD kernels match lane by lane.
void float_sample_row_interval(const FloatRowEdges& edges, int row, int i0, int i1, std::int32_t& first, std::int32_t& last);

// A triangle set up for the row kernels, once, however many bands then rasterize it: its
// edge functions with the coverage thresholds (or their float form), its depth plane, and the
// samples [i0, i1] x [j0, j1] whose centres lie in its bounding box.
struct RasterTriangle {
    // The row rule's terms: in float where prepare_float_row_edges allows (plane.float_rows),
    // else the double edge functions. One or the other: the bins of the two-thread render copy every
    // triangle, and this keeps the copy at 192 bytes.
    union {
        TriangleEdges edges;        // when !plane.float_rows
        FloatRowEdges float_edges;  // when plane.float_rows
    };
    PreparedTriangle plane;
    int i0, i1, j0, j1;
};
static_assert(sizeof(RasterTriangle) == 192, "the two-thread render copies every binned triangle");

// The sample rows [row_lo, row_hi] within the triangle's [j0, j1] outside which no row holds a
// sample in its columns [i0, i1] (false: none does). The row rule (sample_row_interval, or
// float_sample_row_interval for float_rows) bounds a row's samples by each edge's boundary x_k,
// a linear function of the row: a lower edge's first sample is past x_k - 1/2 and an upper
// edge's last before it, so a row where a lower edge's boundary lies right of i1 + 1/2 or an
// upper one's left of i0 + 1/2 has none, whatever the other edges. Solved for the rows in
// double with a margin of a sample beyond the rules' roundings, then widened by a row on each
// side. A large triangle partly beside the view spans rows its part in it does not reach: the
// row loop skips them before computing their intervals. Rows inside may still be empty.
bool rows_reaching_columns(const RasterTriangle& triangle, int& row_lo, int& row_hi);
// The same for the double rule's edges (any thresholds: the occludee tests' outer ones too) over
// columns [i0, i1] and rows [j0, j1].
bool rows_reaching_columns(const TriangleEdges& edges, int i0, int i1, int j0, int j1, int& row_lo, int& row_hi);
// Whether rows_reaching_columns may pay for a triangle's box of samples [i0, i1] x [j0, j1] in a
// view sample_width wide: only where the view's side cut its columns (elsewhere every row of the
// box reaches them) and it spans 16 sample rows or more (on the castle's walk, bounding every
// triangle cost 1.25 % more instructions than it saved).
inline bool rows_worth_bounding(int i0, int i1, int j0, int j1, int sample_width) {
    return (i0 == 0 || i1 == sample_width - 1) && j1 - j0 >= 4 * kSubtileHeight;
}

// The coverage threshold of an edge with sign-normalized normal (sa, sb): an inner margin of
// edge_margin samples (times the normal's L1 length) on a silhouette edge, none on a shared one.
inline double edge_threshold(bool shared, double edge_margin, double sa, double sb) {
    return shared ? 0.0 : edge_margin * (std::abs(sa) + std::abs(sb));
}

// Sets up a triangle of either orientation for a sample grid of width x height, with the inner
// coverage margin edge_margin (samples) on its silhouette edges. False when it covers no
// sample centre's bounding box or has no area: nothing to rasterize.
bool setup_raster_triangle(const ScreenTriangle& triangle, double edge_margin, int sample_width, int sample_height,
                           RasterTriangle& out);

// A screen triangle with its vertices ordered so that twice its signed area, area2, is
// positive: its edge functions are then positive inside. Shared-edge flags follow the edges.
struct OrientedTriangle {
    glm::dvec2 v[3];
    double d[3];
    bool shared[3];
    double area2;
};
// False when the triangle's area is zero: `out` then holds its vertices and depths in input
// order, but no usable area or orientation.
bool orient_triangle(const ScreenTriangle& triangle, OrientedTriangle& out);

// The three edge functions of an oriented triangle (see TriangleEdges), with the shared flags
// copied and every threshold 0: the caller sets the thresholds it needs (inner margins for
// occluders, outer ones for occludees).
TriangleEdges edge_functions(const OrientedTriangle& triangle);

// The samples [first, last] of sample row `row` (centres at row + 0.5) within [i0, i1] on the
// covered side of every edge: the row formula of rasterize.cpp. Empty when first > last.
void sample_row_interval(const TriangleEdges& edges, int row, int i0, int i1, std::int32_t& first, std::int32_t& last);

// The intervals [first[j], last[j]] of subtile row ty's four sample rows: sample_row_interval
// for the rows in [j0, j1] (the whole span [i0, i1] when edges is null), empty for the others.
void subtile_row_intervals(const TriangleEdges* edges, int ty, int i0, int i1, int j0, int j1, std::int32_t first[4],
                           std::int32_t last[4]);

// The samples of subtile column tx that a subtile row's intervals [first[j], last[j]] cover,
// and the columns and rows (within the subtile) of their bounding rectangle; mask 0 when none.
struct SubtileCoverage {
    std::uint32_t mask = 0;
    int column_lo = kSubtileWidth, column_hi = -1, row_lo = kSubtileHeight, row_hi = -1;
};
SubtileCoverage subtile_coverage(const std::int32_t first[4], const std::int32_t last[4], int tx);

// The scalar reference of the subtile-row update: the subtiles (tx_begin..tx_end, ty) from the
// row intervals [first[j], last[j]] of the subtile row's four sample rows. Returns the number
// of subtiles updated.
std::uint64_t update_subtile_row_reference(const SubtilePlanes& planes, int ty, int tx_begin, int tx_end, const std::int32_t first[4],
                                           const std::int32_t last[4], const PreparedTriangle& tri, int sample_width, int sample_height);

// Bit count without a library call (the baseline x86-64 target has no popcnt instruction).
inline std::uint32_t bit_count(std::uint32_t v) {
    v = v - ((v >> 1) & 0x55555555u);
    v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
    return (((v + (v >> 4)) & 0x0F0F0F0Fu) * 0x01010101u) >> 24;
}

// The mask of subtile (tx, ty)'s samples that lie in the sample range [i0, i1] x [j0, j1].
inline std::uint32_t subtile_rect_bits(int tx, int ty, int i0, int i1, int j0, int j1) {
    constexpr int kW = kSubtileWidth, kH = kSubtileHeight;
    const int c0 = std::max(0, i0 - tx * kW), c1 = std::min(kW - 1, i1 - tx * kW);
    const int r0 = std::max(0, j0 - ty * kH), r1 = std::min(kH - 1, j1 - ty * kH);
    if (c0 > c1 || r0 > r1) return 0;
    const std::uint32_t columns = (0xFFu >> (kW - 1 - c1)) & (0xFFu << c0);
    std::uint32_t rect = 0;
    for (int j = r0; j <= r1; ++j) rect |= columns << (j * kW);
    return rect;
}

// The samples of a grid of `count` whose centres (i + 0.5) lie in [lo, hi]: [first, last],
// empty when first > last. The one rule for what a span of the screen covers, used by the
// triangle bounding box, the binning and the rectangle tests.
// lo and hi are first clamped to [-1, count + 1], which changes no non-empty answer and keeps
// the conversions to int defined for any input: a NaN bound gives an empty span (callers that
// must not read "no sample" as "hidden" reject non-finite input before).
inline void sample_span(double lo, double hi, int count, int& first, int& last) {
    const double top = double(count) + 1.0;
    lo = lo >= -1.0 ? std::min(lo, top) : (lo < -1.0 ? -1.0 : top);  // NaN: top
    hi = hi <= top ? std::max(hi, -1.0) : (hi > top ? top : -1.0);   // NaN: -1
    // ceil and floor of numbers in [-1.5, count + 0.5] by truncation: exact for any int count,
    // and cheaper than std::ceil and std::floor, which the baseline x86-64 target (no SSE4.1
    // round) computes with a range check and two conversions (measurably so on single
    // test_rect calls).
    const double first_edge = lo - 0.5, last_edge = hi - 0.5;
    const int first_truncated = int(first_edge), last_truncated = int(last_edge);
    first = std::max(0, first_truncated + int(double(first_truncated) < first_edge));
    last = std::min(count - 1, last_truncated - int(double(last_truncated) > last_edge));
}

// The subtile columns [tx_begin, tx_end] that a subtile row's sample-row intervals
// [first[j], last[j]] reach, within the triangle's columns [i0, i1]; false when none.
inline bool reached_subtile_columns(const std::int32_t first[4], const std::int32_t last[4], int i0, int i1, int& tx_begin,
                                    int& tx_end) {
    constexpr int kW = kSubtileWidth;
    int reach_lo = i1 + 1, reach_hi = i0 - 1;
    for (int j = 0; j < kSubtileHeight; ++j)
        if (first[j] <= last[j]) {
            reach_lo = std::min(reach_lo, int(first[j]));
            reach_hi = std::max(reach_hi, int(last[j]));
        }
    if (reach_lo > reach_hi) return false;
    tx_begin = std::max(i0 / kW, reach_lo / kW);
    tx_end = std::min(i1 / kW, reach_hi / kW);
    return true;
}

// The mask of the samples of subtile (tx, ty) that exist (the buffer's right and bottom
// subtiles may be partly outside the sample grid).
std::uint32_t valid_sample_mask(int tx, int ty, int sample_width, int sample_height);

// The per-sample depth of a subtile row's covered samples (planes.sample_depth, which must be
// non-null): the maximum of what it holds and conservative_depth at the sample. The scalar
// reference; the SIMD kernels repeat its float operations lane by lane (UpdateSampleDepth).
void update_sample_depth(const SubtilePlanes& planes, int ty, const std::int32_t first[4], const std::int32_t last[4],
                         const PreparedTriangle& tri);

// The rows of a triangle are taken in chunks of this many subtile rows: the SIMD row loop
// computes a chunk's sample-row intervals in one pass, and every row loop first skips a chunk
// where the triangle is hidden behind the reference layer (hidden_behind_reference_layer).
constexpr int kChunkSubtileRows = 16;

// The reference row loop: scalar intervals and update_subtile_row_reference.
std::uint64_t rasterize_rows_reference(const RasterTarget& target, const RasterTriangle& triangle);

// Whether the row loops skip chunks hidden behind the reference layer (default: yes). The
// skip changes no bit; switching it off gives the tests an oracle for that.
void set_hidden_skip(bool enabled);
bool hidden_skip_enabled();

// subtile_row_intervals for the sample rows [row0, row0 + rows) at once (rows a multiple of
// 4), the rows as SIMD lanes: the row loop's double intervals, with the same operations, so
// the same intervals on every row in [j0, j1] (first > last elsewhere, with other values).
// Writes up to kMaxSimdLanes entries past `rows`. (The scalar reference has none: RasterKernels.)
using RowIntervalsKernel = void (*)(const TriangleEdges& edges, int i0, int i1, int j0, int j1, int row0, int rows,
                                    std::int32_t* first, std::int32_t* last);

}  // namespace homcull::detail
