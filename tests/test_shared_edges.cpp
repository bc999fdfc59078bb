// compute_shared_edges against its definition, checked pair by pair: an edge is shared when
// another edge of the mesh joins the same two positions (float ==) in the opposite direction.
#include <homcull/occlusion_buffer.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace {

using Position = std::array<float, 3>;

// The definition, in O(edges^2): for tests only.
std::vector<std::uint8_t> shared_edges_by_pairs(const std::vector<Position>& positions, const std::vector<std::uint32_t>& indices) {
    struct Edge {
        Position from, to;
        std::size_t triangle;
        std::uint8_t bit;
    };
    const std::size_t triangles = indices.size() / 3;
    std::vector<Edge> edges;
    for (std::size_t t = 0; t < triangles; ++t) {
        const std::uint32_t* v = &indices[3 * t];
        if (v[0] >= positions.size() || v[1] >= positions.size() || v[2] >= positions.size()) continue;
        bool finite = true;
        for (int k = 0; k < 3; ++k)
            for (float c : positions[v[k]]) finite = finite && std::isfinite(c);
        if (!finite) continue;
        for (int k = 0; k < 3; ++k) {
            const Position& a = positions[v[k]];
            const Position& b = positions[v[(k + 1) % 3]];
            if (a != b) edges.push_back({a, b, t, std::uint8_t(1u << k)});
        }
    }
    std::vector<std::uint8_t> shared(triangles, 0);
    for (const Edge& e : edges)
        for (const Edge& o : edges)
            if (e.from == o.to && e.to == o.from) {
                shared[e.triangle] |= e.bit;
                break;
            }
    return shared;
}

// A random mesh over few distinct positions, so that edges repeat in both directions, in the
// same direction, and around non-manifold fans; with -0 beside +0, degenerate triangles, a few
// non-finite positions and indices out of range.
void random_mesh(std::mt19937& rng, std::vector<Position>& positions, std::vector<std::uint32_t>& indices) {
    std::uniform_int_distribution<int> coordinate(-2, 2);
    std::uniform_int_distribution<int> percent(0, 99);
    const int distinct = 4 + int(rng() % 12);
    positions.clear();
    for (int i = 0; i < distinct; ++i) {
        Position p{float(coordinate(rng)), float(coordinate(rng)), float(coordinate(rng))};
        for (float& c : p)
            if (c == 0.0f && percent(rng) < 50) c = -0.0f;
        if (percent(rng) < 5) p[std::size_t(rng() % 3)] = percent(rng) < 50 ? NAN : INFINITY;
        positions.push_back(p);
    }
    indices.clear();
    const int triangles = 1 + int(rng() % 40);
    for (int t = 0; t < triangles * 3; ++t) {
        std::uint32_t v = std::uint32_t(rng() % std::uint32_t(distinct));
        if (percent(rng) < 2) v = std::uint32_t(distinct) + 5;  // out of range
        indices.push_back(v);
    }
}

TEST(SharedEdges, MatchTheirDefinitionOnRandomMeshes) {
    std::mt19937 rng(7);
    std::size_t shared_bits = 0, checked = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        std::vector<Position> positions;
        std::vector<std::uint32_t> indices;
        random_mesh(rng, positions, indices);
        const std::size_t triangles = indices.size() / 3;
        std::vector<std::uint8_t> shared(triangles, 0xFF);
        homcull::compute_shared_edges(positions[0].data(), sizeof(Position), positions.size(), indices.data(), triangles, shared.data());
        const std::vector<std::uint8_t> expected = shared_edges_by_pairs(positions, indices);
        ASSERT_EQ(shared, expected) << "trial " << trial;
        for (std::uint8_t bits : expected) shared_bits += std::size_t(__builtin_popcount(bits));
        checked += triangles;
    }
    // The meshes reach every case: most edges are shared, but far from all.
    EXPECT_GT(shared_bits, checked / 2);
    EXPECT_LT(shared_bits, checked * 3 * 9 / 10);
}

// A closed mesh has every edge shared; an open one keeps its border; without indices the
// vertices 3t, 3t + 1, 3t + 2 are taken.
TEST(SharedEdges, ClosedAndOpenMeshes) {
    const std::vector<Position> tetrahedron = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const std::vector<std::uint32_t> closed = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
    std::vector<std::uint8_t> shared(4, 0);
    homcull::compute_shared_edges(tetrahedron[0].data(), sizeof(Position), 4, closed.data(), 4, shared.data());
    EXPECT_EQ(shared, std::vector<std::uint8_t>(4, 7));
    homcull::compute_shared_edges(tetrahedron[0].data(), sizeof(Position), 4, closed.data(), 3, shared.data());
    EXPECT_EQ(shared_edges_by_pairs(tetrahedron, std::vector<std::uint32_t>(closed.begin(), closed.begin() + 9)),
              std::vector<std::uint8_t>(shared.begin(), shared.begin() + 3));

    const std::vector<Position> soup = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}};
    std::uint8_t soup_shared[2] = {0, 0};
    homcull::compute_shared_edges(soup[0].data(), sizeof(Position), soup.size(), nullptr, 2, soup_shared);
    EXPECT_EQ(soup_shared[0], 2u);  // edge 1 -> 2 of the first triangle
    EXPECT_EQ(soup_shared[1], 1u);  // edge 0 -> 1 of the second
}

}  // namespace
