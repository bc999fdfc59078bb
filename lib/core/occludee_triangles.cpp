// Occludee triangles tested sample by sample against the buffer (OcclusionBuffer::
// test_triangles): the occludee's own shape instead of a box or rectangles around it, as masked
// occlusion culling's TestTriangles (Hasselgren, Andersson, Akenine-Moller, HPG 2016), made
// conservative for an exact ray cast at the sample centres:
// - coverage is outer: every sample the triangle may cover once the rounding of its float
//   input is accounted for (the Minkowski sum of the triangle with a box of that size is inside
//   the three edge half-planes pushed out by the box's support, |a| dx + |b| dy);
// - depth is the triangle's nearest over the covered samples of a subtile: its plane at the
//   nearest corner of their bounding rectangle, raised by the plane's float error and by how
//   much the rounding of the vertices can tilt the plane, never above its nearest vertex.
// The row intervals and subtile masks are the rasterizer's (one formula, see rasterize.cpp).
#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "core/rect_tests.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_setup.hpp"

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

using detail::OrientedTriangle;
using detail::PreparedTriangle;
using detail::TriangleEdges;
constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// How far, in samples, a projected vertex may lie from where an exact computation with the
// same scene puts it, and how far its w may be off, relatively. The matrix and the positions
// are floats (ground truth rounds its world positions to float as well): each entry and each
// coordinate carries a relative rounding of 2^-24, so clip coordinate r is off by at most
// 2^-24 (1 + 2^-24) sum_i |m_ri p_i| ~ 2^-23 of that sum; 2^-22 leaves a factor 2 for the
// ray's own rounding and second-order terms. NDC x = x / w is then off by (ex + |x / w| ew) / w.
struct VertexSlack {
    double x = 0.0, y = 0.0, w_relative = 0.0;
};

VertexSlack vertex_slack(const std::array<float, 16>& m, const glm::dvec4 model[3], const glm::dvec4 clip[3], int sample_width,
                         int sample_height) {
    VertexSlack s;
    for (int k = 0; k < 3; ++k) {
        double magnitude[4] = {0.0, 0.0, 0.0, 0.0};
        for (int row = 0; row < 4; ++row)
            for (int i = 0; i < 4; ++i) magnitude[row] += std::abs(double(m[std::size_t(4 * i + row)]) * model[k][i]);
        const double w = clip[k].w;  // >= near_w > 0 here
        const double ex = 0x1.0p-22 * magnitude[0], ey = 0x1.0p-22 * magnitude[1], ew = 0x1.0p-22 * magnitude[3];
        s.x = std::max(s.x, (ex + std::abs(clip[k].x / w) * ew) / w * 0.5 * sample_width);
        s.y = std::max(s.y, (ey + std::abs(clip[k].y / w) * ew) / w * 0.5 * sample_height);
        s.w_relative = std::max(s.w_relative, ew / w);
    }
    return s;
}

// The triangle's nearest depth bound over the samples of one subtile row, per subtile.
struct OccludeeDepth {
    PreparedTriangle plane;  // usable when plane.has_plane
    float error;             // plane.error plus the tilt bound, rounded up
    float z_vertex_max;      // the nearest vertex, rounded up
    float raise;             // final relative raise, rounded up: 1 + 2^-20 + the w rounding

    float at(int column, int row) const {
        float bound = z_vertex_max;
        if (plane.has_plane) {
            const float x = float(column) + 0.5f, y = float(row) + 0.5f;
            bound = std::min(bound, ((plane.a + plane.dzdy * y) + plane.dzdx * x) + error);
        }
        return bound * raise;
    }
};

// How much moving each vertex by up to (dx, dy) samples can change the plane at a point of
// the padded bounding box (W x H samples): barycentric l_k = E_k / A, where the edge function
// E_k changes by at most B = 2 dx (H + dy) + 2 dy W and the doubled area A by at most 3 B, and
// |E_k| <= e_max; so l_k changes by at most (B A + 3 B e_max) / (A (A - 3 B)), and the
// plane, sum l_k d_k with sum l_k = 1, by 3 times that times the depth range. Infinite when
// A <= 6 B (the plane could tilt arbitrarily: only the nearest vertex bounds it).
double plane_tilt_bound(const OrientedTriangle& tri, const TriangleEdges& e, double dx, double dy, double width, double height) {
    const double b = 2.0 * dx * (height + dy) + 2.0 * dy * width;
    const double area = tri.area2;
    if (!(area > 6.0 * b)) return HUGE_VAL;
    double e_max = 0.0;
    for (int k = 0; k < 3; ++k) e_max = std::max(e_max, std::abs(e.sa[k]) * width + std::abs(e.sb[k]) * height);
    const double lambda = (b * area + 3.0 * b * e_max) / (area * (area - 3.0 * b));
    const double range = std::max({tri.d[0], tri.d[1], tri.d[2]}) - std::min({tri.d[0], tri.d[1], tri.d[2]});
    return 3.0 * lambda * range;
}

struct SampleCounts {
    std::uint64_t samples = 0, visible = 0;
};

// Counts one screen triangle's outer-covered samples and those not certainly hidden; stops
// once more than `tolerated` are visible.
void count_triangle(const detail::ScreenTriangle& screen, const VertexSlack& slack, double margin, const detail::SubtileView& view,
                    int sample_width, int sample_height, std::uint64_t tolerated, SampleCounts& counts) {
    OrientedTriangle tri;
    const bool has_area = detail::orient_triangle(screen, tri);
    const double pad_x = slack.x + margin, pad_y = slack.y + margin;
    const glm::dvec2* v = tri.v;
    const double min_x = std::min({v[0].x, v[1].x, v[2].x}) - pad_x, max_x = std::max({v[0].x, v[1].x, v[2].x}) + pad_x;
    const double min_y = std::min({v[0].y, v[1].y, v[2].y}) - pad_y, max_y = std::max({v[0].y, v[1].y, v[2].y}) + pad_y;
    int i0, i1, j0, j1;
    detail::sample_span(min_x, max_x, sample_width, i0, i1);
    detail::sample_span(min_y, max_y, sample_height, j0, j1);
    if (i0 > i1 || j0 > j1) return;

    OccludeeDepth depth;
    depth.z_vertex_max = detail::float_up(std::max({tri.d[0], tri.d[1], tri.d[2]}));
    depth.raise = detail::float_up(1.0 + 0x1.0p-20 + slack.w_relative);
    TriangleEdges edges{};
    if (has_area) {
        edges = detail::edge_functions(tri);
        for (int k = 0; k < 3; ++k) {  // outer: pushed out by the support of the pad box
            edges.shared[k] = false;
            edges.threshold[k] = -(std::abs(edges.sa[k]) * pad_x + std::abs(edges.sb[k]) * pad_y);
        }
        depth.plane = detail::prepare_depth_plane(tri.v, tri.d, tri.area2, sample_width, sample_height);
        const double tilt = plane_tilt_bound(tri, edges, pad_x, pad_y, max_x - min_x, max_y - min_y);
        depth.error = detail::float_up(double(depth.plane.error) + tilt);
        if (!std::isfinite(depth.error)) depth.plane.has_plane = false;
    } else {
        depth.plane.has_plane = false;  // zero area after projection: its padded bounding box, at its nearest vertex
    }
    const bool far_is_left = depth.plane.has_plane && depth.plane.far_is_left;
    const bool far_is_top = depth.plane.has_plane && depth.plane.far_is_top;

    for (int ty = j0 / kH; ty <= j1 / kH; ++ty) {
        std::int32_t first[kH], last[kH];
        for (int j = 0; j < kH; ++j) {
            const int row = ty * kH + j;
            if (row < j0 || row > j1) {
                first[j] = i0;
                last[j] = i0 - 1;
            } else if (has_area) {
                detail::sample_row_interval(edges, row, i0, i1, first[j], last[j]);
            } else {
                first[j] = i0;
                last[j] = i1;
            }
        }
        int tx_begin, tx_end;
        if (!detail::reached_subtile_columns(first, last, i0, i1, tx_begin, tx_end)) continue;
        for (int tx = tx_begin; tx <= tx_end; ++tx) {
            const detail::SubtileCoverage c = detail::subtile_coverage(first, last, tx);
            if (c.mask == 0) continue;
            // The plane is largest (nearest) away from its far side.
            const float d_near = depth.at(tx * kW + (far_is_left ? c.column_hi : c.column_lo), ty * kH + (far_is_top ? c.row_hi : c.row_lo));
            counts.samples += detail::bit_count(c.mask);
            counts.visible += std::uint64_t(detail::subtile_visible_samples(view, tx, ty, c.mask, d_near));
            if (counts.visible > tolerated) return;
        }
    }
}

}  // namespace

OcclusionBuffer::TriangleTest OcclusionBuffer::test_triangles(const TriangleInput& in, std::uint64_t tolerated_samples) const {
    TriangleTest result;
    if (in.triangle_count == 0) return result;
    if (in.position_components != 3 && in.position_components != 4) throw Error("test_triangles: positions must have 3 or 4 components");
    if (!in.positions || in.position_stride < sizeof(float) * std::size_t(in.position_components))
        throw Error("test_triangles: positions missing, or stride smaller than one position");
    if (!in.indices && in.vertex_count / 3 < in.triangle_count)
        throw Error("test_triangles: without indices, vertex_count must be at least 3 * triangle_count");

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
    for (std::size_t t = 0; t < in.triangle_count; ++t) {
        glm::dvec4 model[3], clip[3];
        if (!detail::fetch_clip_triangle(in, t, model, clip)) return visible();  // nothing to reason with: never cull
        if ((clip[0].w <= 0.0 && clip[1].w <= 0.0 && clip[2].w <= 0.0) || detail::outside_side_plane(clip)) continue;
        in_frustum = true;
        if (clip[0].w < near_w || clip[1].w < near_w || clip[2].w < near_w) return visible();  // reaches before the near plane
        const VertexSlack slack = vertex_slack(in.model_to_clip, model, clip, sample_width_, sample_height_);
        RasterStats stats;
        const detail::SetupResult setup =
            detail::setup_clip_triangle(clip, 0, Backface::none, near_w, sample_width_, sample_height_, stats);
        if (stats.too_large) return visible();  // not clipped precisely enough to reason with
        for (int k = 0; k < setup.count; ++k) {
            count_triangle(setup.triangles[k], slack, config_.edge_margin, view, sample_width_, sample_height_, tolerated_samples, counts);
            if (counts.visible > tolerated_samples) return visible();
        }
    }
    result.visibility = in_frustum ? Visibility::occluded : Visibility::view_culled;
    result.samples = counts.samples;
    result.visible_samples = counts.visible;
    return result;
}

}  // namespace homcull
