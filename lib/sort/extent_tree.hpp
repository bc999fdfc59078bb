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

#include "sort/extent_scan.hpp"

#include <cstdint>

namespace homcull::sort_detail {

class ExtentTree {
public:
    // The leaves' scan of an instruction set (extent_scan.hpp); the reference until set.
    void use(ExtentScan scan) { scan_ = scan; }
    // A tree over extents[ids[k]] (ids: the objects to hold; extents indexed by object).
    void build(const detail::Vector<Extent>& extents, const detail::Vector<std::uint32_t>& ids);
    // Appends to `out` every object held whose direction box overlaps `box` and whose nearest
    // distance is below `farthest`.
    void query(const Extent& box, float farthest, detail::Vector<std::uint32_t>& out) const;

    // Objects a leaf holds at most: the scan tests them a vector at a time.
    static constexpr std::uint32_t kLeafSize = 128;

private:
    struct Node {
        Extent bounds;           // the union of its objects' boxes, nearest: their least
        std::uint32_t first = 0; // leaf: objects_[first, first + count); inner: first = right child
        std::uint32_t count = 0; // 0 for an inner node (its left child follows it)
    };
    // Median splits halve the objects at each level: 2^32 objects need fewer levels than this.
    static constexpr int kMaxDepth = 40;
    ExtentScan scan_ = &extent_scan_reference;
    detail::Vector<Node> nodes_;
    // The held objects in the leaves' order, and their extents as columns in that order (both
    // padded for the scan, extent_scan.hpp).
    detail::Vector<std::uint32_t> objects_;
    detail::Vector<float> lo_[3], hi_[3], nearest_;
    struct Range {
        std::uint32_t node, first, count;
    };
    detail::Vector<Range> work_;  // build scratch
};

}  // namespace homcull::sort_detail
