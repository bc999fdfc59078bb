#include <homcull/world_triangles.hpp>

#include "common/float_mode.hpp"
#include "common/run_tasks.hpp"
#include "scene/coplanar_merge.hpp"
#include "scene/world_point.hpp"

#include <meshoptimizer.h>

namespace homcull {

TriangleInput WorldTriangles::input(const std::array<float, 16>& clip_from_world, Backface backface) const {
    TriangleInput in;
    in.positions = positions.data();
    in.vertex_count = positions.size() / 3;
    in.indices = indices.data();
    in.triangle_count = triangle_count();
    in.model_to_clip = clip_from_world;
    in.backface = backface;
    in.shared_edges = shared_edges.data();
    in.edge_apexes = edge_apexes.data();
    return in;
}

void write_world_positions(const Object& object, const Mesh& mesh, float* out, const glm::dvec3& anchor) {
    for (const glm::vec3& p : mesh.positions) {
        const glm::vec3 w = detail::world_point_from(object.world, p, anchor);
        *out++ = w.x, *out++ = w.y, *out++ = w.z;
    }
}

void append_world_positions(const Scene& scene, const Object& object, std::vector<float>& positions, const glm::dvec3& anchor) {
    const Mesh& mesh = scene.meshes[object.mesh];
    const std::size_t first = positions.size();
    positions.resize(first + 3 * mesh.positions.size());
    write_world_positions(object, mesh, positions.data() + first, anchor);
}

namespace {

// Each object's coplanar regions merged (merge_coplanar_triangles), on the world positions,
// rounded as drawn and as ground truth casts at them: the merged regions are exactly those
// triangles' regions. A vertex whose position another object's triangles use stays, so that the
// edges objects share stay shared.
void merge_coplanar_regions(WorldTriangles& w, const ParallelFor& parallel) {
    const std::size_t objects = w.object_first_triangle.size() - 1, vertices = w.positions.size() / 3;
    // One number per position, by bytes (meshoptimizer's vertex remap, as compute_shared_edges
    // matches positions by bits), and the object using it, or kMany.
    std::vector<unsigned> point(vertices);
    meshopt_generateVertexRemap(point.data(), nullptr, vertices, w.positions.data(), vertices, 3 * sizeof(float));
    constexpr std::uint32_t kNone = ~0u, kMany = ~0u - 1;
    std::vector<std::uint32_t> user(vertices, kNone);
    for (std::size_t k = 0; k < objects; ++k)
        for (std::size_t i = 3 * std::size_t(w.object_first_triangle[k]); i < 3 * std::size_t(w.object_first_triangle[k + 1]); ++i) {
            std::uint32_t& u = user[point[w.indices[i]]];
            u = u == kNone || u == k ? std::uint32_t(k) : kMany;
        }
    std::vector<std::uint8_t> keep(vertices);
    for (std::size_t i = 0; i < vertices; ++i) keep[i] = user[point[i]] == kMany;
    // Each object's merge on its own (its triangles, the shared positions and `keep` read only),
    // then the objects' triangles in their order.
    std::vector<std::vector<std::uint32_t>> merged(objects);
    detail::for_each_index(parallel, objects, 8, [&](std::size_t k) {
        const std::size_t begin = 3 * std::size_t(w.object_first_triangle[k]), end = 3 * std::size_t(w.object_first_triangle[k + 1]);
        std::vector<std::uint32_t>& own = merged[k];
        own.assign(w.indices.begin() + std::ptrdiff_t(begin), w.indices.begin() + std::ptrdiff_t(end));
        own.resize(3 * detail::merge_coplanar_triangles(w.positions.data(), own.data(), own.size() / 3, keep.data()));
    });
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> first{0};
    for (const std::vector<std::uint32_t>& own : merged) {
        indices.insert(indices.end(), own.begin(), own.end());
        first.push_back(std::uint32_t(indices.size() / 3));
    }
    w.indices = std::move(indices);
    w.object_first_triangle = std::move(first);
}

}  // namespace

WorldTriangles gather_world_triangles(const Scene& scene, const std::vector<std::uint32_t>& objects, const glm::dvec3& anchor,
                                      bool merge_coplanar, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    WorldTriangles out;
    // Where each object's vertices and triangles go, then each object's in a task of its own.
    std::vector<std::size_t> first_vertex(objects.size() + 1, 0);
    out.object_first_triangle.resize(objects.size() + 1);
    for (std::size_t k = 0; k < objects.size(); ++k) {
        const Mesh& mesh = scene.meshes[scene.objects.at(objects[k]).mesh];
        first_vertex[k + 1] = first_vertex[k] + mesh.positions.size();
        out.object_first_triangle[k + 1] = out.object_first_triangle[k] + std::uint32_t(mesh.triangle_count());
    }
    out.positions.resize(3 * first_vertex.back());
    out.indices.resize(3 * std::size_t(out.object_first_triangle.back()));
    detail::for_each_index(parallel, objects.size(), 8, [&](std::size_t k) {
        const Object& object = scene.objects[objects[k]];
        const Mesh& mesh = scene.meshes[object.mesh];
        write_world_positions(object, mesh, out.positions.data() + 3 * first_vertex[k], anchor);
        const auto base = std::uint32_t(first_vertex[k]);
        std::uint32_t* indices = out.indices.data() + 3 * std::size_t(out.object_first_triangle[k]);
        for (std::uint32_t index : mesh.indices) *indices++ = base + index;
    });
    if (merge_coplanar) merge_coplanar_regions(out, parallel);
    out.shared_edges.resize(out.triangle_count());
    out.edge_apexes.resize(out.indices.size());
    compute_shared_edges(out.positions.data(), 3 * sizeof(float), out.positions.size() / 3, out.indices.data(),
                         out.triangle_count(), out.shared_edges.data(), out.edge_apexes.data());
    return out;
}

std::vector<std::uint32_t> objects_with_role(const Scene& scene, std::string_view role) {
    std::vector<std::uint32_t> ids;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const std::string* r = scene.objects[i].extra("role");
        if (role.empty() || (r && *r == role)) ids.push_back(std::uint32_t(i));
    }
    return ids;
}

}  // namespace homcull
