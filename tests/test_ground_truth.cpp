// Ground truth on hand-built scenes whose answers are known by construction.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/id_image.hpp>
#include <homcull/truth/ground_truth.hpp>

#include <gtest/gtest.h>

#include <vector>

namespace homcull {
namespace {

using test::add_box;
using test::add_quad;
using test::camera_down_minus_z;

TruthResult cast(const Scene& scene, const Camera& camera, Resolution resolution, int samples = 1) {
    const RayScene rays(scene);
    TruthOptions options;
    options.resolution = resolution;
    options.samples = samples;
    options.keep_sample_ids = true;
    return compute_ground_truth(rays, scene, camera, options);
}

TEST(GroundTruth, BoxFullyHidesAnotherBox) {
    Scene scene;
    // From the eye, the front box covers |x/z|, |y/z| <= 1/4; the back box lies within 1/20.
    const auto front = add_box(scene, "front", {-1, -1, -6}, {1, 1, -4});
    const auto back = add_box(scene, "back", {-0.5f, -0.5f, -12}, {0.5f, 0.5f, -10});
    const TruthResult r = cast(scene, camera_down_minus_z(60.0), {64, 48});
    EXPECT_TRUE(r.objects[back].in_frustum);
    EXPECT_EQ(r.objects[back].visible_samples, 0u);
    EXPECT_GT(r.objects[front].visible_samples, 0u);
    // Move the hidden box out from behind: now it is seen.
    Scene moved;
    add_box(moved, "front", {-1, -1, -6}, {1, 1, -4});
    add_box(moved, "back", {4, -0.5f, -12}, {5, 0.5f, -10});  // |x/z| in [1/3, 1/2]
    EXPECT_GT(cast(moved, camera_down_minus_z(60.0), {64, 48}).objects[back].visible_samples, 0u);
}

// An orthographic camera's rays are parallel: a box behind a smaller one shows round its edges
// however far it is (a perspective view shrinks it behind), one behind a larger one never does,
// and one beside the view's rectangle is outside its frustum (a box, not a pyramid).
TEST(GroundTruth, OrthographicRaysAreParallel) {
    Scene scene;
    const auto front = add_box(scene, "front", {-1, -1, -6}, {1, 1, -4});
    const auto larger = add_box(scene, "larger behind", {-1.25f, -1.25f, -40}, {1.25f, 1.25f, -38});
    const auto smaller = add_box(scene, "smaller behind", {-0.9f, 3.1f, -40}, {0.9f, 4.9f, -38});
    add_box(scene, "cover", {-1, 3, -6}, {1, 5, -4});
    const auto beside = add_box(scene, "beside", {15, -1, -51}, {15.5f, 1, -50});  // |x/z| about 0.3: in the perspective view
    Camera camera = camera_down_minus_z(60.0);
    const TruthResult perspective = cast(scene, camera, {64, 48});
    EXPECT_EQ(perspective.objects[larger].visible_samples, 0u);  // 1.25 / 39 is well inside 1 / 5
    camera.ortho_height = 12.0;                                  // 16 x 12 world units
    const TruthResult ortho = cast(scene, camera, {64, 48});
    EXPECT_GT(ortho.objects[front].visible_samples, 0u);
    EXPECT_GT(ortho.objects[larger].visible_samples, 0u);
    EXPECT_EQ(ortho.objects[smaller].visible_samples, 0u);
    EXPECT_TRUE(ortho.objects[smaller].in_frustum);
    EXPECT_FALSE(ortho.objects[beside].in_frustum);  // x in [15, 15.5], the orthographic view's in [-8, 8]
    EXPECT_EQ(ortho.objects[beside].visible_samples, 0u);
    EXPECT_GT(perspective.objects[beside].visible_samples, 0u);
}

// Two occluders at view depth 1 leave a gap exactly one pixel wide: with fov 90 and a square
// 64x64 display, x_ndc equals x_world at depth 1 and a pixel is 1/32 wide. The gap
// [0, 1/32] holds the centres of column 32 only, so the wall behind is seen by exactly
// 64 samples at S = 1, all in column 32.
Scene gap_scene(float gap_left, float gap_right) {
    Scene scene;
    add_quad(scene, "left", {-10, -10, -1}, {gap_left, -10, -1}, {gap_left, 10, -1}, {-10, 10, -1});
    add_quad(scene, "right", {gap_right, -10, -1}, {10, -10, -1}, {10, 10, -1}, {gap_right, 10, -1});
    add_quad(scene, "wall", {-100, -100, -5}, {100, -100, -5}, {100, 100, -5}, {-100, 100, -5});
    return scene;
}

TEST(GroundTruth, OnePixelGapIsSeenThroughByExactlyTheRightSamples) {
    const Scene scene = gap_scene(0.0f, 1.0f / 32.0f);
    const TruthResult r = cast(scene, camera_down_minus_z(90.0), {64, 64});
    EXPECT_EQ(r.objects[2].visible_samples, 64u);
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const std::uint32_t id = r.sample_ids[std::size_t(y * 64 + x)];
            EXPECT_EQ(id, x < 32 ? 0u : x == 32 ? 2u : 1u) << "pixel " << x << "," << y;
        }
    EXPECT_EQ(r.objects[0].visible_samples + r.objects[1].visible_samples + r.objects[2].visible_samples, 64u * 64u);
}

TEST(GroundTruth, GapWithSubSamplesSeenByBothSubColumnsOfItsPixel) {
    // S = 2: the sub-sample columns of pixel 32 sit at x_ndc = 1/128 and 3/128.
    const TruthResult r = cast(gap_scene(0.0f, 1.0f / 32.0f), camera_down_minus_z(90.0), {64, 64}, 2);
    EXPECT_EQ(r.objects[2].visible_samples, 2u * 128u);
    // A half-pixel gap [1/64, 1/32] holds only the right sub-column (3/128).
    const TruthResult half = cast(gap_scene(1.0f / 64.0f, 1.0f / 32.0f), camera_down_minus_z(90.0), {64, 64}, 2);
    EXPECT_EQ(half.objects[2].visible_samples, 128u);
    for (int y = 0; y < 128; ++y) EXPECT_EQ(half.sample_ids[std::size_t(y * 128 + 65)], 2u);
    // At S = 1 a gap [1/48, 1/32] holds no pixel centre (column 32's is at 1/64): nothing
    // is seen through it.
    const TruthResult centre = cast(gap_scene(1.0f / 48.0f, 1.0f / 32.0f), camera_down_minus_z(90.0), {64, 64}, 1);
    EXPECT_EQ(centre.objects[2].visible_samples, 0u);
}

TEST(GroundTruth, NearAndFarPlanesClipByViewDepth) {
    Scene scene;
    const auto too_near = add_quad(scene, "too_near", {-1, -1, -0.5f}, {1, -1, -0.5f}, {1, 1, -0.5f}, {-1, 1, -0.5f});
    const auto middle = add_quad(scene, "middle", {-1, -1, -3}, {0, -1, -3}, {0, 1, -3}, {-1, 1, -3});
    const auto too_far = add_quad(scene, "too_far", {-100, -100, -20}, {100, -100, -20}, {100, 100, -20}, {-100, 100, -20});
    const TruthResult r = cast(scene, camera_down_minus_z(60.0, 1.0, 10.0), {32, 32});
    EXPECT_EQ(r.objects[too_near].visible_samples, 0u);  // view depth 0.5 < near
    EXPECT_EQ(r.objects[too_far].visible_samples, 0u);   // view depth 20 > far
    EXPECT_GT(r.objects[middle].visible_samples, 0u);
    // Depth is view depth, not distance: a plane at view depth 9.9 is inside far = 10 all
    // the way to the corners of the image, where the distance along the ray is larger.
    Scene plane;
    add_quad(plane, "plane", {-100, -100, -9.9f}, {100, -100, -9.9f}, {100, 100, -9.9f}, {-100, 100, -9.9f});
    EXPECT_EQ(cast(plane, camera_down_minus_z(90.0, 1.0, 10.0), {16, 16}).objects[0].visible_samples, 256u);
}

TEST(GroundTruth, BackFacesCount) {
    Scene scene;
    // Wound clockwise as seen from the camera: a back face.
    add_quad(scene, "back_facing", {-1, -1, -3}, {-1, 1, -3}, {1, 1, -3}, {1, -1, -3});
    EXPECT_GT(cast(scene, camera_down_minus_z(60.0), {16, 16}).objects[0].visible_samples, 0u);
}

TEST(GroundTruth, CoincidentSurfacesAreVisibleButNotRobust) {
    Scene scene;
    const auto a = add_quad(scene, "a", {-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    const auto b = add_quad(scene, "b", {-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    const auto c = add_quad(scene, "c", {2, -1, -3}, {4, -1, -3}, {4, 1, -3}, {2, 1, -3});
    const auto d = add_quad(scene, "d_behind_c", {2, -1, -3.01f}, {4, -1, -3.01f}, {4, 1, -3.01f}, {2, 1, -3.01f});
    const TruthResult r = cast(scene, camera_down_minus_z(90.0), {64, 64});
    EXPECT_GT(r.objects[a].visible_samples + r.objects[b].visible_samples, 0u);
    EXPECT_EQ(r.objects[a].robust_samples + r.objects[b].robust_samples, 0u);
    // 0.01 behind at depth 3 is a relative depth of 3.3e-3 > 1e-4: c's samples are robust.
    EXPECT_GT(r.objects[c].visible_samples, 0u);
    EXPECT_EQ(r.objects[c].robust_samples, r.objects[c].visible_samples);
    EXPECT_EQ(r.objects[d].visible_samples, 0u);
    // Tie samples: at every sample of the two coincident quads, the one not hit lies in the
    // hit's window; d is hidden outright (no tie samples), and c's hits have no tie.
    EXPECT_EQ(r.objects[a].tie_samples + r.objects[b].tie_samples, r.objects[a].visible_samples + r.objects[b].visible_samples);
    EXPECT_EQ(r.objects[c].tie_samples, 0u);
    EXPECT_EQ(r.objects[d].tie_samples, 0u);
}

// A quad seen nowhere because a coincident one wins every tie is hidden only through ties: it
// has tie samples, which tell it apart from a quad hidden outright.
TEST(GroundTruth, AnObjectHiddenOnlyThroughTiesHasTieSamples) {
    Scene scene;
    const auto big = add_quad(scene, "big", {-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
    const auto behind = add_quad(scene, "behind", {-0.5f, -0.5f, -4}, {0.5f, -0.5f, -4}, {0.5f, 0.5f, -4}, {-0.5f, 0.5f, -4});
    // Up to four coincident copies of a small quad inside the big one's area: each sample of it
    // hits one of the five surfaces; the others at that sample are its ties.
    std::vector<std::uint32_t> copies;
    for (int k = 0; k < 4; ++k)
        copies.push_back(add_quad(scene, "copy", {-0.25f, -0.25f, -3}, {0.25f, -0.25f, -3}, {0.25f, 0.25f, -3}, {-0.25f, 0.25f, -3}));
    const TruthResult r = cast(scene, camera_down_minus_z(90.0), {64, 64});
    EXPECT_GT(r.objects[big].visible_samples, 0u);  // alone around the copies
    EXPECT_EQ(r.objects[behind].visible_samples, 0u);
    EXPECT_EQ(r.objects[behind].tie_samples, 0u);
    // Whichever surface wins a sample of the small area (that depends on Embree's traversal
    // order), the other four lie in its window: four tie samples per sample there.
    std::uint64_t copies_seen = 0, ties = r.objects[big].tie_samples;
    for (std::uint32_t c : copies) {
        copies_seen += r.objects[c].visible_samples;
        ties += r.objects[c].tie_samples;
        if (r.objects[c].visible_samples == 0) {
            EXPECT_GT(r.objects[c].tie_samples, 0u) << "copy " << c << " is hidden only through ties";
        }
    }
    EXPECT_GE(ties, 4 * copies_seen);
    EXPECT_GT(ties, 0u);
}

TEST(GroundTruth, ObjectsOutsideTheFrustumAreNotInIt) {
    Scene scene;
    const auto behind = add_box(scene, "behind", {-1, -1, 4}, {1, 1, 6});
    const auto beside = add_box(scene, "beside", {50, -1, -6}, {52, 1, -4});
    const auto ahead = add_box(scene, "ahead", {-1, -1, -6}, {1, 1, -4});
    const TruthResult r = cast(scene, camera_down_minus_z(60.0), {32, 32});
    EXPECT_FALSE(r.objects[behind].in_frustum);
    EXPECT_FALSE(r.objects[beside].in_frustum);
    EXPECT_TRUE(r.objects[ahead].in_frustum);
    EXPECT_EQ(r.objects[behind].visible_samples + r.objects[beside].visible_samples, 0u);
}

// The packet tracer against the simplest possible reference: one rtcIntersect1 ray per
// sample, with the ray built here from DESIGN.md's formulas.
void expect_matches_single_rays(const Scene& scene, const Camera& camera, Resolution res, int samples) {
    const RayScene rays(scene);
    TruthOptions options;
    options.resolution = res;
    options.samples = samples;
    options.keep_sample_ids = true;
    const TruthResult r = compute_ground_truth(rays, scene, camera, options);
    const CameraBasis basis = camera_basis(camera);
    std::vector<std::uint64_t> counts(scene.objects.size(), 0);
    std::size_t mismatches = 0;
    for (int y = 0; y < res.height * samples; ++y)
        for (int x = 0; x < res.width * samples; ++x) {
            const glm::dvec2 ndc = pixel_to_ndc(res, (x + 0.5) / samples, (y + 0.5) / samples);
            const glm::vec3 dir(ray_direction(camera, basis, res.aspect(), ndc));
            const RayHit hit = rays.intersect(glm::vec3(camera.eye), dir, float(camera.near_plane), float(camera.far_plane));
            if (hit.hit()) ++counts[hit.object];
            mismatches += hit.object != r.sample_ids[std::size_t(y) * std::size_t(res.width * samples) + std::size_t(x)];
        }
    EXPECT_EQ(mismatches, 0u);
    for (std::size_t id = 0; id < counts.size(); ++id) EXPECT_EQ(counts[id], r.objects[id].visible_samples) << "object " << id;
}

TEST(GroundTruth, PacketsMatchSingleRaysOnGeneratedScenes) {
    const Scene city = generate_scene("city:seed=5,blocks=4");
    Camera street;
    street.eye = {-1.0, 1.7, -20.0};
    street.target = {30.0, 2.0, 15.0};
    street.near_plane = 0.1;
    street.far_plane = 1000.0;
    expect_matches_single_rays(city, street, {160, 90}, 2);
    const Scene forest = generate_scene("forest:seed=2,radius=40");
    Camera hiker;
    hiker.eye = {0.3, 1.7, 0.2};
    hiker.target = {10.0, 1.5, 30.0};
    expect_matches_single_rays(forest, hiker, {97, 61}, 1);  // odd sizes: partial packets
}

TEST(GroundTruth, CountsAddUpAndRunsAreDeterministic) {
    const Scene city = generate_scene("city:seed=9,blocks=3");
    Camera high;
    high.eye = {-80.0, 60.0, -90.0};
    high.target = {0.0, 0.0, 0.0};
    const TruthResult a = cast(city, high, {120, 80}, 3);
    const TruthResult b = cast(city, high, {120, 80}, 3);
    EXPECT_EQ(a.sample_ids, b.sample_ids);
    std::uint64_t hits = 0, background = 0;
    for (const auto& v : a.objects) {
        hits += v.visible_samples;
        EXPECT_LE(v.robust_samples, v.visible_samples);
        if (v.visible_samples > 0) { EXPECT_TRUE(v.in_frustum); }
    }
    for (std::uint32_t id : a.sample_ids) background += id == kNoObject;
    EXPECT_EQ(hits + background, 120u * 80u * 9u);
}

TEST(GroundTruth, RejectsInvalidOptions) {
    Scene scene;
    add_box(scene, "box", {-1, -1, -3}, {1, 1, -2});
    const RayScene rays(scene);
    TruthOptions options;
    options.resolution = {0, 10};
    EXPECT_THROW(compute_ground_truth(rays, scene, camera_down_minus_z(), options), Error);
    options.resolution = {10, 10};
    options.samples = 0;
    EXPECT_THROW(compute_ground_truth(rays, scene, camera_down_minus_z(), options), Error);
    options.samples = 1;
    Camera bad = camera_down_minus_z();
    bad.target = bad.eye;
    EXPECT_THROW(compute_ground_truth(rays, scene, bad, options), Error);
}

}  // namespace
}  // namespace homcull
