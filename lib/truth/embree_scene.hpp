#pragma once
// What RayScene holds, for the truth library's own files that talk to Embree directly.
#include <homcull/camera.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <embree3/rtcore.h>
#include <glm/vec3.hpp>

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

// A single ray from `origin` (relative to the ray scene's anchor) along `direction` over
// [t_near, t_far], every mask bit set, with no hit yet: the ray rtcIntersect1 takes.
inline RTCRayHit single_ray(const glm::vec3& origin, const glm::vec3& direction, float t_near, float t_far) {
    RTCRayHit rh{};
    rh.ray.org_x = origin.x, rh.ray.org_y = origin.y, rh.ray.org_z = origin.z;
    rh.ray.dir_x = direction.x, rh.ray.dir_y = direction.y, rh.ray.dir_z = direction.z;
    rh.ray.tnear = t_near;
    rh.ray.tfar = t_far;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

// One ray per display pixel centre from a perspective camera's eye, as the sort truth and the
// occluder bound cast them (one at a time, with a filter that sees every hit).
struct PixelCentreRays {
    PixelCentreRays(const RayScene& rays, const Camera& view, Resolution screen)
        : scene(rays.impl().scene),
          camera(view),
          basis(camera_basis(view)),
          display(screen),
          eye(view.eye - rays.anchor()),
          t_near(float(view.near_plane)),
          t_far(float(view.far_plane)) {}
    RTCRayHit at(int x, int y) const {
        const glm::vec3 d(ray_direction(camera, basis, display.aspect(), pixel_to_ndc(display, x + 0.5, y + 0.5)));
        return single_ray(eye, d, t_near, t_far);
    }
    RTCScene scene;
    Camera camera;
    CameraBasis basis;
    Resolution display;
    glm::vec3 eye;  // relative to the anchor in double, then rounded
    float t_near, t_far;
};

}  // namespace homcull
