#pragma once
// Triangle setup: index and vertex fetch, model-to-clip transform (double), trivial
// rejection, near-plane and guard-band clipping, backface culling, projection to sample space.
#include "raster/rasterize.hpp"

#include <homcull/parallel_for.hpp>
#include <homcull/triangle_input.hpp>

#include <cmath>
#include <limits>
#include <cstdint>
#include <cstring>

namespace homcull::detail {

// The rounding error of s = a + b in double: a + b = s + two_sum_error(a, b, s) exactly
// (Knuth's TwoSum, six additions, no branch; needs round-to-nearest and no fused or
// reassociated arithmetic, which -ffp-contract=off and the absence of -ffast-math give).
inline double two_sum_error(double a, double b, double s) {
    const double b_virtual = s - a;
    return (a - (s - b_virtual)) + (b - b_virtual);
}

// p0 + p1 + p2 + p3 as if computed in twice the precision, then rounded (Ogita, Rump and
// Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26(6), 2005, Algorithm 4.4,
// Sum2): the error is at most 2^-53 |sum| + (3 * 2^-53)^2 (|p0| + |p1| + |p2| + |p3|). A plain
// sum errs by up to 3 * 2^-53 (|p0| + ... + |p3|), which is no bound at all where the terms
// cancel: model coordinates near 2^42 that the matrix translates back next to the eye lose
// 2^-11 of a clip unit, far more than the coverage margin absorbs.
inline double accurate_sum4(double p0, double p1, double p2, double p3) {
    const double s1 = p0 + p1;
    double error = two_sum_error(p0, p1, s1);
    const double s2 = s1 + p2;
    error += two_sum_error(s1, p2, s2);
    const double s3 = s2 + p3;
    error += two_sum_error(s2, p3, s3);
    return s3 + error;
}

// Model to clip space in double, column-major m[column * 4 + row], one fixed order of
// operations (the rasterizer and the occludee tests must agree to the bit). The products of a
// float matrix entry and a float coordinate are exact in double; their sum is accurate_sum4's,
// so each clip coordinate is within about 2^-52 of its exact value relative to itself, however
// large the model coordinates the matrix brings back near the eye (up to 2^50 times the clip
// coordinate, where the second term of accurate_sum4's bound reaches 2^-52 of it).
inline glm::dvec4 transform_to_clip(const std::array<float, 16>& m, double x, double y, double z, double w) {
    glm::dvec4 r;
    for (int row = 0; row < 4; ++row)
        r[row] = accurate_sum4(double(m[row]) * x, double(m[4 + row]) * y, double(m[8 + row]) * z, double(m[12 + row]) * w);
    return r;
}

// The plain sum of the same products, ((m x + m y) + m z) + m w: off by up to 3 * 2^-53 of
// the terms' magnitudes. For the occludee tests, which pad every vertex by 2^-22 of that
// magnitude anyway (clip_error in buffer/occludee_triangles.cpp) and so need no more; their
// transform is most of what they cost (castle C0's occludee tests: about 15 % slower with Sum2).
inline glm::dvec4 transform_to_clip_plain(const std::array<float, 16>& m, double x, double y, double z, double w) {
    glm::dvec4 r;
    for (int row = 0; row < 4; ++row)
        r[row] = double(m[row]) * x + double(m[4 + row]) * y + double(m[8 + row]) * z + double(m[12 + row]) * w;
    return r;
}

// The representative an orthographic buffer takes of a clip point (BufferConfig::orthographic):
// (x, y, z, w) / h with h = (3w - z) / 2, the same point on the screen (x/w, y/w) with
// 1/w' = h / w = (3 - z/w) / 2, the depth g that is affine on the screen as 1/w is for a
// perspective view. For points with h > 0 the homogeneous segment between two representatives
// is the image of the segment between the points, with 1/w' along it the depth g there, so
// clipping at w' >= 0.5 (z/w >= -1, the near plane) and the rest of the setup hold unchanged.
// Points with w <= 0 or g < 2^-8 (beyond twice the far distance) get NaN, which makes their
// triangles invalid (skipped as occluders) and their occludees visible. One fixed order of
// operations, as the SIMD kernels have it: the same bits on every instruction set.
inline glm::dvec4 orthographic_representative(const glm::dvec4& c) {
    const double h = (3.0 * c.w - c.z) * 0.5;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (!(c.w > 0.0) || !(h >= 0x1.0p-8 * c.w)) return {nan, nan, c.z, nan};  // z untouched, as the SIMD kernels leave it
    return {c.x / h, c.y / h, c.z, c.w / h};
}
// How far a coordinate v / h of a representative may lie from the exact one when |v| is at most
// `v` (a bound, or the value), v is off by at most ev and h by at most dh (h > 2 dh):
// (ev h + |v| dh) / (h (h - dh)), which falls as h grows past 2 dh, plus the division's own
// rounding (2^-52 of the result covers it). The box tests and the occludee triangles use it.
inline double representative_error(double v, double ev, double h, double dh) {
    return (ev * h + std::abs(v) * dh) / (h * (h - dh)) + 0x1.0p-52 * std::abs(v / h);
}
// The near plane of an orthographic buffer: w' = 1 / g >= 0.5 is z >= -1.
constexpr float kOrthographicNearW = 0.5f;

// Whether m is the identity (a -0 counts as 0): transform_to_clip then returns the position,
// but for the sign of a zero and for a position with a coordinate that is not finite (all NaN).
inline bool is_identity(const std::array<float, 16>& m) {
    for (int i = 0; i < 16; ++i)
        if (m[std::size_t(i)] != (i % 5 == 0 ? 1.0f : 0.0f)) return false;
    return true;
}

inline bool finite_clip(const glm::dvec4& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.w); }
inline bool finite_clip_triangle(const glm::dvec4 clip[3]) { return finite_clip(clip[0]) && finite_clip(clip[1]) && finite_clip(clip[2]); }

// A position of the input in clip space as the buffer takes it: transform_to_clip (or _plain),
// then the orthographic representative for an orthographic input.
inline glm::dvec4 input_to_clip(const TriangleInput& in, double x, double y, double z, double w) {
    const glm::dvec4 c = transform_to_clip(in.model_to_clip, x, y, z, w);
    return in.orthographic ? orthographic_representative(c) : c;
}
inline glm::dvec4 input_to_clip_plain(const TriangleInput& in, double x, double y, double z, double w) {
    const glm::dvec4 c = transform_to_clip_plain(in.model_to_clip, x, y, z, w);
    return in.orthographic ? orthographic_representative(c) : c;
}

// Throws homcull::Error, naming `caller`, for input no triangle can be read from: 3 or 4
// components, positions and a stride of at least one position, and without indices, enough
// vertices for every triangle, numbered in 32 bits.
void check_triangle_input(const TriangleInput& in, const char* caller);
// The input as drawn: a clip_space one with the identity as its matrix (in `storage`), any
// other as it is.
const TriangleInput& with_clip_space_matrix(const TriangleInput& in, TriangleInput& storage);

// Vertex number k of triangle t: from 16- or 32-bit indices, or 3t + k without them (indices
// null; render() checks that 3t + k fits 32 bits).
template <typename Index>
inline std::uint32_t vertex_index(const Index* indices, std::size_t t, int k) {
    const std::size_t n = 3 * t + std::size_t(k);
    return indices ? std::uint32_t(indices[n]) : std::uint32_t(n);
}
// Calls f with the input's indices as the type they have: const std::uint16_t* or const
// std::uint32_t*, or a null const std::uint32_t* without indices (vertex_index then counts).
// The one place that chooses among the three, for the loops that must not choose per index.
template <class F>
inline decltype(auto) with_typed_indices(const TriangleInput& in, F&& f) {
    if (!in.indices) return f(static_cast<const std::uint32_t*>(nullptr));
    if (in.indices_16bit) return f(static_cast<const std::uint16_t*>(in.indices));
    return f(static_cast<const std::uint32_t*>(in.indices));
}
inline std::uint32_t vertex_index(const TriangleInput& in, std::size_t t, int k) {
    return with_typed_indices(in, [&](const auto* indices) { return vertex_index(indices, t, k); });
}

// The position of vertex v (below vertex_count) as (x, y, z, w), w = 1 for 3 components.
// A fixed-size copy per float: the stride need not keep floats aligned. A copy of a run-time
// size went through a library call whose byte stores the following loads could not forward
// from (a third of the castle's render time once); one 12-byte copy became an 8-byte and a
// 4-byte move through the stack, and reading y back from the middle of the 8-byte store
// stalled (a fifth of gather_triangle_batch's time on castle C0's occludee tests).
inline void read_position(const TriangleInput& in, std::uint32_t v, float p[4]) {
    const unsigned char* vertex = static_cast<const unsigned char*>(in.positions) + std::size_t(v) * in.position_stride;
    for (int c = 0; c < 3; ++c) std::memcpy(&p[c], vertex + std::size_t(c) * sizeof(float), sizeof(float));
    p[3] = 1.0f;
    if (in.position_components == 4) std::memcpy(&p[3], vertex + 3 * sizeof(float), sizeof(float));
}

// Triangle t's vertices as given (x, y, z, w with w = 1 for 3 components) and in clip space.
// False when an index is out of range or a clip coordinate is not finite.
// plain: with transform_to_clip_plain (the occludee tests) instead of transform_to_clip.
bool fetch_clip_triangle(const TriangleInput& in, std::size_t t, glm::dvec4 model[3], glm::dvec4 clip[3], bool plain = false);

// Whether all three vertices lie outside one side plane of the view frustum (|x| or |y| > w):
// then so does the whole triangle.
bool outside_side_plane(const glm::dvec4 clip[3]);
// The same with every vertex beyond the plane by more than a margin (in clip units: x - w >
// margin_x, ...): for coordinates known only to within a rounding bound.
bool outside_side_plane(const glm::dvec4 clip[3], double margin_x, double margin_y);

// Whether the triangle lies entirely behind the near plane or outside one side plane.
bool outside_frustum(const glm::dvec4 clip[3], double near_w);

// The guard band, in NDC units: triangles reaching beyond |x/w| or |y/w| = kGuardBand are
// clipped there, so that sample coordinates stay small enough for double edge functions to be
// exact to far below the coverage margin.
constexpr double kGuardBand = 32.0;

// Reaching more than 2^28 times its nearest w (or near_w) in x, y or w: clipping it in double would
// lose the precision conservative coverage needs (RasterStats::too_large). w counts too: a vertex
// at w = 4.6e33 and one behind the eye put the clipped vertex at w = 0 instead of near_w (the
// interpolation's parameter rounds to 1), and so a depth in front of the near plane.
bool too_large_to_clip(const glm::dvec4 clip[3], double near_w);

// A clip-space point (x, y, w > 0) in sample space (y down) with its depth 1/w: the
// projection of setup_clip_triangle, which the occludee triangle tests repeat for a triangle
// that needs no clipping.
inline void project_to_samples(double x, double y, double w, int sample_width, int sample_height, glm::dvec2& screen, double& depth) {
    const double inv_w = 1.0 / w;
    screen = {(x * inv_w + 1.0) * 0.5 * sample_width, (1.0 - y * inv_w) * 0.5 * sample_height};
    depth = inv_w;
}

// Whether a vertex lies before the near plane or beyond the guard band: the triangle is clipped.
bool needs_clipping(const glm::dvec4 clip[3], double near_w);

// The homogeneous determinant det[x y w] of three clip-space points (w > 0 after clipping):
// positive for counter-clockwise in NDC, and exactly zero for collinear input, before any
// division rounds it. One fixed order of operations, which the SIMD front end repeats.
template <typename V>
inline double homogeneous_det(const V& a, const V& b, const V& c) {
    auto w = [](const V& v) {
        if constexpr (V::length() == 4) return v.w;
        else return v.z;  // ClipVertex keeps w in z
    };
    return a.x * (b.y * w(c) - w(b) * c.y) - a.y * (b.x * w(c) - w(b) * c.x) + w(a) * (b.x * c.y - b.y * c.x);
}

// Whether a triangle of determinant det (homogeneous_det, non-zero) is culled by the backface mode.
inline bool facing_away(double det, Backface backface) {
    const bool ccw_in_ndc = det > 0.0;
    return (backface == Backface::cw && !ccw_in_ndc) || (backface == Backface::ccw && ccw_in_ndc);
}

// What setup_clip_triangle will do with a triangle, decided without clipping: rejected as
// outside, degenerate or backfacing (the statistic it counts), or set up (clipped, too large,
// or rasterized: setup_clip_triangle decides).
enum class TriangleFate : std::uint8_t { needs_setup, invalid, outside, degenerate, backfacing };
TriangleFate unclipped_fate(const glm::dvec4 clip[3], Backface backface, double near_w);

struct SetupResult {
    ScreenTriangle triangles[6];  // the clipped polygon's fan (a triangle clips to at most 8 vertices)
    int count = 0;
};

// Sets up a triangle already fetched and in clip space (fetch_clip_triangle), with its shared-edge
// bits: clipping, backface culling, projection to the sample grid of sample_width x sample_height.
// Counts the setup statistics but triangles_in, invalid and subtiles_updated.
// occludee: the triangle is an occludee's, whose exact triangle may reach samples its rounded
// coordinates miss (the caller pads its coverage by the rounding): it is not rejected beyond a
// side plane (the caller rejects those beyond the rounding), and a polygon whose determinant is 0
// in double is projected anyway, as zero-area triangles, rather than dropped as degenerate.
//
// A clipped polygon is drawn as a fan, whose diagonals are shared between its triangles. Each fan
// triangle keeps a margin-free edge (a diagonal, or a part of a shared edge of the triangle, whose
// neighbour's third vertex is apexes[k] for edge k, read only where shared_bits has bit k) only
// as margin_free_edges allows: a clipped sliver's fan triangles can be far thinner than the
// rounding of their diagonals. apexes may be null when shared_bits is 0; edge_margin is the
// buffer's.
struct SetupEdgeRule {
    const glm::dvec4* apexes = nullptr;
    double edge_margin = 0.0;
};
SetupResult setup_clip_triangle(const glm::dvec4 clip[3], std::uint8_t shared_bits, Backface backface, double near_w, int sample_width,
                                int sample_height, RasterStats& stats, bool occludee = false, SetupEdgeRule rule = {});

}  // namespace homcull::detail
