#pragma once
// Which of a triangle's shared edges may go without the coverage margin in this view
// (TriangleInput::shared_edges, docs/occlusion-buffer.md "Why it never hides what is visible").
//
// A margin-free edge keeps the samples on its computed boundary, which lies within a rounding
// distance delta of the exact edge. Such a sample outside the exact triangle is backed only if
// the neighbour across the edge covers it. Three things can fail:
// - the neighbour lies on the same side (a view silhouette of a closed mesh: it faces the other
//   way), or is degenerate: neighbour_across_edge;
// - near an end of the edge, the neighbour (or the triangle) is too thin there: a point within
//   delta of the edge's line, outside both, lies within delta / sin(angle) of that end. If the
//   triangle's other edge at that end keeps its margin m, no sample the triangle claims is that
//   close to the end, provided every angle there has sin > 4 delta / m;
// - at a corner where both of the triangle's edges are margin-free, such points lie within
//   3 delta / sin(smallest angle there) of the corner, and the fan of triangles around it may
//   not cover them (the corner is on the mesh's outline): no sample centre may lie that close.
// Where a check fails the edge (or both edges at the corner) keeps its margin: always safe. A
// corner clipped away (behind the near plane or beyond the guard band) needs no check: the clip
// edge there keeps its margin, and the neighbour is cut by the same straight line.
//
// delta = 2^-36 (sample_width + sample_height) samples bounds the rounding of a margin-free
// boundary against the exact edge with room to spare: the projected vertices and the row
// formula err by a few 2^-52 of sample coordinates below 17 (sample_width + sample_height)
// (the guard band), and the clip coordinates by 2^-38.7 sample_width within the transform's
// guaranteed range (rule 4 there).
#include "raster/triangle_setup.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace homcull::detail {

// Whether |det| exceeds 2^-40 of the sum of its six terms' magnitudes: its double evaluation
// errs by less than 2^-50 of that sum, and the clip coordinates' own error adds 3 2^-52, so the
// sign is the exact geometry's.
inline bool certain_sign(double det, double magnitude) { return std::abs(det) > 0x1.0p-40 * magnitude; }
template <typename V>
inline double homogeneous_det_magnitude(const V& a, const V& b, const V& c) {
    return std::abs(a.x * b.y * c.w) + std::abs(a.x * b.w * c.y) + std::abs(a.y * b.x * c.w) + std::abs(a.y * b.w * c.x) +
           std::abs(a.w * b.x * c.y) + std::abs(a.w * b.y * c.x);
}

// Whether the neighbour across edge k of a triangle (own, in clip space, as given, whose
// homogeneous determinant own_det has a certain sign) certainly lies on the other side of that
// edge in this view. The neighbour runs from own[k + 1] to own[k] to `apex`: it lies across the
// edge when it has the triangle's orientation (its determinant the triangle's sign: both face the
// eye, or both face away), its sign certain too. Clipping keeps the answer: clipped polygons are
// positive combinations of the vertices.
inline bool neighbour_across_edge(const glm::dvec4 own[3], double own_det, int k, const glm::dvec4& apex) {
    const glm::dvec4 &a = own[k], &b = own[(k + 1) % 3];
    const double det = homogeneous_det(b, a, apex);
    return (own_det > 0.0) == (det > 0.0) && certain_sign(det, homogeneous_det_magnitude(b, a, apex));
}

// The direction in which the projected segment from v towards p leaves v, in sample units (up
// to a positive factor; y flipped, which no sine below minds). Right for any w of p: only v
// must lie in front of the eye.
inline glm::dvec2 screen_direction(const glm::dvec4& v, const glm::dvec4& p, int sample_width, int sample_height) {
    return {(p.x * v.w - v.x * p.w) * sample_width, (p.y * v.w - v.y * p.w) * sample_height};
}
// Of the triangle's shared-edge bits `flags` (bit k: the edge own[k] -> own[k + 1]), those that
// may go without their margin in this view; apex[k] is the third vertex of the neighbour across
// edge k (read where its bit is set in apex_valid: none elsewhere). edge_margin as the buffer's.
inline std::uint8_t margin_free_edges(const glm::dvec4 own[3], const glm::dvec4 apex[3], std::uint8_t apex_valid, std::uint8_t flags,
                                      double near_w, double edge_margin, int sample_width, int sample_height) {
    flags &= apex_valid;
    if (flags == 0) return 0;
    const double own_det = homogeneous_det(own[0], own[1], own[2]);
    if (!certain_sign(own_det, homogeneous_det_magnitude(own[0], own[1], own[2]))) return 0;
    std::uint8_t kept = 0;
    for (int k = 0; k < 3; ++k)
        if ((flags >> k) & 1u && neighbour_across_edge(own, own_det, k, apex[k])) kept |= std::uint8_t(1u << k);
    if (kept == 0) return 0;
    const double delta = 0x1.0p-36 * double(sample_width + sample_height);
    const double thin_end = 4.0 * delta / edge_margin;  // sines at an end whose other edge keeps its margin
    // The edges' screen directions, each once: from its end k + 1 back to k it is the opposite
    // (screen_direction(b, a) is exactly -screen_direction(a, b)).
    glm::dvec2 edge[3];
    double edge_length2[3];
    for (int k = 0; k < 3; ++k) {
        edge[k] = screen_direction(own[k], own[(k + 1) % 3], sample_width, sample_height);
        edge_length2[k] = glm::dot(edge[k], edge[k]);
    }
    // Each corner k (between edge k - 1, coming in, and edge k, going out), until nothing changes:
    // dropping an edge at one corner can leave the next corner with one margin-free edge.
    for (bool changed = true; changed;) {
        changed = false;
        for (int k = 0; k < 3; ++k) {
            const int out = k, in = (k + 2) % 3;
            const bool keeps_out = (kept >> out) & 1u, keeps_in = (kept >> in) & 1u;
            if (!keeps_out && !keeps_in) continue;
            const glm::dvec4& v = own[k];
            if (!(v.w >= near_w) || !(std::abs(v.x) <= kGuardBand * v.w) || !(std::abs(v.y) <= kGuardBand * v.w)) continue;  // clipped away
            // bound2: what every squared sine at the corner must exceed. One margin-free edge:
            // (4 delta / m)^2. Two: the corner must be clear of sample centres by 3 delta / sine,
            // so sine^2 > (3 delta / clearance)^2, with clearance the distance from the nearest
            // centre on the farther axis.
            double bound2 = thin_end * thin_end;
            if (keeps_out && keeps_in) {
                const double inv_w = 1.0 / v.w;
                const double x = (v.x * inv_w + 1.0) * 0.5 * sample_width, y = (1.0 - v.y * inv_w) * 0.5 * sample_height;
                const double clearance = std::max(std::abs(x - (std::floor(x) + 0.5)), std::abs(y - (std::floor(y) + 0.5)));
                bound2 = 9.0 * delta * delta / (clearance * clearance);  // inf (or NaN) when on a centre: dropped
            }
            // Squared sines as cross^2 against bound2 |a|^2 |b|^2 (no division): the triangle's
            // angle between edge k and edge k - 1, and each neighbour's between its edge and the
            // direction to its apex.
            const auto above = [&](const glm::dvec2& a, double a_length2, const glm::dvec2& b) {
                const double cross = a.x * b.y - a.y * b.x;
                return cross * cross > bound2 * (a_length2 * glm::dot(b, b));
            };
            bool keep = above(edge[out], edge_length2[out], edge[in]);
            if (keep && keeps_out) keep = above(edge[out], edge_length2[out], screen_direction(v, apex[out], sample_width, sample_height));
            if (keep && keeps_in) keep = above(edge[in], edge_length2[in], screen_direction(v, apex[in], sample_width, sample_height));
            if (!keep) {
                kept &= std::uint8_t(~((1u << out) | (1u << in)));
                changed = true;
            }
        }
    }
    return kept;
}

// margin_free_edges for up to kMarginFreeLanes triangles at once, in structure-of-arrays form:
// lane t's own vertices (clip x, y, w), the apexes of its edges, and its flags already
// restricted to the edges with an apex (flags & apex_valid; 0: the lane is not asked, and gets
// 0). The SIMD kernel (shared_edge_rule_simd.cpp) does in each lane exactly the operations of
// margin_free_edges, in its order: the same bits on every instruction set.
constexpr int kMarginFreeLanes = 16;
struct MarginFreeLanes {
    alignas(64) double ox[3][kMarginFreeLanes], oy[3][kMarginFreeLanes], ow[3][kMarginFreeLanes];  // own vertex k
    alignas(64) double ax[3][kMarginFreeLanes], ay[3][kMarginFreeLanes], aw[3][kMarginFreeLanes];  // apex across edge k
    std::uint8_t flags[kMarginFreeLanes];
    int count;  // lanes [0, count) are read; whole vectors past it may be too (their flags must be 0)
};
using MarginFreeKernel = void (*)(const MarginFreeLanes& lanes, double near_w, double edge_margin, int sample_width, int sample_height,
                                  std::uint8_t* kept);

}  // namespace homcull::detail
