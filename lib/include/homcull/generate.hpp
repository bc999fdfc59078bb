#pragma once
// Procedural test scenes, deterministic from a seed (splitmix64 and integer arithmetic on
// the random stream, no std:: distributions, no trigonometry), so that a seed gives the same
// scene with every compiler and standard library.
#include <homcull/scene.hpp>

#include <cstdint>
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

// "city", "forest", or either with options: "city:seed=3,blocks=10",
// "forest:seed=2,radius=80,spacing=5,rocks=100". Throws homcull::Error on an unknown name or
// option, or an out-of-range value.
Scene generate_scene(std::string_view spec);

}  // namespace homcull
