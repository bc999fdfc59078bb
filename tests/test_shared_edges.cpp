// compute_shared_edges against its definition, checked pair by pair: an edge is shared when
// another edge of the mesh joins the same two positions (float ==) in the opposite direction.
#include <homcull/detail/memory.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
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

// Whether every flagged edge's apex is the third vertex of a triangle that has the edge the other
// way round, and every other edge's apex is kNoApex.
bool apexes_name_neighbours(const std::vector<Position>& positions, const std::vector<std::uint32_t>& indices,
                            const std::vector<std::uint8_t>& shared, const std::vector<std::uint32_t>& apexes) {
    const std::size_t triangles = indices.size() / 3;
    for (std::size_t t = 0; t < triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t apex = apexes[3 * t + std::size_t(k)];
            if (!((shared[t] >> k) & 1u)) {
                if (apex != homcull::kNoApex) return false;
                continue;
            }
            const Position& a = positions[indices[3 * t + std::size_t(k)]];
            const Position& b = positions[indices[3 * t + std::size_t((k + 1) % 3)]];
            bool found = false;
            for (std::size_t u = 0; u < triangles && !found; ++u) {
                const std::uint32_t* v = &indices[3 * u];
                if (v[0] >= positions.size() || v[1] >= positions.size() || v[2] >= positions.size()) continue;
                for (int j = 0; j < 3 && !found; ++j)
                    found = positions[v[j]] == b && positions[v[(j + 1) % 3]] == a && v[(j + 2) % 3] == apex;
            }
            if (!found) return false;
        }
    return true;
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
        std::vector<std::uint32_t> apexes(3 * triangles, 7);
        homcull::compute_shared_edges(positions[0].data(), sizeof(Position), positions.size(), indices.data(), triangles, shared.data(),
                                      apexes.data());
        const std::vector<std::uint8_t> expected = shared_edges_by_pairs(positions, indices);
        ASSERT_EQ(shared, expected) << "trial " << trial;
        ASSERT_TRUE(apexes_name_neighbours(positions, indices, shared, apexes)) << "trial " << trial;
        for (std::uint8_t bits : expected) shared_bits += std::bitset<8>(bits).count();
        checked += triangles;
    }
    // The meshes reach every case: most edges are shared, but far from all.
    EXPECT_GT(shared_bits, checked / 2);
    EXPECT_LT(shared_bits, checked * 3 * 9 / 10);
}

// A large mesh (a height field of 20,000 triangles over repeated heights, with some triangles
// wound the other way and some duplicated), so that the hash table grows far past the small
// meshes': against the definition computed by sorting the edges.
TEST(SharedEdges, MatchTheirDefinitionOnALargeMesh) {
    constexpr int kSide = 101;
    std::mt19937 rng(3);
    std::vector<Position> positions;
    for (int j = 0; j < kSide; ++j)
        for (int i = 0; i < kSide; ++i) positions.push_back({float(i), float(rng() % 3), float(j)});
    std::vector<std::uint32_t> indices;
    for (int j = 0; j + 1 < kSide; ++j)
        for (int i = 0; i + 1 < kSide; ++i) {
            const std::uint32_t a = std::uint32_t(j * kSide + i), b = a + 1, c = a + kSide + 1, d = a + kSide;
            indices.insert(indices.end(), {a, c, b, a, d, c});
            if (rng() % 10 == 0) std::swap(indices[indices.size() - 1], indices[indices.size() - 2]);  // wound the other way
            if (rng() % 20 == 0) indices.insert(indices.end(), {a, c, b});                             // a duplicate
        }
    const std::size_t triangles = indices.size() / 3;
    std::vector<std::uint8_t> shared(triangles, 0xFF);
    std::vector<std::uint32_t> apexes(3 * triangles);
    homcull::compute_shared_edges(positions[0].data(), sizeof(Position), positions.size(), indices.data(), triangles, shared.data(),
                                  apexes.data());
    EXPECT_TRUE(apexes_name_neighbours(positions, indices, shared, apexes));

    struct Edge {
        std::array<float, 6> key;  // lower position first
        bool reversed;
        std::size_t triangle;
        std::uint8_t bit;
    };
    std::vector<Edge> edges;
    for (std::size_t t = 0; t < triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            const Position& a = positions[indices[3 * t + std::size_t(k)]];
            const Position& b = positions[indices[3 * t + std::size_t((k + 1) % 3)]];
            const bool reversed = b < a;
            const Position& lo = reversed ? b : a;
            const Position& hi = reversed ? a : b;
            edges.push_back({{lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]}, reversed, t, std::uint8_t(1u << k)});
        }
    std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.key < y.key; });
    std::vector<std::uint8_t> expected(triangles, 0);
    for (std::size_t i = 0, j = 0; i < edges.size(); i = j) {
        bool forward = false, backward = false;
        for (j = i; j < edges.size() && edges[j].key == edges[i].key; ++j) (edges[j].reversed ? backward : forward) = true;
        if (forward && backward)
            for (std::size_t k = i; k < j; ++k) expected[edges[k].triangle] |= edges[k].bit;
    }
    EXPECT_EQ(shared, expected);
    std::size_t shared_bits = 0;
    for (std::uint8_t bits : expected) shared_bits += std::bitset<8>(bits).count();
    EXPECT_GT(shared_bits, 2 * triangles);      // most interior edges
    EXPECT_LT(shared_bits, 3 * triangles - 100);  // not the border, nor the flipped triangles' edges
}

// A closed mesh has every edge shared; an open one keeps its border; without indices the
// vertices 3t, 3t + 1, 3t + 2 are taken.
TEST(SharedEdges, ClosedAndOpenMeshes) {
    const std::vector<Position> tetrahedron = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const std::vector<std::uint32_t> closed = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
    std::vector<std::uint8_t> shared(4, 0);
    std::vector<std::uint32_t> apexes(12);
    homcull::compute_shared_edges(tetrahedron[0].data(), sizeof(Position), 4, closed.data(), 4, shared.data(), apexes.data());
    EXPECT_EQ(shared, std::vector<std::uint8_t>(4, 7));
    // Each edge's neighbour is the face across it: its apex is the vertex this face lacks.
    for (std::size_t t = 0; t < 4; ++t)
        for (std::size_t k = 0; k < 3; ++k) {
            const std::uint32_t* face = &closed[3 * t];
            EXPECT_TRUE(std::find(face, face + 3, apexes[3 * t + k]) == face + 3) << t << " " << k;
        }
    homcull::compute_shared_edges(tetrahedron[0].data(), sizeof(Position), 4, closed.data(), 3, shared.data(), apexes.data());
    EXPECT_EQ(shared_edges_by_pairs(tetrahedron, std::vector<std::uint32_t>(closed.begin(), closed.begin() + 9)),
              std::vector<std::uint8_t>(shared.begin(), shared.begin() + 3));

    const std::vector<Position> soup = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}};
    std::uint8_t soup_shared[2] = {0, 0};
    std::uint32_t soup_apexes[6];
    homcull::compute_shared_edges(soup[0].data(), sizeof(Position), soup.size(), nullptr, 2, soup_shared, soup_apexes);
    EXPECT_EQ(soup_shared[0], 2u);  // edge 1 -> 2 of the first triangle
    EXPECT_EQ(soup_shared[1], 1u);  // edge 0 -> 1 of the second
    EXPECT_EQ(soup_apexes[1], 5u);  // across it: the second triangle's vertex 2 (vertex 3 + 2)
    EXPECT_EQ(soup_apexes[3], 0u);  // and the first's vertex 0
    EXPECT_EQ(soup_apexes[0], homcull::kNoApex);
}

// Indices far apart (two triangles using vertices 0 to 2 and 2,000,000 of a large array): the
// positions are numbered index by index rather than over the whole range between them, so that
// the memory follows the triangles (the whole range would take some 70 MB here).
TEST(SharedEdges, FarApartIndicesTakeMemoryForTheTrianglesOnly) {
    constexpr std::uint32_t kFar = 2000000;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<Position> positions(kFar + 1, Position{nan, nan, nan});
    positions[0] = {0, 0, 0}, positions[1] = {1, 0, 0}, positions[2] = {1, 1, 0}, positions[kFar] = {0, 1, 0};
    const std::vector<std::uint32_t> indices = {0, 1, kFar, kFar, 1, 2};
    struct Counted {
        std::size_t bytes = 0;
    } counted;
    homcull::detail::MemoryHooks hooks;
    hooks.user = &counted;
    hooks.allocate = [](void* user, std::size_t size, std::size_t) -> void* {
        static_cast<Counted*>(user)->bytes += size;
        return std::aligned_alloc(64, (size + 63) / 64 * 64);
    };
    hooks.deallocate = [](void*, void* memory, std::size_t) { std::free(memory); };
    std::uint8_t shared[2] = {0xFF, 0xFF};
    std::uint32_t apexes[6];
    {
        const homcull::detail::MemoryScope scope(&hooks);
        homcull::compute_shared_edges(positions[0].data(), sizeof(Position), positions.size(), indices.data(), 2, shared, apexes);
    }
    EXPECT_EQ(shared[0], 2u);  // edge 1 -> far of the first triangle
    EXPECT_EQ(shared[1], 1u);  // edge far -> 1 of the second
    EXPECT_EQ(apexes[1], 2u);
    EXPECT_EQ(apexes[3], 0u);
    EXPECT_LT(counted.bytes, 4096u);
    EXPECT_GT(counted.bytes, 0u);  // the hooks were used: the count means something
}

}  // namespace
