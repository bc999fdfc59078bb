// A city of box buildings on a street grid: the classic urban walkthrough of the occlusion
// culling literature (large, well-fused occluders; most of the city hidden from street level).
#include "scene/primitives.hpp"
#include "common/random.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>

#include <string>

namespace homcull {

Scene generate_city(const CityOptions& o) {
    if (o.blocks < 1 || o.blocks > 256) throw Error("city: blocks must be in [1, 256]");
    if (!(o.block_size >= 10.0 && o.block_size <= 1000.0))
        throw Error("city: block size must be in [10, 1000] metres");
    if (!(o.street_width >= 2.0 && o.street_width <= 1000.0))
        throw Error("city: street width must be in [2, 1000] metres");
    if (o.cars_per_block < 0 || o.cars_per_block > 1000)
        throw Error("city: cars per block must be in [0, 1000]");

    detail::SplitMix64 rng(o.seed);
    Scene scene;
    scene.source = "gen:city:seed=" + std::to_string(o.seed);
    scene.meshes.push_back(detail::make_ground_mesh());  // mesh 0
    scene.meshes.push_back(detail::make_box_mesh());     // mesh 1, shared by every box
    const std::uint32_t ground_mesh = 0, box_mesh = 1;

    const double pitch = o.block_size + o.street_width;
    const double half = o.blocks * pitch * 0.5;
    detail::add_object(scene, "ground", ground_mesh, detail::place({0, 0, 0}, {2 * half + 40, 1, 2 * half + 40}),
        "ground", "occluder");

    struct Roof { glm::dvec3 centre; glm::dvec2 size; };
    std::vector<Roof> roofs;
    const double lot = o.block_size * 0.5;
    for (int bz = 0; bz < o.blocks; ++bz)
        for (int bx = 0; bx < o.blocks; ++bx)
            for (int l = 0; l < 4; ++l) {
                const double x0 = -half + 0.5 * o.street_width + bx * pitch + (l & 1) * lot;
                const double z0 = -half + 0.5 * o.street_width + bz * pitch + (l >> 1) * lot;
                // Set-backs of 0.5 to 3 m on each side; heights skewed towards low-rise.
                const double west = rng.uniform(0.5, 3.0), east = rng.uniform(0.5, 3.0);
                const double north = rng.uniform(0.5, 3.0), south = rng.uniform(0.5, 3.0);
                const double u = rng.uniform();
                const double height = 6.0 + 54.0 * u * u;
                const glm::dvec3 size(lot - west - east, height, lot - north - south);
                const glm::dvec3 base(x0 + west + 0.5 * size.x, 0.0, z0 + north + 0.5 * size.z);
                detail::add_object(scene, "building_" + std::to_string(bx) + "_" + std::to_string(bz) + "_" +
                        std::to_string(l),
                    box_mesh, detail::place(base, size), "buildings", "occluder");
                roofs.push_back({base + glm::dvec3(0, height, 0), {size.x, size.z}});
            }

    // Cars parked along the streets, between the blocks and around the city.
    const int cars = o.cars_per_block * o.blocks * o.blocks;
    for (int k = 0; k < cars; ++k) {
        const bool along_x = rng.below(2) == 0;
        const double street = -half + pitch * double(rng.below(std::uint64_t(o.blocks) + 1));
        const double along = rng.uniform(-half + 3.0, half - 3.0);
        const double lane = (rng.below(2) ? 1.0 : -1.0) * 0.25 * o.street_width;
        const glm::dvec3 size = along_x ? glm::dvec3(4.5, 1.5, 1.9) : glm::dvec3(1.9, 1.5, 4.5);
        const glm::dvec3 base = along_x ? glm::dvec3(along, 0, street + lane)
                                        : glm::dvec3(street + lane, 0, along);
        detail::add_object(scene, "car_" + std::to_string(k), box_mesh, detail::place(base, size), "cars", "occludee");
    }

    // Units on about a third of the roofs, seen only from above or from far away.
    int unit = 0;
    for (const Roof& roof : roofs) {
        if (rng.uniform() >= 0.35) continue;
        const glm::dvec3 size(rng.uniform(1.5, 4.0), rng.uniform(1.0, 3.0), rng.uniform(1.5, 4.0));
        const glm::dvec3 offset(rng.uniform(-0.3, 0.3) * (roof.size.x - size.x), 0,
                                rng.uniform(-0.3, 0.3) * (roof.size.y - size.z));
        detail::add_object(scene, "roof_unit_" + std::to_string(unit++), box_mesh,
            detail::place(roof.centre + offset, size), "roof_units", "occludee");
    }
    scene.finalize();
    return scene;
}

}  // namespace homcull
