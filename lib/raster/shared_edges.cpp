// Shared edges of a mesh, matched by position: two triangles share an edge when one has it
// from position A to position B and the other from B to A (consistent winding), bit for bit.
#include <homcull/detail/memory.hpp>
#include <homcull/error.hpp>
#include <homcull/triangle_input.hpp>

#include <array>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <vector>

namespace homcull {
namespace {

// An edge's two positions, lower first (lexicographically), as the bits of their floats with
// -0 made +0: equal keys are equal positions under float ==, which is what "the same
// position" has always meant here.
struct EdgeKey {
    std::array<std::uint32_t, 6> bits;
    bool operator==(const EdgeKey& o) const { return bits == o.bits; }
};

std::uint32_t float_key(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u == 0x80000000u ? 0u : u;
}

std::uint64_t hash(const EdgeKey& key) {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint32_t b : key.bits) {  // a multiply-xorshift step per word
        h = (h ^ b) * 0xBF58476D1CE4E5B9ull;
        h ^= h >> 31;
    }
    return h;
}

}  // namespace

// Edges are matched through a hash table of their keys rather than by sorting them: the scene
// culler runs this over every occluder of a scene at load time, and sorting sponza's 786,000
// edges was most of its setup.
void compute_shared_edges(const float* positions, std::size_t stride, std::size_t vertex_count,
                          const std::uint32_t* indices, std::size_t triangle_count, std::uint8_t* shared_edges,
                          std::uint32_t* edge_apexes) {
    if (triangle_count == 0) return;
    if (!positions || !shared_edges || !edge_apexes || stride < 3 * sizeof(float))
        throw Error("compute_shared_edges: positions or an output missing, or stride smaller than one position");
    struct Edge {
        EdgeKey key;
        std::uint32_t triangle;
        std::uint32_t apex;  // the vertex number of the triangle's third vertex (opposite this edge)
        std::uint8_t bit;
        bool reversed;   // the triangle runs from its higher position to its lower one
        std::uint8_t directions = 0;  // on the first edge of each key: 1 forward seen, 2 reversed seen
        std::uint32_t first = 0;      // the first edge with this key
        // On the first edge of each key: the apex of the first edge seen in each direction.
        std::uint32_t apex_of[2] = {kNoApex, kNoApex};
    };
    if (triangle_count > 0xFFFFFFFFull / 3)
        throw Error("compute_shared_edges: more than 2^32 / 3 triangles");
    auto position = [&](std::size_t v) {
        std::array<float, 3> p;
        std::memcpy(p.data(), reinterpret_cast<const unsigned char*>(positions) + std::size_t(v) * stride, sizeof p);
        return p;
    };
    detail::Vector<Edge> edges;
    edges.reserve(triangle_count * 3);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        shared_edges[t] = 0;
        for (int k = 0; k < 3; ++k) edge_apexes[3 * t + std::size_t(k)] = kNoApex;
        std::size_t v[3];
        for (int k = 0; k < 3; ++k) v[k] = indices ? indices[3 * t + std::size_t(k)] : 3 * t + std::size_t(k);
        if (v[0] >= vertex_count || v[1] >= vertex_count || v[2] >= vertex_count) continue;
        bool finite = true;  // such triangles are not drawn anyway
        for (int k = 0; k < 3; ++k)
            for (float c : position(v[k])) finite = finite && std::isfinite(c);
        if (!finite) continue;
        for (int k = 0; k < 3; ++k) {
            const auto a = position(v[k]), b = position(v[(k + 1) % 3]);
            if (a == b) continue;
            const bool reversed = b < a;
            const auto& lo = reversed ? b : a;
            const auto& hi = reversed ? a : b;
            Edge e{{{float_key(lo[0]), float_key(lo[1]), float_key(lo[2]), float_key(hi[0]), float_key(hi[1]), float_key(hi[2])}},
                   std::uint32_t(t), std::uint32_t(v[(k + 2) % 3]), std::uint8_t(1u << k), reversed};
            edges.push_back(e);
        }
    }

    // Open addressing, at most half full: slot = 1 + the first edge with that key, 0 = empty.
    std::size_t capacity = 16;
    while (capacity < 2 * edges.size()) capacity *= 2;
    detail::Vector<std::uint32_t> table(capacity, 0);
    for (std::size_t i = 0; i < edges.size(); ++i) {
        Edge& e = edges[i];
        for (std::size_t slot = hash(e.key) & (capacity - 1);; slot = (slot + 1) & (capacity - 1)) {
            if (table[slot] == 0) {
                table[slot] = std::uint32_t(i + 1);
                e.first = std::uint32_t(i);
                break;
            }
            if (edges[table[slot] - 1].key == e.key) {
                e.first = table[slot] - 1;
                break;
            }
        }
        Edge& first = edges[e.first];
        first.directions |= e.reversed ? 2u : 1u;
        if (first.apex_of[e.reversed] == kNoApex) first.apex_of[e.reversed] = e.apex;
    }
    // An edge is shared when its key was seen in the opposite direction too; its neighbour is
    // the first triangle seen the other way (on a non-manifold edge, any one of them will do: the
    // render keeps the flag only where that neighbour lies across the edge).
    for (const Edge& e : edges) {
        const Edge& first = edges[e.first];
        if (first.directions != 3u) continue;
        shared_edges[e.triangle] |= e.bit;
        edge_apexes[3 * std::size_t(e.triangle) + std::size_t(__builtin_ctz(e.bit))] = first.apex_of[!e.reversed];
    }
}

}  // namespace homcull
