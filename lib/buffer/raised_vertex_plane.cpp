// The raised-vertex depth bound of an occludee triangle: see raised_vertex_plane.hpp.
#include "buffer/raised_vertex_plane.hpp"

#include <algorithm>
#include <cmath>

namespace homcull::detail {
namespace {

// Closed intervals of doubles, their ends rounded to nearest: a few operations, each off by at
// most 2^-53 of its result. The gradient bound below absorbs that: the determinant's lower
// end is lowered by 2^-50 of its products, and E_k is raised by a relative 2^-30.
struct Interval {
    double lo, hi;
};
Interval around(double value, double radius) { return {value - radius, value + radius}; }
Interval operator-(Interval a, Interval b) { return {a.lo - b.hi, a.hi - b.lo}; }
Interval operator*(Interval a, Interval b) {
    const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    return {std::min({p[0], p[1], p[2], p[3]}), std::max({p[0], p[1], p[2], p[3]})};
}
double magnitude(Interval a) { return std::max(std::abs(a.lo), std::abs(a.hi)); }

}  // namespace

RaisedVertexPlane raised_vertex_plane(const OrientedTriangle& t, const double vertex_x[3], const double vertex_y[3],
                                      const double vertex_depth[3], double pad_x, double pad_y) {
    RaisedVertexPlane plane;
    // The exact triangle's edges from vertex 0 and depth differences, as intervals.
    const Interval e1x = around(t.v[1].x - t.v[0].x, vertex_x[0] + vertex_x[1]);
    const Interval e1y = around(t.v[1].y - t.v[0].y, vertex_y[0] + vertex_y[1]);
    const Interval e2x = around(t.v[2].x - t.v[0].x, vertex_x[0] + vertex_x[2]);
    const Interval e2y = around(t.v[2].y - t.v[0].y, vertex_y[0] + vertex_y[2]);
    const Interval dd1 = around(t.d[1] - t.d[0], vertex_depth[0] + vertex_depth[1]);
    const Interval dd2 = around(t.d[2] - t.d[0], vertex_depth[0] + vertex_depth[2]);
    // Its gradient by Cramer's rule: (dd1 e2y - dd2 e1y, dd2 e1x - dd1 e2x) / (e1x e2y - e1y e2x).
    const Interval det = e1x * e2y - e1y * e2x;
    const double min_det = std::min(std::abs(det.lo), std::abs(det.hi)) -
                           0x1.0p-50 * (magnitude(e1x) * magnitude(e2y) + magnitude(e1y) * magnitude(e2x));
    if (!(det.lo > 0.0 || det.hi < 0.0) || !(min_det > 0.0)) return plane;  // the exact triangle may have no area on screen
    const double gx = magnitude(dd1 * e2y - dd2 * e1y) / min_det, gy = magnitude(dd2 * e1x - dd1 * e2x) / min_det;
    if (!std::isfinite(gx) || !std::isfinite(gy)) return plane;

    double raise[3], most = 0.0;
    for (int k = 0; k < 3; ++k) {
        raise[k] = (vertex_depth[k] + gx * vertex_x[k] + gy * vertex_y[k]) * (1.0 + 0x1.0p-30);
        most = std::max(most, raise[k]);
    }
    // The plane through the raised vertices (t.area2 > 0: oriented).
    const double r1 = (t.d[1] + raise[1]) - (t.d[0] + raise[0]), r2 = (t.d[2] + raise[2]) - (t.d[0] + raise[0]);
    const double ex1 = t.v[1].x - t.v[0].x, ey1 = t.v[1].y - t.v[0].y, ex2 = t.v[2].x - t.v[0].x, ey2 = t.v[2].y - t.v[0].y;
    plane.dzdx = (r1 * ey2 - r2 * ey1) / t.area2;
    plane.dzdy = (r2 * ex1 - r1 * ex2) / t.area2;
    plane.d0 = t.d[0] + raise[0];
    plane.x0 = t.v[0].x;
    plane.y0 = t.v[0].y;
    // Barycentric l_k is below 0 by at most the pad's reach across the opposite edge over
    // twice the area; sum |l_k| E_k exceeds sum l_k E_k by twice the negative parts.
    double negative = 0.0;
    for (int k = 0; k < 3; ++k) {
        const glm::dvec2 edge = t.v[(k + 2) % 3] - t.v[(k + 1) % 3];
        negative += (std::abs(edge.y) * pad_x + std::abs(edge.x) * pad_y) / t.area2;
    }
    plane.outside = 2.0 * most * negative;
    plane.usable = std::isfinite(plane.dzdx) && std::isfinite(plane.dzdy) && std::isfinite(plane.d0) && std::isfinite(plane.outside);
    return plane;
}

}  // namespace homcull::detail
