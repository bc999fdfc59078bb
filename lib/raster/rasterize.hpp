#pragma once
// The rasterizer: one projected triangle into the subtiles of the buffer. Triangle
// preparation and the per-row coverage intervals are shared; the per-subtile work of a subtile
// row (masks, depth bound, layer update) has a plain scalar reference and SIMD kernels
// (rasterize_simd.cpp) that must give the same bits.
#include <homcull/occlusion_buffer.hpp>

namespace homcull::detail {

// A triangle in sample space (x right, y down, in samples) with depth d = 1/w per vertex.
struct ScreenTriangle {
    glm::dvec2 p[3];
    double d[3];
    std::uint8_t shared = 0;  // bit k: the edge p[k] -> p[k + 1] is shared with a drawn triangle
};

struct PreparedTriangle;

// Updates the subtiles (tx_begin..tx_end, ty) from the row intervals [first[j], last[j]] of
// the subtile row's four sample rows. Returns the number of subtiles updated.
using SubtileRowKernel = std::uint64_t (*)(OcclusionBuffer::Subtile* row, int ty, int tx_begin, int tx_end, const int first[4],
                                           const int last[4], const PreparedTriangle& tri, int subtiles_x, int subtiles_y,
                                           int sample_width, int sample_height);

struct RasterTarget {
    OcclusionBuffer::Subtile* subtiles;
    int subtiles_x, subtiles_y;
    int sample_width, sample_height;
    double edge_margin;
    int row_begin, row_end;  // the subtile rows [row_begin, row_end) this call may write
    SubtileRowKernel kernel;
};

// What the subtile-row kernels need of a triangle: its depth plane
// d(P) = z0 + dzdx (P.x - x0) + dzdy (P.y - y0) and its smallest vertex depth.
struct PreparedTriangle {
    double x0, y0, z0, dzdx, dzdy, z_vertex_min;
};

// Rasterizes a triangle of either orientation. Returns the number of subtiles updated.
std::uint64_t rasterize_triangle(const RasterTarget& target, const ScreenTriangle& triangle);

// The scalar reference kernel.
std::uint64_t update_subtile_row_reference(OcclusionBuffer::Subtile* row, int ty, int tx_begin, int tx_end, const int first[4],
                                           const int last[4], const PreparedTriangle& tri, int subtiles_x, int subtiles_y,
                                           int sample_width, int sample_height);

// The mask of the samples of subtile (tx, ty) that exist (the buffer's right and bottom
// subtiles may be partly outside the sample grid).
std::uint32_t valid_sample_mask(int tx, int ty, int sample_width, int sample_height);

// The kernel for the selected instruction set (see select_isa in occlusion_buffer.hpp).
SubtileRowKernel selected_subtile_row_kernel();

}  // namespace homcull::detail
