#include <homcull/truth/walkthrough.hpp>

#include <homcull/frustum.hpp>

#include <chrono>

namespace homcull {

WalkFrame measure_walk_frame(const Scene& scene, SceneCuller& culler, const Camera& camera, const TruthResult* truth,
                             std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    const auto start = std::chrono::steady_clock::now();
    culler.cull(camera, answers, parallel);
    const double frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    WalkFrame f;
    f.frame_ms = frame_ms;
    f.ms = culler.timings();
    f.work = culler.work();
    f.has_truth = truth != nullptr;
    if (truth) f.truth_ms = truth->trace_ms;
    // The frustum's axes once, not once per object (intersects() computes them per call: on
    // OpenArena's walks a sixth of the walk's run time).
    const FrustumAxes frustum = frustum_axes(make_frustum(camera, culler.config().display.aspect()));
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Object& object = scene.objects[id];
        const std::uint64_t n = scene.triangle_count(object);
        // The culler may answer "occluded" for an object outside the frustum (a hidden node
        // above it): the frustum count is the exact test of the object's own box.
        const bool in_frustum = !separated(frustum, object.world_bounds);
        const bool kept = answers[id].visibility == Visibility::visible;
        f.objects.total += 1;
        f.triangles.total += n;
        f.objects.after_frustum += in_frustum;
        f.triangles.after_frustum += in_frustum ? n : 0;
        f.objects.after_occlusion += kept;
        f.triangles.after_occlusion += kept ? n : 0;
        if (truth && !object.world_bounds.empty() && truth->objects[id].visible_samples > 0) {
            f.objects.exactly_visible += 1;
            f.triangles.exactly_visible += n;
        }
    }
    if (truth) tally_answers(scene, *truth, answers, camera, f.truth);
    return f;
}

}  // namespace homcull
