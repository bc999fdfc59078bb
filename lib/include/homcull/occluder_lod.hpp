#pragma once
// Occluder LOD: simplified stand-ins for occluder meshes that can only hide less than the
// meshes they replace, never more. They are built by build_occluder_lods
// (homcull/truth/occluder_lod_build.hpp, which needs Embree); this header is the data and the
// check made when one is drawn.
//
// The guarantee. A mesh, or a part of one (triangles linked through shared vertices), is
// "closed" when, after welding equal positions, every undirected edge is used by exactly two
// triangles, in opposite directions. A closed part O bounds a solid: the points from which a
// ray to infinity crosses O's surface an odd number of times (well defined because every edge
// is used an even number of times; it is the usual inside of a watertight 2-manifold, and
// still means something where O touches itself). Suppose a simplified surface S lies inside
// solid(O), off O's surface. Take an eye outside solid(O) and a ray from it that meets S at a
// point p. The eye has parity 0 and p has parity 1, so the segment from the eye to p crosses
// O's surface: the ray meets O no farther than it meets S. Whatever S hides along a ray, O
// hides too, at the same depth or nearer: drawing S instead of O can only hide less.
//
// An LOD is built part by part: each closed part large enough is replaced by a simplified,
// shrunk copy verified to lie inside it; every other part (open, too small, or whose copies
// all failed the check) is kept as it is and hides exactly what it hid. A mesh with no closed
// part gets no LOD. Parts are handled alone because a part inside or across another is a
// solid of its own, while points inside both have even parity: the union is not a solid.
//
// Conditions, each checked where it can be:
// - The replaced parts are closed (checked at build time).
// - Each copy lies inside its part's solid: checked at build time with Embree in the mesh's
//   model space, in float (see occluder_lod_build.hpp). World transforms are affine, and
//   affine maps keep one set inside another; what they do not keep exactly is the float
//   rounding of transform_point, which moves a vertex by at most 2^-24 of its largest world
//   coordinate (times sqrt 3). Copies are shrunk inward by a margin (by default 1e-3 of the
//   part's box diagonal) that the build raises, where needed, to 16 times that rounding for
//   every object it was given, and to 16 times the rounding of the model positions
//   themselves. The LOD is meant for those objects (OccluderLods::lod_for enforces it).
//   Caveat: the margin is how far the vertices moved inward; the Embree check proves that the
//   surfaces do not cross, not how far apart they stay. A part of S within rounding of O's
//   surface (away from S's vertices) could in principle slip through; the tests' ray checks
//   (millions of rays on the shared scenes, no tolerance) have found none.
// - The eye sees the object without near-plane clipping: ground truth starts its rays at the
//   near plane, so O's entry point could be cut away while S's hit is kept. lod_usable()
//   asks that the object's world box lie wholly beyond the near plane. That also puts the
//   eye outside the box, hence outside every part's solid. The far plane needs nothing: O is
//   met no farther than S.
#include <cstdint>
#include <homcull/aabb.hpp>
#include <homcull/camera.hpp>
#include <homcull/scene.hpp>
#include <vector>

namespace homcull {

// Why a mesh has an LOD or not, one per scene mesh.
enum class LodStatus : std::uint8_t {
    not_requested,        // no object given to the build uses the mesh
    built,                // the mesh has a verified LOD
    empty,                // no triangles
    invalid_geometry,     // a non-finite position, an index out of range, or indices not in threes
    degenerate_triangle,  // no closed part, and some triangle has zero area (such a part is
                          // never trusted: a sliver can make open edges count as closed)
    not_closed,           // no part is closed
    too_small,            // fewer triangles than LodOptions::min_triangles, or no closed part
                          // with LodOptions::min_part_triangles
    not_reduced,          // the simplifier could not get below LodOptions::max_kept_ratio
    not_contained,        // no simplified part passed the containment check
    bad_transform         // an object's transform is singular or not finite
};

// "built", "not_closed", ...: the enumerator's name.
const char* lod_status_name(LodStatus status);

struct OccluderLod {
    // In the model space of the original mesh, so that it is placed by the same Object::world:
    // its parts one after the other, each simplified, shrunk and verified, or as it was.
    Mesh mesh;
    std::uint32_t source_mesh = 0;
    std::uint32_t parts_simplified = 0;
    std::uint32_t parts_kept = 0;
    float margin = 0.0f;  // the smallest inward move of a simplified part's vertices, model units
};

struct OccluderLods {
    std::vector<std::int32_t> lod_of_mesh;  // per scene mesh: index into lods, or -1
    std::vector<LodStatus> status_of_mesh;  // per scene mesh
    std::vector<OccluderLod> lods;
    // Per scene object: 1 when the build was given it, so that its LOD's margin covers the
    // rounding of its transform. Only those objects may be drawn with an LOD (lod_for).
    std::vector<std::uint8_t> built_for_object;

    // Meshes used by the objects given to the build; how many of them are closed as a whole
    // (every part closed); how many got an LOD, and their triangles before and after (each
    // mesh counted once however many objects place it).
    std::size_t meshes_considered = 0;
    std::size_t meshes_closed = 0;
    std::size_t meshes_with_lod = 0;
    std::size_t triangles_before = 0;
    std::size_t triangles_after = 0;
    double build_seconds = 0.0;

    // The LOD of a mesh, or nullptr.
    const OccluderLod* lod_of(std::uint32_t mesh) const {
        if (mesh >= lod_of_mesh.size() || lod_of_mesh[mesh] < 0) return nullptr;
        return &lods[std::size_t(lod_of_mesh[mesh])];
    }
    // The LOD an object may be drawn with: its mesh's, if the build was given the object.
    const OccluderLod* lod_for(std::uint32_t object, std::uint32_t mesh) const {
        if (object >= built_for_object.size() || !built_for_object[object]) return nullptr;
        return lod_of(mesh);
    }
};

// Whether an object whose world box is `world_box` may be drawn with its LOD from this
// camera: every corner of the box has a view depth greater than the near plane. False for an
// empty or non-finite box. Decided in double, per frame and object.
bool lod_usable(const Aabb& world_box, const Camera& camera);

}  // namespace homcull
