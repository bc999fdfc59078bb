// Step 1 of the occluder LOD build: welding by bytes (meshoptimizer's vertex remap), the split
// into parts (union-find over the vertices each triangle links), and each part's closedness
// check (every directed edge once and its reverse once, no zero-area triangle).
#include "truth/lod_mesh_parts.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>

namespace homcull::detail::lod {
namespace {

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// A zero-area triangle adds no surface but can make the edge count look closed (a sliver
// over a T-junction), so a part holding one is not trusted.
bool has_zero_area_triangle(const TriangleMesh& mesh) {
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        if (triangle_cross(mesh.positions, &mesh.indices[t]) == glm::dvec3(0.0)) return true;
    return false;
}

bool is_closed(const TriangleMesh& mesh) {
    std::vector<std::uint64_t> directed;
    directed.reserve(mesh.indices.size());
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) directed.push_back(edge_key(mesh.indices[t + k], mesh.indices[t + (k + 1) % 3]));
    std::sort(directed.begin(), directed.end());
    if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return false;
    for (std::uint64_t e : directed)
        if (!std::binary_search(directed.begin(), directed.end(), edge_key(std::uint32_t(e), std::uint32_t(e >> 32))))
            return false;
    return true;
}

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

}  // namespace

LodStatus weld(const Mesh& mesh, TriangleMesh& out) {
    if (mesh.indices.size() % 3 != 0) return LodStatus::invalid_geometry;
    if (mesh.indices.empty()) return LodStatus::empty;
    for (std::uint32_t i : mesh.indices)
        if (i >= mesh.positions.size() || !finite(mesh.positions[i])) return LodStatus::invalid_geometry;
    // By bytes, after turning -0 into +0 so that the two zeros weld. Unused non-finite
    // positions become 0: no triangle sees them.
    std::vector<glm::vec3> positions(mesh.positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v)
        positions[v] = finite(mesh.positions[v]) ? mesh.positions[v] + glm::vec3(0.0f) : glm::vec3(0.0f);
    std::vector<unsigned> remap(positions.size());
    const std::size_t unique = meshopt_generateVertexRemap(remap.data(), nullptr, positions.size(), positions.data(),
                                                           positions.size(), sizeof(glm::vec3));
    out.positions.resize(unique);
    meshopt_remapVertexBuffer(out.positions.data(), positions.data(), positions.size(), sizeof(glm::vec3),
                              remap.data());
    out.indices.resize(mesh.indices.size());
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) out.indices[i] = remap[mesh.indices[i]];
    return LodStatus::built;
}

std::vector<Part> split_into_parts(const TriangleMesh& welded) {
    std::vector<std::uint32_t> parent(welded.positions.size());
    for (std::uint32_t v = 0; v < parent.size(); ++v) parent[v] = v;
    for (std::size_t i = 0; i < welded.indices.size(); ++i) {
        const std::uint32_t a = find_root(parent, welded.indices[i]);
        const std::uint32_t b = find_root(parent, welded.indices[i - i % 3]);
        parent[a] = b;
    }
    std::vector<std::uint32_t> part_of_root(welded.positions.size(), kUnset), local(welded.positions.size(), kUnset);
    std::vector<Part> parts;
    for (std::size_t t = 0; t < welded.indices.size(); t += 3) {
        std::uint32_t& p = part_of_root[find_root(parent, welded.indices[t])];
        if (p == kUnset) {
            p = std::uint32_t(parts.size());
            parts.emplace_back();
        }
        TriangleMesh& mesh = parts[p].mesh;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = welded.indices[t + std::size_t(k)];
            if (local[v] == kUnset) {
                local[v] = std::uint32_t(mesh.positions.size());
                mesh.positions.push_back(welded.positions[v]);
            }
            mesh.indices.push_back(local[v]);
        }
    }
    for (Part& part : parts) {
        part.degenerate = has_zero_area_triangle(part.mesh);
        part.closed = !part.degenerate && is_closed(part.mesh);
    }
    return parts;
}

}  // namespace homcull::detail::lod
