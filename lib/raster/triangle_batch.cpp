#include "raster/triangle_batch.hpp"

#include <cmath>
#include <utility>

namespace homcull::detail {
namespace {

template <typename Index>
std::uint32_t read_indices(const Index* indices, const std::size_t* triangle, int count, std::size_t vertex_count,
                           std::uint32_t (&index)[3][TriangleBatch::kSize]) {
    std::uint32_t valid = 0;
    for (int t = 0; t < count; ++t) {
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            index[k][t] = vertex_index(indices, triangle[t], k);
            ok = ok && index[k][t] < vertex_count;
        }
        valid |= std::uint32_t(ok) << t;
    }
    return valid;
}

template <typename Index>
std::size_t gather_cached(const Index* indices, const TriangleInput& in, const VertexClip& cache, std::size_t first, std::size_t end,
                          TriangleBatch& batch, RasterStats& stats) {
    // Counters, the vertex count and the cache's planes in locals: the stores to the batch
    // could alias them, and were reloaded and stored for every triangle.
    const VertexClip c = cache;
    const std::size_t vertex_count = in.vertex_count;
    std::uint64_t invalid = 0, outside = 0;
    int count = 0;
    std::size_t t = first;
    for (; t < end && count < TriangleBatch::kSize; ++t) {
        std::uint32_t v[3];
        bool valid = true;
        for (int k = 0; k < 3; ++k) {
            v[k] = vertex_index(indices, t, k);
            valid = valid && v[k] < vertex_count;
        }
        if (!valid) {
            ++invalid;
            continue;
        }
        const std::uint8_t a = c.outcode[v[0]], b = c.outcode[v[1]], o = c.outcode[v[2]];
        if ((a | b | o) & kNotFinite) {
            ++invalid;
            continue;
        }
        if (a & b & o & kOutsidePlanes) {
            ++outside;
            continue;
        }
        const int lane = count++;
        batch.triangle[lane] = t;
        for (int k = 0; k < 3; ++k) {
            batch.cx[k][lane] = c.x[v[k]], batch.cy[k][lane] = c.y[v[k]];
            batch.cz[k][lane] = c.z[v[k]], batch.cw[k][lane] = c.w[v[k]];
        }
    }
    stats.triangles_in += t - first;
    stats.invalid += invalid;
    stats.outside += outside;
    batch.count = count;
    batch.indices_valid = (1u << count) - 1u;  // count <= kSize < 32
    return t;
}

}  // namespace

std::uint8_t outcode(const glm::dvec4& c, double near_w) {
    if (!finite_clip(c)) return kNotFinite;
    return std::uint8_t((c.w < near_w ? kBehindNear : 0) | (c.x > c.w ? kBeyondRight : 0) | (c.x < -c.w ? kBeyondLeft : 0) |
                        (c.y > c.w ? kBeyondTop : 0) | (c.y < -c.w ? kBeyondBottom : 0));
}

void transform_vertices_reference(const TriangleInput& in, double near_w, std::size_t begin, std::size_t end, const VertexClip& cache) {
    for (std::size_t v = begin; v < end; ++v) {
        float p[4];
        read_position(in, std::uint32_t(v), p);
        const glm::dvec4 c = input_to_clip(in, p[0], p[1], p[2], p[3]);
        cache.x[v] = c.x, cache.y[v] = c.y, cache.z[v] = c.z, cache.w[v] = c.w;
        cache.outcode[v] = outcode(c, near_w);
    }
}

bool use_vertex_cache(const TriangleInput& in) {
    constexpr std::size_t kMaxCachedVertices = std::size_t(1) << 22;  // 4M vertices: 136 MB of cache at most
    // At most two vertices per triangle: fewer transforms than the three per triangle of the
    // setup without a cache. The scene culler's frames draw a subset of a scene's occluders
    // through indices into all their vertices (on sponza about 110,000 of 262,000 triangles):
    // with this bound instead of one vertex per triangle, sponza's walk renders 7.12 -> 6.81 ms
    // a frame, castle 2.63 -> 2.56, fzk_haus 2.84 -> 2.81 (three per triangle did no better).
    return in.indices && in.vertex_count > 0 && in.vertex_count <= 2 * in.triangle_count && in.vertex_count <= kMaxCachedVertices;
}

void gather_triangle_batch(const TriangleInput& in, std::size_t first, int count, TriangleBatch& batch, const std::uint32_t* order) {
    std::uint32_t index[3][TriangleBatch::kSize];
    for (int t = 0; t < count; ++t) batch.triangle[t] = order ? std::size_t(order[first + std::size_t(t)]) : first + std::size_t(t);
    batch.indices_valid =
        with_typed_indices(in, [&](const auto* indices) { return read_indices(indices, batch.triangle, count, in.vertex_count, index); });
    for (int k = 0; k < 3; ++k)
        for (int t = 0; t < TriangleBatch::kSize; ++t) {
            float p[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // lanes without valid indices (and past count) read nothing
            if ((batch.indices_valid >> t) & 1u) read_position(in, index[k][t], p);
            batch.px[k][t] = p[0], batch.py[k][t] = p[1], batch.pz[k][t] = p[2], batch.pw[k][t] = p[3];
        }
}

std::size_t gather_cached_batch(const TriangleInput& in, const VertexClip& cache, std::size_t first, std::size_t end, TriangleBatch& batch,
                                RasterStats& stats) {
    return with_typed_indices(in, [&](const auto* indices) { return gather_cached(indices, in, cache, first, end, batch, stats); });
}

namespace {
template <bool kPlain>
void transform_batch_with(const TriangleInput& in, TriangleBatch& batch) {
    for (int t = 0; t < TriangleBatch::kSize; ++t)
        for (int k = 0; k < 3; ++k) {
            const glm::dvec4 c = kPlain ? input_to_clip_plain(in, batch.px[k][t], batch.py[k][t], batch.pz[k][t], batch.pw[k][t])
                                        : input_to_clip(in, batch.px[k][t], batch.py[k][t], batch.pz[k][t], batch.pw[k][t]);
            batch.cx[k][t] = c.x, batch.cy[k][t] = c.y, batch.cz[k][t] = c.z, batch.cw[k][t] = c.w;
        }
}
}  // namespace

void transform_batch_reference(const TriangleInput& in, TriangleBatch& batch) { transform_batch_with<false>(in, batch); }
void transform_batch_plain_reference(const TriangleInput& in, TriangleBatch& batch) { transform_batch_with<true>(in, batch); }

std::uint32_t beyond_side_plane_reference(const TriangleBatch& batch, int count, double scale_x, double scale_y) {
    std::uint32_t bits = 0;
    for (int t = 0; t < count; ++t) {
        const glm::dvec4 clip[3] = {batch.clip(t, 0), batch.clip(t, 1), batch.clip(t, 2)};
        double p = 0.0;
        for (int k = 0; k < 3; ++k)
            p = std::max({p, std::abs(batch.px[k][t]), std::abs(batch.py[k][t]), std::abs(batch.pz[k][t]), std::abs(batch.pw[k][t])});
        if (((batch.indices_valid >> t) & 1u) && finite_clip_triangle(clip) &&
            outside_side_plane(clip, scale_x * p, scale_y * p))
            bits |= 1u << t;
    }
    return bits;
}

bool assemble_raster_triangle(const BatchSetup& s, int t, std::uint8_t shared_bits, double edge_margin, RasterTriangle& out) {
    if (s.area2[t] == 0.0) return false;  // orient_triangle
    out.i0 = s.i0[t], out.i1 = s.i1[t], out.j0 = s.j0[t], out.j1 = s.j1[t];
    if (out.i0 > out.i1 || out.j0 > out.j1) return false;
    bool shared[3] = {(shared_bits & 1u) != 0, (shared_bits & 2u) != 0, (shared_bits & 4u) != 0};
    if ((s.flipped >> t) & 1u) std::swap(shared[0], shared[2]);  // edges 0->2, 2->1, 1->0 were edges 2, 1, 0
    // prepare_float_row_edges' answer: the batch's floats when no edge is shared.
    out.plane.float_rows = !shared[0] && !shared[1] && !shared[2] && ((s.float_ready >> t) & 1u);
    if (out.plane.float_rows) {
        FloatRowEdges& f = out.float_edges;
        for (int k = 0; k < 3; ++k) {
            f.row_origin[k] = s.row_origin[k][t], f.y_offset[k] = s.y_offset[k][t], f.slope[k] = s.slope[k][t];
            f.base[k] = s.base[k][t], f.lo_clamp[k] = s.lo_clamp[k][t], f.hi_clamp[k] = s.hi_clamp[k][t];
            f.column_shift[k] = s.column_shift[k][t];
            f.lower[k] = s.sa[k][t] > 0.0;
        }
    } else {
        for (int k = 0; k < 3; ++k) {
            out.edges.ox[k] = s.ox[k][t], out.edges.oy[k] = s.oy[k][t];
            out.edges.sa[k] = s.sa[k][t], out.edges.sb[k] = s.sb[k][t], out.edges.inverse_sa[k] = s.inverse_sa[k][t];
            out.edges.shared[k] = shared[k];
            out.edges.threshold[k] = edge_threshold(shared[k], edge_margin, s.sa[k][t], s.sb[k][t]);
        }
    }
    PreparedTriangle& plane = out.plane;  // finish_depth_plane's, from SetupPlanes
    plane.a = s.plane_a[t], plane.dzdx = s.plane_dzdx[t], plane.dzdy = s.plane_dzdy[t], plane.error = s.plane_error[t];
    plane.z_vertex_min = s.z_vertex_min[t];
    plane.has_plane = (s.has_plane >> t) & 1u;
    set_far_corner(plane);
    return true;
}

void classify_batch_reference(Backface backface, double near_w, TriangleBatch& batch, RasterStats& stats) {
    batch.needs_setup = 0;
    batch.simple = 0;  // the reference sets every triangle up with setup_clip_triangle
    for (int t = 0; t < batch.count; ++t) {
        const glm::dvec4 clip[3] = {batch.clip(t, 0), batch.clip(t, 1), batch.clip(t, 2)};
        const bool finite = finite_clip_triangle(clip);
        const TriangleFate fate =
            !((batch.indices_valid >> t) & 1u) || !finite ? TriangleFate::invalid : unclipped_fate(clip, backface, near_w);
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
