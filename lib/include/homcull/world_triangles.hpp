#pragma once
// A scene's occluders as one world-space triangle list, ready for OcclusionBuffer::render:
// positions transformed exactly as ground truth transforms them (transform_point_from, relative
// to an anchor: the scene culler's and ground truth's is scene_anchor), and the shared-edge
// flags of the whole set (edges shared between objects count too).
#include <homcull/occlusion_buffer.hpp>
#include <homcull/parallel_for.hpp>
#include <homcull/scene.hpp>

#include <string_view>
#include <vector>

namespace homcull {

struct WorldTriangles {
    std::vector<float> positions;  // x, y, z per vertex
    std::vector<std::uint32_t> indices;
    std::vector<std::uint8_t> shared_edges;
    std::vector<std::uint32_t> edge_apexes;  // 3 per triangle (compute_shared_edges)
    // Object k's triangles are [object_first_triangle[k], object_first_triangle[k + 1]), in the
    // order the objects were given.
    std::vector<std::uint32_t> object_first_triangle{0};

    std::size_t triangle_count() const { return indices.size() / 3; }
    TriangleInput input(const std::array<float, 16>& clip_from_world, Backface backface = Backface::cw) const;
};

// Appends an object's vertices in world space relative to `anchor` (x, y, z each), transformed
// exactly as ground truth transforms them, in the order of its mesh's positions.
void append_world_positions(const Scene& scene, const Object& object, std::vector<float>& positions,
                            const glm::dvec3& anchor = glm::dvec3(0.0));
// The same into `out`, room for 3 x mesh.positions.size() floats (`mesh`: the object's).
void write_world_positions(const Object& object, const Mesh& mesh, float* out, const glm::dvec3& anchor = glm::dvec3(0.0));

// The triangles of the given objects, relative to `anchor`. With merge_coplanar, each object's
// exactly coplanar regions are re-triangulated with fewer triangles covering the same points
// (in world space, as drawn and as ground truth sees them: docs/scene-culling.md, "Coplanar
// merge"). Allocates: meant for load time or tools. With a job system (`parallel`) the objects'
// positions and merges run in its tasks; the result is the same bits.
WorldTriangles gather_world_triangles(const Scene& scene, const std::vector<std::uint32_t>& objects,
                                      const glm::dvec3& anchor = glm::dvec3(0.0), bool merge_coplanar = false,
                                      const ParallelFor& parallel = {});

// Ids of the objects whose extra "role" equals `role`, or of every object when role is empty.
std::vector<std::uint32_t> objects_with_role(const Scene& scene, std::string_view role);

}  // namespace homcull
