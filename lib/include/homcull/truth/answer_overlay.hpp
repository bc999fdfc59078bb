#pragma once
// The scene as the eye sees it, coloured by the culler's answers (Zhang 1998, Fig. 1.1 style):
// a debugging picture of one frame. Rays from the eye through every pixel centre (the samples
// ground truth uses) find the visible surface; its object's answer picks the colour:
//   - drawn as an occluder this frame: blue;
//   - kept (answered visible): grey;
//   - culled (occluded or view-culled) yet seen here: magenta, unshaded. Every magenta pixel is
//     a false cull, the one thing a conservative culler must never do;
//   - nothing hit: black.
// Surfaces are shaded by the angle between their normal and the ray, and object outlines are
// darkened, so that the picture reads as geometry.
#include <homcull/aabb.hpp>
#include <homcull/camera.hpp>
#include <homcull/occlusion_maps.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

struct AnswerOverlay {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  // 3 bytes per pixel, rows top to bottom
    std::size_t false_cull_pixels = 0;
    std::vector<std::uint32_t> false_culls;  // object ids seen although culled, ascending
};

// `answers` per object id (SceneCuller::cull's); `drawn` the objects drawn as occluders this
// frame (SceneCuller::drawn_occluders()). Throws homcull::Error on a mismatch of sizes or an
// invalid camera or resolution. Uses TBB's threads.
AnswerOverlay render_answer_overlay(const RayScene& rays, const Camera& camera, Resolution resolution,
                                    const std::vector<OccludeeAnswer>& answers, const std::vector<std::uint32_t>& drawn);

// The same answers seen from above (Zhang 1998, Fig. 1.1 style): an orthographic view down
// the y axis over the scene's x-z extent, `width` pixels wide, each pixel coloured by the
// answer of the object on top there: drawn occluder blue, kept grey, occluded orange,
// view-culled dark slate, and the objects in `false_culls` magenta. The camera's frustum is
// drawn in yellow from the eye. Objects hidden under a roof in this view are not shown.
AnswerOverlay render_answer_map(const RayScene& rays, const Aabb& scene_bounds, const Camera& camera, Resolution display,
                                const std::vector<OccludeeAnswer>& answers, const std::vector<std::uint32_t>& drawn,
                                const std::vector<std::uint32_t>& false_culls, int width = 800);

}  // namespace homcull
