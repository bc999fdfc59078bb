#include "buffer/exact_view_test.hpp"

#include <cmath>

namespace homcull::detail {

bool centre_in_view(const std::array<float, 16>& m, const float box_min[3], const float box_max[3], float near_w, bool orthographic) {
    double centre[3];
    for (int axis = 0; axis < 3; ++axis) centre[axis] = (double(box_min[axis]) + double(box_max[axis])) * 0.5;
    double clip[4];
    for (std::size_t row = 0; row < 4; ++row)
        clip[row] = double(m[row]) * centre[0] + double(m[4 + row]) * centre[1] + double(m[8 + row]) * centre[2] + double(m[12 + row]);
    const bool beyond_near = orthographic ? clip[2] >= -clip[3] : clip[3] >= double(near_w);
    return beyond_near && std::abs(clip[0]) <= clip[3] && std::abs(clip[1]) <= clip[3];
}

FrustumAxes view_volume_of(const std::array<float, 16>& m, float near_w, bool orthographic) {
    glm::dmat4 clip_from_space;
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row) clip_from_space[column][row] = double(m[std::size_t(4 * column + row)]);
    return view_volume_axes(clip_from_space, orthographic ? 0.0 : double(near_w), orthographic, 0x1.0p-20);
}

bool corner_in_view(const std::array<float, 16>& m, const float box_min[3], const float box_max[3], float near_w, bool orthographic) {
    for (int corner = 0; corner < 8; ++corner) {
        const double p[3] = {double(corner & 1 ? box_max[0] : box_min[0]), double(corner & 2 ? box_max[1] : box_min[1]),
                             double(corner & 4 ? box_max[2] : box_min[2])};
        double clip[4];
        for (std::size_t row = 0; row < 4; ++row)
            clip[row] = double(m[row]) * p[0] + double(m[4 + row]) * p[1] + double(m[8 + row]) * p[2] + double(m[12 + row]);
        const bool beyond_near = orthographic ? clip[2] >= -clip[3] : clip[3] >= double(near_w);
        if (beyond_near && std::abs(clip[0]) <= clip[3] && std::abs(clip[1]) <= clip[3]) return true;
    }
    return false;
}

Visibility ExactViewTest::visible_box(const float box_min[3], const float box_max[3]) {
    if (centre_in_view(m_, box_min, box_max, near_w_, orthographic_)) return Visibility::visible;
    // A corner in view settles it as well; only boxes with neither (beside a corner of the view,
    // or around all of it) need the volume.
    if (corner_in_view(m_, box_min, box_max, near_w_, orthographic_)) return Visibility::visible;
    if (!made_) volume_ = view_volume_of(m_, near_w_, orthographic_), made_ = true;
    const Aabb box{{box_min[0], box_min[1], box_min[2]}, {box_max[0], box_max[1], box_max[2]}};
    return separated(volume_, box) ? Visibility::view_culled : Visibility::visible;
}

}  // namespace homcull::detail
