#pragma once
// Occludees that are closed solids, whose triangles facing away from the eye need no test.
//
// Ground truth casts rays from the eye and reports the first triangle each one meets beyond the
// near plane (truth/ground_truth.cpp). Let an object's triangles form closed surfaces: every edge
// shared with another triangle of the object, in opposite order (compute_shared_edges), so that
// each connected piece is consistently wound, and each piece enclosing a volume of one sign,
// its triangles' fronts facing out of it. A ray that starts outside every piece and first meets
// the object where it enters a piece meets it on the front side of the triangle there: the eye
// lies in front of that triangle's plane. So when every triangle of the object that the eye
// does not certainly see from behind is hidden at every sample, the object is hidden; the
// others need no test. The ray starts outside every piece when the object's box lies wholly
// beyond the near plane (SceneCullerState::beyond_near_plane). Two assumptions, as ground truth's own
// geometry: the pieces are not inside out anywhere (a closed piece that crosses itself could
// enclose a region of the opposite sign; meshes from modelling tools are unions of solids), and
// a ray grazing a silhouette edge, which Embree may report on the back triangle there, meets the
// front one at the same point, which its outer coverage includes.
//
// The scene culler applies this to the parts of occludees tested triangle by triangle
// (scene_traversal.cpp): the buffer's test passes over the triangles that the eye certainly
// sees from behind (buffer/seen_solid.hpp) once they are known to lie within the view's sides.
#include <homcull/parallel_for.hpp>
#include <homcull/scene.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace homcull::detail {

// Per object: +1 when its triangles in world space (world_positions from its first_vertex[id],
// the mesh's indices; kNotGathered: not gathered, 0) form closed surfaces whose every connected
// piece encloses a clearly positive volume (fronts facing out), -1 when every piece's volume is
// clearly negative (a mirroring transform: fronts facing in), 0 otherwise (open, mixed, or too
// flat to tell). Meant for load time: it allocates per mesh. With a job system, the meshes and
// then the objects are taken in its tasks: the same answers.
std::vector<std::int8_t> closed_occludee_orientations(const Scene& scene, const std::vector<float>& world_positions,
                                                      const std::vector<std::size_t>& first_vertex, std::size_t not_gathered,
                                                      const ParallelFor& parallel = {});

}  // namespace homcull::detail
