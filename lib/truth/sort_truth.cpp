// Ground truth for visibility sorting (homcull/truth/sort_truth.hpp): every hit along each
// pixel-centre ray, in parallel over rows (oneTBB), then the edges between consecutive objects.
#include "truth/embree_scene.hpp"

#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/truth/sort_truth.hpp>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <utility>

namespace homcull {
namespace {

struct Hit {
    float t;
    std::uint32_t object;
    bool operator<(const Hit& o) const { return t < o.t || (t == o.t && object < o.object); }
};

// The context the filter sees: every hit it is shown is recorded and rejected, so that
// traversal goes on to the next one (Embree 3 sets the ray's tfar to the hit's distance
// before calling it).
struct HitCollector {
    RTCIntersectContext context;  // first, so that the filter can cast back
    std::vector<Hit>* hits;
};

void collect_and_reject(const RTCFilterFunctionNArguments* args) {
    auto* collector = reinterpret_cast<HitCollector*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        collector->hits->push_back({RTCRayN_tfar(args->ray, args->N, i), RTCHitN_geomID(args->hit, args->N, i)});
        args->valid[i] = 0;
    }
}

std::uint64_t edge_key(std::uint32_t front, std::uint32_t back) { return std::uint64_t(front) << 32 | back; }

// Iterative Tarjan over the edges among `members` (adjacency from sorted edges): the size of
// each member's strongly connected component within them.
std::vector<std::uint32_t> component_sizes(const std::vector<std::uint32_t>& members,
                                           const std::vector<std::vector<std::uint32_t>>& next) {
    const std::size_t n = members.size();
    std::vector<int> index(n, -1), low(n, 0);
    std::vector<char> on_stack(n, 0);
    std::vector<std::uint32_t> stack, sizes(n, 0);
    int counter = 0;
    for (std::size_t root = 0; root < n; ++root) {
        if (index[root] >= 0) continue;
        std::vector<std::pair<std::uint32_t, std::size_t>> calls{{std::uint32_t(root), 0}};
        while (!calls.empty()) {
            auto& [v, child] = calls.back();
            if (child == 0) {
                index[v] = low[v] = counter++;
                stack.push_back(v);
                on_stack[v] = 1;
            }
            if (child < next[v].size()) {
                const std::uint32_t w = next[v][child++];
                if (index[w] < 0) calls.push_back({w, 0});
                else if (on_stack[w]) low[v] = std::min(low[v], index[w]);
                continue;
            }
            if (low[v] == index[v]) {
                std::vector<std::uint32_t> component;
                for (std::uint32_t w = ~0u; w != v;) {
                    w = stack.back();
                    stack.pop_back();
                    on_stack[w] = 0;
                    component.push_back(w);
                }
                for (std::uint32_t w : component) sizes[w] = std::uint32_t(component.size());
            }
            const std::uint32_t done = v;
            calls.pop_back();
            if (!calls.empty()) low[calls.back().first] = std::min(low[calls.back().first], low[done]);
        }
    }
    return sizes;
}

}  // namespace

SortTruth occlusion_edges(const RayScene& rays, std::size_t objects, const Camera& camera, Resolution display) {
    validate_camera(camera);
    validate_resolution(display);
    if (camera.ortho_height > 0.0) throw Error("sort truth: orthographic cameras are not supported (rays start at the eye)");
    if (rays.object_count() != objects) throw Error("sort truth: the ray scene was built from another scene");
    const PixelCentreRays pixel_rays(rays, camera, display);

    struct Local {
        std::vector<std::uint64_t> edges;  // one per ray that shows it
        std::uint64_t hits = 0;
    };
    tbb::combinable<Local> locals;
    tbb::parallel_for(tbb::blocked_range<int>(0, display.height, 4), [&](const tbb::blocked_range<int>& rows) {
        Local& local = locals.local();
        std::vector<Hit> hits;
        HitCollector collector;
        rtcInitIntersectContext(&collector.context);
        collector.context.filter = collect_and_reject;
        collector.hits = &hits;
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < display.width; ++x) {
                RTCRayHit rh = pixel_rays.at(x, y);
                hits.clear();
                rtcIntersect1(pixel_rays.scene, &collector.context, &rh);
                local.hits += hits.size();
                std::sort(hits.begin(), hits.end());
                // Consecutive distinct objects; the same object again after another is a new
                // edge (a cycle of concave objects), one after itself is not.
                std::vector<std::uint64_t> ray_edges;
                for (std::size_t k = 1; k < hits.size(); ++k)
                    if (hits[k].object != hits[k - 1].object) ray_edges.push_back(edge_key(hits[k - 1].object, hits[k].object));
                std::sort(ray_edges.begin(), ray_edges.end());
                ray_edges.erase(std::unique(ray_edges.begin(), ray_edges.end()), ray_edges.end());
                local.edges.insert(local.edges.end(), ray_edges.begin(), ray_edges.end());
            }
    });

    SortTruth truth;
    truth.rays = std::uint64_t(display.width) * std::uint64_t(display.height);
    std::vector<std::uint64_t> all;
    locals.combine_each([&](const Local& l) {
        all.insert(all.end(), l.edges.begin(), l.edges.end());
        truth.hits += l.hits;
    });
    std::sort(all.begin(), all.end());
    for (std::size_t k = 0; k < all.size();) {
        std::size_t end = k;
        while (end < all.size() && all[end] == all[k]) ++end;
        truth.edges.push_back({std::uint32_t(all[k] >> 32), std::uint32_t(all[k]), std::uint32_t(end - k)});
        k = end;
    }
    return truth;
}

SortCheck check_sort(const SortTruth& truth, const std::vector<std::uint32_t>& layer_of) {
    const auto layer = [&](std::uint32_t object) { return object < layer_of.size() ? layer_of[object] : kUnsorted; };
    SortCheck check;
    for (const OcclusionEdge& e : truth.edges) {
        const std::uint32_t a = layer(e.front), b = layer(e.back);
        if (a == kUnsorted || b == kUnsorted) {
            ++check.unsorted_edges;
        } else if (b < a) {
            ++check.violations;
            if (check.violating.size() < 20) check.violating.push_back(e);
        }
    }
    // Grouped layers: the true edges within each, and their strongly connected components.
    std::vector<std::vector<std::uint32_t>> members;
    for (std::uint32_t object = 0; object < layer_of.size(); ++object) {
        const std::uint32_t l = layer_of[object];
        if (l == kUnsorted) continue;
        if (l >= members.size()) members.resize(std::size_t(l) + 1);
        members[l].push_back(object);
    }
    for (const std::vector<std::uint32_t>& group : members) {
        if (group.size() < 2) continue;
        ++check.grouped_layers;
        std::vector<std::vector<std::uint32_t>> next(group.size());
        const auto local = [&](std::uint32_t object) {
            return std::uint32_t(std::lower_bound(group.begin(), group.end(), object) - group.begin());
        };
        for (std::uint32_t i = 0; i < group.size(); ++i) {
            const auto first = std::lower_bound(truth.edges.begin(), truth.edges.end(), group[i],
                                                [](const OcclusionEdge& e, std::uint32_t front) { return e.front < front; });
            for (auto e = first; e != truth.edges.end() && e->front == group[i]; ++e)
                if (layer(e->back) == layer(group[i]) && e->back != group[i]) next[i].push_back(local(e->back));
        }
        const std::vector<std::uint32_t> sizes = component_sizes(group, next);
        const auto lone = std::uint64_t(std::count(sizes.begin(), sizes.end(), 1u));
        check.needlessly_grouped += lone;
        check.needless_layers += lone == group.size();
    }
    return check;
}

}  // namespace homcull
