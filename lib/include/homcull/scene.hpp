#pragma once
// The scene model every tool works on: meshes, and objects that place a mesh in the world.
// A mesh used by many objects is stored once (the castle places 437 meshes 2,114 times).
// Object ids are indices into Scene::objects, in the order of DESIGN.md's convention.
#include <homcull/aabb.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace homcull {

// "No object": the id of a sample that sees nothing.
inline constexpr std::uint32_t kNoObject = 0xFFFFFFFFu;

struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;
    std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise front faces

    std::size_t triangle_count() const { return indices.size() / 3; }
};

struct Object {
    std::string name;
    std::uint32_t mesh = 0;
    glm::dmat4 world{1.0};  // model to world
    Aabb world_bounds;      // of the transformed vertices the mesh's triangles use
    // Application data from the file (glTF node extras such as the castle's set and role);
    // keys sorted, string values as they are, other JSON values as their JSON text.
    std::vector<std::pair<std::string, std::string>> extras;

    // The value of an extra, or nullptr.
    const std::string* extra(std::string_view key) const;
};

struct Scene {
    std::string source;  // file path or generator spec, for messages
    std::vector<Mesh> meshes;
    std::vector<Object> objects;

    std::size_t triangle_count(const Object& object) const {
        return meshes[object.mesh].triangle_count();
    }
    // Triangles stored once per mesh, and triangles as placed in the world.
    std::size_t unique_triangle_count() const;
    std::size_t instanced_triangle_count() const;
    Aabb bounds() const;

    // Checks that every object names a mesh and every index names a vertex (throws
    // homcull::Error naming the source, the mesh and the bad index), then computes every
    // object's world_bounds, and makes names and extras valid UTF-8 (invalid bytes become U+FFFD:
    // they reach glTF and JSON). Importers and generators call it last.
    void finalize();
};

// The world-space position of a model-space vertex, computed in double and rounded to float:
// the one definition used by ground truth, bounds and (later) the rasterizer's input.
glm::vec3 transform_point(const glm::dmat4& world, const glm::vec3& p);

// The scene moved by `offset`, as by a parent node translating it: every object's world
// matrix is translate(offset) * world, in double; ids and meshes unchanged.
Scene translated_scene(const Scene& scene, const glm::dvec3& offset);

// Where the culler and ground truth put their floats' origin: the centre of the scene's bounds
// (the origin for an empty scene or infinite bounds). World positions rounded to float lose
// 2^-24 of their distance from the origin they are taken from: at 1e4 from the world's origin
// that is 5e-4, enough to open or close one-pixel cracks; taken from the anchor it is 2^-24 of
// the scene's extent, wherever the scene lies.
glm::dvec3 scene_anchor(const Scene& scene);
// transform_point relative to an anchor: the world position minus the anchor, in double, then
// rounded to float. The one definition of "a vertex as the culler and ground truth see it".
glm::vec3 transform_point_from(const glm::dmat4& world, const glm::vec3& p, const glm::dvec3& anchor);
// A world box relative to an anchor, rounded outwards: it holds every anchored point of the
// objects inside the world box (and the world box itself, moved).
Aabb anchored_box(const Aabb& world_box, const glm::dvec3& anchor);

}  // namespace homcull
