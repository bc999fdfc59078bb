#pragma once
// Which objects are drawn into the occlusion buffer (Zhang 1998, ch. 7, "occluder selection").
// Two stages:
//   - a static filter, once per scene: the objects the scene marks as occluders (the castle's
//     `role: occluder`), every object, or the objects large enough to hide something;
//   - per frame, optionally: the candidates in the view frustum ranked by distance or by
//     projected size and kept in rank order while their triangles fit a triangle budget.
// Selection decides only how much is hidden, never correctness: whatever is drawn is real
// geometry, so every answer stays conservative.
#include <homcull/camera.hpp>
#include <homcull/occluder_lod.hpp>
#include <homcull/scene.hpp>
#include <homcull/visibility_grid.hpp>

#include <cstdint>
#include <utility>
#include <vector>

namespace homcull {

enum class OccluderFilter : std::uint8_t {
    role,  // objects whose extra "role" is "occluder"; every object when none is marked
    all,   // every object
    size,  // role when the scene marks occluders, else objects whose box diagonal is at least
           // 2 % of the scene's (Zhang's static size filter)
};

// The objects a filter keeps, in id order. Objects without geometry are never kept.
std::vector<std::uint32_t> occluder_candidates(const Scene& scene, OccluderFilter filter);

// Zhang's complexity filter: an occluder should hide much for few triangles. Keeps the
// candidates whose triangles per unit of their own surface (the inverse of their mean triangle
// area, in world space) are at most `factor` times the median of the candidates' (railings,
// spiral stairs and finely tessellated patches cover little for their cost); candidates with no
// surface are dropped (they count in the median as infinitely dense: when they are most of the
// candidates, every candidate with a surface is kept). factor <= 0 keeps every candidate.
// Spatial locality, Zhang's third static criterion, is applied per frame instead: distance
// ranking and the baked grid.
std::vector<std::uint32_t> filter_by_complexity(const Scene& scene, const std::vector<std::uint32_t>& candidates, double factor);

enum class OccluderRanking : std::uint8_t {
    none,      // every candidate, every frame (no per-frame work)
    distance,  // nearest box first (Zhang's distance-based selection under a polygon budget)
    area,      // largest projected size first: box diagonal over distance, squared
    baked,     // the visibility grid's point nearest to the eye (Zhang 7.5): by expected hidden
               // objects per triangle drawn (greedy knapsack order: the most hidden for the
               // budget), the expectation being the point's score plus a share for the
               // projected size (box diagonal / distance)^2, which ranks the occluders the
               // point does not list
};

struct OccluderBudget {
    OccluderRanking ranking = OccluderRanking::none;
    // At most this many triangles per frame, taken in rank order (id order with `none`);
    // 0 = no limit (every candidate in the frustum). Objects that do not fit what is left are
    // skipped, smaller ones after them may still fit.
    std::size_t triangles = 0;
    // baked: the grid (not owned; it must outlive the ranking's users).
    const VisibilityGrid* grid = nullptr;
    // Candidates whose box looks smaller than this from the eye are not drawn: its projected
    // size, (box diagonal / distance to the box)^2 in square radians (the size area ranking
    // sorts by), below the limit. Zhang's occluder selection keeps the objects that are large on
    // the screen: a near pillar hides a room, a far one a few pixels. 0 = no limit.
    double min_projected_size = 0.0;
};

// Per frame: the candidates whose box meets the camera's frustum (plane test), in rank
// order, within the budget, into `chosen` (cleared first). `scratch` is reused across frames;
// neither allocates once it has grown to the candidate count. With `lods`, an object counts
// against the budget with the triangles it is drawn with: its LOD's where
// occluder_triangles_drawn says so.
void rank_occluders(const Scene& scene, const std::vector<std::uint32_t>& candidates, const Camera& camera, double aspect,
                    const OccluderBudget& budget, std::vector<std::uint32_t>& chosen,
                    std::vector<std::pair<float, std::uint32_t>>& scratch, const OccluderLods* lods = nullptr);

// Whether a candidate with this box is large enough to draw from the camera's eye
// (OccluderBudget::min_projected_size; always, without a limit). Every per-frame choice of
// occluders (rank_occluders, temporal's second pass, progressive's draws) asks it.
bool large_enough_to_draw(const Aabb& box, const Camera& camera, const OccluderBudget& budget);

// The triangles an occluder is drawn with this frame: its LOD's when it has one and
// lod_usable() allows it, else its mesh's. `lods` may be null.
std::size_t occluder_triangles_drawn(const Scene& scene, std::uint32_t id, const Camera& camera, const OccluderLods* lods);

}  // namespace homcull
