// Coverage: a sample is covered when, for each edge, the edge function exceeds the edge's
// margin: edge_margin samples times the L1 length of the edge normal (so at least edge_margin
// samples of distance) on a silhouette edge, and 0 (inclusive) on an edge shared with another
// drawn triangle. Edge functions are evaluated in double from unsnapped vertices, always from
// the edge's lower endpoint (by y, then x) and in one fixed order of operations (no fused
// multiply-add): the two triangles of a shared edge then compute exactly opposite values, so
// every sample near it lands in at least one of them, and results are the same on every target.
//
// Depth: the triangle's 1/w is linear in screen space; its minimum over the covered samples of
// a subtile is at least the plane's minimum over their bounding rectangle (at a corner) and at
// least the smallest vertex 1/w. That bound, rounded down to float and lowered by a relative
// 2^-20, enters the subtile by the "quick mask" rule of masked occlusion culling (Hasselgren
// et al. 2016, section 3.2).
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cmath>

namespace homcull::detail {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// Round a positive double down to float, then lower it by a relative 2^-20.
float conservative_far(double d) {
    float f = float(d);
    if (double(f) > d) f = std::nextafter(f, 0.0f);
    return f * (1.0f - 0x1.0p-20f);
}

}  // namespace

std::uint32_t valid_sample_mask(int tx, int ty, int sample_width, int sample_height) {
    const int columns = std::min(kW, sample_width - tx * kW), rows = std::min(kH, sample_height - ty * kH);
    if (columns <= 0 || rows <= 0) return 0;
    const std::uint32_t row_bits = columns >= 32 ? 0xFFFFFFFFu : (1u << columns) - 1u;
    std::uint32_t mask = 0;
    for (int j = 0; j < rows; ++j) mask |= row_bits << (j * kW);
    return mask;
}

std::uint64_t rasterize_triangle(const RasterTarget& t, const ScreenTriangle& tri) {
    glm::dvec2 p0 = tri.p[0], p1 = tri.p[1], p2 = tri.p[2];
    double z0 = tri.d[0], z1 = tri.d[1], z2 = tri.d[2];
    bool shared[3] = {(tri.shared & 1u) != 0, (tri.shared & 2u) != 0, (tri.shared & 4u) != 0};
    double area2 = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
    if (area2 == 0.0) return 0;
    if (area2 < 0.0) {  // make the edge functions positive inside: order 0, 2, 1
        std::swap(p1, p2);
        std::swap(z1, z2);
        std::swap(shared[0], shared[2]);  // edges 0->2, 2->1, 1->0 were edges 2, 1, 0
        area2 = -area2;
    }
    const glm::dvec2 v[3] = {p0, p1, p2};
    // E_k(P) = sign_k * (a_k (P.x - o_k.x) + b_k (P.y - o_k.y)), o_k the edge's lower endpoint.
    double a[3], b[3], sign[3], threshold[3];
    glm::dvec2 origin[3];
    for (int k = 0; k < 3; ++k) {
        const glm::dvec2& from = v[k];
        const glm::dvec2& to = v[(k + 1) % 3];
        const bool forward = from.y != to.y ? from.y < to.y : from.x < to.x;
        const glm::dvec2& lo = forward ? from : to;
        const glm::dvec2& hi = forward ? to : from;
        origin[k] = lo;
        a[k] = -(hi.y - lo.y);
        b[k] = hi.x - lo.x;
        sign[k] = forward ? 1.0 : -1.0;
        threshold[k] = shared[k] ? 0.0 : t.edge_margin * (std::abs(a[k]) + std::abs(b[k]));
    }

    // Samples whose centres lie in the triangle's bounding box.
    const double min_x = std::min({p0.x, p1.x, p2.x}), max_x = std::max({p0.x, p1.x, p2.x});
    const double min_y = std::min({p0.y, p1.y, p2.y}), max_y = std::max({p0.y, p1.y, p2.y});
    const int i0 = std::max(0, int(std::ceil(min_x - 0.5))), i1 = std::min(t.sample_width - 1, int(std::floor(max_x - 0.5)));
    const int j0 = std::max(0, int(std::ceil(min_y - 0.5))), j1 = std::min(t.sample_height - 1, int(std::floor(max_y - 0.5)));
    if (i0 > i1 || j0 > j1) return 0;

    // Depth plane d(P) = z0 + dzdx (P.x - p0.x) + dzdy (P.y - p0.y).
    const double dzdx = ((z1 - z0) * (p2.y - p0.y) - (z2 - z0) * (p1.y - p0.y)) / area2;
    const double dzdy = ((z2 - z0) * (p1.x - p0.x) - (z1 - z0) * (p2.x - p0.x)) / area2;
    const double z_vertex_min = std::min({z0, z1, z2});

    std::uint64_t touched = 0;
    for (int ty = j0 / kH; ty <= j1 / kH; ++ty)
        for (int tx = i0 / kW; tx <= i1 / kW; ++tx) {
            std::uint32_t m = 0;
            int cmin_x = kW, cmax_x = -1, cmin_y = kH, cmax_y = -1;
            for (int j = 0; j < kH; ++j) {
                const int sy = ty * kH + j;
                if (sy < j0 || sy > j1) continue;
                const double py = sy + 0.5;
                for (int i = 0; i < kW; ++i) {
                    const int sx = tx * kW + i;
                    if (sx < i0 || sx > i1) continue;
                    const double px = sx + 0.5;
                    bool inside = true;
                    for (int k = 0; k < 3 && inside; ++k) {
                        const double e = sign[k] * (a[k] * (px - origin[k].x) + b[k] * (py - origin[k].y));
                        inside = shared[k] ? e >= 0.0 : e > threshold[k];
                    }
                    if (!inside) continue;
                    m |= 1u << (j * kW + i);
                    cmin_x = std::min(cmin_x, i), cmax_x = std::max(cmax_x, i);
                    cmin_y = std::min(cmin_y, j), cmax_y = std::max(cmax_y, j);
                }
            }
            if (m == 0) continue;
            ++touched;
            OcclusionBuffer::Subtile& s = t.subtiles[std::size_t(ty) * std::size_t(t.subtiles_x) + std::size_t(tx)];
            s.covered |= m;

            // Lower bound of 1/w over the covered samples.
            const double x_far = (dzdx > 0.0 ? tx * kW + cmin_x : tx * kW + cmax_x) + 0.5;
            const double y_far = (dzdy > 0.0 ? ty * kH + cmin_y : ty * kH + cmax_y) + 0.5;
            const double plane_min = z0 + dzdx * (x_far - p0.x) + dzdy * (y_far - p0.y);
            const double bound = std::max(plane_min, z_vertex_min);
            if (!(bound > 0.0)) continue;
            const float d_tri = conservative_far(bound);
            if (!(d_tri > s.d0)) continue;  // behind what is already known: nothing to add

            // Quick mask: drop the working layer when the triangle is farther in front of it than
            // it is in front of the reference layer (d_tri - d1 > d1 - d0), then merge, and
            // promote a full layer to the reference.
            if (s.mask != 0 && 2.0f * s.d1 - (d_tri + s.d0) < 0.0f) s.mask = 0;
            s.d1 = s.mask == 0 ? d_tri : std::min(s.d1, d_tri);
            s.mask |= m;
            if (s.mask == valid_sample_mask(tx, ty, t.sample_width, t.sample_height)) {
                s.d0 = s.d1;
                s.mask = 0;
                s.d1 = 0.0f;
            }
        }
    return touched;
}

}  // namespace homcull::detail
