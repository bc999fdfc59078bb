#include <homcull/error.hpp>
#include <homcull/truth/visibility_bake.hpp>
#include <homcull/truth/walk_path.hpp>

#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

namespace homcull {
namespace {

constexpr float kFar = std::numeric_limits<float>::infinity();

// `count` unit directions spread evenly over the sphere: the Fibonacci lattice (points at
// equal-area heights, turned by the golden angle), deterministic.
std::vector<glm::vec3> sphere_directions(std::uint32_t count) {
    std::vector<glm::vec3> d(count);
    const double golden_angle = glm::pi<double>() * (3.0 - std::sqrt(5.0));
    for (std::uint32_t k = 0; k < count; ++k) {
        const double y = 1.0 - (2.0 * k + 1.0) / double(count);
        const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
        const double a = golden_angle * k;
        d[k] = glm::vec3(float(r * std::cos(a)), float(y), float(r * std::sin(a)));
    }
    return d;
}

// The candidates alone, as a scene of their own: its object k is candidates[k].
Scene candidate_scene(const Scene& scene, const std::vector<std::uint32_t>& candidates) {
    Scene only;
    only.source = scene.source + " (occluder candidates)";
    only.meshes = scene.meshes;
    for (std::uint32_t id : candidates) only.objects.push_back(scene.objects[id]);
    only.finalize();
    return only;
}

class PointScorer {
public:
    PointScorer(const RayScene& all, const RayScene& candidates, const std::vector<std::uint32_t>& candidate_ids,
                const std::vector<glm::vec3>& directions, double epsilon)
        : all_(all), candidates_(candidates), ids_(candidate_ids), directions_(directions), epsilon_(float(epsilon)) {}

    // The point's occluders, best first, at most `keep`; false when the point is inside a
    // solid (the back of surfaces first in more than half of the directions that meet any).
    // `pairs` and `seen` are scratch.
    bool score(const glm::vec3& p, std::uint32_t keep, std::vector<std::pair<std::uint32_t, std::uint32_t>>& out,
               std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs, std::vector<std::uint32_t>& seen) const {
        pairs.clear();  // (candidate k, object met behind it)
        seen.clear();   // objects some ray sees
        std::uint32_t hits = 0, back_faces = 0;
        for (const glm::vec3& d : directions_) {
            const RayHit first = all_.intersect(p, d, 0.0f, kFar);
            if (first.hit()) {
                seen.push_back(first.object);
                ++hits;
                back_faces += glm::dot(first.normal, d) > 0.0f;
            }
            const RayHit occluder = candidates_.intersect(p, d, 0.0f, kFar);
            if (!occluder.hit()) continue;
            const std::uint32_t behind = object_behind(p, d, occluder.t, ids_[occluder.object]);
            if (behind != kNoObject) pairs.emplace_back(occluder.object, behind);
        }
        if (2 * back_faces > hits) return false;
        // Score: the distinct objects met behind the occluder that no ray sees from here (an
        // object seen elsewhere, such as a post sunk into the ground, is not hidden).
        std::sort(seen.begin(), seen.end());
        std::sort(pairs.begin(), pairs.end());
        pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
        out.clear();
        for (const auto& [k, behind] : pairs) {
            if (std::binary_search(seen.begin(), seen.end(), behind)) continue;
            if (out.empty() || out.back().first != ids_[k]) out.emplace_back(ids_[k], 0);
            ++out.back().second;
        }
        std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second != b.second ? a.second > b.second : a.first < b.first; });
        if (out.size() > keep) out.resize(keep);
        return true;
    }

private:
    // The first other object along the ray beyond the occluder's hit at t, or kNoObject (the
    // occluder's own further surfaces, such as the far side of a box, do not count).
    std::uint32_t object_behind(const glm::vec3& p, const glm::vec3& d, float t, std::uint32_t occluder) const {
        for (int step = 0; step < 16; ++step) {
            const float from = t + epsilon_ + t * 1e-5f;
            const RayHit behind = all_.intersect(p, d, from, kFar);
            if (!behind.hit() || behind.object != occluder) return behind.object;
            t = behind.t;
        }
        return kNoObject;
    }

    const RayScene& all_;
    const RayScene& candidates_;
    const std::vector<std::uint32_t>& ids_;
    const std::vector<glm::vec3>& directions_;
    float epsilon_;
};

}  // namespace

VisibilityGridHeader bake_header(const Scene& scene, const BakeOptions& o) {
    const Aabb b = scene.bounds();
    if (b.empty()) throw Error("bake: the scene " + scene.source + " is empty");
    if (o.rays == 0) throw Error("bake: at least one ray per point is needed");
    if (o.keep == 0) throw Error("bake: keep at least one occluder per point");
    if (o.shard.count == 0 || o.shard.index >= o.shard.count)
        throw Error("bake: shard " + std::to_string(o.shard.index) + "/" + std::to_string(o.shard.count) +
                    " does not exist (the index counts from 0 and must be below the count)");
    if (!(o.spacing >= 0.0) || !std::isfinite(o.spacing)) throw Error("bake: the spacing must be positive");
    VisibilityGridHeader h;
    h.scene = scene.source;
    h.scene_objects = scene.objects.size();
    h.scene_triangles = scene.instanced_triangle_count();
    h.occluders = o.candidates_name;
    h.layout = o.layout;
    const glm::dvec3 extent(b.extent());
    h.spacing = o.spacing > 0.0 ? o.spacing : std::max({extent.x, extent.z, 1e-6}) / 64.0;
    auto columns = [&](double length) {
        const double n = std::ceil(length / h.spacing);
        if (n > 16384.0) throw Error("bake: the spacing is too small for the scene (more than 16,384 lattice steps per axis)");
        return std::uint32_t(std::max(1.0, n));
    };
    h.columns_x = columns(extent.x);
    h.columns_z = columns(extent.z);
    if (o.layout == GridLayout::volume) columns(extent.y);  // the same limit on the points per column
    h.origin_x = b.min.x;
    h.origin_z = b.min.z;
    h.origin_y = double(b.min.y) + 0.5 * h.spacing;
    h.eye_height = o.eye_height > 0.0 ? o.eye_height : default_eye_height(scene);
    h.rays = o.rays;
    h.keep = o.keep;
    return h;
}

VisibilityGrid bake_visibility_grid(const RayScene& rays, const Scene& scene, const BakeOptions& o,
                                    const std::function<void(std::size_t, std::size_t)>& progress) {
    VisibilityGrid grid;
    grid.header = bake_header(scene, o);
    const VisibilityGridHeader& h = grid.header;
    if (o.candidates.empty()) throw Error("bake: no occluder candidates in " + scene.source);
    for (std::uint32_t id : o.candidates)
        if (id >= scene.objects.size()) throw Error("bake: occluder candidate " + std::to_string(id) + " is not an object");
    const RayScene candidate_rays(candidate_scene(scene, o.candidates), rays.anchor());  // rounded as `rays`: their hits are compared
    const std::vector<glm::vec3> directions = sphere_directions(h.rays);
    const Aabb bounds = scene.bounds();
    const double diagonal = glm::length(glm::dvec3(bounds.extent()));
    const PointScorer scorer(rays, candidate_rays, o.candidates, directions, 1e-6 * diagonal);

    // The shard's columns, each baked on its own (in parallel), then laid out in column order.
    std::vector<std::size_t> columns;
    for (std::size_t c = 0; c < grid.column_count(); ++c)
        if (o.shard.holds(c)) columns.push_back(c);
    std::vector<std::vector<GridPoint>> baked(columns.size());
    std::mutex progress_mutex;
    std::size_t done = 0;  // under progress_mutex
    tbb::parallel_for(std::size_t(0), columns.size(), [&](std::size_t k) {
        const std::size_t c = columns[k];
        const double x = h.origin_x + (double(c % h.columns_x) + 0.5) * h.spacing;
        const double z = h.origin_z + (double(c / h.columns_x) + 0.5) * h.spacing;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
        std::vector<std::uint32_t> seen;
        auto try_point = [&](const glm::dvec3& p) {
            GridPoint point;
            point.position = glm::vec3(p);
            if (scorer.score(point.position, h.keep, point.occluders, pairs, seen)) baked[k].push_back(std::move(point));
        };
        if (h.layout == GridLayout::volume) {
            for (double y = h.origin_y; y <= double(bounds.max.y); y += h.spacing) try_point({x, y, z});
        } else {
            // Floors: surfaces within 45 degrees of level met going down the column, the eye
            // above each with headroom (walk_path's rules), top storey first.
            const glm::vec3 top(float(x), bounds.max.y + float(0.01 * diagonal), float(z));
            const glm::vec3 down(0.0f, -1.0f, 0.0f);
            float t = 0.0f;
            int floors = 0;
            for (int hits = 0; hits < 8 * o.max_floors && floors < o.max_floors; ++hits) {
                const RayHit hit = rays.intersect(top, down, t, kFar);
                if (!hit.hit()) break;
                t = hit.t + float(1e-4 * diagonal);
                if (std::abs(glm::normalize(hit.normal).y) < 0.7071f) continue;
                const glm::dvec3 eye(x, double(top.y) - double(hit.t) + h.eye_height, z);
                const glm::vec3 up(0.0f, 1.0f, 0.0f);
                const float headroom = float(0.3 * h.eye_height);
                if (rays.intersect(glm::vec3(eye), up, 0.0f, headroom).hit()) continue;
                ++floors;
                try_point(eye);
            }
        }
        if (progress) {
            std::lock_guard<std::mutex> lock(progress_mutex);
            progress(++done, columns.size());
        }
    });

    grid.column_first.assign(grid.column_count() + 1, 0);
    std::vector<std::uint32_t> count(grid.column_count(), 0);
    for (std::size_t k = 0; k < columns.size(); ++k) count[columns[k]] = std::uint32_t(baked[k].size());
    for (std::size_t c = 0; c < grid.column_count(); ++c) grid.column_first[c + 1] = grid.column_first[c] + count[c];
    for (auto& points : baked)
        for (GridPoint& p : points) grid.points.push_back(std::move(p));
    grid.index(scene.objects.size(), scene.source);
    return grid;
}

}  // namespace homcull
