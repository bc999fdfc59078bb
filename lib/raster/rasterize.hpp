#pragma once
// The reference rasterizer: one projected triangle into the subtiles of the buffer. Written
// for clarity and as the oracle that SIMD kernels must match bit for bit.
#include <homcull/occlusion_buffer.hpp>

namespace homcull::detail {

// A triangle in sample space (x right, y down, in samples) with depth d = 1/w per vertex.
struct ScreenTriangle {
    glm::dvec2 p[3];
    double d[3];
    std::uint8_t shared = 0;  // bit k: the edge p[k] -> p[k + 1] is shared with a drawn triangle
};

struct RasterTarget {
    OcclusionBuffer::Subtile* subtiles;
    int subtiles_x, subtiles_y;
    int sample_width, sample_height;
    double edge_margin;
    int row_begin, row_end;  // the subtile rows [row_begin, row_end) this call may write
};

// Rasterizes a counter-clockwise-in-NDC or clockwise triangle (either; orientation is
// normalized here). Returns the number of subtiles updated.
std::uint64_t rasterize_triangle(const RasterTarget& target, const ScreenTriangle& triangle);

// The mask of the samples of subtile (tx, ty) that exist (the buffer's right and bottom
// subtiles may be partly outside the sample grid).
std::uint32_t valid_sample_mask(int tx, int ty, int sample_width, int sample_height);

}  // namespace homcull::detail
