#pragma once
// The bounding rectangles of a batch of occludee triangles (occludee_rectangles_simd.cpp), for
// OcclusionBuffer::test_triangles' pass-over of triangles hidden by their bounding rectangle
// (occludee_triangles.cpp, bounding_rectangle) several triangles at a time.
#include "buffer/rect_queries.hpp"
#include "raster/triangle_batch.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>

namespace homcull::detail {

struct OccludeeRectangleParams {
    const float* matrix;  // the input's model_to_clip, column-major (TriangleInput)
    double near_w, edge_margin;
    int sample_width, sample_height;
};

// For the lanes [0, count) of a batch transformed by transform_batch_plain (a perspective input):
// bit t set where lane t's triangle is one that the one-triangle code would set up without
// clipping (valid indices, finite, every w above near_w, within the guard band, not too large,
// and a rounding bound of w small enough to place the near plane: error.w below near_w), and
// then rects[t] holds its samples and depth: every sample outer_bounds' box holds, at a depth
// no farther than its raised nearest vertex (an empty span, i0 > i1 or j0 > j1, where that
// box holds none). A hidden rectangle (test_prepared_rect) so proves the one-triangle
// rectangle hidden too; a visible one proves nothing. Null for the scalar choice.
using OccludeeRectanglesKernel = std::uint32_t (*)(const TriangleBatch& batch, int count, const OccludeeRectangleParams& params,
                                                   RectQuery* rects);

// The one-triangle rectangle (occludee_triangles.cpp): for a perspective input's triangle (model
// positions and their clip coordinates, as transform_batch_plain gives them) that the test sets
// up without clipping, the samples of outer_bounds' box (i0 > i1 or j0 > j1: none) at its raised
// nearest vertex; false for the others. What the kernel's rectangles must hold.
bool occludee_bounding_rectangle(const std::array<float, 16>& model_to_clip, const glm::dvec4 model[3], const glm::dvec4 clip[3],
                                 double near_w, double edge_margin, int sample_width, int sample_height, RectQuery& rect);

}  // namespace homcull::detail
