#pragma once
// Step 1 of the occluder LOD build (homcull/truth/occluder_lod_build.hpp): weld equal
// positions, split the welded mesh into parts (triangles linked through shared vertices), and
// tell which parts are closed, so bound a solid that a simplified copy can be checked against.
#include "truth/lod_triangle_mesh.hpp"

#include <homcull/occluder_lod.hpp>
#include <homcull/scene.hpp>
#include <vector>

namespace homcull::detail::lod {

// Equal positions welded into one vertex; invalid_geometry or empty, else built.
LodStatus weld(const Mesh& mesh, TriangleMesh& out);

// Triangles linked through shared vertices, as a mesh of its own. Parts are simplified and
// checked one by one: a part inside another, or crossing it, is still a solid of its own,
// while the mesh as a whole is not one by parity (points inside both parts are even).
struct Part {
    TriangleMesh mesh;
    bool degenerate = false;  // has a zero-area triangle
    bool closed = false;      // every directed edge once, its reverse once; nothing degenerate
};

std::vector<Part> split_into_parts(const TriangleMesh& welded);

}  // namespace homcull::detail::lod
