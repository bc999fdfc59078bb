#pragma once
// The exact view test of boxes the buffer answers visible. box_rectangle's own test of the view
// (the box's screen rectangle against the screen, and its corners against the clip planes)
// keeps a box that lies beside a corner of the view: outside two side planes at once, though
// within each alone. The separating-axis test against the view volume (view_volume_axes,
// homcull/frustum.hpp) finds it apart. Only a box whose centre lies outside the view can be,
// so most visible boxes end at point_of_box_in_view, and the volume's axes are made once per batch,
// the first time a box needs them (one whose centre and corners all lie outside the view).
#include <homcull/frustum.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <array>

namespace homcull::detail {

// Whether the box's centre or one of its corners lies in the view, by the model-to-clip matrix
// (taken in double): the box then meets the view and the exact test has nothing to find.
// Rounding that puts a point inside that is not only keeps a box visible.
bool point_of_box_in_view(const std::array<float, 16>& model_to_clip, const float box_min[3], const float box_max[3], float near_w, bool orthographic);

// The view volume of a model-to-clip matrix as separating axes (view_volume_axes), apart by at
// least 2^-20 of the terms (as the scene culler's frustum test): a margin far above the
// rounding of the engine's float transforms and of box_rectangle's. The float form takes the
// entries as they are, in double. (The C API passes its double matrices.)
FrustumAxes view_volume_of(const glm::dmat4& clip_from_space, float near_w, bool orthographic);
FrustumAxes view_volume_of(const std::array<float, 16>& model_to_clip, float near_w, bool orthographic);

// One batch's exact view test: `visible` boxes of one matrix, the volume made when first needed.
class ExactViewTest {
public:
    ExactViewTest(const std::array<float, 16>& model_to_clip, float near_w, bool orthographic)
        : m_(model_to_clip), near_w_(near_w), orthographic_(orthographic) {}
    // view_culled when the box, answered visible, lies apart from the view volume; else visible.
    Visibility visible_box(const float box_min[3], const float box_max[3]);

private:
    const std::array<float, 16>& m_;
    float near_w_;
    bool orthographic_;
    bool made_ = false;
    FrustumAxes volume_;
};

}  // namespace homcull::detail
