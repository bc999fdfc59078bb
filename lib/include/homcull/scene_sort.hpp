#pragma once
// A scene's objects as a visibility sort sees them (visibility_sort.hpp): one convex hull per
// mesh, made at load time, and each object's transform per frame relative to an origin.
#include <homcull/camera.hpp>
#include <homcull/scene.hpp>
#include <homcull/visibility_sort.hpp>

#include <array>
#include <vector>

namespace homcull {

// A sorter over the scene's objects: each mesh's hull (of the vertices its triangles use; a
// mesh with none gets its one vertex at the model origin, a point never in front of anything
// but the eye), object i's shape being its mesh. Throws homcull::Error on a non-finite vertex.
// hull_points: the limit of convex_hull_points (0: exact hulls).
VisibilitySorter make_visibility_sorter(const Scene& scene, std::size_t hull_points = kSortHullPoints);

// Object i's model-to-world transform relative to `origin` (translate(-origin) * world, in
// double, then rounded to float), into `out` (resized to the object count).
void sort_transforms(const Scene& scene, const glm::dvec3& origin, std::vector<glm::mat4>& out);

// The camera's view frustum (make_frustum, width / height = aspect) as SortFrame::planes,
// relative to `origin`: the sort then leaves out the objects wholly outside the view.
std::array<glm::vec4, 6> sort_frustum_planes(const Camera& camera, double aspect, const glm::dvec3& origin);

}  // namespace homcull
