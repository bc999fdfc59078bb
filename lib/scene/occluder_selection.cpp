#include <homcull/occluder_selection.hpp>

#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/world_triangles.hpp>

#include "common/complexity_rule.hpp"

#include <algorithm>

namespace homcull {

std::vector<std::uint32_t> occluder_candidates(const Scene& scene, OccluderFilter filter) {
    std::vector<std::uint32_t> ids;
    if (filter != OccluderFilter::all) ids = objects_with_role(scene, "occluder");
    if (ids.empty() && filter == OccluderFilter::size) {
        const float min_diagonal = 0.02f * glm::length(scene.bounds().extent());
        for (std::uint32_t id = 0; id < scene.objects.size(); ++id) {
            const Aabb& b = scene.objects[id].world_bounds;
            if (!b.empty() && glm::length(b.extent()) >= min_diagonal) ids.push_back(id);
        }
    } else if (ids.empty()) {
        ids = objects_with_role(scene, "");
    }
    ids.erase(std::remove_if(ids.begin(), ids.end(), [&](std::uint32_t id) { return scene.objects[id].world_bounds.empty(); }),
              ids.end());
    return ids;
}

namespace {

// Triangles per unit of the object's own surface (the sum of its world-space triangle areas):
// the inverse of its mean triangle area. Its box's surface, the first measure, rated thin
// detailed objects that hide much (FZK-Haus's windows, 500 to 2,200 times the median per unit of
// box surface) as dense as railings, and dropping them cost culling from outside the house.
double object_triangle_density(const Scene& scene, std::uint32_t id) {
    const Object& object = scene.objects[id];
    const Mesh& mesh = scene.meshes[object.mesh];
    std::vector<float> world;  // each vertex once, as ground truth places it
    append_world_positions(scene, object, world);
    const auto vertex = [&](std::uint32_t v) { return glm::dvec3(world[3 * v], world[3 * v + 1], world[3 * v + 2]); };
    double area = 0.0;
    for (std::size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
        const glm::dvec3 a = vertex(mesh.indices[k]), b = vertex(mesh.indices[k + 1]), c = vertex(mesh.indices[k + 2]);
        area += detail::triangle_area(a, b, c);
    }
    return detail::triangle_density(scene.triangle_count(object), area);
}

}  // namespace

std::vector<std::uint32_t> filter_by_complexity(const Scene& scene, const std::vector<std::uint32_t>& candidates, double factor) {
    if (!(factor > 0.0) || candidates.empty()) return candidates;
    std::vector<double> densities;
    for (std::uint32_t id : candidates) densities.push_back(object_triangle_density(scene, id));
    std::vector<double> sorted = densities;
    const double limit = detail::complexity_limit(sorted.data(), sorted.size(), factor);
    std::vector<std::uint32_t> kept;
    for (std::size_t k = 0; k < candidates.size(); ++k)
        if (detail::within_complexity(densities[k], limit)) kept.push_back(candidates[k]);
    return kept;
}

namespace {

// Distance from a point to a box (0 inside it).
double distance_to_box(const glm::dvec3& p, const Aabb& box) {
    const glm::dvec3 nearest = glm::clamp(p, glm::dvec3(box.min), glm::dvec3(box.max));
    return glm::length(p - nearest);
}

// Projected size of a box, a square angle: (box diagonal / distance)^2.
double projected_size(const Aabb& box, double distance) {
    const double diagonal = glm::length(glm::dvec3(box.extent()));
    return (diagonal * diagonal) / (distance * distance);
}

// The size limit (OccluderBudget::min_projected_size) for a box at `distance` from the eye (the
// near plane bounding it below): the one rule rank_occluders and large_enough_to_draw apply.
bool below_size_limit(const Aabb& box, double distance, const OccluderBudget& budget) {
    return budget.min_projected_size > 0.0 && projected_size(box, distance) < budget.min_projected_size;
}

// The hidden objects credited to an occluder whose box diagonal subtends one radian, on top of
// its baked score. The grid's rays are a few degrees apart (4,096 over the sphere), so the
// scores are small counts (mostly 1 to 4 on the castle) and many occluders that do hide
// something from the eye score 0. Projected size fills that gap. On the castle's walks, 1 to 4
// do about equally well; more lets size outweigh the grid.
constexpr double kHiddenPerSquareRadian = 2.0;

// Baked ranking's estimate of the objects an occluder hides from the eye: its score at the
// grid point plus a share for its projected size (the size area ranking uses).
double expected_hidden(std::uint32_t score, const Aabb& box, double distance) {
    return double(score) + kHiddenPerSquareRadian * projected_size(box, distance);
}

}  // namespace

void rank_occluders(const Scene& scene, const std::vector<std::uint32_t>& candidates, const Camera& camera, double aspect,
                    const OccluderBudget& budget, std::vector<std::uint32_t>& chosen,
                    std::vector<std::pair<float, std::uint32_t>>& scratch, const OccluderLods* lods) {
    chosen.clear();
    if (budget.ranking == OccluderRanking::baked && !budget.grid) throw Error("baked occluder ranking needs a visibility grid");
    const GridPoint* point = budget.ranking == OccluderRanking::baked ? budget.grid->nearest(camera.eye) : nullptr;
    const Frustum frustum = make_frustum(camera, aspect);
    scratch.clear();
    for (std::uint32_t id : candidates) {
        const Aabb& box = scene.objects[id].world_bounds;
        if (!may_meet(frustum, box)) continue;
        // Smaller keys first. The near plane bounds the distance below: every object that
        // reaches in front of it ranks alike by size.
        const double distance = std::max(distance_to_box(camera.eye, box), camera.near_plane);
        if (below_size_limit(box, distance, budget)) continue;
        double key = distance;
        if (budget.ranking == OccluderRanking::area) {
            key = -projected_size(box, distance);
        } else if (point) {
            // One order for all candidates, by decreasing expected hidden objects per triangle
            // drawn (the greedy knapsack order; negative keys). Putting every listed occluder
            // before every unlisted one spent half a 4,000-triangle budget on a gate that scored
            // 1 for 1,968 triangles, ahead of small walls next to the eye that scored 0.
            const double hidden = expected_hidden(budget.grid->score(*point, id), box, distance);
            key = -hidden / double(std::max<std::size_t>(occluder_triangles_drawn(scene, id, camera, lods), 1));
        }
        scratch.emplace_back(float(key), id);
    }
    if (budget.ranking != OccluderRanking::none) std::sort(scratch.begin(), scratch.end());
    std::size_t left = budget.triangles == 0 ? ~std::size_t(0) : budget.triangles;
    for (const auto& [key, id] : scratch) {
        const std::size_t n = occluder_triangles_drawn(scene, id, camera, lods);
        if (n > left) continue;
        chosen.push_back(id);
        left -= n;
    }
}

bool large_enough_to_draw(const Aabb& box, const Camera& camera, const OccluderBudget& budget) {
    return !below_size_limit(box, std::max(distance_to_box(camera.eye, box), camera.near_plane), budget);
}

std::size_t occluder_triangles_drawn(const Scene& scene, std::uint32_t id, const Camera& camera, const OccluderLods* lods) {
    const Object& object = scene.objects[id];
    if (lods)
        if (const OccluderLod* lod = lods->lod_for(id, object.mesh); lod && lod_usable(object.world_bounds, camera))
            return lod->mesh.triangle_count();
    return scene.triangle_count(object);
}

}  // namespace homcull
