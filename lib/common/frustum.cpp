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

FrustumAxes frustum_axes(const Frustum& fr, double relative_margin, const glm::dvec3& position_slack) {
    FrustumAxes axes;
    axes.relative_margin = relative_margin;
    const auto add = [&](const glm::dvec3& axis) {
        if (!(glm::length(axis) > 1e-12)) return;  // degenerate cross product (or not finite): no axis
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        for (const auto& p : fr.corners) {
            const double d = glm::dot(axis, p);
            if (!std::isfinite(d)) return;  // std::min would pass over a NaN and shrink the extent
            lo = std::min(lo, d);
            hi = std::max(hi, d);
        }
        const double slack = glm::dot(glm::abs(axis), position_slack);
        const int k = axes.count++;
        axes.axis[std::size_t(k)] = axis, axes.lo[std::size_t(k)] = lo - slack, axes.hi[std::size_t(k)] = hi + slack;
    };
    for (const auto& plane : fr.planes) add(glm::dvec3(plane));
    axes.plane_count = axes.count;
    const glm::dvec3 box_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const auto& a : box_axes) add(a);
    for (const auto& a : box_axes)
        for (const auto& e : fr.edge_directions) add(glm::cross(a, e));
    return axes;
}

bool separated(const FrustumAxes& axes, const Aabb& box) {
    if (box.empty()) return true;
    const glm::dvec3 lo(box.min), hi(box.max);
    const glm::dvec3 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
    bool centre_inside = true;
    for (int k = 0; k < axes.count; ++k) {
        const glm::dvec3& a = axes.axis[std::size_t(k)];
        const glm::dvec3 abs_a = glm::abs(a);
        const double c = glm::dot(a, centre);
        const double r = glm::dot(abs_a, half);
        const double f_lo = axes.lo[std::size_t(k)], f_hi = axes.hi[std::size_t(k)];
        // The box's terms without their cancellation (|a| |centre|, not |a . centre|).
        const double margin = axes.relative_margin * (glm::dot(abs_a, glm::abs(centre)) + r + std::abs(f_lo) + std::abs(f_hi));
        if (f_hi + margin < c - r || c + r + margin < f_lo) return true;
        // A box whose centre lies within every plane's extent (inside the frustum) meets it:
        // most boxes tested are in view, and end here without the 21 other axes.
        centre_inside = centre_inside && f_lo <= c && c <= f_hi;
        if (k + 1 == axes.plane_count && centre_inside) return false;
    }
    return false;
}

bool intersects(const Frustum& fr, const Aabb& box) { return !separated(frustum_axes(fr), box); }

}  // namespace homcull
