#pragma once
// Which triangles of a closed solid seen from outside the eye certainly sees from behind
// (OcclusionBuffer::ClosedSolid: test_triangles passes over them; scene/closed_occludees.hpp
// says when the scene culler's occludees are such solids, and why that is exact).
#include <homcull/occlusion_buffer.hpp>

#include <glm/glm.hpp>

#include <cmath>

namespace homcull::detail {

// Whether the eye certainly lies behind triangle (a, b, c) (float coordinates, exact in double):
// orientation ((b - a) x (c - a)) . (eye - a) < 0 beyond the double evaluation's rounding (2^-40
// of the terms' magnitudes, far more than the few roundings of 2^-53 each). Seen edge-on, or
// not finite: false.
inline bool certainly_faces_away(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const OcclusionBuffer::ClosedSolid& solid) {
    const glm::dvec3 e1 = b - a, e2 = c - a, to_eye = glm::dvec3(solid.eye[0], solid.eye[1], solid.eye[2]) - a;
    const glm::dvec3 n = glm::cross(e1, e2);
    const glm::dvec3 n_magnitude(std::abs(e1.y * e2.z) + std::abs(e1.z * e2.y), std::abs(e1.z * e2.x) + std::abs(e1.x * e2.z),
                                 std::abs(e1.x * e2.y) + std::abs(e1.y * e2.x));
    return double(solid.orientation) * glm::dot(n, to_eye) < -0x1.0p-40 * glm::dot(n_magnitude, glm::abs(to_eye));
}

}  // namespace homcull::detail
