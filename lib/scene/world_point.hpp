#pragma once
// transform_point and transform_point_from (homcull/scene.hpp) as inline functions, for the
// loops that transform every vertex of a scene: its objects' bounds, the culler's world
// positions and part boxes. The same expressions, compiled with the library's flags (no
// contraction into fused multiply-adds: lib/CMakeLists.txt), so the same floats as the public
// functions, which call these. Not in the public header: a program including it with other
// flags could contract them and round differently from ground truth.
#include <glm/glm.hpp>

namespace homcull::detail {

// glTF node transforms are affine: the fourth row is not used (the compiler drops it here).
inline glm::vec3 world_point(const glm::dmat4& world, const glm::vec3& p) {
    return glm::vec3(glm::dvec3(world * glm::dvec4(glm::dvec3(p), 1.0)));
}

inline glm::vec3 world_point_from(const glm::dmat4& world, const glm::vec3& p, const glm::dvec3& anchor) {
    return glm::vec3(glm::dvec3(world * glm::dvec4(glm::dvec3(p), 1.0)) - anchor);
}

}  // namespace homcull::detail
