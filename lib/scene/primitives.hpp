#pragma once
// Small meshes the scene generators place many times.
#include <homcull/scene.hpp>

#include <string>

namespace homcull::detail {

// Box with its base on y = 0: x and z in [-0.5, 0.5], y in [0, 1]; faces wound CCW outward.
Mesh make_box_mesh();
// Square x, z in [-0.5, 0.5] at y = 0, facing +y.
Mesh make_ground_mesh();
// A tree: hexagonal trunk (radius 0.25, height 3.2) under an octahedral crown centred at
// y = 5 (radius 1.8, half height 2.5). Closed, CCW outward.
Mesh make_tree_mesh();
inline constexpr double kTreeCrownRadius = 1.8;

// Model-to-world for a mesh scaled by `scale` and then moved to `position`.
glm::dmat4 place(const glm::dvec3& position, const glm::dvec3& scale);

// Appends an object with the generators' extras: role ("occluder"/"occludee") and set.
void add_object(Scene& scene, std::string name, std::uint32_t mesh, const glm::dmat4& world, const char* set,
                const char* role);

}  // namespace homcull::detail
