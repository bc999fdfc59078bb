#pragma once
// What SceneCuller's steps share within one frame (scene_culler.cpp selects and renders,
// scene_traversal.cpp tests).
#include <homcull/frustum.hpp>
#include <homcull/scene_culler.hpp>

#include "scene/scene_culler_state.hpp"

#include <array>
#include <chrono>

namespace homcull {

struct detail::SceneCullerState::Frame {
    const Camera* camera;
    std::array<float, 16> clip;  // anchored world (world minus the anchor) to clip, in float: the buffer's and the maps' input
    glm::dmat4 clip_double;      // world to clip in double, as ground truth transforms
    // The display's view frustum in anchored world (view_frustum_axes), for the exact test of
    // the boxes the buffer's screen rectangles find visible and of the occluder clusters.
    FrustumAxes frustum;
};

inline double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace homcull
