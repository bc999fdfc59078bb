// A forest of many small disjoint occluders. No single tree hides much; what is hidden is
// hidden by the fusion of many (Zhang 1998, ch. 1: "occluder fusion"), which is what the
// opacity pyramid is for and what per-occluder shadow-frusta methods miss.
#include "scene/primitives.hpp"
#include "common/random.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>

#include <algorithm>
#include <string>

namespace homcull {

Scene generate_forest(const ForestOptions& o) {
    if (!(o.radius >= 5.0 && o.radius <= 5000.0)) throw Error("forest: radius must be in [5, 5000] metres");
    // A crown of scale 1.2 is 2 * 1.8 * 1.2 = 4.32 m wide; the cell must hold it.
    if (!(o.tree_spacing >= 4.5 && o.tree_spacing <= 1000.0))
        throw Error("forest: tree spacing must be in [4.5, 1000] metres");
    if (o.rocks < 0 || o.rocks > 1000000) throw Error("forest: rocks must be in [0, 1000000]");
    const int cells = int(2.0 * o.radius / o.tree_spacing);
    if (cells < 1) throw Error("forest: radius too small for the tree spacing");
    if (double(cells) * cells > 4e6) throw Error("forest: more than 4 million trees; raise the spacing");

    detail::SplitMix64 rng(o.seed);
    Scene scene;
    scene.source = "gen:forest:seed=" + std::to_string(o.seed);
    scene.meshes.push_back(detail::make_ground_mesh());
    scene.meshes.push_back(detail::make_tree_mesh());
    scene.meshes.push_back(detail::make_box_mesh());
    const std::uint32_t ground_mesh = 0, tree_mesh = 1, box_mesh = 2;

    detail::add_object(scene, "ground", ground_mesh, detail::place({0, 0, 0}, {2 * o.radius + 20, 1, 2 * o.radius + 20}),
        "ground", "occluder");

    // One tree per grid cell, jittered inside its cell so that crowns never touch; about one
    // cell in ten is left as a clearing.
    const double start = -o.radius + 0.5 * o.tree_spacing;
    int tree = 0;
    for (int cz = 0; cz < cells; ++cz)
        for (int cx = 0; cx < cells; ++cx) {
            const double scale = rng.uniform(0.7, 1.2);
            const double slack = std::max(0.0, 0.5 * o.tree_spacing - detail::kTreeCrownRadius * scale - 0.05);
            const double jx = rng.uniform(-slack, slack), jz = rng.uniform(-slack, slack);
            if (rng.uniform() < 0.1) continue;
            const glm::dvec3 base(start + cx * o.tree_spacing + jx, 0.0, start + cz * o.tree_spacing + jz);
            detail::add_object(scene, "tree_" + std::to_string(tree++), tree_mesh,
                detail::place(base, glm::dvec3(scale, scale * rng.uniform(0.9, 1.3), scale)),
                "trees", "occluder");
        }

    for (int k = 0; k < o.rocks; ++k) {
        const glm::dvec3 size(rng.uniform(0.4, 1.5), rng.uniform(0.3, 1.0), rng.uniform(0.4, 1.5));
        const glm::dvec3 base(rng.uniform(-o.radius, o.radius), 0.0, rng.uniform(-o.radius, o.radius));
        detail::add_object(scene, "rock_" + std::to_string(k), box_mesh, detail::place(base, size), "rocks", "occludee");
    }
    scene.finalize();
    return scene;
}

}  // namespace homcull
