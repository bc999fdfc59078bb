#include <homcull/error.hpp>
#include <homcull/truth/culling_accuracy.hpp>

namespace homcull {

void tally_culling(const Scene& scene, const RayScene& rays, const WorldTriangles& occluders, const Camera& camera,
                   Resolution display, int samples, CullingTally& tally) {
    if (samples < 1 || display.width % samples != 0 || display.height % samples != 0)
        throw Error("culling accuracy: the display resolution must be a multiple of the samples per pixel axis");
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
                tally.robust_false_culls += t.robust_samples > 0;
                tally.false_cull_reports.push_back(scene.source + ": object " + std::to_string(id) + " (" + scene.objects[id].name +
                                                   ") seen by " + std::to_string(t.visible_samples) + " samples (" +
                                                   std::to_string(t.robust_samples) + " robust) from eye " + format_vec3(camera.eye) +
                                                   " to " + format_vec3(camera.target));
            }
        } else if (t.in_frustum) {
            ++tally.hidden_in_frustum;
            tally.culled_hidden += answer != Visibility::visible;
        }
    }
}

}  // namespace homcull
