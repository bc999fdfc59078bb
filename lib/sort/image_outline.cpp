#include "image_outline.hpp"

#include <algorithm>

namespace homcull::sort_detail {

bool outlines_apart(const ImageOutline& a, const ImageOutline& b) {
    const float gap = a.pad + b.pad;
    for (const glm::vec2& normal : {a.across, b.across}) {
        float a_max = -3.4e38f, a_min = 3.4e38f, b_max = -3.4e38f, b_min = 3.4e38f;
        for (int i = 0; i < 8; ++i) {
            const float s = glm::dot(normal, a.corners[i]), t = glm::dot(normal, b.corners[i]);
            a_max = std::max(a_max, s), a_min = std::min(a_min, s);
            b_max = std::max(b_max, t), b_min = std::min(b_min, t);
        }
        // The pads along a unit normal, and the dot products' own roundings.
        const float room = gap * glm::length(normal) * (1.0f + 1e-5f);
        if (b_min - a_max > room || a_min - b_max > room) return true;
    }
    return false;
}

}  // namespace homcull::sort_detail
