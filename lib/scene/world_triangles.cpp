#include <homcull/world_triangles.hpp>

#include "common/float_mode.hpp"
#include "scene/coplanar_merge.hpp"

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

void append_world_positions(const Scene& scene, const Object& object, std::vector<float>& positions, const glm::dvec3& anchor) {
    for (const glm::vec3& p : scene.meshes[object.mesh].positions) {
        const glm::vec3 w = transform_point_from(object.world, p, anchor);
        positions.insert(positions.end(), {w.x, w.y, w.z});
    }
}

namespace {

// Each object's coplanar regions merged (merge_coplanar_triangles), on the world positions,
// rounded as drawn and as ground truth casts at them: the merged regions are exactly those
// triangles' regions. A vertex whose position another object's triangles use stays, so that the
// edges objects share stay shared.
void merge_coplanar_regions(WorldTriangles& w) {
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
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> first{0};
    for (std::size_t k = 0; k < objects; ++k) {
        const std::size_t begin = 3 * std::size_t(w.object_first_triangle[k]), end = 3 * std::size_t(w.object_first_triangle[k + 1]);
        std::vector<std::uint32_t> own(w.indices.begin() + std::ptrdiff_t(begin), w.indices.begin() + std::ptrdiff_t(end));
        own.resize(3 * detail::merge_coplanar_triangles(w.positions.data(), own.data(), own.size() / 3, keep.data()));
        indices.insert(indices.end(), own.begin(), own.end());
        first.push_back(std::uint32_t(indices.size() / 3));
    }
    w.indices = std::move(indices);
    w.object_first_triangle = std::move(first);
}

}  // namespace

WorldTriangles gather_world_triangles(const Scene& scene, const std::vector<std::uint32_t>& objects, const glm::dvec3& anchor,
                                      bool merge_coplanar) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    WorldTriangles out;
    for (std::uint32_t id : objects) {
        const Object& object = scene.objects.at(id);
        const Mesh& mesh = scene.meshes[object.mesh];
        const auto base = std::uint32_t(out.positions.size() / 3);
        append_world_positions(scene, object, out.positions, anchor);
        for (std::uint32_t index : mesh.indices) out.indices.push_back(base + index);
        out.object_first_triangle.push_back(std::uint32_t(out.indices.size() / 3));
    }
    if (merge_coplanar) merge_coplanar_regions(out);
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
