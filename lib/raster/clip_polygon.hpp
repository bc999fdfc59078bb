#pragma once
// Homogeneous clipping of one triangle in clip space (Sutherland and Hodgman, "Reentrant
// polygon clipping", CACM 1974), in double precision.
#include <glm/glm.hpp>

#include <cstdint>

namespace homcull::detail {

// Clip-space x, y, w of a vertex (z is not used: depth is 1/w).
using ClipVertex = glm::dvec3;

struct ClipPolygon {
    static constexpr int kMax = 3 + 5;  // a triangle gains at most one vertex per plane
    ClipVertex v[kMax];
    std::uint8_t shared[kMax];  // whether the edge from v[i] to v[i + 1] is shared
    std::uint8_t source[kMax];  // the triangle's edge it lies on (0, 1, 2), or kClipEdge
    int count = 0;
    static constexpr std::uint8_t kClipEdge = 3;
};

// Clips against w >= near_w and the guard band |x|, |y| <= guard * w. Returns the polygon
// (count 0 when nothing is left). Edges keep their shared flag; edges along a clip plane are
// not shared. An edge is cut at the same point whichever way round it is traversed, so
// neighbours clipped separately still share it exactly.
ClipPolygon clip_triangle(const ClipVertex (&v)[3], std::uint8_t shared_bits, double near_w, double guard);

}  // namespace homcull::detail
