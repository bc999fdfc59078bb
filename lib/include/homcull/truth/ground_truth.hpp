#pragma once
// Exact per-object visibility by ray casting (DESIGN.md, "The occlusion representation").
// Rays go from the eye (an orthographic camera: from the eye's plane, parallel to the view
// direction: Camera::ortho_height) through S x S sample positions per pixel, a regular grid at
// ((i + (a + 0.5)/S), (j + (b + 0.5)/S)) for a, b in [0, S): S = 1 is the pixel centre.
// A sample sees the closest surface with view depth in [near, far]; back faces count.
#include <homcull/camera.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

struct TruthOptions {
    Resolution resolution{1280, 720};
    int samples = 1;  // S, sub-samples per pixel along each axis, 1..16
    // A sample is "robust" when no other object lies within this relative view depth of its
    // hit: coincident surfaces (the castle's stacked market stalls, the house's rafters 1e-6
    // under the roof) make the closest hit arbitrary, and robust counts leave them out.
    double tie_relative_depth = 1e-4;
    bool keep_sample_ids = false;  // fill TruthResult::sample_ids
};

struct ObjectVisibility {
    bool in_frustum = false;  // the world AABB meets the view frustum (exact test)
    std::uint64_t visible_samples = 0;
    std::uint64_t robust_samples = 0;
    // Samples that see another object while this one lies within the tie window of that hit:
    // had the tie gone the other way, they would see this one. An object with no visible
    // sample but some tie samples is hidden only through ties (DESIGN.md's robust samples,
    // seen from the hidden side). At most 4 other objects are recorded per sample; a fifth
    // coincident one gets no tie sample there (and may then count as hidden outright).
    std::uint64_t tie_samples = 0;
};

// Hidden outright: in the frustum, no sample sees it, and no tie could have shown it (the
// objects a robust efficiency counts: DESIGN.md, "coincident surfaces").
inline bool hidden_outright(const ObjectVisibility& v) { return v.in_frustum && v.visible_samples == 0 && v.tie_samples == 0; }

// "visible" (some sample sees it), "occluded" (in the frustum, no sample sees it) or
// "view_culled": the per-object result of DESIGN.md's format.
inline const char* truth_result_name(const ObjectVisibility& v) {
    return v.visible_samples > 0 ? "visible" : v.in_frustum ? "occluded" : "view_culled";
}

struct TruthResult {
    std::vector<ObjectVisibility> objects;  // indexed by object id
    int sample_width = 0, sample_height = 0;  // resolution * samples
    // Object id per sample (kNoObject where nothing is hit), rows top to bottom; only when
    // TruthOptions::keep_sample_ids.
    std::vector<std::uint32_t> sample_ids;
    std::uint64_t rays = 0;     // primary plus tie-check rays
    double trace_ms = 0.0;
};

// Throws homcull::Error on an invalid camera or options. Uses all cores (TBB).
TruthResult compute_ground_truth(const RayScene& rays, const Scene& scene, const Camera& camera,
                                 const TruthOptions& options);

}  // namespace homcull
