#pragma once
// The triangle list that the steps of the occluder LOD build pass between them (a welded mesh,
// a part, a simplified and shrunk copy), and the small helpers they share: edge keys and
// triangle cross products. Used by lod_mesh_parts, lod_simplify, lod_containment and the
// driver, occluder_lod_build.cpp.
#include <glm/glm.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace homcull::detail::lod {

constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();

struct TriangleMesh {
    std::vector<glm::vec3> positions;
    std::vector<std::uint32_t> indices;
};

inline std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; }

inline glm::dvec3 triangle_cross(const std::vector<glm::vec3>& positions, const std::uint32_t* corner) {
    const glm::dvec3 a(positions[corner[0]]), b(positions[corner[1]]), c(positions[corner[2]]);
    return glm::cross(b - a, c - a);  // twice the area, along the CCW normal
}

}  // namespace homcull::detail::lod
