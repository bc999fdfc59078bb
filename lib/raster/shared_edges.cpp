// Shared edges of a mesh, matched by position: two triangles share an edge when one has it
// from position A to position B and the other from B to A (consistent winding), bit for bit.
#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

namespace homcull {

void compute_shared_edges(const float* positions, std::size_t stride, std::size_t vertex_count,
                          const std::uint32_t* indices, std::size_t triangle_count, std::uint8_t* shared_edges) {
    if (triangle_count == 0) return;
    if (!positions || !shared_edges || stride < 3 * sizeof(float))
        throw Error("compute_shared_edges: positions or output missing, or stride smaller than one position");
    struct Edge {
        std::array<float, 6> key;  // from, to (from < to lexicographically)
        bool reversed;             // the triangle runs to -> from
        std::size_t triangle;
        std::uint8_t bit;
    };
    auto position = [&](std::size_t v) {
        std::array<float, 3> p;
        std::memcpy(p.data(), reinterpret_cast<const unsigned char*>(positions) + std::size_t(v) * stride, sizeof p);
        return p;
    };
    std::vector<Edge> edges;
    edges.reserve(triangle_count * 3);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        shared_edges[t] = 0;
        std::size_t v[3];
        for (int k = 0; k < 3; ++k) v[k] = indices ? indices[3 * t + std::size_t(k)] : 3 * t + std::size_t(k);
        if (v[0] >= vertex_count || v[1] >= vertex_count || v[2] >= vertex_count) continue;
        bool finite = true;  // NaN would break the sort's ordering; such triangles are not drawn anyway
        for (int k = 0; k < 3; ++k)
            for (float c : position(v[k])) finite = finite && std::isfinite(c);
        if (!finite) continue;
        for (int k = 0; k < 3; ++k) {
            const auto a = position(v[k]), b = position(v[(k + 1) % 3]);
            if (a == b) continue;
            const bool reversed = b < a;
            const auto& lo = reversed ? b : a;
            const auto& hi = reversed ? a : b;
            edges.push_back({{lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]}, reversed, t, std::uint8_t(1u << k)});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.key < y.key; });
    // Within a run of equal edges, each edge is shared if the run holds the opposite direction.
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i;
        bool forward = false, backward = false;
        while (j < edges.size() && edges[j].key == edges[i].key) {
            (edges[j].reversed ? backward : forward) = true;
            ++j;
        }
        if (forward && backward)
            for (std::size_t k = i; k < j; ++k) shared_edges[edges[k].triangle] |= edges[k].bit;
        i = j;
    }
}

}  // namespace homcull
