#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/scene_sort.hpp>

#include <glm/gtc/matrix_transform.hpp>

namespace homcull {

VisibilitySorter make_visibility_sorter(const Scene& scene, std::size_t hull_points) {
    std::vector<detail::Vector<glm::vec3>> hulls;
    hulls.reserve(scene.meshes.size());
    std::vector<glm::vec3> used;
    std::vector<char> seen;
    for (const Mesh& mesh : scene.meshes) {
        used.clear();
        seen.assign(mesh.positions.size(), 0);
        for (std::uint32_t i : mesh.indices) {
            if (i >= mesh.positions.size())
                throw Error("make_visibility_sorter: mesh '" + mesh.name + "' names vertex " + std::to_string(i) + " of " +
                            std::to_string(mesh.positions.size()));
            if (!seen[i]) seen[i] = 1, used.push_back(mesh.positions[i]);
        }
        if (used.empty()) used.emplace_back(0.0f);
        hulls.push_back(convex_hull_points(used.data(), used.size(), hull_points));
    }
    std::vector<HullPoints> views;
    for (const auto& hull : hulls) views.push_back({hull.data(), hull.size()});
    std::vector<std::uint32_t> shapes;
    shapes.reserve(scene.objects.size());
    for (const Object& object : scene.objects) shapes.push_back(object.mesh);
    return VisibilitySorter(views.data(), views.size(), shapes.data(), shapes.size());
}

void sort_transforms(const Scene& scene, const glm::dvec3& origin, std::vector<glm::mat4>& out) {
    out.resize(scene.objects.size());
    const glm::dmat4 shift = glm::translate(glm::dmat4(1.0), -origin);
    for (std::size_t i = 0; i < scene.objects.size(); ++i) out[i] = glm::mat4(shift * scene.objects[i].world);
}

std::array<glm::vec4, 6> sort_frustum_planes(const Camera& camera, double aspect, const glm::dvec3& origin) {
    const Frustum frustum = make_frustum(camera, aspect);
    std::array<glm::vec4, 6> planes;
    for (std::size_t k = 0; k < 6; ++k) {
        // dot(n, p) + w >= 0 with p = p' + origin: dot(n, p') + (w + dot(n, origin)) >= 0.
        const glm::dvec4& p = frustum.planes[k];
        planes[k] = glm::vec4(glm::vec3(p), float(p.w + glm::dot(glm::dvec3(p), origin)));
    }
    return planes;
}

}  // namespace homcull
