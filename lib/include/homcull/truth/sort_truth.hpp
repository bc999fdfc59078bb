#pragma once
// Ground truth for visibility sorting (Snyder and Lengyel, "Visibility Sorting and Compositing
// for Image-Based Rendering", 1997): the occlusion graph has an edge A -> B when some ray from
// the eye hits A and then B. Rays through the display's pixel centres collect every hit along
// them (an Embree filter that records and rejects each one, so that traversal goes on), sorted
// by distance; consecutive distinct objects along a ray give the true edges (A -> B -> C also
// means A occludes C, which the order then implies). A sort is correct when every true edge
// A -> B has A in an earlier layer than B, or both in one layer.
#include <homcull/camera.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

struct OcclusionEdge {
    std::uint32_t front = 0, back = 0;  // a ray hits `front`, then `back` next
    std::uint32_t rays = 0;             // how many rays show it
};

struct SortTruth {
    std::vector<OcclusionEdge> edges;  // each (front, back) once, sorted by front then back
    std::uint64_t rays = 0;            // rays cast
    std::uint64_t hits = 0;            // hits collected, all rays together
};

// Every hit within the camera's [near, far] view depths along the ray through each pixel
// centre of `display` (perspective cameras; ties at one distance keep Embree's order of
// report, sorted by object id). Thread-safe; runs on oneTBB. Throws homcull::Error on an
// invalid camera or resolution, or a ray scene of another size than `objects`.
SortTruth occlusion_edges(const RayScene& rays, std::size_t objects, const Camera& camera, Resolution display);

// A sort's place for each object: its layer's index, front to back (kUnsorted: left out).
constexpr std::uint32_t kUnsorted = ~std::uint32_t(0);

struct SortCheck {
    std::uint64_t violations = 0;           // true edges whose back object's layer comes first
    std::vector<OcclusionEdge> violating;   // the first 20 of them
    std::uint64_t unsorted_edges = 0;       // true edges with an object the sort left out
    std::uint64_t grouped_layers = 0;       // layers of more than one object
    std::uint64_t needless_layers = 0;      // of those, layers with no true cycle among their objects
    std::uint64_t needlessly_grouped = 0;   // objects of grouped layers in no true cycle within their layer
};

// Checks a sort against the true edges. layer_of[i] is object i's layer (kUnsorted, or beyond
// the vector's end: left out). Grouping objects with no true cycle between them is allowed,
// but a cost: it is counted (Tarjan's strongly connected components of the true edges within
// each grouped layer).
SortCheck check_sort(const SortTruth& truth, const std::vector<std::uint32_t>& layer_of);

}  // namespace homcull
