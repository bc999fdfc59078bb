#pragma once
// Triangle setup: index and vertex fetch, model-to-clip transform (double), trivial
// rejection, near-plane and guard-band clipping, backface culling, projection to sample space.
#include "raster/rasterize.hpp"

#include <homcull/occlusion_buffer.hpp>

#include <cmath>

namespace homcull::detail {

// Model to clip space in double, column-major m[column * 4 + row], one fixed order of
// operations (the rasterizer and the occludee tests must agree to the bit).
inline glm::dvec4 transform_to_clip(const std::array<float, 16>& m, double x, double y, double z, double w) {
    glm::dvec4 r;
    for (int row = 0; row < 4; ++row)
        r[row] = double(m[row]) * x + double(m[4 + row]) * y + double(m[8 + row]) * z + double(m[12 + row]) * w;
    return r;
}

inline bool finite_clip(const glm::dvec4& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.w); }

struct SetupResult {
    ScreenTriangle triangles[6];  // the clipped polygon's fan (a triangle clips to at most 8 vertices)
    int count = 0;
};

// Sets up triangle t of the input; updates the setup statistics (everything but
// subtiles_touched). `sample_width/height` is the buffer's sample grid.
SetupResult setup_triangle(const TriangleInput& in, std::size_t t, double near_w, int sample_width, int sample_height,
                           RasterStats& stats);

}  // namespace homcull::detail
