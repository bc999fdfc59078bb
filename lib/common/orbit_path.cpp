#include <homcull/camera.hpp>
#include <homcull/error.hpp>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace homcull {

CameraPath orbit_path(const glm::dvec3& lo, const glm::dvec3& hi, int frames, double fov_y_degrees,
                      double height_fraction) {
    if (frames < 1) throw Error("orbit: the number of frames must be at least 1");
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) throw Error("orbit: the scene is empty");
    const glm::dvec3 centre = (lo + hi) * 0.5, extent = hi - lo;
    const double diagonal = std::max(glm::length(extent), 1e-6);
    // Far enough out that the whole box fits the vertical field of view.
    const double radius = 0.5 * diagonal / std::tan(glm::radians(fov_y_degrees) * 0.5) * 0.9 + 1e-6;
    CameraPath path;
    for (int k = 0; k < frames; ++k) {
        const double angle = 2.0 * glm::pi<double>() * k / frames;
        Camera c;
        c.eye = centre + glm::dvec3(radius * std::cos(angle), height_fraction * extent.y + 0.25 * radius,
                                    radius * std::sin(angle));
        c.target = centre;
        c.fov_y_degrees = fov_y_degrees;
        c.near_plane = std::max(1e-4, radius * 1e-3);
        c.far_plane = 2.0 * radius + 2.0 * diagonal;
        validate_camera(c);
        path.frames.push_back(c);
    }
    return path;
}

}  // namespace homcull
