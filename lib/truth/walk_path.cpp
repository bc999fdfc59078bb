// Walkthrough paths: a walker at eye height that feels its way through the scene with rays.
#include "common/random.hpp"

#include <homcull/error.hpp>
#include <homcull/truth/walk_path.hpp>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <utility>

namespace homcull {
namespace {

const glm::dvec3 kDown(0.0, -1.0, 0.0);

glm::dvec3 heading_vector(double angle) { return {std::cos(angle), 0.0, std::sin(angle)}; }

class Walker {
public:
    Walker(const RayScene& rays, double eye_height, double step)
        : rays_(rays), eye_height_(eye_height), step_(step), clearance_(0.25 * eye_height),
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

    // One move of `distance` along a horizontal direction: no wall within the move plus the
    // clearance (at eye and knee height), a floor under the new position that is at most a
    // stair step higher and not a ledge lower, and room to rise onto it. The one rule both
    // the walk and the search for a start point use.
    bool try_move(const glm::dvec3& eye, const glm::dvec3& direction, double distance, glm::dvec3& next) const {
        const double needed = distance + 2.0 * clearance_;
        if (free_ahead(eye, direction, needed) < needed) return false;
        const glm::dvec3 moved = eye + distance * direction;
        double floor_y;
        if (!floor_below(moved, eye_height_ + max_drop_, floor_y)) return false;
        if (floor_y > moved.y - eye_height_ + max_step_up_) return false;
        const glm::dvec3 raised(moved.x, floor_y + eye_height_, moved.z);
        if (raised.y > moved.y && free_distance(moved, raised - moved, 1.0) < 1.0) return false;
        next = raised;
        return true;
    }

    // Rejects eye positions that are not in open space (too little room around or overhead,
    // or inside a solid); otherwise counts the 8 horizontal directions that meet geometry
    // within `reach`: streets and halls are enclosed, roofs and open fields are not.
    bool enclosure(const glm::dvec3& eye, double reach, int& enclosed) const {
        if (free_distance(eye, {0, 1, 0}, 0.3 * eye_height_) < 0.3 * eye_height_) return false;
        enclosed = 0;
        int back_faces = 0;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 d = heading_vector(k * glm::quarter_pi<double>());
            const RayHit hit = rays_.intersect(glm::vec3(eye), glm::vec3(d), 0.0f, float(reach));
            if (hit.hit() && double(hit.t) < 2.0 * clearance_) return false;
            // Seeing the inside of surfaces in most directions means we are inside a solid.
            if (hit.hit() && glm::dot(glm::dvec3(hit.normal), d) > 0.0) ++back_faces;
            enclosed += hit.hit();
        }
        return back_faces < 5;
    }

    // How much floor can be walked to from `eye`: a breadth-first flood fill over a grid of
    // cells 4 steps wide, moving by try_move, counting cells up to `cap`. A roof or a
    // balcony is small; a street network or a hall is large.
    int reachable_cells(const glm::dvec3& eye, int cap) const {
        const double cell = 4.0 * step_;
        std::map<std::pair<int, int>, bool> seen;
        std::deque<std::pair<std::pair<int, int>, glm::dvec3>> queue;
        seen[{0, 0}] = true;
        queue.push_back({{0, 0}, eye});
        const int dx[4] = {1, -1, 0, 0}, dz[4] = {0, 0, 1, -1};
        int count = 1;
        while (!queue.empty() && count < cap) {
            const auto [key, position] = queue.front();
            queue.pop_front();
            for (int k = 0; k < 4 && count < cap; ++k) {
                const std::pair<int, int> next_key(key.first + dx[k], key.second + dz[k]);
                if (seen.count(next_key)) continue;
                glm::dvec3 next;
                if (!try_move(position, glm::dvec3(dx[k], 0, dz[k]), cell, next)) continue;
                seen[next_key] = true;
                queue.push_back({next_key, next});
                ++count;
            }
        }
        return count;
    }

    const RayScene& rays_;
    double eye_height_, step_, clearance_, max_step_up_, max_drop_;
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
    const Walker walker(rays, eye_height, step);
    const double look = 20.0 * step;
    detail::SplitMix64 rng(options.seed);

    // Start at the best of up to 32 valid random floor points: enclosed (6 or more of 8
    // directions meet geometry), then the most floor to walk on.
    glm::dvec3 eye(0.0);
    std::pair<bool, int> best(false, -1);
    int found = 0;
    for (int attempt = 0; attempt < 20000 && found < 32; ++attempt) {
        const glm::dvec3 probe(rng.uniform(lo.x, hi.x), rng.uniform(lo.y, hi.y), rng.uniform(lo.z, hi.z));
        double floor_y;
        if (!walker.floor_below(probe, hi.y - lo.y + 1.0, floor_y)) continue;
        const glm::dvec3 candidate(probe.x, floor_y + eye_height, probe.z);
        int enclosed;
        if (!walker.enclosure(candidate, diagonal, enclosed)) continue;
        ++found;
        const std::pair<bool, int> score(enclosed >= 6, walker.reachable_cells(candidate, 600));
        if (score > best) {
            best = score;
            eye = candidate;
        }
    }
    if (found == 0 || best.second < 4)
        throw Error("walk: found no walkable floor with room to walk in " + scene.source + " (eye height " +
                    std::to_string(eye_height) + "; try --eye-height)");

    Camera camera;
    camera.fov_y_degrees = options.fov_y_degrees;
    camera.near_plane = eye_height / 17.0;  // 0.1 m for a 1.7 m eye
    camera.far_plane = std::max(2.0 * diagonal, 10.0 * eye_height);

    // Set off towards the most open of 16 directions.
    double heading = 0.0, heading_free = -1.0;
    const double offset = rng.uniform(0.0, glm::pi<double>() / 8.0);
    for (int k = 0; k < 16; ++k) {
        const double angle = offset + k * glm::pi<double>() / 8.0;
        const double free = walker.free_ahead(eye, heading_vector(angle), 4.0 * look);
        if (free > heading_free) {
            heading_free = free;
            heading = angle;
        }
    }
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
        glm::dvec3 next;
        if (walker.try_move(eye, heading_vector(heading), step, next)) {
            eye = next;
            continue;
        }
        // Blocked by a wall or a ledge: turn towards the most open direction in which a
        // step is possible (the smallest turn on ties); turn around if there is none.
        double best_free = -1.0, best_turn = glm::pi<double>();
        for (int k = 1; k < 16; ++k) {
            const double turn = (k <= 8 ? k : k - 16) * glm::pi<double>() / 8.0;
            const glm::dvec3 dir = heading_vector(heading + turn);
            if (!walker.try_move(eye, dir, step, next)) continue;
            const double free = walker.free_ahead(eye, dir, look);
            if (free > best_free + 1e-6 || (std::abs(free - best_free) <= 1e-6 && std::abs(turn) < std::abs(best_turn))) {
                best_free = free;
                best_turn = turn;
            }
        }
        pending_turn = best_turn;
        turn_rate = 0.0;
    }
    return path;
}

CameraPath random_views(const RayScene& rays, const Scene& scene, int count, std::uint64_t seed) {
    if (count < 1) throw Error("random views: the number of views must be at least 1");
    const Aabb bounds = scene.bounds();
    if (bounds.empty()) throw Error("random views: the scene " + scene.source + " is empty");
    const glm::dvec3 lo(bounds.min), hi(bounds.max);
    const double unit = default_eye_height(scene) / 1.7;  // 1, or 64 for scenes in inches
    detail::SplitMix64 rng(seed);
    // The six axes and the eight diagonals.
    std::vector<glm::dvec3> probes;
    for (int axis = 0; axis < 3; ++axis)
        for (double sign : {-1.0, 1.0}) {
            glm::dvec3 d(0.0);
            d[axis] = sign;
            probes.push_back(d);
        }
    for (int k = 0; k < 8; ++k) probes.push_back(glm::normalize(glm::dvec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1)));
    CameraPath path;
    for (int attempt = 0; int(path.frames.size()) < count; ++attempt) {
        if (attempt >= 200 * count) throw Error("random views: no free space found in " + scene.source);
        const glm::dvec3 eye(rng.uniform(lo.x, hi.x), rng.uniform(lo.y, hi.y), rng.uniform(lo.z, hi.z));
        int hits = 0, back_faces = 0;
        for (const glm::dvec3& d : probes) {
            const RayHit hit = rays.intersect(eye, glm::vec3(d), 0.0f, std::numeric_limits<float>::infinity());
            if (!hit.hit()) continue;
            ++hits;
            back_faces += glm::dot(glm::dvec3(hit.normal), d) > 0.0;
        }
        if (2 * back_faces > hits) continue;  // inside a solid
        // A direction uniform on the sphere: z uniform in [-1, 1], the azimuth uniform.
        const double z = rng.uniform(-1.0, 1.0), azimuth = rng.uniform(0.0, 2.0 * glm::pi<double>());
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const glm::dvec3 direction(r * std::cos(azimuth), z, r * std::sin(azimuth));
        Camera c;
        c.eye = eye;
        c.target = eye + direction;
        c.up = std::abs(direction.y) > 0.99 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
        c.near_plane = 0.1 * unit;
        c.far_plane = 10000.0 * unit;
        path.frames.push_back(c);
    }
    return path;
}

}  // namespace homcull
