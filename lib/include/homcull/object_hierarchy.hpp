#pragma once
// A bounding volume hierarchy over a scene's objects, for hierarchical culling: a node whose
// box is outside the view frustum or occluded answers for every object under it, which are
// then never tested (Greene's octree of the hierarchical Z-buffer; Yoon, Salomon and
// Manocha's cluster hierarchy, "a parent found occluded skips its children"). A node's box
// contains its objects' boxes, so a conservative box test that hides the node would hide
// each of them.
//
// Built top-down with the surface area heuristic over binned object centres (MacDonald and
// Booth, "Heuristics for ray tracing using space subdivision", 1990), which keeps nodes
// compact: a compact box is hidden more often than a long one holding the same objects.
#include <homcull/scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

struct ObjectHierarchy {
    struct Node {
        Aabb bounds;
        // Its objects: object_ids[begin, end) (the objects of a subtree are contiguous).
        std::uint32_t begin = 0, end = 0;
        // 0: a leaf. Else its children are nodes[first_child] and nodes[first_child + 1].
        std::uint32_t first_child = 0;
        bool leaf() const { return first_child == 0; }
    };
    std::vector<Node> nodes;               // nodes[0] is the root; empty when no object has geometry
    std::vector<std::uint32_t> object_ids;  // every object with a non-empty box, once

    // At most leaf_size objects per leaf (>= 1). Objects with empty world bounds (no
    // geometry) are left out. Allocates: meant for load time.
    static ObjectHierarchy build(const Scene& scene, int leaf_size = 4);
};

}  // namespace homcull
