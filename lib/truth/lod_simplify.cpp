// Steps 2 and 3 of the occluder LOD build: angle-weighted vertex normals of a part, its
// simplification with meshopt_simplify under an error bound in model units, and the inward
// shrink of the simplified triangles along those normals (dropping zero-area ones).
#include "truth/lod_simplify.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>

namespace homcull::detail::lod {

std::vector<glm::dvec3> angle_weighted_normals(const TriangleMesh& mesh) {
    std::vector<glm::dvec3> normals(mesh.positions.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const std::uint32_t* corner = &mesh.indices[t];
        const glm::dvec3 unit = glm::normalize(triangle_cross(mesh.positions, corner));
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 p(mesh.positions[corner[k]]);
            const glm::dvec3 to_next = glm::dvec3(mesh.positions[corner[(k + 1) % 3]]) - p;
            const glm::dvec3 to_prev = glm::dvec3(mesh.positions[corner[(k + 2) % 3]]) - p;
            normals[corner[k]] +=
                unit * std::atan2(glm::length(glm::cross(to_next, to_prev)), glm::dot(to_next, to_prev));
        }
    }
    return normals;
}

std::vector<std::uint32_t> simplify(const TriangleMesh& o, double target_ratio, double max_error) {
    const std::size_t triangles = o.indices.size() / 3;
    const std::size_t target = std::max<std::size_t>(1, std::size_t(double(triangles) * target_ratio)) * 3;
    const float scale = meshopt_simplifyScale(&o.positions[0].x, o.positions.size(), sizeof(glm::vec3));
    std::vector<std::uint32_t> out(o.indices.size());
    // meshoptimizer's error is relative to the mesh's extent (its scale).
    const float relative_error = scale > 0.0f ? float(max_error / double(scale)) : 0.0f;
    out.resize(meshopt_simplify(out.data(), o.indices.data(), o.indices.size(), &o.positions[0].x, o.positions.size(),
                                sizeof(glm::vec3), target, relative_error, 0, nullptr));
    return out;
}

bool shrink(const TriangleMesh& o, const std::vector<glm::dvec3>& normals, const std::vector<std::uint32_t>& indices,
            double margin, double sign, TriangleMesh& out) {
    std::vector<glm::vec3> moved(o.positions.size());
    std::vector<std::uint8_t> done(o.positions.size(), 0);
    for (std::uint32_t v : indices) {
        if (done[v]) continue;
        done[v] = 1;
        const double length = glm::length(normals[v]);
        if (!(length > 0.0) || !std::isfinite(length)) return false;
        moved[v] = glm::vec3(glm::dvec3(o.positions[v]) + normals[v] * (sign * margin / length));
        if (!(glm::length(glm::dvec3(moved[v]) - glm::dvec3(o.positions[v])) >= 0.5 * margin)) return false;
    }
    std::vector<std::uint32_t> compact(o.positions.size(), kUnset);
    out.positions.clear();
    out.indices.clear();
    for (std::size_t t = 0; t < indices.size(); t += 3) {
        if (triangle_cross(moved, &indices[t]) == glm::dvec3(0.0)) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = indices[t + std::size_t(k)];
            if (compact[v] == kUnset) {
                compact[v] = std::uint32_t(out.positions.size());
                out.positions.push_back(moved[v]);
            }
            out.indices.push_back(compact[v]);
        }
    }
    return !out.indices.empty();
}

}  // namespace homcull::detail::lod
