#pragma once
// Camera conventions shared by every tool and test (../shared/DESIGN.md, "Conventions"):
// right-handed, OpenGL style. forward f = normalize(target - eye), right r = normalize(f x up),
// true up u = r x f, vertical field of view in degrees, aspect = W/H. Pixel column i runs left
// to right, row j top to bottom; the centre of pixel (i, j) is at
//   NDC x = (i + 0.5)/W*2 - 1,  y = 1 - (j + 0.5)/H*2.
// Everything here is computed in double: it is the reference the rasterizer and the ground
// truth are both checked against.
#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace homcull {

struct Resolution {
    int width = 0;
    int height = 0;
    double aspect() const { return double(width) / double(height); }
    long long pixel_count() const { return (long long)width * height; }
};

struct Camera {
    glm::dvec3 eye{0.0, 0.0, 0.0};
    glm::dvec3 target{0.0, 0.0, -1.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    double fov_y_degrees = 60.0;
    double near_plane = 0.1;
    double far_plane = 10000.0;
    // Above 0: an orthographic camera whose view is this many world units high (and the aspect
    // times that wide), its rays parallel to the view direction; fov_y_degrees is then unused.
    double ortho_height = 0.0;
};

struct CameraBasis {
    glm::dvec3 forward;
    glm::dvec3 right;
    glm::dvec3 up;
};

// Throws homcull::Error naming the problem when the camera cannot define a view: non-finite
// numbers, eye == target, up parallel to the view direction, fov_y outside (0, 180),
// near <= 0 or far <= near.
void validate_camera(const Camera& camera);
// Throws homcull::Error unless 1 <= width, height <= 65536.
void validate_resolution(Resolution resolution);

CameraBasis camera_basis(const Camera& camera);

// World to view space (the camera looks down -z, as glm::lookAt).
glm::dmat4 view_matrix(const Camera& camera);
// View to clip space, OpenGL convention (NDC z in [-1, 1]); clip w equals the view depth (an
// orthographic camera: w = 1, glm::ortho's matrix).
glm::dmat4 projection_matrix(const Camera& camera, double aspect);

// NDC of a continuous pixel position: (i + 0.5, j + 0.5) is the centre of pixel (i, j).
glm::dvec2 pixel_to_ndc(Resolution resolution, double pixel_x, double pixel_y);

// Direction of the ray from the eye through an NDC point, scaled so that
// dot(direction, forward) == 1: along it, the ray parameter t *is* the view depth, so the
// depth range [near, far] is the ray interval [near, far].
glm::dvec3 ray_direction(const Camera& camera, const CameraBasis& basis, double aspect,
                         glm::dvec2 ndc);
// Where that ray starts: the eye, or for an orthographic camera the point of the eye's plane
// in front of the NDC point (its direction is then the view direction).
glm::dvec3 ray_origin(const Camera& camera, const CameraBasis& basis, double aspect, glm::dvec2 ndc);

// "x,y,z" with enough digits to read back the same double.
std::string format_vec3(const glm::dvec3& v);

// A recorded or generated camera path: one camera per frame (file format in io/camera_path.hpp).
struct CameraPath {
    std::vector<Camera> frames;
};

// A circle around the scene's bounding box at `height_fraction` of its height above its
// centre, looking at the centre: the whole scene seen from every side.
CameraPath orbit_path(const glm::dvec3& bounds_min, const glm::dvec3& bounds_max, int frames,
                      double fov_y_degrees = 60.0, double height_fraction = 0.5);

}  // namespace homcull
