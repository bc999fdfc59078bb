#include <homcull/error.hpp>
#include <homcull/scene.hpp>

#include <string>

namespace homcull {

const std::string* Object::extra(std::string_view key) const {
    for (const auto& [k, v] : extras)
        if (k == key) return &v;
    return nullptr;
}

std::size_t Scene::unique_triangle_count() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.triangle_count();
    return n;
}

std::size_t Scene::instanced_triangle_count() const {
    std::size_t n = 0;
    for (const auto& o : objects) n += triangle_count(o);
    return n;
}

Aabb Scene::bounds() const {
    Aabb b;
    for (const auto& o : objects) b.extend(o.world_bounds);
    return b;
}

glm::vec3 transform_point(const glm::dmat4& world, const glm::vec3& p) {
    // glTF node transforms are affine; the fourth row is not used.
    return glm::vec3(glm::dvec3(world * glm::dvec4(glm::dvec3(p), 1.0)));
}

void Scene::finalize() {
    for (std::size_t m = 0; m < meshes.size(); ++m) {
        const Mesh& mesh = meshes[m];
        if (mesh.indices.size() % 3 != 0)
            throw Error(source + ": mesh " + std::to_string(m) + " ('" + mesh.name +
                        "') has " + std::to_string(mesh.indices.size()) +
                        " indices, not a multiple of 3");
        for (std::uint32_t index : mesh.indices)
            if (index >= mesh.positions.size())
                throw Error(source + ": mesh " + std::to_string(m) + " ('" + mesh.name +
                            "') uses vertex " + std::to_string(index) + " but has only " +
                            std::to_string(mesh.positions.size()) + " vertices");
    }
    for (std::size_t i = 0; i < objects.size(); ++i) {
        Object& object = objects[i];
        if (object.mesh >= meshes.size())
            throw Error(source + ": object " + std::to_string(i) + " ('" + object.name +
                        "') names mesh " + std::to_string(object.mesh) + " but there are " +
                        std::to_string(meshes.size()));
        object.world_bounds = Aabb{};
        for (std::uint32_t index : meshes[object.mesh].indices)
            object.world_bounds.extend(transform_point(object.world, meshes[object.mesh].positions[index]));
    }
}

}  // namespace homcull
