// merge_coplanar_triangles: fewer triangles over exactly the same points. Flat grids become
// two triangles, a crease between two planes keeps one edge on both sides, anything not exactly
// flat (a vertex one float step off the plane) or not representable on a 40-bit grid stays, and
// on the OpenArena maps the triangles halve while every object's area and bounds stay.
#include "scene/coplanar_merge.hpp"

#include "support.hpp"

#include <homcull/io/scene_io.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

namespace homcull {
namespace {

struct Soup {
    std::vector<float> positions;
    std::vector<std::uint32_t> triangles;
    std::uint32_t add(glm::vec3 p) {
        positions.insert(positions.end(), {p.x, p.y, p.z});
        return std::uint32_t(positions.size() / 3 - 1);
    }
    // An n x m grid of quads from `origin` along u and v (2 triangles each, counter-clockwise
    // seen from u x v), its vertices shared; with notch, the quads i, j >= notch left out (an
    // L-shaped region, its inner corner concave).
    void grid(glm::vec3 origin, glm::vec3 u, glm::vec3 v, int n, int m, int notch = 1 << 20) {
        std::vector<std::uint32_t> ids;
        for (int j = 0; j <= m; ++j)
            for (int i = 0; i <= n; ++i) ids.push_back(add(origin + float(i) * u + float(j) * v));
        const auto at = [&](int i, int j) { return ids[std::size_t(j * (n + 1) + i)]; };
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < n; ++i)
                if (i < notch || j < notch)
                triangles.insert(triangles.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
    glm::dvec3 vertex(std::uint32_t i) const { return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]}; }
    glm::dvec3 normal(std::size_t t) const {
        return glm::cross(vertex(triangles[3 * t + 1]) - vertex(triangles[3 * t]), vertex(triangles[3 * t + 2]) - vertex(triangles[3 * t]));
    }
    // Area and area-weighted normal of triangles[0, count): the same region gives the same
    // sums, and a triangle folded over another adds to the area, not to the vector.
    double area(std::size_t count) const {
        double sum = 0.0;
        for (std::size_t t = 0; t < count; ++t) sum += 0.5 * glm::length(normal(t));
        return sum;
    }
    glm::dvec3 area_vector(std::size_t count) const {
        glm::dvec3 sum(0.0);
        for (std::size_t t = 0; t < count; ++t) sum += 0.5 * normal(t);
        return sum;
    }
    std::size_t merge(const std::uint8_t* keep = nullptr) {
        return detail::merge_coplanar_triangles(positions.data(), triangles.data(), triangles.size() / 3, keep);
    }
};

TEST(CoplanarMerge, FlatGridBecomesTwoTriangles) {
    Soup s;
    s.grid({1.5f, -2.0f, 0.25f}, {0.5f, 0.0f, 0.25f}, {0.0f, 0.75f, 0.0f}, 6, 5);  // a tilted plane
    const glm::dvec3 before = s.area_vector(s.triangles.size() / 3);
    const std::size_t kept = s.merge();
    EXPECT_EQ(kept, 2u);
    const glm::dvec3 after = s.area_vector(kept);
    EXPECT_NEAR(glm::length(after - before), 0.0, 1e-9 * glm::length(before));
    // Its corners, and nothing else.
    std::set<std::uint32_t> used(s.triangles.begin(), s.triangles.begin() + std::ptrdiff_t(3 * kept));
    EXPECT_EQ(used, (std::set<std::uint32_t>{0, 6, 35, 41}));

    // An L-shaped region: the collapses that would fold a triangle over its neighbours (towards
    // the concave corner) are passed over, and it ends as few triangles as its six corners allow.
    Soup l;
    l.grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 6, 6, 3);
    const double area = l.area(l.triangles.size() / 3);
    const std::size_t l_kept = l.merge();
    EXPECT_EQ(l_kept, 4u);
    EXPECT_NEAR(l.area(l_kept), area, 1e-12 * area);
    for (std::size_t t = 0; t < l_kept; ++t) EXPECT_GT(l.normal(t).z, 0.0) << "triangle " << t << " faces away";
}

TEST(CoplanarMerge, CreaseBetweenTwoPlanesKeepsOneEdgeOnBothSides) {
    Soup s;
    s.grid({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, 4, 3);  // a floor, facing up
    s.grid({0, 0, -3}, {1, 0, 0}, {0, 1, 0}, 4, 2);  // a wall standing on its far edge, facing +z
    const std::size_t kept = s.merge();
    EXPECT_EQ(kept, 4u);
    // Every edge drawn is used by two triangles in opposite directions, or lies on the outline:
    // no vertex left in the middle of another triangle's edge (a T-junction, a crack).
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::size_t t = 0; t < kept; ++t)
        for (int e = 0; e < 3; ++e) ++edges[{s.triangles[3 * t + std::size_t(e)], s.triangles[3 * t + std::size_t((e + 1) % 3)]}];
    const std::uint32_t crease_left = 15, crease_right = 19;  // floor vertices (0, 0, -3) and (4, 0, -3)
    const bool floor_way = edges.count({crease_left, crease_right}) + edges.count({crease_right, crease_left}) > 0;
    EXPECT_TRUE(floor_way) << "the crease is one edge";
    std::set<std::uint32_t> used(s.triangles.begin(), s.triangles.begin() + std::ptrdiff_t(3 * kept));
    for (const std::uint32_t v : used) {
        const glm::dvec3 p = s.vertex(v);
        EXPECT_TRUE((p.x == 0 || p.x == 4) && (p.z == 0 || p.z == -3) && (p.y == 0 || p.y == 2)) << p.x << ", " << p.y << ", " << p.z;
    }
}

// A vertex marked to stay (one another mesh uses) stays, and the straight edges through it keep
// it: the neighbour's edges still match these.
TEST(CoplanarMerge, VerticesMarkedToStayStay) {
    Soup s;
    s.grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 4, 1);  // vertices 0..4 along y = 0, 5..9 along y = 1
    std::vector<std::uint8_t> keep(s.positions.size() / 3, 0);
    keep[2] = 1;  // the middle of the lower edge, shared with a mesh below
    const std::size_t kept = s.merge(keep.data());
    EXPECT_EQ(kept, 3u);
    std::set<std::uint32_t> used(s.triangles.begin(), s.triangles.begin() + std::ptrdiff_t(3 * kept));
    EXPECT_EQ(used, (std::set<std::uint32_t>{0, 2, 4, 5, 9}));
}

TEST(CoplanarMerge, WhatIsNotExactlyFlatOrOnAGridStays) {
    Soup bent;
    bent.grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 3, 3);
    bent.positions[3 * 5 + 2] = std::nextafter(0.0f, 1.0f);  // vertex (1, 1) one float step off the plane
    const std::size_t kept = bent.merge();
    EXPECT_GT(kept, 2u);
    // The vertex off the plane keeps every triangle it had (6 of the 18).
    std::size_t at_bent = 0;
    for (std::size_t t = 0; t < kept; ++t)
        for (int e = 0; e < 3; ++e) at_bent += bent.triangles[3 * t + std::size_t(e)] == 5;
    EXPECT_EQ(at_bent, 6u);

    // A grid that needs more than 40 bits: 1e6 wide with a 2^-30 step in it.
    Soup wide;
    wide.grid({0, 0, 0}, {1 << 20, 0, 0}, {0, 1, 0}, 2, 2);
    wide.positions[0] = 0x1.0p-30f;
    const std::size_t count = wide.triangles.size() / 3;
    EXPECT_EQ(wide.merge(), count);
    // Degenerate triangles and their vertices stay; fewer than two triangles: nothing to do.
    Soup degenerate;
    degenerate.grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 2, 1);
    degenerate.triangles.insert(degenerate.triangles.end(), {1, 1, 4});
    EXPECT_GT(degenerate.merge(), 2u);
    Soup one;
    one.grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1, 1);
    EXPECT_EQ(detail::merge_coplanar_triangles(one.positions.data(), one.triangles.data(), 1), 1u);
}

// The OpenArena maps, merged as the scene culler merges them (gather_world_triangles): about
// half the triangles (brush splits), each object's area vector and bounds unchanged, and the
// edges between objects still shared along all their length (no crack between objects).
TEST(CoplanarMerge, OpenArenaMapsHalveAndEachObjectKeepsItsSurface) {
    const std::string file = test::shared_scene("openarena_pul1duel-oa.glb");
    if (file.empty()) GTEST_SKIP() << "openarena_pul1duel-oa.glb is missing from " << test::shared_scenes_dir();
    const Scene scene = load_scene(file);
    const std::vector<std::uint32_t> all = objects_with_role(scene, "");
    const WorldTriangles original = gather_world_triangles(scene, all), merged = gather_world_triangles(scene, all, glm::dvec3(0.0), true);
    ASSERT_EQ(merged.object_first_triangle.size(), all.size() + 1);
    EXPECT_LT(merged.triangle_count(), original.triangle_count() * 60 / 100);
    EXPECT_EQ(merged.positions, original.positions);
    const auto vertex = [](const WorldTriangles& w, std::size_t i) {
        return glm::dvec3(w.positions[3 * w.indices[i]], w.positions[3 * w.indices[i] + 1], w.positions[3 * w.indices[i] + 2]);
    };
    // Undirected edges by their end positions, and the objects that have each.
    using Position = std::array<float, 3>;
    const auto edges_of_objects = [&](const WorldTriangles& w) {
        std::map<std::pair<Position, Position>, std::set<std::size_t>> edges;
        for (std::size_t k = 0; k < all.size(); ++k)
            for (std::size_t t = w.object_first_triangle[k]; t < w.object_first_triangle[k + 1]; ++t)
                for (std::size_t e = 0; e < 3; ++e) {
                    const std::uint32_t a = w.indices[3 * t + e], b = w.indices[3 * t + (e + 1) % 3];
                    Position pa{w.positions[3 * a], w.positions[3 * a + 1], w.positions[3 * a + 2]};
                    Position pb{w.positions[3 * b], w.positions[3 * b + 1], w.positions[3 * b + 2]};
                    if (pb < pa) std::swap(pa, pb);
                    edges[{pa, pb}].insert(k);
                }
        return edges;
    };
    // Every edge two objects shared (the same two vertices on both sides) still lies within an
    // edge two objects share: a vertex gone from one side only would leave its edges unmatched,
    // a crack. (The merge may match more: a side's vertex in the middle of the other's edge, a
    // T-junction, may go.)
    const auto shared_segments = [](const auto& edges) {
        std::vector<std::pair<glm::dvec3, glm::dvec3>> segments;
        for (const auto& [edge, owners] : edges)
            if (owners.size() >= 2)
                segments.push_back({glm::dvec3(edge.first[0], edge.first[1], edge.first[2]), glm::dvec3(edge.second[0], edge.second[1], edge.second[2])});
        return segments;
    };
    const auto before = shared_segments(edges_of_objects(original)), after = shared_segments(edges_of_objects(merged));
    EXPECT_GT(before.size(), 1000u);
    std::size_t lost = 0;
    for (const auto& segment : before) {
        const glm::dvec3 p = segment.first, q = segment.second;  // named, not bound: the lambda takes them
        const bool within = std::any_of(after.begin(), after.end(), [&](const auto& s) {
            const glm::dvec3 d = s.second - s.first;
            const double length2 = glm::dot(d, d);
            const auto on = [&](const glm::dvec3& x) {
                const double t = glm::dot(x - s.first, d) / length2;
                return t >= -1e-12 && t <= 1 + 1e-12 && glm::length(glm::cross(x - s.first, d)) <= 1e-9 * length2;
            };
            return on(p) && on(q);
        });
        lost += !within;
    }
    EXPECT_EQ(lost, 0u) << "edges between objects lost their twin";
    for (std::size_t k = 0; k < all.size(); ++k) {
        glm::dvec3 area[2] = {glm::dvec3(0.0), glm::dvec3(0.0)}, lo[2], hi[2];
        double unsigned_area[2] = {0.0, 0.0};
        for (int which = 0; which < 2; ++which) {
            const WorldTriangles& w = which ? merged : original;
            lo[which] = glm::dvec3(HUGE_VAL), hi[which] = glm::dvec3(-HUGE_VAL);
            for (std::size_t t = w.object_first_triangle[k]; t < w.object_first_triangle[k + 1]; ++t) {
                const glm::dvec3 a = vertex(w, 3 * t), b = vertex(w, 3 * t + 1), c = vertex(w, 3 * t + 2);
                area[which] += glm::cross(b - a, c - a);
                unsigned_area[which] += glm::length(glm::cross(b - a, c - a));
                for (const glm::dvec3& p : {a, b, c}) lo[which] = glm::min(lo[which], p), hi[which] = glm::max(hi[which], p);
            }
        }
        EXPECT_NEAR(glm::length(area[1] - area[0]), 0.0, 1e-9 * (glm::length(area[0]) + 1.0)) << "object " << all[k];
        EXPECT_NEAR(unsigned_area[1], unsigned_area[0], 1e-9 * (unsigned_area[0] + 1.0)) << "object " << all[k] << ": a fold";
        if (original.object_first_triangle[k + 1] > original.object_first_triangle[k]) {
            EXPECT_EQ(lo[1], lo[0]) << "object " << all[k];
            EXPECT_EQ(hi[1], hi[0]) << "object " << all[k];
        }
    }
}

}  // namespace
}  // namespace homcull
