#pragma once
// Visibility preprocessing for occluder selection (Zhang 1998, sec. 7.5): sample points in
// the free space of a scene, and for each point the occluder candidates seen from it, ranked
// by how much they hide. At run time the eye snaps to the nearest sample point, and the
// frame's occluders are taken in that point's order (OccluderRanking::baked).
//
// The points stand on a lattice of columns over the scene's x-z extent (y is up): a column
// holds the free points above its centre, at eye height over each floor (layout "floors", for
// walkthroughs) or on a regular y lattice (layout "volume", for free-flying cameras).
// `homcull bake` computes a grid with Embree (truth/visibility_bake.hpp) and writes it as JSON
// (io/visibility_grid_io.hpp); a grid can be baked in shards of columns and merged.
//
// Selection decides only how much is hidden: whatever the grid says, the occluders drawn are
// real geometry and every answer stays conservative.
#include <homcull/aabb.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace homcull {

enum class GridLayout : std::uint8_t {
    floors,  // at eye height above each walkable floor of a column
    volume,  // every free point of a regular 3D lattice
};

// What a grid was baked for and how: two shards merge only when these agree.
struct VisibilityGridHeader {
    std::string scene;                 // the scene's source, for messages
    std::size_t scene_objects = 0;     // object count and placed triangle count: a grid
    std::size_t scene_triangles = 0;   //   baked for another scene is refused
    std::string occluders;             // the candidate filter: role, all or auto
    GridLayout layout = GridLayout::floors;
    double spacing = 1.0;              // lattice step along x, z (and y for volume)
    double origin_x = 0.0, origin_z = 0.0;  // corner of column (0, 0); its centre is origin + spacing / 2
    double origin_y = 0.0;             // volume: y of the first lattice point
    std::uint32_t columns_x = 0, columns_z = 0;
    double eye_height = 1.7;           // floors: the eye above the floor
    std::uint32_t rays = 4096;         // directions cast from each point
    std::uint32_t keep = 128;          // at most this many occluders kept per point
};

// One sample point and its occluders, best first.
struct GridPoint {
    glm::vec3 position{0.0f};
    // Occluder object ids with their score: the number of distinct objects that the point's
    // rays meet right behind the occluder (the first candidate they meet) and see nowhere
    // else, an estimate of how much it hides from there. Sorted by decreasing score, ties by increasing id.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> occluders;
};

class VisibilityGrid {
public:
    VisibilityGridHeader header;
    // Column c = ix + columns_x * iz holds points[column_first[c] .. column_first[c + 1]).
    std::vector<std::uint32_t> column_first;
    std::vector<GridPoint> points;

    std::size_t column_count() const { return std::size_t(header.columns_x) * header.columns_z; }
    // The point nearest to `eye` (Euclidean), or nullptr when the grid has none or the eye is
    // not finite. Searches the
    // eye's column (clamped to the lattice) and rings of columns around it until no nearer
    // point can exist. Allocates nothing; thread-safe.
    const GridPoint* nearest(const glm::dvec3& eye) const;

    // The score of an occluder at a point (0 when not listed): a binary search in the point's
    // id-sorted copy, built by index().
    std::uint32_t score(const GridPoint& point, std::uint32_t object) const;

    // Checks the layout (column_first consistent, every point inside its column's x-z square,
    // every point's occluders valid ids below object_count, none twice) and builds the
    // per-point id index score() uses. Throws
    // homcull::Error with `source` in the message. Readers and bakers call it last.
    void index(std::size_t object_count, const std::string& source);

private:
    // Per point p: its occluders sorted by id, in by_id[by_id_first[p] .. by_id_first[p + 1]).
    std::vector<std::uint32_t> by_id_first_;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> by_id_;
};

const char* grid_layout_name(GridLayout layout);

// A share of a bake: shard `index` of `count` holds the columns c with c % count == index
// (interleaved, so that every shard gets some of the dense and some of the empty columns).
struct GridShard {
    std::uint32_t index = 0, count = 1;
    bool holds(std::size_t column) const { return column % count == index; }
};

}  // namespace homcull
