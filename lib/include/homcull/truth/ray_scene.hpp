#pragma once
// An Embree 3 ray-tracing scene built from a homcull::Scene: the ground truth every culling
// answer is measured against. Each object becomes one Embree triangle geometry whose
// geometry id is the object id, with its vertices transformed to world space in double, taken
// relative to the scene's anchor (scene_anchor) and rounded to float (transform_point_from), as
// the scene culler takes them: edges shared between objects stay watertight, and a scene moved
// far from the origin keeps its precision (the rays' origins are made relative the same way).
// Instanced meshes are expanded here on purpose: exactness matters more than memory for
// ground truth (the castle's 1.07M placed triangles take about 100 MB).
#include <homcull/scene.hpp>

#include <cstdint>
#include <memory>

namespace homcull {

struct RayHit {
    std::uint32_t object = kNoObject;  // when nothing was hit
    float t = 0.0f;                      // ray parameter of the hit
    glm::vec3 normal{0.0f};              // geometric normal, unnormalized, CCW front side
    bool hit() const { return object != kNoObject; }
};

class RayScene {
public:
    // Throws homcull::Error when Embree cannot be set up or the scene cannot be built.
    explicit RayScene(const Scene& scene);
    // With the vertices relative to a given anchor: for ray scenes whose hits are compared with
    // each other's (a scene and a part of it, a mesh and its LOD), which must round alike.
    RayScene(const Scene& scene, const glm::dvec3& anchor);
    ~RayScene();
    RayScene(RayScene&&) noexcept;
    RayScene& operator=(RayScene&&) noexcept;
    RayScene(const RayScene&) = delete;
    RayScene& operator=(const RayScene&) = delete;

    // Closest hit with t in [t_near, t_far] (back faces count), from a world-space origin (made
    // relative to the anchor in double, then rounded). Thread-safe.
    RayHit intersect(const glm::dvec3& origin, const glm::vec3& direction, float t_near, float t_far) const;
    RayHit intersect(const glm::vec3& origin, const glm::vec3& direction, float t_near, float t_far) const {
        return intersect(glm::dvec3(origin), direction, t_near, t_far);
    }
    // The point the Embree vertices are relative to (scene_anchor of the scene).
    glm::dvec3 anchor() const;

    std::size_t object_count() const;
    struct Impl;
    const Impl& impl() const { return *impl_; }

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace homcull
