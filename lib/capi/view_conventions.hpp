#pragma once
// An engine's camera conventions (homcull_view) turned into the library's: a column-major
// clip-from-world matrix with clip y up the screen and clip w the view depth, the faces to cull
// as the library names them (Backface, by their winding in that clip space), and the far plane
// as a half-space of clip space.
#include <homcull/homcull.h>

#include <homcull/occlusion_buffer.hpp>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <array>

namespace homcull::capi {

struct ViewConventions {
    glm::dmat4 clip_from_world{1.0};
    Backface backface = Backface::cw;
    bool far_plane = false;
    // In front of the far plane, or on it: dot(far_row, clip_from_world * p) >= 0.
    glm::dvec4 far_row{0.0};
    // Orthographic: clip_from_world has w = 1 and OpenGL's z (-1 at the near plane, 1 at the
    // far one), as BufferConfig::orthographic takes it; the engine's clip z is then
    // (z - ortho_z_offset) / ortho_z_scale of it.
    bool orthographic = false;
    double ortho_z_scale = 1.0, ortho_z_offset = 0.0;
};

// Reads a view, or returns an error result naming what is wrong (through capi::report): a
// non-finite matrix, an unknown enum value, an orthographic projection whose w is not positive
// or that claims an infinite far plane.
homcull_result read_view(const homcull_context* context, const homcull_view& view, ViewConventions& out);

// 16 numbers in a homcull_matrix_layout as a glm matrix (glm is column-major).
glm::dmat4 read_matrix(const double* m, homcull_matrix_layout layout);
glm::dmat4 read_matrix(const float* m, homcull_matrix_layout layout);

// Whether every number of a model matrix is finite (null: the identity, which is).
bool finite_matrix(const float* m);

// The library's float model-to-clip matrix: clip_from_world * model, composed in double and
// rounded once.
std::array<float, 16> float_clip_from_model(const glm::dmat4& clip_from_world, const glm::dmat4& model);

// Whether a box (in the model space the row is expressed in: far_row * clip_from_model) lies
// wholly beyond the far plane, by a margin that covers the engine's float rounding: every corner
// further than 2^-20 of the plane equation's terms.
bool box_beyond_far(const glm::dvec4& far_row_in_model, const float box_min[3], const float box_max[3]);

}  // namespace homcull::capi
