#pragma once
// Visibility grid files (JSON), whole or one shard of a bake:
//   {"format": "homcull-visibility-grid", "version": 1,
//    "scene": "...", "scene_objects": N, "scene_triangles": T, "occluders": "role",
//    "layout": "floors"|"volume", "spacing": s, "origin": [x, y, z], "columns": [nx, nz],
//    "eye_height": h, "rays": R, "keep": K,
//    "shard": [i, n],                         (shard files only)
//    "points": [{"column": c, "position": [x, y, z], "occluders": [[id, score], ...]}, ...]}
// A point's occluders are listed best first. Every failure throws homcull::Error naming the
// file and what is wrong.
#include <homcull/scene.hpp>
#include <homcull/visibility_grid.hpp>

#include <string>
#include <vector>

namespace homcull {

// A whole grid is the part {0, 1}.
struct VisibilityGridPart {
    VisibilityGrid grid;  // only the shard's columns hold points
    GridShard shard;
    std::string source;   // the file it was read from
};

void write_visibility_grid(const VisibilityGrid& grid, const GridShard& shard, const std::string& file);
VisibilityGridPart read_visibility_grid_part(const std::string& file);

// Every shard 0 .. n-1 of one bake, exactly once, with equal headers: the whole grid.
VisibilityGrid merge_visibility_grid_parts(const std::vector<VisibilityGridPart>& parts);

// A whole grid for `scene`, indexed and ready for OccluderRanking::baked. Refuses a shard
// and a grid baked for another scene (object or triangle count differ).
VisibilityGrid read_visibility_grid(const std::string& file, const Scene& scene);

}  // namespace homcull
