#pragma once
// An upper bound of an occludee triangle's exact 1/w at a sample, from how far the rounding of
// its input can move each vertex, not the plane as a whole (occludee_triangles.cpp).
//
// On screen, d = 1/w is an affine function f of the sample position over a triangle. Let the
// exact triangle have vertices p'_k = p_k + delta_k (|delta_k| <= (sx_k, sy_k) samples) and
// depths d'_k = d_k + e_k (|e_k| <= dd_k), and f' its affine function. A sample s with
// barycentrics l_k (of our triangle) gives the exact triangle's point sum l_k p'_k = s + u,
// u = sum l_k delta_k, at depth sum l_k d'_k; f' being affine,
//     f'(s) = f(s) + sum l_k e_k - grad f' . u,
// exactly. So |f'(s) - f(s)| <= sum |l_k| E_k with E_k = dd_k + Gx sx_k + Gy sy_k, where
// (Gx, Gy) bounds |grad f'| over every such perturbation (interval arithmetic on the three
// vertices). Inside the triangle sum |l_k| E_k = sum l_k E_k: the plane through the vertices
// raised by E_k. Within the outer coverage pad, some l_k are negative by at most the pad over
// the triangle's height; twice that times max E_k is added.
//
// The plane-error bound (occludee_triangles.cpp, PlaneError) tilts the whole plane about the
// eye, which for a long thin triangle seen at a grazing angle (a wall's top face running away
// from the eye, flush with a floor) is 10 to 100 times larger than what its vertices allow
// at the samples it covers. Both bounds hold; the test takes the smaller.
#include "raster/rasterize.hpp"

namespace homcull::detail {

struct RaisedVertexPlane {
    bool usable = false;  // false: the gradient could not be bounded (the perturbed area may vanish)
    double d0 = 0.0, x0 = 0.0, y0 = 0.0, dzdx = 0.0, dzdy = 0.0;  // the raised plane through vertex 0
    double outside = 0.0;  // added for samples within the pad outside the triangle

    // The bound at sample centre (column + 0.5, row + 0.5), before the caller's final raise.
    // `outside` is added everywhere, inside the triangle too: one affine function plus a
    // constant keeps a rectangle's largest value at a corner.
    double at(int column, int row) const { return d0 + dzdx * (column + 0.5 - x0) + dzdy * (row + 0.5 - y0) + outside; }
};

// vertex_x/y: how far each vertex may move on screen (samples); vertex_depth: how far its 1/w
// may move; pad_x/y: the outer coverage pad of the test.
RaisedVertexPlane raised_vertex_plane(const OrientedTriangle& triangle, const double vertex_x[3], const double vertex_y[3],
                                      const double vertex_depth[3], double pad_x, double pad_y);

}  // namespace homcull::detail
