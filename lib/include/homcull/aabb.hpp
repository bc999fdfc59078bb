#pragma once
// Axis-aligned bounding boxes in float, the precision of the geometry they bound.
#include <glm/glm.hpp>

#include <limits>

namespace homcull {

struct Aabb {
    // An empty box: min > max, so that extend() of the first point gives that point.
    glm::vec3 min{std::numeric_limits<float>::infinity()};
    glm::vec3 max{-std::numeric_limits<float>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void extend(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Aabb& b) {
        if (b.empty()) return;
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
    glm::vec3 center() const { return (min + max) * 0.5f; }
    glm::vec3 extent() const { return max - min; }
};

}  // namespace homcull
