#pragma once
// Walkthrough camera paths through the free space of a scene, found with ray casts.
#include <homcull/camera.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <cstdint>

namespace homcull {

struct WalkOptions {
    int frames = 200;
    std::uint64_t seed = 1;
    // Eye above the floor, in scene units; 0 = automatic: 1.7, or 64 for scenes larger than
    // 2,000 units across (Quake maps are in inches).
    double eye_height = 0.0;
    double step = 0.0;  // distance per frame; 0 = eye_height / 5
    double fov_y_degrees = 60.0;
};

// A smooth walk at eye height above walkable floors (surfaces within 45 degrees of level):
// it starts at a random floor point in the most enclosed open space (a street or a hall,
// not a roof), turns gently, steps up at most a
// fifth of the eye height, never steps off a ledge higher than half the eye height, and
// never moves closer than a quarter of the eye height to a wall. Every move is checked by
// ray casts at eye and knee height, so the path does not pass through geometry.
// Throws homcull::Error when no walkable floor with room to walk is found.
CameraPath walk_path(const RayScene& rays, const Scene& scene, const WalkOptions& options);

// `count` still views from random points of the scene's free space, looking anywhere: each eye
// uniform in the scene's bounding box, kept when it is not inside a solid (it sees the back of
// surfaces in at most half of 14 directions that meet any), with a direction uniform on the
// sphere (up +y, or +x when looking nearly straight up or down) and fov_y 60. Near 0.1 and far
// 10000 (64 times both for scenes over 2,000 units across, as default_eye_height). Throws
// homcull::Error when the scene is empty or 200 times `count` eyes were all inside solids.
CameraPath random_views(const RayScene& rays, const Scene& scene, int count, std::uint64_t seed);

// The automatic eye height of WalkOptions for a scene.
double default_eye_height(const Scene& scene);

}  // namespace homcull
