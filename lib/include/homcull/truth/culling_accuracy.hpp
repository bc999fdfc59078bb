#pragma once
// Culling answers against ground truth, per view: the measure every culling feature is
// checked with (DESIGN.md, "false cull", "missed cull", "culling efficiency").
#include <homcull/occlusion_buffer.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/world_triangles.hpp>

#include <string>
#include <vector>

namespace homcull {

struct CullingTally {
    int views = 0;
    std::size_t visible = 0;            // objects some sample sees
    std::size_t hidden_in_frustum = 0;  // in the frustum, seen by no sample
    std::size_t culled_hidden = 0;      // of those, declared occluded or view-culled
    std::size_t false_culls = 0;        // seen, yet declared occluded or view-culled
    std::size_t robust_false_culls = 0; // of those, seen by at least one robust sample
    std::vector<std::string> false_cull_reports;  // one line each: view, object, samples
    double efficiency() const { return hidden_in_frustum ? double(culled_hidden) / double(hidden_in_frustum) : 1.0; }
    std::size_t missed_culls() const { return hidden_in_frustum - culled_hidden; }
};

// Renders `occluders` (no backface culling: back faces are surfaces to ground truth) into a
// buffer of display / samples pixels with samples x samples samples each, so that its samples
// are the display's pixel centres; tests every object's world AABB; and tallies the answers
// against ground truth cast at the display's pixel centres.
void tally_culling(const Scene& scene, const RayScene& rays, const WorldTriangles& occluders, const Camera& camera,
                   Resolution display, int samples, CullingTally& tally);

}  // namespace homcull
