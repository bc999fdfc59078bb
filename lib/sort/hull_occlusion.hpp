#pragma once
// The exact test on convex hulls: may object A hide part of object B from the eye?
//
// A ray from the eye E meets A and then B exactly when A meets the set of points between the
// eye and B: the convex hull of E and B's hull (every point of it lies on a segment from E to
// a point of B). So "A occludes B" is an intersection test of two convex sets, A's hull and
// hull(B + E), which GJK answers from their support points alone (Gilbert, Johnson and
// Keerthi, "A fast procedure for computing the distance between complex objects in
// three-dimensional space", IEEE J. Robotics and Automation, 1988).
//
// The answer is conservative: "no" only with a certificate, a direction along which the two
// sets are apart by more than a margin (the float roundings of the objects' coordinates, and
// the ground truth's own). GJK that does not settle within its iterations says "yes".
#include "sort/support_scan.hpp"

#include <glm/glm.hpp>

#include <cstdint>

namespace homcull::sort_detail {

// One object's hull as the tests see it this frame: model-space points (structure of arrays),
// the model-to-world transform, and the support scan of the sorter's instruction set.
struct PlacedHull {
    const float* x = nullptr;
    const float* y = nullptr;
    const float* z = nullptr;
    std::uint32_t count = 0;
    glm::mat4 transform{1.0f};
    SupportScan scan = &support_scan_reference;
};

// The world point of the hull farthest along world direction d.
glm::dvec3 support_point(const PlacedHull& hull, const glm::dvec3& d);

// What one test of a pair leaves for the same pair's test in the next frame: Snyder and
// Lengyel's temporal coherence in GJK's terms (warm starting, as in Cameron, "Enhancing GJK:
// computing minimum and penetration distances between convex polyhedra", ICRA 1997). Objects
// move little between frames, so the last search direction still parts most apart pairs in
// one step, and the last enclosing tetrahedron, its corners moved with the objects, still
// encloses the origin for most pairs that meet, without a single scan. A hint only decides
// where GJK starts: "apart" still needs this frame's certificate, and "may occlude" is the
// conservative answer, so a stale or foreign hint costs time, never correctness.
struct GjkHint {
    static constexpr std::uint32_t kEye = 0xffffffffu;  // a corner's back point that is the eye
    glm::vec3 direction{0.0f};  // the last search direction (zero: none)
    std::uint8_t corners = 0;   // 4 when the indices below name an enclosing tetrahedron
    std::uint32_t back[4] = {}, front[4] = {};  // each corner: back's point (or kEye) - front's
};

// What one test cost: GJK's steps and the hull scans they made.
struct GjkWork {
    std::uint32_t iterations = 0;
    std::uint32_t scans = 0;
};

// Whether `front` may hide part of `back` seen from `eye`: whether front's hull meets the hull
// of the eye and back's hull, both grown by `margin` (world units). `start` is the first
// direction GJK tries when the hint has none (any non-zero vector; the one from back towards
// front converges fast). `hint` (optional) is read and then rewritten for the next frame.
bool may_occlude(const PlacedHull& front, const PlacedHull& back, const glm::dvec3& eye, double margin, const glm::dvec3& start,
                 GjkHint* hint = nullptr, GjkWork* work = nullptr);

// Two hulls on their own, without the eye: apart (with the direction of a plane between them,
// from `first` towards `second`), meeting (GJK enclosed the origin, or its simplex collapsed
// there: within `margin`), or not settled within GJK's iterations.
enum class Contact : std::uint8_t { apart, meet, unsettled };
struct HullContact {
    Contact contact = Contact::unsettled;
    glm::dvec3 direction{0.0};  // apart: first lies below second along it
};
HullContact hull_contact(const PlacedHull& first, const PlacedHull& second, double margin, const glm::dvec3& start);

}  // namespace homcull::sort_detail
