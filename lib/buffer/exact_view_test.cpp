#include "buffer/exact_view_test.hpp"

#include <cmath>

namespace homcull::detail {

namespace {

bool point_in_view(const std::array<float, 16>& m, const double p[3], float near_w, bool orthographic) {
    double clip[4];
    for (std::size_t row = 0; row < 4; ++row)
        clip[row] = double(m[row]) * p[0] + double(m[4 + row]) * p[1] + double(m[8 + row]) * p[2] + double(m[12 + row]);
    const bool beyond_near = orthographic ? clip[2] >= -clip[3] : clip[3] >= double(near_w);
    return beyond_near && std::abs(clip[0]) <= clip[3] && std::abs(clip[1]) <= clip[3];
}

}  // namespace

bool point_of_box_in_view(const std::array<float, 16>& m, const float box_min[3], const float box_max[3], float near_w, bool orthographic) {
    // The centre first: most boxes in view have it there.
    double p[3];
    for (int axis = 0; axis < 3; ++axis) p[axis] = (double(box_min[axis]) + double(box_max[axis])) * 0.5;
    if (point_in_view(m, p, near_w, orthographic)) return true;
    for (int corner = 0; corner < 8; ++corner) {
        p[0] = corner & 1 ? box_max[0] : box_min[0];
        p[1] = corner & 2 ? box_max[1] : box_min[1];
        p[2] = corner & 4 ? box_max[2] : box_min[2];
        if (point_in_view(m, p, near_w, orthographic)) return true;
    }
    return false;
}

FrustumAxes view_volume_of(const glm::dmat4& clip_from_space, float near_w, bool orthographic) {
    return view_volume_axes(clip_from_space, orthographic ? 0.0 : double(near_w), orthographic, 0x1.0p-20);
}

FrustumAxes view_volume_of(const std::array<float, 16>& m, float near_w, bool orthographic) {
    glm::dmat4 clip_from_space;
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row) clip_from_space[column][row] = double(m[std::size_t(4 * column + row)]);
    return view_volume_of(clip_from_space, near_w, orthographic);
}

Visibility ExactViewTest::visible_box(const float box_min[3], const float box_max[3]) {
    if (point_of_box_in_view(m_, box_min, box_max, near_w_, orthographic_)) return Visibility::visible;
    if (!made_) volume_ = view_volume_of(m_, near_w_, orthographic_), made_ = true;
    const Aabb box{{box_min[0], box_min[1], box_min[2]}, {box_max[0], box_max[1], box_max[2]}};
    return separated(volume_, box) ? Visibility::view_culled : Visibility::visible;
}

}  // namespace homcull::detail
