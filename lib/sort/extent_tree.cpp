#include "extent_tree.hpp"

#include <algorithm>

namespace homcull::sort_detail {
namespace {

Extent empty_extent() {
    Extent e;
    for (int k = 0; k < 3; ++k) e.lo[k] = 2.0f, e.hi[k] = -2.0f;
    e.nearest = 3.4e38f;
    return e;
}

void grow(Extent& into, const Extent& e) {
    for (int k = 0; k < 3; ++k) into.lo[k] = std::min(into.lo[k], e.lo[k]), into.hi[k] = std::max(into.hi[k], e.hi[k]);
    into.nearest = std::min(into.nearest, e.nearest);
}

}  // namespace

void ExtentTree::build(const detail::Vector<Extent>& extents, const detail::Vector<std::uint32_t>& ids) {
    objects_.assign(ids.begin(), ids.end());
    nodes_.clear();
    work_.clear();
    if (objects_.empty()) return;
    nodes_.emplace_back();
    work_.push_back({0, 0, std::uint32_t(objects_.size())});
    while (!work_.empty()) {
        const Range r = work_.back();
        work_.pop_back();
        Extent bounds = empty_extent();
        for (std::uint32_t k = r.first; k < r.first + r.count; ++k) grow(bounds, extents[objects_[k]]);
        nodes_[r.node].bounds = bounds;
        if (r.count <= kLeafSize) {
            nodes_[r.node].first = r.first;
            nodes_[r.node].count = r.count;
            continue;
        }
        // The axis along which the boxes' centres spread most, split at their median.
        float lo[3] = {2, 2, 2}, hi[3] = {-2, -2, -2};
        for (std::uint32_t k = r.first; k < r.first + r.count; ++k) {
            const Extent& e = extents[objects_[k]];
            for (int a = 0; a < 3; ++a) {
                const float c = e.lo[a] + e.hi[a];
                lo[a] = std::min(lo[a], c), hi[a] = std::max(hi[a], c);
            }
        }
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
        auto begin = objects_.begin() + r.first;
        const std::uint32_t half = r.count / 2;
        std::nth_element(begin, begin + half, begin + r.count, [&](std::uint32_t a, std::uint32_t b) {
            const float ca = extents[a].lo[axis] + extents[a].hi[axis], cb = extents[b].lo[axis] + extents[b].hi[axis];
            return ca < cb || (ca == cb && a < b);
        });
        const std::uint32_t left = std::uint32_t(nodes_.size());
        nodes_.emplace_back();
        const std::uint32_t right = std::uint32_t(nodes_.size());
        nodes_.emplace_back();
        nodes_[r.node].first = right;
        nodes_[r.node].count = 0;
        // The children are made side by side: the left one is right - 1.
        work_.push_back({left, r.first, half});
        work_.push_back({right, r.first + half, r.count - half});
    }
    // The columns, padded with extents that match nothing (a kernel masks them off anyway).
    const std::size_t held = objects_.size(), padded = held + kExtentColumnPadding;
    for (int a = 0; a < 3; ++a) lo_[a].resize(padded), hi_[a].resize(padded);
    nearest_.resize(padded);
    for (std::size_t k = 0; k < held; ++k) {
        const Extent& e = extents[objects_[k]];
        for (int a = 0; a < 3; ++a) lo_[a][k] = e.lo[a], hi_[a][k] = e.hi[a];
        nearest_[k] = e.nearest;
    }
    for (std::size_t k = held; k < padded; ++k) {
        for (int a = 0; a < 3; ++a) lo_[a][k] = 2.0f, hi_[a][k] = -2.0f;
        nearest_[k] = 3.4e38f;
    }
    objects_.resize(padded, 0u);
}

void ExtentTree::query(const Extent& box, float farthest, detail::Vector<std::uint32_t>& out) const {
    if (nodes_.empty()) return;
    const auto overlaps = [&](const Extent& e) { return e.nearest < farthest && boxes_overlap(e, box); };
    if (!overlaps(nodes_[0].bounds)) return;
    const ExtentColumns columns{{lo_[0].data(), lo_[1].data(), lo_[2].data()},
                                {hi_[0].data(), hi_[1].data(), hi_[2].data()},
                                nearest_.data(),
                                objects_.data()};
    std::uint32_t hits[kLeafSize + kExtentColumnPadding];
    // Depth first, right child first, each child tested before it is pushed; the stack holds
    // at most one node a level and the one being opened.
    std::uint32_t stack[kMaxDepth + 2];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        if (node.count == 0) {
            const std::uint32_t right = node.first, left = right - 1;
            if (overlaps(nodes_[left].bounds)) stack[top++] = left;
            if (overlaps(nodes_[right].bounds)) stack[top++] = right;  // opened first
            continue;
        }
        const std::uint32_t found = scan_(columns, node.first, node.count, box, farthest, hits);
        out.insert(out.end(), hits, hits + found);
    }
}

}  // namespace homcull::sort_detail
