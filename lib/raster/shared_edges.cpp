// Shared edges of a mesh, matched by position: two triangles share an edge when one has it
// from position A to position B and the other from B to A (consistent winding), bit for bit.
//
// In two steps, each touching memory in order where it can:
// 1. Number the positions the triangles use, equal positions (float ==, so -0 and +0 alike)
//    one number, through a hash table of the positions themselves.
// 2. Each edge goes to the bucket of its lower number (a counting sort, stable: within a
//    bucket the edges keep the mesh's order); within a bucket, the edges with the same higher
//    number are one edge of the mesh, met in one or both directions.
// An earlier version hashed every edge by its six floats (48 bytes an edge, read back at random
// at every probe): on sponza's 786,000 edges it took 180 ns an edge, most of the scene culler's
// setup; numbering the positions first leaves the edges 12 bytes each and in order.
#include <homcull/detail/memory.hpp>
#include <homcull/error.hpp>
#include <homcull/triangle_input.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace homcull {
namespace {

constexpr std::uint32_t kNoNumber = 0xFFFFFFFFu;

// A coordinate's bits with -0 made +0: equal bits are equal floats (no NaN gets here).
std::uint32_t float_key(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u == 0x80000000u ? 0u : u;
}

// A table of its own rather than meshoptimizer's meshopt_generateVertexRemap (which the scene
// layer uses to weld): the raster layer does not depend on meshoptimizer, whose allocations
// would also have to be routed to the engine's memory hooks here (homcull_mesh_create runs this
// inside them), and the remap compares bytes, so -0 and +0 would need a canonical copy first.
//
// Numbers for `count` positions (position(i, p) fills p and returns false when there is none):
// equal positions one number, numbers from 0 in the order the positions first appear;
// kNoNumber where there is no position or a coordinate is not finite (such triangles are not
// drawn, and share nothing). `numbers`: how many.
template <typename Position>
detail::Vector<std::uint32_t> number_positions(std::size_t count, const Position& position, std::uint32_t& numbers) {
    struct Slot {
        std::uint32_t key[3];
        std::uint32_t number_plus_one;  // 0: empty
    };
    std::size_t capacity = 16;
    int bits = 4;
    while (capacity < 2 * count) capacity *= 2, ++bits;
    detail::Vector<Slot> table(capacity, Slot{{0, 0, 0}, 0});
    detail::Vector<std::uint32_t> number(count, kNoNumber);
    numbers = 0;
    for (std::size_t i = 0; i < count; ++i) {
        float p[3];
        if (!position(i, p) || !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
        const std::uint32_t key[3] = {float_key(p[0]), float_key(p[1]), float_key(p[2])};
        // The slot from the hash's high bits: a float's low bits are often all 0 (whole numbers).
        std::uint64_t h = (std::uint64_t(key[0]) << 32 | key[1]) * 0x9E3779B97F4A7C15ull;
        h = (h ^ key[2] ^ (h >> 32)) * 0xBF58476D1CE4E5B9ull;
        for (std::size_t slot = std::size_t(h >> (64 - bits));; slot = (slot + 1) & (capacity - 1)) {
            Slot& s = table[slot];
            if (s.number_plus_one == 0) {
                std::memcpy(s.key, key, sizeof key);
                s.number_plus_one = ++numbers;
                number[i] = numbers - 1;
                break;
            }
            if (std::memcmp(s.key, key, sizeof key) == 0) {
                number[i] = s.number_plus_one - 1;
                break;
            }
        }
    }
    return number;
}

}  // namespace

void compute_shared_edges(const float* positions, std::size_t stride, std::size_t vertex_count,
                          const std::uint32_t* indices, std::size_t triangle_count, std::uint8_t* shared_edges,
                          std::uint32_t* edge_apexes) {
    if (triangle_count == 0) return;
    if (!positions || !shared_edges || !edge_apexes || stride < 3 * sizeof(float))
        throw Error("compute_shared_edges: positions or an output missing, or stride smaller than one position");
    if (triangle_count > 0xFFFFFFFFull / 3)
        throw Error("compute_shared_edges: more than 2^32 / 3 triangles");
    const auto vertex = [&](std::size_t i) -> std::size_t { return indices ? indices[i] : i; };

    // The vertices the triangles use lie within [low, high]. Numbered vertex by vertex when that
    // range is not much longer than the triangles' indices (a caller may pass one object's
    // triangles with a whole scene's positions, as the scene culler does: only the object's are
    // numbered), else index by index, so that memory follows the triangles whatever the indices.
    std::size_t low = vertex_count, high = 0;
    for (std::size_t i = 0; i < 3 * triangle_count; ++i) {
        const std::size_t v = vertex(i);
        if (v < vertex_count) low = std::min(low, v), high = std::max(high, v);
    }
    const bool by_vertex = low <= high && high - low < 2 * 3 * triangle_count;
    const auto position_of = [&](std::size_t v, float* p) {
        if (v >= vertex_count) return false;
        std::memcpy(p, reinterpret_cast<const unsigned char*>(positions) + v * stride, 3 * sizeof(float));
        return true;
    };
    std::uint32_t numbers = 0;
    const detail::Vector<std::uint32_t> number =
        by_vertex ? number_positions(high - low + 1, [&](std::size_t i, float* p) { return position_of(low + i, p); }, numbers)
                  : number_positions(3 * triangle_count, [&](std::size_t i, float* p) { return position_of(vertex(i), p); }, numbers);
    // Each corner's position number, once for both passes below: kNoNumber at every corner of a
    // triangle with a corner unnumbered (such a triangle has no edge).
    detail::Vector<std::uint32_t> corner_number(3 * triangle_count);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        std::uint32_t n[3];
        for (std::size_t k = 0; k < 3; ++k) {
            const std::size_t i = 3 * t + k, v = vertex(i);
            n[k] = v >= vertex_count ? kNoNumber : by_vertex ? number[v - low] : number[i];
        }
        const bool usable = n[0] != kNoNumber && n[1] != kNoNumber && n[2] != kNoNumber;
        for (std::size_t k = 0; k < 3; ++k) corner_number[3 * t + k] = usable ? n[k] : kNoNumber;
    }

    // Each edge of a triangle whose three vertices are numbered, between two different
    // positions, into the bucket of its lower number.
    detail::Vector<std::uint32_t> bucket_first(std::size_t(numbers) + 1, 0);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        shared_edges[t] = 0;
        for (std::size_t k = 0; k < 3; ++k) edge_apexes[3 * t + k] = kNoApex;
        if (corner_number[3 * t] == kNoNumber) continue;
        for (std::size_t k = 0; k < 3; ++k) {
            const std::uint32_t a = corner_number[3 * t + k], b = corner_number[3 * t + (k + 1) % 3];
            if (a != b) ++bucket_first[std::min(a, b) + 1];
        }
    }
    for (std::size_t n = 0; n < numbers; ++n) bucket_first[n + 1] += bucket_first[n];
    struct BucketEdge {
        std::uint32_t higher;  // the higher number of its two positions
        std::uint32_t edge;    // 3 x triangle + k: the triangle's edge from vertex k to k + 1
        std::uint32_t upward;  // 1: from the lower number to the higher one
    };
    detail::Vector<BucketEdge> edges(bucket_first[numbers]);
    {
        detail::Vector<std::uint32_t> fill(bucket_first.begin(), bucket_first.end() - 1);
        for (std::size_t t = 0; t < triangle_count; ++t) {
            if (corner_number[3 * t] == kNoNumber) continue;
            for (std::size_t k = 0; k < 3; ++k) {
                const std::uint32_t a = corner_number[3 * t + k], b = corner_number[3 * t + (k + 1) % 3];
                if (a != b) edges[fill[std::min(a, b)]++] = {std::max(a, b), std::uint32_t(3 * t + k), a < b ? 1u : 0u};
            }
        }
    }

    // Within a bucket, the edges joining the same two positions, in the mesh's order (sorted by
    // the higher number, then the edge: std::sort allocates nothing, unlike std::stable_sort,
    // and a bucket holds a handful of edges): such an edge is shared when met in both
    // directions, and its neighbour is the first triangle met the other way (on a non-manifold
    // edge, any one of them will do: the render keeps the flag only where that neighbour lies
    // across the edge).
    for (std::size_t n = 0; n < numbers; ++n) {
        BucketEdge* begin = edges.data() + bucket_first[n];
        BucketEdge* end = edges.data() + bucket_first[n + 1];
        std::sort(begin, end, [](const BucketEdge& x, const BucketEdge& y) { return x.higher != y.higher ? x.higher < y.higher : x.edge < y.edge; });
        for (BucketEdge* group = begin; group != end;) {
            BucketEdge* group_end = group;
            std::uint32_t apex_of[2] = {kNoApex, kNoApex};  // the apex of the first edge met each way
            for (; group_end != end && group_end->higher == group->higher; ++group_end) {
                std::uint32_t& apex = apex_of[group_end->upward];
                if (apex == kNoApex) {
                    const std::size_t t = group_end->edge / 3, k = group_end->edge % 3;
                    apex = std::uint32_t(vertex(3 * t + (k + 2) % 3));
                }
            }
            if (apex_of[0] != kNoApex && apex_of[1] != kNoApex)
                for (const BucketEdge* e = group; e != group_end; ++e) {
                    shared_edges[e->edge / 3] |= std::uint8_t(1u << (e->edge % 3));
                    edge_apexes[e->edge] = apex_of[!e->upward];
                }
            group = group_end;
        }
    }
}

}  // namespace homcull
