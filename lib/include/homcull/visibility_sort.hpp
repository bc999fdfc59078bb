#pragma once
// Visibility sorting with occlusion cycles (Snyder and Lengyel, "Visibility Sorting and
// Compositing for Image-Based Rendering", MSR-TR-97-11, 1997; SIGGRAPH 1998 as "Visibility
// sorting and compositing without splitting for image layer decompositions").
//
// Objects are convex hulls, made once from their meshes (convex_hull_points); each frame gives
// every object's transform and the eye point. The sort orders the objects front to back in
// layers: a layer is one object, or the objects of an occlusion cycle (a strongly connected
// component of the occlusion graph, which no order can draw), so that no object occludes one
// in an earlier layer. A -> B in the occlusion graph when some ray from the eye meets A and
// then B; here, conservatively, when B's hull meets the convex hull of the eye and A's hull.
//
// Answers are conservative for the objects' hulls: every true edge is found, and layers may
// group objects whose hulls form a cycle where the meshes do not (concave objects, or hulls
// that touch). The sort is incremental (the paper's IVS): it keeps the last frame's order
// wherever it still holds, and then tests only the pairs that could change it.
//
// No allocation per frame once the sorter has seen its largest frame; one sorter is not
// thread-safe (sort from one thread at a time), but sorters are independent.
#include <homcull/detail/memory.hpp>

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace homcull {

// The points of `points` that are vertices of their convex hull (quickhull, in double), in
// the order they first appear: the smallest set whose hull is the hull of all of them. Sets
// with no volume (fewer than four points, or all on one plane or line) come back with their
// duplicates removed but otherwise whole, which holds their hull too. Throws homcull::Error
// naming the first point that is not finite.
detail::Vector<glm::vec3> convex_hull_points(const glm::vec3* points, std::size_t count);
// The same, with at most `max_points` points (at least 8; 0: no limit): a hull of that many of
// the vertices, spread evenly, grown about its centre until it holds every point (and checked
// after rounding to float). Looser than the exact hull by a few percent, and as many times
// faster to test as it has fewer points. Falls back to the exact hull when that fails.
detail::Vector<glm::vec3> convex_hull_points(const glm::vec3* points, std::size_t count, std::size_t max_points);
// The limit the scene and C interface sorters use: none. (On the toothpicks a limit of 64 or
// 128 costs more in extra cycles and tests than it saves per test; `homcull sort
// --hull-points N` measures it on a scene.)
constexpr std::size_t kSortHullPoints = 0;

// One layer of a sort: objects [first, first + count) of VisibilitySort::order.
struct SortLayer {
    std::uint32_t first = 0, count = 0;
};

// An occlusion found by a sort's tests: `occluder` may hide part of `occluded`.
struct OcclusionPair {
    std::uint32_t occluder = 0, occluded = 0;
};

struct VisibilitySortStats {
    std::uint32_t sorted = 0;             // objects in the layers
    std::uint32_t left_out = 0;           // objects wholly outside the given planes
    std::uint32_t layers = 0;
    std::uint32_t cycles = 0;             // layers of more than one object
    std::uint32_t objects_in_cycles = 0;  // objects in those layers
    std::uint32_t largest_cycle = 0;      // objects in the largest layer
    std::uint64_t candidates = 0;         // pairs the extent tree returned
    std::uint64_t hull_tests = 0;         // GJK runs on hulls (the full test, or two still objects')
    std::uint64_t remembered = 0;         // pairs of still objects answered from an earlier frame's test
    std::uint64_t core_crossings = 0;     // pairs found occluding by their core segments, without GJK
    std::uint64_t gjk_iterations = 0;     // GJK's steps in the full tests (0 when the last frame's
                                          // enclosing tetrahedron still encloses the origin)
    std::uint64_t support_scans = 0;      // hull scans those steps made (two a step)
    std::uint64_t occlusions = 0;         // pairs that test found occluding (the pairs listed)
    bool kept_last_order = false;         // the last frame's order held: the sort changed nothing
    // Stage times, milliseconds (steady clock): the objects' bounds and extents, the extent
    // tree, and the order (tests, cycles and layers).
    double extents_ms = 0, tree_ms = 0, order_ms = 0, total_ms = 0;
};

// A sort's answer; it lives in the sorter until its next sort. (detail::Vector: std::vector
// with the allocator of the sorter's memory, homcull/detail/memory.hpp.)
struct VisibilitySort {
    detail::Vector<std::uint32_t> order;  // the sorted objects, front to back, layer after layer
    detail::Vector<SortLayer> layers;     // front to back
    detail::Vector<OcclusionPair> pairs;  // the occlusions the tests found (not all of the graph:
                                       // pairs the order already settled are not tested)
    VisibilitySortStats stats;
};

struct SortFrame {
    // Object i's model-to-world transform (affine: the bottom row is ignored). Give the
    // transforms and the eye relative to an origin near the objects (floats lose 2^-24 of the
    // distance from the origin).
    const glm::mat4* transforms = nullptr;
    glm::vec3 eye{0.0f};
    // Optional planes (normal, offset), dot(normal, p) + offset >= 0 inside: objects whose
    // bounding sphere lies wholly outside one of them are left out of the layers (for
    // example the view frustum's six planes). At most 16.
    const glm::vec4* planes = nullptr;
    std::size_t plane_count = 0;
    // false: sort from scratch (nearest first) instead of from the last frame's order. The
    // layers are the same either way; the order within what the occlusions leave free may
    // differ.
    bool incremental = true;
};

// A shape's points (model space), whose convex hull holds its mesh (see convex_hull_points;
// any set holding the mesh is correct, a smaller one faster).
struct HullPoints {
    const glm::vec3* points = nullptr;
    std::size_t count = 0;
};

class VisibilitySorter {
public:
    // shapes[s]: shape s's points (copied). object_shapes[i]: object i's shape. Throws
    // homcull::Error on a shape index out of range, an empty shape, or a point that is not
    // finite. Everything the sorter holds comes from the memory hooks current here
    // (homcull/detail/memory.hpp; operator new by default).
    VisibilitySorter(const HullPoints* shapes, std::size_t shape_count, const std::uint32_t* object_shapes, std::size_t object_count);
    VisibilitySorter(const std::vector<std::vector<glm::vec3>>& shapes, const std::vector<std::uint32_t>& object_shapes);
    ~VisibilitySorter();
    VisibilitySorter(VisibilitySorter&&) noexcept;
    VisibilitySorter& operator=(VisibilitySorter&&) noexcept;
    VisibilitySorter(const VisibilitySorter&) = delete;
    VisibilitySorter& operator=(const VisibilitySorter&) = delete;

    std::size_t object_count() const;
    std::size_t shape_count() const;
    std::size_t hull_point_count() const;  // all shapes together

    // Sorts the objects for one frame. Objects with a transform or bound that is not finite
    // are left out (counted in stats.left_out). Throws homcull::Error on a null transform
    // array or more than 16 planes. The answer stays valid until the next call.
    const VisibilitySort& sort(const SortFrame& frame);
    // The last answer.
    const VisibilitySort& last() const;
    // Forgets the last order, what was learned about still objects and where each pair's last
    // test left GJK: the next sort starts from scratch.
    void forget_order();

private:
    struct State;
    detail::HookPtr<State> state_;
};

}  // namespace homcull
