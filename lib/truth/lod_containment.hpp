#pragma once
// Step 4 of the occluder LOD build (homcull/truth/occluder_lod_build.hpp): verify with Embree 3,
// in robust mode and in the mesh's model space, that a shrunk simplified copy S lies inside the
// solid of its closed part O: neither surface's edges meet the other's triangles, and S's
// vertices are inside O by the parity of ray crossings.
#include "truth/lod_triangle_mesh.hpp"

#include <embree3/rtcore.h>

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace homcull::detail::lod {

// One triangle mesh as an Embree scene, robust (no shortcuts that could miss a hit on an
// edge) and accepting context filters (the parity count).
class TriangleScene {
public:
    TriangleScene(RTCDevice device, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices);
    ~TriangleScene();
    TriangleScene(const TriangleScene&) = delete;
    TriangleScene& operator=(const TriangleScene&) = delete;

    bool ok() const { return ok_; }

    // Whether the segment from a to b meets a triangle.
    bool segment_hits(const glm::vec3& a, const glm::vec3& b) const;

    // How many distinct triangles the ray from `origin` along `direction` crosses.
    std::size_t crossings(const glm::vec3& origin, const glm::vec3& direction) const;

private:
    RTCScene scene_ = nullptr;
    bool ok_ = false;
};

// (a), (b) and (c) of homcull/truth/occluder_lod_build.hpp: S's surface does not cross O's,
// and S's vertices are inside. `o_scene` holds O's triangles.
bool contained(const TriangleMesh& o, const TriangleScene& o_scene, const TriangleMesh& s, RTCDevice device);

}  // namespace homcull::detail::lod
