// Walkthrough paths: a walker at eye height that feels its way through the scene with rays.
#include "scene/random.hpp"

#include <homcull/error.hpp>
#include <homcull/truth/walk_path.hpp>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

constexpr float kNoLimit = 1e30f;
const glm::dvec3 kDown(0.0, -1.0, 0.0);

glm::dvec3 heading_vector(double angle) { return {std::cos(angle), 0.0, std::sin(angle)}; }

class Walker {
public:
    Walker(const RayScene& rays, double eye_height)
        : rays_(rays), eye_height_(eye_height), clearance_(0.25 * eye_height),
          max_step_up_(0.2 * eye_height), max_drop_(0.5 * eye_height) {}

    // Free distance along a direction from a point, up to `limit`.
    double free_distance(const glm::dvec3& from, const glm::dvec3& direction, double limit) const {
        const RayHit hit = rays_.intersect(glm::vec3(from), glm::vec3(direction), 0.0f, float(limit));
        return hit.hit() ? double(hit.t) : limit;
    }

    // The floor under a point: a surface within 45 degrees of level. Returns its height.
    bool floor_below(const glm::dvec3& from, double limit, double& floor_y) const {
        const RayHit hit = rays_.intersect(glm::vec3(from), glm::vec3(kDown), 0.0f, float(limit));
        if (!hit.hit()) return false;
        const glm::vec3 n = glm::normalize(hit.normal);
        if (std::abs(n.y) < 0.7071f) return false;
        floor_y = from.y - double(hit.t);
        return true;
    }

    // Horizontal free distance from an eye position, the smaller of eye and knee height.
    double free_ahead(const glm::dvec3& eye, const glm::dvec3& direction, double limit) const {
        const glm::dvec3 knee = eye - glm::dvec3(0.0, 0.7 * eye_height_, 0.0);
        return std::min(free_distance(eye, direction, limit), free_distance(knee, direction, limit));
    }

    // Is the eye position in open space: room around it and overhead, not inside a solid?
    // Returns the mean free distance over 8 directions (a measure of openness), or -1.
    double openness(const glm::dvec3& eye, double look) const {
        if (free_distance(eye, {0, 1, 0}, 0.3 * eye_height_) < 0.3 * eye_height_) return -1;
        double total = 0.0;
        int back_faces = 0;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 d = heading_vector(k * glm::quarter_pi<double>());
            const RayHit hit = rays_.intersect(glm::vec3(eye), glm::vec3(d), 0.0f, float(look));
            const double free = hit.hit() ? double(hit.t) : look;
            if (free < 2 * clearance_) return -1;
            // Seeing the inside of surfaces in most directions means we are inside a solid.
            if (hit.hit() && glm::dot(glm::dvec3(hit.normal), d) > 0.0) ++back_faces;
            total += free;
        }
        if (back_faces >= 5) return -1;
        return total / 8.0;
    }

    const RayScene& rays_;
    double eye_height_, clearance_, max_step_up_, max_drop_;
};

}  // namespace

double default_eye_height(const Scene& scene) {
    const Aabb b = scene.bounds();
    if (b.empty()) return 1.7;
    return glm::length(glm::dvec3(b.extent())) > 2000.0 ? 64.0 : 1.7;
}

CameraPath walk_path(const RayScene& rays, const Scene& scene, const WalkOptions& options) {
    if (options.frames < 1) throw Error("walk: the number of frames must be at least 1");
    const Aabb bounds = scene.bounds();
    if (bounds.empty()) throw Error("walk: the scene " + scene.source + " is empty");
    const double eye_height = options.eye_height > 0 ? options.eye_height : default_eye_height(scene);
    const double step = options.step > 0 ? options.step : eye_height / 5.0;
    const glm::dvec3 lo(bounds.min), hi(bounds.max);
    const double diagonal = glm::length(hi - lo);
    const Walker walker(rays, eye_height);
    const double look = 20.0 * step;
    detail::SplitMix64 rng(options.seed);

    // Start at the most open of up to 48 valid random floor points.
    glm::dvec3 eye(0.0);
    double best = -1.0;
    int found = 0;
    for (int attempt = 0; attempt < 20000 && found < 48; ++attempt) {
        const glm::dvec3 probe(rng.uniform(lo.x, hi.x), rng.uniform(lo.y, hi.y), rng.uniform(lo.z, hi.z));
        double floor_y;
        if (!walker.floor_below(probe, hi.y - lo.y + 1.0, floor_y)) continue;
        const glm::dvec3 candidate(probe.x, floor_y + eye_height, probe.z);
        const double open = walker.openness(candidate, look);
        if (open < 4.0 * step) continue;
        ++found;
        if (open > best) { best = open; eye = candidate; }
    }
    if (found == 0)
        throw Error("walk: found no walkable floor with room to walk in " + scene.source +
                    " (eye height " + std::to_string(eye_height) + "; try --eye-height)");

    Camera camera;
    camera.fov_y_degrees = options.fov_y_degrees;
    camera.near_plane = eye_height / 17.0;  // 0.1 m for a 1.7 m eye
    camera.far_plane = std::max(2.0 * diagonal, 10.0 * eye_height);

    double heading = rng.uniform(0.0, 2.0 * glm::pi<double>());
    double turn_rate = 0.0;        // radians per frame, smoothed
    double pending_turn = 0.0;     // a turn away from an obstacle, done gradually
    const double max_turn = 0.12;  // radians per frame
    CameraPath path;
    for (int frame = 0; frame < options.frames; ++frame) {
        camera.eye = eye;
        camera.target = eye + heading_vector(heading);
        validate_camera(camera);
        path.frames.push_back(camera);

        if (std::abs(pending_turn) > 1e-9) {  // turning in place, away from an obstacle
            const double t = std::clamp(pending_turn, -max_turn, max_turn);
            heading += t;
            pending_turn -= t;
            continue;
        }
        turn_rate = 0.9 * turn_rate + 0.02 * rng.uniform(-1.0, 1.0);
        heading += turn_rate;
        const glm::dvec3 dir = heading_vector(heading);

        bool moved = false;
        if (walker.free_ahead(eye, dir, step + 2 * walker.clearance_) >= step + 2 * walker.clearance_) {
            const glm::dvec3 next = eye + step * dir;
            double floor_y;
            // The floor under the next position: not more than a step up, not a ledge down.
            if (walker.floor_below(next, eye_height + walker.max_drop_, floor_y) &&
                floor_y <= next.y - eye_height + walker.max_step_up_) {
                const glm::dvec3 raised(next.x, floor_y + eye_height, next.z);
                if (raised.y <= next.y || walker.free_distance(next, raised - next, 1.0) >= 1.0) {
                    eye = raised;
                    moved = true;
                }
            }
        }
        if (!moved) {
            // Blocked: turn towards the most open of 16 directions (the smallest turn on ties).
            double best_free = -1.0, best_turn = glm::pi<double>();
            for (int k = 1; k < 16; ++k) {
                const double turn = (k <= 8 ? k : k - 16) * glm::pi<double>() / 8.0;
                const double free = walker.free_ahead(eye, heading_vector(heading + turn), look);
                if (free > best_free + 1e-6 || (std::abs(free - best_free) <= 1e-6 && std::abs(turn) < std::abs(best_turn))) {
                    best_free = free;
                    best_turn = turn;
                }
            }
            pending_turn = best_turn;
            turn_rate = 0.0;
        }
    }
    return path;
}

}  // namespace homcull
