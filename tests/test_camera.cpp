// Camera math: the pixel-centre rays of ground truth and the projection matrix of the
// rasterizer must agree on where every point lands.
#include <homcull/camera.hpp>
#include <homcull/error.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace homcull {
namespace {

Camera random_camera(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(-100.0, 100.0), fov(5.0, 150.0);
    Camera c;
    c.eye = {u(rng), u(rng), u(rng)};
    c.target = c.eye + glm::dvec3(u(rng), u(rng) * 0.3, u(rng));
    c.fov_y_degrees = fov(rng);
    c.near_plane = 0.05;
    c.far_plane = 5000.0;
    return c;
}

TEST(Camera, PixelCentreRaysAndProjectionMatrixAgree) {
    std::mt19937_64 rng(42);
    for (int trial = 0; trial < 200; ++trial) {
        const Camera c = random_camera(rng);
        const Resolution res{int(rng() % 1919) + 1, int(rng() % 1079) + 1};
        const CameraBasis b = camera_basis(c);
        const glm::dmat4 clip_from_world = projection_matrix(c, res.aspect()) * view_matrix(c);
        const int i = int(rng() % std::uint64_t(res.width)), j = int(rng() % std::uint64_t(res.height));
        const glm::dvec2 ndc = pixel_to_ndc(res, i + 0.5, j + 0.5);
        const double t = 0.1 + double(rng() % 1000);
        const glm::dvec3 point = c.eye + t * ray_direction(c, b, res.aspect(), ndc);
        const glm::dvec4 clip = clip_from_world * glm::dvec4(point, 1.0);
        EXPECT_NEAR(clip.w, t, 1e-9 * t) << "clip w is the view depth, which is the ray parameter";
        EXPECT_NEAR(clip.x / clip.w, ndc.x, 1e-9);
        EXPECT_NEAR(clip.y / clip.w, ndc.y, 1e-9);
        // And back to the pixel: column i, row j (rows top to bottom).
        EXPECT_EQ(int(std::floor((clip.x / clip.w + 1.0) * 0.5 * res.width)), i);
        EXPECT_EQ(int(std::floor((1.0 - clip.y / clip.w) * 0.5 * res.height)), j);
    }
}

TEST(Camera, PixelCentresFollowTheDesignFormula) {
    const Resolution res{1920, 1080};
    for (int i : {0, 1, 959, 960, 1919})
        for (int j : {0, 539, 540, 1079}) {
            const glm::dvec2 ndc = pixel_to_ndc(res, i + 0.5, j + 0.5);
            EXPECT_EQ(ndc.x, (i + 0.5) / 1920 * 2 - 1);
            EXPECT_EQ(ndc.y, 1 - (j + 0.5) / 1080 * 2);
        }
    EXPECT_LT(pixel_to_ndc(res, 0.5, 0.5).x, 0.0);  // top-left pixel: left ...
    EXPECT_GT(pixel_to_ndc(res, 0.5, 0.5).y, 0.0);  // ... and up
}

TEST(Camera, BasisIsRightHandedAndOrthonormal) {
    Camera c;
    c.eye = {1, 2, 3};
    c.target = {4, 2.5, -1};
    c.up = {0, 1, 0};
    const CameraBasis b = camera_basis(c);
    EXPECT_NEAR(glm::length(b.forward), 1.0, 1e-12);
    EXPECT_NEAR(glm::length(b.right), 1.0, 1e-12);
    EXPECT_NEAR(glm::length(b.up), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(b.right, b.forward), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(b.up, b.forward), 0.0, 1e-12);
    const glm::dvec3 back = glm::cross(b.right, b.up);  // right x up = -forward
    EXPECT_NEAR(glm::length(back + b.forward), 0.0, 1e-12);
    EXPECT_GT(b.up.y, 0.0);
}

TEST(Camera, MatricesMatchGlm) {
    Camera c;
    c.eye = {3, -2, 7};
    c.target = {-1, 0.5, 2};
    c.up = {0.1, 1, 0};
    c.fov_y_degrees = 47;
    c.near_plane = 0.3;
    c.far_plane = 800;
    const glm::dmat4 view = glm::lookAt(c.eye, c.target, c.up);
    const glm::dmat4 proj = glm::perspective(glm::radians(47.0), 16.0 / 9.0, 0.3, 800.0);
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) {
            EXPECT_NEAR(view_matrix(c)[col][row], view[col][row], 1e-12);
            EXPECT_NEAR(projection_matrix(c, 16.0 / 9.0)[col][row], proj[col][row], 1e-12);
        }
}

TEST(Camera, InvalidCamerasAreRejectedWithAReason) {
    Camera ok;
    EXPECT_NO_THROW(validate_camera(ok));
    auto rejects = [](Camera c, const char* fragment) {
        try {
            validate_camera(c);
            ADD_FAILURE() << "accepted a camera that should fail with '" << fragment << "'";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    };
    Camera c = ok; c.target = c.eye; rejects(c, "same point");
    c = ok; c.up = {0, 0, -2}; rejects(c, "parallel");
    c = ok; c.up = {0, 0, 0}; rejects(c, "zero");
    c = ok; c.fov_y_degrees = 0; rejects(c, "fov_y");
    c = ok; c.fov_y_degrees = 180; rejects(c, "fov_y");
    c = ok; c.near_plane = 0; rejects(c, "near");
    c = ok; c.far_plane = c.near_plane; rejects(c, "far");
    c = ok; c.eye.x = std::nan(""); rejects(c, "finite");
    c = ok; c.target.y = INFINITY; rejects(c, "finite");
    EXPECT_THROW(validate_resolution({0, 10}), Error);
    EXPECT_THROW(validate_resolution({10, -1}), Error);
    EXPECT_NO_THROW(validate_resolution({1, 1}));
    EXPECT_NO_THROW(validate_resolution({1921, 1081}));
}

TEST(Camera, OrbitLooksAtTheCentreFromOutsideTheBox) {
    const CameraPath path = orbit_path({-10, 0, -20}, {30, 15, 40}, 36);
    ASSERT_EQ(path.frames.size(), 36u);
    for (const Camera& c : path.frames) {
        EXPECT_EQ(c.target, glm::dvec3(10, 7.5, 10));
        EXPECT_GT(glm::length(c.eye - c.target), glm::length(glm::dvec3(40, 15, 60)) * 0.5);
        EXPECT_NO_THROW(validate_camera(c));
    }
    EXPECT_THROW(orbit_path({0, 0, 0}, {1, 1, 1}, 0), Error);
}

}  // namespace
}  // namespace homcull
