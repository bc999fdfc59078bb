// Walkthrough paths stay in free space: at eye height over a floor, never through geometry.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/truth/walk_path.hpp>

#include <gtest/gtest.h>

namespace homcull {
namespace {

// Checks a walk against the scene with rays the walker did not cast itself.
void expect_walk_in_free_space(const Scene& scene, const CameraPath& path, double eye_height, double step) {
    const RayScene rays(scene);
    int moves = 0;
    for (std::size_t k = 0; k < path.frames.size(); ++k) {
        const Camera& c = path.frames[k];
        EXPECT_NO_THROW(validate_camera(c));
        const RayHit floor = rays.intersect(glm::vec3(c.eye), {0, -1, 0}, 0.0f, 1e30f);
        ASSERT_TRUE(floor.hit()) << "frame " << k << ": no floor under the eye";
        EXPECT_NEAR(floor.t, eye_height, 1e-3 * eye_height) << "frame " << k;
        if (k == 0) continue;
        const glm::dvec3 a = path.frames[k - 1].eye, b = c.eye;
        const double length = glm::length(b - a);
        if (length == 0.0) continue;
        ++moves;
        EXPECT_LE(length, step * 1.5) << "frame " << k;
        // The segment between two eyes, and the same segment at knee height, hit nothing.
        for (double lift : {0.0, -0.7 * eye_height}) {
            const glm::dvec3 from = a + glm::dvec3(0, lift, 0), to = b + glm::dvec3(0, lift, 0);
            if (lift < 0 && std::abs(a.y - b.y) > 1e-9) continue;  // stepping up a stair
            const RayHit hit = rays.intersect(glm::vec3(from), glm::vec3(to - from), 0.0f, 1.0f);
            EXPECT_FALSE(hit.hit()) << "frame " << k << ": the walk passes through object " << hit.object;
        }
    }
    EXPECT_GT(moves, int(path.frames.size()) / 3) << "the walker hardly moved";
}

TEST(WalkPath, CityWalkStaysOnTheStreets) {
    const Scene city = generate_scene("city:seed=2,blocks=4");
    const RayScene rays(city);
    WalkOptions options;
    options.frames = 300;
    const CameraPath path = walk_path(rays, city, options);
    ASSERT_EQ(path.frames.size(), 300u);
    expect_walk_in_free_space(city, path, 1.7, 1.7 / 5);
    // Deterministic for a seed, different for another.
    const CameraPath again = walk_path(rays, city, options);
    for (std::size_t k = 0; k < path.frames.size(); ++k) EXPECT_EQ(path.frames[k].eye, again.frames[k].eye);
    options.seed = 99;
    EXPECT_NE(walk_path(rays, city, options).frames[0].eye, path.frames[0].eye);
}

TEST(WalkPath, ForestWalkWeavesBetweenTrees) {
    const Scene forest = generate_scene("forest:seed=3,radius=30");
    const RayScene rays(forest);
    WalkOptions options;
    options.frames = 200;
    options.eye_height = 1.5;
    const CameraPath path = walk_path(rays, forest, options);
    expect_walk_in_free_space(forest, path, 1.5, 1.5 / 5);
}

TEST(WalkPath, SceneWithoutFloorIsAClearError) {
    Scene wall;
    test::add_quad(wall, "wall", {-5, 0, -5}, {5, 0, -5}, {5, 10, -5}, {-5, 10, -5});
    const RayScene rays(wall);
    try {
        walk_path(rays, wall, WalkOptions{});
        ADD_FAILURE() << "a walk was found on a scene with no floor";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no walkable floor"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace homcull
