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

// The automatic eye height of WalkOptions for a scene.
double default_eye_height(const Scene& scene);

}  // namespace homcull
