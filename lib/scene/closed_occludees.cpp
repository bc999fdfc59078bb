// closed_occludee_orientations (closed_occludees.hpp): each mesh's topology once, in model space
// (which edges are shared, which triangles form a connected piece), then each object's pieces'
// volumes from its world positions, as ground truth has them.
#include "scene/closed_occludees.hpp"

#include "common/run_tasks.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace homcull::detail {
namespace {

// A mesh's closed pieces: whether every edge is shared in opposite order, and the piece of each
// triangle (connected to the others of its piece through shared edges: two closed surfaces that
// only touch at a vertex are two pieces, each with its own sign).
struct MeshPieces {
    bool closed = false;
    std::vector<std::uint32_t> piece;  // per triangle, in [0, count)
    std::uint32_t count = 0;
};

constexpr std::uint32_t kNoPiece = ~std::uint32_t(0);

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];  // path halving
    return v;
}

// One pass over the edges, matched by position through the positions' numbers (meshoptimizer's
// vertex remap on the positions with -0 made +0: equal numbers are equal positions under float
// ==, as compute_shared_edges matches them). The mesh is closed when every triangle is finite,
// has three distinct positions, and each of its edges is also met in the opposite direction
// (compute_shared_edges' flags all set); the triangles across each edge are joined.
MeshPieces mesh_pieces(const Mesh& mesh) {
    MeshPieces m;
    const std::size_t triangles = mesh.triangle_count(), vertices = mesh.positions.size();
    if (triangles == 0 || vertices == 0) return m;
    std::vector<glm::vec3> canonical(vertices);
    for (std::size_t v = 0; v < vertices; ++v) canonical[v] = mesh.positions[v] + glm::vec3(0.0f);  // -0 + 0 = +0
    for (const std::uint32_t index : mesh.indices)
        if (index >= vertices || !std::isfinite(canonical[index].x) || !std::isfinite(canonical[index].y) || !std::isfinite(canonical[index].z))
            return m;
    std::vector<unsigned> point(vertices);
    meshopt_generateVertexRemap(point.data(), nullptr, vertices, canonical.data(), vertices, sizeof(glm::vec3));

    // Open addressing on the edge's two numbers, lower first (never 0: the numbers differ), at
    // most half full: which directions were met, and the first triangle met.
    struct Slot {
        std::uint64_t key = 0;
        std::uint32_t triangle = 0;
        std::uint8_t directions = 0;
    };
    std::size_t capacity = 16;
    while (capacity < 6 * triangles) capacity *= 2;
    std::vector<Slot> table(capacity);
    const int shift = 64 - __builtin_ctzll(capacity);
    std::vector<std::uint32_t> parent(triangles);
    std::iota(parent.begin(), parent.end(), 0u);
    for (std::uint32_t t = 0; t < triangles; ++t)
        for (std::size_t k = 0; k < 3; ++k) {
            const std::uint32_t a = point[mesh.indices[3 * std::size_t(t) + k]], b = point[mesh.indices[3 * std::size_t(t) + (k + 1) % 3]];
            if (a == b) return m;  // a degenerate edge is shared with nothing
            const std::uint64_t key = std::uint64_t(std::min(a, b)) << 32 | std::max(a, b);
            std::size_t slot = std::size_t((key * 0x9E3779B97F4A7C15ull) >> shift);
            while (table[slot].key != 0 && table[slot].key != key) slot = (slot + 1) & (capacity - 1);
            Slot& s = table[slot];
            if (s.key == 0) s.key = key, s.triangle = t;
            else parent[find_root(parent, t)] = find_root(parent, s.triangle);
            s.directions |= a < b ? 1 : 2;
        }
    for (const Slot& s : table)
        if (s.key != 0 && s.directions != 3) return m;
    std::vector<std::uint32_t> number(triangles, kNoPiece);  // per root triangle
    m.piece.resize(triangles);
    for (std::uint32_t t = 0; t < triangles; ++t) {
        std::uint32_t& n = number[find_root(parent, t)];
        if (n == kNoPiece) n = m.count++;
        m.piece[t] = n;
    }
    m.closed = true;
    return m;
}

// +1, -1 or 0 for one object: the signed volume of each piece (the divergence theorem, each
// triangle's tetrahedron with a point of the piece) against the sum of the tetrahedra's absolute
// volumes: a sign counts when the volume is above 2^-20 of that sum (a flat or two-sided piece
// gives about 0).
std::int8_t object_orientation(const Mesh& mesh, const MeshPieces& pieces, const float* world) {
    std::vector<double> volume(pieces.count, 0.0), magnitude(pieces.count, 0.0);
    std::vector<glm::dvec3> origin(pieces.count);
    std::vector<std::uint8_t> has_origin(pieces.count, 0);
    const auto point = [&](std::uint32_t v) { return glm::dvec3(world[3 * std::size_t(v)], world[3 * std::size_t(v) + 1], world[3 * std::size_t(v) + 2]); };
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t p = pieces.piece[t];
        const glm::dvec3 a = point(mesh.indices[3 * t]), b = point(mesh.indices[3 * t + 1]), c = point(mesh.indices[3 * t + 2]);
        if (!has_origin[p]) origin[p] = a, has_origin[p] = 1;
        const double v = glm::dot(a - origin[p], glm::cross(b - origin[p], c - origin[p]));
        volume[p] += v;
        magnitude[p] += std::abs(v);
    }
    int sign = 0;
    for (std::uint32_t p = 0; p < pieces.count; ++p) {
        const int s = volume[p] > 0x1.0p-20 * magnitude[p] ? 1 : volume[p] < -0x1.0p-20 * magnitude[p] ? -1 : 0;
        if (s == 0 || (sign != 0 && s != sign)) return 0;
        sign = s;
    }
    return std::int8_t(sign);
}

}  // namespace

std::vector<std::int8_t> closed_occludee_orientations(const Scene& scene, const std::vector<float>& world_positions,
                                                      const std::vector<std::size_t>& first_vertex, std::size_t not_gathered,
                                                      const ParallelFor& parallel) {
    const std::size_t objects = std::min(scene.objects.size(), first_vertex.size());
    std::vector<std::uint8_t> needed(scene.meshes.size(), 0);
    for (std::size_t id = 0; id < objects; ++id)
        if (first_vertex[id] != not_gathered) needed[scene.objects[id].mesh] = 1;
    std::vector<MeshPieces> meshes(scene.meshes.size());
    for_each_index(parallel, scene.meshes.size(), 4, [&](std::size_t m) {
        if (needed[m]) meshes[m] = mesh_pieces(scene.meshes[m]);
    });
    std::vector<std::int8_t> orientation(scene.objects.size(), 0);
    for_each_index(parallel, objects, 16, [&](std::size_t id) {
        const std::size_t mesh_id = scene.objects[id].mesh;
        if (first_vertex[id] == not_gathered || !meshes[mesh_id].closed) return;
        orientation[id] = object_orientation(scene.meshes[mesh_id], meshes[mesh_id], world_positions.data() + 3 * first_vertex[id]);
    });
    return orientation;
}

}  // namespace homcull::detail
