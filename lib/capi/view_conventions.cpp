#include "capi/view_conventions.hpp"

#include "capi/c_objects.hpp"

#include <cmath>

namespace homcull::capi {

glm::dmat4 read_matrix(const double* m, homcull_matrix_layout layout) {
    glm::dmat4 out;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[c][r] = layout == HOMCULL_ROW_MAJOR ? m[4 * r + c] : m[4 * c + r];
    return out;
}

glm::dmat4 read_matrix(const float* m, homcull_matrix_layout layout) {
    double d[16];
    for (int i = 0; i < 16; ++i) d[i] = double(m[i]);
    return read_matrix(d, layout);
}

bool finite_matrix(const float* m) {
    if (!m) return true;
    for (int i = 0; i < 16; ++i)
        if (!std::isfinite(m[i])) return false;
    return true;
}

std::array<float, 16> float_clip_from_model(const glm::dmat4& clip_from_world, const glm::dmat4& model) {
    const glm::dmat4 m = clip_from_world * model;
    std::array<float, 16> out;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[std::size_t(4 * c + r)] = float(m[c][r]);
    return out;
}

homcull_result read_view(const homcull_context* context, const homcull_view& view, ViewConventions& out) {
    const char* const fn = "homcull_buffer_begin_frame";
    for (double x : view.world_to_clip)
        if (!std::isfinite(x)) return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: world_to_clip has a number that is not finite", fn);
    if (view.layout != HOMCULL_COLUMN_MAJOR && view.layout != HOMCULL_ROW_MAJOR)
        return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: layout %d is not a homcull_matrix_layout", fn, int(view.layout));
    if (view.depth_range != HOMCULL_DEPTH_MINUS_ONE_TO_ONE && view.depth_range != HOMCULL_DEPTH_ZERO_TO_ONE)
        return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: depth_range %d is not a homcull_depth_range", fn, int(view.depth_range));
    if (view.front_face != HOMCULL_FRONT_CCW && view.front_face != HOMCULL_FRONT_CW)
        return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: front_face %d is not a homcull_winding", fn, int(view.front_face));
    if (view.cull != HOMCULL_CULL_BACK && view.cull != HOMCULL_CULL_NONE && view.cull != HOMCULL_CULL_FRONT)
        return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: cull %d is not a homcull_cull", fn, int(view.cull));
    if (view.flags & ~uint32_t(HOMCULL_VIEW_REVERSED_Z | HOMCULL_VIEW_INFINITE_FAR | HOMCULL_VIEW_Y_DOWN))
        return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: unknown flags 0x%x", fn, unsigned(view.flags));

    glm::dmat4 m = read_matrix(view.world_to_clip, view.layout);
    // A projection whose w row ignores the position (w the same everywhere) is orthographic.
    // The buffer then takes w = 1 and OpenGL's z (BufferConfig::orthographic): the matrix is
    // divided by w, and its z row mapped from the view's depth range.
    out.orthographic = m[0][3] == 0.0 && m[1][3] == 0.0 && m[2][3] == 0.0;
    if (out.orthographic) {
        const double w = m[3][3];
        if (!(w > 0.0))
            return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: an orthographic projection needs a positive clip w, got %g", fn, w);
        if (view.flags & HOMCULL_VIEW_INFINITE_FAR)
            return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: an orthographic projection has a far plane (no HOMCULL_VIEW_INFINITE_FAR)", fn);
        // z_gl = scale * z + offset: near -> -1, far -> 1.
        const bool zero_to_one = view.depth_range == HOMCULL_DEPTH_ZERO_TO_ONE, reversed = (view.flags & HOMCULL_VIEW_REVERSED_Z) != 0;
        double scale = zero_to_one ? 2.0 : 1.0, offset = zero_to_one ? -1.0 : 0.0;
        if (reversed) scale = -scale, offset = -offset;
        out.ortho_z_scale = scale, out.ortho_z_offset = offset;
        for (int c = 0; c < 4; ++c) {
            for (int r = 0; r < 4; ++r) m[c][r] /= w;
            m[c][2] = scale * m[c][2] + offset * m[c][3];
        }
    }
    if (view.flags & HOMCULL_VIEW_Y_DOWN)
        for (int c = 0; c < 4; ++c) m[c][1] = -m[c][1];  // the library's clip y points up
    out.clip_from_world = m;

    // Culling, by the winding the faces show on the screen (now that y is up in clip space as on
    // the screen): Backface::cw culls clockwise ones.
    const bool front_ccw = view.front_face == HOMCULL_FRONT_CCW;
    out.backface = view.cull == HOMCULL_CULL_NONE ? Backface::none
                   : (view.cull == HOMCULL_CULL_BACK) == front_ccw ? Backface::cw
                                                                     : Backface::ccw;

    // The far plane: z <= w without reversed depth; z >= 0 (D3D range) or z >= -w (OpenGL range)
    // with it. far_row is taken against (x, y, z, w) of the engine's clip space, whose z the
    // y flip leaves alone.
    out.far_plane = !(view.flags & HOMCULL_VIEW_INFINITE_FAR);
    if (out.orthographic) out.far_row = {0.0, 0.0, -1.0, 1.0};  // z <= w in the OpenGL z it was mapped to
    else if (!(view.flags & HOMCULL_VIEW_REVERSED_Z)) out.far_row = {0.0, 0.0, -1.0, 1.0};
    else if (view.depth_range == HOMCULL_DEPTH_ZERO_TO_ONE) out.far_row = {0.0, 0.0, 1.0, 0.0};
    else out.far_row = {0.0, 0.0, 1.0, 1.0};
    return HOMCULL_OK;
}

bool box_beyond_far(const glm::dvec4& row, const float box_min[3], const float box_max[3]) {
    for (int corner = 0; corner < 8; ++corner) {
        const double p[3] = {double((corner & 1) ? box_max[0] : box_min[0]), double((corner & 2) ? box_max[1] : box_min[1]),
                             double((corner & 4) ? box_max[2] : box_min[2])};
        const double d = row.x * p[0] + row.y * p[1] + row.z * p[2] + row.w;
        const double terms = std::abs(row.x * p[0]) + std::abs(row.y * p[1]) + std::abs(row.z * p[2]) + std::abs(row.w);
        if (!(d < -0x1.0p-20 * terms)) return false;  // on this side, too close to tell, or not a number
    }
    return true;
}

}  // namespace homcull::capi
