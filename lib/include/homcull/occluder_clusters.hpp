#pragma once
// An occluder mesh split once, when it is loaded, into clusters of nearby triangles (the
// meshlets of meshoptimizer's meshopt_buildMeshlets), each with its own vertices and bounding
// box. OcclusionBuffer::render(ClusteredInput) then decides whole clusters before setting up
// any of their triangles: those outside the view are dropped, the rest are drawn nearest
// first, and a cluster whose box lies behind what nearer clusters already drew (in a band of
// the buffer) is skipped there. That is Greene's hierarchical Z-buffer culling of octree
// cubes front to back (Greene, Kass and Miller, "Hierarchical Z-Buffer Visibility",
// SIGGRAPH 1993), with a flat list of clusters in place of the octree.
//
// Building is not an offline bake: it runs at load time, in time linear in the mesh (half of
// it in meshoptimizer), and keeps every triangle and vertex bit for bit.
#include <homcull/aabb.hpp>
#include <homcull/detail/memory.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace homcull {

struct OccluderCluster {
    std::uint32_t first_vertex = 0, vertex_count = 0;      // in OccluderClusters::positions
    std::uint32_t first_triangle = 0, triangle_count = 0;  // in indices (3 each) and shared_edges
    Aabb bounds;   // of its vertices
    bool bounded = false;  // false when a vertex is not finite (or unknown): the box says nothing, the cluster is always drawn
};

// Its arrays come from the memory hooks current where it was built (homcull/detail/memory.hpp):
// operator new, unless the C interface builds it.
struct OccluderClusters {
    detail::Vector<float> positions;            // x, y, z per vertex; each cluster's vertices together
    detail::Vector<std::uint16_t> indices;      // 3 per triangle, relative to its cluster's first vertex
    detail::Vector<std::uint8_t> shared_edges;  // one per triangle, as TriangleInput::shared_edges
    // Three per triangle, as TriangleInput::edge_apexes, numbered within the triangle's cluster
    // (from its first_vertex): a cluster's vertices end with copies of the apexes its triangles
    // need that none of them uses (never part of its box).
    detail::Vector<std::uint32_t> edge_apexes;
    detail::Vector<std::uint32_t> source_triangles;  // one per triangle: its number in the input mesh
    detail::Vector<OccluderCluster> clusters;
    std::uint32_t max_cluster_vertices = 0;  // the largest vertex_count (information: render does not rely on it)

    std::size_t triangle_count() const { return shared_edges.size(); }
};

// meshopt_buildMeshlets' limits: at most 255 vertices, and at most 512 triangles, a multiple of 4.
struct ClusterLimits {
    std::size_t max_vertices = 64;
    std::size_t max_triangles = 124;
};
// Throws homcull::Error, naming `caller`, for limits meshopt_buildMeshlets does not accept
// (build_occluder_clusters' own check, for callers that want it before loading a mesh).
void check_cluster_limits(const ClusterLimits& limits, const char* caller = "build_occluder_clusters");

// How a mesh splits into clusters, apart from where its vertices are: each cluster's input
// vertices and input triangles, in order. plan_occluder_clusters makes it (meshoptimizer's
// meshlets: most of the work of a build); build_occluder_clusters(plan, ...) makes the clusters
// from it and any positions of the mesh's vertices, so that a mesh placed many times is split
// once. Its arrays come from the memory hooks current where it was made.
struct OccluderClusterPlan {
    std::size_t vertex_count = 0, triangle_count = 0;  // of the mesh planned
    detail::Vector<std::uint32_t> vertices;            // each cluster's input vertices, cluster by cluster
    detail::Vector<std::uint32_t> vertex_begin;        // cluster c's are [vertex_begin[c], vertex_begin[c + 1])
    detail::Vector<std::uint8_t> local_indices;        // 3 per cluster triangle, into its cluster's vertices
    detail::Vector<std::uint32_t> source_triangles;    // per cluster triangle, its input triangle
    detail::Vector<std::uint32_t> triangle_begin;      // cluster c's are [triangle_begin[c], triangle_begin[c + 1])
};

// The plan of build_occluder_clusters(positions, ...) below; the same checks and errors (the
// shared edges are not needed yet).
OccluderClusterPlan plan_occluder_clusters(const float* positions, std::size_t position_stride, std::size_t vertex_count,
                                           const std::uint32_t* indices, std::size_t triangle_count, const ClusterLimits& limits = {});

// The clusters of a plan, with these positions of the planned mesh's vertex_count vertices and
// these shared-edge bits and apexes of its triangles (as below). A plan made from the same
// positions gives build_occluder_clusters(positions, ...)'s clusters, bit for bit; other
// positions keep the plan's clusters (whose boxes are then these positions'). Throws
// homcull::Error on a stride smaller than a position, flags without apexes, or a plan whose
// arrays do not fit together or name vertices or triangles it does not have.
OccluderClusters build_occluder_clusters(const OccluderClusterPlan& plan, const float* positions, std::size_t position_stride,
                                         const std::uint8_t* shared_edges, const std::uint32_t* edge_apexes);

// Splits an indexed triangle mesh (x, y, z floats every position_stride bytes; 32-bit indices)
// into clusters. Each triangle keeps its vertices in order and its shared-edge bits and their
// apexes (compute_shared_edges'; both null: none shared); triangles and vertices are reordered
// cluster by cluster, and a vertex used by several clusters (or the apex of a neighbour in
// another cluster) is copied into each. Meant for load time: it allocates. Throws
// homcull::Error on an index out of range, a stride smaller than a position, or limits that
// meshopt_buildMeshlets does not accept.
OccluderClusters build_occluder_clusters(const float* positions, std::size_t position_stride, std::size_t vertex_count,
                                         const std::uint32_t* indices, std::size_t triangle_count, const std::uint8_t* shared_edges,
                                         const std::uint32_t* edge_apexes, const ClusterLimits& limits = {});

}  // namespace homcull
