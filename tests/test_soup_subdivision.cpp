// Zhang's subdivision of polygon soups into objects (Zhang 1998, sec. 8.2.1;
// homcull/soup_subdivision.hpp): the cells partition the triangles exactly (same world-space
// triangles, each in one cell), degenerate input never breaks that, and the bunny split into
// cells lets the culler hide its back behind its front, with no false cull against Embree.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/soup_subdivision.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/truth/walkthrough.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace homcull {
namespace {

using WorldTriangle = std::array<float, 9>;

// Every placed triangle as its world-space vertex positions, sorted: a multiset to compare.
// NaN coordinates count as 0, so that scenes holding them still compare.
std::vector<WorldTriangle> world_triangles(const Scene& scene) {
    std::vector<WorldTriangle> triangles;
    for (const Object& object : scene.objects) {
        const Mesh& mesh = scene.meshes[object.mesh];
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
            WorldTriangle w;
            for (std::size_t k = 0; k < 3; ++k) {
                const glm::vec3 p = transform_point(object.world, mesh.positions[mesh.indices[3 * t + k]]);
                for (int axis = 0; axis < 3; ++axis) w[3 * k + std::size_t(axis)] = std::isnan(p[axis]) ? 0.0f : p[axis];
            }
            triangles.push_back(w);
        }
    }
    std::sort(triangles.begin(), triangles.end());
    return triangles;
}

bool contains(const Aabb& outer, const Aabb& inner) {
    return glm::all(glm::lessThanEqual(outer.min, inner.min)) && glm::all(glm::greaterThanEqual(outer.max, inner.max));
}

// The partition checks that hold for every input: the same placed triangles, each once; every
// object either the original (same name, same mesh contents) or one of its cells, in order;
// cells named and tagged by their path, with compact meshes of their own, inside the
// original's box.
void expect_partition(const Scene& before, const Scene& after, std::size_t max_triangles) {
    EXPECT_EQ(after.instanced_triangle_count(), before.instanced_triangle_count());
    EXPECT_TRUE(world_triangles(after) == world_triangles(before)) << "the cells do not hold the original's triangles";
    std::size_t next = 0;  // id in `after`
    for (const Object& original : before.objects) {
        ASSERT_LT(next, after.objects.size()) << original.name;
        if (after.objects[next].name == original.name) {  // kept whole
            const Object& kept = after.objects[next++];
            EXPECT_EQ(after.meshes[kept.mesh].indices, before.meshes[original.mesh].indices);
            EXPECT_EQ(kept.extras, original.extras);
            continue;
        }
        const std::string prefix = original.name + '#';
        std::string last_name;
        for (; next < after.objects.size() && after.objects[next].name.compare(0, prefix.size(), prefix) == 0; ++next) {
            const Object& cell = after.objects[next];
            const Mesh& mesh = after.meshes[cell.mesh];
            const std::string path = cell.name.substr(prefix.size());
            EXPECT_LT(last_name, cell.name) << "cells are listed in the order of their names";
            last_name = cell.name;
            ASSERT_NE(cell.extra("soup_cell"), nullptr) << cell.name;
            EXPECT_EQ(*cell.extra("soup_cell"), path);
            EXPECT_TRUE(std::is_sorted(cell.extras.begin(), cell.extras.end())) << cell.name;
            EXPECT_EQ(cell.extras.size(), original.extras.size() + (original.extra("soup_cell") ? 0 : 1));
            EXPECT_EQ(cell.world, original.world);
            EXPECT_GT(mesh.triangle_count(), 0u) << cell.name;
            if (max_triangles > 0) {
                EXPECT_LE(mesh.triangle_count(), max_triangles) << cell.name;
            }
            std::vector<char> used(mesh.positions.size(), 0);
            for (std::uint32_t v : mesh.indices) used[v] = 1;
            EXPECT_EQ(std::count(used.begin(), used.end(), 1), std::ptrdiff_t(used.size())) << cell.name << " is not compact";
            EXPECT_TRUE(contains(original.world_bounds, cell.world_bounds)) << cell.name;
        }
        EXPECT_FALSE(last_name.empty()) << original.name << " is missing from the result";
    }
    EXPECT_EQ(next, after.objects.size());
    // Every cell has its mesh to itself.
    std::vector<int> users(after.meshes.size(), 0);
    for (const Object& object : after.objects)
        if (object.extra("soup_cell")) {
            EXPECT_EQ(++users[object.mesh], 1) << object.name;
        }
}

std::size_t most_triangles(const Scene& scene) {
    std::size_t most = 0;
    for (const Object& object : scene.objects) most = std::max(most, scene.triangle_count(object));
    return most;
}

TEST(PolygonSoup, BunnyCellsPartitionItsTriangles) {
    const std::string path = test::shared_scene("stanford_bunny.obj");
    if (path.empty()) GTEST_SKIP() << "stanford_bunny.obj is not in " << test::shared_scenes_dir();
    const Scene bunny = load_scene(path);
    ASSERT_EQ(bunny.objects.size(), 1u);
    const auto start = std::chrono::steady_clock::now();
    const Scene cells = subdivide_polygon_soups(bunny, {2000});
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("[ soup     ] bunny: %zu triangles -> %zu cells of at most %zu triangles in %.1f ms\n",
                bunny.instanced_triangle_count(), cells.objects.size(), most_triangles(cells), ms);
    EXPECT_GT(cells.objects.size(), bunny.instanced_triangle_count() / 2000);
    EXPECT_LT(ms, 1000.0);
    EXPECT_EQ(cells.source, bunny.source + " (soup cells <= 2000 triangles)");
    EXPECT_EQ(cells.meshes.size(), cells.objects.size()) << "the bunny's own mesh is dropped";
    expect_partition(bunny, cells, 2000);
}

TEST(PolygonSoup, InstancesSplitOneByOneAndLargeThresholdsChangeNothing) {
    const Scene city = generate_scene("city:seed=2,blocks=3");
    const Scene same = subdivide_polygon_soups(city, {1000000});
    EXPECT_EQ(same.source, city.source);
    ASSERT_EQ(same.objects.size(), city.objects.size());
    for (std::size_t id = 0; id < city.objects.size(); ++id) {
        EXPECT_EQ(same.objects[id].name, city.objects[id].name);
        EXPECT_EQ(same.objects[id].mesh, city.objects[id].mesh);
    }
    ASSERT_EQ(same.meshes.size(), city.meshes.size());
    for (std::size_t m = 0; m < city.meshes.size(); ++m) {
        EXPECT_EQ(same.meshes[m].positions, city.meshes[m].positions);
        EXPECT_EQ(same.meshes[m].indices, city.meshes[m].indices);
    }
    // Split small: instances of one mesh are placed differently and split one by one.
    std::vector<int> users(city.meshes.size(), 0);
    for (const Object& object : city.objects) ++users[object.mesh];
    ASSERT_GT(*std::max_element(users.begin(), users.end()), 1) << "the city no longer shares meshes";
    const Scene split = subdivide_polygon_soups(city, {8});
    EXPECT_GT(split.objects.size(), city.objects.size());
    expect_partition(city, split, 0);
}

// A scene of one object per mesh, finalized.
Scene scene_of(std::vector<Mesh> meshes) {
    Scene scene;
    scene.source = "test";
    for (Mesh& mesh : meshes) {
        Object object;
        object.name = mesh.name;
        object.mesh = std::uint32_t(scene.meshes.size());
        object.extras = {{"role", "occluder"}, {"z", "last"}};
        scene.meshes.push_back(std::move(mesh));
        scene.objects.push_back(object);
    }
    scene.finalize();
    return scene;
}

// `count` triangles around `centre(t)`: a small fan of three distinct vertices each.
template <typename Centre>
Mesh triangles_around(const std::string& name, int count, Centre centre, float size) {
    Mesh mesh;
    mesh.name = name;
    for (int t = 0; t < count; ++t) {
        const glm::vec3 c = centre(t);
        const float turn = 0.7f * float(t);
        for (int k = 0; k < 3; ++k) {
            const float angle = turn + 2.0943951f * float(k);
            mesh.positions.push_back(c + size * glm::vec3(std::cos(angle), std::sin(angle), 0.25f * float(k - 1)));
            mesh.indices.push_back(std::uint32_t(mesh.positions.size() - 1));
        }
    }
    return mesh;
}

// `count` distinct triangles with integer vertices whose centres are all exactly `centre`.
Mesh coincident_centres(const std::string& name, int count, glm::vec3 centre) {
    Mesh mesh;
    mesh.name = name;
    for (int t = 0; t < count; ++t) {
        const glm::vec3 u(float(t + 1), 0.0f, 1.0f), v(0.0f, float(t + 2), -1.0f);
        mesh.positions.insert(mesh.positions.end(), {centre + u, centre + v, centre - u - v});
        for (int k = 3; k > 0; --k) mesh.indices.push_back(std::uint32_t(mesh.positions.size()) - std::uint32_t(k));
    }
    return mesh;
}

TEST(PolygonSoup, DegenerateInputNeverBreaksThePartition) {
    // All vertices at one point, and distinct triangles whose centres all coincide: unsplittable,
    // kept whole however large.
    Mesh point;
    point.name = "point";
    point.positions.assign(4, glm::vec3(1.0f, 2.0f, 3.0f));
    for (int t = 0; t < 50; ++t) point.indices.insert(point.indices.end(), {0, 1, std::uint32_t(2 + t % 2)});
    Mesh empty{"no triangles", {glm::vec3(0.0f), glm::vec3(1.0f)}, {}};
    const Scene degenerate = scene_of({point, coincident_centres("same centre", 40, glm::vec3(5.0f)),
                                       empty, Mesh{"nothing", {}, {}}});
    for (std::size_t max_triangles : {std::size_t(0), std::size_t(1), std::size_t(7), std::numeric_limits<std::size_t>::max()}) {
        const Scene result = subdivide_polygon_soups(degenerate, {max_triangles});
        EXPECT_EQ(result.objects.size(), degenerate.objects.size()) << max_triangles;
        EXPECT_EQ(result.source, degenerate.source) << "nothing was split";
        expect_partition(degenerate, result, 0);
    }

    // max_triangles = 1: one triangle per cell wherever the centres differ.
    Scene boxes;
    boxes.source = "boxes";
    test::add_box(boxes, "box", {0, 0, 0}, {1, 2, 3});
    test::add_box(boxes, "long", {0, 0, 0}, {40, 1, 2});
    const Scene singles = subdivide_polygon_soups(boxes, {1});
    EXPECT_EQ(most_triangles(singles), 1u);
    EXPECT_EQ(singles.objects.size(), 24u);
    expect_partition(boxes, singles, 1);
    EXPECT_EQ(subdivide_polygon_soups(boxes, {0}).objects.size(), 2u);

    // Many small random triangles, one per cell; and centres spread as 2^-k, which peel off
    // one triangle per level until the depth limit keeps the rest as one cell.
    std::uint32_t state = 12345u;
    auto random = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / 16777216.0f; };
    const Scene spread =
        scene_of({triangles_around("random", 3000, [&](int) { return glm::vec3(random(), random(), random()) * 100.0f; }, 0.5f),
                  triangles_around("halving", 200, [](int t) { return glm::vec3(std::ldexp(1.0f, -t / 2), 0.0f, 0.0f); }, 0.0f)});
    const Scene spread_cells = subdivide_polygon_soups(spread, {1});
    std::printf("[ soup     ] 3000 random triangles and 200 at 2^-k: %zu cells, at most %zu triangles\n",
                spread_cells.objects.size(), most_triangles(spread_cells));
    EXPECT_GE(spread_cells.objects.size(), 3000u);
    EXPECT_GT(most_triangles(spread_cells), 1u) << "the depth limit should have kept the 2^-k tail whole";
    expect_partition(spread, spread_cells, 0);

    // A vertex at NaN or infinity: placed somewhere, never lost.
    Scene bad = spread;
    bad.meshes[0].positions[0] = glm::vec3(std::numeric_limits<float>::quiet_NaN());
    bad.meshes[0].positions[4] = glm::vec3(std::numeric_limits<float>::infinity());
    const Scene bad_cells = subdivide_polygon_soups(bad, {16});
    EXPECT_EQ(bad_cells.instanced_triangle_count(), bad.instanced_triangle_count());
    EXPECT_TRUE(world_triangles(bad_cells) == world_triangles(bad));

    // Bad references are errors, not crashes.
    Scene missing_mesh = boxes;
    missing_mesh.objects[1].mesh = 7;
    EXPECT_THROW(subdivide_polygon_soups(missing_mesh, {1}), Error);
    Scene missing_vertex = boxes;
    missing_vertex.meshes[0].indices[5] = 8;
    EXPECT_THROW(subdivide_polygon_soups(missing_vertex, {1}), Error);
    EXPECT_THROW(subdivide_polygon_soups(missing_vertex, {100}), Error) << "the result is validated too";
}

TEST(PolygonSoup, BunnyCellsHideItsBackWithoutFalseCulls) {
    const std::string path = test::shared_scene("stanford_bunny.obj");
    if (path.empty()) GTEST_SKIP() << "stanford_bunny.obj is not in " << test::shared_scenes_dir();
    const Scene scene = subdivide_polygon_soups(load_scene(path), {2000});
    const RayScene rays(scene);
    SceneCullerConfig config;
    config.display = {320, 240};
    SceneCuller culler(scene, occluder_candidates(scene, OccluderFilter::all), config);
    TruthOptions truth_options;
    truth_options.resolution = config.display;
    const glm::dvec3 centre(-0.017, 0.11, 0.0);
    std::vector<OccludeeAnswer> answers;
    std::size_t views = 0, culled = 0, hidden = 0, false_culls = 0;
    for (int k = 0; k < 6; ++k) {
        const double angle = 2.0 * 3.14159265358979323846 * k / 6.0;
        Camera camera;
        camera.eye = centre + glm::dvec3(0.3 * std::cos(angle), 0.08 * (k % 3 - 1), 0.3 * std::sin(angle));
        camera.target = centre;
        camera.near_plane = 0.01;
        camera.far_plane = 10.0;
        const TruthResult truth = compute_ground_truth(rays, scene, camera, truth_options);
        const WalkFrame f = measure_walk_frame(scene, culler, camera, &truth, answers);
        ++views;
        hidden += f.truth.hidden_in_frustum;
        culled += f.truth.hidden_in_frustum - f.truth.missed_culls();
        false_culls += f.truth.false_culls;
        EXPECT_EQ(f.truth.false_culls, 0u) << "view " << k;
    }
    std::printf("[ soup     ] bunny in %zu cells, %zu views: culled %zu of %zu hidden cells, %zu false culls\n",
                scene.objects.size(), views, culled, hidden, false_culls);
    EXPECT_GT(culled, 0u) << "the bunny's front hides none of its back";
}

}  // namespace
}  // namespace homcull
