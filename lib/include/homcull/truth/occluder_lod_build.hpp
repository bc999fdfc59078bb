#pragma once
// Building occluder LODs (the guarantee they keep is stated in homcull/occluder_lod.hpp).
//
// Per mesh used by the given objects, once however many objects place it:
// 1. Weld equal positions and split the mesh into parts (triangles linked through shared
//    vertices). A part is closed when every directed edge appears once and its reverse once,
//    and no triangle has zero area. Empty or non-finite input gets no LOD, with the reason in
//    OccluderLods::status_of_mesh; so does a mesh without a closed part.
// Then per closed part with at least LodOptions::min_part_triangles, O below:
// 2. Simplify with meshoptimizer's meshopt_simplify: edge collapses ordered by Garland and
//    Heckbert's quadric error metric ("Surface Simplification Using Quadric Error Metrics",
//    SIGGRAPH 1997). It keeps the original vertex positions, so the simplified surface S
//    touches O's surface at its vertices; its error bound is kept below the shrink of step 3.
// 3. Shrink: move each vertex of S into the solid along O's angle-weighted vertex normal, by a
//    margin relative to the part's box diagonal (LodOptions::margin), raised where needed to
//    16 times the float rounding of the given objects' transforms and of the model positions.
//    Zero-area triangles of S are dropped (they cover nothing).
// 4. Verify with Embree 3 in robust mode, in model space, that S lies inside solid(O):
//    (a) no edge of S meets a triangle of O and (b) no edge of O meets a triangle of S, so
//    the two surfaces do not cross (where two triangles meet, an edge of one meets the
//    other) and each connected piece of S lies wholly inside or wholly outside solid(O);
//    (c) every vertex of S is inside: rays in three fixed directions, counting every
//    triangle each one crosses, must all find an odd count (a ray grazing an edge can
//    miscount; then the directions disagree and the check fails, which is safe).
//    Steps 2 to 4 are tried with two triangle targets and three margins (1, 4 and 16 times
//    LodOptions::margin); the first result that passes replaces the part. A part with no
//    passing result is kept as it was.
// The check is exact up to Embree's float arithmetic in robust mode: it proves that the
// surfaces do not cross, not how far apart they are, and a part of S within rounding of O's
// surface could slip through. The margin makes that unlikely at S's vertices, and the tests
// cast rays at both meshes to confirm it.
// 5. The mesh gets the LOD when some part was replaced and it keeps at most
//    LodOptions::max_kept_ratio of the triangles.
#include <cstdint>
#include <homcull/occluder_lod.hpp>
#include <homcull/scene.hpp>
#include <vector>

namespace homcull {

struct LodOptions {
    double target_ratio = 0.25;           // triangles to aim for, as a fraction of a part's own
    std::size_t min_triangles = 64;       // smaller meshes are left as they are
    std::size_t min_part_triangles = 20;  // smaller parts are kept as they are (a box has 12)
    double max_kept_ratio = 0.75;         // an LOD keeping more of the triangles is not worth it
    double margin = 1e-3;                 // inward shrink, as a fraction of a part's box diagonal
};

// LODs of the meshes used by `objects` (ids into scene.objects), valid for those objects'
// transforms. Meshes, and the parts of each, are processed in parallel (TBB). Throws
// homcull::Error for bad options, an object id or mesh id out of range, or when Embree fails;
// bad geometry is a status, not an error.
OccluderLods build_occluder_lods(const Scene& scene, const std::vector<std::uint32_t>& objects,
                                 const LodOptions& options = {});

}  // namespace homcull
