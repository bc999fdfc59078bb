// The BSP painter's oracle (homcull/truth/bsp_painter.hpp) against Embree: drawn back to front
// with the painter's algorithm, the BSP order of a scene's polygons gives Embree's first-hit id
// image at every pixel centre, except where a ray passes within the rounding tolerance of an
// edge (counted, and few).
#include "support.hpp"

#include <homcull/generate.hpp>
#include <homcull/truth/bsp_painter.hpp>
#include <homcull/truth/sort_truth.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace homcull {
namespace {

struct PaintTally {
    std::size_t pixels = 0, ambiguous = 0, mismatches = 0, covered = 0;
};

// Paints the BSP order from `camera` and compares it with Embree's first hits, pixel by pixel.
void compare_with_embree(const Scene& scene, const BspTree& tree, const RayScene& rays, const Camera& camera, Resolution display,
                         PaintTally& tally, const std::string& what) {
    std::vector<const BspPolygon*> order;
    tree.painter_order(camera.eye, order);
    std::vector<std::uint8_t> ambiguous;
    const std::vector<std::uint32_t> painted = paint_ids(order, tree.anchor(), camera, display, &ambiguous);
    const std::vector<std::uint32_t> seen = test::embree_first_hits(rays, scene, camera, display);
    ASSERT_EQ(seen.size(), painted.size());
    for (std::size_t p = 0; p < painted.size(); ++p) {
        ++tally.pixels;
        tally.covered += painted[p] != kNoObject;
        if (ambiguous[p]) {
            ++tally.ambiguous;
            continue;
        }
        if (painted[p] != seen[p]) {
            ++tally.mismatches;
            if (tally.mismatches <= 5)
                ADD_FAILURE() << what << ": pixel (" << p % std::size_t(display.width) << ", " << p / std::size_t(display.width)
                              << ") painted object " << painted[p] << ", Embree sees " << seen[p];
        }
    }
}

// A generated city from random eyes above its streets, looking anywhere: every certain pixel
// as Embree sees it, at an odd resolution.
TEST(BspPainter, BackToFrontOrderPaintsEmbreesFirstHitsOnACity) {
    CityOptions options;
    options.blocks = 2;
    options.cars_per_block = 3;
    const Scene city = generate_city(options);
    const BspTree tree(city);
    const RayScene rays(city);
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> across(-45.0, 45.0), height(1.5, 40.0), angle(0.0, 6.283185307179586);
    PaintTally tally;
    for (int view = 0; view < 6; ++view) {
        Camera camera;
        // In free space: outside every object's box (inside a building the eye would see its
        // floor, which lies in the ground's plane: a tie on every pixel).
        const auto inside_something = [&](const glm::dvec3& p) {
            for (const Object& o : city.objects)
                if (o.world_bounds.max.y > 0.0f && glm::all(glm::greaterThanEqual(p, glm::dvec3(o.world_bounds.min) - 0.5)) &&
                    glm::all(glm::lessThanEqual(p, glm::dvec3(o.world_bounds.max) + 0.5)))
                    return true;
            return false;
        };
        do camera.eye = {across(rng), height(rng), across(rng)};
        while (inside_something(camera.eye));
        const double a = angle(rng);
        camera.target = camera.eye + glm::dvec3(std::cos(a), -0.3 - 0.1 * view, std::sin(a));
        camera.near_plane = 0.5;
        compare_with_embree(city, tree, rays, camera, {161, 97}, tally, "view " + std::to_string(view));
    }
    std::printf("[ bsp      ] %zu polygons (%zu splits), %zu pixels, %zu covered, %zu ambiguous, %zu mismatches\n", tree.polygon_count(),
                tree.split_count(), tally.pixels, tally.covered, tally.ambiguous, tally.mismatches);
    EXPECT_EQ(tally.mismatches, 0u);
    EXPECT_GT(tally.covered, tally.pixels / 4) << "the views see too little to mean anything";
    EXPECT_LT(tally.ambiguous, tally.pixels / 100);

    // The comparison can fail: the same polygons front to back paint what lies behind.
    Camera camera;
    camera.eye = {0.0, 60.0, -70.0};
    camera.target = {0.0, 0.0, 0.0};
    std::vector<const BspPolygon*> order;
    tree.painter_order(camera.eye, order);
    std::reverse(order.begin(), order.end());
    const Resolution small{64, 36};
    const std::vector<std::uint32_t> wrong = paint_ids(order, tree.anchor(), camera, small);
    const std::vector<std::uint32_t> seen = test::embree_first_hits(rays, city, camera, small);
    std::size_t differ = 0;
    for (std::size_t p = 0; p < wrong.size(); ++p) differ += wrong[p] != seen[p];
    EXPECT_GT(differ, wrong.size() / 10);
}

// Interlocked objects, which no object order can draw, are drawn right polygon by polygon.
TEST(BspPainter, PaintsACycleThatNoObjectOrderCan) {
    Scene scene;
    test::add_interlocked_pair(scene, 0.3f);
    const BspTree tree(scene);
    const RayScene rays(scene);
    const SortTruth truth = occlusion_edges(rays, scene.objects.size(), test::camera_down_minus_z(), {41, 23});
    ASSERT_EQ(truth.edges.size(), 2u);  // 0 -> 1 and 1 -> 0
    PaintTally tally;
    compare_with_embree(scene, tree, rays, test::camera_down_minus_z(), {41, 23}, tally, "cycle");
    EXPECT_EQ(tally.mismatches, 0u);
    EXPECT_EQ(tally.covered, tally.pixels);
}

}  // namespace
}  // namespace homcull
