#pragma once
// Which occluder candidates can share one cluster plan (docs/scene-culling.md, "Placements
// share their plan"): those placing the same mesh with the same triangles, numbered from their
// first vertex. The plan (which triangles and vertices each cluster takes) depends on those
// alone; each placement then builds its clusters from its own world positions and flags.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace homcull::detail {

// A candidate's triangles relative to its first vertex: indices in [0, vertices), the
// candidate's own vertices being `base` onwards in the culler's positions.
struct LocalTriangles {
    std::uint32_t base = 0;
    std::size_t vertices = 0;
    std::vector<std::uint32_t> indices;
};

// The grouping key of a candidate's mesh and local triangles: equal for equal ones, and rarely
// equal otherwise.
using TrianglesKey = std::uint64_t (*)(std::uint32_t mesh, const LocalTriangles& triangles);
std::uint64_t triangles_key(std::uint32_t mesh, const LocalTriangles& triangles);

// For each candidate k, the first candidate with the same mesh (mesh_of) and the same local
// triangles (vertex count and index list), k itself when none comes before it: the candidates
// whose entry is themselves make the plans. Depends only on the candidates' order. Candidates
// are grouped by `key` and compared in full only within a group, so that many placements of one
// mesh with differing triangles cost linear time, not quadratic. (The tests pass a key that
// groups everything, to reach the full comparison that equal keys of differing triangles need.)
std::vector<std::uint32_t> first_with_same_triangles(const std::vector<std::uint32_t>& mesh_of, const std::vector<LocalTriangles>& local,
                                                     TrianglesKey key = &triangles_key);

}  // namespace homcull::detail
