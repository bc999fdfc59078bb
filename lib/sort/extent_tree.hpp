#pragma once
// The pruning of pairs: a kd-tree over the objects' angular and spatial extents about the eye
// (Snyder and Lengyel, section 4: pairs whose extents are apart cannot occlude each other).
//
// An object's angular extent is the range, along each of the three fixed world axes, of the
// unit directions from the eye to its bounding sphere: a box in direction space holding the
// sphere's cone. Two objects can overlap on screen only if those boxes overlap. Its spatial
// extent is its range of distances from the eye: A can hide part of B only if A's nearest
// point is nearer than B's farthest. The tree is rebuilt every frame, without allocation once
// it has held its largest frame: median splits on the widest axis of the boxes' centres.
#include <homcull/detail/memory.hpp>

#include <cstdint>

namespace homcull::sort_detail {

struct Extent {
    float lo[3], hi[3];  // the direction box: components of the unit directions to the object
    float nearest = 0;   // distance from the eye to the bounding sphere (0 when it holds the eye)
};

// Whether two extents' boxes overlap (the nearest distances aside).
inline bool boxes_overlap(const Extent& a, const Extent& b) {
    for (int k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
    return true;
}

class ExtentTree {
public:
    // A tree over extents[ids[k]] (ids: the objects to hold; extents indexed by object).
    void build(const detail::Vector<Extent>& extents, const detail::Vector<std::uint32_t>& ids);
    // Appends to `out` every object held whose direction box overlaps `box` and whose nearest
    // distance is below `farthest`.
    void query(const Extent& box, float farthest, detail::Vector<std::uint32_t>& out) const;

private:
    struct Node {
        Extent bounds;           // the union of its objects' boxes, nearest: their least
        std::uint32_t first = 0; // leaf: objects_[first, first + count); inner: first = right child
        std::uint32_t count = 0; // 0 for an inner node (its left child follows it)
    };
    // Median splits halve the objects at each level: 2^32 objects need fewer levels than this.
    static constexpr int kMaxDepth = 40;
    detail::Vector<Node> nodes_;
    detail::Vector<std::uint32_t> objects_;
    detail::Vector<Extent> leaf_extents_;  // objects_[k]'s extent at k: the leaves read them in order
    detail::Vector<float> keys_;  // build scratch: the split axis' centres
    struct Range {
        std::uint32_t node, first, count;
    };
    detail::Vector<Range> work_;  // build scratch
};

}  // namespace homcull::sort_detail
