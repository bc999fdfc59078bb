// The scene culler's preparation (SceneCuller's constructor) with a job system: its per-object
// and per-mesh work runs in tasks, each writing only its own results, so that the culler made
// is the one a single thread makes. Checked through everything a culler shows: answers, the
// work counts and the buffer's bits, frame after frame, culled on one thread so that only the
// preparation differs.
#include "support.hpp"

#include "scene/shared_plans.hpp"

#include <homcull/camera.hpp>
#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/scene_culler.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace homcull {
namespace {

// A city with what takes the preparation's less common paths: an object mirrored by its
// transform (a closed mesh facing in), and one placed so far out that its world positions
// overflow float (its occludee parts are left out).
Scene city_with_odd_objects() {
    CityOptions city;
    city.blocks = 4;
    Scene scene = generate_city(city);
    Object mirrored = scene.objects[1];
    mirrored.world = glm::scale(mirrored.world, glm::dvec3(-1.0, 1.0, 1.0));
    scene.objects.push_back(mirrored);
    Object overflowing = scene.objects[2];
    overflowing.world = glm::scale(glm::dmat4(1.0), glm::dvec3(1e39, 1.0, 1.0)) * overflowing.world;
    scene.objects.push_back(overflowing);
    scene.finalize();
    return scene;
}

// Random views from the lower part of the box of the scene's objects placed within float.
std::vector<Camera> views_over(const Scene& scene, int count, std::uint64_t seed) {
    Aabb bounds;
    for (const Object& object : scene.objects)
        if (std::isfinite(object.world_bounds.min.x + object.world_bounds.max.x)) bounds.extend(object.world_bounds);
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto inside = [&] {
        glm::dvec3 p;
        for (int k = 0; k < 3; ++k) p[k] = double(bounds.min[k]) + unit(random) * (double(bounds.max[k]) - double(bounds.min[k]));
        return p;
    };
    std::vector<Camera> cameras;
    while (int(cameras.size()) < count) {
        Camera c;
        c.eye = inside();
        c.eye.y = double(bounds.min.y) + (0.05 + 0.2 * unit(random)) * (double(bounds.max.y) - double(bounds.min.y));
        c.target = inside();
        if (glm::length(c.target - c.eye) < 1.0) continue;
        c.far_plane = 1e4;
        cameras.push_back(c);
    }
    return cameras;
}

void expect_same_cullers(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                         const std::vector<Camera>& cameras, const std::string& what) {
    std::mt19937_64 order(5);
    const ParallelFor shuffled{&test::run_shuffled, &order, 2};
    SceneCuller serial(scene, occluders, config), threaded(scene, occluders, config, test::thread_jobs(2)),
        reordered(scene, occluders, config, shuffled);
    EXPECT_EQ(serial.occluder_triangles(), threaded.occluder_triangles()) << what;
    EXPECT_EQ(serial.occluder_triangles(), reordered.occluder_triangles()) << what;
    std::vector<OccludeeAnswer> a, b, c;
    std::size_t hidden = 0;
    for (std::size_t v = 0; v < cameras.size(); ++v) {
        serial.cull(cameras[v], a);
        threaded.cull(cameras[v], b);
        reordered.cull(cameras[v], c);
        for (std::size_t id = 0; id < a.size(); ++id) {
            ASSERT_EQ(a[id].visibility, b[id].visibility) << what << ", view " << v << ", object " << id;
            ASSERT_EQ(a[id].level_of_visibility, b[id].level_of_visibility) << what << ", view " << v << ", object " << id;
            ASSERT_EQ(a[id].visibility, c[id].visibility) << what << ", view " << v << ", object " << id;
            hidden += a[id].visibility == Visibility::occluded;
        }
        for (const SceneCuller* other : {&threaded, &reordered}) {
            EXPECT_EQ(serial.work().occluder_triangles, other->work().occluder_triangles) << what << ", view " << v;
            EXPECT_EQ(serial.work().objects_tested, other->work().objects_tested) << what << ", view " << v;
            EXPECT_EQ(serial.work().occludee_parts_tested, other->work().occludee_parts_tested) << what << ", view " << v;
            EXPECT_EQ(serial.work().solid_parts_tested, other->work().solid_parts_tested) << what << ", view " << v;
            EXPECT_TRUE(test::same_subtiles(serial.buffer(), other->buffer())) << what << ", view " << v;
        }
    }
    EXPECT_GT(hidden, 0u) << what << ": no object hidden, the views test nothing";
}

TEST(CullerPreparation, InTasksMakesTheCullerOfOneThread) {
    const Scene city = city_with_odd_objects();
    const std::vector<std::uint32_t> occluders = occluder_candidates(city, OccluderFilter::role);
    const std::vector<Camera> cameras = views_over(city, 6, 1);
    for (const bool clusters : {true, false}) {
        SceneCullerConfig config;
        config.display = {320, 180};
        config.occluder_clusters = clusters;
        expect_same_cullers(city, occluders, config, cameras, clusters ? "city, clusters" : "city, triangles");
    }
}

// The castle: coplanar merges, closed meshes, hundreds of meshes split into parts, occluders
// drawn as clusters; the defaults at 640x360.
TEST(CullerPreparation, InTasksMakesTheCastleCullerOfOneThread) {
    const std::string file = test::shared_scene("intel_castle.glb");
    if (file.empty()) GTEST_SKIP() << "the shared scenes are missing";
    const Scene castle = load_scene(file);
    SceneCullerConfig config;
    config.display = {640, 360};
    std::vector<Camera> cameras = views_over(castle, 3, 2);
    cameras.push_back(test::castle_view_c0());
    expect_same_cullers(castle, occluder_candidates(castle, OccluderFilter::role), config, cameras, "castle");
}

// The plans' sharing: a candidate shares the plan of the first one placing the same mesh with
// the same local triangles, and plans itself when its triangles differ in any way (an index,
// their count, the vertex count) or its mesh does, wherever its vertices begin.
TEST(CullerPreparation, PlacementsShareAPlanOnlyWithTheSameMeshAndTriangles) {
    using detail::LocalTriangles;
    const LocalTriangles quad{0, 4, {0, 1, 2, 0, 2, 3}};
    LocalTriangles other_split = quad;
    other_split.indices = {0, 1, 3, 1, 2, 3};  // the quad cut along its other diagonal
    LocalTriangles one_more_vertex = quad;
    one_more_vertex.vertices = 5;
    LocalTriangles placed_elsewhere = quad;
    placed_elsewhere.base = 40;  // the same triangles from another first vertex: shared
    const LocalTriangles fewer{0, 4, {0, 1, 2}};
    const std::vector<LocalTriangles> local = {quad, other_split, placed_elsewhere, quad, one_more_vertex, fewer, other_split, quad};
    const std::vector<std::uint32_t> mesh_of = {0, 0, 0, 1, 0, 0, 0, 1};
    const std::vector<std::uint32_t> expected = {0, 1, 0, 3, 4, 5, 1, 3};
    EXPECT_EQ(detail::first_with_same_triangles(mesh_of, local), expected);
    EXPECT_TRUE(detail::first_with_same_triangles({}, {}).empty());
    EXPECT_THROW(detail::first_with_same_triangles({0}, local), Error);
    EXPECT_THROW(detail::first_with_same_triangles(mesh_of, local, nullptr), Error);
    // The same under a key that puts every candidate in one group, as a collision of the real
    // key would put two: the full comparison alone tells them apart.
    const detail::TrianglesKey one_group = [](std::uint32_t, const LocalTriangles&) -> std::uint64_t { return 42; };
    EXPECT_EQ(detail::first_with_same_triangles(mesh_of, local, one_group), expected);

    // Many placements of one mesh, every one with triangles of its own but the last, which
    // repeats the first: each plans for itself, the last shares the first's; under the real key
    // (linear) and in one group (quadratic: fewer placements).
    const std::pair<std::uint32_t, detail::TrianglesKey> runs[] = {{5000u, &detail::triangles_key}, {400u, one_group}};
    for (const auto& [count, key] : runs) {
        std::vector<LocalTriangles> many;
        for (std::uint32_t k = 0; k < count; ++k) many.push_back({0, count, {0, 1, 2, k % 3, (k + 1) % 3, k}});
        many.push_back(many.front());
        const std::vector<std::uint32_t> plan = detail::first_with_same_triangles(std::vector<std::uint32_t>(many.size(), 7), many, key);
        for (std::size_t k = 0; k + 1 < many.size(); ++k) ASSERT_EQ(plan[k], k);
        EXPECT_EQ(plan.back(), 0u);
    }
    // The real key tells the test's differing triangles apart (else the cases above would not
    // reach the grouping they are meant to test).
    for (std::size_t a = 0; a < local.size(); ++a)
        for (std::size_t b = 0; b < local.size(); ++b) {
            if (expected[a] == expected[b]) continue;
            EXPECT_NE(detail::triangles_key(mesh_of[a], local[a]), detail::triangles_key(mesh_of[b], local[b])) << a << " " << b;
        }
}

}  // namespace
}  // namespace homcull
