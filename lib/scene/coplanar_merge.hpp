#pragma once
// Fewer occluder triangles covering exactly the same points: each connected region of exactly
// coplanar triangles re-triangulated by vertex collapses. Maps made of brushes (Quake's BSP,
// OpenArena) are cut into many coplanar pieces by their compilers' splits: on the shared
// OpenArena maps the scene culler's merge (gather_world_triangles) leaves 54 and 60 % of the
// occluder triangles, and each triangle drawn costs its set-up and its rows however small it is.
#include <cstddef>
#include <cstdint>

namespace homcull::detail {

// Rewrites triangles[0, triangle_count) (3 vertex indices each, into positions: x, y, z floats
// per vertex) and returns how many it keeps, in triangles[0, kept). The kept triangles cover the
// same points, at the same depths, as the given ones; every vertex they use is one of theirs, at
// its position. A vertex goes when every triangle around it lies in one plane (it is inside a
// flat region), or when on every plane its triangles lie in it sits on the region's boundary
// strictly between two neighbours on a straight line (a crease between two walls, or a wall's
// edge), and its triangles can be re-made from one of those neighbours, each facing the same way
// as before: a half-edge collapse (Hoppe, "Progressive meshes", SIGGRAPH 1996) with no error.
//
// Every test is exact: the positions, as integers on the finest binary grid that holds them,
// in 128-bit arithmetic. An object whose coordinates need more than 40 bits on that grid (widely
// different magnitudes: a floor 1e4 wide with details of 1e-5) is left as it is, and so are its
// degenerate triangles and the vertices they touch. Equal positions count as one vertex.
//
// keep (null: none), per position index: vertices that stay whatever their triangles, such as
// those other meshes drawn beside this one also use. An edge two meshes share, the same two
// vertices in both, keeps the rasterizer's shared-edge rule (each sample on it covered once);
// with one side's vertex on it gone the two sides' edges would differ, and the samples exactly on
// them would be covered by neither: a crack the farther surface shows through.
// Allocates (load time).
std::size_t merge_coplanar_triangles(const float* positions, std::uint32_t* triangles, std::size_t triangle_count,
                                     const std::uint8_t* keep = nullptr);

}  // namespace homcull::detail
