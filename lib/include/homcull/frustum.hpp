#pragma once
// The view frustum of a perspective camera as a convex polyhedron, and an exact test of
// whether an axis-aligned box meets it.
#include <homcull/aabb.hpp>
#include <homcull/camera.hpp>

#include <array>

namespace homcull {

struct Frustum {
    // Corners: near plane (0..3) then far plane (4..7), each as
    // bottom-left, bottom-right, top-right, top-left seen from the eye.
    std::array<glm::dvec3, 8> corners;
    // Inward-facing planes (normal, offset) with dot(normal, p) + offset >= 0 inside:
    // left, right, bottom, top, near, far.
    std::array<glm::dvec4, 6> planes;
    // Directions of the frustum's edges: the four side edges, then right and up (the
    // directions of the near and far rectangles' edges).
    std::array<glm::dvec3, 6> edge_directions;
};

Frustum make_frustum(const Camera& camera, double aspect);

// True when the box and the frustum share at least one point. Exact (separating axis theorem
// over the 6 frustum planes, the 3 box axes and the 18 edge-edge cross products), not the
// usual conservative plane-only test that keeps boxes near frustum corners.
bool intersects(const Frustum& frustum, const Aabb& box);

// The candidate separating axes of intersects() with the frustum's extent along each, computed
// once per frustum: every box is axis-aligned, so the axes (the frustum's plane normals, the
// world axes and their cross products with the frustum's edges) depend on the frustum alone,
// and a box then costs one projection per axis. Axes of a degenerate cross product are left out.
struct FrustumAxes {
    int count = 0;
    int plane_count = 0;  // the first axes: the planes' normals
    std::array<glm::dvec3, 27> axis;
    std::array<double, 27> lo, hi;  // the frustum's corners projected on axis[k], widened by position_slack
    // |lo| + |hi| without an infinite one (view_volume_axes: an unbounded side): the margin's
    // frustum term.
    std::array<double, 27> extent_magnitude;
    // How far apart, relative to the magnitudes of the box's and the frustum's terms, a box and
    // the frustum must lie to count as separated (0: exact, as intersects()).
    double relative_margin = 0.0;
};
// position_slack: how far, along each world axis, the frustum may lie from where its corners say
// (a copy of it whose eye was rounded, say); each axis's extent is widened by that much. An axis
// along which a corner's projection is not finite (a far plane at infinity) is left out.
FrustumAxes frustum_axes(const Frustum& frustum, double relative_margin = 0.0, const glm::dvec3& position_slack = glm::dvec3(0.0));

// The view volume of a clip-from-space matrix (column-major, the library's clip space: y up the
// screen, w the view depth) as separating axes in that space, for boxes given in it (world
// boxes with clip_from_world, model boxes with clip_from_model): the points with |x| <= w,
// |y| <= w and w >= near_w, or for an orthographic matrix (w = 1, OpenGL's z) |x| <= 1,
// |y| <= 1 and z >= -1. No far plane: the volume is unbounded beyond the near rectangle (its
// four side edges are rays), so that a view without one is exact too; a box beyond a far plane
// has a plane test of its own. The axes are intersects()'s: the five planes' normals, the space's
// axes and their cross products with the side edges and the near rectangle's edges; along an
// axis that a side edge climbs, the volume's extent is infinite on that side. A matrix whose
// volume is degenerate or not finite gives no axis (nothing is separated).
FrustumAxes view_volume_axes(const glm::dmat4& clip_from_space, double near_w, bool orthographic, double relative_margin);

// True when some axis separates the box from the frustum by more than the margin (a box that
// is empty is separated).
bool separated(const FrustumAxes& axes, const Aabb& box);

// Whether a box may meet the frustum: false only when it lies wholly outside one of the six
// planes. Cheaper than intersects() and conservative (it keeps some boxes near the frustum's
// edges that intersects() rejects): enough where a spare object only costs time.
bool may_meet(const Frustum& frustum, const Aabb& box);

}  // namespace homcull
