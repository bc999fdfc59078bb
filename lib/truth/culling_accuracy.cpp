#include <homcull/error.hpp>
#include <homcull/truth/culling_accuracy.hpp>

#include <algorithm>

namespace homcull {

void tally_culling(const Scene& scene, const RayScene& rays, SceneCuller& culler, const Camera& camera, CullingTally& tally,
                   const glm::dvec3& culler_offset) {
    TruthOptions truth_options;
    truth_options.resolution = culler.config().display;
    const TruthResult truth = compute_ground_truth(rays, scene, camera, truth_options);
    std::vector<OccludeeAnswer> answers;
    Camera moved = camera;
    moved.eye += culler_offset;
    moved.target += culler_offset;
    culler.cull(moved, answers);
    tally.total_ms.render_ms += culler.timings().render_ms;
    tally.total_ms.maps_ms += culler.timings().maps_ms;
    tally.total_ms.test_ms += culler.timings().test_ms;
    tally_answers(scene, truth, answers, camera, tally);
}

CullingTally& CullingTally::operator+=(const CullingTally& o) {
    views += o.views;
    visible += o.visible;
    hidden_in_frustum += o.hidden_in_frustum;
    culled_hidden += o.culled_hidden;
    hidden_through_ties += o.hidden_through_ties;
    culled_through_ties += o.culled_through_ties;
    false_culls += o.false_culls;
    robust_false_culls += o.robust_false_culls;
    most_samples_falsely_culled = std::max(most_samples_falsely_culled, o.most_samples_falsely_culled);
    false_cull_reports.insert(false_cull_reports.end(), o.false_cull_reports.begin(), o.false_cull_reports.end());
    total_ms.select_ms += o.total_ms.select_ms;
    total_ms.render_ms += o.total_ms.render_ms;
    total_ms.maps_ms += o.total_ms.maps_ms;
    total_ms.test_ms += o.total_ms.test_ms;
    return *this;
}

void tally_answers(const Scene& scene, const TruthResult& truth, const std::vector<OccludeeAnswer>& answers, const Camera& camera,
                   CullingTally& tally) {
    ++tally.views;
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        if (scene.objects[id].world_bounds.empty()) continue;
        const Visibility answer = answers[id].visibility;
        const ObjectVisibility& t = truth.objects[id];
        if (t.visible_samples > 0) {
            ++tally.visible;
            if (answer != Visibility::visible) {
                ++tally.false_culls;
                tally.robust_false_culls += t.robust_samples > 0;
                tally.most_samples_falsely_culled = std::max(tally.most_samples_falsely_culled, t.visible_samples);
                tally.false_cull_reports.push_back(scene.source + ": object " + std::to_string(id) + " (" + scene.objects[id].name +
                                                   ") seen by " + std::to_string(t.visible_samples) + " samples (" +
                                                   std::to_string(t.robust_samples) + " robust) from eye " + format_vec3(camera.eye) +
                                                   " to " + format_vec3(camera.target));
            }
        } else if (t.in_frustum) {
            ++tally.hidden_in_frustum;
            tally.culled_hidden += answer != Visibility::visible;
            if (t.tie_samples > 0) {
                ++tally.hidden_through_ties;
                tally.culled_through_ties += answer != Visibility::visible;
            }
        }
    }
}

}  // namespace homcull
