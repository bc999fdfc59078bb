#include "scene/shared_plans.hpp"

#include <homcull/error.hpp>

#include <unordered_map>

namespace homcull::detail {
namespace {

// FNV-1a over the mesh, the vertex count and the indices, 64 bits: only a grouping key (equal
// keys are compared in full), so its quality only has to keep groups small.
std::uint64_t triangles_key(std::uint32_t mesh, const LocalTriangles& t) {
    std::uint64_t h = 14695981039346656037ull;
    const auto mix = [&h](std::uint64_t v) {
        for (int byte = 0; byte < 8; ++byte, v >>= 8) h = (h ^ (v & 0xffu)) * 1099511628211ull;
    };
    mix(mesh);
    mix(t.vertices);
    for (const std::uint32_t i : t.indices) mix(i);
    return h;
}

}  // namespace

std::vector<std::uint32_t> first_with_same_triangles(const std::vector<std::uint32_t>& mesh_of, const std::vector<LocalTriangles>& local) {
    if (mesh_of.size() != local.size())
        throw Error("first_with_same_triangles: " + std::to_string(mesh_of.size()) + " meshes for " + std::to_string(local.size()) +
                    " candidates");
    std::vector<std::uint32_t> first(local.size());
    // The planning candidates under each key: distinct from each other, so at most one matches.
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> planning;
    planning.reserve(local.size());
    for (std::size_t k = 0; k < local.size(); ++k) {
        std::vector<std::uint32_t>& group = planning[triangles_key(mesh_of[k], local[k])];
        first[k] = std::uint32_t(k);
        for (const std::uint32_t r : group)
            if (mesh_of[r] == mesh_of[k] && local[r].vertices == local[k].vertices && local[r].indices == local[k].indices) {
                first[k] = r;
                break;
            }
        if (first[k] == k) group.push_back(std::uint32_t(k));
    }
    return first;
}

}  // namespace homcull::detail
