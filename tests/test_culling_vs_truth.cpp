// The first test of anything that culls: the occlusion buffer's AABB answers against Embree
// ground truth at the same sample positions. A false cull (an object declared occluded or
// outside the view while some sample sees it) must never happen.
#include "support.hpp"

#include <homcull/generate.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/walk_path.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

namespace homcull {
namespace {

struct Tally {
    int views = 0;
    std::size_t false_culls = 0, culled_hidden = 0, hidden_in_frustum = 0, visible = 0;
    double efficiency() const { return hidden_in_frustum ? double(culled_hidden) / double(hidden_in_frustum) : 1.0; }
};

// Renders the occluders into a buffer of display / samples pixels with `samples` x `samples`
// samples each (so the samples are the display's pixel centres) and tests every object's AABB.
void tally_view(const Scene& scene, const RayScene& rays, const WorldTriangles& occluders, const Camera& camera,
                Resolution display, int samples, Tally& tally) {
    TruthOptions truth_options;
    truth_options.resolution = display;
    const TruthResult truth = compute_ground_truth(rays, scene, camera, truth_options);
    BufferConfig config;
    config.width = display.width / samples;
    config.height = display.height / samples;
    config.samples = samples;
    config.near_w = float(camera.near_plane);
    OcclusionBuffer buffer(config);
    const auto clip = clip_from_world(camera, display.aspect());
    // Back faces are surfaces to ground truth too, so they are fair occluders.
    buffer.render(occluders.input(clip, Backface::none));
    ++tally.views;
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Aabb& box = scene.objects[id].world_bounds;
        if (box.empty()) continue;
        const float lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
        const Visibility answer = buffer.test_aabb(lo, hi, clip);
        const ObjectVisibility& t = truth.objects[id];
        if (t.visible_samples > 0) {
            ++tally.visible;
            if (answer != Visibility::visible) {
                ++tally.false_culls;
                ADD_FAILURE() << scene.source << ": false cull of object " << id << " (" << scene.objects[id].name << "), seen by "
                              << t.visible_samples << " samples (" << t.robust_samples << " robust), eye "
                              << format_vec3(camera.eye) << " target " << format_vec3(camera.target);
            }
        } else if (t.in_frustum) {
            ++tally.hidden_in_frustum;
            tally.culled_hidden += answer != Visibility::visible;
        }
    }
}

void report(const char* what, const Tally& t) {
    std::printf("[ culling  ] %s: %d views, %zu visible objects, %zu false culls, culled %zu of %zu hidden (%.1f %%)\n", what,
                t.views, t.visible, t.false_culls, t.culled_hidden, t.hidden_in_frustum, 100.0 * t.efficiency());
}

void tally_walk(const Scene& scene, const std::vector<std::uint32_t>& occluder_ids, int frames, Resolution display, int samples,
                Tally& tally) {
    const RayScene rays(scene);
    const WorldTriangles occluders = gather_world_triangles(scene, occluder_ids);
    WalkOptions walk;
    walk.frames = frames * 10;
    const CameraPath path = walk_path(rays, scene, walk);
    for (int k = 0; k < frames; ++k) tally_view(scene, rays, occluders, path.frames[std::size_t(k) * 10], display, samples, tally);
}

TEST(CullingVsTruth, GeneratedCityAndForestHaveNoFalseCulls) {
    for (const char* spec : {"city:seed=3,blocks=5", "forest:seed=4,radius=40"}) {
        const Scene scene = generate_scene(spec);
        Tally tally;
        tally_walk(scene, objects_with_role(scene, "occluder"), 6, {320, 180}, 1, tally);
        tally_walk(scene, objects_with_role(scene, "occluder"), 3, {320, 180}, 2, tally);
        report(spec, tally);
        EXPECT_EQ(tally.false_culls, 0u);
        EXPECT_GT(tally.culled_hidden, 0u);
    }
}

TEST(CullingVsTruth, CastleViewsHaveNoFalseCulls) {
    const std::string castle_path = test::shared_scene("intel_castle.glb");
    if (castle_path.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene castle = load_scene(castle_path);
    const RayScene rays(castle);
    const WorldTriangles occluders = gather_world_triangles(castle, objects_with_role(castle, "occluder"));
    const CameraPath views = read_camera_path(std::string(HOMCULL_SOURCE_DIR) + "/data/views/castle.json");
    Tally tally;
    for (const Camera& view : views.frames) tally_view(castle, rays, occluders, view, {1280, 720}, 1, tally);
    tally_view(castle, rays, occluders, views.frames[0], {1280, 720}, 4, tally);  // 320x180 buffer, 4x4 samples
    report("castle views", tally);
    EXPECT_EQ(tally.false_culls, 0u);
}

TEST(CullingVsTruth, SharedScenesAlongWalksHaveNoFalseCulls) {
    int found = 0;
    for (const char* file : {"crytek_sponza.glb", "fzk_haus.glb", "openarena_oa_thor.glb", "openarena_pul1duel-oa.glb"}) {
        const std::string path = test::shared_scene(file);
        if (path.empty()) continue;
        ++found;
        const Scene scene = load_scene(path);
        Tally tally;
        tally_walk(scene, objects_with_role(scene, ""), 5, {640, 360}, 1, tally);
        report(file, tally);
        EXPECT_EQ(tally.false_culls, 0u) << file;
    }
    if (found == 0) GTEST_SKIP() << "no shared scene in " << test::shared_scenes_dir();
}

}  // namespace
}  // namespace homcull
