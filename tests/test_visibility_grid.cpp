// Visibility preprocessing (Zhang 7.5): the grid's nearest-point lookup, baking in shards and
// merging, the grid file's errors, and the baked occluder ranking against distance ranking on
// the castle (zero false culls; more culled under the same triangle budget).
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/io/visibility_grid_io.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/truth/visibility_bake.hpp>
#include <homcull/truth/walk_path.hpp>
#include <homcull/truth/walkthrough.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

namespace homcull {
namespace {

bool same_points(const VisibilityGrid& a, const VisibilityGrid& b) {
    if (a.column_first != b.column_first || a.points.size() != b.points.size()) return false;
    for (std::size_t p = 0; p < a.points.size(); ++p)
        if (a.points[p].position != b.points[p].position || a.points[p].occluders != b.points[p].occluders) return false;
    return true;
}

TEST(VisibilityGrid, NearestIsTheClosestPointFromAnywhere) {
    // A 7 x 5 lattice with 0 to 3 points per column at random heights.
    VisibilityGrid grid;
    grid.header.spacing = 2.0;
    grid.header.origin_x = -3.0;
    grid.header.origin_z = 10.0;
    grid.header.columns_x = 7;
    grid.header.columns_z = 5;
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    grid.column_first.push_back(0);
    for (std::uint32_t c = 0; c < grid.column_count(); ++c) {
        const int n = int(rng() % 4);
        for (int k = 0; k < n; ++k) {
            GridPoint p;
            p.position = {float(grid.header.origin_x + (c % 7 + unit(rng)) * 2.0), float(10.0 * unit(rng)),
                          float(grid.header.origin_z + (c / 7 + unit(rng)) * 2.0)};
            grid.points.push_back(p);
        }
        grid.column_first.push_back(std::uint32_t(grid.points.size()));
    }
    grid.index(1, "test grid");
    std::uniform_real_distribution<double> around(-20.0, 30.0);
    for (int trial = 0; trial < 2000; ++trial) {
        const glm::dvec3 eye(around(rng), around(rng), 10.0 + around(rng));
        double best = 1e300;
        for (const GridPoint& p : grid.points) best = std::min(best, glm::length(glm::dvec3(p.position) - eye));
        const GridPoint* found = grid.nearest(eye);
        ASSERT_NE(found, nullptr);
        EXPECT_DOUBLE_EQ(glm::length(glm::dvec3(found->position) - eye), best) << "trial " << trial;
    }
    EXPECT_NE(grid.nearest({1e30, -1e30, 1e30}), nullptr);  // far outside: some edge point
    EXPECT_EQ(grid.nearest({std::nan(""), 0.0, 0.0}), nullptr);
    VisibilityGrid empty;
    EXPECT_EQ(empty.nearest({0, 0, 0}), nullptr);
}

BakeOptions city_bake(const Scene& scene) {
    BakeOptions o;
    o.candidates = occluder_candidates(scene, OccluderFilter::role);
    o.spacing = 4.0;
    o.rays = 256;
    o.keep = 16;
    return o;
}

TEST(VisibilityGrid, ShardsMergeIntoTheWholeBakeAndTheFileRoundTrips) {
    const Scene scene = generate_scene("city:seed=2,blocks=4");
    const RayScene rays(scene);
    BakeOptions options = city_bake(scene);
    const VisibilityGrid whole = bake_visibility_grid(rays, scene, options);
    ASSERT_GT(whole.points.size(), 20u);
    std::size_t listed = 0;
    for (const GridPoint& p : whole.points) {
        listed += !p.occluders.empty();
        EXPECT_LE(p.occluders.size(), options.keep);
        for (std::size_t k = 1; k < p.occluders.size(); ++k) EXPECT_GE(p.occluders[k - 1].second, p.occluders[k].second);
        for (const auto& [id, score] : p.occluders) EXPECT_EQ(whole.score(p, id), score);
    }
    EXPECT_GT(listed, whole.points.size() / 2) << "most street points see an occluder that hides something";

    const std::string dir = test::temp_dir("visibility_grid_shards");
    write_visibility_grid(whole, {}, dir + "/whole.json");
    EXPECT_TRUE(same_points(read_visibility_grid(dir + "/whole.json", scene), whole));

    std::vector<VisibilityGridPart> parts;
    for (std::uint32_t i : {2u, 0u, 1u}) {  // any order
        options.shard = {i, 3};
        const std::string file = dir + "/part" + std::to_string(i) + ".json";
        write_visibility_grid(bake_visibility_grid(rays, scene, options), options.shard, file);
        parts.push_back(read_visibility_grid_part(file));
    }
    EXPECT_TRUE(same_points(merge_visibility_grid_parts(parts), whole));

    // A shard is not a grid; shards missing, given twice, or from another bake do not merge.
    EXPECT_THROW(read_visibility_grid(dir + "/part1.json", scene), Error);
    EXPECT_THROW(merge_visibility_grid_parts({parts[0], parts[1]}), Error);
    EXPECT_THROW(merge_visibility_grid_parts({parts[0], parts[1], parts[1]}), Error);
    VisibilityGridPart other = parts[2];
    other.grid.header.rays = 512;
    EXPECT_THROW(merge_visibility_grid_parts({parts[0], parts[1], other}), Error);
    // Nor is a grid read for another scene.
    EXPECT_THROW(read_visibility_grid(dir + "/whole.json", generate_scene("city:seed=2,blocks=5")), Error);

    options.shard = {3, 3};
    EXPECT_THROW(bake_visibility_grid(rays, scene, options), Error);
    options.shard = {};
    options.candidates.clear();
    EXPECT_THROW(bake_visibility_grid(rays, scene, options), Error);
}

TEST(VisibilityGrid, MalformedFilesAreClearErrors) {
    const std::string dir = test::temp_dir("visibility_grid_malformed");
    const Scene scene = generate_scene("city:seed=2,blocks=3");
    auto message = [&](const std::string& text) {
        test::write_text(dir + "/grid.json", text);
        try {
            read_visibility_grid(dir + "/grid.json", scene);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string header = R"("format":"homcull-visibility-grid","version":1,"scene":"s","scene_objects":)" +
                               std::to_string(scene.objects.size()) + R"(,"scene_triangles":)" +
                               std::to_string(scene.instanced_triangle_count()) +
                               R"(,"occluders":"role","layout":"floors","spacing":2.0,"origin":[0,0,0],"columns":[2,2],"eye_height":1.7,"rays":64,"keep":8)";
    EXPECT_NE(message("{}").find("not a homcull visibility grid"), std::string::npos);
    EXPECT_NE(message("not json").find("not valid JSON"), std::string::npos);
    EXPECT_NE(message("{" + header + "}").find("points"), std::string::npos);
    EXPECT_NE(message("{" + header + R"(,"points":[{"column":9,"position":[0,0,0],"occluders":[]}]})").find("outside the grid"),
              std::string::npos);
    EXPECT_NE(message("{" + header + R"(,"points":[{"column":1,"position":[3,0,1],"occluders":[[99999,1]]}]})").find("names object"),
              std::string::npos);
    EXPECT_NE(message("{" + header + R"(,"points":[{"column":1,"position":[3,0,1],"occluders":[[1,1],[1,2]]}]})").find("twice"),
              std::string::npos);
    EXPECT_EQ(message("{" + header + R"(,"points":[{"column":1,"position":[3,0,1],"occluders":[[1,3]]}]})"), "no error");
    EXPECT_NE(message("{" + header + R"(,"points":[{"column":1,"position":[0,0,0],"occluders":[]}]})").find("outside its column"),
              std::string::npos);
    EXPECT_NE(message("{" + header + R"(,"points":[{"column":1,"position":[3,0,1],"occluders":[[4294967298,1]]}]})").find("below 2^32"),
              std::string::npos);
    EXPECT_NE(message(R"({"format":5})").find("not a homcull visibility grid"), std::string::npos);
    try {
        read_visibility_grid(dir + "/missing.json", scene);
        FAIL() << "no error for a missing file";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("missing.json"), std::string::npos);
    }
}

TEST(VisibilityGrid, BakedRankingOrdersByExpectedHiddenPerTriangle) {
    const Scene scene = generate_scene("city:seed=2,blocks=4");
    const RayScene rays(scene);
    const BakeOptions options = city_bake(scene);
    const VisibilityGrid grid = bake_visibility_grid(rays, scene, options);
    Camera camera;
    camera.eye = glm::dvec3(grid.points[grid.points.size() / 2].position);
    camera.target = camera.eye + glm::dvec3(1.0, 0.0, 0.3);
    const GridPoint* point = grid.nearest(camera.eye);
    ASSERT_NE(point, nullptr);
    std::vector<std::uint32_t> chosen;
    std::vector<std::pair<float, std::uint32_t>> scratch;
    OccluderBudget budget{OccluderRanking::baked, 0, &grid};
    rank_occluders(scene, options.candidates, camera, 16.0 / 9.0, budget, chosen, scratch);
    ASSERT_FALSE(chosen.empty());
    // Listed and unlisted candidates in one order: by the point's score plus 2 per square
    // radian of (box diagonal / distance), per triangle, decreasing.
    bool listed_after_unlisted = false, unlisted_seen = false;
    double last = 1e300;
    for (std::uint32_t id : chosen) {
        const Aabb& box = scene.objects[id].world_bounds;
        const glm::dvec3 nearest = glm::clamp(camera.eye, glm::dvec3(box.min), glm::dvec3(box.max));
        const double distance = std::max(glm::length(camera.eye - nearest), camera.near_plane);
        const double diagonal = glm::length(glm::dvec3(box.extent()));
        const std::uint32_t score = grid.score(*point, id);
        const double hidden = double(score) + 2.0 * diagonal * diagonal / (distance * distance);
        const double density = hidden / double(scene.triangle_count(scene.objects[id]));
        EXPECT_LE(density, last * (1.0 + 1e-5)) << "object " << id;
        last = density;
        listed_after_unlisted |= score > 0 && unlisted_seen;
        unlisted_seen |= score == 0;
    }
    // The order mixes them here (it did not when listed candidates always came first).
    EXPECT_TRUE(listed_after_unlisted);
    budget.grid = nullptr;
    EXPECT_THROW(rank_occluders(scene, options.candidates, camera, 16.0 / 9.0, budget, chosen, scratch), Error);
}

// The check of issue 5: on a castle walkthrough, the baked ranking culls more than distance
// ranking under the same occluder triangle budget, and neither culls anything visible. At
// 4,000 triangles the two tied while every listed occluder came before every unlisted one.
TEST(VisibilityGrid, BakedRankingBeatsDistanceOnTheCastle) {
    const std::string file = test::shared_scene("intel_castle.glb");
    if (file.empty()) GTEST_SKIP() << "intel_castle.glb is not in " << test::shared_scenes_dir();
    const Scene scene = load_scene(file);
    const RayScene rays(scene);
    BakeOptions options;
    options.candidates = occluder_candidates(scene, OccluderFilter::role);
    options.rays = 2048;
    const VisibilityGrid grid = bake_visibility_grid(rays, scene, options);
    WalkOptions walk;
    walk.frames = 120;
    walk.seed = 7;
    const CameraPath path = walk_path(rays, scene, walk);
    TruthOptions truth_options;
    truth_options.resolution = {640, 360};
    std::vector<TruthResult> truths;
    for (std::size_t k = 0; k < path.frames.size(); k += 4)
        truths.push_back(compute_ground_truth(rays, scene, path.frames[k], truth_options));
    for (const std::size_t triangles : {std::size_t(4000), std::size_t(10000)}) {
        SceneCullerConfig config;
        config.display = truth_options.resolution;
        config.occluder_budget = {OccluderRanking::distance, triangles, nullptr};
        SceneCuller by_distance(scene, options.candidates, config);
        config.occluder_budget = {OccluderRanking::baked, triangles, &grid};
        SceneCuller baked(scene, options.candidates, config);
        std::size_t hidden = 0, culled_by_distance = 0, culled_baked = 0, false_culls = 0;
        std::vector<OccludeeAnswer> answers;
        for (std::size_t k = 0; k < path.frames.size(); k += 4) {
            const TruthResult& truth = truths[k / 4];
            const WalkFrame d = measure_walk_frame(scene, by_distance, path.frames[k], &truth, answers);
            const WalkFrame b = measure_walk_frame(scene, baked, path.frames[k], &truth, answers);
            hidden += d.truth.hidden_in_frustum;
            culled_by_distance += d.truth.hidden_in_frustum - d.truth.missed_culls();
            culled_baked += b.truth.hidden_in_frustum - b.truth.missed_culls();
            false_culls += d.truth.false_culls + b.truth.false_culls;
            EXPECT_LE(b.work.occluder_triangles, triangles);
        }
        std::printf("[ baked    ] castle, %zu occluder triangles: distance culls %zu, baked %zu of %zu hidden\n", triangles,
                    culled_by_distance, culled_baked, hidden);
        EXPECT_EQ(false_culls, 0u) << triangles << " triangles";
        // At least 2 % of the hidden objects more (the tie was within 0.1 %).
        EXPECT_GT(culled_baked, culled_by_distance + hidden / 50) << triangles << " triangles";
    }
}

}  // namespace
}  // namespace homcull
