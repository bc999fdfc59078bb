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

// Whether `front` may hide part of `back` seen from `eye`: whether front's hull meets the hull
// of the eye and back's hull, both grown by `margin` (world units). `start` is the first
// direction GJK tries (any non-zero vector; the one from back towards front converges fast).
bool may_occlude(const PlacedHull& front, const PlacedHull& back, const glm::dvec3& eye, double margin, const glm::dvec3& start);

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
