// The first test of anything that culls: the occlusion buffer's AABB answers against Embree
// ground truth at the same sample positions. A false cull (an object declared occluded or
// outside the view while some sample sees it) must never happen.
#include "support.hpp"

#include <homcull/generate.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/culling_accuracy.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/walk_path.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <string>
#include <utility>

namespace homcull {
namespace {

void report(const char* what, const CullingTally& t) {
    std::printf("[ culling  ] %s: %d views, %zu visible objects, %zu false culls, culled %zu of %zu hidden (%.1f %%; "
                "%zu hidden only through ties, %.1f %% of those hidden outright)\n",
                what, t.views, t.visible, t.false_culls, t.culled_hidden, t.hidden_in_frustum, 100.0 * t.efficiency(),
                t.hidden_through_ties, 100.0 * t.robust_efficiency());
    for (const std::string& line : t.false_cull_reports) ADD_FAILURE() << "false cull: " << line;
}

void tally_walk(const Scene& scene, const std::vector<std::uint32_t>& occluder_ids, int frames, Resolution display, int samples,
                CullingTally& tally, DepthTest depth = DepthTest::masked, std::uint64_t seed = 1, double hole = 0.0,
                bool clusters = false, bool merge_coplanar = false) {
    const RayScene rays(scene);
    SceneCullerConfig config;
    config.occluder_clusters = clusters;
    config.merge_coplanar_occluders = merge_coplanar;
    config.display = display;
    config.samples = samples;
    config.maps.depth = depth;
    config.maps.hole_pixels = hole;
    SceneCuller culler(scene, occluder_ids, config);
    WalkOptions walk;
    walk.frames = frames * 10;
    walk.seed = seed;
    const CameraPath path = walk_path(rays, scene, walk);
    for (int k = 0; k < frames; ++k) tally_culling(scene, rays, culler, path.frames[std::size_t(k) * 10], tally);
}

TEST(CullingVsTruth, GeneratedCityAndForestHaveNoFalseCulls) {
    for (const char* spec : {"city:seed=3,blocks=5", "forest:seed=4,radius=40"}) {
        const Scene scene = generate_scene(spec);
        CullingTally tally;
        tally_walk(scene, objects_with_role(scene, "occluder"), 6, {320, 180}, 1, tally);
        tally_walk(scene, objects_with_role(scene, "occluder"), 3, {320, 180}, 2, tally);
        report(spec, tally);
        EXPECT_EQ(tally.false_culls, 0u);
        EXPECT_GT(tally.culled_hidden, 0u);
    }
}

// Property test: random generated scenes and random walks through them; every conservative
// depth test of the occlusion maps, at one and at 2 x 2 samples per buffer pixel, has no false
// cull. (nbz is conservative only with one sample per pixel, where it equals hzb.)
TEST(CullingVsTruth, EveryConservativeDepthTestOnRandomScenesAndCameras) {
    std::uint64_t seed = 20;
    for (const char* spec : {"city:seed=7,blocks=4", "forest:seed=9,radius=30", "city:seed=12,blocks=3"}) {
        const Scene scene = generate_scene(spec);
        const std::vector<std::uint32_t> occluders = objects_with_role(scene, "occluder");
        for (DepthTest depth : {DepthTest::masked, DepthTest::hzb, DepthTest::deb, DepthTest::plane, DepthTest::nbz}) {
            CullingTally tally;
            tally_walk(scene, occluders, 3, {240, 136}, 1, tally, depth, ++seed);
            if (depth != DepthTest::nbz) tally_walk(scene, occluders, 2, {240, 136}, 2, tally, depth, ++seed);
            report((std::string(spec) + " depth " + std::to_string(int(depth))).c_str(), tally);
            EXPECT_EQ(tally.false_culls, 0u) << spec << " depth " << int(depth);
        }
    }
}

// Approximate mode may hide an object seen only through holes of at most L display pixels in
// all (buffer samples on the display's pixel centres), never one seen by more.
TEST(CullingVsTruth, ApproximateModeHidesNothingSeenByMoreThanL) {
    for (const char* spec : {"city:seed=7,blocks=4", "forest:seed=9,radius=30"}) {
        const Scene scene = generate_scene(spec);
        for (DepthTest depth : {DepthTest::masked, DepthTest::hzb}) {
            CullingTally tally;
            tally_walk(scene, objects_with_role(scene, "occluder"), 4, {240, 136}, 1, tally, depth, 31, 8.0);
            std::printf("[ culling  ] %s approximate L = 8, depth %d: %zu false culls (at most %llu samples), culled %zu of %zu hidden\n",
                        spec, int(depth), tally.false_culls, (unsigned long long)tally.most_samples_falsely_culled,
                        tally.culled_hidden, tally.hidden_in_frustum);
            EXPECT_LE(tally.most_samples_falsely_culled, 8u) << spec;
        }
    }
    // The castle's decorations (many triangles behind walls with small gaps) once showed each
    // triangle spending its own budget.
    const std::string castle_path = test::shared_scene("intel_castle.glb");
    if (castle_path.empty()) return;
    const Scene castle = load_scene(castle_path);
    CullingTally tally;
    tally_walk(castle, objects_with_role(castle, "occluder"), 8, {960, 540}, 1, tally, DepthTest::hzb, 1, 16.0);
    std::printf("[ culling  ] castle approximate L = 16: %zu false culls (at most %llu samples)\n", tally.false_culls,
                (unsigned long long)tally.most_samples_falsely_culled);
    EXPECT_LE(tally.most_samples_falsely_culled, 16u);
}

TEST(CullingVsTruth, CastleViewsHaveNoFalseCulls) {
    const std::string castle_path = test::shared_scene("intel_castle.glb");
    if (castle_path.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene castle = load_scene(castle_path);
    const RayScene rays(castle);
    const std::vector<std::uint32_t> occluders = objects_with_role(castle, "occluder");
    const CameraPath views = read_camera_path(std::string(HOMCULL_SOURCE_DIR) + "/data/views/castle.json");
    for (const bool clusters : {false, true}) {  // the occluders triangle by triangle, or as clusters
        SceneCullerConfig config;
        config.display = {1280, 720};
        config.occluder_clusters = clusters;
        SceneCuller full(castle, occluders, config);
        config.samples = 4;  // 320x180 buffer, 4x4 samples
        SceneCuller quarter(castle, occluders, config);
        CullingTally tally;
        for (const Camera& view : views.frames) tally_culling(castle, rays, full, view, tally);
        tally_culling(castle, rays, quarter, views.frames[0], tally);
        report(clusters ? "castle views, clusters" : "castle views", tally);
        EXPECT_EQ(tally.false_culls, 0u);
        EXPECT_GE(tally.efficiency(), 0.94) << "culling efficiency regressed (96.0 % when this floor was set)";
    }
}

// Occludee parts (SceneCullerConfig::occludee_parts) with box occludees: every object the
// object's box hides stays hidden, more are hidden (the parts' boxes are tighter), and none of
// them is seen by Embree. On the castle views and along a walk.
TEST(CullingVsTruth, CastlePartBoxesHideMoreThanObjectBoxesWithoutFalseCulls) {
    const std::string castle_path = test::shared_scene("intel_castle.glb");
    if (castle_path.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene castle = load_scene(castle_path);
    const RayScene rays(castle);
    const std::vector<std::uint32_t> occluders = objects_with_role(castle, "occluder");
    CameraPath views = read_camera_path(std::string(HOMCULL_SOURCE_DIR) + "/data/views/castle.json");
    WalkOptions walk;
    walk.frames = 40;
    const CameraPath path = walk_path(rays, castle, walk);
    for (std::size_t f = 0; f < path.frames.size(); f += 8) views.frames.push_back(path.frames[f]);
    SceneCullerConfig config;
    config.display = {640, 360};
    config.occludees = OccludeeShape::box;
    config.occluder_clusters = true;
    config.occludee_parts = 0;
    SceneCuller boxes(castle, occluders, config);
    config.occludee_parts = 16;
    SceneCuller parts(castle, occluders, config);
    CullingTally tally;
    std::vector<OccludeeAnswer> by_box, by_parts;
    std::size_t hidden_by_box = 0, hidden_by_parts = 0;
    for (const Camera& view : views.frames) {
        boxes.cull(view, by_box);
        parts.cull(view, by_parts);
        EXPECT_GT(parts.work().occludee_parts_tested, 0u);
        for (std::size_t id = 0; id < by_box.size(); ++id) {
            if (by_box[id].visibility == Visibility::occluded) {
                EXPECT_EQ(by_parts[id].visibility, Visibility::occluded) << "object " << id;
            }
            hidden_by_box += by_box[id].visibility == Visibility::occluded;
            hidden_by_parts += by_parts[id].visibility == Visibility::occluded;
        }
        tally_culling(castle, rays, parts, view, tally);
    }
    report("castle, box occludees with 16 parts", tally);
    EXPECT_EQ(tally.false_culls, 0u);
    EXPECT_GT(hidden_by_parts, hidden_by_box + hidden_by_box / 100) << "parts should hide at least 1 % more than boxes";
}

TEST(CullingVsTruth, SharedScenesAlongWalksHaveNoFalseCulls) {
    int found = 0;
    // Floors under the efficiency measured when they were set (100, 91.3, 99.4, 98.2 % with
    // the raised-vertex occludee bound): the house's misses are coplanar neighbours and
    // coincident faces, ties no conservative test can break.
    const std::pair<const char*, double> scenes[] = {
        {"crytek_sponza.glb", 0.97}, {"fzk_haus.glb", 0.88}, {"openarena_oa_thor.glb", 0.97}, {"openarena_pul1duel-oa.glb", 0.96}};
    for (const auto& [file, floor] : scenes) {
        const std::string path = test::shared_scene(file);
        if (path.empty()) continue;
        ++found;
        const Scene scene = load_scene(path);
        // The occluders triangle by triangle, as clusters, and as clusters of their merged
        // coplanar regions (SceneCullerConfig::merge_coplanar_occluders).
        for (const auto& [clusters, merged] : {std::pair{false, false}, std::pair{true, false}, std::pair{true, true}}) {
            CullingTally tally;
            tally_walk(scene, objects_with_role(scene, ""), 5, {640, 360}, 1, tally, DepthTest::masked, 1, 0.0, clusters, merged);
            const std::string what = std::string(file) + (clusters ? ", clusters" : "") + (merged ? ", coplanar regions merged" : "");
            report(what.c_str(), tally);
            EXPECT_EQ(tally.false_culls, 0u) << what;
            EXPECT_GE(tally.efficiency(), floor) << what << ": culling efficiency regressed";
            // Over the objects hidden outright (no tie could show them) every scene culls more
            // than 95 % (issue 4's figure), the house included: 98.4 % (63 of 64) on this short
            // walk, 99.3 to 100 % on the others when set. The floor keeps a margin of two objects.
            EXPECT_GE(tally.robust_efficiency(), 0.95) << what;
        }
    }
    if (found == 0) GTEST_SKIP() << "no shared scene in " << test::shared_scenes_dir();
}

}  // namespace
}  // namespace homcull
