#pragma once
// An exact oracle for the occlusion buffer's promises, at the sample centres, in rational
// arithmetic (GMP): no rounding anywhere, so a disagreement is the buffer's.
//
// A triangle is given as the buffer reads it: float positions times a float matrix. Its clip
// vertices V0, V1, V2 = (x, y, w) are exact rationals. The ray through the sample centre with
// NDC (X, Y) is t (X, Y, 1) in (x, y, w), t > 0 its w. It meets the triangle's plane where
// t (X, Y, 1) = M lambda with lambda summing to 1 (M's columns the V_k), so lambda = t M^-1 P
// and 1/t = sum(M^-1 P): the hit is inside when every (M^-1 P)_k has the sign of that sum and
// the sum is positive, and its 1/w is the sum itself. With a = adj(M) P and det = det(M),
// M^-1 P = a / det: only products and sums, no division until the comparison.
#include <homcull/occlusion_buffer.hpp>

#include <gmpxx.h>

#include <array>
#include <vector>

namespace homcull::test {

struct ExactTriangle {
    mpq_class adjugate[3][3];  // rows of adj(M)
    mpq_class det;
    bool flat = true;  // det == 0: the plane passes through the eye, seen edge-on, covers nothing
    // The same rounded to double, for a filter that decides most samples without rationals
    // (and falls back to them whenever its error bound leaves the answer open).
    double adjugate_d[3][3], det_d;
};

// The clip-space (x, y, w) of the input's triangle t, exactly; false when an index is out of
// range or a coordinate is not finite.
bool exact_clip_triangle(const TriangleInput& in, std::size_t t, std::array<std::array<mpq_class, 3>, 3>& clip);
ExactTriangle exact_triangle(const std::array<std::array<mpq_class, 3>, 3>& clip);

// The sample centre (i + 0.5, j + 0.5) of a sample_width x sample_height grid in NDC (y up).
struct ExactSample {
    mpq_class x, y;
    double x_d, y_d;  // rounded
};
ExactSample exact_sample(int i, int j, int sample_width, int sample_height);

// Whether the triangle covers the sample's ray at w >= near_w (boundary included), and there
// its exact 1/w.
bool exact_hit(const ExactTriangle& tri, const ExactSample& s, const mpq_class& inverse_near_w, mpq_class& inverse_w);
// Whether it covers the sample's ray at w >= near_w with 1/w >= d: exact_hit's answer, most often
// decided in double with an error bound.
bool hit_at_or_nearer(const ExactTriangle& tri, const ExactSample& s, const mpq_class& inverse_near_w, double inverse_near_d, float d);

// All of an input's valid triangles, whatever their facing: an occluder's claim is right when any
// surface backs it, and occludee triangles count either way.
std::vector<ExactTriangle> exact_triangles(const TriangleInput& in);

// The largest exact 1/w of the triangles at the sample (0 where none covers it at w >= near_w).
mpq_class nearest_inverse_w(const std::vector<ExactTriangle>& tris, const ExactSample& s, const mpq_class& inverse_near_w);

// The buffer's claim at each sample, as its queries read it: 1/w of the subtile layers (the
// working layer where the sample is in its mask) or the per-sample depth where nearer; 0 where
// it claims nothing. Row-major, sample_width x sample_height.
std::vector<float> claimed_inverse_w(const OcclusionBuffer& buffer);

// Every claim backed: at each sample with a claim d > 0, some drawn occluder covers the
// sample at w >= near_w with exact 1/w >= d. Returns the number of unbacked claims (and the
// first one's sample in *first when not null).
long unbacked_claims(const OcclusionBuffer& buffer, const std::vector<ExactTriangle>& occluders, int* first = nullptr);

// Whether a rectangle answered occluded is hidden at every sample centre it holds: each has an
// occluder at exact w <= w_min (1/w >= 1/w_min).
bool rect_truly_hidden(const std::vector<ExactTriangle>& occluders, const ScreenRect& r, int sample_width, int sample_height,
                       float near_w);

// Whether occludee triangles answered occluded are hidden at every sample where one of them is
// seen (at w >= near_w): an occluder at the same sample at or nearer than it.
bool triangles_truly_hidden(const std::vector<ExactTriangle>& occluders, const std::vector<ExactTriangle>& occludee, int sample_width,
                            int sample_height, float near_w);

}  // namespace homcull::test
