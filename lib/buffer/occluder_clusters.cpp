#include <homcull/detail/memory.hpp>
#include <homcull/error.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "common/float_mode.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <vector>

namespace homcull {
namespace {

// A triangle's three vertex numbers and its input number: sorted by vertices (then number),
// they find which input triangle a meshlet triangle is (meshopt_buildMeshlets keeps each
// triangle's vertices in order but not its number).
struct NumberedTriangle {
    std::uint32_t v[3];
    std::uint32_t number;
    bool same_vertices(const NumberedTriangle& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
    bool operator<(const NumberedTriangle& o) const {
        return std::tie(v[0], v[1], v[2], number) < std::tie(o.v[0], o.v[1], o.v[2], o.number);
    }
};

// meshoptimizer's temporary memory, from the hooks current on the calling thread (operator new
// without them, as meshoptimizer's default), so that clusters built for the C interface take
// every byte from the engine. meshoptimizer frees without a size: a header before each block
// keeps it and the hooks. Set once for the process; with no hooks current it does what
// meshoptimizer's default does.
constexpr std::size_t kMeshoptHeader = 16;
static_assert(sizeof(void*) + sizeof(std::size_t) <= kMeshoptHeader, "the header holds the hooks and the size");

void* meshopt_allocate(std::size_t size) {
    const detail::MemoryHooks* hooks = detail::current_memory_hooks();
    auto* block = static_cast<unsigned char*>(detail::hooked_allocate(hooks, size + kMeshoptHeader, kMeshoptHeader));
    std::memcpy(block, &hooks, sizeof hooks);
    std::memcpy(block + sizeof hooks, &size, sizeof size);
    return block + kMeshoptHeader;
}

void meshopt_deallocate(void* memory) {
    if (!memory) return;
    unsigned char* block = static_cast<unsigned char*>(memory) - kMeshoptHeader;
    const detail::MemoryHooks* hooks;
    std::size_t size;
    std::memcpy(&hooks, block, sizeof hooks);
    std::memcpy(&size, block + sizeof hooks, sizeof size);
    detail::hooked_deallocate(hooks, block, size + kMeshoptHeader, kMeshoptHeader);
}

void route_meshopt_memory() {
    static const bool routed = (meshopt_setAllocator(meshopt_allocate, meshopt_deallocate), true);
    (void)routed;
}

}  // namespace

void check_cluster_limits(const ClusterLimits& limits, const char* caller) {
    if (limits.max_vertices < 3 || limits.max_vertices > 255) throw Error(std::string(caller) + ": max_vertices must be in [3, 255]");
    if (limits.max_triangles < 4 || limits.max_triangles > 512 || limits.max_triangles % 4 != 0)
        throw Error(std::string(caller) + ": max_triangles must be a multiple of 4 in [4, 512]");
}

namespace {

// plan_occluder_clusters, its errors naming `caller`.
OccluderClusterPlan plan_clusters(const char* caller, const float* positions, std::size_t position_stride, std::size_t vertex_count,
                                  const std::uint32_t* indices, std::size_t triangle_count, const ClusterLimits& limits) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const auto fail = [&](const std::string& why) { throw Error(std::string(caller) + ": " + why); };
    check_cluster_limits(limits, caller);
    OccluderClusterPlan plan;
    plan.vertex_count = vertex_count;
    plan.triangle_count = triangle_count;
    plan.vertex_begin.push_back(0);
    plan.triangle_begin.push_back(0);
    if (triangle_count == 0) return plan;
    if (!positions || !indices) fail("positions or indices missing");
    if (position_stride < 3 * sizeof(float)) fail("position stride smaller than one position (12 bytes)");
    for (std::size_t i = 0; i < 3 * triangle_count; ++i)
        if (indices[i] >= vertex_count)
            fail("index " + std::to_string(indices[i]) + " of triangle " + std::to_string(i / 3) + " is not below vertex_count " +
                 std::to_string(vertex_count));

    // meshopt_buildMeshlets reads packed x, y, z. meshoptimizer sorts positions spatially: it
    // sees non-finite ones as the origin (the clusters keep them as they are, and their boxes
    // say so).
    detail::Vector<float> finite(3 * vertex_count);
    for (std::size_t v = 0; v < vertex_count; ++v) {
        std::memcpy(&finite[3 * v], reinterpret_cast<const unsigned char*>(positions) + v * position_stride, 3 * sizeof(float));
        for (std::size_t k = 0; k < 3; ++k)
            if (!std::isfinite(finite[3 * v + k])) finite[3 * v + k] = 0.0f;
    }

    const std::size_t index_count = 3 * triangle_count;
    detail::Vector<meshopt_Meshlet> meshlets(meshopt_buildMeshletsBound(index_count, limits.max_vertices, limits.max_triangles));
    detail::Vector<unsigned int> meshlet_vertices(meshlets.size() * limits.max_vertices);
    detail::Vector<unsigned char> meshlet_triangles(meshlets.size() * limits.max_triangles * 3);
    route_meshopt_memory();
    // cone_weight 0: clusters as compact in space as it can make them (their boxes are what the
    // render tests), not grouped by facing.
    meshlets.resize(meshopt_buildMeshlets(meshlets.data(), meshlet_vertices.data(), meshlet_triangles.data(), indices, index_count,
                                          finite.data(), vertex_count, 3 * sizeof(float), limits.max_vertices, limits.max_triangles, 0.0f));

    // The input triangles sorted by their vertices (a repeated triangle: its copies in input
    // order), each handed out once. One sorted array rather than a list per triangle: the
    // scene culler builds the clusters of every occluder at load time. Sorted by first vertex
    // with a counting sort, then each first vertex's few triangles by the other two, so that a
    // meshlet triangle is searched for among those alone (a search of the whole array missed
    // the cache at every step).
    detail::Vector<std::uint32_t> first_vertex_begin(vertex_count + 1, 0);
    for (std::size_t t = 0; t < triangle_count; ++t) ++first_vertex_begin[indices[3 * t] + 1];
    for (std::size_t v = 0; v < vertex_count; ++v) first_vertex_begin[v + 1] += first_vertex_begin[v];
    detail::Vector<NumberedTriangle> by_vertices(triangle_count);
    {
        detail::Vector<std::uint32_t> fill(first_vertex_begin.begin(), first_vertex_begin.end() - 1);
        for (std::size_t t = 0; t < triangle_count; ++t)
            by_vertices[fill[indices[3 * t]]++] = {{indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]}, std::uint32_t(t)};
    }
    for (std::size_t v = 0; v < vertex_count; ++v)
        std::sort(by_vertices.begin() + first_vertex_begin[v], by_vertices.begin() + first_vertex_begin[v + 1]);
    detail::Vector<std::uint32_t> handed_out(triangle_count, 0);  // at a run's first entry: how many of the run are taken

    std::size_t cluster_vertices = 0;
    for (const meshopt_Meshlet& m : meshlets) cluster_vertices += m.vertex_count;
    plan.vertices.reserve(cluster_vertices);
    plan.vertex_begin.reserve(meshlets.size() + 1);
    plan.local_indices.reserve(index_count);
    plan.source_triangles.reserve(triangle_count);
    plan.triangle_begin.reserve(meshlets.size() + 1);
    for (const meshopt_Meshlet& m : meshlets) {
        const unsigned int* vertices = meshlet_vertices.data() + m.vertex_offset;
        const unsigned char* local = meshlet_triangles.data() + m.triangle_offset;
        plan.vertices.insert(plan.vertices.end(), vertices, vertices + m.vertex_count);
        plan.vertex_begin.push_back(std::uint32_t(plan.vertices.size()));
        plan.local_indices.insert(plan.local_indices.end(), local, local + 3 * m.triangle_count);
        for (unsigned t = 0; t < m.triangle_count; ++t) {
            const NumberedTriangle key{{vertices[local[3 * t]], vertices[local[3 * t + 1]], vertices[local[3 * t + 2]]}, 0};
            const auto bucket_end = by_vertices.begin() + first_vertex_begin[key.v[0] + 1];
            const auto found = std::lower_bound(by_vertices.begin() + first_vertex_begin[key.v[0]], bucket_end, key);
            const std::size_t run = std::size_t(found - by_vertices.begin()), end = std::size_t(bucket_end - by_vertices.begin());
            const std::size_t next = run + (run < end ? handed_out[run] : 0);
            if (run == end || next >= end || !by_vertices[next].same_vertices(key))
                fail("meshoptimizer changed a triangle (internal error)");
            ++handed_out[run];
            plan.source_triangles.push_back(by_vertices[next].number);
        }
        plan.triangle_begin.push_back(std::uint32_t(plan.source_triangles.size()));
    }
    if (plan.source_triangles.size() != triangle_count)
        fail("meshoptimizer left out " + std::to_string(triangle_count - plan.source_triangles.size()) + " triangles (internal error)");
    return plan;
}

}  // namespace

OccluderClusterPlan plan_occluder_clusters(const float* positions, std::size_t position_stride, std::size_t vertex_count,
                                           const std::uint32_t* indices, std::size_t triangle_count, const ClusterLimits& limits) {
    return plan_clusters("plan_occluder_clusters", positions, position_stride, vertex_count, indices, triangle_count, limits);
}

OccluderClusters build_occluder_clusters(const OccluderClusterPlan& plan, const float* positions, std::size_t position_stride,
                                         const std::uint8_t* shared_edges, const std::uint32_t* edge_apexes) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const auto fail = [](const std::string& why) { throw Error("build_occluder_clusters: " + why); };
    OccluderClusters out;
    if (plan.triangle_count == 0) return out;
    if (!positions) fail("positions missing");
    if (position_stride < 3 * sizeof(float)) fail("position stride smaller than one position (12 bytes)");
    if (shared_edges && !edge_apexes) fail("shared_edges without edge_apexes (compute_shared_edges writes both)");
    // A plan is a struct anyone can fill: one that does not hold together is refused before
    // anything is read through it.
    const std::size_t vertex_count = plan.vertex_count;
    if (plan.vertex_begin.empty() || plan.vertex_begin.size() != plan.triangle_begin.size() || plan.vertex_begin.front() != 0 ||
        plan.triangle_begin.front() != 0 || plan.vertex_begin.back() != plan.vertices.size() ||
        plan.triangle_begin.back() != plan.source_triangles.size() || plan.source_triangles.size() != plan.triangle_count ||
        plan.local_indices.size() != 3 * plan.triangle_count)
        fail("the plan's arrays do not fit together (plan_occluder_clusters makes them)");
    const std::size_t clusters = plan.vertex_begin.size() - 1;
    for (std::size_t c = 0; c < clusters; ++c) {
        if (plan.vertex_begin[c] > plan.vertex_begin[c + 1] || plan.triangle_begin[c] > plan.triangle_begin[c + 1] ||
            plan.vertex_begin[c + 1] - plan.vertex_begin[c] > 255)
            fail("cluster " + std::to_string(c) + " of the plan has its ranges out of order or more than 255 vertices");
        for (std::size_t i = 3 * std::size_t(plan.triangle_begin[c]); i < 3 * std::size_t(plan.triangle_begin[c + 1]); ++i)
            if (plan.local_indices[i] >= plan.vertex_begin[c + 1] - plan.vertex_begin[c])
                fail("cluster " + std::to_string(c) + " of the plan has a triangle corner past its vertices");
    }
    for (const std::uint32_t v : plan.vertices)
        if (v >= vertex_count) fail("the plan names vertex " + std::to_string(v) + " of " + std::to_string(vertex_count));
    for (const std::uint32_t t : plan.source_triangles)
        if (t >= plan.triangle_count) fail("the plan names triangle " + std::to_string(t) + " of " + std::to_string(plan.triangle_count));
    const auto position = [&](std::uint32_t v) {  // copied: a stride need not keep floats aligned
        std::array<float, 3> p;
        std::memcpy(p.data(), reinterpret_cast<const unsigned char*>(positions) + std::size_t(v) * position_stride, sizeof p);
        return p;
    };

    // Positions: each cluster's vertices, and up to one copy per shared edge of an apex from
    // another cluster (reserved, so that the array is not copied at every doubling).
    std::size_t cluster_vertices = plan.vertices.size();
    for (std::size_t t = 0; t < plan.triangle_count && shared_edges; ++t) cluster_vertices += std::size_t(__builtin_popcount(shared_edges[t] & 7u));
    out.positions.reserve(3 * cluster_vertices);
    out.indices.reserve(3 * plan.triangle_count);
    out.shared_edges.reserve(plan.triangle_count);
    out.source_triangles.reserve(plan.triangle_count);
    out.clusters.reserve(clusters);
    out.edge_apexes.reserve(3 * plan.triangle_count);
    // Each input vertex's number in the cluster being appended (kNotInCluster: none; reset after
    // each cluster), to find an apex among the cluster's vertices at once.
    constexpr std::uint32_t kNotInCluster = 0xFFFFFFFFu;
    detail::Vector<std::uint32_t> local_of(vertex_count, kNotInCluster);
    detail::Vector<std::uint32_t> vertices;  // the cluster's input vertices, then its apex copies
    for (std::size_t cluster = 0; cluster < clusters; ++cluster) {
        vertices.assign(plan.vertices.begin() + plan.vertex_begin[cluster], plan.vertices.begin() + plan.vertex_begin[cluster + 1]);
        const std::uint32_t first_triangle = plan.triangle_begin[cluster], end_triangle = plan.triangle_begin[cluster + 1];
        OccluderCluster c;
        c.first_vertex = std::uint32_t(out.positions.size() / 3);
        c.first_triangle = std::uint32_t(out.shared_edges.size());
        c.triangle_count = end_triangle - first_triangle;
        c.bounded = true;
        for (std::size_t i = 0; i < vertices.size(); ++i) local_of[vertices[i]] = std::uint32_t(i);
        for (const std::uint32_t v : vertices) {
            const std::array<float, 3> p = position(v);
            out.positions.insert(out.positions.end(), p.begin(), p.end());
            c.bounded = c.bounded && std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
            c.bounds.extend(glm::vec3(p[0], p[1], p[2]));
        }
        out.indices.insert(out.indices.end(), plan.local_indices.begin() + 3 * std::ptrdiff_t(first_triangle),
                           plan.local_indices.begin() + 3 * std::ptrdiff_t(end_triangle));
        // The triangles' flags, then the apexes they need: one of the cluster's vertices, or a
        // copy appended after them.
        for (std::uint32_t i = first_triangle; i < end_triangle; ++i) {
            const std::uint32_t t = plan.source_triangles[i];
            const std::uint8_t flags = shared_edges ? shared_edges[t] : 0;
            out.shared_edges.push_back(flags);
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t apex = (flags >> k) & 1u ? edge_apexes[3 * std::size_t(t) + std::size_t(k)] : kNoApex;
                if (apex >= vertex_count) {  // none, or out of range: the render drops the flag
                    out.edge_apexes.push_back(kNoApex);
                    continue;
                }
                if (local_of[apex] != kNotInCluster) {
                    out.edge_apexes.push_back(local_of[apex]);
                    continue;
                }
                out.edge_apexes.push_back(local_of[apex] = std::uint32_t(vertices.size()));
                vertices.push_back(apex);
                const std::array<float, 3> p = position(apex);
                out.positions.insert(out.positions.end(), p.begin(), p.end());
            }
        }
        c.vertex_count = std::uint32_t(vertices.size());
        for (const std::uint32_t v : vertices) local_of[v] = kNotInCluster;
        out.source_triangles.insert(out.source_triangles.end(), plan.source_triangles.begin() + first_triangle,
                                    plan.source_triangles.begin() + end_triangle);
        out.max_cluster_vertices = std::max(out.max_cluster_vertices, c.vertex_count);
        out.clusters.push_back(c);
    }
    return out;
}

OccluderClusters build_occluder_clusters(const float* positions, std::size_t position_stride, std::size_t vertex_count,
                                         const std::uint32_t* indices, std::size_t triangle_count, const std::uint8_t* shared_edges,
                                         const std::uint32_t* edge_apexes, const ClusterLimits& limits) {
    // The checks in the order they always ran: the limits, then the mesh, then the flags.
    check_cluster_limits(limits);
    if (triangle_count == 0) return {};
    if (!positions || !indices) throw Error("build_occluder_clusters: positions or indices missing");
    if (position_stride < 3 * sizeof(float)) throw Error("build_occluder_clusters: position stride smaller than one position (12 bytes)");
    if (shared_edges && !edge_apexes) throw Error("build_occluder_clusters: shared_edges without edge_apexes (compute_shared_edges writes both)");
    const OccluderClusterPlan plan =
        plan_clusters("build_occluder_clusters", positions, position_stride, vertex_count, indices, triangle_count, limits);
    return build_occluder_clusters(plan, positions, position_stride, shared_edges, edge_apexes);
}

}  // namespace homcull
