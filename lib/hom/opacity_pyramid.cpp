// Reference paths of the occlusion maps' level 0 and pyramid reduction (opacity_pyramid.hpp);
// the SIMD kernels are in opacity_pyramid_simd.cpp.
#include "hom/opacity_pyramid.hpp"

#include "buffer/min_pyramid.hpp"

#include <homcull/occlusion_buffer.hpp>

#include <algorithm>
#include <cmath>

namespace homcull::detail {
void level0_reference(const Level0Maps& m, int tx_begin) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    const int s = m.samples, pixels_x = kW / s, pixels_y = kH / s;  // pixels per subtile
    std::uint32_t pixel_bits[kW * kH];  // each pixel's samples in a subtile, row-major
    for (int py = 0; py < pixels_y; ++py)
        for (int px = 0; px < pixels_x; ++px) {
            std::uint32_t bits = 0;
            for (int r = 0; r < s; ++r) bits |= ((0xFFu >> (kW - s)) << (px * s)) << ((py * s + r) * kW);
            pixel_bits[py * pixels_x + px] = bits;
        }
    for (int ty = 0; ty < m.subtiles_y; ++ty) {
        const int rows = std::min(pixels_y, m.height - ty * pixels_y);
        for (int tx = tx_begin; tx < m.subtiles_x; ++tx) {
            const std::size_t i = std::size_t(ty) * m.stride + std::size_t(tx);
            const std::uint32_t cov = m.covered[i], mask = m.mask[i];
            const float d0 = m.d0[i], layered = std::max(d0, m.d1[i]);
            const int columns = std::min(pixels_x, m.width - tx * pixels_x);
            for (int py = 0; py < rows; ++py) {
                const std::size_t row = std::size_t(ty * pixels_y + py) * std::size_t(m.width) + std::size_t(tx * pixels_x);
                for (int px = 0; px < columns; ++px) {
                    const std::uint32_t c = cov & pixel_bits[py * pixels_x + px];
                    const bool outside_mask = (c & ~mask) != 0, inside_mask = (c & mask) != 0;
                    m.covered_out[row + std::size_t(px)] = bit_count(c);
                    if (m.far_out) m.far_out[row + std::size_t(px)] = outside_mask ? d0 : inside_mask ? layered : INFINITY;  // d0 <= layered
                    if (m.near_out) m.near_out[row + std::size_t(px)] = inside_mask ? layered : outside_mask ? d0 : INFINITY;
                }
            }
        }
    }
}

void reduce_pyramid_row_reference(const PyramidRows& r, int begin, int end, int below_width) {
    for (int x = begin; x < end; ++x) {
        // A missing right child repeats the left one: the minimum is unaffected, the sum skips it.
        const std::size_t a = std::size_t(2 * x), b = std::size_t(std::min(2 * x + 1, below_width - 1));
        const std::uint32_t second_column = b != a ? 1u : 0u;
        std::uint32_t covered = r.covered0[a] + second_column * r.covered0[b];
        if (r.second_row) covered += r.covered1[a] + second_column * r.covered1[b];
        r.covered_out[x] = covered;
    }
    if (r.far_out) reduce_min_row(r.far0, r.far1, begin, end, below_width, r.far_out);
    if (r.near_out) reduce_min_row(r.near0, r.near1, begin, end, below_width, r.near_out);
}

}  // namespace homcull::detail
