#pragma once
// What RayScene holds, for the truth library's own files that talk to Embree directly.
#include <homcull/truth/ray_scene.hpp>

#include <embree3/rtcore.h>

#include <mutex>
#include <string>

namespace homcull {

struct RayScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::size_t objects = 0;
    glm::dvec3 anchor{0.0};  // vertices and ray origins are relative to it

    // Embree reports errors through a callback; the first one is kept here.
    std::mutex error_mutex;
    std::string first_error;

    ~Impl();
};

}  // namespace homcull
