// Occludee triangles tested sample by sample against the buffer (OcclusionBuffer::
// test_triangles): the occludee's own shape instead of a box or rectangles around it, as masked
// occlusion culling's TestTriangles (Hasselgren, Andersson, Akenine-Moller, HPG 2016), made
// conservative for an exact ray cast at the sample centres:
// - coverage is outer: every sample the triangle may cover once the rounding of its float
//   input is accounted for (the Minkowski sum of the triangle with a box of that size is inside
//   the three edge half-planes pushed out by the box's support, |a| dx + |b| dy);
// - depth is the triangle's nearest over the covered samples of a subtile: its plane at the
//   nearest corner of their bounding rectangle (or at each sample, against a per-sample depth),
//   raised by the plane's float error and by how much the rounding of the vertices can move
//   the plane, never above its nearest vertex; or, where smaller, the plane through its
//   vertices raised by how far each may move (raised_vertex_plane.hpp).
// The row intervals and subtile masks are the rasterizer's (one formula, see rasterize.cpp).
#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "common/float_mode.hpp"
#include "buffer/occludee_depth.hpp"
#include "buffer/occludee_rectangles.hpp"
#include "buffer/raised_vertex_plane.hpp"
#include "buffer/seen_solid.hpp"
#include "buffer/rect_queries.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_batch.hpp"
#include "raster/triangle_setup.hpp"

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

using detail::OccludeeDepth;
using detail::OrientedTriangle;
using detail::PreparedTriangle;
using detail::TriangleEdges;
constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// How far an exact computation with the same scene may put the triangle's clip coordinates
// from ours. The matrix and the positions are floats (ground truth rounds its world positions
// to float as well): each entry and each coordinate carries a relative rounding of 2^-24, so
// clip coordinate r is off by at most about 2^-23 sum_i |m_ri p_i|; 2^-22 leaves a factor 2
// for the ray's own rounding and second-order terms. A point of the triangle (or of its part
// clipped at the near plane: a convex combination of the corners) is off by at most the
// largest corner error, per coordinate.
struct ClipError {
    double x = 0.0, y = 0.0, w = 0.0;
};

// sum_i |m_ri p_i| for each clip row r of a model point p.
void row_magnitudes(const std::array<float, 16>& m, const glm::dvec4& p, double magnitude[4]) {
    for (int row = 0; row < 4; ++row) {
        magnitude[row] = 0.0;
        for (int i = 0; i < 4; ++i) magnitude[row] += std::abs(double(m[std::size_t(4 * i + row)]) * p[i]);
    }
}

ClipError clip_error(const std::array<float, 16>& m, const glm::dvec4 model[3]) {
    ClipError e;
    for (int k = 0; k < 3; ++k) {
        double magnitude[4];
        row_magnitudes(m, model[k], magnitude);
        e.x = std::max(e.x, 0x1.0p-22 * magnitude[0]);
        e.y = std::max(e.y, 0x1.0p-22 * magnitude[1]);
        e.w = std::max(e.w, 0x1.0p-22 * magnitude[3]);
    }
    return e;
}

// The same for an orthographic input, whose clip coordinates are the representatives
// (x, y, w) / h, h = (3w - z) / 2 (orthographic_representative): with x, z, w off by their
// ClipError-style bounds, h is off by dh = (3 ew + ez) / 2 plus its rounding, and each
// coordinate by representative_error at the vertex's own h. Infinite where h comes within
// 2 dh of 0 (nothing to reason with: the occludee is visible).
ClipError orthographic_clip_error(const std::array<float, 16>& m, const glm::dvec4 model[3]) {
    ClipError e;
    for (int k = 0; k < 3; ++k) {
        double magnitude[4];
        row_magnitudes(m, model[k], magnitude);
        const glm::dvec4 c = detail::transform_to_clip_plain(m, model[k].x, model[k].y, model[k].z, model[k].w);
        const double ex = 0x1.0p-22 * magnitude[0], ey = 0x1.0p-22 * magnitude[1], ez = 0x1.0p-22 * magnitude[2],
                     ew = 0x1.0p-22 * magnitude[3];
        const double h = (3.0 * c.w - c.z) * 0.5, dh = (3.0 * ew + ez) * 0.5 + 0x1.0p-50 * (3.0 * std::abs(c.w) + std::abs(c.z));
        if (!(h > 2.0 * dh)) return {HUGE_VAL, HUGE_VAL, HUGE_VAL};
        e.x = std::max(e.x, detail::representative_error(c.x, ex, h, dh));
        e.y = std::max(e.y, detail::representative_error(c.y, ey, h, dh));
        e.w = std::max(e.w, detail::representative_error(c.w, ew, h, dh));
    }
    return e;
}

// Whether all three vertices lie beyond one side plane by more than the rounding of the plain
// transform (clip_error's bound, taken without products: each term |m p| is at most |m| times
// the largest |p|), so that the exact triangle lies beyond it too. The rounded coordinates alone
// are not enough where the terms cancel (model coordinates far larger than the clip coordinates
// they give: 2^-22 of them can exceed half a sample). row_x, row_y, row_w: 2^-22 times the sum
// of the magnitudes of the matrix's row.
bool beyond_side_plane_exactly(const glm::dvec4 model[3], const glm::dvec4 clip[3], double row_x, double row_y, double row_w) {
    double p = 0.0;
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 4; ++i) p = std::max(p, std::abs(model[k][i]));
    return detail::outside_side_plane(clip, (row_x + row_w) * p, (row_y + row_w) * p);
}

// The same in samples for a projected triangle (corners with d = 1/w), per vertex: NDC x =
// x / w is off by (ex + |x / w| ew) / w; w is off by a relative ew d, and so d by d (ew d).
// Their largest over the vertices pad the coverage and raise the plane-error bound; the
// raised-vertex bound takes them vertex by vertex.
struct VertexSlack {
    double x[3], y[3], depth[3];
    double max_x = 0.0, max_y = 0.0, w_relative = 0.0;
};

VertexSlack vertex_slack(const ClipError& e, const OrientedTriangle& t, int sample_width, int sample_height) {
    VertexSlack s;
    for (int k = 0; k < 3; ++k) {
        const double ndc_x = t.v[k].x / (0.5 * sample_width) - 1.0, ndc_y = 1.0 - t.v[k].y / (0.5 * sample_height);
        s.x[k] = (e.x + std::abs(ndc_x) * e.w) * t.d[k] * 0.5 * sample_width;
        s.y[k] = (e.y + std::abs(ndc_y) * e.w) * t.d[k] * 0.5 * sample_height;
        s.depth[k] = t.d[k] * (e.w * t.d[k]);
        s.max_x = std::max(s.max_x, s.x[k]);
        s.max_y = std::max(s.max_y, s.y[k]);
        s.w_relative = std::max(s.w_relative, e.w * t.d[k]);
    }
    return s;
}

// How far the rounding of the input (ClipError) can move the triangle's 1/w at an on-screen
// point. In clip space (x, y, w) the triangle spans the plane n . V = c, n = (V1 - V0) x
// (V2 - V0), c = n . V0, so at NDC (u, v) its 1/w is d = n . q / c with q = (u, v, 1),
// |q| <= sqrt(3) on screen. Moving each coordinate by at most e moves the edge vectors by at
// most 2 |e| and so n by dn <= 2 |e| (|E1| + |E2|) + 4 |e|^2, and c by dc <= dn |V0| +
// (|n| + dn) |e|; then d changes by at most (dn sqrt(3) + d dc) / (|c| - dc): an absolute
// part and a part relative to d. The bound depends on how the triangle sits in space (c = 0:
// seen edge-on), not on how it is clipped, so a floor cut at the near plane keeps its plane.
// Unusable (infinite) when |c| <= 2 dc.
struct PlaneError {
    double absolute = HUGE_VAL, relative = HUGE_VAL;
};

PlaneError plane_error(const glm::dvec4 clip[3], const ClipError& e) {
    const glm::dvec3 v0(clip[0].x, clip[0].y, clip[0].w), v1(clip[1].x, clip[1].y, clip[1].w), v2(clip[2].x, clip[2].y, clip[2].w);
    const glm::dvec3 e1 = v1 - v0, e2 = v2 - v0, n = glm::cross(e1, e2);
    const double ee = std::sqrt(e.x * e.x + e.y * e.y + e.w * e.w);
    const double dn = 2.0 * ee * (glm::length(e1) + glm::length(e2)) + 4.0 * ee * ee;
    const double dc = dn * glm::length(v0) + (glm::length(n) + dn) * ee;
    const double c = std::abs(glm::dot(n, v0));
    if (!(c > 2.0 * dc)) return {};
    return {dn * std::sqrt(3.0) / (c - dc), dc / (c - dc)};
}

// What OcclusionBuffer::ClosedSolid's argument needs: rays from one eye point (a perspective
// input) and model positions that are points (3 components, not clip space), whose planes the
// eye can be placed against; an orientation of +1 or -1 and a finite eye. Anything else throws.
void check_closed_solid(const TriangleInput& in, const OcclusionBuffer::ClosedSolid& solid) {
    if (in.orthographic || in.clip_space || in.position_components != 3)
        throw Error("test_triangles: ClosedSolid needs a perspective input with 3-component model positions (not orthographic, not "
                    "clip space)");
    if (solid.orientation != 1 && solid.orientation != -1) throw Error("test_triangles: ClosedSolid::orientation must be +1 or -1");
    if (!std::isfinite(solid.eye[0]) || !std::isfinite(solid.eye[1]) || !std::isfinite(solid.eye[2]))
        throw Error("test_triangles: ClosedSolid::eye must be finite");
}

struct SampleCounts {
    std::uint64_t samples = 0, visible = 0;
};


// A screen triangle's outer bounds: its oriented vertices, their rounding (VertexSlack), the
// padding of its coverage and the samples [i0, i1] x [j0, j1] of its padded bounding box,
// which hold every sample its outer coverage may reach; its nearest vertex's depth and the
// relative raise, whose product bounds its depth at any of them.
struct OuterBounds {
    OrientedTriangle tri;
    bool has_area;
    VertexSlack slack;
    double pad_x, pad_y;
    int i0, i1, j0, j1;
    float z_vertex_max, raise;
    bool empty() const { return i0 > i1 || j0 > j1; }
};

OuterBounds outer_bounds(const detail::ScreenTriangle& screen, const ClipError& error, double margin, int sample_width, int sample_height) {
    OuterBounds b;
    b.has_area = detail::orient_triangle(screen, b.tri);  // its vertices and depths are set either way
    b.slack = vertex_slack(error, b.tri, sample_width, sample_height);
    b.pad_x = b.slack.max_x + margin, b.pad_y = b.slack.max_y + margin;
    const glm::dvec2* v = b.tri.v;
    const double min_x = std::min({v[0].x, v[1].x, v[2].x}) - b.pad_x, max_x = std::max({v[0].x, v[1].x, v[2].x}) + b.pad_x;
    const double min_y = std::min({v[0].y, v[1].y, v[2].y}) - b.pad_y, max_y = std::max({v[0].y, v[1].y, v[2].y}) + b.pad_y;
    detail::sample_span(min_x, max_x, sample_width, b.i0, b.i1);
    detail::sample_span(min_y, max_y, sample_height, b.j0, b.j1);
    b.z_vertex_max = detail::float_up(std::max({b.tri.d[0], b.tri.d[1], b.tri.d[2]}));
    b.raise = detail::float_up(1.0 + 0x1.0p-20 + b.slack.w_relative);
    return b;
}

// The outer bounds of a triangle that setup_clip_triangle sets up without clipping (at the near
// plane near_clip): the screen triangle it makes of it (its projection alone). False for the
// others.
bool unclipped_outer_bounds(const glm::dvec4 clip[3], const ClipError& error, double near_clip, double margin, int sample_width,
                            int sample_height, OuterBounds& bounds) {
    if (detail::needs_clipping(clip, near_clip) || detail::too_large_to_clip(clip, near_clip)) return false;
    detail::ScreenTriangle screen;
    for (int k = 0; k < 3; ++k) detail::project_to_samples(clip[k].x, clip[k].y, clip[k].w, sample_width, sample_height, screen.p[k], screen.d[k]);
    bounds = outer_bounds(screen, error, margin, sample_width, sample_height);
    return true;
}

// The rectangle test of the triangle's whole bounding box of samples at its nearest vertex's
// raised depth: its samples include every sample the triangle's outer coverage reaches, at a
// depth no nearer than any bound count_triangle takes there (OccludeeDepth::at is at most
// z_vertex_max * raise in float, rounded up here), and test_prepared_rect compares them with
// the same layer bounds (subtile_unhidden_samples). Where it is hidden (or empty), the triangle
// hides nothing count_triangle would find: its samples are not counted.
detail::RectQuery bounding_rectangle(const OuterBounds& b) {
    return {b.i0, b.i1, b.j0, b.j1, detail::float_up(double(b.z_vertex_max) * double(b.raise))};
}

// Counts one screen triangle's outer-covered samples and those not certainly hidden; stops
// once more than `tolerated` are visible.
void count_triangle(const OuterBounds& b, const PlaneError& depth_error, const detail::SubtileView& view, int sample_width, int sample_height, std::uint64_t tolerated,
                    const detail::BufferKernels& kernels, SampleCounts& counts) {
    if (b.empty()) return;
    const OrientedTriangle& tri = b.tri;
    const bool has_area = b.has_area;
    const VertexSlack& slack = b.slack;
    const double pad_x = b.pad_x, pad_y = b.pad_y;
    const int i0 = b.i0, i1 = b.i1, j0 = b.j0, j1 = b.j1;

    OccludeeDepth depth;
    depth.z_vertex_max = b.z_vertex_max;
    depth.raise = b.raise;
    TriangleEdges edges{};
    if (has_area) {
        edges = detail::edge_functions(tri);
        for (int k = 0; k < 3; ++k) {  // outer: pushed out by the support of the pad box
            edges.shared[k] = false;
            edges.threshold[k] = -(std::abs(edges.sa[k]) * pad_x + std::abs(edges.sb[k]) * pad_y);
        }
        depth.plane = detail::prepare_depth_plane(tri.v, tri.d, tri.area2, sample_width, sample_height);
        depth.error = detail::float_up(double(depth.plane.error) + depth_error.absolute);
        if (std::isfinite(depth.error) && std::isfinite(depth_error.relative))
            depth.plane_raise = detail::float_up(1.0 + depth_error.relative);
        else
            depth.plane.has_plane = false;  // seen edge-on, as far as the rounding can tell: the nearest vertex alone
    } else {
        depth.plane.has_plane = false;  // zero area after projection: its padded bounding box, at its nearest vertex
    }

    const bool no_tolerance = tolerated == 0;
    bool raised_ready = false;
    const detail::OccludeeRowKernel row_kernel = kernels.occludee_row;
    const detail::SampleDepthUnhiddenKernel sample_depth_unhidden = kernels.sample_depth_unhidden;
    constexpr int kRunSubtiles = 64;
    // Rows reaching fewer subtiles go subtile by subtile (castle C0's occludee tests: 3.04 ms
    // with lanes from 2 subtiles on, 3.08 from 1 or 3; the castle walk the same as without
    // lanes, oa_thor's 16 % faster).
    constexpr int kLaneRun = 2;
    std::uint32_t masks[kRunSubtiles + detail::kMaxSimdLanes], unhidden[kRunSubtiles + detail::kMaxSimdLanes];
    // The rows' intervals a chunk of subtile rows at a time: in SIMD lanes where the instruction
    // set has them (the row loop's kernel, the same intervals), else row by row. They were about
    // a fifth of the castle's occludee tests.
    const detail::RowIntervalsKernel row_intervals = has_area ? kernels.raster.row_intervals : nullptr;
    constexpr int kChunkRows = detail::kChunkSubtileRows * kH;
    std::int32_t chunk_first[kChunkRows + detail::kMaxSimdLanes], chunk_last[kChunkRows + detail::kMaxSimdLanes];
    // Only the rows that can hold a sample in the triangle's columns (the row loop's bound, for
    // the outer edges here). The rows it leaves out hold no sample: their intervals are empty,
    // and they would add nothing to the counts.
    int row_lo = j0, row_hi = j1;
    if (has_area && detail::rows_worth_bounding(i0, i1, j0, j1, sample_width) &&
        !detail::rows_reaching_columns(edges, i0, i1, j0, j1, row_lo, row_hi))
        return;
    for (int ty = row_lo / kH, chunk_ty = ty; ty <= row_hi / kH; ++ty) {
        if (row_intervals && (ty == row_lo / kH || ty - chunk_ty == detail::kChunkSubtileRows)) {
            chunk_ty = ty;
            const int chunk_rows = std::min(detail::kChunkSubtileRows, row_hi / kH - ty + 1) * kH;
            row_intervals(edges, i0, i1, j0, j1, ty * kH, chunk_rows, chunk_first, chunk_last);
        }
        std::int32_t row_first[kH], row_last[kH];
        const std::int32_t *first = row_first, *last = row_last;
        if (row_intervals) first = chunk_first + (ty - chunk_ty) * kH, last = chunk_last + (ty - chunk_ty) * kH;
        else detail::subtile_row_intervals(has_area ? &edges : nullptr, ty, i0, i1, j0, j1, row_first, row_last);
        int tx_begin, tx_end;
        if (!detail::reached_subtile_columns(first, last, i0, i1, tx_begin, tx_end)) continue;
        // With no tolerance, a subtile row whose reached subtiles all lie farther than the
        // layers' far bound there (d0) shows nothing: passed over before its masks are made, its
        // samples not counted, as for a triangle its bounding rectangle hides. The triangle's
        // bound over the row is its plane's at the corner of the row's subtiles where the plane
        // is nearest (OccludeeDepth::over takes each subtile's at the same corner of its covered
        // samples, and float rounding keeps the order), or its nearest vertex's without a plane.
        if (no_tolerance) {
            const int column = depth.plane.has_plane && depth.plane.far_is_left ? tx_end * kW + kW - 1 : tx_begin * kW;
            const int row = depth.plane.has_plane && depth.plane.far_is_top ? ty * kH + kH - 1 : ty * kH;
            const float row_bound = depth.plane_bound(column, row);
            const float* d0 = view.d0 + std::size_t(ty) * view.stride;
            bool behind = true;
            for (int tx = tx_begin; tx <= tx_end && behind; ++tx) behind = d0[tx] > row_bound;
            if (behind) continue;
        }
        // A subtile's samples into the counts: those the per-sample depth leaves unhidden too.
        // True once more than `tolerated` are visible: the triangle shows the occludee.
        const auto count_subtile = [&](int tx, std::uint32_t mask, std::uint32_t unhidden_samples) {
            counts.samples += detail::bit_count(mask);
            if (view.sample_depth && unhidden_samples) {
                if (view.sample_tiles) detail::ensure_depth_subtile(*view.sample_tiles, tx, ty);
                unhidden_samples = sample_depth_unhidden(view, tx, ty, unhidden_samples, depth);
            }
            counts.visible += detail::bit_count(unhidden_samples);
            return counts.visible > tolerated;
        };
        const auto raise_vertices = [&] {  // the raised-vertex bound, once a triangle needs it
            raised_ready = true;
            depth.raised = detail::raised_vertex_plane(tri, slack.x, slack.y, slack.depth, pad_x, pad_y);
        };
        if (!row_kernel || tx_end - tx_begin + 1 < kLaneRun) {
            // Subtile by subtile (the scalar reference, and rows of one subtile: there a
            // vector's set-up costs more than it saves). The same steps as the runs below,
            // written out: one loop over runs for both, the reference through the kernel
            // pointer, made castle C0's occludee tests 2 % slower (3.04 -> 3.10 ms).
            for (int tx = tx_begin; tx <= tx_end; ++tx) {
                const detail::SubtileCoverage c = detail::subtile_coverage(first, last, tx);
                if (c.mask == 0) continue;
                std::uint32_t unhidden_samples = detail::occludee_unhidden(view, tx, ty, c, depth);
                if (unhidden_samples && has_area && !raised_ready) {
                    raise_vertices();
                    unhidden_samples = detail::occludee_unhidden(view, tx, ty, c, depth);
                }
                if (count_subtile(tx, c.mask, unhidden_samples)) return;
            }
            continue;
        }
        // A subtile per SIMD lane, runs of kRunSubtiles (the same masks and answers); a run the
        // layers hide throughout adds its samples at once; in the others, the counts in order,
        // the rest of the run taken again once it needs the raised-vertex bound.
        for (int run_begin = tx_begin; run_begin <= tx_end; run_begin += kRunSubtiles) {
            const int run_end = std::min(run_begin + kRunSubtiles, tx_end + 1);
            const detail::OccludeeRowSummary run = row_kernel(view, ty, first, last, run_begin, run_end - run_begin, depth, masks, unhidden);
            if (!run.any_unhidden) {
                counts.samples += run.samples;
                continue;
            }
            for (int tx = run_begin; tx < run_end; ++tx) {
                const int k = tx - run_begin;
                if (masks[k] == 0) continue;
                if (unhidden[k] && has_area && !raised_ready) {
                    raise_vertices();
                    row_kernel(view, ty, first, last, tx, run_end - tx, depth, masks + k, unhidden + k);
                }
                if (count_subtile(tx, masks[k], unhidden[k])) return;
            }
        }
    }
}

}  // namespace

bool detail::occludee_bounding_rectangle(const std::array<float, 16>& model_to_clip, const glm::dvec4 model[3], const glm::dvec4 clip[3],
                                         double near_w, double edge_margin, int sample_width, int sample_height, RectQuery& rect) {
    if (!detail::finite_clip_triangle(clip)) return false;  // test_triangles answers visible
    const ClipError error = clip_error(model_to_clip, model);
    const double near_clip = near_w * (1.0 - 0x1.0p-20) - error.w;
    if (!(near_clip > 0.0)) return false;  // shows() answers visible
    OuterBounds bounds;
    if (!unclipped_outer_bounds(clip, error, near_clip, edge_margin, sample_width, sample_height, bounds)) return false;
    rect = bounding_rectangle(bounds);
    return true;
}

OcclusionBuffer::TriangleTest detail::BufferState::test_triangles(const TriangleInput& given, std::uint64_t tolerated_samples,
                                                              std::size_t first_triangle, const OcclusionBuffer::ClosedSolid* solid) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    TriangleInput identity;
    const TriangleInput& in = detail::with_clip_space_matrix(given, identity);
    if (solid) check_closed_solid(given, *solid);
    TriangleTest result;
    if (in.triangle_count == 0) return result;
    detail::check_triangle_input(in, "test_triangles");
    check_projection(in.orthographic, "test_triangles");

    const detail::SubtileView view = subtile_view();
    const double near_w = config_.near_w;
    SampleCounts counts;
    bool in_frustum = false;
    auto visible = [&] {
        result.visibility = Visibility::visible;
        result.samples = counts.samples;
        result.visible_samples = counts.visible;
        return result;
    };
    // 2^-22 times each matrix row's magnitudes, for beyond_side_plane_exactly.
    double rows[4] = {0.0, 0.0, 0.0, 0.0};
    for (int row = 0; row < 4; ++row)
        for (int i = 0; i < 4; ++i) rows[row] += 0x1.0p-22 * std::abs(double(in.model_to_clip[std::size_t(4 * i + row)]));
    // An orthographic input's shortcut needs its representatives' ClipError, which the test
    // then uses as well: x - w > ex + ew is beyond whatever their rounding.
    const auto beyond_with = [](const glm::dvec4 clip[3], const ClipError& e) {
        return detail::outside_side_plane(clip, e.x + e.w, e.y + e.w);
    };
    const auto beyond_exactly = [&](const glm::dvec4 model[3], const glm::dvec4 clip[3]) {
        if (in.orthographic) return beyond_with(clip, orthographic_clip_error(in.model_to_clip, model));
        return beyond_side_plane_exactly(model, clip, rows[0], rows[1], rows[3]);
    };
    // One triangle: true when it makes the occludee visible.
    auto shows = [&](const glm::dvec4 model[3], const glm::dvec4 clip[3]) {
        // Outside a side plane first, beyond the transform's rounding: the fate of most triangles
        // tested (castle walk: 88 % of them, the parts of partly seen objects). A perspective
        // input's shortcut costs less than its ClipError, which only the others need.
        ClipError error;
        if (in.orthographic) {
            error = orthographic_clip_error(in.model_to_clip, model);
            if (beyond_with(clip, error)) return false;
        } else {
            if (beyond_side_plane_exactly(model, clip, rows[0], rows[1], rows[3])) return false;
            error = clip_error(in.model_to_clip, model);
        }
        // A closed solid's triangles seen from behind (seen_solid.hpp): its first surface along
        // any ray is a triangle seen from the front.
        if (solid && detail::certainly_faces_away(glm::dvec3(model[0]), glm::dvec3(model[1]), glm::dvec3(model[2]), *solid)) return false;
        // Ground truth sees surfaces from the near plane on: the part before it is clipped
        // away, at a plane moved towards the eye by the rounding bound of w.
        const double near_clip = near_w * (1.0 - 0x1.0p-20) - error.w;
        if (clip[0].w < near_clip && clip[1].w < near_clip && clip[2].w < near_clip) return false;
        in_frustum = true;
        if (!(near_clip > 0.0)) return true;  // coordinates too large to place the near plane
        // A triangle that needs no clipping, tested with no tolerance, goes through its bounding
        // rectangle first: most triangles of hidden occludees are hidden there (castle C3: 93 %),
        // for a fraction of the set-up and the row scan. The triangle is the one
        // setup_clip_triangle makes of it (its projection, no clipping); with a tolerance every
        // sample counts, so the others go through setup.
        OuterBounds bounds;
        if (tolerated_samples == 0 && unclipped_outer_bounds(clip, error, near_clip, config_.edge_margin, sample_width_, sample_height_, bounds)) {
            if (bounds.empty() || test_prepared_rect(bounding_rectangle(bounds)) != Visibility::visible) return false;
            count_triangle(bounds, plane_error(clip, error), view, sample_width_, sample_height_, 0, *kernels_, counts);
            return counts.visible > 0;
        }
        RasterStats stats;
        const detail::SetupResult setup =
            detail::setup_clip_triangle(clip, 0, Backface::none, near_clip, sample_width_, sample_height_, stats, /*occludee=*/true);
        if (stats.too_large) return true;  // not clipped precisely enough to reason with
        const PlaneError depth_error = plane_error(clip, error);
        for (int k = 0; k < setup.count; ++k) {
            count_triangle(outer_bounds(setup.triangles[k], error, config_.edge_margin, sample_width_, sample_height_), depth_error, view,
                           sample_width_, sample_height_, tolerated_samples, *kernels_, counts);
            if (counts.visible > tolerated_samples) return true;
        }
        return false;
    };
    // The first triangle alone: a visible occludee is mostly decided by it (last frame's
    // deciding one). Then 16 at a time through the render's SIMD fetch and transform: the
    // triangles of a partly seen object are mostly outside, and their transform was most of
    // what they cost; a last remainder of fewer than 8 one at a time, where a batch's fixed
    // cost is more than theirs. (The first 16 one at a time cost the castle views' triangle
    // tests about 6 % more.) Same order, same answers and counts.
    constexpr std::size_t kBatch = detail::TriangleBatch::kSize;
    constexpr std::size_t kSingleFirst = 1, kSingleRemainder = kBatch / 2;
    const detail::FrontEndKernels& kernels = kernels_->raster.front_end;
    detail::TriangleBatch batch;  // gather_triangle_batch fills every lane
    const bool rectangles_first = tolerated_samples == 0 && !in.orthographic && kernels_->occludee_rectangles;
    const detail::OccludeeRectangleParams rectangle_params{in.model_to_clip.data(), near_w, config_.edge_margin, sample_width_, sample_height_};
    detail::RectQuery rectangles[kBatch];
    std::size_t t = first_triangle < in.triangle_count ? first_triangle : 0;
    for (std::size_t n = 0; n < in.triangle_count;) {
        if (n < kSingleFirst || in.triangle_count - n < kSingleRemainder) {
            result.deciding_triangle = t;
            glm::dvec4 model[3], clip[3];
            if (!detail::fetch_clip_triangle(in, t, model, clip, /*plain=*/true)) return visible();  // nothing to reason with: never cull
            if (shows(model, clip)) return visible();
            ++n;
            t = t + 1 == in.triangle_count ? 0 : t + 1;
            continue;
        }
        const std::size_t count = std::min({kBatch, in.triangle_count - t, in.triangle_count - n});  // up to the wrap
        detail::gather_triangle_batch(in, t, int(count), batch);
        kernels.transform_batch_plain(in, batch);
        // Lanes beyond a side plane (valid and finite) cannot show the occludee: shows() would
        // pass over them first thing. Decided for the whole batch in SIMD lanes: most lanes on
        // a walk (the castle's: 88 %). The others are taken in order, as before. For a
        // perspective input the kernel applies beyond_side_plane_exactly's margins itself, so
        // the lanes it passes over need nothing more; an orthographic input's are confirmed
        // beyond its rounding (beyond_exactly), else taken in order with the others.
        const std::uint32_t passed_over = in.orthographic ? kernels.beyond_side_plane(batch, int(count), 0.0, 0.0)
                                                          : kernels.beyond_side_plane(batch, int(count), rows[0] + rows[3], rows[1] + rows[3]);
        // The other lanes' bounding rectangles, where shows() would test one first (no
        // tolerance, perspective, no clipping): each at least as large and as near as shows()'s,
        // so one found hidden here would be found hidden there, and the lane is passed over as
        // shows() would pass it over.
        const std::uint32_t all_lanes = (std::uint32_t(1) << count) - 1u;  // count <= 16
        const std::uint32_t rectangle_ready = rectangles_first && (passed_over & all_lanes) != all_lanes
                                                  ? kernels_->occludee_rectangles(batch, int(count), rectangle_params, rectangles) & ~passed_over
                                                  : 0u;
        for (std::size_t k = 0; k < count; ++k) {
            if (!in.orthographic && ((passed_over >> k) & 1u)) continue;
            glm::dvec4 model[3], clip[3];
            for (int v = 0; v < 3; ++v) {
                model[v] = {batch.px[v][k], batch.py[v][k], batch.pz[v][k], batch.pw[v][k]};
                clip[v] = batch.clip(int(k), v);
            }
            if (((passed_over >> k) & 1u) && beyond_exactly(model, clip)) continue;
            // Invalid indices or a non-finite vertex: nothing to reason with, whatever the
            // rectangles say (a lane is passed over on its rectangle only once it is known finite).
            result.deciding_triangle = t + k;
            if (!((batch.indices_valid >> k) & 1u)) return visible();  // as fetch_clip_triangle
            if (!detail::finite_clip_triangle(clip)) return visible();
            if (((rectangle_ready >> k) & 1u) && (rectangles[k].i0 > rectangles[k].i1 || rectangles[k].j0 > rectangles[k].j1 ||
                                                   test_prepared_rect(rectangles[k]) != Visibility::visible)) {
                // shows()'s steps before its rectangle decide whether the triangle reaches the
                // frustum: beyond a side plane, or a closed solid's triangle seen from behind, it
                // does not; otherwise it does (in front of the near plane: the kernel's condition).
                if (!beyond_side_plane_exactly(model, clip, rows[0], rows[1], rows[3]) &&
                    !(solid && detail::certainly_faces_away(glm::dvec3(model[0]), glm::dvec3(model[1]), glm::dvec3(model[2]), *solid)))
                    in_frustum = true;
                continue;
            }
            if (shows(model, clip)) return visible();
        }
        result.deciding_triangle = t + count - 1;  // the batch's last triangle, passed over or not
        n += count;
        t = t + count == in.triangle_count ? 0 : t + count;
    }
    result.visibility = in_frustum ? Visibility::occluded : Visibility::view_culled;
    result.samples = counts.samples;
    result.visible_samples = counts.visible;
    return result;
}

}  // namespace homcull
