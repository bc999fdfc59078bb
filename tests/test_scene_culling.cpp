// Culling whole scenes (issue 5): the object hierarchy, occluder selection, and every
// strategy along walkthroughs against Embree ground truth: zero false culls, always.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/object_hierarchy.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/occluder_lod_build.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/truth/walk_path.hpp>
#include <homcull/truth/walkthrough.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <cstdio>

namespace homcull {
namespace {

bool contains(const Aabb& outer, const Aabb& inner) {
    return glm::all(glm::lessThanEqual(outer.min, inner.min)) && glm::all(glm::greaterThanEqual(outer.max, inner.max));
}

TEST(ObjectHierarchy, HoldsEveryObjectOnceInNestedBoxes) {
    Scene scene = generate_scene("city:seed=5,blocks=6");
    test::add_quad(scene, "empty mesh", {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0});  // a real box still
    scene.meshes.push_back({"no triangles", {}, {}});
    scene.objects.push_back({"no geometry", std::uint32_t(scene.meshes.size() - 1), glm::dmat4(1.0), {}, {}});
    scene.finalize();
    for (int leaf_size : {1, 4, 16}) {
        const ObjectHierarchy h = ObjectHierarchy::build(scene, leaf_size);
        ASSERT_FALSE(h.nodes.empty());
        std::vector<int> seen(scene.objects.size(), 0);
        for (std::uint32_t id : h.object_ids) ++seen[id];
        for (std::size_t id = 0; id < scene.objects.size(); ++id)
            EXPECT_EQ(seen[id], scene.objects[id].world_bounds.empty() ? 0 : 1) << "object " << id;
        EXPECT_EQ(h.nodes[0].begin, 0u);
        EXPECT_EQ(h.nodes[0].end, h.object_ids.size());
        for (const ObjectHierarchy::Node& node : h.nodes) {
            for (std::uint32_t i = node.begin; i < node.end; ++i)
                EXPECT_TRUE(contains(node.bounds, scene.objects[h.object_ids[i]].world_bounds));
            if (node.leaf()) {
                EXPECT_LE(node.end - node.begin, std::uint32_t(leaf_size));
                continue;
            }
            // The children split the parent's objects in two non-empty, contiguous parts.
            const ObjectHierarchy::Node& a = h.nodes[node.first_child];
            const ObjectHierarchy::Node& b = h.nodes[node.first_child + 1];
            EXPECT_EQ(a.begin, node.begin);
            EXPECT_EQ(a.end, b.begin);
            EXPECT_EQ(b.end, node.end);
            EXPECT_LT(a.begin, a.end);
            EXPECT_LT(b.begin, b.end);
        }
    }
    EXPECT_TRUE(ObjectHierarchy::build(Scene{}).nodes.empty());
    EXPECT_THROW(ObjectHierarchy::build(scene, 0), Error);
}

TEST(OccluderSelection, RankingKeepsTheFrustumOrderAndTheBudget) {
    const Scene scene = generate_scene("city:seed=3,blocks=6");
    const std::vector<std::uint32_t> candidates = occluder_candidates(scene, OccluderFilter::all);
    ASSERT_GT(candidates.size(), 50u);
    Camera camera;
    camera.eye = {-1.0, 1.7, -30.0};
    camera.target = {20.0, 3.0, 10.0};
    const double aspect = 16.0 / 9.0;
    const Frustum frustum = make_frustum(camera, aspect);
    std::vector<std::uint32_t> chosen;
    std::vector<std::pair<float, std::uint32_t>> scratch;

    // No budget: every candidate that may meet the frustum, and none that cannot.
    rank_occluders(scene, candidates, camera, aspect, {OccluderRanking::none, 0}, chosen, scratch);
    std::size_t in_frustum = 0;
    for (std::uint32_t id : candidates) in_frustum += may_meet(frustum, scene.objects[id].world_bounds);
    EXPECT_EQ(chosen.size(), in_frustum);
    EXPECT_LT(chosen.size(), candidates.size());
    for (std::uint32_t id : candidates) {  // the exact test never keeps what the plane test drops
        if (intersects(frustum, scene.objects[id].world_bounds)) {
            EXPECT_NE(std::find(chosen.begin(), chosen.end(), id), chosen.end());
        }
    }

    // Distance under a budget: nearest first, within the budget.
    for (std::size_t budget : {std::size_t(12), std::size_t(200), std::size_t(5000)}) {
        rank_occluders(scene, candidates, camera, aspect, {OccluderRanking::distance, budget}, chosen, scratch);
        ASSERT_FALSE(chosen.empty());
        std::size_t triangles = 0;
        double last = 0.0;
        for (std::uint32_t id : chosen) {
            triangles += scene.triangle_count(scene.objects[id]);
            const Aabb& b = scene.objects[id].world_bounds;
            const glm::dvec3 nearest = glm::clamp(camera.eye, glm::dvec3(b.min), glm::dvec3(b.max));
            const double d = std::max(glm::length(camera.eye - nearest), camera.near_plane);
            EXPECT_GE(d, last * (1.0 - 1e-6));
            last = d;
        }
        EXPECT_LE(triangles, budget);
    }
    // Area: the largest projected size first.
    rank_occluders(scene, candidates, camera, aspect, {OccluderRanking::area, 0}, chosen, scratch);
    EXPECT_EQ(chosen.size(), in_frustum);

    // A size limit: the candidates in the frustum whose box looks at least that large, (box
    // diagonal / distance)^2, the distance at least the near plane's; large_enough_to_draw agrees.
    for (const double limit : {0.001, 0.01, 0.1}) {
        OccluderBudget budget;
        budget.min_projected_size = limit;
        rank_occluders(scene, candidates, camera, aspect, budget, chosen, scratch);
        std::size_t large = 0;
        for (std::uint32_t id : candidates) {
            const Aabb& b = scene.objects[id].world_bounds;
            const glm::dvec3 nearest = glm::clamp(camera.eye, glm::dvec3(b.min), glm::dvec3(b.max));
            const double d = std::max(glm::length(camera.eye - nearest), camera.near_plane);
            const double diagonal = glm::length(glm::dvec3(b.extent()));
            const bool kept = std::find(chosen.begin(), chosen.end(), id) != chosen.end();
            const bool is_large = diagonal * diagonal / (d * d) >= limit;
            EXPECT_EQ(kept, is_large && may_meet(frustum, b)) << "object " << id << ", limit " << limit;
            EXPECT_EQ(large_enough_to_draw(b, camera, budget), is_large) << "object " << id << ", limit " << limit;
            large += kept;
        }
        EXPECT_GT(large, 0u) << limit;
        EXPECT_LT(large, in_frustum) << limit;
    }
}

TEST(OccluderSelection, ComplexityFilterDropsObjectsDenseForTheirSurface) {
    Scene scene;
    for (int k = 0; k < 5; ++k) test::add_box(scene, "box", {float(3 * k), 0, 0}, {float(3 * k + 2), 2, 2});
    const auto add_mesh = [&](const char* name, const std::vector<std::array<glm::vec3, 3>>& triangles) {
        Mesh mesh{name, {}, {}};
        for (const auto& t : triangles) {
            for (const glm::vec3& p : t) mesh.indices.push_back(std::uint32_t(mesh.positions.size())), mesh.positions.push_back(p);
        }
        scene.meshes.push_back(mesh);
        scene.objects.push_back({name, std::uint32_t(scene.meshes.size() - 1), glm::dmat4(1.0), {}, {}});
    };
    // The boxes: 12 triangles over 24 units of surface. "dense": 600 slivers of 0.04 each, 50 times
    // the boxes' triangles per unit of surface, in a box no smaller than theirs.
    std::vector<std::array<glm::vec3, 3>> slivers, flat;
    for (int t = 0; t < 600; ++t) {
        const float x = 20.0f + float(t) / 300.0f;
        slivers.push_back({glm::vec3{x, 0, 0}, glm::vec3{x, 0.2f, 0}, glm::vec3{x, 0, 0.4f}});
    }
    add_mesh("dense", slivers);
    // "flat": a panel of 2 x 2 triangles of 2 units each, as dense as the boxes, in a flat box.
    for (int t = 0; t < 2; ++t) flat.push_back({glm::vec3{30, 0, 2.0f * float(t)}, glm::vec3{32, 0, 2.0f * float(t)}, glm::vec3{30, 0, 2.0f * float(t) + 2}});
    add_mesh("flat", flat);
    // "empty": degenerate triangles only, no surface to hide anything with.
    add_mesh("empty", {{glm::vec3{40, 0, 0}, glm::vec3{41, 1, 1}, glm::vec3{42, 2, 2}}});
    scene.finalize();
    const std::vector<std::uint32_t> all = occluder_candidates(scene, OccluderFilter::all);
    ASSERT_EQ(all.size(), 8u);
    EXPECT_EQ(filter_by_complexity(scene, all, 0.0), all);  // off
    std::vector<std::uint32_t> without_empty(all.begin(), all.begin() + 7);
    EXPECT_EQ(filter_by_complexity(scene, all, 1000.0), without_empty);
    std::vector<std::uint32_t> boxes_and_flat(all.begin(), all.begin() + 5);
    boxes_and_flat.push_back(all[6]);
    EXPECT_EQ(filter_by_complexity(scene, all, 16.0), boxes_and_flat);
    EXPECT_TRUE(filter_by_complexity(scene, {}, 16.0).empty());
    // Mostly candidates without surface: the median is infinite, every one with a surface stays.
    EXPECT_EQ(filter_by_complexity(scene, {all[7], all[5], all[7]}, 16.0), std::vector<std::uint32_t>{all[5]});
    EXPECT_TRUE(filter_by_complexity(scene, {all[7]}, 16.0).empty());
}

struct StrategyCase {
    const char* name;
    CullStrategy strategy;
    OccluderBudget budget;
    bool hierarchy;
    bool lod = false;
    bool clusters = false;  // SceneCullerConfig::occluder_clusters
};
const StrategyCase kStrategies[] = {
    {"one-pass", CullStrategy::one_pass, {}, true},
    {"one-pass, flat", CullStrategy::one_pass, {}, false},
    {"one-pass, distance budget", CullStrategy::one_pass, {OccluderRanking::distance, 3000}, true},
    {"one-pass, area budget", CullStrategy::one_pass, {OccluderRanking::area, 3000}, true},
    {"progressive", CullStrategy::progressive, {}, true},
    {"progressive, budget", CullStrategy::progressive, {OccluderRanking::none, 2000}, true},
    {"temporal", CullStrategy::temporal, {}, true},
    {"temporal, distance budget", CullStrategy::temporal, {OccluderRanking::distance, 3000}, true},
    {"one-pass, LOD", CullStrategy::one_pass, {}, true, true},
    {"progressive, LOD", CullStrategy::progressive, {}, true, true},
    {"temporal, distance budget, LOD", CullStrategy::temporal, {OccluderRanking::distance, 3000}, true, true},
    {"one-pass, clusters", CullStrategy::one_pass, {}, true, false, true},
    {"progressive, clusters", CullStrategy::progressive, {}, true, false, true},
    {"temporal, distance budget, LOD, clusters", CullStrategy::temporal, {OccluderRanking::distance, 3000}, true, true, true},
    {"progressive, size limit", CullStrategy::progressive, {OccluderRanking::none, 0, nullptr, 0.02}, true},
    {"temporal, size limit, clusters", CullStrategy::temporal, {OccluderRanking::none, 0, nullptr, 0.02}, true, false, true},
};
constexpr std::size_t kOnePassLod = 8;

struct WalkTotals {
    std::size_t false_culls = 0, hidden = 0, missed = 0, objects_tested = 0, occluder_triangles = 0, occluder_lods = 0;
    double efficiency() const { return hidden ? double(hidden - missed) / double(hidden) : 1.0; }
};

// Consecutive frames of a walk (temporal needs them consecutive), every strategy with its own
// culler, ground truth cast once per frame.
std::vector<WalkTotals> walk_every_strategy(const Scene& scene, const std::vector<std::uint32_t>& candidates, int frames,
                                            Resolution display, std::uint64_t seed, int stride = 1) {
    const RayScene rays(scene);
    WalkOptions walk;
    walk.frames = frames * stride;
    walk.seed = seed;
    const CameraPath path = walk_path(rays, scene, walk);
    const OccluderLods lods = build_occluder_lods(scene, candidates);
    std::vector<SceneCuller> cullers;
    for (const StrategyCase& s : kStrategies) {
        SceneCullerConfig config;
        config.display = display;
        config.strategy = s.strategy;
        config.occluder_budget = s.budget;
        config.hierarchy = s.hierarchy;
        config.lods = s.lod ? &lods : nullptr;
        config.occluder_clusters = s.clusters;
        cullers.emplace_back(scene, candidates, config);
    }
    std::vector<WalkTotals> totals(cullers.size());
    TruthOptions truth_options;
    truth_options.resolution = display;
    std::vector<OccludeeAnswer> answers;
    for (int k = 0; k < frames; ++k) {
        const Camera& camera = path.frames[std::size_t(k * stride)];
        const TruthResult truth = compute_ground_truth(rays, scene, camera, truth_options);
        for (std::size_t c = 0; c < cullers.size(); ++c) {
            const WalkFrame f = measure_walk_frame(scene, cullers[c], camera, &truth, answers);
            totals[c].false_culls += f.truth.false_culls;
            totals[c].hidden += f.truth.hidden_in_frustum;
            totals[c].missed += f.truth.missed_culls();
            totals[c].objects_tested += f.work.objects_tested;
            totals[c].occluder_triangles += f.work.occluder_triangles;
            totals[c].occluder_lods += f.work.occluder_lods;
            if (kStrategies[c].budget.triangles) {
                EXPECT_LE(f.work.occluder_triangles, kStrategies[c].budget.triangles);
            }
            EXPECT_EQ(f.objects.total, scene.objects.size());
            EXPECT_LE(f.objects.exactly_visible, f.objects.after_frustum);
        }
    }
    for (std::size_t c = 0; c < cullers.size(); ++c)
        std::printf("[ strategy ] %s: %s: %zu false culls, culled %zu of %zu hidden (%.1f %%), %zu objects tested, %zu occluder "
                    "triangles (%zu LODs)\n",
                    scene.source.c_str(), kStrategies[c].name, totals[c].false_culls, totals[c].hidden - totals[c].missed,
                    totals[c].hidden, 100.0 * totals[c].efficiency(), totals[c].objects_tested, totals[c].occluder_triangles,
                    totals[c].occluder_lods);
    return totals;
}

// SceneCullerConfig::samples = 0: the samples that put a buffer on the display's pixel centres,
// else 4 x 4 for a low-resolution buffer; and what the buffer is then made with.
TEST(SceneCulling, AutomaticSamplesPutTheBufferOnTheDisplayOrGiveLowResolutionOnes4x4) {
    const Resolution display{1280, 720};
    EXPECT_EQ(automatic_samples(display, {0, 0}), 1);
    EXPECT_EQ(automatic_samples(display, {1280, 720}), 1);
    EXPECT_EQ(automatic_samples(display, {640, 360}), 2);
    EXPECT_EQ(automatic_samples(display, {320, 180}), 4);
    EXPECT_EQ(automatic_samples({1920, 1080}, {256, 128}), 4);  // low resolution, not on the display's grid
    EXPECT_EQ(automatic_samples({1920, 1080}, {600, 300}), 2);  // 4 x 4 would pass the display
    EXPECT_EQ(automatic_samples(display, {1280, 360}), 1);      // as wide as the display
    EXPECT_EQ(automatic_samples(display, {1200, 700}), 1);      // a little smaller: not 16 times the samples
    EXPECT_EQ(automatic_samples(display, {2560, 1440}), 1);     // more than the display

    SceneCullerConfig c;
    c.display = display;
    ASSERT_EQ(c.samples, 0);  // the default
    BufferConfig b = scene_buffer_config(c, 0.1f);
    EXPECT_EQ(b.width, 1280);
    EXPECT_EQ(b.height, 720);
    EXPECT_EQ(b.samples, 1);
    c.buffer = {320, 180};  // conservative: accepted, on the display's pixel centres
    b = scene_buffer_config(c, 0.1f);
    EXPECT_EQ(b.width, 320);
    EXPECT_EQ(b.samples, 4);
    c.buffer = {256, 128};  // not on them: conservative mode refuses it, approximate mode takes it 4 x 4
    EXPECT_THROW(scene_buffer_config(c, 0.1f), Error);
    c.maps.hole_pixels = 4.0;
    b = scene_buffer_config(c, 0.1f);
    EXPECT_EQ(b.samples, 4);
    c.samples = 2;  // given: kept
    EXPECT_EQ(scene_buffer_config(c, 0.1f).samples, 2);
    c.samples = 3;
    EXPECT_THROW(scene_buffer_config(c, 0.1f), Error);
}

TEST(SceneCulling, EveryStrategyOnGeneratedScenesHasNoFalseCulls) {
    for (const char* spec : {"city:seed=3,blocks=5", "forest:seed=4,radius=40"}) {
        const Scene scene = generate_scene(spec);
        const std::vector<WalkTotals> t = walk_every_strategy(scene, occluder_candidates(scene, OccluderFilter::role), 12, {320, 180}, 2);
        for (std::size_t c = 0; c < t.size(); ++c) {
            EXPECT_EQ(t[c].false_culls, 0u) << spec << ", " << kStrategies[c].name;
            EXPECT_GT(t[c].hidden - t[c].missed, 0u) << spec << ", " << kStrategies[c].name << " culls nothing";
        }
        // The hierarchy answers for whole hidden subtrees: fewer objects are tested, the same are culled.
        EXPECT_LT(t[0].objects_tested, t[1].objects_tested) << spec;
        EXPECT_EQ(t[0].missed, t[1].missed) << spec;
    }
}

TEST(SceneCulling, EveryStrategyOnSharedScenesHasNoFalseCulls) {
    int found = 0;
    for (const char* file : {"intel_castle.glb", "openarena_pul1duel-oa.glb"}) {
        const std::string path = test::shared_scene(file);
        if (path.empty()) continue;
        ++found;
        const Scene scene = load_scene(path);
        const std::vector<WalkTotals> t = walk_every_strategy(scene, occluder_candidates(scene, OccluderFilter::size), 8, {320, 180}, 1, 4);
        for (std::size_t c = 0; c < t.size(); ++c) EXPECT_EQ(t[c].false_culls, 0u) << file << ", " << kStrategies[c].name;
        // Temporal draws fewer occluders than one-pass for nearly the same culling.
        EXPECT_LT(t[6].occluder_triangles, t[0].occluder_triangles) << file;
        EXPECT_GE(t[6].efficiency(), t[0].efficiency() - 0.05) << file;
        // The castle's closed occluders have LODs: fewer triangles drawn, nothing more hidden
        // than the originals would hide (the false-cull check above), little culling lost.
        if (std::string(file) == "intel_castle.glb") {
            EXPECT_GT(t[kOnePassLod].occluder_lods, 0u);
            EXPECT_LT(t[kOnePassLod].occluder_triangles, t[0].occluder_triangles);
            EXPECT_GE(t[kOnePassLod].efficiency(), t[0].efficiency() - 0.02);
        }
    }
    if (found == 0) GTEST_SKIP() << "no shared scene in " << test::shared_scenes_dir();
}

// The castle, its role occluders and a walk of `frames` frames through it; false when the
// shared scene is missing.
struct CastleWalk {
    Scene castle;
    std::vector<std::uint32_t> candidates;
    CameraPath frames;
};
bool load_castle_walk(int frames, CastleWalk& out) {
    const std::string path = test::shared_scene("intel_castle.glb");
    if (path.empty()) return false;
    out.castle = load_scene(path);
    out.candidates = occluder_candidates(out.castle, OccluderFilter::role);
    const RayScene rays(out.castle);
    WalkOptions walk;
    walk.frames = frames;
    out.frames = walk_path(rays, out.castle, walk);
    return true;
}

// Occluders as clusters with a job system: the same answers and statistics as on one thread,
// frame after frame (progressive renders several batches a frame into the same buffer).
TEST(SceneCulling, ClustersGiveTheSameAnswersWithAJobSystem) {
    CastleWalk walk;
    if (!load_castle_walk(12, walk)) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene& castle = walk.castle;
    const std::vector<std::uint32_t>& candidates = walk.candidates;
    const CameraPath& frames = walk.frames;
    for (const CullStrategy strategy : {CullStrategy::one_pass, CullStrategy::progressive}) {
        SceneCullerConfig config;
        config.display = {480, 270};
        config.strategy = strategy;
        config.occluder_clusters = true;
        SceneCuller serial(castle, candidates, config), threaded(castle, candidates, config);
        std::vector<OccludeeAnswer> a, b;
        for (std::size_t f = 0; f < frames.frames.size(); f += 3) {
            serial.cull(frames.frames[f], a);
            threaded.cull(frames.frames[f], b, test::parallel_jobs());
            ASSERT_EQ(a.size(), b.size());
            for (std::size_t id = 0; id < a.size(); ++id) {
                EXPECT_EQ(a[id].visibility, b[id].visibility) << "frame " << f << ", object " << id;
                EXPECT_EQ(a[id].level_of_visibility, b[id].level_of_visibility) << "frame " << f << ", object " << id;
            }
            EXPECT_TRUE(serial.buffer().stats() == threaded.buffer().stats()) << "frame " << f;
            EXPECT_GT(serial.buffer().stats().cluster_bands_drawn, 0u);
        }
    }
}

// Lazy maps (the default): the buffer's depth test alone gives every object the visibility that
// the overlap test followed by the depth test gives, for boxes and for occludee triangles, along
// a castle walk with every strategy (progressive rebuilds the maps for each batch); the levels of
// visibility are shares in [0, 1], 0 for what is hidden.
TEST(SceneCulling, LazyMapsGiveTheSameVisibilityAsMapsWithTheirPyramids) {
    CastleWalk walk;
    if (!load_castle_walk(10, walk)) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene& castle = walk.castle;
    const std::vector<std::uint32_t>& candidates = walk.candidates;
    const CameraPath& frames = walk.frames;
    for (const CullStrategy strategy : {CullStrategy::one_pass, CullStrategy::progressive, CullStrategy::temporal})
        for (const OccludeeShape shape : {OccludeeShape::box, OccludeeShape::automatic}) {
            SceneCullerConfig config;
            config.display = {416, 234};
            config.strategy = strategy;
            config.occludees = shape;
            config.maps.pyramid = PyramidBuild::always;
            SceneCuller full(castle, candidates, config);
            config.maps.pyramid = PyramidBuild::lazy;
            SceneCuller lazy(castle, candidates, config);
            std::vector<OccludeeAnswer> a, b;
            std::size_t hidden = 0;
            for (std::size_t f = 0; f < frames.frames.size(); ++f) {
                lazy.cull(frames.frames[f], a);
                full.cull(frames.frames[f], b);
                ASSERT_EQ(a.size(), b.size());
                for (std::size_t id = 0; id < a.size(); ++id) {
                    ASSERT_EQ(a[id].visibility, b[id].visibility) << "strategy " << int(strategy) << ", frame " << f << ", object " << id;
                    ASSERT_GE(a[id].level_of_visibility, 0.0f);
                    ASSERT_LE(a[id].level_of_visibility, 1.0f);
                    if (a[id].visibility == Visibility::occluded) {
                        ASSERT_EQ(a[id].level_of_visibility, 0.0f);
                        ++hidden;
                    }
                }
                EXPECT_EQ(lazy.overlap_exits().count[std::size_t(OverlapExit::passed)], 0u);
                EXPECT_GT(full.overlap_exits().count[std::size_t(OverlapExit::passed)], 0u);
                // Dumps read the pyramids: maps() makes them.
                EXPECT_TRUE(lazy.maps().pyramid_built());
            }
            EXPECT_GT(hidden, 1000u) << "strategy " << int(strategy);
        }
}

// Temporal's second pass: an occluder hidden last frame that comes into view is drawn in the
// same frame, so what it hides is culled at once, as one-pass culls it.
TEST(SceneCulling, TemporalDrawsAnOccluderThatComesIntoViewAtOnce) {
    Scene scene;
    const std::uint32_t near_wall = test::add_quad(scene, "near wall", {-1, -1, -5}, {1, -1, -5}, {1, 1, -5}, {-1, 1, -5});
    const std::uint32_t far_wall = test::add_quad(scene, "far wall", {-1.8f, -1.8f, -10}, {1.8f, -1.8f, -10}, {1.8f, 1.8f, -10},
                                                  {-1.8f, 1.8f, -10});
    const std::uint32_t box = test::add_box(scene, "box", {-0.5f, -0.5f, -15.5f}, {0.5f, 0.5f, -14.5f});
    scene.finalize();
    const std::vector<std::uint32_t> candidates = {near_wall, far_wall};
    SceneCullerConfig config;
    config.display = {128, 128};
    config.strategy = CullStrategy::one_pass;
    SceneCuller one_pass(scene, candidates, config);
    config.strategy = CullStrategy::temporal;
    SceneCuller temporal(scene, candidates, config);
    // Frame a: the near wall hides the far wall and the box. Frame b: a step to the side (6
    // near distances, no camera cut) uncovers part of the far wall, which alone hides the box.
    const Camera a = test::camera_down_minus_z(60.0, 0.5);
    Camera b = a;
    b.eye = {3.0, 0.0, 0.0};
    b.target = {3.0, 0.0, -1.0};
    std::vector<OccludeeAnswer> answers, expected;
    temporal.cull(a, answers);
    ASSERT_EQ(answers[far_wall].visibility, Visibility::occluded);
    ASSERT_EQ(answers[box].visibility, Visibility::occluded);
    one_pass.cull(b, expected);
    ASSERT_EQ(expected[far_wall].visibility, Visibility::visible);
    ASSERT_EQ(expected[box].visibility, Visibility::occluded);
    temporal.cull(b, answers);
    EXPECT_EQ(answers[far_wall].visibility, Visibility::visible);
    EXPECT_EQ(answers[box].visibility, Visibility::occluded) << "the far wall, hidden last frame, was not drawn";
    EXPECT_EQ(temporal.work().occluder_objects, 2u);
    EXPECT_EQ(temporal.work().renders, 2u);  // the second pass
    EXPECT_TRUE(temporal.work().used_history);
}

// temporal works as one_pass at a camera cut: an eye that moved more than TemporalCut's step in
// near distances, or a view that turned more than its angle, since the last frame. Not at the
// limits themselves, nor after a step or a turn within them. From `start` the near wall hides
// the far one: a frame with history draws the near wall alone first (and the far wall in a
// second pass if it came into view), a cut frame draws what one_pass draws, in one render.
TEST(SceneCulling, TemporalWorksAsOnePassAtACameraCut) {
    Scene scene;
    const std::uint32_t near_wall = test::add_quad(scene, "near wall", {-1, -1, -5}, {1, -1, -5}, {1, 1, -5}, {-1, 1, -5});
    const std::uint32_t far_wall = test::add_quad(scene, "far wall", {-1.8f, -1.8f, -10}, {1.8f, -1.8f, -10}, {1.8f, 1.8f, -10},
                                                  {-1.8f, 1.8f, -10});
    scene.finalize();
    SceneCullerConfig config;
    config.display = {128, 128};
    ASSERT_EQ(config.strategy, CullStrategy::temporal);  // the default
    config.temporal_cut = {16.0, 20.0};
    SceneCuller culler(scene, {near_wall, far_wall}, config);
    config.strategy = CullStrategy::one_pass;
    SceneCuller one_pass(scene, {near_wall, far_wall}, config);
    const Camera start = test::camera_down_minus_z(60.0, 0.25);
    const auto moved = [&](double dx, double turn_degrees) {
        Camera c = start;
        c.eye.x += dx;
        const double t = glm::radians(turn_degrees);
        c.target = c.eye + glm::dvec3(std::sin(t), 0.0, -std::cos(t));
        return c;
    };
    std::vector<OccludeeAnswer> answers, expected;
    culler.cull(start, answers);
    EXPECT_FALSE(culler.work().used_history);  // the first frame
    ASSERT_EQ(answers[far_wall].visibility, Visibility::occluded);
    struct Step {
        double dx, turn_degrees;
        bool cut;
    };
    // Each from `start`, culled twice before it (the way back from a cut is one too): 4.0 is
    // exactly 16 near distances of 0.25.
    for (const Step& s : {Step{1.0, 0.0, false}, Step{4.0, 0.0, false}, Step{4.01, 0.0, true}, Step{0.0, 19.0, false},
                          Step{0.0, 21.0, true}, Step{-5.0, 0.0, true}, Step{0.0, -45.0, true}}) {
        culler.cull(start, answers);
        culler.cull(start, answers);
        ASSERT_TRUE(culler.work().used_history);
        const Camera camera = moved(s.dx, s.turn_degrees);
        culler.cull(camera, answers);
        EXPECT_EQ(culler.work().used_history, !s.cut) << "step " << s.dx << ", turn " << s.turn_degrees;
        if (!s.cut) continue;
        one_pass.cull(camera, expected);
        EXPECT_EQ(culler.drawn_occluders(), one_pass.drawn_occluders()) << "step " << s.dx << ", turn " << s.turn_degrees;
        EXPECT_EQ(culler.work().renders, one_pass.work().renders) << "step " << s.dx << ", turn " << s.turn_degrees;  // no second pass
        for (std::size_t id = 0; id < answers.size(); ++id) EXPECT_EQ(answers[id].visibility, expected[id].visibility);
    }
    // reset_history() makes the next frame one-pass whatever the camera.
    culler.cull(start, answers);
    culler.reset_history();
    culler.cull(start, answers);
    EXPECT_FALSE(culler.work().used_history);

    // Limits out of range are errors; infinity and 180 degrees turn the cuts off.
    config.strategy = CullStrategy::temporal;
    for (const TemporalCut bad : {TemporalCut{-1.0, 20.0}, TemporalCut{std::nan(""), 20.0}, TemporalCut{16.0, 181.0},
                                  TemporalCut{16.0, -1.0}, TemporalCut{16.0, std::nan("")}}) {
        config.temporal_cut = bad;
        EXPECT_THROW(SceneCuller(scene, {near_wall, far_wall}, config), Error);
    }
    config.temporal_cut = {std::numeric_limits<double>::infinity(), 180.0};
    SceneCuller never(scene, {near_wall, far_wall}, config);
    never.cull(start, answers);
    never.cull(moved(-1000.0, 180.0), answers);
    EXPECT_TRUE(never.work().used_history);
}

// A box beside the view that reaches behind the eye has its corners behind it, so the buffer's
// screen rectangle of the box covers the screen, though the box does not meet the frustum: it
// is answered view-culled (without a triangle test), in every occludee shape, as ground truth
// finds it outside the frustum; a box beside it that reaches into the frustum is not, nor is
// one in view. A wall hides nothing of them.
TEST(SceneCulling, BoxesBesideTheFrustumAreViewCulledThoughTheirRectangleCoversTheScreen) {
    Scene scene;
    const std::uint32_t wall = test::add_quad(scene, "wall", {-50, -50, -60}, {50, -50, -60}, {50, 50, -60}, {-50, 50, -60});
    // At depth 20 the view (60 degrees, 16:9) is 20.5 wide either side of the axis.
    const std::uint32_t beside = test::add_box(scene, "beside the view", {30, -1, -20}, {31, 3, 20});
    const std::uint32_t reaching = test::add_box(scene, "reaching into it", {15, -1, -20}, {16, 3, 20});
    const std::uint32_t ahead = test::add_box(scene, "ahead", {-1, -1, -12}, {1, 1, -10});
    scene.finalize();
    const Camera camera = test::camera_down_minus_z(60.0, 0.1, 1000.0);
    const Resolution display{160, 90};
    const RayScene rays(scene);
    TruthOptions options;
    options.resolution = display;
    const TruthResult truth = compute_ground_truth(rays, scene, camera, options);
    ASSERT_FALSE(truth.objects[beside].in_frustum);
    ASSERT_TRUE(truth.objects[reaching].in_frustum);
    ASSERT_GT(truth.objects[reaching].visible_samples, 0u);
    ASSERT_GT(truth.objects[ahead].visible_samples, 0u);
    for (const OccludeeShape shape : {OccludeeShape::box, OccludeeShape::rectangles, OccludeeShape::samples}) {
        SceneCullerConfig config;
        config.display = display;
        config.occludees = shape;
        SceneCuller culler(scene, {wall}, config);
        std::vector<OccludeeAnswer> answers;
        culler.cull(camera, answers);
        EXPECT_EQ(answers[beside].visibility, Visibility::view_culled) << int(shape);
        EXPECT_EQ(answers[reaching].visibility, Visibility::visible) << int(shape);
        EXPECT_EQ(answers[ahead].visibility, Visibility::visible) << int(shape);
        EXPECT_EQ(answers[wall].visibility, Visibility::visible) << int(shape);
    }
    // The same far from the world's origin (the culler tests boxes relative to its anchor).
    const glm::dvec3 far_away(3.0e5, -2.0e4, 7.0e5);
    Scene moved = scene;
    for (Object& object : moved.objects) object.world = glm::translate(glm::dmat4(1.0), far_away) * object.world;
    moved.finalize();
    Camera moved_camera = camera;
    moved_camera.eye += far_away, moved_camera.target += far_away;
    SceneCullerConfig config;
    config.display = display;
    SceneCuller culler(moved, {wall}, config);
    std::vector<OccludeeAnswer> answers;
    culler.cull(moved_camera, answers);
    EXPECT_EQ(answers[beside].visibility, Visibility::view_culled);
    EXPECT_EQ(answers[reaching].visibility, Visibility::visible);
    EXPECT_EQ(answers[ahead].visibility, Visibility::visible);
    // A far plane at the largest double (no far plane): the frustum leaves out the axes its far
    // corners reach; nothing in view is culled.
    Camera unbounded = camera;
    unbounded.far_plane = std::numeric_limits<double>::max();
    SceneCuller far_culler(scene, {wall}, config);
    far_culler.cull(unbounded, answers);
    EXPECT_EQ(answers[reaching].visibility, Visibility::visible);
    EXPECT_EQ(answers[ahead].visibility, Visibility::visible);
    EXPECT_EQ(answers[wall].visibility, Visibility::visible);
}

// An occluder above and beside the view that reaches behind the eye: its box passes the
// six-plane test (so it is drawn) but does not meet the frustum, and the screen rectangle of its
// cluster's box covers the screen (corners behind the eye), yet the culler leaves the cluster
// out (none of its triangles set up). The buffer is the one drawing it gives.
TEST(SceneCulling, ClustersOutsideTheFrustumAreNotSetUp) {
    Camera camera = test::camera_down_minus_z(60.0, 0.1, 1000.0);
    camera.target = {1.0, 0.8, -1.0};
    const Resolution display{160, 90};
    const Frustum frustum = make_frustum(camera, display.aspect());
    const Aabb corner{{-6, 6, 4}, {10, 14, 44}};  // reaching behind the eye
    ASSERT_TRUE(may_meet(frustum, corner));
    ASSERT_FALSE(intersects(frustum, corner));
    Scene scene;
    const std::uint32_t beside = test::add_box(scene, "beside a corner", corner.min, corner.max);
    // A wall facing the eye, 20 units down the view.
    const CameraBasis basis = camera_basis(camera);
    const glm::vec3 centre(camera.eye + 20.0 * basis.forward), right(4.0 * basis.right), up(4.0 * basis.up);
    const std::uint32_t wall = test::add_quad(scene, "wall", centre - right - up, centre + right - up, centre + right + up, centre - right + up);
    scene.finalize();
    SceneCullerConfig config;
    config.display = display;
    config.occludees = OccludeeShape::box;
    std::vector<OccludeeAnswer> answers;
    SceneCuller both(scene, {wall, beside}, config);
    both.cull(camera, answers);
    EXPECT_NE(answers[beside].visibility, Visibility::visible);
    EXPECT_EQ(answers[wall].visibility, Visibility::visible);
    EXPECT_EQ(both.work().occluder_objects, 2u);  // selected by the plane test, then its cluster left out
    SceneCuller wall_alone(scene, {wall}, config);
    wall_alone.cull(camera, answers);
    EXPECT_GT(wall_alone.buffer().stats().rasterized, 0u);
    EXPECT_EQ(both.buffer().stats().triangles_in, wall_alone.buffer().stats().triangles_in);
    config.occluder_clusters = false;
    SceneCuller as_triangles(scene, {wall, beside}, config);
    as_triangles.cull(camera, answers);
    EXPECT_GT(as_triangles.buffer().stats().triangles_in, both.buffer().stats().triangles_in);
    std::vector<float> depth_both, depth_triangles;
    both.buffer().read_depth(depth_both);
    as_triangles.buffer().read_depth(depth_triangles);
    EXPECT_EQ(depth_both, depth_triangles);
}

// Closed occluder meshes enclosing a positive volume are drawn without the triangles facing
// away from the eye (SceneCullerConfig::skip_closed_back_faces): left out at selection, or, as
// clusters, culled by the rasterizer; open meshes and closed ones wound inside out keep every
// triangle. The answers are those of drawing everything.
TEST(SceneCulling, ClosedOccludersAreDrawnWithoutTheirBackFaces) {
    Scene scene;
    const std::uint32_t wall = test::add_box(scene, "solid wall", {-5, -5, -20}, {5, 5, -10});
    Mesh inverted;  // a box wound inside out: its volume is negative, so it is left whole
    inverted.name = "inside-out box";
    for (int k = 0; k < 8; ++k) inverted.positions.emplace_back((k & 1) ? 9.0f : 7.0f, (k & 2) ? 1.0f : -1.0f, (k & 4) ? -12.0f : -14.0f);
    inverted.indices = {0, 6, 4, 0, 2, 6, 1, 7, 3, 1, 5, 7, 0, 5, 1, 0, 4, 5, 2, 7, 6, 2, 3, 7, 0, 3, 2, 0, 1, 3, 4, 7, 5, 4, 6, 7};
    const std::uint32_t inside_out = test::add_object_with_own_mesh(scene, std::move(inverted));
    const std::uint32_t quad = test::add_quad(scene, "open quad", {-9, -1, -12}, {-7, -1, -12}, {-7, 1, -12}, {-9, 1, -12});
    const std::uint32_t hidden = test::add_box(scene, "behind the wall", {-1, -1, -30}, {1, 1, -28});
    scene.finalize();
    const std::vector<std::uint32_t> candidates = {wall, inside_out, quad};
    const Camera camera = test::camera_down_minus_z(90.0);
    for (const bool clusters : {false, true}) {
        SceneCullerConfig config;
        config.display = {160, 120};
        config.occluder_clusters = clusters;
        SceneCuller skipping(scene, candidates, config);
        config.skip_closed_back_faces = false;
        SceneCuller drawing(scene, candidates, config);
        std::vector<OccludeeAnswer> skipped, drawn;
        skipping.cull(camera, skipped);
        drawing.cull(camera, drawn);
        ASSERT_EQ(skipped.size(), drawn.size());
        for (std::size_t id = 0; id < drawn.size(); ++id) EXPECT_EQ(skipped[id].visibility, drawn[id].visibility) << id;
        EXPECT_EQ(skipped[hidden].visibility, Visibility::occluded);
        EXPECT_EQ(drawing.work().back_faces_skipped, 0u);
        // Seen from straight in front, five of the wall's six faces face away; the inside-out
        // box and the quad keep all their triangles.
        EXPECT_EQ(drawing.buffer().stats().backface_culled, 0u);
        if (clusters) {
            EXPECT_EQ(skipping.work().back_faces_skipped, 0u);
            EXPECT_EQ(skipping.buffer().stats().backface_culled, 10u);  // one band of rows: counted once
        } else {
            EXPECT_EQ(skipping.work().back_faces_skipped, 10u);
            EXPECT_EQ(skipping.work().occluder_triangles, drawing.work().occluder_triangles);
        }
    }
}

// With backface cw (the CLI's --back-faces cull), no occluder triangle facing away from the eye
// is drawn, closed or not: a quad seen from behind hides nothing, one seen from the front still
// does, as triangles and as clusters.
TEST(SceneCulling, BackfaceCullingLeavesOutEveryOccluderTriangleFacingAway) {
    Scene scene;
    const std::uint32_t front = test::add_quad(scene, "seen from the front", {-6, -2, -10}, {-0.2f, -2, -10}, {-0.2f, 2, -10}, {-6, 2, -10});
    const std::uint32_t back = test::add_quad(scene, "seen from behind", {0.2f, -2, -10}, {0.2f, 2, -10}, {6, 2, -10}, {6, -2, -10});
    const std::uint32_t behind_front = test::add_box(scene, "behind the front quad", {-2.5f, -1, -20}, {-1.5f, 1, -18});
    const std::uint32_t behind_back = test::add_box(scene, "behind the back quad", {1.5f, -1, -20}, {2.5f, 1, -18});
    scene.finalize();
    const Camera camera = test::camera_down_minus_z(90.0);
    for (const bool clusters : {false, true}) {
        for (const Backface backface : {Backface::none, Backface::cw}) {
            SceneCullerConfig config;
            config.display = {160, 120};
            config.occluder_clusters = clusters;
            config.backface = backface;
            SceneCuller culler(scene, {front, back}, config);
            std::vector<OccludeeAnswer> answers;
            culler.cull(camera, answers);
            const char* what = clusters ? "clusters" : "triangles";
            EXPECT_EQ(answers[behind_front].visibility, Visibility::occluded) << what;
            EXPECT_EQ(answers[behind_back].visibility, backface == Backface::cw ? Visibility::visible : Visibility::occluded) << what;
            EXPECT_EQ(culler.buffer().stats().backface_culled, backface == Backface::cw ? 2u : 0u) << what;
        }
    }
}

// A wall made of two objects that meet along the view's middle column of sample centres (a
// hair beside them), and a stick behind that column alone. Drawing every candidate in the frustum (one-pass, no budget),
// the edge the two objects share goes without its coverage margin, as triangles and as
// clusters alike, and the wall hides the stick. With a budget the triangles take the flags
// within each object only: the margin opens a leak one sample wide along the seam, and the stick
// shows through it; the clusters keep the flag, the neighbour being drawn, unless the budget
// leaves it out.
// The two halves and the stick, for a 65 x 33 display seen by test::camera_down_minus_z(90).
struct SeamedWall {
    std::uint32_t left, right, stick;
};
// right_end: where the right half ends (x); narrower than the left half, it looks smaller.
SeamedWall add_seamed_wall(Scene& scene, float right_end = 10.0f) {
    // The seam 2^-12 sample right of the column's centres: inside the left half by less than the
    // margin (2^-10 sample). (A sample centre exactly on a shared edge is covered by neither side.)
    const float seam = 5.0f * (65.0f / 33.0f) * (2.0f / 65.0f) * 0x1.0p-12f;
    SeamedWall w;
    w.left = test::add_quad(scene, "left half", {-10, -10, -5}, {seam, -10, -5}, {seam, 10, -5}, {-10, 10, -5});
    w.right = test::add_quad(scene, "right half", {seam, -10, -5}, {right_end, -10, -5}, {right_end, 10, -5}, {seam, 10, -5});
    w.stick = test::add_box(scene, "stick behind the seam", {-1e-4f, -1, -10}, {1e-4f, 1, -9});
    return w;
}

TEST(SceneCulling, EdgesSharedAcrossObjectsCloseTheSeamAsTrianglesAndAsClusters) {
    Scene scene;
    const auto [left, right, stick] = add_seamed_wall(scene);
    scene.finalize();
    const Camera camera = test::camera_down_minus_z(90.0);
    for (const bool clusters : {false, true}) {
        for (const bool budget : {false, true}) {
            SceneCullerConfig config;
            config.display = {65, 33};  // odd: sample column 32's centres lie at NDC x = 0
            config.occluder_clusters = clusters;
            // Room for both, but a budget could have left one out: triangles and clusters take
            // the flags whose neighbour is drawn, here both halves.
            if (budget) config.occluder_budget.triangles = 100;
            SceneCuller culler(scene, {left, right}, config);
            std::vector<OccludeeAnswer> answers;
            culler.cull(camera, answers);
            EXPECT_EQ(culler.work().occluder_objects, 2u);
            EXPECT_EQ(answers[stick].visibility, Visibility::occluded)
                << (clusters ? "clusters" : "triangles") << (budget ? ", budget" : ", every candidate");
        }
        // Room for the left half alone: its edge on the seam keeps its margin, and the column
        // the seam passes just right of stays open.
        SceneCullerConfig config;
        config.display = {65, 33};
        config.occluder_clusters = clusters;
        config.occluder_budget.triangles = 2;
        SceneCuller culler(scene, {left, right}, config);
        std::vector<OccludeeAnswer> answers;
        culler.cull(camera, answers);
        ASSERT_EQ(culler.drawn_occluders(), std::vector<std::uint32_t>{left}) << (clusters ? "clusters" : "triangles");
        EXPECT_EQ(answers[stick].visibility, Visibility::visible) << (clusters ? "clusters" : "triangles") << ", the left half alone";
    }
}

// A size limit (OccluderBudget::min_projected_size) that leaves the narrower right half out
// leaves the seam open, as a budget does: the left half's edge on it keeps its margin, and the
// stick shows through; with both halves large enough, the seam closes.
TEST(SceneCulling, ASizeLimitLeavesTheSeamOpenWithTheNeighbourLeftOut) {
    Scene scene;
    const auto [left, right, stick] = add_seamed_wall(scene, 1.0f);
    scene.finalize();
    const Camera camera = test::camera_down_minus_z(90.0);
    // From the eye, 5 before the wall: the left half's box 20 x 10, (diagonal / 5)^2 = 20; the right
    // half's 20 x 1, 16.04.
    for (const bool clusters : {false, true}) {
        for (const double limit : {18.0, 15.0}) {
            SceneCullerConfig config;
            config.display = {65, 33};
            config.occluder_clusters = clusters;
            config.occluder_budget.min_projected_size = limit;
            SceneCuller culler(scene, {left, right}, config);
            std::vector<OccludeeAnswer> answers;
            culler.cull(camera, answers);
            const std::string label = std::string(clusters ? "clusters" : "triangles") + ", limit " + std::to_string(limit);
            if (limit == 18.0) {
                EXPECT_EQ(culler.drawn_occluders(), std::vector<std::uint32_t>{left}) << label;
                EXPECT_EQ(answers[stick].visibility, Visibility::visible) << label;
            } else {
                EXPECT_EQ(culler.drawn_occluders().size(), 2u) << label;
                EXPECT_EQ(answers[stick].visibility, Visibility::occluded) << label;
            }
        }
    }    // A limit below 0 or not a number is refused, naming the value; infinity draws nothing.
    for (const double limit : {-1.0, std::nan("")}) {
        SceneCullerConfig config;
        config.occluder_budget.min_projected_size = limit;
        EXPECT_THROW(SceneCuller(scene, {left, right}, config), Error) << limit;
    }
    SceneCullerConfig config;
    config.display = {65, 33};
    config.occluder_budget.min_projected_size = std::numeric_limits<double>::infinity();
    SceneCuller culler(scene, {left, right}, config);
    std::vector<OccludeeAnswer> answers;
    culler.cull(camera, answers);
    EXPECT_TRUE(culler.drawn_occluders().empty());
    EXPECT_EQ(answers[stick].visibility, Visibility::visible);
}

// Temporal culling draws last frame's visible candidates, then those that came into view: an
// edge shared with another object keeps its margin unless that object is drawn too, drawn as
// clusters or as triangles. Two halves of a wall, seam as above, a stick behind the seam, and a
// screen nearer the eye. From an eye moved right, the screen hides the right half. Back at the
// aligned eye, the left half and the screen are drawn first, the left half's seam edge with
// its margin (its neighbour is not drawn); the right half, found visible, is drawn next: the
// seam's column stays open and the stick visible. The frame after, both halves are drawn
// together and the seam is closed.
TEST(SceneCulling, TemporalClosesASeamOnlyWithTheNeighbourDrawn) {
    Scene scene;
    const auto [left, right, stick] = add_seamed_wall(scene);
    const std::uint32_t screen = test::add_quad(scene, "screen", {0.5f, -10, -2}, {10, -10, -2}, {10, 10, -2}, {0.5f, 10, -2});
    scene.finalize();
    const Camera aligned = test::camera_down_minus_z(90.0);
    Camera moved = aligned;
    moved.eye.x += 1.5;
    moved.target.x += 1.5;
    for (const bool clusters : {true, false}) {
        SceneCullerConfig config;
        config.display = {65, 33};
        config.strategy = CullStrategy::temporal;
        config.occluder_clusters = clusters;
        SceneCuller culler(scene, {left, right, screen}, config);
        std::vector<OccludeeAnswer> answers;
        culler.cull(moved, answers);
        ASSERT_EQ(answers[right].visibility, Visibility::occluded);
        culler.cull(aligned, answers);
        EXPECT_EQ(culler.drawn_occluders(), (std::vector<std::uint32_t>{left, screen, right}));
        EXPECT_EQ(answers[stick].visibility, Visibility::visible) << (clusters ? "clusters" : "triangles");
        culler.cull(aligned, answers);
        EXPECT_EQ(culler.drawn_occluders().size(), 3u);
        EXPECT_EQ(answers[stick].visibility, Visibility::occluded) << (clusters ? "clusters" : "triangles");
    }
}

// An orthographic camera is refused with an error that names it, not answered as a perspective
// one (its w = 1 everywhere would cull nothing, silently); the culler stays usable.
TEST(SceneCulling, OrthographicCamerasAreRefused) {
    Scene scene;
    const std::uint32_t wall = test::add_quad(scene, "wall", {-1, -1, -5}, {1, -1, -5}, {1, 1, -5}, {-1, 1, -5});
    const std::uint32_t box = test::add_box(scene, "box", {-0.5f, -0.5f, -15.5f}, {0.5f, 0.5f, -14.5f});
    scene.finalize();
    SceneCullerConfig config;
    config.display = {64, 64};
    SceneCuller culler(scene, {wall}, config);
    Camera ortho = test::camera_down_minus_z(60.0);
    ortho.ortho_height = 4.0;
    std::vector<OccludeeAnswer> answers;
    try {
        culler.cull(ortho, answers);
        ADD_FAILURE() << "an orthographic camera was culled with";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("orthographic"), std::string::npos) << e.what();
    }
    culler.cull(test::camera_down_minus_z(60.0), answers);
    EXPECT_EQ(answers[box].visibility, Visibility::occluded);
}

TEST(SceneCulling, TemporalFirstFrameIsOnePassAndResetForgets) {
    const Scene scene = generate_scene("city:seed=3,blocks=5");
    const std::vector<std::uint32_t> candidates = occluder_candidates(scene, OccluderFilter::role);
    SceneCullerConfig config;
    config.display = {160, 90};
    SceneCuller one_pass(scene, candidates, config);
    config.strategy = CullStrategy::temporal;
    SceneCuller temporal(scene, candidates, config);
    Camera a, b;
    a.eye = {-1.0, 1.7, -30.0};
    a.target = {20.0, 3.0, 10.0};
    b.eye = {-1.0, 1.7, -26.0};
    b.target = {18.0, 3.0, 12.0};
    std::vector<OccludeeAnswer> expected, answers;
    auto same_visibility = [&] {
        for (std::size_t id = 0; id < answers.size(); ++id)
            if (answers[id].visibility != expected[id].visibility) return false;
        return true;
    };
    one_pass.cull(a, expected);
    temporal.cull(a, answers);
    EXPECT_TRUE(same_visibility());
    EXPECT_EQ(temporal.work().occluder_triangles, one_pass.work().occluder_triangles);
    temporal.cull(b, answers);  // last frame's non-occluded candidates only
    EXPECT_LT(temporal.work().occluder_triangles, one_pass.work().occluder_triangles);
    temporal.reset_history();
    temporal.cull(a, answers);
    EXPECT_TRUE(same_visibility());
    EXPECT_EQ(temporal.work().occluder_triangles, one_pass.work().occluder_triangles);
}

}  // namespace
}  // namespace homcull
