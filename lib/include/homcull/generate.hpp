#pragma once
// Procedural test scenes, deterministic from a seed (splitmix64 and integer arithmetic on
// the random stream, no std:: distributions, no trigonometry), so that a seed gives the same
// scene with every compiler and standard library.
#include <homcull/scene.hpp>

#include <cstdint>
#include <optional>
#include <string_view>

namespace homcull {

// A city of box buildings on a street grid: `blocks` x `blocks` blocks of 2x2 lots, each lot
// a building (role "occluder"), cars on the streets and units on the roofs (role "occludee"),
// and a ground plane (role "occluder"). Y up, ground at y = 0, metres, centred on the origin.
struct CityOptions {
    std::uint64_t seed = 1;
    int blocks = 6;
    double block_size = 40.0;    // side of a block, metres
    double street_width = 12.0;  // between blocks
    int cars_per_block = 6;
};
Scene generate_city(const CityOptions& options);

// A forest of many small disjoint occluders: trees (trunk and crown, role "occluder") on a
// jittered grid so that no two touch, rocks between them (role "occludee"), and a ground
// plane. This is the case where only the fusion of many occluders hides anything.
struct ForestOptions {
    std::uint64_t seed = 1;
    double radius = 60.0;     // half side of the square forest, metres
    double tree_spacing = 6.0;  // grid cell per tree
    int rocks = 400;
};
Scene generate_forest(const ForestOptions& options);

// Snyder and Lengyel's "toothpicks" (Visibility Sorting and Compositing for Image-Based
// Rendering, 1997), the test of visibility sorting: eccentric ellipsoids of 328 polygons each
// (41 slices by 8 stacks: 574 triangles), tumbling and moving through each other inside a
// cube, frame after frame. Each toothpick keeps a random start (position, orientation), a
// velocity that reflects off the cube's walls, and a tumble (a fixed rotation per frame about
// a random axis), all from the seed. Uniform scale keeps the cube's side at `cube` whatever the
// count; uniform density grows it as the cube root of count / 200, so that 1,600 toothpicks
// fill a cube twice as wide as 200 do (the paper's two runs). Role "occludee", centred on the
// origin, metres. No trigonometry: the mesh and the rotations come from rational
// parametrizations and quaternion products, the same bits with every compiler.
struct ToothpickOptions {
    std::uint64_t seed = 1;
    int count = 200;
    bool uniform_density = false;
    double cube = 10.0;          // side of the cube (uniform density: at 200 toothpicks)
    double length = 2.0;         // the long axis of each ellipsoid
    double thickness = 0.25;     // its two short axes
    double speed = 0.04;         // distance moved per frame, times the cube's side
    double tumble = 0.05;        // rotation per frame, in radians (approximately)
};
Scene generate_toothpicks(const ToothpickOptions& options, int frame = 0);
// Toothpick `index`'s model-to-world transform at `frame` (what generate_toothpicks places
// it with), for moving an already generated scene along frames.
glm::dmat4 toothpick_transform(const ToothpickOptions& options, int index, int frame);
// The options and frame of a "toothpicks:..." spec (with or without "gen:" in front), as
// generate_scene reads them; nullopt for any other scene. Throws homcull::Error as
// generate_scene does on a bad option.
struct ToothpickSpec {
    ToothpickOptions options;
    int frame = 0;
};
std::optional<ToothpickSpec> toothpick_spec(std::string_view spec);

// "city", "forest", "toothpicks", or one with options: "city:seed=3,blocks=10",
// "forest:seed=2,radius=80,spacing=5,rocks=100", "toothpicks:seed=1,count=1600,density=uniform,frame=10"
// (density: uniform or scale, the default). Throws homcull::Error on an unknown name or
// option, or an out-of-range value.
Scene generate_scene(std::string_view spec);

}  // namespace homcull
