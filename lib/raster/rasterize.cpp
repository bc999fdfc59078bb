// Coverage. A sample is covered when, for each edge, the edge function exceeds the edge's
// threshold: edge_margin samples times the L1 length of the edge normal (so at least
// edge_margin samples of distance) on a silhouette edge, and 0 (inclusive) on an edge shared
// with another drawn triangle. It is computed per sample row: in a row each edge bounds the
// covered samples on one side, at
//     x_k = o_k.x + (threshold_k - sb_k * (y - o_k.y)) * (1 / sa_k)
// (sa, sb the sign-normalized edge normal, o_k the edge's lower endpoint by y then x), in
// double, in exactly this order, without fused multiply-add. That formula is the definition:
// SIMD kernels evaluate it the same way and get the same bits. The two triangles of a shared
// edge compute bit-identical x_k (negation is exact), one keeping samples at or right of it and
// the other at or left of it, so every sample near a shared edge lands in at least one.
// Triangles whose three edges are silhouette edges (no neighbour to match bit for bit) use a
// float form of it instead, whose boundary is moved inwards by its own rounding bound: see
// prepare_float_row_edges in rasterize.hpp.
//
#include "raster/rasterize.hpp"
#include "raster/layer_merge.hpp"
#include "raster/sample_depth_tiles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace homcull::detail {
namespace {

constexpr int kW = kSubtileWidth, kH = kSubtileHeight;

// floor and ceil of doubles well inside the int range (sample coordinates stay within the guard
// band), exact, without a libm call.
inline int floor_int(double x) {
    const int i = int(x);  // truncates toward zero
    return i - (double(i) > x);
}
inline int ceil_int(double x) {
    const int i = int(x);
    return i + (double(i) < x);
}

}  // namespace

std::uint32_t valid_sample_mask(int tx, int ty, int sample_width, int sample_height) {
    return subtile_rect_bits(tx, ty, 0, sample_width - 1, 0, sample_height - 1);
}

// The plane d(X, Y) = z0 + dzdx (X - x0) + dzdy (Y - y0) through the vertices, rewritten as
// a + dzdy Y + dzdx X and evaluated in float (conservative_depth). Its float evaluation at
// sample centres (|X| <= width, |Y| <= height, exact in float) differs from the double plane
// by at most 2^-24 for each of the 5 roundings (a, dzdy, dzdx, two products, two sums) times the
// magnitudes involved, that is less than 2^-21 (|a| + |dzdx| width + |dzdy| height); the
// subtraction of `error` rounds by less than 2^-25 of the same; `error` = 2^-20 of it covers
// both, plus the double rounding of a (2^-40 of its terms is far more than it needs). That
// relative bound holds for normal floats only: a rounding into the subnormal range (depths below
// 2^-126, w beyond 2^126) errs by up to 2^-150 however small the value, and dzdx, dzdy are
// multiplied by columns and rows below 2^23. 2^-126 more covers all of it: such planes are then
// no bound at all, and the smallest vertex depth (rounded down) is used alone.
DepthPlaneTerms depth_plane_terms(const glm::dvec2 p[3], const double d[3], double area2, int width, int height) {
    DepthPlaneTerms t;
    t.dzdx = ((d[1] - d[0]) * (p[2].y - p[0].y) - (d[2] - d[0]) * (p[1].y - p[0].y)) / area2;
    t.dzdy = ((d[2] - d[0]) * (p[1].x - p[0].x) - (d[1] - d[0]) * (p[2].x - p[0].x)) / area2;
    t.a = d[0] - t.dzdx * p[0].x - t.dzdy * p[0].y;
    t.magnitude = std::abs(t.a) + std::abs(t.dzdx) * width + std::abs(t.dzdy) * height;
    t.error = (0x1.0p-20 * t.magnitude + 0x1.0p-40 * (std::abs(d[0]) + std::abs(t.dzdx * p[0].x) + std::abs(t.dzdy * p[0].y))) + 0x1.0p-126;
    return t;
}

PreparedTriangle finish_depth_plane(const DepthPlaneTerms& t, const double d[3]) {
    PreparedTriangle tri;
    tri.float_rows = false;
    tri.z_vertex_min = float_down(std::min({d[0], d[1], d[2]}));
    if (std::isfinite(t.error) && t.magnitude < 0x1.0p100) {
        tri.a = float(t.a);
        tri.dzdx = float(t.dzdx);
        tri.dzdy = float(t.dzdy);
        tri.error = float_up(t.error);
        tri.has_plane = true;
    } else {  // a plane too steep for float (a sliver seen edge-on): the farthest vertex alone
        tri.a = tri.dzdx = tri.dzdy = tri.error = 0.0f;
        tri.has_plane = false;
    }
    set_far_corner(tri);
    return tri;
}

PreparedTriangle prepare_depth_plane(const glm::dvec2 p[3], const double d[3], double area2, int width, int height) {
    return finish_depth_plane(depth_plane_terms(p, d, area2, width, height), d);
}

bool orient_triangle(const ScreenTriangle& tri, OrientedTriangle& out) {
    out.v[0] = tri.p[0], out.v[1] = tri.p[1], out.v[2] = tri.p[2];
    out.d[0] = tri.d[0], out.d[1] = tri.d[1], out.d[2] = tri.d[2];
    for (int k = 0; k < 3; ++k) out.shared[k] = (tri.shared >> k) & 1u;
    const glm::dvec2 p0 = tri.p[0], p1 = tri.p[1], p2 = tri.p[2];
    out.area2 = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
    if (out.area2 == 0.0) return false;
    if (out.area2 < 0.0) {  // make the edge functions positive inside: order 0, 2, 1
        std::swap(out.v[1], out.v[2]);
        std::swap(out.d[1], out.d[2]);
        std::swap(out.shared[0], out.shared[2]);  // edges 0->2, 2->1, 1->0 were edges 2, 1, 0
        out.area2 = -out.area2;
    }
    return true;
}

TriangleEdges edge_functions(const OrientedTriangle& tri) {
    TriangleEdges edges;
    for (int k = 0; k < 3; ++k) {
        const glm::dvec2& from = tri.v[k];
        const glm::dvec2& to = tri.v[(k + 1) % 3];
        const bool forward = from.y != to.y ? from.y < to.y : from.x < to.x;
        const glm::dvec2& lo = forward ? from : to;
        const glm::dvec2& hi = forward ? to : from;
        const double a = -(hi.y - lo.y), b = hi.x - lo.x, sign = forward ? 1.0 : -1.0;
        edges.ox[k] = lo.x;
        edges.oy[k] = lo.y;
        edges.sa[k] = sign * a;
        edges.sb[k] = sign * b;
        edges.inverse_sa[k] = edges.sa[k] != 0.0 ? 1.0 / edges.sa[k] : 0.0;
        edges.shared[k] = tri.shared[k];
        edges.threshold[k] = 0.0;
    }
    return edges;
}

bool setup_raster_triangle(const ScreenTriangle& triangle, double edge_margin, int sample_width, int sample_height,
                           RasterTriangle& out) {
    OrientedTriangle tri;
    if (!orient_triangle(triangle, tri)) return false;
    // Sample rows and columns whose centres lie in the triangle's bounding box.
    const glm::dvec2* v = tri.v;
    sample_span(std::min({v[0].x, v[1].x, v[2].x}), std::max({v[0].x, v[1].x, v[2].x}), sample_width, out.i0, out.i1);
    sample_span(std::min({v[0].y, v[1].y, v[2].y}), std::max({v[0].y, v[1].y, v[2].y}), sample_height, out.j0, out.j1);
    if (out.i0 > out.i1 || out.j0 > out.j1) return false;

    TriangleEdges edges = edge_functions(tri);
    for (int k = 0; k < 3; ++k)  // inner margin on silhouette edges (see the top of this file)
        edges.threshold[k] = edge_threshold(edges.shared[k], edge_margin, edges.sa[k], edges.sb[k]);
    out.plane = prepare_depth_plane(tri.v, tri.d, tri.area2, sample_width, sample_height);
    FloatRowEdges float_edges;
    out.plane.float_rows = prepare_float_row_edges(edges, out.i0, out.i1, float_edges);
    if (out.plane.float_rows) out.float_edges = float_edges;
    else out.edges = edges;
    return true;
}

void sample_row_interval(const TriangleEdges& edges, int row, int i0, int i1, std::int32_t& first, std::int32_t& last) {
    first = i0;
    last = i1;
    const double py = row + 0.5;
    for (int k = 0; k < 3; ++k) {
        const double c = edges.threshold[k] - edges.sb[k] * (py - edges.oy[k]);  // need sa * (x - o.x) > c
        if (edges.sa[k] == 0.0) {
            if (edges.shared[k] ? !(0.0 >= c) : !(0.0 > c)) last = first - 1;
            continue;
        }
        const double x = edges.ox[k] + c * edges.inverse_sa[k];  // boundary, in samples
        // The boundary may lie far outside the buffer for a nearly horizontal edge: clamp
        // before converting to int (the interval is clamped to [i0, i1] anyway).
        // A NaN boundary (only from non-finite or extreme setup values) bounds nothing: the row is
        // empty, never the whole span (std::clamp would pass NaN on to an undefined int conversion).
        if (x != x) {
            last = first - 1;
            continue;
        }
        const double xs = std::clamp(x - 0.5, double(i0) - 2.0, double(i1) + 2.0);
        if (edges.sa[k] > 0.0) first = std::max(first, edges.shared[k] ? ceil_int(xs) : floor_int(xs) + 1);
        else last = std::min(last, edges.shared[k] ? floor_int(xs) : ceil_int(xs) - 1);
    }
}

bool prepare_float_row_edges(const TriangleEdges& e, int i0, int i1, FloatRowEdges& out) {
    constexpr double kLimit = 0x1.0p22, kMaxError = 0x1.0p-8;
    for (int k = 0; k < 3; ++k) {
        if (e.shared[k] || e.sa[k] == 0.0) return false;
        const double ox = e.ox[k], oy = e.oy[k];
        if (!(std::abs(ox) < kLimit && std::abs(oy) < kLimit)) return false;
        const double ox_int = floor_int(ox), oy_int = floor_int(oy);  // exact: |ox|, |oy| < 2^22
        const double slope = e.sb[k] * e.inverse_sa[k], offset = e.threshold[k] * e.inverse_sa[k];
        // The rows whose boundary lies within [i0 - 3, i1 + 3] have |x_k - ox| <= reach.
        const double reach = std::max(std::abs(ox - (i0 - 3)), std::abs(ox - (i1 + 3))) + 1.0;
        const double error = 0x1.0p-20 * (reach + std::abs(slope) + std::abs(offset) + 2.0);
        if (!(error <= kMaxError)) return false;
        const bool lower = e.sa[k] > 0.0;
        const double h = lower ? 0.5 - error : 0.5 + error;
        out.row_origin[k] = float(oy_int);
        out.y_offset[k] = float((oy - oy_int) - 0.5);  // exact in double: frac(oy) is a multiple of oy's ulp
        out.slope[k] = float(slope);
        out.base[k] = float((ox - ox_int) + offset - h);
        out.lo_clamp[k] = float(i0 - 2 - ox_int);
        out.hi_clamp[k] = float(i1 + 2 - ox_int);
        out.column_shift[k] = float(lower ? 1.0 + ox_int : ox_int - 1.0);
        out.lower[k] = lower;
    }
    return true;
}

void float_sample_row_interval(const FloatRowEdges& e, int row, int i0, int i1, std::int32_t& first, std::int32_t& last) {
    float lo = float(i0), hi = float(i1);
    const float y = float(row);
    for (int k = 0; k < 3; ++k) {
        const float v = e.base[k] - e.slope[k] * ((y - e.row_origin[k]) - e.y_offset[k]);
        const float clamped = std::min(std::max(v, e.lo_clamp[k]), e.hi_clamp[k]);
        if (e.lower[k]) lo = std::max(lo, std::floor(clamped) + e.column_shift[k]);
        else hi = std::min(hi, std::ceil(clamped) + e.column_shift[k]);
    }
    first = std::int32_t(lo);
    last = std::int32_t(hi);
}

namespace {

// Narrows the rows [lo, hi] to those where a boundary value(row) = alpha + beta row is at most
// `limit` (a lower edge's) or at least (an upper edge's), as a row with a sample needs: by a
// margin of a sample plus `relative` times the magnitude of the terms the rules round.
struct RowBounds {
    double lo, hi;
    void constrain(double alpha, double beta, double limit, bool at_most, double magnitude, double relative) {
        const double margin = 1.0 + relative * (magnitude + std::abs(limit));
        const double b = at_most ? beta : -beta;  // as b row <= r
        const double r = at_most ? limit + margin - alpha : alpha - limit + margin;
        if (!(std::isfinite(b) && std::isfinite(r))) return;
        if (b > 0x1.0p-20) hi = std::min(hi, r / b);
        else if (b < -0x1.0p-20) lo = std::max(lo, r / b);
        // A nearly vertical boundary bounds no rows here (its rows' columns hardly move).
    }
    // Whole rows, widened by one on each side, within [j0, j1] (so the conversions are exact).
    bool rows(int j0, int j1, int& row_lo, int& row_hi) const {
        if (!(lo <= hi)) return false;  // no row (NaN bounds were passed over)
        row_lo = int(std::max(double(j0), std::floor(lo) - 1.0));
        row_hi = int(std::min(double(j1), std::ceil(hi) + 1.0));
        return row_lo <= row_hi;
    }
};

}  // namespace

bool rows_reaching_columns(const TriangleEdges& e, int i0, int i1, int j0, int j1, int& row_lo, int& row_hi) {
    row_lo = j0, row_hi = j1;
    if (j0 > j1 || i0 > i1) return false;
    RowBounds bounds{double(j0), double(j1)};
    for (int k = 0; k < 3; ++k) {
        if (!(e.sa[k] != 0.0)) continue;  // horizontal: bounds rows, which [j0, j1] does
        // x = ox + (threshold - sb (row + 1/2 - oy)) / sa; first > x - 1/2 on a lower edge
        // (sa > 0), last < x - 1/2 on an upper one.
        const double slope = e.sb[k] * e.inverse_sa[k];
        const double alpha = e.ox[k] + (e.threshold[k] - e.sb[k] * (0.5 - e.oy[k])) * e.inverse_sa[k] - 0.5;
        const double reach = std::max(std::abs(double(j0)), std::abs(double(j1))) + std::abs(e.oy[k]) + 1.0;
        const double magnitude = std::abs(e.ox[k]) + std::abs(e.threshold[k] * e.inverse_sa[k]) + std::abs(slope) * reach + 1.0;
        bounds.constrain(alpha, -slope, e.sa[k] > 0.0 ? double(i1) : double(i0), e.sa[k] > 0.0, magnitude, 0x1.0p-40);
    }
    return bounds.rows(j0, j1, row_lo, row_hi);
}

bool rows_reaching_columns(const RasterTriangle& triangle, int& row_lo, int& row_hi) {
    const int i0 = triangle.i0, i1 = triangle.i1, j0 = triangle.j0, j1 = triangle.j1;
    if (!triangle.plane.float_rows) return rows_reaching_columns(triangle.edges, i0, i1, j0, j1, row_lo, row_hi);
    row_lo = j0, row_hi = j1;
    if (j0 > j1 || i0 > i1) return false;
    RowBounds bounds{double(j0), double(j1)};
    const FloatRowEdges& e = triangle.float_edges;
    for (int k = 0; k < 3; ++k) {
        // v = base - slope ((row - row_origin) - y_offset), in float; a lower edge's first
        // sample is floor(v) + 1 + ox_int, an upper one's last ceil(v) - 1 + ox_int.
        const double slope = double(e.slope[k]), origin = double(e.row_origin[k]) + double(e.y_offset[k]);
        const double alpha = double(e.base[k]) + slope * origin;
        const double reach = std::max(std::abs(double(j0) - origin), std::abs(double(j1) - origin)) + 1.0;
        const double magnitude = std::abs(double(e.base[k])) + std::abs(slope) * reach;
        const double ox_int = e.lower[k] ? double(e.column_shift[k]) - 1.0 : double(e.column_shift[k]) + 1.0;
        bounds.constrain(alpha, -slope, (e.lower[k] ? double(i1) : double(i0)) - ox_int, e.lower[k], magnitude, 0x1.0p-20);
    }
    return bounds.rows(j0, j1, row_lo, row_hi);
}

bool hidden_behind_reference_layer(const SubtilePlanes& planes, int tx0, int tx1, int ty0, int ty1, float nearest) {
    // d0 >= max(nearest, the smallest positive float) is d0 >= nearest and d0 > 0.
    nearest = std::max(nearest, std::numeric_limits<float>::denorm_min());
    for (int ty = ty0; ty <= ty1; ++ty) {
        const float* d0 = planes.d0 + std::size_t(ty) * planes.stride;
        for (int tx = tx0; tx <= tx1; ++tx)
            if (d0[tx] < nearest) return false;
    }
    return true;
}

std::uint64_t rasterize_rows_reference(const RasterTarget& t, const RasterTriangle& triangle) {
    const PreparedTriangle& prepared = triangle.plane;
    const int i0 = triangle.i0, i1 = triangle.i1, j0 = triangle.j0, j1 = triangle.j1;
    int ty_first, ty_last;
    if (!subtile_rows_within(j0, j1, t.row_begin, t.row_end, ty_first, ty_last)) return 0;
    std::uint64_t updated = 0;
    // The per-sample depth: written below (the planes'), or when the buffer computes it where
    // read, each chunk's intervals listed, or written below into its zeroed tiles (list_sample_depth).
    SubtilePlanes depth_planes = t.planes;
    const bool listed = t.sample_tiles && list_sample_depth(*t.sample_tiles, triangle, ty_first, ty_last);
    if (t.sample_tiles && !listed) depth_planes.sample_depth = t.sample_tiles->depth;
    std::int32_t chunk_first[kChunkSubtileRows * kH], chunk_last[kChunkSubtileRows * kH];  // a listed chunk's intervals
    for (int ty0 = ty_first; ty0 <= ty_last; ty0 += kChunkSubtileRows) {
        const int ty1 = std::min(ty_last, ty0 + kChunkSubtileRows - 1);
        if (t.skip_hidden &&
            hidden_behind_reference_layer(t.planes, i0 / kW, i1 / kW, ty0, ty1, chunk_nearest_depth(prepared, i0, i1, j0, j1, ty0, ty1)))
            continue;
        for (int ty = ty0; ty <= ty1; ++ty) {
            // The covered interval [first, last] of each of the subtile row's sample rows.
            std::int32_t first[kH], last[kH];
            if (!triangle.plane.float_rows) subtile_row_intervals(&triangle.edges, ty, i0, i1, j0, j1, first, last);
            else
                for (int j = 0; j < kH; ++j) {
                    const int row = ty * kH + j;
                    first[j] = i0;
                    last[j] = i0 - 1;
                    if (row >= j0 && row <= j1) float_sample_row_interval(triangle.float_edges, row, i0, i1, first[j], last[j]);
                }
            std::copy(first, first + kH, chunk_first + (ty - ty0) * kH);
            std::copy(last, last + kH, chunk_last + (ty - ty0) * kH);
            int tx_begin, tx_end;
            if (!reached_subtile_columns(first, last, i0, i1, tx_begin, tx_end)) continue;
            updated += update_subtile_row_reference(t.planes, ty, tx_begin, tx_end, first, last, prepared, t.sample_width, t.sample_height);
            if (depth_planes.sample_depth) update_sample_depth(depth_planes, ty, first, last, prepared);
        }
        if (listed)
            record_sample_depth(*t.sample_tiles, prepared, i0, i1, ty0 * kH, (ty1 - ty0 + 1) * kH, chunk_first, chunk_last,
                                [&](const std::int32_t* record, int ux, int uy) { apply_depth_record_reference(*t.sample_tiles, record, ux, uy); });
    }
    return updated;
}

void update_sample_depth(const SubtilePlanes& planes, int ty, const std::int32_t first[4], const std::int32_t last[4],
                         const PreparedTriangle& triangle) {
    const PreparedTriangle tri = triangle;  // a local copy: the stores below cannot alias it, so the loop vectorizes
    for (int j = 0; j < kH; ++j) {
        const int row = ty * kH + j;
        float* depth = planes.sample_depth + std::size_t(row) * planes.sample_stride;
        for (int x = first[j]; x <= last[j]; ++x) depth[x] = std::max(depth[x], conservative_depth(tri, x, row));
    }
}

void subtile_row_intervals(const TriangleEdges* edges, int ty, int i0, int i1, int j0, int j1, std::int32_t first[4],
                           std::int32_t last[4]) {
    for (int j = 0; j < kH; ++j) {
        const int row = ty * kH + j;
        first[j] = i0;
        last[j] = i1;
        if (row < j0 || row > j1) last[j] = i0 - 1;
        else if (edges) sample_row_interval(*edges, row, i0, i1, first[j], last[j]);
    }
}

SubtileCoverage subtile_coverage(const std::int32_t first[4], const std::int32_t last[4], int tx) {
    SubtileCoverage c;
    for (int j = 0; j < kH; ++j) {
        const int lo = std::max(first[j] - tx * kW, 0), hi = std::min(last[j] - tx * kW, kW - 1);
        if (lo > hi) continue;
        c.mask |= ((0xFFu >> (kW - 1 - hi)) & (0xFFu << lo)) << (j * kW);
        c.column_lo = std::min(c.column_lo, lo);
        c.column_hi = std::max(c.column_hi, hi);
        c.row_lo = std::min(c.row_lo, j);
        c.row_hi = j;
    }
    return c;
}

std::uint64_t update_subtile_row_reference(const SubtilePlanes& planes, int ty, int tx_begin, int tx_end, const std::int32_t first[4],
                                           const std::int32_t last[4], const PreparedTriangle& tri, int sample_width, int sample_height) {
    std::uint64_t updated = 0;
    for (int tx = tx_begin; tx <= tx_end; ++tx) {
        // The coverage mask, and the column and row of its bounding rectangle where the depth
        // plane is smallest.
        const SubtileCoverage c = subtile_coverage(first, last, tx);
        const std::uint32_t m = c.mask;
        if (m == 0) continue;
        const int far_column = tri.far_is_left ? c.column_lo : c.column_hi, far_row = tri.far_is_top ? c.row_lo : c.row_hi;
        const std::size_t i = std::size_t(ty) * planes.stride + std::size_t(tx);
        planes.covered[i] |= m;

        const float d_tri = conservative_depth(tri, tx * kW + far_column, ty * kH + far_row);
        const SubtileLayers layers{planes.d0[i], planes.d1[i], planes.mask[i]};
        if (!(d_tri > layers.d0)) continue;  // behind what is already known (or no bound): nothing to add
        ++updated;
        const SubtileLayers merged = merge_triangle_into_layers(layers, m, d_tri, valid_sample_mask(tx, ty, sample_width, sample_height));
        planes.d0[i] = merged.d0;
        planes.d1[i] = merged.d1;
        planes.mask[i] = merged.mask;
    }
    return updated;
}

}  // namespace homcull::detail
