#pragma once
// Culling answers against ground truth, per view: the measure every culling feature is
// checked with (DESIGN.md, "false cull", "missed cull", "culling efficiency").
#include <homcull/occlusion_buffer.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/scene_culler.hpp>

#include <string>
#include <vector>

namespace homcull {

struct CullingTally {
    int views = 0;
    std::size_t visible = 0;            // objects some sample sees
    std::size_t hidden_in_frustum = 0;  // in the frustum, seen by no sample
    std::size_t culled_hidden = 0;      // of those, declared occluded or view-culled
    // Of the hidden ones, those hidden only through ties (ObjectVisibility::tie_samples > 0):
    // under another tie-break some sample would see them, so culling them is not required.
    std::size_t hidden_through_ties = 0;
    std::size_t culled_through_ties = 0;  // of those, declared occluded or view-culled
    std::size_t false_culls = 0;        // seen, yet declared occluded or view-culled
    std::size_t robust_false_culls = 0; // of those, seen by at least one robust sample
    std::uint64_t most_samples_falsely_culled = 0;  // the largest visible_samples among them
    std::vector<std::string> false_cull_reports;  // one line each: view, object, samples
    SceneCullTimings total_ms;                    // the culler's stage times, summed over views
    double efficiency() const { return hidden_in_frustum ? double(culled_hidden) / double(hidden_in_frustum) : 1.0; }
    std::size_t missed_culls() const { return hidden_in_frustum - culled_hidden; }
    // Culling efficiency over the objects hidden outright (no tie samples).
    double robust_efficiency() const {
        const std::size_t hidden = hidden_in_frustum - hidden_through_ties;
        return hidden ? double(culled_hidden - culled_through_ties) / double(hidden) : 1.0;
    }
    // Adds another tally's views (a walk sums its frames' tallies).
    CullingTally& operator+=(const CullingTally& o);
};

// Tallies one view's answers (answers[id] per object) against its ground truth.
void tally_answers(const Scene& scene, const TruthResult& truth, const std::vector<OccludeeAnswer>& answers, const Camera& camera,
                   CullingTally& tally);

// Culls the scene from `camera` with `culler` and tallies its answers against ground truth
// cast at the display's pixel centres (the culler's display resolution). With an offset, the
// culler's scene is `scene` moved by it (translated_scene, the same object ids) and it culls
// from the camera moved by it: the moved culler judged against the exact, unmoved geometry.
void tally_culling(const Scene& scene, const RayScene& rays, SceneCuller& culler, const Camera& camera, CullingTally& tally,
                   const glm::dvec3& culler_offset = glm::dvec3(0.0));

}  // namespace homcull
