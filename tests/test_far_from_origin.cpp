// Scenes far from the origin: the culler and ground truth keep their precision wherever the
// scene lies, because both take world positions relative to the scene's anchor before rounding
// them to float (scene_anchor). Judged as the issue that found it did: the moved scene culled
// from moved cameras, against Embree on the unmoved scene.
#include "support.hpp"

#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/truth/culling_accuracy.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/truth/walk_path.hpp>

#include <gtest/gtest.h>

namespace homcull {
namespace {

Camera moved(Camera c, const glm::dvec3& offset) {
    c.eye += offset;
    c.target += offset;
    return c;
}

// Ground truth of a moved scene from moved cameras sees what the unmoved one sees: the same
// objects, and at most a few samples' difference in all (the anchored floats of the two scenes
// round a little differently). Rounding world positions at 1e4 to float moved them by up to
// 5e-4 and changed tens of thousands of samples per view.
TEST(FarFromOrigin, GroundTruthOfAMovedSceneSeesWhatTheUnmovedSceneSees) {
    std::vector<Scene> scenes;
    scenes.push_back(generate_scene("city:seed=4,blocks=4"));
    if (const std::string castle = test::shared_scene("intel_castle.glb"); !castle.empty()) scenes.push_back(load_scene(castle));
    TruthOptions options;
    options.resolution = {320, 180};
    for (const Scene& scene : scenes) {
        const RayScene rays(scene);
        const CameraPath views = random_views(rays, scene, 6, 3);
        for (const double offset : {1e4, 1e5, 1e6}) {
            const glm::dvec3 shift(offset, 0.0, offset);
            const Scene far = translated_scene(scene, shift);
            const RayScene far_rays(far);
            std::uint64_t differing = 0, samples = 0;
            for (const Camera& view : views.frames) {
                const TruthResult near_truth = compute_ground_truth(rays, scene, view, options);
                const TruthResult far_truth = compute_ground_truth(far_rays, far, moved(view, shift), options);
                for (std::size_t id = 0; id < scene.objects.size(); ++id) {
                    const std::uint64_t a = near_truth.objects[id].visible_samples, b = far_truth.objects[id].visible_samples;
                    differing += a > b ? a - b : b - a;
                    samples += a;
                    EXPECT_TRUE((a <= 2 || b > 0) && (b <= 2 || a > 0)) << scene.source << " at " << offset << ": object " << id << " seen by " << a << " / " << b;
                }
            }
            EXPECT_LE(differing, samples / 10000 + 8) << scene.source << " at " << offset;
            RecordProperty(scene.source + " at " + std::to_string(offset) + ": samples differing", std::to_string(differing) + " of " + std::to_string(samples));
        }
    }
}

// The reproducer: sponza moved by (1e4, 0, 1e4); object 1032 is seen by one pixel and
// the culler hid it. And the moved culler against the unmoved truth from random views.
TEST(FarFromOrigin, TheMovedCullerHidesNothingTheUnmovedTruthSees) {
    const std::string file = test::shared_scene("crytek_sponza.glb");
    if (file.empty()) GTEST_SKIP() << "needs ../shared/scenes/crytek_sponza.glb";
    const Scene scene = load_scene(file);
    const glm::dvec3 shift(1e4, 0.0, 1e4);
    const Scene far = translated_scene(scene, shift);
    const RayScene rays(scene);
    SceneCullerConfig config;
    config.display = {1280, 720};
    SceneCuller culler(far, objects_with_role(far, ""), config);
    Camera c;
    c.eye = glm::dvec3(9987.865259231337, 7.578402070416574, 10001.456824568562) - shift;
    c.target = glm::dvec3(9988.477916628659, 7.168506156960603, 10000.781075906973) - shift;
    c.fov_y_degrees = 60.0;
    c.near_plane = 0.1;
    c.far_plane = 10000.0;
    CullingTally tally;
    tally_culling(scene, rays, culler, c, tally, shift);
    for (const Camera& view : random_views(rays, scene, 8, 5).frames) tally_culling(scene, rays, culler, view, tally, shift);
    EXPECT_EQ(tally.false_culls, 0) << (tally.false_cull_reports.empty() ? "" : tally.false_cull_reports[0]);
    EXPECT_GT(tally.culled_hidden, 0);
}

}  // namespace
}  // namespace homcull
