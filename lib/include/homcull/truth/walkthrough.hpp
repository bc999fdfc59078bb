#pragma once
// One frame of a walkthrough measured as Zhang's culling graphs are: objects and triangles in
// total, after view-frustum culling, after occlusion culling and exactly visible (Embree), with
// the false and missed culls against that ground truth and the time of every stage.
#include <homcull/scene_culler.hpp>
#include <homcull/truth/culling_accuracy.hpp>
#include <homcull/truth/ground_truth.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

// Counts of objects or of their triangles at each step of the culling graph.
struct CullingGraphCounts {
    std::uint64_t total = 0;
    std::uint64_t after_frustum = 0;    // whose box meets the view frustum (exact test)
    std::uint64_t after_occlusion = 0;  // the culler's visible answers
    std::uint64_t exactly_visible = 0;  // seen by some sample (ground truth); 0 without truth
};

struct WalkFrame {
    CullingGraphCounts objects, triangles;
    bool has_truth = false;
    // The answers against ground truth (tally_answers, one view; empty without truth): false
    // and missed culls, ties. Its stage times are in `ms`, not here.
    CullingTally truth;
    SceneCullTimings ms;
    // The whole cull() call, as an engine pays it: the stages in `ms` and what lies between
    // them (the answers' reset, a new near plane).
    double frame_ms = 0.0;
    SceneCullWork work;
    double truth_ms = 0.0;
};

// Culls one frame with `culler` (answers[id] out) and measures it; with `truth` (computed for
// the same camera at the culler's display resolution) also against ground truth.
WalkFrame measure_walk_frame(const Scene& scene, SceneCuller& culler, const Camera& camera, const TruthResult* truth,
                             std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel = {});

}  // namespace homcull
