#pragma once
// Baking a visibility grid (visibility_grid.hpp) with Embree ray casts: Zhang's visibility
// preprocessing (1998, sec. 7.5), "for each sample point in free space, the occluders visible
// from it, ranked".
//
// From every sample point, `rays` directions spread evenly over the sphere (a Fibonacci
// lattice). Along each direction, the first occluder candidate met and the first other object
// behind it are found; an occluder's score is the number of distinct objects found behind it
// that no ray from the point sees.
// An occluder earns what it hides, not the view it fills: the ground under the eye fills half
// the sphere and hides little, a wall before the town hides many objects. The same rays decide whether
// the point is in free space: a point that sees the back of surfaces in most directions is
// inside a solid and is left out.
#include <homcull/scene.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/visibility_grid.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace homcull {

struct BakeOptions {
    std::vector<std::uint32_t> candidates;  // occluder candidates (object ids)
    std::string candidates_name = "role";   // how they were chosen, recorded in the header
    GridLayout layout = GridLayout::floors;
    double spacing = 0.0;     // lattice step; 0 = the longer of the scene's x and z extents / 64
    double eye_height = 0.0;  // floors: 0 = default_eye_height(scene) (walk_path's)
    std::uint32_t rays = 4096;
    std::uint32_t keep = 128;  // occluders kept per point, best first
    int max_floors = 8;        // floors: floors kept per column, from at most 8 times as many surface hits
    GridShard shard;           // bake only this shard's columns
};

// Throws homcull::Error on invalid options (no candidates, rays or keep 0, a non-positive
// spacing, a shard index beyond its count) or an empty scene. `progress(done, total)` is
// called after each column, from the calling thread or a worker (serialized). Uses TBB's threads.
VisibilityGrid bake_visibility_grid(const RayScene& rays, const Scene& scene, const BakeOptions& options,
                                    const std::function<void(std::size_t, std::size_t)>& progress = {});

// The grid's header for a scene and options (what bake_visibility_grid records).
VisibilityGridHeader bake_header(const Scene& scene, const BakeOptions& options);

}  // namespace homcull
