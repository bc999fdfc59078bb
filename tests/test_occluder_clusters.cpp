// Occluder clusters: the build keeps every triangle, and the clustered render skips what it
// should, gives the same bits on every instruction set and with any threads, and never claims
// an occluder nearer than Embree finds one.
#include "support.hpp"

#include <homcull/camera.hpp>
#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/world_triangles.hpp>

#include <glm/ext/matrix_clip_space.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <tuple>

namespace homcull {
namespace {

// Appends a cluster made by hand: the given vertices and triangles (local indices, with their
// shared-edge flags and apexes, 3 per triangle; none: kNoApex).
void append_cluster(OccluderClusters& clusters, const std::vector<glm::vec3>& vertices, const std::vector<std::uint16_t>& indices,
                    const std::vector<std::uint8_t>& flags, std::vector<std::uint32_t> apexes = {}) {
    if (apexes.empty()) apexes.assign(3 * flags.size(), kNoApex);
    OccluderCluster c;
    c.first_vertex = std::uint32_t(clusters.positions.size() / 3);
    c.vertex_count = std::uint32_t(vertices.size());
    c.first_triangle = std::uint32_t(clusters.shared_edges.size());
    c.triangle_count = std::uint32_t(flags.size());
    c.bounded = true;
    for (const glm::vec3& v : vertices) {
        clusters.positions.insert(clusters.positions.end(), {v.x, v.y, v.z});
        c.bounds.extend(v);
    }
    clusters.indices.insert(clusters.indices.end(), indices.begin(), indices.end());
    clusters.shared_edges.insert(clusters.shared_edges.end(), flags.begin(), flags.end());
    clusters.edge_apexes.insert(clusters.edge_apexes.end(), apexes.begin(), apexes.end());
    clusters.max_cluster_vertices = std::max(clusters.max_cluster_vertices, c.vertex_count);
    clusters.clusters.push_back(c);
}

// A quad a, b, c, d (counter-clockwise from the side it faces) as a cluster of two triangles
// sharing the diagonal a-c.
void append_quad(OccluderClusters& clusters, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    append_cluster(clusters, {a, b, c, d}, {0, 1, 2, 0, 2, 3}, {0b100, 0b001}, {kNoApex, kNoApex, 3, 1, kNoApex, kNoApex});
}

// A triangle as its three positions and flags, to compare meshes whatever their order.
using TriangleRecord = std::array<float, 10>;
TriangleRecord record(const float* p0, const float* p1, const float* p2, std::uint8_t flags) {
    return {p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], p2[0], p2[1], p2[2], float(flags)};
}

// The world triangles of `count` boxes of three heights in rows of `row`, 3 apart, their shared
// edges found.
WorldTriangles box_grid(int count, int row) {
    Scene scene;
    for (int k = 0; k < count; ++k)
        test::add_box(scene, "box", glm::vec3(float(k % row) * 3.0f, 0.0f, float(k / row) * -3.0f),
                      glm::vec3(float(k % row) * 3.0f + 2.0f, 1.0f + float(k % 3), float(k / row) * -3.0f + 2.0f));
    scene.finalize();
    return gather_world_triangles(scene, objects_with_role(scene, ""));
}

TEST(OccluderClusters, KeepEveryTriangleWithItsVerticesAndFlags) {
    const WorldTriangles world = box_grid(40, 8);
    ASSERT_EQ(world.triangle_count(), 480u);
    for (const std::size_t max_triangles : {std::size_t(4), std::size_t(64), std::size_t(512)}) {
        ClusterLimits limits;
        limits.max_triangles = max_triangles;
        limits.max_vertices = std::min<std::size_t>(255, max_triangles);
        const OccluderClusters clusters = test::cluster_world(world, limits);
        std::vector<TriangleRecord> before, after;
        for (std::size_t t = 0; t < world.triangle_count(); ++t) {
            const std::uint32_t* v = &world.indices[3 * t];
            before.push_back(record(&world.positions[3 * v[0]], &world.positions[3 * v[1]], &world.positions[3 * v[2]], world.shared_edges[t]));
        }
        std::uint32_t largest = 0;
        for (const OccluderCluster& c : clusters.clusters) {
            EXPECT_LE(c.triangle_count, max_triangles);
            EXPECT_LE(c.vertex_count, limits.max_vertices + 3 * c.triangle_count);  // its own, then apexes of other clusters' triangles
            EXPECT_TRUE(c.bounded);
            largest = std::max(largest, c.vertex_count);
            for (std::uint32_t t = c.first_triangle; t < c.first_triangle + c.triangle_count; ++t) {
                const float* p[3];
                for (int k = 0; k < 3; ++k) {
                    const std::uint16_t local = clusters.indices[3 * t + std::size_t(k)];
                    ASSERT_LT(local, limits.max_vertices);
                    p[k] = &clusters.positions[3 * (std::size_t(c.first_vertex) + local)];
                    for (int axis = 0; axis < 3; ++axis) {  // inside the cluster's box
                        EXPECT_GE(p[k][axis], c.bounds.min[axis]);
                        EXPECT_LE(p[k][axis], c.bounds.max[axis]);
                    }
                }
                after.push_back(record(p[0], p[1], p[2], clusters.shared_edges[t]));
                // Each flagged edge's apex: a vertex of the cluster at the source triangle's apex.
                const std::uint32_t source = clusters.source_triangles[t];
                for (std::size_t k = 0; k < 3; ++k) {
                    if (!((clusters.shared_edges[t] >> k) & 1u)) continue;
                    const std::uint32_t apex = clusters.edge_apexes[3 * t + k];
                    ASSERT_LT(apex, c.vertex_count);
                    const float* at = &clusters.positions[3 * (std::size_t(c.first_vertex) + apex)];
                    const float* expected = &world.positions[3 * std::size_t(world.edge_apexes[3 * source + k])];
                    EXPECT_TRUE(std::equal(at, at + 3, expected));
                }
            }
        }
        EXPECT_EQ(largest, clusters.max_cluster_vertices);
        std::sort(before.begin(), before.end());
        std::sort(after.begin(), after.end());
        EXPECT_EQ(before, after) << "clusters of at most " << max_triangles << " triangles";
        if (max_triangles == 4) {
            EXPECT_GE(clusters.clusters.size(), 120u);
        }
    }
}

// A mesh that repeats a triangle (three copies with different flags, among others): every
// input triangle is in the clusters exactly once, with its own flags (source_triangles names it).
TEST(OccluderClusters, RepeatedTrianglesAreEachKeptOnce) {
    const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0};
    const std::vector<std::uint32_t> indices = {0, 1, 2, 1, 3, 2, 0, 1, 2, 1, 4, 3, 0, 1, 2};
    const std::vector<std::uint8_t> flags = {1, 2, 3, 4, 5};
    const std::vector<std::uint32_t> apexes(15, 4);
    const OccluderClusters clusters = build_occluder_clusters(positions.data(), 3 * sizeof(float), 5, indices.data(), 5, flags.data(), apexes.data());
    std::vector<std::uint32_t> sources(clusters.source_triangles.begin(), clusters.source_triangles.end());
    std::sort(sources.begin(), sources.end());
    EXPECT_EQ(sources, (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
    for (std::size_t t = 0; t < clusters.source_triangles.size(); ++t)
        EXPECT_EQ(clusters.shared_edges[t], flags[clusters.source_triangles[t]]);
}

// A plan (plan_occluder_clusters) then the clusters from it are the one-step build, bit for
// bit; the same plan with a placement's positions (a mesh placed elsewhere, turned, with other
// shared edges) gives the plan's clusters at those positions, each with that placement's flags
// and apexes and its own box.
TEST(OccluderClusters, APlanGivesTheBuildsClustersAndServesAnyPlacement) {
    const WorldTriangles world = box_grid(12, 4);
    const std::size_t vertices = world.positions.size() / 3, triangles = world.triangle_count();
    const ClusterLimits limits{16, 8};
    const OccluderClusterPlan plan = plan_occluder_clusters(world.positions.data(), 12, vertices, world.indices.data(), triangles, limits);
    EXPECT_EQ(plan.vertex_count, vertices);
    EXPECT_EQ(plan.triangle_count, triangles);
    const OccluderClusters direct = build_occluder_clusters(world.positions.data(), 12, vertices, world.indices.data(), triangles,
                                                            world.shared_edges.data(), world.edge_apexes.data(), limits);
    const OccluderClusters planned = build_occluder_clusters(plan, world.positions.data(), 12, world.shared_edges.data(), world.edge_apexes.data());
    ASSERT_GT(direct.clusters.size(), 1u);
    const auto same_bits = [](const auto& a, const auto& b) {
        return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
    };
    EXPECT_TRUE(same_bits(direct.positions, planned.positions));
    EXPECT_TRUE(same_bits(direct.indices, planned.indices));
    EXPECT_TRUE(same_bits(direct.shared_edges, planned.shared_edges));
    EXPECT_TRUE(same_bits(direct.edge_apexes, planned.edge_apexes));
    EXPECT_TRUE(same_bits(direct.source_triangles, planned.source_triangles));
    ASSERT_EQ(direct.clusters.size(), planned.clusters.size());
    for (std::size_t c = 0; c < direct.clusters.size(); ++c) {
        EXPECT_EQ(direct.clusters[c].first_vertex, planned.clusters[c].first_vertex);
        EXPECT_EQ(direct.clusters[c].vertex_count, planned.clusters[c].vertex_count);
        EXPECT_EQ(direct.clusters[c].triangle_count, planned.clusters[c].triangle_count);
        EXPECT_EQ(std::memcmp(&direct.clusters[c].bounds, &planned.clusters[c].bounds, sizeof(Aabb)), 0);
    }
    EXPECT_EQ(direct.max_cluster_vertices, planned.max_cluster_vertices);

    // Another placement: positions turned a quarter about y and moved, in a wider stride, and
    // only every other triangle's flags kept.
    std::vector<float> moved(4 * vertices);
    for (std::size_t v = 0; v < vertices; ++v) {
        const float* p = &world.positions[3 * v];
        moved[4 * v] = p[2] + 100.0f, moved[4 * v + 1] = p[1] - 7.0f, moved[4 * v + 2] = -p[0], moved[4 * v + 3] = 1.0f;
    }
    std::vector<std::uint8_t> flags(world.shared_edges.begin(), world.shared_edges.end());
    for (std::size_t t = 1; t < triangles; t += 2) flags[t] = 0;
    const OccluderClusters placed = build_occluder_clusters(plan, moved.data(), 16, flags.data(), world.edge_apexes.data());
    ASSERT_EQ(placed.clusters.size(), direct.clusters.size());
    EXPECT_TRUE(same_bits(direct.source_triangles, placed.source_triangles));  // the plan's triangles, in its order
    EXPECT_TRUE(same_bits(direct.indices, placed.indices));
    for (const OccluderCluster& c : placed.clusters) {
        Aabb box;
        for (std::uint32_t t = c.first_triangle; t < c.first_triangle + c.triangle_count; ++t) {
            const std::uint32_t source = placed.source_triangles[t];
            EXPECT_EQ(placed.shared_edges[t], flags[source]);
            for (int k = 0; k < 3; ++k) {
                // Each corner is the placement's position of the source triangle's vertex.
                const float* at = &placed.positions[3 * (std::size_t(c.first_vertex) + placed.indices[3 * t + std::size_t(k)])];
                const float* expected = &moved[4 * std::size_t(world.indices[3 * source + std::size_t(k)])];
                EXPECT_TRUE(std::equal(at, at + 3, expected));
                box.extend(glm::vec3(at[0], at[1], at[2]));
                if (!((flags[source] >> k) & 1u)) continue;
                const float* apex = &placed.positions[3 * (std::size_t(c.first_vertex) + placed.edge_apexes[3 * t + std::size_t(k)])];
                const float* apex_expected = &moved[4 * std::size_t(world.edge_apexes[3 * source + std::size_t(k)])];
                EXPECT_TRUE(std::equal(apex, apex + 3, apex_expected));
            }
        }
        EXPECT_EQ(std::memcmp(&box, &c.bounds, sizeof(Aabb)), 0);
    }
    // A plan's own checks, named after it.
    try {
        plan_occluder_clusters(world.positions.data(), 12, 3, world.indices.data(), triangles, limits);
        ADD_FAILURE() << "an index out of range was planned";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("plan_occluder_clusters: index"), std::string::npos) << e.what();
    }
    EXPECT_THROW(build_occluder_clusters(plan, world.positions.data(), 8, nullptr, nullptr), Error);
    EXPECT_THROW(build_occluder_clusters(plan, world.positions.data(), 12, flags.data(), nullptr), Error);
    EXPECT_TRUE(build_occluder_clusters(OccluderClusterPlan{}, nullptr, 12, nullptr, nullptr).clusters.empty());
    // A plan filled by hand that does not hold together is refused, whatever is wrong with it.
    for (int broken = 0; broken < 5; ++broken) {
        OccluderClusterPlan bad = plan;
        if (broken == 0) bad.vertex_begin.pop_back();
        if (broken == 1) bad.vertices[3] = std::uint32_t(vertices);
        if (broken == 2) bad.source_triangles[5] = std::uint32_t(triangles);
        if (broken == 3) bad.local_indices[7] = 200;
        if (broken == 4) bad.triangle_count += 1;
        EXPECT_THROW(build_occluder_clusters(bad, world.positions.data(), 12, nullptr, nullptr), Error) << "broken plan " << broken;
    }
}

TEST(OccluderClusters, BadInputIsAnErrorOrADefinedResult) {
    const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    const std::vector<std::uint32_t> indices = {0, 1, 2, 2, 1, 3};
    const std::uint8_t flags[2] = {1, 0};
    EXPECT_THROW(build_occluder_clusters(positions.data(), 12, 3, indices.data(), 2, nullptr, nullptr), Error);  // index 3 of 3 vertices
    EXPECT_THROW(build_occluder_clusters(positions.data(), 8, 4, indices.data(), 2, nullptr, nullptr), Error);
    EXPECT_THROW(build_occluder_clusters(nullptr, 12, 4, indices.data(), 2, nullptr, nullptr), Error);
    EXPECT_THROW(build_occluder_clusters(positions.data(), 12, 4, indices.data(), 2, flags, nullptr), Error);  // flags without apexes
    EXPECT_THROW(build_occluder_clusters(positions.data(), 12, 4, indices.data(), 2, nullptr, nullptr, {64, 6}), Error);    // not a multiple of 4
    EXPECT_THROW(build_occluder_clusters(positions.data(), 12, 4, indices.data(), 2, nullptr, nullptr, {300, 64}), Error);  // over 255 vertices
    EXPECT_TRUE(build_occluder_clusters(positions.data(), 12, 4, indices.data(), 0, nullptr, nullptr).clusters.empty());
    // A triangle with a repeated vertex is kept, and counted degenerate when drawn.
    const std::vector<std::uint32_t> with_repeat = {0, 1, 2, 1, 1, 3, 2, 1, 3};
    const OccluderClusters kept = build_occluder_clusters(positions.data(), 12, 4, with_repeat.data(), 3, nullptr, nullptr);
    EXPECT_EQ(kept.triangle_count(), 3u);

    // A vertex that is not a number: its cluster has no box, is always drawn, and the
    // triangle pipeline counts its triangle invalid.
    std::vector<float> bad = positions;
    bad[4] = std::numeric_limits<float>::quiet_NaN();
    const OccluderClusters clusters = build_occluder_clusters(bad.data(), 12, 4, indices.data(), 2, nullptr, nullptr);
    ASSERT_EQ(clusters.clusters.size(), 1u);
    EXPECT_FALSE(clusters.clusters[0].bounded);
    OcclusionBuffer buffer(test::buffer_config(64, 48, 1, 0.1f));
    Camera camera = test::camera_down_minus_z();
    camera.eye = {0.5, 0.5, 2};
    buffer.render_frame(ClusteredInput{&clusters, clip_from_world(camera, 64.0 / 48.0), Backface::none});
    EXPECT_EQ(buffer.stats().invalid, 2u);  // both triangles use vertex 1
    EXPECT_EQ(buffer.stats().cluster_bands_drawn, 1u);

    // Clusters that do not fit their arrays are refused before anything is read.
    OccluderClusters broken = clusters;
    broken.clusters[0].vertex_count = 9;
    EXPECT_THROW(buffer.render(ClusteredInput{&broken, clip_from_world(camera, 64.0 / 48.0), Backface::none}), Error);
    broken = clusters;
    broken.clusters[0].triangle_count = 3;
    EXPECT_THROW(buffer.render(ClusteredInput{&broken, clip_from_world(camera, 64.0 / 48.0), Backface::none}), Error);
    EXPECT_THROW(buffer.render(ClusteredInput{}), Error);
    buffer.render_frame(ClusteredInput{&kept, clip_from_world(camera, 64.0 / 48.0), Backface::none});
    EXPECT_EQ(buffer.stats().triangles_in, 3u);
    EXPECT_EQ(buffer.stats().degenerate, 1u);
}

// Two clusters made by hand, the far one first: a wall filling the view at z = -5 and a small
// quad behind it at z = -50. Drawn nearest first, the far one is hidden in every band it
// reaches and skipped there: the buffer is the wall's alone.
TEST(ClusteredRender, SkipsAClusterHiddenBehindANearerOne) {
    OccluderClusters clusters;
    append_quad(clusters, {-3, -3, -50}, {3, -3, -50}, {3, 3, -50}, {-3, 3, -50});      // far, small on screen
    append_quad(clusters, {-20, -20, -5}, {20, -20, -5}, {20, 20, -5}, {-20, 20, -5});  // near, covers the view
    const Camera camera = test::camera_down_minus_z(90.0, 0.5);
    const std::array<float, 16> m = clip_from_world(camera, 300.0 / 260.0);
    OcclusionBuffer both(test::buffer_config(300, 260, 1, 0.5f)), wall_only(test::buffer_config(300, 260, 1, 0.5f));
    both.render_frame(ClusteredInput{&clusters, m, Backface::cw});
    OccluderClusters wall = clusters;
    wall.clusters.erase(wall.clusters.begin());
    wall_only.render_frame(ClusteredInput{&wall, m, Backface::cw});
    EXPECT_TRUE(test::same_subtiles(both, wall_only));
    EXPECT_TRUE(test::same_pyramid(both, wall_only));
    // 260 rows: 65 subtile rows, 3 bands; the far quad's rows (122 to 138) reach the first two.
    EXPECT_EQ(both.stats().cluster_bands_drawn, 3u);
    EXPECT_EQ(both.stats().cluster_bands_hidden, 2u);
    EXPECT_EQ(both.stats().triangles_in, 6u);  // the wall's two triangles, in each of 3 bands

    // With the wall drawn last (the far quad nearer than it), both are drawn.
    for (float& p : clusters.positions)
        if (p == -50.0f) p = -4.0f;
    clusters.clusters[0].bounds.min.z = clusters.clusters[0].bounds.max.z = -4.0f;
    both.render_frame(ClusteredInput{&clusters, m, Backface::cw});
    EXPECT_EQ(both.stats().cluster_bands_hidden, 0u);
    EXPECT_EQ(both.stats().cluster_bands_drawn, 5u);
}

// ClusteredInput's subset and flags: drawing clusters {2, 0} of three is drawing a mesh of those
// two alone, and other flags are used instead of the clusters' own.
TEST(ClusteredRender, ASubsetAndOtherFlagsAreThatMesh) {
    OccluderClusters three, two;
    const auto quads = [](OccluderClusters& c, std::initializer_list<int> which) {
        for (const int k : which) {
            const float z = -6.0f - 3.0f * float(k), x = float(k) - 1.5f;
            append_quad(c, {x - 1, -1, z}, {x + 1, -1, z}, {x + 1, 1, z}, {x - 1, 1, z});
        }
    };
    quads(three, {0, 1, 2});
    quads(two, {2, 0});
    const std::array<float, 16> m = clip_from_world(test::camera_down_minus_z(70.0, 0.5), 200.0 / 150.0);
    const std::uint32_t ids[] = {2, 0};
    OcclusionBuffer subset(test::buffer_config(200, 150, 2, 0.5f)), alone(test::buffer_config(200, 150, 2, 0.5f));
    ClusteredInput in{&three, m, Backface::cw};
    in.cluster_ids = ids;
    in.cluster_count = 2;
    subset.render_frame(in);
    alone.render_frame(ClusteredInput{&two, m, Backface::cw});
    EXPECT_TRUE(test::same_subtiles(subset, alone));
    EXPECT_TRUE(subset.stats() == alone.stats());

    // Other flags: a quad in clip space (identity matrix, w = 1) whose diagonal runs through
    // sample centres. Shared, the diagonal needs no margin and its samples are covered; with
    // the flags replaced by none, it keeps the margin and they are not.
    OccluderClusters square;
    append_quad(square, {-1, -1, 0.5f}, {1, -1, 0.5f}, {1, 1, 0.5f}, {-1, 1, 0.5f});
    std::array<float, 16> identity{};
    for (int k = 0; k < 4; ++k) identity[std::size_t(5 * k)] = 1.0f;
    const std::vector<std::uint8_t> none(square.shared_edges.size(), 0);
    OcclusionBuffer shared(test::buffer_config(8, 8, 1, 0.5f)), margin(test::buffer_config(8, 8, 1, 0.5f));
    shared.render_frame(ClusteredInput{&square, identity, Backface::none});
    ClusteredInput without{&square, identity, Backface::none};
    without.shared_edges = none.data();
    without.edge_apexes = square.edge_apexes.data();
    margin.render_frame(without);
    std::vector<std::uint8_t> covered_shared, covered_margin;
    shared.read_coverage(covered_shared);
    margin.read_coverage(covered_margin);
    EXPECT_EQ(std::count(covered_shared.begin(), covered_shared.end(), 1), 64);
    EXPECT_EQ(std::count(covered_margin.begin(), covered_margin.end(), 1), 64 - 8);  // the diagonal's 8 samples

    const std::uint32_t bad[] = {3};
    in = ClusteredInput{&three, m, Backface::cw};
    in.cluster_ids = bad;
    in.cluster_count = 1;
    EXPECT_THROW(subset.render(in), Error);
}

// A cluster whose box crosses the near plane is drawn in every band, untested; one wholly
// behind the eye or beside the view is counted outside and never set up.
TEST(ClusteredRender, ClustersAcrossTheNearPlaneAreDrawnAndThoseOutsideAreNot) {
    OccluderClusters clusters;
    append_quad(clusters, {-50, -1, 20}, {50, -1, 20}, {50, -1, -100}, {-50, -1, -100});  // the floor, under the eye, facing up
    append_quad(clusters, {-1, -1, 10}, {1, -1, 10}, {1, 1, 10}, {-1, 1, 10});           // behind the eye
    append_quad(clusters, {100, -1, -10}, {102, -1, -10}, {102, 1, -10}, {100, 1, -10});  // beside the view
    OcclusionBuffer buffer(test::buffer_config(320, 200, 1, 0.1f));
    buffer.render_frame(ClusteredInput{&clusters, clip_from_world(test::camera_down_minus_z(60.0), 1.6), Backface::none});
    EXPECT_GT(buffer.stats().near_clipped, 0u);
    EXPECT_EQ(buffer.stats().cluster_bands_drawn, 2u);  // the floor's cluster, in both bands
    EXPECT_EQ(buffer.stats().clusters_outside, 2u);
    EXPECT_EQ(buffer.stats().triangles_in, 4u);  // the floor's two, in each band
    std::vector<std::uint8_t> covered;
    buffer.read_coverage(covered);
    EXPECT_EQ(covered.back(), 1u);  // the floor reaches the bottom row
}

struct CastleOccluders {
    Scene scene;
    WorldTriangles world;
    CameraPath views;
};
const CastleOccluders* castle() {
    static const CastleOccluders* loaded = [] {
        const std::string path = test::shared_scene("intel_castle.glb");
        if (path.empty()) return static_cast<CastleOccluders*>(nullptr);
        auto* c = new CastleOccluders;
        c->scene = load_scene(path);
        c->world = gather_world_triangles(c->scene, objects_with_role(c->scene, "occluder"));
        c->views = read_camera_path(std::string(HOMCULL_SOURCE_DIR) + "/data/views/castle.json");
        return c;
    }();
    return loaded;
}

// The castle's occluders in clusters, from two of its views, with and without per-sample
// depth: every instruction set and every job system gives the scalar reference's bits,
// statistics and pyramid.
TEST(ClusteredRender, SameBitsOnEveryIsaAndWithAnyThreads) {
    const CastleOccluders* c = castle();
    if (!c) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const OccluderClusters clusters = test::cluster_world(c->world);
    std::mt19937_64 order_rng(5);
    const ParallelFor tbb = test::parallel_jobs(), shuffled{test::run_shuffled, &order_rng};
    for (const std::size_t view : {std::size_t(0), c->views.frames.size() - 1}) {
        const Camera& camera = c->views.frames[view];
        const ClusteredInput in{&clusters, clip_from_world(camera, 1280.0 / 720.0), Backface::cw};
        for (const bool sample_depth : {false, true}) {
            const BufferConfig config = test::buffer_config(sample_depth ? 320 : 1280, sample_depth ? 180 : 720, sample_depth ? 4 : 1,
                                                            float(camera.near_plane), sample_depth);
            const test::ScopedIsa reference_isa("scalar");
            OcclusionBuffer reference(config);
            reference.render_frame(in);
            EXPECT_GT(reference.stats().cluster_bands_hidden, 10u);
            EXPECT_GT(reference.stats().clusters_outside, 50u);
            for (const std::string& isa : available_isas())
                for (const ParallelFor& parallel : {ParallelFor{}, tbb, shuffled}) {
                    const test::ScopedIsa selected(isa);
                    OcclusionBuffer buffer(config);
                    buffer.render(in, parallel);  // into an empty buffer: what render_frame gives
                    const std::string what = isa + (parallel.run ? (parallel.user ? ", shuffled" : ", TBB") : ", serial") +
                                             ", view " + std::to_string(view) + (sample_depth ? ", sample depth" : "");
                    EXPECT_TRUE(reference.stats() == buffer.stats()) << what;
                    EXPECT_TRUE(test::same_subtiles(reference, buffer)) << what;
                    EXPECT_TRUE(test::same_pyramid(reference, buffer)) << what;
                }
        }
    }
    // Frame after frame on the same buffers (render_frame clears each band in its task; the
    // job systems' kept triangles are reused from frame to frame), with per-sample depth.
    const BufferConfig config = test::buffer_config(640, 360, 2, float(c->views.frames[0].near_plane), true);
    OcclusionBuffer serial(config), threaded(config), shuffled_order(config);
    for (const std::size_t view : {std::size_t(0), c->views.frames.size() - 1, std::size_t(2), std::size_t(0)}) {
        const ClusteredInput in{&clusters, clip_from_world(c->views.frames[view], 1280.0 / 720.0), Backface::cw};
        serial.render_frame(in);
        threaded.render_frame(in, tbb);
        shuffled_order.render_frame(in, shuffled);
        for (const OcclusionBuffer* b : {&threaded, &shuffled_order}) {
            EXPECT_TRUE(serial.stats() == b->stats()) << "view " << view;
            EXPECT_TRUE(test::same_subtiles(serial, *b)) << "view " << view;
            EXPECT_TRUE(test::same_pyramid(serial, *b)) << "view " << view;
        }
    }
}

// Bands racing on two threads, frame after frame at full size: bands that share the horizon's
// clusters come to them at once (one sets a cluster up, the other sets up the next ones
// meanwhile, or the same one again for itself), and each frame takes the bands in the order of
// the last one's times. Whatever the race, the serial render's bits and statistics.
TEST(ClusteredRender, BandsRacingFrameAfterFrameGiveTheSerialBits) {
    const CastleOccluders* c = castle();
    if (!c) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const OccluderClusters clusters = test::cluster_world(c->world);
    const ParallelFor tbb = test::parallel_jobs(), threads = test::thread_jobs(2);
    const BufferConfig config = test::buffer_config(1280, 720, 1, float(c->views.frames[0].near_plane), true);
    OcclusionBuffer serial(config), with_tbb(config), with_threads(config);
    for (int round = 0; round < 3; ++round)
        for (std::size_t view = 0; view < c->views.frames.size(); ++view) {
            const ClusteredInput in{&clusters, clip_from_world(c->views.frames[view], 1280.0 / 720.0), Backface::cw};
            serial.render_frame(in);
            with_tbb.render_frame(in, tbb);
            with_threads.render_frame(in, threads);
            for (const OcclusionBuffer* b : {&with_tbb, &with_threads}) {
                const std::string what = (b == &with_tbb ? "TBB" : "two threads") + std::string(", round ") + std::to_string(round) + ", view " +
                                         std::to_string(view);
                EXPECT_TRUE(serial.stats() == b->stats()) << what;
                EXPECT_TRUE(test::same_subtiles(serial, *b)) << what;
                EXPECT_TRUE(test::same_pyramid(serial, *b)) << what;
                for (const float x : {-0.9f, -0.3f, 0.2f, 0.7f})  // the per-sample depth where queries read it
                    EXPECT_EQ(serial.test_rect(x, -0.2f, x + 0.1f, 0.1f, 2.0f), b->test_rect(x, -0.2f, x + 0.1f, 0.1f, 2.0f)) << what;
            }
        }
}

// ClusteredInput::backfaces: each cluster drawn with its own backface mode. All of them cw is
// the draw's cw; a mix (cw for every other cluster listed) gives the same bits on every
// instruction set, serial or in tasks, and culls fewer triangles than all cw and more than none.
TEST(ClusteredRender, EachClusterTakesItsOwnBackfaceMode) {
    const CastleOccluders* c = castle();
    if (!c) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const OccluderClusters clusters = test::cluster_world(c->world);
    const Camera& camera = c->views.frames[0];
    const BufferConfig config = test::buffer_config(320, 180, 2, float(camera.near_plane));
    const ClusteredInput whole{&clusters, clip_from_world(camera, 1280.0 / 720.0), Backface::cw};
    std::vector<std::uint32_t> ids;  // every cluster, in reverse: backfaces follow the list, not the numbers
    for (std::size_t k = clusters.clusters.size(); k-- > 0;) ids.push_back(std::uint32_t(k));
    std::vector<Backface> all_cw(ids.size(), Backface::cw), mixed(ids.size(), Backface::none);
    for (std::size_t n = 0; n < ids.size(); n += 2) mixed[n] = Backface::cw;
    const test::ScopedIsa reference_isa("scalar");
    OcclusionBuffer by_draw(config), by_cluster(config), reference(config), none(config);
    by_draw.render_frame(whole);
    ClusteredInput listed = whole;
    listed.backface = Backface::none;  // overridden by every cluster's own
    listed.cluster_ids = ids.data();
    listed.cluster_count = ids.size();
    listed.backfaces = all_cw.data();
    by_cluster.render_frame(listed);
    EXPECT_TRUE(test::same_subtiles(by_draw, by_cluster));
    EXPECT_EQ(by_draw.stats().backface_culled, by_cluster.stats().backface_culled);
    listed.backfaces = mixed.data();
    reference.render_frame(listed);
    listed.backfaces = nullptr;
    none.render_frame(listed);
    EXPECT_GT(reference.stats().backface_culled, 0u);
    EXPECT_LT(reference.stats().backface_culled, by_draw.stats().backface_culled);
    EXPECT_EQ(none.stats().backface_culled, 0u);
    listed.backfaces = mixed.data();
    std::mt19937_64 order_rng(7);
    const ParallelFor tbb = test::parallel_jobs(), shuffled{test::run_shuffled, &order_rng};
    for (const std::string& isa : available_isas())
        for (const ParallelFor& parallel : {ParallelFor{}, tbb, shuffled}) {
            const test::ScopedIsa selected(isa);
            OcclusionBuffer buffer(config);
            buffer.render_frame(listed, parallel);
            const std::string what = isa + (parallel.run ? (parallel.user ? ", shuffled" : ", TBB") : ", serial");
            EXPECT_TRUE(reference.stats() == buffer.stats()) << what;
            EXPECT_TRUE(test::same_subtiles(reference, buffer)) << what;
            EXPECT_TRUE(test::same_pyramid(reference, buffer)) << what;
        }
}

// Runs a closed task list's tasks through a job system (the engine's side of the pull model).
void run_task_list(OcclusionBuffer& buffer, const ParallelFor& jobs) {
    const std::size_t tasks = buffer.close_tasks();
    const auto task = [](void* b, std::size_t i) { static_cast<OcclusionBuffer*>(b)->run_task(i); };
    if (jobs.run) jobs.run(jobs.user, tasks, task, &buffer);
    else
        for (std::size_t i = 0; i < tasks; ++i) task(&buffer, i);
    buffer.finish_tasks();
}

// The castle's clusters as many draws (slices of its clusters, as an engine draws object by
// object), and one draw of quads crossing the near plane and the guard band (clipping gives
// them more triangles than their room, so every band sets them up itself), recorded in a task
// list: on every instruction set, with the tasks in order, shuffled or on threads, the buffer
// holds the bits, statistics and pyramid of one render per draw on one thread.
TEST(ClusteredRender, TaskListsGiveTheBitsOfOneRenderPerDraw) {
    const CastleOccluders* c = castle();
    if (!c) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const OccluderClusters clusters = test::cluster_world(c->world);
    OccluderClusters near_quads;
    for (int k = 0; k < 6; ++k) {  // from behind the eye to far ahead, wide enough to reach the guard band
        const float x = -3.0f + 1.3f * float(k), z = 2.0f - 4.0f * float(k);
        append_quad(near_quads, {x - 1e4f, -1.0f, 5.0f}, {x, -1.0f, z - 40.0f}, {x, 1.0f, z - 40.0f}, {x - 1e4f, 1.0f, 5.0f});
        // One triangle, one vertex behind the eye: clipped into a quad, two triangles in a room of one.
        append_cluster(near_quads, {{x, -2.0f, 3.0f}, {x + 2.0f, -1.0f, z - 30.0f}, {x - 2.0f, 1.5f, z - 30.0f}}, {0, 1, 2}, {0});
    }
    std::vector<std::uint32_t> ids(clusters.clusters.size());
    for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = std::uint32_t(k);
    std::mt19937_64 order_rng(9);
    const ParallelFor tbb = test::parallel_jobs(), shuffled{test::run_shuffled, &order_rng}, threads = test::thread_jobs(2);
    for (const std::size_t view : {std::size_t(0), std::size_t(3)}) {
        const Camera& camera = c->views.frames[view];
        const std::array<float, 16> clip = clip_from_world(camera, 1280.0 / 720.0);
        std::vector<ClusteredInput> draws;
        for (std::size_t first = 0; first < ids.size(); first += 37) {
            ClusteredInput d{&clusters, clip, Backface::cw};
            d.cluster_ids = ids.data() + first;
            d.cluster_count = std::min<std::size_t>(37, ids.size() - first);
            draws.push_back(d);
            if (first == 37 * 4)  // the quads are in the camera's view space
                draws.push_back(ClusteredInput{&near_quads, float_matrix(projection_matrix(camera, 1280.0 / 720.0)), Backface::none});
        }
        for (const bool keep_before : {false, true}) {
            const BufferConfig config = test::buffer_config(640, 360, 2, float(camera.near_plane), view == 3);
            const test::ScopedIsa reference_isa("scalar");
            OcclusionBuffer reference(config);
            if (keep_before) reference.render(draws[2]);  // the list then draws onto what is there
            for (const ClusteredInput& d : draws) reference.render(d);
            EXPECT_GT(reference.stats().cluster_bands_hidden, 10u);
            EXPECT_GT(reference.stats().near_clipped, 0u);
            for (const std::string& isa : available_isas())
                for (const ParallelFor* jobs : {&shuffled, &tbb, &threads}) {
                    const test::ScopedIsa selected(isa);
                    OcclusionBuffer buffer(config);
                    if (keep_before) buffer.render(draws[2]);
                    else buffer.render(draws[5]);  // cleared by the list
                    buffer.begin_tasks(!keep_before);
                    for (const ClusteredInput& d : draws) buffer.record(d, jobs == &tbb ? tbb : ParallelFor{});
                    run_task_list(buffer, *jobs);
                    const std::string what = isa + (jobs == &shuffled ? ", shuffled" : jobs == &tbb ? ", TBB" : ", threads") + ", view " +
                                             std::to_string(view) + (keep_before ? ", onto a render" : ", cleared");
                    EXPECT_TRUE(reference.stats() == buffer.stats()) << what;
                    EXPECT_TRUE(test::same_subtiles(reference, buffer)) << what;
                    EXPECT_TRUE(test::same_pyramid(reference, buffer)) << what;
                }
        }
    }
}

// A task list keeps at most 65,536 set-up triangles for its bands (render_bands.hpp,
// kSetUpRoomTriangles): the clusters past them, nearest first, are set up by every band that
// draws them. 450 small walls of 162 triangles each (72,900 in view), staggered in depth so that
// far ones show between near ones: the task list, on threads and shuffled, gives the bits,
// statistics and pyramid of one render on one thread.
TEST(ClusteredRender, TaskListsPastTheSetUpPoolGiveTheBitsOfOneRender) {
    OccluderClusters clusters;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> across(-1.0f, 1.0f);
    for (int k = 0; k < 450; ++k) {
        const float z = -4.0f - 0.25f * float(k % 80), x = across(rng) * 0.8f * -z, y = across(rng) * 0.5f * -z;
        const float w = 0.04f * -z, h = 0.3f * -z;  // narrow: the ones behind show beside it
        std::vector<glm::vec3> vertices;
        std::vector<std::uint16_t> indices;
        for (int j = 0; j < 10; ++j)
            for (int i = 0; i < 10; ++i) vertices.push_back({x + w * float(i) / 9.0f, y + h * float(j) / 9.0f, z + 0.01f * float(i)});
        for (int j = 0; j < 9; ++j)
            for (int i = 0; i < 9; ++i) {
                const auto v = [&](int a, int b) { return std::uint16_t(10 * b + a); };
                indices.insert(indices.end(), {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j), v(i + 1, j + 1), v(i, j + 1)});
            }
        append_cluster(clusters, vertices, indices, std::vector<std::uint8_t>(indices.size() / 3, 0));
    }
    ASSERT_GT(clusters.shared_edges.size(), std::size_t(1) << 16);
    const Camera camera = test::camera_down_minus_z(90.0, 0.5);
    const ClusteredInput draw{&clusters, clip_from_world(camera, 16.0 / 9.0), Backface::none};
    const BufferConfig config = test::buffer_config(640, 360, 1, 0.5f, true);
    OcclusionBuffer reference(config);
    reference.render_frame(draw);
    EXPECT_EQ(reference.stats().clusters_outside, 0u);
    EXPECT_GT(reference.stats().cluster_bands_hidden, 50u);
    EXPECT_GT(reference.stats().cluster_bands_drawn, 450u);
    std::mt19937_64 order_rng(3);
    const ParallelFor shuffled{test::run_shuffled, &order_rng}, threads = test::thread_jobs(2);
    for (const ParallelFor* jobs : {&shuffled, &threads}) {
        OcclusionBuffer buffer(config);
        buffer.render_frame(draw, *jobs);
        const std::string what = jobs == &shuffled ? "shuffled" : "threads";
        EXPECT_TRUE(reference.stats() == buffer.stats()) << what;
        EXPECT_TRUE(test::same_subtiles(reference, buffer)) << what;
        EXPECT_TRUE(test::same_pyramid(reference, buffer)) << what;
    }
}

// Calls out of order are errors that change nothing; a task list whose tasks did not all run
// is an error, and the buffer then holds what ran (with its pyramid): conservative, and no row
// of the frame before when the list clears.
TEST(ClusteredRender, TaskListMisuseIsAnErrorAndMissingTasksStayConservative) {
    constexpr int kBandSampleRows = 32 * OcclusionBuffer::kSubtileHeight;  // a task's rows (render_bands.hpp)
    OccluderClusters clusters;
    for (int k = 0; k < 40; ++k) {
        const float x = -10.0f + 0.5f * float(k), z = -5.0f - 0.5f * float(k % 7);
        append_quad(clusters, {x - 2.0f, -8.0f, z}, {x + 2.0f, -8.0f, z}, {x + 2.0f, 8.0f, z}, {x - 2.0f, 8.0f, z});
    }
    const ClusteredInput draw{&clusters, clip_from_world(test::camera_down_minus_z(70.0, 0.5), 1.6), Backface::cw};
    const BufferConfig config = test::buffer_config(320, 300, 2, 0.5f);
    OcclusionBuffer buffer(config), full(config);
    full.render(draw);
    EXPECT_THROW(buffer.record(draw), Error);
    EXPECT_THROW((void)buffer.close_tasks(), Error);
    EXPECT_THROW(buffer.finish_tasks(), Error);
    buffer.run_task(0);  // no list: nothing happens
    buffer.begin_tasks();
    EXPECT_THROW(buffer.begin_tasks(), Error);
    EXPECT_THROW(buffer.render(draw), Error);
    ClusteredInput bad = draw;
    bad.cluster_ids = nullptr;
    bad.clusters = nullptr;
    EXPECT_THROW(buffer.record(bad), Error);
    buffer.record(draw);
    const std::size_t tasks = buffer.close_tasks();
    ASSERT_GE(tasks, 2u);
    EXPECT_THROW(buffer.record(draw), Error);
    buffer.run_task(tasks);  // out of range: ignored
    buffer.run_task(0);
    EXPECT_THROW(buffer.finish_tasks(), Error);  // the others did not run
    buffer.begin_tasks();  // the list is closed, whatever finish_tasks said
    buffer.finish_tasks(std::nothrow);
    std::vector<float> drawn, whole;
    buffer.read_depth(drawn);
    full.read_depth(whole);
    std::size_t claimed = 0;
    for (std::size_t i = 0; i < drawn.size(); ++i) {
        if (drawn[i] == INFINITY) continue;
        ++claimed;
        ASSERT_GE(drawn[i], whole[i]) << "sample " << i;  // never nearer than the whole render claims
        ASSERT_LT(i, std::size_t(kBandSampleRows) * std::size_t(buffer.sample_width())) << "only the first band ran";
    }
    EXPECT_GT(claimed, 0u);
    std::vector<float> pyramid;
    buffer.read_pyramid(pyramid);
    EXPECT_TRUE(pyramid == test::pyramid_by_definition(buffer));

    // A clearing list that did not run leaves none of the frame before.
    buffer.begin_tasks(true);
    buffer.record(draw);
    (void)buffer.close_tasks();
    buffer.run_task(1);
    EXPECT_THROW(buffer.finish_tasks(), Error);
    buffer.read_depth(drawn);
    for (std::size_t i = 0; i < std::size_t(kBandSampleRows) * std::size_t(buffer.sample_width()); ++i)
        ASSERT_EQ(drawn[i], INFINITY) << "sample " << i << " of the band that did not run";
    buffer.read_pyramid(pyramid);
    EXPECT_TRUE(pyramid == test::pyramid_by_definition(buffer));
}

// An orthographic view (BufferConfig::orthographic) of walls as clusters, indexed (through the
// vertex cache) and drawn with and without a job system: every instruction set gives the
// scalar bits, boxes behind the nearest wall are occluded and those before it visible, and a
// perspective input into it is refused.
TEST(ClusteredRender, OrthographicViewsGiveTheSameBitsEverywhereAndHideWhatIsBehind) {
    OccluderClusters clusters;
    for (int k = 0; k < 90; ++k) {
        const float x = -30.0f + 0.7f * float(k), z = -10.0f - 3.0f * float(k % 9), half = 1.0f + float(k % 5);
        append_quad(clusters, {x - half, -20.0f, z}, {x + half, -20.0f, z}, {x + half, 20.0f, z}, {x - half, 20.0f, z});
    }
    // Looking down -z from the origin at a 40 x 24 window, near 1, far 60 (OpenGL's z range).
    const std::array<float, 16> ortho = float_matrix(glm::ortho(-20.0, 20.0, -12.0, 12.0, 1.0, 60.0));
    BufferConfig config = test::buffer_config(333, 197, 2, 0.1f);
    config.orthographic = true;
    ClusteredInput in{&clusters, ortho, Backface::cw};
    in.orthographic = true;
    const test::ScopedIsa reference_isa("scalar");
    OcclusionBuffer reference(config);
    reference.render_frame(in);
    EXPECT_EQ(reference.config().near_w, 0.5f);  // the near plane's, whatever was asked
    EXPECT_GT(reference.stats().rasterized, 50u);
    std::mt19937_64 order_rng(2);
    const ParallelFor tbb = test::parallel_jobs(), shuffled{test::run_shuffled, &order_rng};
    for (const std::string& isa : available_isas())
        for (const ParallelFor& parallel : {ParallelFor{}, tbb, shuffled}) {
            const test::ScopedIsa selected(isa);
            OcclusionBuffer buffer(config);
            buffer.render_frame(in, parallel);
            EXPECT_TRUE(reference.stats() == buffer.stats()) << isa;
            EXPECT_TRUE(test::same_subtiles(reference, buffer)) << isa;
            EXPECT_TRUE(test::same_pyramid(reference, buffer)) << isa;
        }
    const auto box = [&](float z0, float z1) {
        const float lo[3] = {-2.0f, -2.0f, z0}, hi[3] = {2.0f, 2.0f, z1};
        return reference.test_aabb(lo, hi, ortho);
    };
    EXPECT_EQ(box(-50.0f, -45.0f), Visibility::occluded);  // behind every wall
    EXPECT_EQ(box(-8.0f, -5.0f), Visibility::visible);     // before them
    EXPECT_EQ(box(-3.0f, 0.5f), Visibility::visible);      // across the near plane (view z = -1)
    EXPECT_EQ(box(-0.5f, 3.0f), Visibility::view_culled);  // before it
    EXPECT_EQ(box(-200.0f, -190.0f), Visibility::visible);  // beyond twice the far distance: not answered
    ClusteredInput perspective = in;
    perspective.orthographic = false;
    EXPECT_THROW(reference.render(perspective), Error);
}

// More clusters than one placement task takes (64), drawn as a subset in another order, with
// empty clusters and clusters outside the view among them, frame after frame on the same
// buffers: every job system gives the serial bits and statistics (no shared scene needed).
TEST(ClusteredRender, ManyClustersGiveTheSameBitsWithAnyJobSystem) {
    OccluderClusters clusters;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> across(-12.0f, 12.0f), depth(-40.0f, -3.0f), half(0.3f, 3.0f);
    for (int k = 0; k < 230; ++k) {
        if (k % 29 == 0) {
            append_cluster(clusters, {}, {}, {});  // no triangles
            continue;
        }
        // Every 17th beside the view, every 23rd behind the eye.
        const float x = k % 17 == 0 ? 500.0f : across(rng), y = 0.6f * across(rng), z = k % 23 == 0 ? 20.0f : depth(rng), s = half(rng);
        append_quad(clusters, {x - s, y - s, z}, {x + s, y - s, z}, {x + s, y + s, z}, {x - s, y + s, z});
    }
    std::vector<std::uint32_t> ids(clusters.clusters.size());
    for (std::size_t k = 0; k < ids.size(); ++k) ids[k] = std::uint32_t(k);
    std::shuffle(ids.begin(), ids.end(), rng);
    const std::array<float, 16> m = clip_from_world(test::camera_down_minus_z(80.0, 0.5), 320.0 / 200.0);
    std::mt19937_64 order_rng(3);
    const ParallelFor tbb = test::parallel_jobs(), shuffled{test::run_shuffled, &order_rng};
    const BufferConfig config = test::buffer_config(320, 200, 2, 0.5f);
    OcclusionBuffer serial(config), threaded(config), shuffled_order(config);
    for (const std::size_t count : {std::size_t(197), std::size_t(70), ids.size()}) {
        ClusteredInput in{&clusters, m, Backface::cw};
        in.cluster_ids = ids.data();
        in.cluster_count = count;
        serial.render_frame(in);
        threaded.render_frame(in, tbb);
        shuffled_order.render_frame(in, shuffled);
        EXPECT_GT(serial.stats().clusters_outside, 0u) << count;
        EXPECT_GT(serial.stats().cluster_bands_hidden, 0u) << count;
        for (const OcclusionBuffer* b : {&threaded, &shuffled_order}) {
            EXPECT_TRUE(serial.stats() == b->stats()) << count;
            EXPECT_TRUE(test::same_subtiles(serial, *b)) << count;
            EXPECT_TRUE(test::same_pyramid(serial, *b)) << count;
        }
    }
}

// Wherever the clustered buffer claims an occluder, a ray through the sample's centre hits
// something at or before the buffer's depth (as FloatRowRule's test of the triangle path):
// castle views and fzk_haus, a full-size buffer and a 4 x 4-sample one.
TEST(ClusteredRender, ClaimedSamplesAreBehindEmbreeHits) {
    struct Case {
        std::string scene, role;
        std::vector<Camera> cameras;
    };
    std::vector<Case> cases;
    if (const CastleOccluders* c = castle()) cases.push_back({"intel_castle.glb", "occluder", {c->views.frames[0], c->views.frames[2]}});
    Camera house;
    house.eye = {-12, 3, 10};
    house.target = {6, 2, -5};
    cases.push_back({"fzk_haus.glb", "", {house}});
    long claimed = 0;
    for (const Case& k : cases) {
        const std::string path = test::shared_scene(k.scene);
        if (path.empty()) GTEST_SKIP() << k.scene << " is missing from " << test::shared_scenes_dir();
        const Scene scene = load_scene(path);
        const RayScene rays(scene);
        const OccluderClusters clusters = test::cluster_world(gather_world_triangles(scene, objects_with_role(scene, k.role)));
        for (const Camera& camera : k.cameras)
            for (const auto& [width, height, samples] : {std::tuple{640, 360, 1}, {160, 90, 4}}) {
                OcclusionBuffer buffer(test::buffer_config(width, height, samples, float(camera.near_plane)));
                buffer.render_frame(ClusteredInput{&clusters, clip_from_world(camera, double(width) / double(height)), Backface::cw});
                EXPECT_GT(buffer.stats().cluster_bands_drawn, 0u);
                claimed += test::expect_claims_behind_embree_hits(rays, camera, buffer, k.scene + " S = " + std::to_string(samples));
            }
    }
    EXPECT_GT(claimed, 100000);
}

}  // namespace
}  // namespace homcull
