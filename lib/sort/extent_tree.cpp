#include "extent_tree.hpp"

#include <algorithm>

namespace homcull::sort_detail {
namespace {

constexpr std::uint32_t kLeafSize = 4;

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
    extents_ = &extents;
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
}

void ExtentTree::query(const Extent& box, float farthest, detail::Vector<std::uint32_t>& out) const {
    if (nodes_.empty()) return;
    stack_.clear();
    stack_.push_back(0);
    while (!stack_.empty()) {
        const Node& node = nodes_[stack_.back()];
        stack_.pop_back();
        if (!(node.bounds.nearest < farthest) || !boxes_overlap(node.bounds, box)) continue;
        if (node.count == 0) {
            stack_.push_back(node.first - 1);  // left child
            stack_.push_back(node.first);      // right child
            continue;
        }
        for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
            const std::uint32_t id = objects_[k];
            const Extent& e = (*extents_)[id];
            if (e.nearest < farthest && boxes_overlap(e, box)) out.push_back(id);
        }
    }
}

}  // namespace homcull::sort_detail
