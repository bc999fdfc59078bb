#include <homcull/object_hierarchy.hpp>

#include <homcull/error.hpp>

#include "common/float_mode.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace homcull {
namespace {

constexpr int kBins = 16;

double surface_area(const Aabb& b) {
    if (b.empty()) return 0.0;
    const glm::dvec3 e(b.extent());
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

// The bin of a centre's coordinate among kBins from lo, `width` wide. A coordinate that is not
// finite (an object placed so far out that its world box overflowed float) goes to an end bin:
// a float that is NaN or beyond int's range is not converted, which would be undefined.
int bin_of(float coordinate, float lo, float width) {
    const float t = float(kBins) * (coordinate - lo) / width;
    return t >= 0.0f ? std::min(kBins - 1, int(std::min(t, float(kBins)))) : 0;
}

struct Builder {
    const Scene& scene;
    int leaf_size;
    ObjectHierarchy& out;
    std::vector<glm::vec3> centre;  // per object id

    Aabb bounds_of(std::uint32_t begin, std::uint32_t end) const {
        Aabb b;
        for (std::uint32_t i = begin; i < end; ++i) b.extend(scene.objects[out.object_ids[i]].world_bounds);
        return b;
    }

    // The split of object_ids[begin, end) with the lowest SAH cost over kBins bins of the
    // centres on each axis; returns the first index of the right part, or `end` when no split
    // separates anything (all centres equal).
    std::uint32_t sah_split(std::uint32_t begin, std::uint32_t end) {
        Aabb centres;
        for (std::uint32_t i = begin; i < end; ++i) centres.extend(centre[out.object_ids[i]]);
        double best_cost = std::numeric_limits<double>::infinity();
        int best_axis = -1, best_bin = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const float lo = centres.min[axis], width = centres.max[axis] - lo;
            if (!(width > 0.0f)) continue;
            std::array<Aabb, kBins> box;
            std::array<std::uint32_t, kBins> count{};
            for (std::uint32_t i = begin; i < end; ++i) {
                const std::uint32_t id = out.object_ids[i];
                const int bin = bin_of(centre[id][axis], lo, width);
                box[bin].extend(scene.objects[id].world_bounds);
                ++count[bin];
            }
            // Cost of splitting after bin k: area(left) * n_left + area(right) * n_right.
            std::array<double, kBins> right_cost{};
            Aabb right;
            std::uint32_t n_right = 0;
            for (int k = kBins - 1; k > 0; --k) {
                right.extend(box[k]);
                n_right += count[k];
                right_cost[k] = surface_area(right) * n_right;
            }
            Aabb left;
            std::uint32_t n_left = 0;
            for (int k = 0; k < kBins - 1; ++k) {
                left.extend(box[k]);
                n_left += count[k];
                if (n_left == 0 || n_left == end - begin) continue;
                const double cost = surface_area(left) * n_left + right_cost[k + 1];
                if (cost < best_cost) best_cost = cost, best_axis = axis, best_bin = k;
            }
        }
        if (best_axis < 0) return end;
        const float lo = centres.min[best_axis], width = centres.max[best_axis] - lo;
        const auto middle = std::partition(out.object_ids.begin() + begin, out.object_ids.begin() + end, [&](std::uint32_t id) {
            return bin_of(centre[id][best_axis], lo, width) <= best_bin;
        });
        return std::uint32_t(middle - out.object_ids.begin());
    }

    // Iterative (a stack of pending nodes), so that a very unbalanced scene cannot overflow
    // the call stack.
    void build_all() {
        struct Pending {
            std::uint32_t node, begin, end;
        };
        std::vector<Pending> stack{{0, 0, std::uint32_t(out.object_ids.size())}};
        while (!stack.empty()) {
            const Pending p = stack.back();
            stack.pop_back();
            out.nodes[p.node].bounds = bounds_of(p.begin, p.end);
            out.nodes[p.node].begin = p.begin;
            out.nodes[p.node].end = p.end;
            std::uint32_t middle = p.end;
            if (p.end - p.begin > std::uint32_t(leaf_size)) {
                middle = sah_split(p.begin, p.end);
                if (middle == p.end) middle = p.begin + (p.end - p.begin) / 2;  // equal centres: any halves
            }
            if (middle == p.end) continue;  // a leaf
            const auto children = std::uint32_t(out.nodes.size());
            out.nodes[p.node].first_child = children;
            out.nodes.resize(out.nodes.size() + 2);
            stack.push_back({children, p.begin, middle});
            stack.push_back({children + 1, middle, p.end});
        }
    }
};

}  // namespace

ObjectHierarchy ObjectHierarchy::build(const Scene& scene, int leaf_size) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    if (leaf_size < 1) throw Error("object hierarchy: leaf_size must be at least 1");
    ObjectHierarchy h;
    Builder b{scene, leaf_size, h, std::vector<glm::vec3>(scene.objects.size())};
    for (std::uint32_t id = 0; id < scene.objects.size(); ++id) {
        const Aabb& box = scene.objects[id].world_bounds;
        if (box.empty()) continue;
        h.object_ids.push_back(id);
        b.centre[id] = box.center();
    }
    if (h.object_ids.empty()) return h;
    h.nodes.reserve(2 * h.object_ids.size());
    h.nodes.resize(1);
    b.build_all();
    return h;
}

}  // namespace homcull
