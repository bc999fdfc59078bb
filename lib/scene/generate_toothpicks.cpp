// Snyder and Lengyel's toothpicks (homcull/generate.hpp): ellipsoids tumbling through each
// other in a cube. Deterministic from the seed with IEEE operations alone (no libm call).
#include <homcull/error.hpp>
#include <homcull/generate.hpp>

#include "common/random.hpp"
#include "scene/primitives.hpp"

#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <string>

namespace homcull {
namespace {

constexpr int kSlices = 41, kStacks = 8;  // 41 x 8 = 328 polygons, as in the paper

// cos and sin of k pi / 8, k = 0..8, written out so that no libm call enters the scene.
constexpr double kStackCos[kStacks + 1] = {1.0, 0.9238795325112867, 0.7071067811865476, 0.3826834323650898, 0.0,
                                           -0.3826834323650898, -0.7071067811865476, -0.9238795325112867, -1.0};
constexpr double kStackSin[kStacks + 1] = {0.0, 0.3826834323650898, 0.7071067811865476, 0.9238795325112867, 1.0,
                                           0.9238795325112867, 0.7071067811865476, 0.3826834323650898, 0.0};

// The unit sphere as 41 slices by 8 stacks: a vertex at each pole, 7 rings of 41 between,
// triangles at the caps and quads (two triangles) between rings, counter-clockwise outward.
// The slices step by a rational rotation ((1 - u^2, 2u) / (1 + u^2), u = tan(pi / 41)).
Mesh unit_sphere() {
    Mesh m;
    m.name = "toothpick";
    double slice_cos[kSlices], slice_sin[kSlices];
    const double u = 0.07676979661624596;  // tan(pi / 41)
    const double step_cos = (1.0 - u * u) / (1.0 + u * u), step_sin = 2.0 * u / (1.0 + u * u);
    slice_cos[0] = 1.0, slice_sin[0] = 0.0;
    for (int k = 1; k < kSlices; ++k) {
        slice_cos[k] = slice_cos[k - 1] * step_cos - slice_sin[k - 1] * step_sin;
        slice_sin[k] = slice_sin[k - 1] * step_cos + slice_cos[k - 1] * step_sin;
    }
    m.positions.emplace_back(0.0f, 1.0f, 0.0f);  // north pole, then the rings from the north
    for (int i = 1; i < kStacks; ++i)
        for (int k = 0; k < kSlices; ++k)
            m.positions.emplace_back(float(kStackSin[i] * slice_cos[k]), float(kStackCos[i]), float(kStackSin[i] * slice_sin[k]));
    m.positions.emplace_back(0.0f, -1.0f, 0.0f);
    const auto ring = [](int i, int k) { return std::uint32_t(1 + (i - 1) * kSlices + (k % kSlices)); };
    const auto south = std::uint32_t(m.positions.size() - 1);
    // Seen from outside, a slice's angle grows clockwise about +y (x towards z): the outward
    // counter-clockwise order goes from slice k + 1 to slice k.
    for (int k = 0; k < kSlices; ++k) {
        m.indices.insert(m.indices.end(), {0, ring(1, k + 1), ring(1, k)});
        for (int i = 1; i + 1 < kStacks; ++i)
            m.indices.insert(m.indices.end(), {ring(i, k), ring(i, k + 1), ring(i + 1, k + 1), ring(i, k), ring(i + 1, k + 1), ring(i + 1, k)});
        m.indices.insert(m.indices.end(), {south, ring(kStacks - 1, k), ring(kStacks - 1, k + 1)});
    }
    return m;
}

// The cube root by Newton's iteration (no libm call): a in [1e-6, 1e6].
double cube_root(double a) {
    double x = a < 1.0 ? 1.0 : a / 3.0 + 1.0;
    for (int k = 0; k < 100; ++k) x -= (x * x * x - a) / (3.0 * x * x);
    return x;
}

// A point uniform in the unit ball, by rejection from the cube.
glm::dvec3 in_ball(detail::SplitMix64& rng) {
    for (;;) {
        const glm::dvec3 p(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
        const double r2 = glm::dot(p, p);
        if (r2 <= 1.0 && r2 > 1e-6) return p;
    }
}

glm::dvec3 unit_vector(detail::SplitMix64& rng) {
    const glm::dvec3 p = in_ball(rng);
    return p / std::sqrt(glm::dot(p, p));
}

// Reflects x back and forth inside [-h, h] (a triangle wave of period 4h).
double fold(double x, double h) {
    const double period = 4.0 * h;
    const double m = (x + h) - period * std::floor((x + h) / period);
    return (m > 2.0 * h ? period - m : m) - h;
}

glm::dquat power(glm::dquat q, int n) {
    glm::dquat result(1.0, 0.0, 0.0, 0.0);
    for (; n > 0; n >>= 1) {
        if (n & 1) result = result * q;
        q = q * q;
    }
    return result;
}

double cube_side(const ToothpickOptions& o) { return o.uniform_density ? o.cube * cube_root(double(o.count) / 200.0) : o.cube; }

void validate(const ToothpickOptions& o) {
    if (o.count < 1 || o.count > 1000000) throw Error("toothpicks: count must be 1 to 1000000, got " + std::to_string(o.count));
    if (!(o.cube > 0.0 && o.cube < 1e6) || !(o.length > 0.0) || !(o.thickness > 0.0) || o.length >= cube_side(o))
        throw Error("toothpicks: cube, length and thickness must be positive, the length below the cube's side");
    if (!(o.speed >= 0.0 && o.speed <= 1.0) || !(o.tumble >= 0.0 && o.tumble <= 1.0))
        throw Error("toothpicks: speed and tumble must be in [0, 1]");
}

}  // namespace

glm::dmat4 toothpick_transform(const ToothpickOptions& o, int index, int frame) {
    validate(o);
    if (index < 0 || index >= o.count || frame < 0) throw Error("toothpicks: index or frame out of range");
    const double side = cube_side(o), h = 0.5 * (side - o.length);  // centres stay a half length inside
    // Each toothpick's own stream: its start, velocity and tumble.
    detail::SplitMix64 rng(o.seed * 0x9E3779B97F4A7C15ull + std::uint64_t(index) * 0xD1B54A32D192ED03ull + 1);
    const glm::dvec3 start(rng.uniform(-h, h), rng.uniform(-h, h), rng.uniform(-h, h));
    const glm::dvec3 velocity = unit_vector(rng) * (o.speed * side);
    glm::dquat orientation(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    orientation = orientation * (1.0 / std::sqrt(glm::dot(orientation, orientation) + 1e-300));
    // A rotation of about `tumble` radians about a random axis: (1, axis tan(tumble / 2)) with
    // tan(a) ~ a, normalized.
    const glm::dvec3 axis = unit_vector(rng) * (0.5 * o.tumble);
    glm::dquat step(1.0, axis.x, axis.y, axis.z);
    step = step * (1.0 / std::sqrt(glm::dot(step, step)));
    glm::dquat q = power(step, frame) * orientation;
    q = q * (1.0 / std::sqrt(glm::dot(q, q)));
    const glm::dvec3 moved = start + velocity * double(frame);
    const glm::dvec3 position(fold(moved.x, h), fold(moved.y, h), fold(moved.z, h));
    // The unit sphere's y axis becomes the long one.
    const glm::dmat4 scale = glm::dmat4(glm::dvec4(0.5 * o.thickness, 0, 0, 0), glm::dvec4(0, 0.5 * o.length, 0, 0),
                                        glm::dvec4(0, 0, 0.5 * o.thickness, 0), glm::dvec4(0, 0, 0, 1));
    glm::dmat4 world = glm::dmat4(glm::mat3_cast(q)) * scale;
    world[3] = glm::dvec4(position, 1.0);
    return world;
}

Scene generate_toothpicks(const ToothpickOptions& o, int frame) {
    validate(o);
    if (frame < 0) throw Error("toothpicks: the frame must be 0 or more");
    Scene scene;
    scene.source = "gen:toothpicks:seed=" + std::to_string(o.seed);
    scene.meshes.push_back(unit_sphere());
    for (int i = 0; i < o.count; ++i)
        detail::add_object(scene, "toothpick_" + std::to_string(i), 0, toothpick_transform(o, i, frame), "toothpicks", "occludee");
    scene.finalize();
    return scene;
}

}  // namespace homcull
