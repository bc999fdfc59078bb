// The visibility sort (homcull/visibility_sort.hpp): hand-built cycles, the incremental sort
// against sorts from scratch, and every layer order checked against the occlusion edges of
// Embree's every-hit rays (homcull/truth/sort_truth.hpp) on toothpicks and the shared scenes.
#include "support.hpp"

#include "common/isa_choice.hpp"
#include "sort/extent_tree.hpp"
#include "sort/hull_occlusion.hpp"
#include "sort/image_outline.hpp"
#include "sort/pair_cache.hpp"
#include "sort/support_scan.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/isa.hpp>
#include <homcull/scene_sort.hpp>
#include <homcull/truth/bsp_painter.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/truth/sort_truth.hpp>
#include <homcull/truth/walk_path.hpp>
#include <homcull/visibility_sort.hpp>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

namespace homcull {
namespace {

// Each object's layer in a sort (kUnsorted for those left out).
std::vector<std::uint32_t> layer_of(const VisibilitySort& sort, std::size_t objects) {
    std::vector<std::uint32_t> layer(objects, kUnsorted);
    for (std::uint32_t l = 0; l < sort.layers.size(); ++l)
        for (std::uint32_t k = 0; k < sort.layers[l].count; ++k) layer[sort.order[sort.layers[l].first + k]] = l;
    return layer;
}

// The layers as sets, for comparing sorts whose orders may differ.
std::set<std::vector<std::uint32_t>> layer_sets(const VisibilitySort& sort) {
    std::set<std::vector<std::uint32_t>> sets;
    for (const SortLayer& l : sort.layers) sets.emplace(sort.order.begin() + l.first, sort.order.begin() + l.first + l.count);
    return sets;
}

// Every pair the sort found occluding has its occluder's layer no later than its occluded's.
void expect_pairs_respected(const VisibilitySort& sort, std::size_t objects) {
    const std::vector<std::uint32_t> layer = layer_of(sort, objects);
    for (const OcclusionPair& p : sort.pairs) EXPECT_LE(layer[p.occluder], layer[p.occluded]) << p.occluder << " -> " << p.occluded;
}

// The sort's frame for a camera over a scene placed relative to `origin`: the eye and the
// view frustum's planes, moved to that origin.
struct CameraFrame {
    std::vector<glm::mat4> transforms;
    std::array<glm::vec4, 6> planes;
    SortFrame frame;

    CameraFrame(const Scene& scene, const Camera& camera, Resolution display, const glm::dvec3& origin) {
        sort_transforms(scene, origin, transforms);
        planes = sort_frustum_planes(camera, double(display.width) / double(display.height), origin);
        frame.transforms = transforms.data();
        frame.eye = glm::vec3(camera.eye - origin);
        frame.planes = planes.data();
        frame.plane_count = 6;
    }
};

struct Tally {
    std::size_t frames = 0, edges = 0, violations = 0, grouped = 0, needless = 0, objects_in_cycles = 0, sorted = 0,
                needlessly_grouped = 0, largest = 0;
    void add(const SortCheck& check, const VisibilitySort& sort, std::size_t edge_count) {
        ++frames;
        edges += edge_count;
        violations += check.violations;
        grouped += check.grouped_layers;
        needless += check.needless_layers;
        objects_in_cycles += sort.stats.objects_in_cycles;
        needlessly_grouped += check.needlessly_grouped;
        largest = std::max<std::size_t>(largest, sort.stats.largest_cycle);
        sorted += sort.stats.sorted;
    }
    void report(const char* what) const {
        std::printf("[ sorting  ] %s: %zu frames, %zu true edges, %zu violations, %zu grouped layers (%zu needless, largest %zu), "
                    "%.1f %% of the sorted objects in them, %.1f %% in none of their true cycles\n",
                    what, frames, edges, violations, grouped, needless, largest,
                    sorted ? 100.0 * double(objects_in_cycles) / double(sorted) : 0.0,
                    sorted ? 100.0 * double(needlessly_grouped) / double(sorted) : 0.0);
    }
};

// Sorts the scene from the camera and checks it against Embree's edges.
void check_view(VisibilitySorter& sorter, const Scene& scene, const RayScene& rays, const Camera& camera, Resolution display,
                Tally& tally) {
    const glm::dvec3 origin = scene_anchor(scene);
    CameraFrame f(scene, camera, display, origin);
    const VisibilitySort& sort = sorter.sort(f.frame);
    const SortTruth truth = occlusion_edges(rays, scene.objects.size(), camera, display);
    const SortCheck check = check_sort(truth, layer_of(sort, scene.objects.size()));
    EXPECT_EQ(check.violations, 0u) << scene.source << " from " << camera.eye.x << "," << camera.eye.y << "," << camera.eye.z;
    for (const OcclusionEdge& e : check.violating) ADD_FAILURE() << "violated: " << e.front << " -> " << e.back << " (" << e.rays << " rays)";
    EXPECT_EQ(check.unsorted_edges, 0u) << "an object the frustum planes left out was seen";
    expect_pairs_respected(sort, scene.objects.size());
    tally.add(check, sort, truth.edges.size());
}

// A thin straight stick as a box mesh from a to b, `half` thick across, its own object.
std::uint32_t add_stick(Scene& scene, const std::string& name, glm::vec3 a, glm::vec3 b, float half) {
    const glm::vec3 along = glm::normalize(b - a);
    const glm::vec3 across = glm::normalize(glm::cross(along, glm::vec3(0, 0, 1))) * half;
    const glm::vec3 up = glm::normalize(glm::cross(across, along)) * half;
    Mesh mesh;
    mesh.name = name;
    for (int k = 0; k < 8; ++k)
        mesh.positions.push_back(((k & 1) ? b : a) + ((k & 2) ? across : -across) + ((k & 4) ? up : -up));
    mesh.indices = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    return test::add_object_with_own_mesh(scene, std::move(mesh));
}

TEST(ConvexHull, KeepsTheCornersAndDropsWhatIsInside) {
    std::vector<glm::vec3> points;
    for (int k = 0; k < 8; ++k) points.emplace_back((k & 1) ? 1.f : -1.f, (k & 2) ? 2.f : -2.f, (k & 4) ? 3.f : -3.f);
    // Inside points, points on faces and edges, and duplicates.
    for (int k = 0; k < 50; ++k) points.emplace_back(0.03f * float(k) - 0.7f, 0.05f * float(k % 7), -2.5f + 0.1f * float(k));
    points.emplace_back(1.f, 0.f, 0.f), points.emplace_back(1.f, 2.f, 0.f), points.push_back(points[3]);
    const auto hull = convex_hull_points(points.data(), points.size());
    ASSERT_EQ(hull.size(), 8u);
    for (int k = 0; k < 8; ++k) EXPECT_EQ(hull[std::size_t(k)], points[std::size_t(k)]);  // in first-seen order

    // A toothpick's ellipsoid is convex: every vertex is on its hull.
    const Scene toothpicks = generate_toothpicks(ToothpickOptions{}, 0);
    const Mesh& mesh = toothpicks.meshes[0];
    EXPECT_EQ(convex_hull_points(mesh.positions.data(), mesh.positions.size()).size(), mesh.positions.size());

    // Flat and tiny sets come back whole, without duplicates; a NaN is an error.
    const std::vector<glm::vec3> flat = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5f, 0.5f, 0}, {1, 0, 0}};
    EXPECT_EQ(convex_hull_points(flat.data(), flat.size()).size(), 5u);
    const std::vector<glm::vec3> bad = {{0, 0, 0}, {1, std::nanf(""), 0}};
    EXPECT_THROW(convex_hull_points(bad.data(), bad.size()), Error);
    EXPECT_TRUE(convex_hull_points(nullptr, 0).empty());
}

// A hull of at most N points holds every point: along 500 directions its support reaches at
// least as far as the points' (a hull holds a point when no direction separates them). The
// same points in another order give the same hull.
TEST(ConvexHull, LimitedHullsHoldEveryPoint) {
    std::vector<glm::vec3> points;
    std::uint64_t state = 7;
    const auto uniform = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return float(double(state >> 11) / 9007199254740992.0) * 2.0f - 1.0f;
    };
    for (int k = 0; k < 3000; ++k) {  // a long, thin, lumpy ellipsoid's surface, off the origin
        glm::vec3 d(uniform(), uniform(), uniform());
        d = glm::normalize(d) * (1.0f + 0.05f * uniform());
        points.push_back(glm::vec3(100.0f, -40.0f, 7.0f) + d * glm::vec3(4.0f, 0.3f, 0.5f));
    }
    const auto exact = convex_hull_points(points.data(), points.size());
    for (const std::size_t limit : {std::size_t(8), std::size_t(16), std::size_t(64)}) {
        const auto limited = convex_hull_points(points.data(), points.size(), limit);
        ASSERT_LE(limited.size(), limit);
        ASSERT_LT(limited.size(), exact.size());
        float worst = 0.0f;  // how much farther the limited hull reaches, at most
        for (int k = 0; k < 500; ++k) {
            const glm::vec3 d = glm::normalize(glm::vec3(uniform(), uniform(), uniform()));
            float reach = -1e30f, held = -1e30f;
            for (const glm::vec3& p : points) reach = std::max(reach, glm::dot(p, d));
            for (const glm::vec3& p : limited) held = std::max(held, glm::dot(p, d));
            EXPECT_GE(held, reach) << limit << " points";
            worst = std::max(worst, held - reach);
        }
        EXPECT_LT(worst, limit >= 64 ? 0.5f : 4.0f) << limit << " points: grown too much, " << worst;  // of a length of 8
        std::vector<glm::vec3> reversed(points.rbegin(), points.rend());
        const auto again = convex_hull_points(reversed.data(), reversed.size(), limit);
        EXPECT_EQ(std::vector<glm::vec3>(again.begin(), again.end()), std::vector<glm::vec3>(limited.begin(), limited.end()));
    }
}

// Three sticks in a triangle, each over the next where they cross (the classic cycle of three
// pencils): no two of them form a cycle, yet no order of the three is right. One layer.
TEST(VisibilitySort, ThreeOverlappingSticksAreOneLayer) {
    Scene scene;
    const double pi = 3.14159265358979323846;
    glm::vec3 corner[3];
    for (int i = 0; i < 3; ++i) corner[i] = glm::vec3(3.0 * std::cos(2 * pi * i / 3), 3.0 * std::sin(2 * pi * i / 3), 0.0);
    for (int i = 0; i < 3; ++i) {
        const glm::vec3 a = corner[i], b = corner[(i + 1) % 3], along = glm::normalize(b - a);
        // Far at its start, near at its end: over the next stick, under the one before.
        add_stick(scene, "stick" + std::to_string(i), a - along + glm::vec3(0, 0, -6.0f), b + along + glm::vec3(0, 0, -4.0f), 0.1f);
    }
    // A box in front of the first stick's middle (seen from the origin), and one behind them all.
    test::add_box(scene, "front", {0.2f, 0.45f, -2.5f}, {0.5f, 0.75f, -2.0f});
    test::add_box(scene, "back", {-8, -8, -12}, {8, 8, -11});

    VisibilitySorter sorter = make_visibility_sorter(scene);
    CameraFrame f(scene, test::camera_down_minus_z(), {96, 96}, glm::dvec3(0.0));
    const VisibilitySort& sort = sorter.sort(f.frame);
    ASSERT_EQ(sort.layers.size(), 3u);
    EXPECT_EQ(std::vector<std::uint32_t>(sort.order.begin(), sort.order.end()), (std::vector<std::uint32_t>{3, 0, 1, 2, 4}));
    EXPECT_EQ(sort.layers[1].count, 3u);
    EXPECT_EQ(sort.stats.cycles, 1u);
    EXPECT_EQ(sort.stats.objects_in_cycles, 3u);
    EXPECT_EQ(sort.stats.core_crossings, 3u);  // each stick's core crosses the next one's seen from the eye
    EXPECT_EQ(sort.stats.left_out, 0u);
    expect_pairs_respected(sort, scene.objects.size());

    // Embree agrees: the three edges of the cycle are true, and the layer is needed.
    const RayScene rays(scene);
    const SortTruth truth = occlusion_edges(rays, scene.objects.size(), test::camera_down_minus_z(), {96, 96});
    const SortCheck check = check_sort(truth, layer_of(sort, scene.objects.size()));
    EXPECT_EQ(check.violations, 0u);
    EXPECT_EQ(check.grouped_layers, 1u);
    EXPECT_EQ(check.needless_layers, 0u);
    for (std::uint32_t stick = 0; stick < 3; ++stick)
        EXPECT_TRUE(std::any_of(truth.edges.begin(), truth.edges.end(),
                                [&](const OcclusionEdge& e) { return e.front == stick && e.back == (stick + 1) % 3; }));
}

// Two interlocked objects (each in front of the other somewhere) are one layer, between what
// lies in front of them and what lies behind.
TEST(VisibilitySort, InterlockedPairIsOneLayer) {
    Scene scene;
    test::add_interlocked_pair(scene);
    test::add_box(scene, "front", {-1, -1, -1.5f}, {1, 1, -1});
    test::add_box(scene, "back", {-60, -60, -9}, {60, 60, -8});
    VisibilitySorter sorter = make_visibility_sorter(scene);
    CameraFrame f(scene, test::camera_down_minus_z(), {64, 64}, glm::dvec3(0.0));
    const VisibilitySort& sort = sorter.sort(f.frame);
    ASSERT_EQ(sort.layers.size(), 3u);
    EXPECT_EQ(std::vector<std::uint32_t>(sort.order.begin(), sort.order.end()), (std::vector<std::uint32_t>{2, 0, 1, 3}));
    EXPECT_EQ(sort.layers[1].count, 2u);

    // Turned around (the eye behind everything, looking up +z), the order reverses.
    Camera behind = test::camera_down_minus_z();
    behind.eye = {0, 0, -20};
    behind.target = {0, 0, 0};
    CameraFrame g(scene, behind, {64, 64}, glm::dvec3(0.0));
    const VisibilitySort& reversed = sorter.sort(g.frame);
    EXPECT_EQ(std::vector<std::uint32_t>(reversed.order.begin(), reversed.order.end()), (std::vector<std::uint32_t>{3, 0, 1, 2}));
}

TEST(VisibilitySort, BadInputIsAnErrorOrLeftOut) {
    Scene scene;
    test::add_box(scene, "a", {-1, -1, -4}, {1, 1, -2});
    test::add_box(scene, "b", {-1, -1, -8}, {1, 1, -6});
    EXPECT_THROW(VisibilitySorter({{glm::vec3(0.0f)}}, {1}), Error);  // shape out of range
    EXPECT_THROW(VisibilitySorter({{}}, {0}), Error);                  // an empty shape
    VisibilitySorter sorter = make_visibility_sorter(scene);
    SortFrame frame;
    EXPECT_THROW(sorter.sort(frame), Error);  // no transforms
    std::vector<glm::mat4> transforms(2, glm::mat4(1.0f));
    frame.transforms = transforms.data();
    std::vector<glm::vec4> planes(17, glm::vec4(0, 0, 1, 0));
    frame.planes = planes.data();
    frame.plane_count = planes.size();
    EXPECT_THROW(sorter.sort(frame), Error);  // too many planes
    frame.plane_count = 0;
    transforms[1][3][0] = std::nanf("");  // a NaN translation: that object is left out
    const VisibilitySort& sort = sorter.sort(frame);
    EXPECT_EQ(sort.stats.sorted, 1u);
    EXPECT_EQ(sort.stats.left_out, 1u);
    frame.eye = glm::vec3(std::nanf(""));
    EXPECT_EQ(sorter.sort(frame).stats.sorted, 0u);
}

// The toothpicks tumbling frame after frame: the incremental sort gives the same layers as a
// sort from scratch every frame, both respect every occlusion they found, and Embree finds no
// true edge that either order breaks.
TEST(VisibilitySort, IncrementalSortsAgreeWithSortsFromScratchOnToothpicks) {
    ToothpickOptions options;
    options.count = 200;
    Scene scene = generate_toothpicks(options, 0);
    VisibilitySorter incremental = make_visibility_sorter(scene), scratch = make_visibility_sorter(scene);
    Camera camera;
    camera.eye = {0.0, 4.0, 24.0};
    camera.target = {0.0, 0.0, 0.0};
    camera.fov_y_degrees = 40.0;
    const Resolution display{200, 150};
    Tally tally;
    std::size_t kept = 0, cycles = 0;
    for (int frame = 0; frame < 12; ++frame) {
        for (std::size_t i = 0; i < scene.objects.size(); ++i) scene.objects[i].world = toothpick_transform(options, int(i), frame);
        scene.finalize();
        CameraFrame f(scene, camera, display, glm::dvec3(0.0));
        const VisibilitySort& a = incremental.sort(f.frame);
        f.frame.incremental = false;
        const VisibilitySort& b = scratch.sort(f.frame);
        EXPECT_EQ(layer_sets(a), layer_sets(b)) << "frame " << frame;
        expect_pairs_respected(a, scene.objects.size());
        expect_pairs_respected(b, scene.objects.size());
        kept += a.stats.kept_last_order;
        cycles += a.stats.cycles;
        if (frame % 4 == 0) {
            const RayScene rays(scene);
            const SortTruth truth = occlusion_edges(rays, scene.objects.size(), camera, display);
            for (const VisibilitySort* s : {&a, &b}) {
                const SortCheck check = check_sort(truth, layer_of(*s, scene.objects.size()));
                EXPECT_EQ(check.violations, 0u) << "frame " << frame;
                tally.add(check, *s, truth.edges.size());
            }
        }
    }
    tally.report("toothpicks, 200");
    EXPECT_GT(cycles, 0u);  // toothpicks pass through each other: there are cycles to find
}

// What a sorter remembers about still objects (their hulls' contact) gives the layers of a
// sort that remembers nothing: toothpicks that move, stop for a few frames, and move again; and
// a walk through the castle, whose objects never move.
TEST(VisibilitySort, RememberedContactsGiveTheLayersOfAFreshSort) {
    ToothpickOptions options;
    options.count = 200;
    Scene scene = generate_toothpicks(options, 0);
    VisibilitySorter remembering = make_visibility_sorter(scene), fresh = make_visibility_sorter(scene);
    std::uint64_t remembered = 0;
    for (const int frame : {0, 1, 2, 2, 2, 3, 3, 4, 5, 5, 5, 5}) {
        std::vector<glm::mat4> transforms(scene.objects.size());
        for (int i = 0; i < options.count; ++i) transforms[std::size_t(i)] = glm::mat4(toothpick_transform(options, i, frame));
        SortFrame f;
        f.transforms = transforms.data();
        f.eye = {1.0f, 4.0f, 24.0f};
        const VisibilitySort& a = remembering.sort(f);
        remembered += a.stats.remembered;
        fresh.forget_order();
        EXPECT_EQ(layer_sets(a), layer_sets(fresh.sort(f))) << "frame " << frame;
    }
    EXPECT_GT(remembered, 0u);

    const std::string castle_file = test::shared_scene("intel_castle.glb");
    if (castle_file.empty()) return;
    const Scene castle = load_scene(castle_file);
    const RayScene rays(castle);
    WalkOptions walk;
    walk.frames = 12;
    const CameraPath path = walk_path(rays, castle, walk);
    VisibilitySorter walking = make_visibility_sorter(castle), again = make_visibility_sorter(castle);
    remembered = 0;
    for (const Camera& camera : path.frames) {
        CameraFrame f(castle, camera, {640, 360}, scene_anchor(castle));
        const VisibilitySort& a = walking.sort(f.frame);
        remembered += a.stats.remembered;
        again.forget_order();
        EXPECT_EQ(layer_sets(a), layer_sets(again.sort(f.frame)));
    }
    EXPECT_GT(remembered, 0u);
}

// The support scan's kernels give the reference's answer (the first point of the largest dot
// product) for every count, with ties and repeated points.
TEST(VisibilitySort, SupportScanKernelsGiveTheReferenceAnswer) {
    std::uint64_t state = 11;
    const auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return std::int32_t(state >> 59) - 16;  // small integers: many ties
    };
    for (const std::string& isa : available_isas()) {
        const sort_detail::SupportScan scan = sort_detail::support_scan_for(detail::isa_choice(isa));
        for (std::uint32_t count = 1; count < 300; count += count < 40 ? 1 : 37) {
            std::vector<float> x(count), y(count), z(count);
            for (std::uint32_t i = 0; i < count; ++i) x[i] = float(next()), y[i] = float(next()), z[i] = float(next());
            for (int trial = 0; trial < 20; ++trial) {
                const float dx = float(next()) * 0.5f, dy = float(next()), dz = float(next()) * 0.25f;
                EXPECT_EQ(scan(x.data(), y.data(), z.data(), count, dx, dy, dz),
                          sort_detail::support_scan_reference(x.data(), y.data(), z.data(), count, dx, dy, dz))
                    << isa << ", " << count << " points";
            }
        }
    }
}

// A hint moves where GJK starts, never what it answers: toothpicks tumbling frame after frame,
// each ordered pair tested with its own hint (carried from frame to frame) and without, from
// an eye outside the cube. Testing a frame twice shows what the hint keeps: an apart pair
// settles in one step, and a pair whose GJK ended enclosing the origin in none.
TEST(VisibilitySort, GjkHintsChangeTheStepsNotTheAnswers) {
    ToothpickOptions options;
    options.count = 40;
    options.cube = 4.0;  // crowded: many pairs meet
    const Scene scene = generate_toothpicks(options, 0);
    const Mesh& mesh = scene.meshes[scene.objects[0].mesh];
    const detail::Vector<glm::vec3> hull = convex_hull_points(mesh.positions.data(), mesh.positions.size());
    std::vector<float> x, y, z;
    for (const glm::vec3& p : hull) x.push_back(p.x), y.push_back(p.y), z.push_back(p.z);
    const std::size_t n = std::size_t(options.count);
    std::vector<sort_detail::GjkHint> hints(n * n);
    const glm::dvec3 eye(0.5, 1.0, 9.0);
    std::size_t apart = 0, meet = 0, steps_with = 0, steps_without = 0;
    for (int frame = 0; frame < 8; ++frame) {
        std::vector<sort_detail::PlacedHull> placed(n);
        for (std::size_t i = 0; i < n; ++i) {
            sort_detail::PlacedHull& h = placed[i];
            h.x = x.data(), h.y = y.data(), h.z = z.data(), h.count = std::uint32_t(x.size());
            h.transform = glm::mat4(toothpick_transform(options, int(i), frame));
        }
        for (std::size_t f = 0; f < n; ++f) {
            for (std::size_t b = 0; b < n; ++b) {
                if (f == b) continue;
                const glm::dvec3 start = glm::dvec3(placed[f].transform[3]) - glm::dvec3(placed[b].transform[3]);
                sort_detail::GjkWork cold, warm, again;
                sort_detail::GjkHint& hint = hints[f * n + b];
                const bool answer = sort_detail::may_occlude(placed[f], placed[b], eye, 1e-5, start, nullptr, &cold);
                ASSERT_EQ(sort_detail::may_occlude(placed[f], placed[b], eye, 1e-5, start, &hint, &warm), answer)
                    << "frame " << frame << ", " << f << " over " << b;
                steps_with += warm.iterations, steps_without += cold.iterations;
                const bool enclosed = hint.corners == 4;
                ASSERT_EQ(sort_detail::may_occlude(placed[f], placed[b], eye, 1e-5, start, &hint, &again), answer);
                if (!answer) {
                    EXPECT_EQ(again.iterations, 1u);
                    ++apart;
                }
                if (enclosed) {
                    EXPECT_EQ(again.iterations, 0u);
                    ++meet;
                }
                EXPECT_EQ(again.scans, 2 * again.iterations);
            }
        }
    }
    EXPECT_GT(apart, 1000u);
    EXPECT_GT(meet, 100u);
    EXPECT_LT(steps_with, steps_without);
    std::printf("[ stats    ] GJK steps over 8 frames: %zu with hints, %zu without\n", steps_with, steps_without);
}

// Outlines on screen: two parallel thin diagonal sticks, whose bounding rectangles overlap, are
// parted by a line along them; moved together until their gap is within the pads, or crossed,
// they are not.
TEST(VisibilitySort, OutlinesOfThinSticksSideBySideAreApart) {
    // A stick from (0, 0) to (1, 1), 0.02 wide, as a flat box's corners (the third axis: none).
    const auto stick = [](glm::vec2 from, glm::vec2 to, float pad) {
        sort_detail::ImageOutline o;
        const glm::vec2 along = to - from, side = 0.01f * glm::normalize(glm::vec2(-along.y, along.x));
        for (int c = 0; c < 8; ++c) o.corners[c] = ((c & 1) ? to : from) + ((c & 2) ? side : -side);
        const glm::vec2 longest = o.corners[1] - o.corners[0];
        o.across = glm::vec2(longest.y, -longest.x);
        o.pad = pad;
        return o;
    };
    const sort_detail::ImageOutline a = stick({0, 0}, {1, 1}, 1e-4f);
    EXPECT_TRUE(sort_detail::outlines_apart(a, stick({0.1f, 0}, {1.1f, 1}, 1e-4f)));   // 0.05 apart across
    EXPECT_TRUE(sort_detail::outlines_apart(stick({0.1f, 0}, {1.1f, 1}, 1e-4f), a));   // either way round
    EXPECT_TRUE(sort_detail::outlines_apart(a, stick({0.03f, 0}, {1.03f, 1}, 1e-4f)));   // 0.001 apart
    EXPECT_FALSE(sort_detail::outlines_apart(a, stick({0.02f, 0}, {1.02f, 1}, 1e-4f)));  // overlapping
    EXPECT_FALSE(sort_detail::outlines_apart(stick({0, 0}, {1, 1}, 0.03f), stick({0.1f, 0}, {1.1f, 1}, 0.03f)));  // within the pads
    EXPECT_FALSE(sort_detail::outlines_apart(a, stick({0, 1}, {1, 0}, 1e-4f)));          // crossing
}

// The pair tables' slots spread pairs that share either object (Fibonacci hashing over the
// whole key): pairs (a, 7) and (7, b) for 256 values each land on most of 1,024 slots.
TEST(VisibilitySort, PairSlotsSpreadPairsSharingAnObject) {
    struct Entry {
        std::uint64_t key = 0;
    };
    sort_detail::PairSlots<Entry> slots;
    slots.reset(64, 16);
    for (const bool first_varies : {true, false}) {
        std::set<const Entry*> used;
        for (std::uint32_t v = 0; v < 256; ++v) {
            const std::uint64_t key = first_varies ? slots.key_of(v, 7) : slots.key_of(7, v);
            used.insert(&slots[key]);
        }
        EXPECT_GT(used.size(), 200u) << (first_varies ? "first id varying" : "second id varying");
    }
}

// The extent scan's kernels give the reference's ids in the reference's order, for every
// count and start (boxes on a coarse grid: many equal bounds), and the extent trees built
// with them answer every query with exactly the objects a test of each extent finds.
TEST(VisibilitySort, ExtentScansAndTreesFindWhatEachExtentsTestFinds) {
    std::uint64_t state = 5;
    const auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return float(std::int32_t(state >> 59) - 16) / 16.0f;  // -1 to 0.94 in steps of 1/16
    };
    const auto random_extent = [&] {
        sort_detail::Extent e;
        for (int a = 0; a < 3; ++a) {
            const float u = next(), v = next();
            e.lo[a] = std::min(u, v), e.hi[a] = std::max(u, v);
        }
        e.nearest = next() + 1.0f;
        return e;
    };
    const std::uint32_t n = 700;
    detail::Vector<sort_detail::Extent> extents(n);
    for (auto& e : extents) e = random_extent();
    std::vector<float> lo[3], hi[3], nearest;
    std::vector<std::uint32_t> ids;
    for (std::uint32_t i = 0; i < n + sort_detail::kExtentColumnPadding; ++i) {
        const sort_detail::Extent& e = extents[i % n];
        for (int a = 0; a < 3; ++a) lo[a].push_back(e.lo[a]), hi[a].push_back(e.hi[a]);
        nearest.push_back(e.nearest), ids.push_back(1000 + i);
    }
    const sort_detail::ExtentColumns columns{{lo[0].data(), lo[1].data(), lo[2].data()}, {hi[0].data(), hi[1].data(), hi[2].data()},
                                             nearest.data(), ids.data()};
    detail::Vector<std::uint32_t> held;  // every third object
    for (std::uint32_t i = 0; i < n; i += 3) held.push_back(i);
    std::size_t total_found = 0;
    for (const std::string& isa : available_isas()) {
        const sort_detail::ExtentScan scan = sort_detail::extent_scan_for(detail::isa_choice(isa));
        sort_detail::ExtentTree tree;
        tree.use(scan);
        tree.build(extents, held);
        for (int trial = 0; trial < 200; ++trial) {
            const sort_detail::Extent box = random_extent();
            const float farthest = next() + 1.5f;
            const std::uint32_t first = std::uint32_t(trial * 7) % 97, count = std::uint32_t(trial * 13) % 300;
            std::vector<std::uint32_t> got(count + sort_detail::kExtentColumnPadding), want(count + sort_detail::kExtentColumnPadding);
            got.resize(scan(columns, first, count, box, farthest, got.data()));
            want.resize(sort_detail::extent_scan_reference(columns, first, count, box, farthest, want.data()));
            EXPECT_EQ(got, want) << isa << ", " << count << " extents from " << first;

            detail::Vector<std::uint32_t> found;
            tree.query(box, farthest, found);
            std::vector<std::uint32_t> tree_ids(found.begin(), found.end()), brute;
            std::sort(tree_ids.begin(), tree_ids.end());
            for (std::uint32_t i : held)
                if (extents[i].nearest < farthest && sort_detail::boxes_overlap(extents[i], box)) brute.push_back(i);
            EXPECT_EQ(tree_ids, brute) << isa << ", query " << trial;
            total_found += brute.size() + want.size();
        }
    }
    EXPECT_GT(total_found, 1000u);
}

// Every instruction set gives the same sort (the support scan is the only SIMD kernel, and
// its answers are defined to the bit), frame after frame of tumbling toothpicks.
TEST(VisibilitySort, EveryInstructionSetGivesTheSameSort) {
    ToothpickOptions options;
    options.count = 300;
    Scene scene = generate_toothpicks(options, 0);
    Camera camera;
    camera.eye = {3.0, 2.0, 20.0};
    camera.target = {0.0, 0.0, 0.0};
    std::vector<std::vector<std::uint32_t>> reference;  // order, then layer sizes, per frame
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        VisibilitySorter sorter = make_visibility_sorter(scene);
        for (int frame = 0; frame < 6; ++frame) {
            std::vector<glm::mat4> transforms(scene.objects.size());
            for (int i = 0; i < options.count; ++i) transforms[std::size_t(i)] = glm::mat4(toothpick_transform(options, i, frame));
            SortFrame f;
            f.transforms = transforms.data();
            f.eye = glm::vec3(camera.eye);
            const VisibilitySort& sort = sorter.sort(f);
            std::vector<std::uint32_t> answer(sort.order.begin(), sort.order.end());
            for (const SortLayer& l : sort.layers) answer.push_back(l.count);
            answer.push_back(std::uint32_t(sort.stats.hull_tests));
            if (std::size_t(frame) >= reference.size()) reference.push_back(answer);
            else EXPECT_EQ(answer, reference[std::size_t(frame)]) << isa << ", frame " << frame;
        }
    }
}

// The exact oracle at the object level: on a scene of disjoint convex objects (rotated boxes,
// one per cell of a grid), painting the sort's layers back to front (each box's faces turned
// away from the eye first) gives Embree's first-hit image at every pixel the painter is sure
// of; the layers reversed do not.
TEST(VisibilitySort, LayersPaintEmbreesImageOnConvexObjects) {
    Scene scene;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> half(0.3f, 1.1f), unit(-1.0f, 1.0f);
    for (int cx = 0; cx < 4; ++cx)
        for (int cy = 0; cy < 3; ++cy)
            for (int cz = 0; cz < 4; ++cz) {
                // Within 1.1 * sqrt(3) < 2 of its cell's centre, 4 apart: no two boxes meet.
                const glm::vec3 centre(4.0f * float(cx), 4.0f * float(cy), 4.0f * float(cz));
                const glm::mat3 turn = glm::mat3_cast(glm::normalize(glm::quat(unit(rng), unit(rng), unit(rng), unit(rng))));
                const glm::vec3 size(half(rng), half(rng), half(rng));
                Mesh mesh;
                mesh.name = "box";
                for (int k = 0; k < 8; ++k)
                    mesh.positions.push_back(centre + turn * (glm::vec3((k & 1) ? 1.f : -1.f, (k & 2) ? 1.f : -1.f, (k & 4) ? 1.f : -1.f) * size));
                mesh.indices = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
                test::add_object_with_own_mesh(scene, std::move(mesh));
            }
    const RayScene rays(scene);
    const glm::dvec3 anchor = scene_anchor(scene);
    // Every object's triangles as painter's polygons (anchored as the ray scene places them).
    std::vector<std::vector<BspPolygon>> faces(scene.objects.size());
    for (std::uint32_t id = 0; id < scene.objects.size(); ++id) {
        const Object& o = scene.objects[id];
        const Mesh& m = scene.meshes[o.mesh];
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
            BspPolygon poly;
            for (int k = 0; k < 3; ++k) poly.vertices.push_back(glm::dvec3(transform_point_from(o.world, m.positions[m.indices[3 * t + std::size_t(k)]], anchor)));
            poly.normal = glm::cross(poly.vertices[1] - poly.vertices[0], poly.vertices[2] - poly.vertices[0]);
            poly.offset = glm::dot(poly.normal, poly.vertices[0]);
            poly.object = id;
            faces[id].push_back(poly);
        }
    }
    VisibilitySorter sorter = make_visibility_sorter(scene);
    const Resolution display{151, 101};
    std::size_t pixels = 0, covered = 0, ambiguous_pixels = 0, mismatches = 0, reversed_mismatches = 0;
    std::uniform_real_distribution<double> around(-6.0, 18.0);
    for (int view = 0; view < 6; ++view) {
        Camera camera;
        // Eyes at cell corners inside the grid (free space), or outside it, looking anywhere.
        camera.eye = view % 2 ? glm::dvec3(2.0 + 4.0 * (view % 3), 2.0 + 4.0 * (view % 2), 2.0 + 4.0 * (view / 3))
                              : glm::dvec3(around(rng), around(rng) + 10.0, around(rng) - 14.0);
        camera.target = glm::dvec3(6.0 + 4.0 * double(unit(rng)), 4.0 + 3.0 * double(unit(rng)), 6.0 + 4.0 * double(unit(rng)));
        camera.near_plane = 0.05;
        CameraFrame f(scene, camera, display, anchor);
        const VisibilitySort& sort = sorter.sort(f.frame);
        ASSERT_EQ(sort.stats.cycles, 0u) << "view " << view << ": disjoint boxes in a cycle; pick another seed";
        const glm::dvec3 eye = camera.eye - anchor;
        const auto painter_order = [&](bool reversed) {
            std::vector<const BspPolygon*> order;
            for (std::size_t k = 0; k < sort.order.size(); ++k) {
                const std::uint32_t id = sort.order[reversed ? k : sort.order.size() - 1 - k];
                for (const bool facing : {false, true})
                    for (const BspPolygon& poly : faces[id])
                        if ((glm::dot(poly.normal, eye) > poly.offset) == facing) order.push_back(&poly);
            }
            return order;
        };
        std::vector<std::uint8_t> ambiguous;
        const std::vector<std::uint32_t> painted = paint_ids(painter_order(false), anchor, camera, display, &ambiguous);
        const std::vector<std::uint32_t> wrong = paint_ids(painter_order(true), anchor, camera, display);
        const std::vector<std::uint32_t> seen = test::embree_first_hits(rays, scene, camera, display);
        ASSERT_EQ(seen.size(), painted.size());
        for (std::size_t p = 0; p < painted.size(); ++p) {
            ++pixels;
            covered += seen[p] != kNoObject;
            reversed_mismatches += wrong[p] != seen[p];
            if (ambiguous[p]) {
                ++ambiguous_pixels;
                continue;
            }
            if (painted[p] != seen[p] && ++mismatches <= 5)
                ADD_FAILURE() << "view " << view << ", pixel " << p << ": painted " << painted[p] << ", Embree sees " << seen[p];
        }
    }
    std::printf("[ painter  ] %zu pixels, %zu covered, %zu ambiguous, %zu mismatches; the layers reversed: %zu\n", pixels, covered,
                ambiguous_pixels, mismatches, reversed_mismatches);
    EXPECT_EQ(mismatches, 0u);
    EXPECT_GT(covered, pixels / 5);
    EXPECT_LT(ambiguous_pixels, pixels / 50);
    EXPECT_GT(reversed_mismatches, covered / 20);
}

// Zero violations against Embree on every shared scene, along a walk and from random views.
TEST(VisibilitySort, NoViolationsOnTheSharedScenes) {
    const Resolution display{240, 136};
    Tally all;
    int scenes = 0;
    for (const char* file : {"intel_castle.glb", "crytek_sponza.glb", "fzk_haus.glb", "openarena_oa_thor.glb", "openarena_pul1duel-oa.glb"}) {
        const std::string path = test::shared_scene(file);
        if (path.empty()) continue;
        ++scenes;
        const Scene scene = load_scene(path);
        const RayScene rays(scene);
        VisibilitySorter sorter = make_visibility_sorter(scene);
        WalkOptions walk;
        walk.frames = 24;
        const CameraPath path_frames = walk_path(rays, scene, walk);
        Tally tally;
        for (std::size_t k = 0; k < path_frames.frames.size(); k += 6) check_view(sorter, scene, rays, path_frames.frames[k], display, tally);
        sorter.forget_order();
        for (const Camera& view : random_views(rays, scene, 4, 7).frames) check_view(sorter, scene, rays, view, display, tally);
        tally.report(file);
        all.frames += tally.frames;
    }
    if (scenes == 0) GTEST_SKIP() << "no shared scenes";
    EXPECT_GT(all.frames, 0u);
}

}  // namespace
}  // namespace homcull
