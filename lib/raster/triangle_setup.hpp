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

// Triangle t's vertices as given (x, y, z, w with w = 1 for 3 components) and in clip space.
// False when an index is out of range or a clip coordinate is not finite.
bool fetch_clip_triangle(const TriangleInput& in, std::size_t t, glm::dvec4 model[3], glm::dvec4 clip[3]);

// Whether all three vertices lie outside one side plane of the view frustum (|x| or |y| > w):
// then so does the whole triangle.
bool outside_side_plane(const glm::dvec4 clip[3]);

// The guard band, in NDC units: triangles reaching beyond |x/w| or |y/w| = kGuardBand are
// clipped there, so that sample coordinates stay small enough for double edge functions to be
// exact to far below the coverage margin.
constexpr double kGuardBand = 32.0;

struct SetupResult {
    ScreenTriangle triangles[6];  // the clipped polygon's fan (a triangle clips to at most 8 vertices)
    int count = 0;
};

// Sets up triangle t of the input; updates the setup statistics (everything but
// subtiles_touched). `sample_width/height` is the buffer's sample grid.
SetupResult setup_triangle(const TriangleInput& in, std::size_t t, double near_w, int sample_width, int sample_height,
                           RasterStats& stats);
// The same for a triangle already fetched and in clip space, with its shared-edge bits
// (counts everything but triangles_in and invalid).
SetupResult setup_clip_triangle(const glm::dvec4 clip[3], std::uint8_t shared_bits, Backface backface, double near_w, int sample_width,
                                int sample_height, RasterStats& stats);

}  // namespace homcull::detail
