#include "raster/triangle_batch.hpp"

#include <cstring>

namespace homcull::detail {
namespace {

// The three indices of lanes [0, count), and the indices_valid bits.
template <typename Index>
std::uint32_t read_indices(const Index* indices, std::size_t first, int count, std::size_t vertex_count,
                           std::uint32_t (&index)[3][TriangleBatch::kSize]) {
    std::uint32_t valid = 0;
    for (int t = 0; t < count; ++t) {
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            const std::size_t n = 3 * (first + std::size_t(t)) + std::size_t(k);
            index[k][t] = indices ? std::uint32_t(indices[n]) : std::uint32_t(n);
            ok = ok && index[k][t] < vertex_count;
        }
        valid |= std::uint32_t(ok) << t;
    }
    return valid;
}

}  // namespace

void gather_triangle_batch(const TriangleInput& in, std::size_t first, int count, TriangleBatch& batch) {
    std::uint32_t index[3][TriangleBatch::kSize];
    if (!in.indices) batch.indices_valid = read_indices<std::uint32_t>(nullptr, first, count, in.vertex_count, index);
    else if (in.indices_16bit)
        batch.indices_valid = read_indices(static_cast<const std::uint16_t*>(in.indices), first, count, in.vertex_count, index);
    else batch.indices_valid = read_indices(static_cast<const std::uint32_t*>(in.indices), first, count, in.vertex_count, index);

    const auto* bytes = static_cast<const unsigned char*>(in.positions);
    const bool has_w = in.position_components == 4;
    for (int k = 0; k < 3; ++k)
        for (int t = 0; t < TriangleBatch::kSize; ++t) {
            // Lanes without valid indices (and past count) read nothing: the origin.
            float p[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            if ((batch.indices_valid >> t) & 1u) {
                // Fixed-size copies (the stride need not keep floats aligned; a copy of a
                // run-time size goes through a library call and stalls the loads after it).
                const unsigned char* vertex = bytes + std::size_t(index[k][t]) * in.position_stride;
                std::memcpy(p, vertex, 3 * sizeof(float));
                if (has_w) std::memcpy(&p[3], vertex + 3 * sizeof(float), sizeof(float));
            }
            batch.px[k][t] = p[0], batch.py[k][t] = p[1], batch.pz[k][t] = p[2], batch.pw[k][t] = p[3];
        }
}

void classify_triangle_batch_reference(const TriangleInput& in, double near_w, int count, TriangleBatch& batch, RasterStats& stats) {
    batch.needs_setup = 0;
    for (int t = 0; t < count; ++t) {
        glm::dvec4 clip[3];
        bool finite = true;
        for (int k = 0; k < 3; ++k) {
            clip[k] = transform_to_clip(in.model_to_clip, batch.px[k][t], batch.py[k][t], batch.pz[k][t], batch.pw[k][t]);
            batch.cx[k][t] = clip[k].x, batch.cy[k][t] = clip[k].y, batch.cz[k][t] = clip[k].z, batch.cw[k][t] = clip[k].w;
            finite = finite && finite_clip(clip[k]);
        }
        const TriangleFate fate =
            !((batch.indices_valid >> t) & 1u) || !finite ? TriangleFate::invalid : unclipped_fate(clip, in.backface, near_w);
        switch (fate) {
        case TriangleFate::invalid: ++stats.invalid; break;
        case TriangleFate::outside: ++stats.outside; break;
        case TriangleFate::degenerate: ++stats.degenerate; break;
        case TriangleFate::backfacing: ++stats.backface_culled; break;
        case TriangleFate::needs_setup: batch.needs_setup |= 1u << t; break;
        }
    }
}

}  // namespace homcull::detail
