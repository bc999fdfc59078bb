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
        const std::size_t k = std::size_t(axes.count++);
        axes.axis[k] = axis, axes.lo[k] = lo - slack, axes.hi[k] = hi + slack;
        axes.extent_magnitude[k] = std::abs(axes.lo[k]) + std::abs(axes.hi[k]);
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
        // Apart by more than the margin only where apart at all (the margin is not negative):
        // the margin is worked out for the few axes that get that far.
        if (f_hi < c - r || c + r < f_lo) {
            // The box's terms without their cancellation (|a| |centre|, not |a . centre|).
            const double margin = axes.relative_margin * (glm::dot(abs_a, glm::abs(centre)) + r + axes.extent_magnitude[std::size_t(k)]);
            if (f_hi + margin < c - r || c + r + margin < f_lo) return true;
        }
        // A box whose centre lies within every plane's extent (inside the frustum) meets it:
        // most boxes tested are in view, and end here without the 21 other axes.
        centre_inside = centre_inside && f_lo <= c && c <= f_hi;
        if (k + 1 == axes.plane_count && centre_inside) return false;
    }
    return false;
}

bool intersects(const Frustum& fr, const Aabb& box) { return !separated(frustum_axes(fr), box); }

FrustumAxes view_volume_axes(const glm::dmat4& m, double near_w, bool orthographic, double relative_margin) {
    FrustumAxes axes;
    axes.relative_margin = relative_margin;
    const auto row = [&](int r) { return glm::dvec4(m[0][r], m[1][r], m[2][r], m[3][r]); };
    const glm::dvec4 x = row(0), y = row(1), z = row(2), w = row(3);
    // The near rectangle's corners (bottom-left, bottom-right, top-right, top-left) and the side
    // edges' directions from them: where x = sx w, y = sy w and w = near_w (orthographic: x = sx,
    // y = sy, z = -1), and the direction along which w (z) grows by 1 on those two planes.
    glm::dvec3 corner[4], ray[4];
    const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; ++k) {
        const glm::dvec4 a = orthographic ? x : x - sx[k] * w, b = orthographic ? y : y - sy[k] * w, c = orthographic ? z : w;
        const glm::dvec3 rhs = orthographic ? glm::dvec3(sx[k] - a.w, sy[k] - b.w, -1.0 - c.w) : glm::dvec3(-a.w, -b.w, near_w - c.w);
        // Rows a, b, c as a column-major glm matrix: its transpose.
        const glm::dmat3 system = glm::transpose(glm::dmat3(glm::dvec3(a), glm::dvec3(b), glm::dvec3(c)));
        const double det = glm::determinant(system);
        if (!std::isfinite(det) || det == 0.0) return axes;  // a degenerate view: nothing is separated
        const glm::dmat3 inverse = glm::inverse(system);
        corner[k] = inverse * rhs;
        ray[k] = inverse * glm::dvec3(0.0, 0.0, 1.0);
        for (int i = 0; i < 3; ++i)
            if (!std::isfinite(corner[k][i]) || !std::isfinite(ray[k][i])) return axes;
    }
    const auto add = [&](const glm::dvec3& axis) {
        if (!(glm::length(axis) > 1e-12)) return;  // degenerate cross product (or not finite): no axis
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        for (const glm::dvec3& p : corner) {
            lo = std::min(lo, glm::dot(axis, p));
            hi = std::max(hi, glm::dot(axis, p));
        }
        // A side edge climbing the axis takes that side of the extent to infinity. One that
        // lies across it (a plane's own edges along its normal) climbs by rounding alone: within
        // 2^-40 of its length, not counted; the margin (2^-40 is far below it) covers the
        // distance that rounding makes along the edge.
        for (const glm::dvec3& d : ray) {
            const double t = glm::dot(axis, d), tolerance = 0x1.0p-40 * glm::dot(glm::abs(axis), glm::abs(d));
            if (t > tolerance) hi = HUGE_VAL;
            if (t < -tolerance) lo = -HUGE_VAL;
        }
        if (lo == -HUGE_VAL && hi == HUGE_VAL) return;  // separates nothing
        const std::size_t k = std::size_t(axes.count++);
        axes.axis[k] = axis, axes.lo[k] = lo, axes.hi[k] = hi;
        axes.extent_magnitude[k] = (std::isfinite(lo) ? std::abs(lo) : 0.0) + (std::isfinite(hi) ? std::abs(hi) : 0.0);
    };
    // The planes' inward normals: w - x >= 0, w + x >= 0, w - y >= 0, w + y >= 0, and the near
    // plane w >= near_w (orthographic: z >= -1).
    for (const glm::dvec4& plane : {w - x, w + x, w - y, w + y, orthographic ? z : w}) add(glm::dvec3(plane));
    axes.plane_count = axes.count;
    const glm::dvec3 edges[6] = {ray[0], ray[1], ray[2], ray[3], corner[1] - corner[0], corner[3] - corner[0]};
    const glm::dvec3 box_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const auto& a : box_axes) add(a);
    for (const auto& a : box_axes)
        for (const auto& e : edges) add(glm::cross(a, e));
    return axes;
}

}  // namespace homcull
