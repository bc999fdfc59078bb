// Occluder LOD (homcull/occluder_lod.hpp): simplified occluders may hide less than the meshes
// they replace, never more. The guarantee is checked here by casting rays, independently of
// the build's own containment check: wherever a ray from an eye outside the object's box
// meets the LOD, it meets the original mesh no farther.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/occluder_lod.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/truth/occluder_lod_build.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/world_triangles.hpp>
#include <limits>
#include <map>
#include <random>

#include "support.hpp"

namespace homcull {
namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- Meshes built in code -------------------------------------------------------------------

// The closed surface of a set of unit cells: every face between a filled and an empty cell,
// split into n x n quads (n a power of two, so that positions are exact and weld), CCW
// outward. The cells must meet only face to face, never along an edge alone.
Mesh voxel_surface(const std::vector<glm::ivec3>& cells, int n) {
    auto filled = [&](glm::ivec3 c) { return std::find(cells.begin(), cells.end(), c) != cells.end(); };
    Mesh mesh;
    mesh.name = "voxels";
    for (const glm::ivec3& cell : cells)
        for (int axis = 0; axis < 3; ++axis)
            for (int side : {-1, 1}) {
                glm::ivec3 neighbour = cell;
                neighbour[axis] += side;
                if (filled(neighbour)) continue;
                const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis
                glm::vec3 base(cell);
                base[axis] += side > 0 ? 1.0f : 0.0f;
                for (int i = 0; i < n; ++i)
                    for (int j = 0; j < n; ++j) {
                        auto corner = [&](int di, int dj) {
                            glm::vec3 p = base;
                            p[u] += float(i + di) / float(n);
                            p[v] += float(j + dj) / float(n);
                            mesh.positions.push_back(p);
                            return std::uint32_t(mesh.positions.size() - 1);
                        };
                        const std::uint32_t a = corner(0, 0), b = corner(1, 0), c = corner(1, 1), d = corner(0, 1);
                        if (side > 0)
                            mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
                        else
                            mesh.indices.insert(mesh.indices.end(), {a, c, b, a, d, c});
                    }
            }
    return mesh;
}

// A torus around the z axis, CCW outward (or inward when inside_out).
Mesh torus(int around, int tube, double major, double minor, bool inside_out = false) {
    Mesh mesh;
    mesh.name = inside_out ? "inside-out torus" : "torus";
    for (int i = 0; i < around; ++i)
        for (int j = 0; j < tube; ++j) {
            const double u = 2 * kPi * i / around, v = 2 * kPi * j / tube;
            const double ring = major + minor * std::cos(v);
            mesh.positions.emplace_back(float(ring * std::cos(u)), float(ring * std::sin(u)),
                                        float(minor * std::sin(v)));
        }
    auto at = [&](int i, int j) { return std::uint32_t((i % around) * tube + (j % tube)); };
    for (int i = 0; i < around; ++i)
        for (int j = 0; j < tube; ++j) {
            // d/du x d/dv points inward for this parametrization: (i, j+1) before (i+1, j).
            const std::uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            if (inside_out)
                mesh.indices.insert(mesh.indices.end(), {a, d, c, a, c, b});
            else
                mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
        }
    return mesh;
}

Mesh box(glm::vec3 lo, glm::vec3 hi) {
    Scene scene;
    test::add_box(scene, "box", lo, hi);
    return scene.meshes[0];
}

// A scene of one object placing `mesh` with `world`.
Scene one_object(const Mesh& mesh, const glm::dmat4& world = glm::dmat4(1.0)) {
    Scene scene;
    scene.source = mesh.name;
    scene.meshes.push_back(mesh);
    scene.objects.push_back({mesh.name, 0, world, {}, {}});
    scene.finalize();
    return scene;
}

LodStatus status_of(const Mesh& mesh, const LodOptions& options = {}) {
    const OccluderLods lods = build_occluder_lods(one_object(mesh), {0}, options);
    EXPECT_EQ(lods.lods.size(), lods.status_of_mesh[0] == LodStatus::built ? 1u : 0u);
    return lods.status_of_mesh[0];
}

// ---- The ray check ----------------------------------------------------------------------------

struct RayTally {
    std::uint64_t rays = 0;      // rays cast at both meshes
    std::uint64_t lod_hits = 0;  // of which met the LOD
    std::uint64_t farther = 0;   // of which met the original mesh farther than the LOD, or not at all
};

// From `eyes` random eyes around the object's world box, at 1.05 to 3 times its half diagonal
// from its centre (so outside it), a grid x grid fan of rays spanning the box, and rays at up
// to 512 of the LOD's vertices (`margin`: the LOD's, model units). Each ray is cast
// at the original mesh and at the LOD, both placed by `world` exactly as ground truth places
// them (RayScene). No tolerance: O must be met at t_o <= t_s.
RayTally cast_at_both(const Mesh& original, const Mesh& lod, float margin, const glm::dmat4& world, int eyes, int grid,
                      std::uint64_t seed) {
    const Scene o_scene = one_object(original, world), s_scene = one_object(lod, world);
    const RayScene o_rays(o_scene), s_rays(s_scene, o_rays.anchor());  // rounded alike: their hits are compared
    const Aabb box = o_scene.objects[0].world_bounds;
    const glm::dvec3 centre(box.center());
    const double half_diagonal = 0.5 * glm::length(glm::dvec3(box.extent()));
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> distance(1.05, 3.0);
    RayTally tally;
    for (int e = 0; e < eyes; ++e) {
        const glm::dvec3 away = glm::normalize(glm::dvec3(gauss(rng), gauss(rng), gauss(rng)));
        const glm::dvec3 eye = centre + away * (distance(rng) * half_diagonal);
        const glm::dvec3 helper = std::abs(away.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
        const glm::dvec3 right = glm::normalize(glm::cross(away, helper)), up = glm::cross(right, away);
        for (int i = 0; i < grid; ++i)
            for (int j = 0; j < grid; ++j) {
                const double x = (i + 0.5) / grid * 2 - 1, y = (j + 0.5) / grid * 2 - 1;
                const glm::dvec3 aim = centre + (right * x + up * y) * half_diagonal;
                const glm::vec3 origin(eye), direction(aim - eye);
                const float inf = std::numeric_limits<float>::infinity();
                const RayHit s = s_rays.intersect(origin, direction, 0.0f, inf);
                ++tally.rays;
                if (!s.hit()) continue;
                ++tally.lod_hits;
                const RayHit o = o_rays.intersect(origin, direction, 0.0f, inf);
                tally.farther += !o.hit() || o.t > s.t;
            }
        // And rays near the LOD's vertices, where it comes closest to the original surface. Not
        // at them: a ray exactly through a vertex hits or misses depending on how the ray
        // tracer breaks ties, and the parts the LOD keeps as they were would then disagree
        // with themselves. A random offset of at most half the margin avoids that.
        const std::size_t step = std::max<std::size_t>(1, lod.positions.size() / 512);
        std::uniform_real_distribution<float> offset(-0.5f * margin, 0.5f * margin);
        for (std::size_t v = 0; v < lod.positions.size(); v += step) {
            const glm::vec3 near_vertex = lod.positions[v] + glm::vec3(offset(rng), offset(rng), offset(rng));
            const glm::vec3 origin(eye), direction(glm::dvec3(transform_point(world, near_vertex)) - eye);
            const RayHit s = s_rays.intersect(origin, direction, 0.0f, std::numeric_limits<float>::infinity());
            ++tally.rays;
            if (!s.hit()) continue;
            ++tally.lod_hits;
            const RayHit o = o_rays.intersect(origin, direction, 0.0f, std::numeric_limits<float>::infinity());
            tally.farther += !o.hit() || o.t > s.t;
        }
    }
    return tally;
}

void expect_lod_never_hides_more(const Mesh& original, const OccluderLod& lod,
                                 const glm::dmat4& world = glm::dmat4(1.0)) {
    const RayTally tally = cast_at_both(original, lod.mesh, lod.margin, world, 32, 64, 7);
    EXPECT_GT(tally.lod_hits, 0u) << original.name << ": the rays should meet the LOD";
    EXPECT_EQ(tally.farther, 0u) << original.name << ": rays that meet the LOD nearer than the original mesh, of "
                                 << tally.lod_hits;
}

// ---- Use-time condition -----------------------------------------------------------------------

TEST(OccluderLod, UsableOnlyWhenTheBoxLiesBeyondTheNearPlane) {
    const Camera camera = test::camera_down_minus_z(90.0, 0.5, 100.0);  // eye at 0, looking down -z
    Aabb ahead;
    ahead.extend({-1, -1, -10});
    ahead.extend({1, 1, -5});
    EXPECT_TRUE(lod_usable(ahead, camera));
    Aabb crossing_near = ahead;
    crossing_near.extend({0, 0, -0.4f});
    EXPECT_FALSE(lod_usable(crossing_near, camera));
    Aabb around_eye = ahead;
    around_eye.extend({0, 0, 1});
    EXPECT_FALSE(lod_usable(around_eye, camera));
    Aabb behind;
    behind.extend({-1, -1, 5});
    behind.extend({1, 1, 10});
    EXPECT_FALSE(lod_usable(behind, camera));
    EXPECT_FALSE(lod_usable(Aabb{}, camera));
    Aabb not_a_number = ahead;
    not_a_number.min.x = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(lod_usable(not_a_number, camera));
    // Off to the side and beyond the far plane do not matter: only the near plane cuts O's entry.
    Aabb aside;
    aside.extend({50, 0, -2});
    aside.extend({60, 1, -200});
    EXPECT_TRUE(lod_usable(aside, camera));
}

// ---- What gets an LOD -------------------------------------------------------------------------

TEST(OccluderLod, OpenMeshesGetNone) {
    Scene quad;
    test::add_quad(quad, "quad", {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
    EXPECT_EQ(status_of(quad.meshes[0]), LodStatus::not_closed);

    // A finely split box with its top face missing: big enough to simplify, but open.
    Mesh open_box = voxel_surface({{0, 0, 0}}, 8);
    std::vector<std::uint32_t> kept;
    for (std::size_t t = 0; t < open_box.indices.size(); t += 3) {
        bool top = true;
        for (int k = 0; k < 3; ++k) top = top && open_box.positions[open_box.indices[t + k]].z == 1.0f;
        if (!top)
            kept.insert(kept.end(), open_box.indices.begin() + std::ptrdiff_t(t),
                        open_box.indices.begin() + std::ptrdiff_t(t + 3));
    }
    ASSERT_LT(kept.size(), open_box.indices.size());
    open_box.indices = kept;
    EXPECT_EQ(status_of(open_box), LodStatus::not_closed);

    // Two triangles on the same directed edge (a face doubled) are not closed either.
    Mesh doubled = box({0, 0, 0}, {1, 1, 1});
    doubled.indices.insert(doubled.indices.end(), doubled.indices.begin(), doubled.indices.begin() + 3);
    EXPECT_EQ(status_of(doubled), LodStatus::not_closed);
}

TEST(OccluderLod, ClosedButSmallMeshesGetNone) {
    EXPECT_EQ(status_of(box({0, 0, 0}, {1, 2, 3})), LodStatus::too_small);  // 12 triangles
    const OccluderLods lods = build_occluder_lods(one_object(box({0, 0, 0}, {1, 2, 3})), {0});
    EXPECT_EQ(lods.meshes_considered, 1u);
    EXPECT_EQ(lods.meshes_closed, 1u);
    EXPECT_EQ(lods.meshes_with_lod, 0u);
    EXPECT_EQ(lods.lod_of(0), nullptr);
}

TEST(OccluderLod, DegenerateInputGetsNoneWithoutCrashing) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(status_of(Mesh{"empty", {}, {}}), LodStatus::empty);
    EXPECT_EQ(status_of(Mesh{"only positions", {{0, 0, 0}, {1, 0, 0}}, {}}), LodStatus::empty);

    Mesh not_a_number = voxel_surface({{0, 0, 0}}, 8);
    not_a_number.positions[5].y = nan;
    // Scene::finalize would compute NaN bounds; the builder sees the mesh as it is.
    Scene scene = one_object(voxel_surface({{0, 0, 0}}, 8));
    scene.meshes[0] = not_a_number;
    EXPECT_EQ(build_occluder_lods(scene, {0}).status_of_mesh[0], LodStatus::invalid_geometry);
    scene.meshes[0].positions[5].y = std::numeric_limits<float>::infinity();
    EXPECT_EQ(build_occluder_lods(scene, {0}).status_of_mesh[0], LodStatus::invalid_geometry);
    scene.meshes[0] = voxel_surface({{0, 0, 0}}, 8);
    scene.meshes[0].indices.push_back(0);  // not a whole triangle
    EXPECT_EQ(build_occluder_lods(scene, {0}).status_of_mesh[0], LodStatus::invalid_geometry);
    scene.meshes[0].indices.back() = 1u << 30;
    scene.meshes[0].indices.insert(scene.meshes[0].indices.end(), {0, 1});  // names no vertex
    EXPECT_EQ(build_occluder_lods(scene, {0}).status_of_mesh[0], LodStatus::invalid_geometry);

    // Every vertex in one place; a box squashed flat.
    Mesh point = voxel_surface({{0, 0, 0}}, 8);
    for (glm::vec3& p : point.positions) p = glm::vec3(1.0f);
    EXPECT_EQ(status_of(point), LodStatus::degenerate_triangle);
    Mesh flat = voxel_surface({{0, 0, 0}}, 8);
    for (glm::vec3& p : flat.positions) p.z = 0.0f;
    EXPECT_EQ(status_of(flat), LodStatus::degenerate_triangle);

    // A box whose edge 0-4 has a T-junction on one side (triangle 0, 4, 6 split at the edge's
    // midpoint m), made to count as closed by the sliver (0, 4, m) of three collinear corners.
    Mesh sliver = box({0, 0, 0}, {1, 1, 1});
    const auto m = std::uint32_t(sliver.positions.size());
    sliver.positions.push_back(0.5f * (sliver.positions[0] + sliver.positions[4]));
    ASSERT_EQ((std::vector<std::uint32_t>(sliver.indices.begin(), sliver.indices.begin() + 3)),
              (std::vector<std::uint32_t>{0, 4, 6}));
    sliver.indices.erase(sliver.indices.begin(), sliver.indices.begin() + 3);
    sliver.indices.insert(sliver.indices.end(), {0, m, 6, m, 4, 6, 0, 4, m});
    EXPECT_EQ(status_of(sliver), LodStatus::degenerate_triangle);
}

TEST(OccluderLod, BadOptionsAndIdsThrow) {
    const Scene scene = one_object(torus(32, 16, 1.0, 0.3));
    EXPECT_THROW(build_occluder_lods(scene, {1}), Error);
    LodOptions options;
    options.target_ratio = 0.0;
    EXPECT_THROW(build_occluder_lods(scene, {0}, options), Error);
    options = {};
    options.max_kept_ratio = 1.5;
    EXPECT_THROW(build_occluder_lods(scene, {0}, options), Error);
    options = {};
    options.margin = 0.0;
    EXPECT_THROW(build_occluder_lods(scene, {0}, options), Error);
    options.margin = std::nan("");
    EXPECT_THROW(build_occluder_lods(scene, {0}, options), Error);
    const OccluderLods none = build_occluder_lods(scene, {});
    EXPECT_EQ(none.meshes_considered, 0u);
    EXPECT_EQ(none.status_of_mesh[0], LodStatus::not_requested);

    // A transform that flattens the mesh keeps no solid: no LOD for any object of that mesh.
    Scene flattened = scene;
    flattened.objects.push_back(flattened.objects[0]);
    flattened.objects[1].world = glm::scale(glm::dmat4(1.0), glm::dvec3(1.0, 1.0, 0.0));
    EXPECT_EQ(build_occluder_lods(flattened, {0}).status_of_mesh[0], LodStatus::built);
    EXPECT_EQ(build_occluder_lods(flattened, {0, 1}).status_of_mesh[0], LodStatus::bad_transform);
}

// ---- Closed meshes: built LODs pass the ray check ---------------------------------------------

TEST(OccluderLod, ConcaveClosedMeshesGetNoneOrOneThatNeverHidesMore) {
    const std::vector<Mesh> meshes = {
        voxel_surface({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {2, 1, 0}}, 4),             // a U
        voxel_surface({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 0, 1}, {2, 0, 1}, {2, 0, 2}}, 4),  // stairs
        torus(48, 24, 1.0, 0.4),
        torus(48, 24, 1.0, 0.4, true),
        torus(64, 12, 1.0, 0.05),  // thin: the shrink must not push through the tube
    };
    int built = 0;
    for (const Mesh& mesh : meshes) {
        const OccluderLods lods = build_occluder_lods(one_object(mesh), {0});
        const LodStatus status = lods.status_of_mesh[0];
        std::printf("[ lod      ] %-18s %5zu triangles: %s", mesh.name.c_str(), mesh.triangle_count(),
                    lod_status_name(status));
        if (const OccluderLod* lod = lods.lod_of(0)) {
            ++built;
            std::printf(", %zu triangles", lod->mesh.triangle_count());
            EXPECT_LE(double(lod->mesh.triangle_count()), 0.75 * double(mesh.triangle_count()));
            expect_lod_never_hides_more(mesh, *lod);
            // Placed far from the origin, turned and scaled, as objects are.
            glm::dmat4 world = glm::translate(glm::dmat4(1.0), glm::dvec3(300.0, -20.0, 75.0));
            world = glm::rotate(world, 0.7, glm::dvec3(0.3, 1.0, 0.2));
            world = glm::scale(world, glm::dvec3(2.5, 0.8, 1.3));
            expect_lod_never_hides_more(mesh, *lod, world);
        } else {
            EXPECT_TRUE(status == LodStatus::not_contained || status == LodStatus::not_reduced)
                << lod_status_name(status);
        }
        std::printf("\n");
    }
    EXPECT_GE(built, 3) << "the voxel shapes and the torus should simplify";
}

// A mesh of several parts: each closed part is replaced on its own, the others kept. Two tori
// crossing each other are one solid by union but not by parity; part by part, both simplify.
TEST(OccluderLod, ClosedPartsAreReplacedOneByOne) {
    Mesh mesh = torus(48, 24, 1.0, 0.4);
    const Mesh crossing = torus(48, 24, 1.0, 0.4);
    auto append = [&](const Mesh& part, const glm::dmat4& place) {
        const auto base = std::uint32_t(mesh.positions.size());
        for (const glm::vec3& p : part.positions) mesh.positions.push_back(transform_point(place, p));
        for (std::uint32_t i : part.indices) mesh.indices.push_back(base + i);
    };
    append(crossing,
           glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(1.0, 0.0, 0.0)), kPi / 2, glm::dvec3(1, 0, 0)));
    Scene quad;
    test::add_quad(quad, "quad", {-2, -2, -1}, {2, -2, -1}, {2, 2, -1}, {-2, 2, -1});
    append(quad.meshes[0], glm::dmat4(1.0));                      // open: kept
    append(box({3, 3, 3}, {3.5f, 3.5f, 3.5f}), glm::dmat4(1.0));  // closed, 12 triangles: kept
    mesh.name = "two tori, a quad and a box";

    const OccluderLods lods = build_occluder_lods(one_object(mesh), {0});
    EXPECT_EQ(lods.meshes_closed, 0u) << "the quad is open";
    const OccluderLod* lod = lods.lod_of(0);
    ASSERT_NE(lod, nullptr) << lod_status_name(lods.status_of_mesh[0]);
    EXPECT_EQ(lod->parts_simplified, 2u);
    EXPECT_EQ(lod->parts_kept, 2u);
    EXPECT_LT(lod->mesh.triangle_count(), mesh.triangle_count());
    expect_lod_never_hides_more(mesh, *lod);
}

// Far from the origin, float rounding of the world transform grows; the margin grows with it
// (16 times the rounding bound) and the rays still never meet the LOD first.
TEST(OccluderLod, FarFromTheOriginTheMarginCoversTransformRounding) {
    const Mesh mesh = torus(48, 24, 1.0, 0.4);
    const glm::dmat4 world = glm::translate(glm::dmat4(1.0), glm::dvec3(2.0e4, -1.0e3, 5.0e3));
    Scene scene = one_object(mesh, world);
    const OccluderLods near_origin = build_occluder_lods(one_object(mesh), {0});
    const OccluderLods far = build_occluder_lods(scene, {0});
    ASSERT_NE(near_origin.lod_of(0), nullptr);
    const OccluderLod* lod = far.lod_of(0);
    ASSERT_NE(lod, nullptr) << lod_status_name(far.status_of_mesh[0]);
    const double rounding = std::ldexp(2.0e4 + 1.4, -24);  // half an ulp of the largest coordinate
    EXPECT_GE(double(lod->margin), 16.0 * rounding);
    EXPECT_GT(lod->margin, near_origin.lod_of(0)->margin);
    expect_lod_never_hides_more(mesh, *lod, world);
}

// ---- Shared scenes -----------------------------------------------------------------------------

std::string triangle_line(const std::string& what, const OccluderLods& lods) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "%s: %zu meshes, %zu closed, %zu with an LOD: %zu -> %zu triangles (%.1f %%), %.2f s", what.c_str(),
                  lods.meshes_considered, lods.meshes_closed, lods.meshes_with_lod, lods.triangles_before,
                  lods.triangles_after,
                  lods.triangles_before ? 100.0 * double(lods.triangles_after) / double(lods.triangles_before) : 0.0,
                  lods.build_seconds);
    return line;
}

// The ray check for every mesh that got an LOD, placed as the first given object using it.
void expect_scene_lods_never_hide_more(const Scene& scene, const std::vector<std::uint32_t>& objects,
                                       const OccluderLods& lods, int eyes, int grid) {
    std::map<std::uint32_t, std::uint32_t> object_of_mesh;
    for (std::uint32_t id : objects) object_of_mesh.emplace(scene.objects[id].mesh, id);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> checks(object_of_mesh.begin(), object_of_mesh.end());
    std::vector<RayTally> tallies(checks.size());
    struct Job {
        const Scene& scene;
        const OccluderLods& lods;
        const std::vector<std::pair<std::uint32_t, std::uint32_t>>& checks;
        std::vector<RayTally>& tallies;
        int eyes, grid;
    } job{scene, lods, checks, tallies, eyes, grid};
    const ParallelFor parallel = test::parallel_jobs();
    parallel.run(
        parallel.user, checks.size(),
        [](void* data, std::size_t i) {
            const Job& j = *static_cast<const Job*>(data);
            const auto [mesh, object] = j.checks[i];
            if (const OccluderLod* lod = j.lods.lod_of(mesh))
                j.tallies[i] = cast_at_both(j.scene.meshes[mesh], lod->mesh, lod->margin, j.scene.objects[object].world,
                                            j.eyes, j.grid, mesh);
        },
        &job);
    RayTally total;
    for (std::size_t i = 0; i < checks.size(); ++i) {
        EXPECT_EQ(tallies[i].farther, 0u) << scene.meshes[checks[i].first].name << " (object " << checks[i].second
                                          << "): rays meet the LOD nearer than the mesh, of " << tallies[i].lod_hits;
        total.rays += tallies[i].rays;
        total.lod_hits += tallies[i].lod_hits;
        total.farther += tallies[i].farther;
    }
    std::printf("[ lod      ] ray check: %llu rays, %llu met an LOD, %llu met it nearer than the mesh\n",
                (unsigned long long)total.rays, (unsigned long long)total.lod_hits, (unsigned long long)total.farther);
}

// The scanned bunny has holes in its base: it is open and gets no LOD. The ray check would
// cover it (and any other mesh of the file) if it were closed.
TEST(OccluderLod, BunnyLodNeverHidesMore) {
    const std::string path = test::shared_scene("stanford_bunny.obj");
    if (path.empty()) GTEST_SKIP() << "stanford_bunny.obj is not in " << test::shared_scenes_dir();
    const Scene scene = load_scene(path);
    std::vector<std::uint32_t> all(scene.objects.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = std::uint32_t(i);
    const OccluderLods lods = build_occluder_lods(scene, all);
    const std::string line = triangle_line("bunny", lods);
    std::printf("[ lod      ] %s\n", line.c_str());
    RecordProperty("bunny", line);
    for (std::size_t m = 0; m < scene.meshes.size(); ++m)
        std::printf("[ lod      ]   %s: %zu triangles, %s\n", scene.meshes[m].name.c_str(),
                    scene.meshes[m].triangle_count(), lod_status_name(lods.status_of_mesh[m]));
    expect_scene_lods_never_hide_more(scene, all, lods, 32, 64);
}

TEST(OccluderLod, CastleOccluderLodsNeverHideMore) {
    const std::string path = test::shared_scene("intel_castle.glb");
    if (path.empty()) GTEST_SKIP() << "intel_castle.glb is not in " << test::shared_scenes_dir();
    const Scene scene = load_scene(path);
    const std::vector<std::uint32_t> occluders = objects_with_role(scene, "occluder");
    ASSERT_FALSE(occluders.empty());
    const OccluderLods lods = build_occluder_lods(scene, occluders);
    const std::string line = triangle_line("castle occluders", lods);
    std::printf("[ lod      ] %s\n", line.c_str());
    RecordProperty("castle_occluders", line);
    std::map<std::string, int> reasons;
    for (std::size_t m = 0; m < scene.meshes.size(); ++m)
        if (lods.status_of_mesh[m] != LodStatus::not_requested) ++reasons[lod_status_name(lods.status_of_mesh[m])];
    for (const auto& [reason, count] : reasons) std::printf("[ lod      ]   %-22s %d meshes\n", reason.c_str(), count);
    std::size_t placed_before = 0, placed_after = 0;
    for (std::uint32_t id : occluders) {
        const std::uint32_t mesh = scene.objects[id].mesh;
        placed_before += scene.meshes[mesh].triangle_count();
        const OccluderLod* lod = lods.lod_of(mesh);
        placed_after += lod ? lod->mesh.triangle_count() : scene.meshes[mesh].triangle_count();
    }
    std::printf("[ lod      ] castle occluders as placed: %zu objects, %zu -> %zu triangles\n", occluders.size(),
                placed_before, placed_after);
    EXPECT_GT(lods.meshes_with_lod, 0u);
    expect_scene_lods_never_hide_more(scene, occluders, lods, 32, 64);
    // Only the objects the build was given may use the LODs (their transforms' rounding is
    // what the margins cover), even where another object places the same mesh.
    for (std::uint32_t id = 0; id < scene.objects.size(); ++id) {
        const bool given = std::find(occluders.begin(), occluders.end(), id) != occluders.end();
        const OccluderLod* lod = lods.lod_for(id, scene.objects[id].mesh);
        if (!given) {
            EXPECT_EQ(lod, nullptr) << scene.objects[id].name;
        } else {
            EXPECT_EQ(lod, lods.lod_of(scene.objects[id].mesh)) << scene.objects[id].name;
        }
    }

    // Every mesh of the castle, as a stronger test of the guarantee (the occluders are few).
    const std::vector<std::uint32_t> all = objects_with_role(scene, "");
    const OccluderLods every = build_occluder_lods(scene, all);
    const std::string every_line = triangle_line("castle, every object", every);
    std::printf("[ lod      ] %s\n", every_line.c_str());
    RecordProperty("castle_all", every_line);
    expect_scene_lods_never_hide_more(scene, all, every, 16, 48);
}

}  // namespace
}  // namespace homcull
