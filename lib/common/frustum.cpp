#include <homcull/frustum.hpp>

#include <algorithm>
#include <cmath>

namespace homcull {

Frustum make_frustum(const Camera& c, double aspect) {
    const CameraBasis b = camera_basis(c);
    const double tan_half = std::tan(glm::radians(c.fov_y_degrees) * 0.5);
    Frustum fr;
    const double depths[2] = {c.near_plane, c.far_plane};
    for (int k = 0; k < 2; ++k) {
        const glm::dvec3 centre = c.eye + depths[k] * b.forward;
        // An orthographic camera's frustum is a box: the same rectangle at every depth.
        const double half_height = c.ortho_height > 0.0 ? 0.5 * c.ortho_height : depths[k] * tan_half;
        const glm::dvec3 half_up = half_height * b.up;
        const glm::dvec3 half_right = half_height * aspect * b.right;
        fr.corners[4 * k + 0] = centre - half_right - half_up;
        fr.corners[4 * k + 1] = centre + half_right - half_up;
        fr.corners[4 * k + 2] = centre + half_right + half_up;
        fr.corners[4 * k + 3] = centre - half_right + half_up;
    }
    glm::dvec3 inside(0.0);
    for (const auto& p : fr.corners) inside += p / 8.0;

    // Each face by three of its corners; the normal is flipped to point inside.
    const int faces[6][3] = {{0, 3, 7}, {1, 2, 6}, {0, 1, 5}, {3, 2, 6}, {0, 1, 2}, {4, 5, 6}};
    for (int f = 0; f < 6; ++f) {
        const glm::dvec3& a = fr.corners[faces[f][0]];
        glm::dvec3 n = glm::normalize(
            glm::cross(fr.corners[faces[f][1]] - a, fr.corners[faces[f][2]] - a));
        if (glm::dot(n, inside - a) < 0.0) n = -n;
        fr.planes[f] = glm::dvec4(n, -glm::dot(n, a));
    }
    for (int k = 0; k < 4; ++k) fr.edge_directions[k] = fr.corners[4 + k] - fr.corners[k];
    fr.edge_directions[4] = b.right;
    fr.edge_directions[5] = b.up;
    return fr;
}

bool may_meet(const Frustum& fr, const Aabb& box) {
    if (box.empty()) return false;
    for (const glm::dvec4& plane : fr.planes) {
        // The box corner farthest along the plane's inward normal.
        const glm::dvec3 p(plane.x >= 0.0 ? box.max.x : box.min.x, plane.y >= 0.0 ? box.max.y : box.min.y,
                           plane.z >= 0.0 ? box.max.z : box.min.z);
        if (glm::dot(glm::dvec3(plane), p) + plane.w < 0.0) return false;
    }
    return true;
}

bool intersects(const Frustum& fr, const Aabb& box) {
    if (box.empty()) return false;
    const glm::dvec3 lo(box.min), hi(box.max);
    const glm::dvec3 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;

    // The two convex bodies are disjoint iff some axis separates their projections.
    auto separated_along = [&](const glm::dvec3& axis) {
        const double scale = glm::length(axis);
        if (!(scale > 1e-12)) return false;  // degenerate cross product: no axis
        double fmin = HUGE_VAL, fmax = -HUGE_VAL;
        for (const auto& p : fr.corners) {
            const double d = glm::dot(axis, p);
            fmin = std::min(fmin, d);
            fmax = std::max(fmax, d);
        }
        const double c = glm::dot(axis, centre);
        const double r = std::abs(axis.x) * half.x + std::abs(axis.y) * half.y +
                         std::abs(axis.z) * half.z;
        return fmax < c - r || c + r < fmin;
    };

    for (const auto& plane : fr.planes)
        if (separated_along(glm::dvec3(plane))) return false;
    const glm::dvec3 box_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const auto& a : box_axes)
        if (separated_along(a)) return false;
    for (const auto& a : box_axes)
        for (const auto& e : fr.edge_directions)
            if (separated_along(glm::cross(a, e))) return false;
    return true;
}

}  // namespace homcull
