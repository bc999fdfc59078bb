#pragma once
// Steps 2 and 3 of the occluder LOD build (homcull/truth/occluder_lod_build.hpp), for one
// closed part O: simplify it with meshoptimizer, which keeps O's vertices, then shrink the
// simplified triangles S into the solid along O's angle-weighted vertex normals, so that
// lod_containment can then verify that S lies inside.
#include "truth/lod_triangle_mesh.hpp"

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace homcull::detail::lod {

// Each vertex's normal as the sum of its triangles' unit normals weighted by the triangle's
// angle at the vertex (Thürmer and Wüthrich, "Computing vertex normals from polygonal facets",
// 1998). Unlike area weights it does not depend on how a flat region is cut into triangles,
// so a vertex on an edge between two faces moves off both. Triangles have non-zero area here.
std::vector<glm::dvec3> angle_weighted_normals(const TriangleMesh& mesh);

// Simplified indices (into the part's positions) with the simplifier's error bounded by
// `max_error` model units. meshopt_simplify collapses edges in the order of Garland and
// Heckbert's quadric error, keeps the mesh's topology, and moves no vertex.
std::vector<std::uint32_t> simplify(const TriangleMesh& o, double target_ratio, double max_error);

// The simplified triangles as a compact mesh, each vertex moved `margin` into the solid along
// O's normal there (S's vertices are O's; S's own normals can be nonsense where the
// simplifier left slivers). `sign` is -1 for outward-facing parts, +1 for inside-out ones.
// Triangles of zero area are dropped: they cover nothing, and a ray tracer can report a hit
// with a meaningless distance on one (Embree does, on the collinear slivers the simplifier
// leaves along straight creases). False when a vertex has no usable normal or, in float, did
// not move by at least half the margin.
bool shrink(const TriangleMesh& o, const std::vector<glm::dvec3>& normals, const std::vector<std::uint32_t>& indices,
            double margin, double sign, TriangleMesh& out);

}  // namespace homcull::detail::lod
