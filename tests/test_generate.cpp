// Generated scenes: deterministic, well formed, the shapes they promise, and a faithful
// round trip through binary glTF.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <algorithm>

namespace homcull {
namespace {

bool overlap_xz(const Aabb& a, const Aabb& b) {
    return a.min.x < b.max.x && b.min.x < a.max.x && a.min.z < b.max.z && b.min.z < a.max.z;
}

void expect_same_scene(const Scene& a, const Scene& b) {
    ASSERT_EQ(a.meshes.size(), b.meshes.size());
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (std::size_t m = 0; m < a.meshes.size(); ++m) {
        EXPECT_EQ(a.meshes[m].positions, b.meshes[m].positions);
        EXPECT_EQ(a.meshes[m].indices, b.meshes[m].indices);
    }
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
        EXPECT_EQ(a.objects[i].name, b.objects[i].name);
        EXPECT_EQ(a.objects[i].mesh, b.objects[i].mesh);
        EXPECT_EQ(a.objects[i].world, b.objects[i].world);
        EXPECT_EQ(a.objects[i].extras, b.objects[i].extras);
        EXPECT_EQ(a.objects[i].world_bounds.min, b.objects[i].world_bounds.min);
        EXPECT_EQ(a.objects[i].world_bounds.max, b.objects[i].world_bounds.max);
    }
}

TEST(Generate, CityIsDeterministicAndSeedDependent) {
    expect_same_scene(generate_scene("city:seed=4"), generate_scene("city:seed=4"));
    const Scene a = generate_scene("city:seed=4"), b = generate_scene("city:seed=5");
    EXPECT_NE(a.objects[1].world, b.objects[1].world);
}

TEST(Generate, CityBuildingsShareOneMeshStandOnTheGroundAndDoNotOverlap) {
    CityOptions options;
    options.blocks = 5;
    const Scene city = generate_city(options);
    EXPECT_EQ(city.meshes.size(), 2u);
    std::vector<Aabb> buildings;
    int occludees = 0;
    for (const Object& o : city.objects) {
        ASSERT_NE(o.extra("role"), nullptr);
        if (*o.extra("set") == "buildings") {
            EXPECT_EQ(o.mesh, city.objects[1].mesh);
            EXPECT_EQ(o.world_bounds.min.y, 0.0f);
            EXPECT_GE(o.world_bounds.max.y, 6.0f);
            buildings.push_back(o.world_bounds);
        }
        occludees += *o.extra("role") == "occludee";
    }
    EXPECT_EQ(buildings.size(), 4u * 25u);
    EXPECT_GT(occludees, 100);
    for (std::size_t i = 0; i < buildings.size(); ++i)
        for (std::size_t j = i + 1; j < buildings.size(); ++j) EXPECT_FALSE(overlap_xz(buildings[i], buildings[j]));
    EXPECT_EQ(city.objects[0].name, "ground");
}

TEST(Generate, ForestTreesAreDisjointSmallOccluders) {
    ForestOptions options;
    options.radius = 40;
    const Scene forest = generate_forest(options);
    std::vector<Aabb> trees;
    for (const Object& o : forest.objects)
        if (*o.extra("set") == "trees") trees.push_back(o.world_bounds);
    EXPECT_GT(trees.size(), 120u);
    for (std::size_t i = 0; i < trees.size(); ++i) {
        EXPECT_LT(trees[i].extent().x, 5.0f);
        for (std::size_t j = i + 1; j < trees.size(); ++j) EXPECT_FALSE(overlap_xz(trees[i], trees[j])) << i << " " << j;
    }
    expect_same_scene(forest, generate_forest(options));
}

// Toothpicks: 328 polygons (574 triangles) each, closed and wound outward; deterministic; inside
// their cube at every frame; moving and tumbling from frame to frame; the cube twice as wide
// for 1,600 as for 200 with uniform density.
TEST(Generate, ToothpicksTumbleInsideTheirCube) {
    expect_same_scene(generate_scene("toothpicks:seed=3,count=50,frame=7"), generate_scene("toothpicks:seed=3,count=50,frame=7"));
    ToothpickOptions o;
    o.count = 200;
    const Scene first = generate_toothpicks(o, 0), later = generate_toothpicks(o, 40);
    ASSERT_EQ(first.objects.size(), 200u);
    ASSERT_EQ(first.meshes.size(), 1u);
    const Mesh& mesh = first.meshes[0];
    EXPECT_EQ(mesh.triangle_count(), 574u);
    // Closed, with a positive volume (the divergence theorem over its triangles).
    double volume = 0.0;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]), b(mesh.positions[mesh.indices[3 * t + 1]]),
            c(mesh.positions[mesh.indices[3 * t + 2]]);
        volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    EXPECT_NEAR(volume, 4.0, 0.2);  // the unit sphere holds 4.19; 8 stacks of facets cut off a little
    std::vector<std::uint8_t> shared(mesh.triangle_count());
    std::vector<std::uint32_t> apexes(mesh.indices.size());
    compute_shared_edges(&mesh.positions[0].x, sizeof(glm::vec3), mesh.positions.size(), mesh.indices.data(), mesh.triangle_count(),
                         shared.data(), apexes.data());
    EXPECT_TRUE(std::all_of(shared.begin(), shared.end(), [](std::uint8_t s) { return s == 7; }));
    for (int frame : {0, 13, 250, 999}) {
        const Scene s = generate_toothpicks(o, frame);
        for (const Object& t : s.objects)
            for (int k = 0; k < 3; ++k) {
                ASSERT_GE(t.world_bounds.min[k], -0.5f * float(o.cube) - 1e-4f) << "frame " << frame;
                ASSERT_LE(t.world_bounds.max[k], 0.5f * float(o.cube) + 1e-4f) << "frame " << frame;
            }
    }
    int moved = 0;
    for (std::size_t i = 0; i < first.objects.size(); ++i) moved += first.objects[i].world != later.objects[i].world;
    EXPECT_EQ(moved, 200);
    // Uniform density: 1,600 fill a cube twice as wide.
    ToothpickOptions dense = o;
    dense.count = 1600;
    dense.uniform_density = true;
    const Scene many = generate_toothpicks(dense, 0);
    Aabb all;
    for (const Object& t : many.objects) all.extend(t.world_bounds);
    EXPECT_GT(all.max.x - all.min.x, 1.8f * float(o.cube));
    EXPECT_LT(all.max.x - all.min.x, 2.0f * float(o.cube) + 1e-3f);
    EXPECT_THROW(generate_scene("toothpicks:count=0"), Error);
    EXPECT_THROW(generate_scene("toothpicks:density=sparse"), Error);
    EXPECT_THROW(generate_scene("toothpicks:length=20"), Error);
    EXPECT_THROW(generate_toothpicks(o, -1), Error);
}

TEST(Generate, SpecsAreParsedAndCheckedWithClearMessages) {
    const Scene small = generate_scene("city:blocks=2,cars=0");
    std::size_t buildings = 0, cars = 0;
    for (const Object& o : small.objects) {
        buildings += *o.extra("set") == "buildings";
        cars += *o.extra("set") == "cars";
    }
    EXPECT_EQ(buildings, 16u);
    EXPECT_EQ(cars, 0u);
    EXPECT_EQ(generate_scene("city:blocks=2,cars=0,seed=1").source, "gen:city:blocks=2,cars=0,seed=1");
    auto message = [](const char* spec) {
        try {
            generate_scene(spec);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    EXPECT_NE(message("town").find("unknown generated scene 'town'"), std::string::npos);
    EXPECT_NE(message("city:colour=red").find("unknown option 'colour'"), std::string::npos);
    EXPECT_NE(message("city:blocks=two").find("blocks must be a number"), std::string::npos);
    EXPECT_NE(message("city:blocks=0").find("blocks must be in"), std::string::npos);
    EXPECT_NE(message("city:seed=-1").find("seed must be"), std::string::npos);
    EXPECT_NE(message("forest:spacing=1").find("spacing"), std::string::npos);
    EXPECT_NE(message("forest:radius").find("key=value"), std::string::npos);
}

TEST(Generate, GlbRoundTripKeepsObjectsMeshesTransformsAndExtras) {
    const std::string dir = test::temp_dir("GlbRoundTrip");
    for (const char* spec : {"city:seed=3,blocks=3", "forest:seed=8,radius=20"}) {
        const Scene original = generate_scene(spec);
        save_glb(original, dir + "/scene.glb");
        const Scene loaded = load_scene(dir + "/scene.glb");
        expect_same_scene(original, loaded);
    }
}

}  // namespace
}  // namespace homcull
