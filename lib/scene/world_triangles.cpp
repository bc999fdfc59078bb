#include <homcull/world_triangles.hpp>

#include "common/float_mode.hpp"
#include "scene/coplanar_merge.hpp"

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

WorldTriangles gather_world_triangles(const Scene& scene, const std::vector<std::uint32_t>& objects, const glm::dvec3& anchor,
                                      bool merge_coplanar) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    WorldTriangles out;
    for (std::uint32_t id : objects) {
        const Object& object = scene.objects.at(id);
        const Mesh& mesh = scene.meshes[object.mesh];
        const auto base = std::uint32_t(out.positions.size() / 3);
        append_world_positions(scene, object, out.positions, anchor);
        const std::size_t first = out.indices.size();
        for (std::uint32_t index : mesh.indices) out.indices.push_back(base + index);
        if (merge_coplanar) {
            // On the world positions, rounded as drawn and as ground truth casts at them: the
            // merged regions are exactly those triangles' regions.
            const std::size_t kept = detail::merge_coplanar_triangles(out.positions.data(), out.indices.data() + first, mesh.triangle_count());
            out.indices.resize(first + 3 * kept);
        }
        out.object_first_triangle.push_back(std::uint32_t(out.indices.size() / 3));
    }
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
