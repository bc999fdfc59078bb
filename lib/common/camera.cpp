#include <homcull/camera.hpp>
#include <homcull/error.hpp>

#include <cmath>
#include <cstdio>
#include <string>

namespace homcull {
namespace {

bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

void validate_camera(const Camera& c) {
    if (!finite(c.eye) || !finite(c.target) || !finite(c.up))
        throw Error("camera: eye, target and up must be finite numbers");
    const glm::dvec3 view = c.target - c.eye;
    if (glm::length(view) == 0.0)
        throw Error("camera: eye and target are the same point (" + format_vec3(c.eye) + ")");
    if (glm::length(c.up) == 0.0) throw Error("camera: up is the zero vector");
    // Up must not be parallel to the view direction, or the right vector is undefined.
    const double sine = glm::length(glm::cross(glm::normalize(view), glm::normalize(c.up)));
    if (!(sine > 1e-9))
        throw Error("camera: up (" + format_vec3(c.up) + ") is parallel to the view direction");
    if (!(c.fov_y_degrees > 0.0 && c.fov_y_degrees < 180.0))
        throw Error("camera: fov_y must be in (0, 180) degrees, got " +
                    std::to_string(c.fov_y_degrees));
    if (!(c.near_plane > 0.0) || !std::isfinite(c.near_plane))
        throw Error("camera: near must be a positive number, got " + std::to_string(c.near_plane));
    if (!(c.ortho_height >= 0.0) || !std::isfinite(c.ortho_height))
        throw Error("camera: ortho_height must be 0 (perspective) or a positive height, got " + std::to_string(c.ortho_height));
    if (!(c.far_plane > c.near_plane) || !std::isfinite(c.far_plane))
        throw Error("camera: far must be finite and greater than near (" +
                    std::to_string(c.near_plane) + "), got " + std::to_string(c.far_plane));
}

void validate_resolution(Resolution r) {
    if (r.width < 1 || r.height < 1 || r.width > 65536 || r.height > 65536)
        throw Error("resolution must be between 1x1 and 65536x65536, got " +
                    std::to_string(r.width) + "x" + std::to_string(r.height));
}

CameraBasis camera_basis(const Camera& c) {
    CameraBasis b;
    b.forward = glm::normalize(c.target - c.eye);
    b.right = glm::normalize(glm::cross(b.forward, c.up));
    b.up = glm::cross(b.right, b.forward);
    return b;
}

glm::dmat4 view_matrix(const Camera& c) {
    const CameraBasis b = camera_basis(c);
    glm::dmat4 m(1.0);  // rows: right, up, -forward (glm is column-major: m[column][row])
    for (int k = 0; k < 3; ++k) {
        m[k][0] = b.right[k];
        m[k][1] = b.up[k];
        m[k][2] = -b.forward[k];
    }
    m[3][0] = -glm::dot(b.right, c.eye);
    m[3][1] = -glm::dot(b.up, c.eye);
    m[3][2] = glm::dot(b.forward, c.eye);
    return m;
}

glm::dmat4 projection_matrix(const Camera& c, double aspect) {
    if (c.ortho_height > 0.0) {
        const double n = c.near_plane, f = c.far_plane;
        glm::dmat4 m(1.0);
        m[0][0] = 2.0 / (c.ortho_height * aspect);
        m[1][1] = 2.0 / c.ortho_height;
        m[2][2] = -2.0 / (f - n);
        m[3][2] = -(f + n) / (f - n);
        return m;
    }
    const double focal = 1.0 / std::tan(glm::radians(c.fov_y_degrees) * 0.5);
    const double n = c.near_plane, f = c.far_plane;
    glm::dmat4 m(0.0);
    m[0][0] = focal / aspect;
    m[1][1] = focal;
    m[2][2] = (f + n) / (n - f);
    m[2][3] = -1.0;  // clip w = -z_view = view depth
    m[3][2] = 2.0 * f * n / (n - f);
    return m;
}

glm::dvec2 pixel_to_ndc(Resolution r, double pixel_x, double pixel_y) {
    // Written exactly as DESIGN.md states it, so that pixel centres round the same way.
    return {pixel_x / r.width * 2.0 - 1.0, 1.0 - pixel_y / r.height * 2.0};
}

glm::dvec3 ray_direction(const Camera& c, const CameraBasis& b, double aspect, glm::dvec2 ndc) {
    if (c.ortho_height > 0.0) return b.forward;
    const double tan_half = std::tan(glm::radians(c.fov_y_degrees) * 0.5);
    return b.forward + (ndc.x * tan_half * aspect) * b.right + (ndc.y * tan_half) * b.up;
}

glm::dvec3 ray_origin(const Camera& c, const CameraBasis& b, double aspect, glm::dvec2 ndc) {
    if (!(c.ortho_height > 0.0)) return c.eye;
    const double half = 0.5 * c.ortho_height;
    return c.eye + (ndc.x * half * aspect) * b.right + (ndc.y * half) * b.up;
}

std::string format_vec3(const glm::dvec3& v) {
    char text[128];
    std::snprintf(text, sizeof text, "%.17g,%.17g,%.17g", v.x, v.y, v.z);
    return text;
}

}  // namespace homcull
