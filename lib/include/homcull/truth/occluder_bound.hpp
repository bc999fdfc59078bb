#pragma once
// The most a culler drawing a given set of occluders can cull from one view: a diagnostic that
// splits a culler's misses into those its occluders could not hide at all (a matter of which
// objects are drawn: occluder selection) and those they could (a matter of how they are drawn
// and tested: margins, bounds, depth estimates).
//
// Rays go through the display's pixel centres, as compute_ground_truth casts them (S = 1), and
// stop only at the occluders' geometry: every other object met before the first occluder hit
// is seen there. An object is hideable by the occluders when no ray sees it: wherever a ray
// meets it, an occluder lies strictly nearer. An occluder met first is seen too (nothing
// drawn hides it there). Objects no ray meets (hidden or outside the view) are hideable.
#include <homcull/camera.hpp>
#include <homcull/occlusion_maps.hpp>
#include <homcull/scene.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

struct OccluderBound {
    std::vector<std::uint8_t> hideable;  // per object id: 1 when the occluders hide it at every pixel centre
    std::uint64_t rays = 0;              // one per pixel centre
    std::uint64_t hits = 0;              // hits met before each ray's first occluder, or its end
    double trace_ms = 0.0;
};

// Throws homcull::Error on an invalid or orthographic camera, an invalid resolution, a ray
// scene built from another scene, or an occluder id out of range. Uses all cores (oneTBB).
OccluderBound occluder_bound(const RayScene& rays, const Scene& scene, const Camera& camera, Resolution display,
                             const std::vector<std::uint32_t>& occluders);

// A culler's answers beside the bound, over the objects ground truth finds hidden outright (in
// the view frustum, no sample seeing them, no tie: the objects CullingTally::robust_efficiency
// counts).
struct OccluderBoundTally {
    std::size_t hidden = 0;               // hidden outright
    std::size_t hideable = 0;             // of those, hideable by the occluders
    std::size_t missed_hideable = 0;      // answered visible though hideable: lost to how the occluders are drawn and tested
    std::size_t missed_not_hideable = 0;  // answered visible and not hideable: lost to which objects are drawn
    double efficiency_bound() const { return hidden ? double(hideable) / double(hidden) : 1.0; }
    OccluderBoundTally& operator+=(const OccluderBoundTally& o);  // a walk sums its frames'
};
// answers[id] and truth.objects[id] per object id, as bound.hideable.
OccluderBoundTally tally_bound(const TruthResult& truth, const OccluderBound& bound, const std::vector<OccludeeAnswer>& answers);

}  // namespace homcull
