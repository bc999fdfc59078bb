#include "raster/clip_polygon.hpp"

namespace homcull::detail {
namespace {

bool lexicographically_less(const ClipVertex& a, const ClipVertex& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
}

// Where the plane cuts the edge ab, computed from the lexicographically smaller end so that
// both directions of the edge give the same point.
ClipVertex cut(const ClipVertex& a, double da, const ClipVertex& b, double db) {
    if (lexicographically_less(b, a)) return b + (a - b) * (db / (db - da));
    return a + (b - a) * (da / (da - db));
}

// Keeps the part of the polygon where dot(plane, (x, y, w)) + constant >= 0. Each output
// vertex carries the flag of the edge that leaves it.
void clip_against(ClipPolygon& poly, const glm::dvec3& plane, double constant) {
    ClipPolygon out;
    for (int i = 0; i < poly.count; ++i) {
        const ClipVertex& a = poly.v[i];
        const ClipVertex& b = poly.v[(i + 1) % poly.count];
        const double da = glm::dot(plane, a) + constant, db = glm::dot(plane, b) + constant;
        if (da >= 0.0) {
            out.v[out.count] = a;
            out.source[out.count] = poly.source[i];
            out.shared[out.count++] = poly.shared[i];
            if (db < 0.0) {  // leaving: the next edge runs along the clip plane
                out.v[out.count] = cut(a, da, b, db);
                out.source[out.count] = ClipPolygon::kClipEdge;
                out.shared[out.count++] = 0;
            }
        } else if (db >= 0.0) {  // entering: the rest of edge ab
            out.v[out.count] = cut(a, da, b, db);
            out.source[out.count] = poly.source[i];
            out.shared[out.count++] = poly.shared[i];
        }
    }
    poly = out;
}

}  // namespace

ClipPolygon clip_triangle(const ClipVertex (&v)[3], std::uint8_t shared_bits, double near_w, double guard) {
    ClipPolygon poly;
    for (int k = 0; k < 3; ++k) {
        poly.v[k] = v[k];
        poly.shared[k] = (shared_bits >> k) & 1u;
        poly.source[k] = std::uint8_t(k);
    }
    poly.count = 3;
    clip_against(poly, {0, 0, 1}, -near_w);  // w - near_w >= 0
    if (poly.count) clip_against(poly, {-1, 0, guard}, 0.0);  // guard*w - x >= 0
    if (poly.count) clip_against(poly, {1, 0, guard}, 0.0);   // guard*w + x >= 0
    if (poly.count) clip_against(poly, {0, -1, guard}, 0.0);
    if (poly.count) clip_against(poly, {0, 1, guard}, 0.0);
    if (poly.count < 3) poly.count = 0;
    return poly;
}

}  // namespace homcull::detail
