#include "raster/triangle_setup.hpp"

#include "raster/clip_polygon.hpp"
#include "raster/shared_edge_rule.hpp"

#include <homcull/error.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace homcull::detail {

void check_triangle_input(const TriangleInput& in, const char* caller) {
    // The message is built only when it is thrown: test_triangles checks every occludee of a frame.
    const auto fail = [caller](const char* why) { throw Error(std::string(caller) + ": " + why); };
    if (in.position_components != 3 && in.position_components != 4) fail("positions must have 3 or 4 components");
    if (!in.positions || in.position_stride < sizeof(float) * std::size_t(in.position_components))
        fail("positions missing, or stride smaller than one position");
    if (!in.indices && in.vertex_count / 3 < in.triangle_count)  // (no overflow for any count)
        fail("without indices, vertex_count must be at least 3 * triangle_count");
    if (!in.indices && in.triangle_count > std::size_t(std::numeric_limits<std::uint32_t>::max()) / 3)
        fail("without indices, at most 2^32 / 3 triangles per call (vertex numbers are 32-bit, as indices)");
    if (in.clip_space && (in.position_components != 4 || in.position_stride != 4 * sizeof(float) || in.indices || in.shared_edges || in.orthographic))
        fail("a clip_space input is 4 packed floats a vertex (position_components 4, position_stride 16), without indices, "
             "shared-edge flags or an orthographic projection");
}

const TriangleInput& with_clip_space_matrix(const TriangleInput& in, TriangleInput& storage) {
    if (!in.clip_space) return in;
    storage = in;
    storage.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    return storage;
}

bool fetch_clip_triangle(const TriangleInput& in, std::size_t t, glm::dvec4 model[3], glm::dvec4 clip[3], bool plain) {
    std::uint32_t index[3];
    for (int k = 0; k < 3; ++k) index[k] = vertex_index(in, t, k);
    if (index[0] >= in.vertex_count || index[1] >= in.vertex_count || index[2] >= in.vertex_count) return false;
    bool valid = true;
    for (int k = 0; k < 3; ++k) {
        float p[4];
        read_position(in, index[k], p);
        model[k] = {p[0], p[1], p[2], p[3]};
        clip[k] = plain ? input_to_clip_plain(in, p[0], p[1], p[2], p[3]) : input_to_clip(in, p[0], p[1], p[2], p[3]);
        valid = valid && finite_clip(clip[k]);
    }
    return valid;
}

bool outside_side_plane(const glm::dvec4 clip[3]) {
    auto all = [&](auto outside) { return outside(clip[0]) && outside(clip[1]) && outside(clip[2]); };
    return all([](const glm::dvec4& c) { return c.x > c.w; }) || all([](const glm::dvec4& c) { return c.x < -c.w; }) ||
           all([](const glm::dvec4& c) { return c.y > c.w; }) || all([](const glm::dvec4& c) { return c.y < -c.w; });
}

bool outside_side_plane(const glm::dvec4 clip[3], double margin_x, double margin_y) {
    auto all = [&](auto beyond) { return beyond(clip[0]) && beyond(clip[1]) && beyond(clip[2]); };
    return all([&](const glm::dvec4& c) { return c.x - c.w > margin_x; }) || all([&](const glm::dvec4& c) { return -c.x - c.w > margin_x; }) ||
           all([&](const glm::dvec4& c) { return c.y - c.w > margin_y; }) || all([&](const glm::dvec4& c) { return -c.y - c.w > margin_y; });
}

bool outside_frustum(const glm::dvec4 clip[3], double near_w) {
    return (clip[0].w < near_w && clip[1].w < near_w && clip[2].w < near_w) || outside_side_plane(clip);
}

bool too_large_to_clip(const glm::dvec4 clip[3], double near_w) {
    double extent = 0.0, min_w = HUGE_VAL;
    for (int k = 0; k < 3; ++k) {
        const glm::dvec4& c = clip[k];
        extent = std::max({extent, std::abs(c.x), std::abs(c.y), std::abs(c.w)});
        min_w = std::min(min_w, c.w);
    }
    return extent > 0x1.0p28 * std::max(near_w, min_w);
}

bool needs_clipping(const glm::dvec4 clip[3], double near_w) {
    bool needs_clip = false;
    for (int k = 0; k < 3; ++k)
        needs_clip = needs_clip || clip[k].w < near_w || std::abs(clip[k].x) > kGuardBand * clip[k].w ||
                     std::abs(clip[k].y) > kGuardBand * clip[k].w;
    return needs_clip;
}

TriangleFate unclipped_fate(const glm::dvec4 clip[3], Backface backface, double near_w) {
    if (outside_frustum(clip, near_w)) return TriangleFate::outside;
    if (too_large_to_clip(clip, near_w) || needs_clipping(clip, near_w)) return TriangleFate::needs_setup;
    const double det = 0.0 + homogeneous_det(clip[0], clip[1], clip[2]);  // as setup_clip_triangle sums it
    if (det == 0.0) return TriangleFate::degenerate;
    return facing_away(det, backface) ? TriangleFate::backfacing : TriangleFate::needs_setup;
}

SetupResult setup_clip_triangle(const glm::dvec4 clip[3], std::uint8_t shared_bits, Backface backface, double near_w, int sample_width,
                                int sample_height, RasterStats& stats, bool occludee, SetupEdgeRule rule) {
    SetupResult result;
    // Entirely outside one plane of the view frustum (or behind the near plane)?
    if (occludee ? clip[0].w < near_w && clip[1].w < near_w && clip[2].w < near_w : outside_frustum(clip, near_w)) {
        ++stats.outside;
        return result;
    }
    if (too_large_to_clip(clip, near_w)) {
        ++stats.too_large;
        return result;
    }
    const bool needs_clip = needs_clipping(clip, near_w);
    const ClipVertex corners[3] = {{clip[0].x, clip[0].y, clip[0].w}, {clip[1].x, clip[1].y, clip[1].w},
                                   {clip[2].x, clip[2].y, clip[2].w}};
    ClipPolygon poly;
    if (needs_clip) {
        poly = clip_triangle(corners, shared_bits, near_w, kGuardBand);
    } else {
        for (int k = 0; k < 3; ++k) {
            poly.v[k] = corners[k];
            poly.shared[k] = (shared_bits >> k) & 1u;
        }
        poly.count = 3;
    }
    stats.near_clipped += needs_clip;
    if (poly.count == 0) {
        ++stats.outside;
        return result;
    }

    // Orientation and degeneracy from homogeneous determinants det[x y w] (w > 0 after
    // clipping): positive for counter-clockwise in NDC, and exactly zero for collinear
    // input, before any division rounds it. Summed over the polygon's fan, because clipping
    // may leave three consecutive vertices on one line.
    double det = 0.0;
    for (int k = 1; k + 1 < poly.count; ++k) det += homogeneous_det(poly.v[0], poly.v[k], poly.v[k + 1]);
    if (det == 0.0 && !occludee) {
        ++stats.degenerate;
        return result;
    }
    if (det != 0.0 && facing_away(det, backface)) {
        ++stats.backface_culled;
        return result;
    }
    // Project to sample space (y down) with depth 1/w.
    glm::dvec2 screen[ClipPolygon::kMax];
    double depth[ClipPolygon::kMax];
    for (int k = 0; k < poly.count; ++k) project_to_samples(poly.v[k].x, poly.v[k].y, poly.v[k].z, sample_width, sample_height, screen[k], depth[k]);
    // Fan triangles (0, k, k + 1): their diagonals are shared with each other. A clipped
    // polygon's fan keeps its margin-free edges only as margin_free_edges allows (an unclipped
    // triangle's flags were decided so already, edges_across).
    const auto vertex = [&](int i) { return glm::dvec4(poly.v[i].x, poly.v[i].y, 0.0, poly.v[i].z); };
    for (int k = 1; k + 1 < poly.count; ++k) {
        const bool first = k == 1, last = k + 2 == poly.count;
        std::uint8_t bits = std::uint8_t((first ? poly.shared[0] : 1u) | (poly.shared[k] << 1) |
                                         ((last ? poly.shared[k + 1] : 1u) << 2));
        if (needs_clip && bits != 0) {
            const glm::dvec4 own[3] = {vertex(0), vertex(k), vertex(k + 1)};
            // Across each edge: the next fan triangle's far vertex, or the triangle's neighbour's apex.
            const int polygon_edge[3] = {first ? 0 : -1, k, last ? k + 1 : -1};
            const int across_diagonal[3] = {k - 1, -1, k + 2};
            glm::dvec4 apex[3];
            std::uint8_t apex_valid = 0;
            for (int e = 0; e < 3; ++e) {
                if (polygon_edge[e] < 0) {
                    apex[e] = vertex(across_diagonal[e]);
                    apex_valid |= std::uint8_t(1u << e);
                } else if (rule.apexes && poly.shared[polygon_edge[e]] && poly.source[polygon_edge[e]] != ClipPolygon::kClipEdge) {
                    apex[e] = rule.apexes[poly.source[polygon_edge[e]]];
                    apex_valid |= std::uint8_t(1u << e);
                }
            }
            bits = margin_free_edges(own, apex, apex_valid, bits, near_w, rule.edge_margin, sample_width, sample_height);
        }
        result.triangles[result.count++] = {{screen[0], screen[k], screen[k + 1]}, {depth[0], depth[k], depth[k + 1]}, bits};
    }
    if (result.count > 0) ++stats.rasterized;
    return result;
}

}  // namespace homcull::detail
