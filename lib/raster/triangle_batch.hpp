#pragma once
// The front of triangle setup, a batch of consecutive triangles at a time: index and vertex
// fetch, the model-to-clip transform, and the rejections that need no clipping (invalid
// input, outside the frustum, degenerate, backfacing). Most of an engine's occluder
// triangles end there (30,000 of the castle's 48,700 are outside view C0, 10,000 more face
// away), so the SIMD kernel (triangle_batch_simd.cpp) decides them in double lanes, several
// triangles per instruction, as Intel's MOC does for its setup. The triangles left go to
// setup_clip_triangle one by one, with clip coordinates bit-identical to fetch_clip_triangle's.
#include "raster/triangle_setup.hpp"

#include <homcull/occlusion_buffer.hpp>

#include <cstddef>
#include <cstdint>

namespace homcull::detail {

// A batch of triangles in structure-of-arrays form: the vertex positions as fetched, and
// after classification the clip-space x, y, z, w and which triangles need the one-triangle setup.
struct TriangleBatch {
    static constexpr int kSize = 16;  // a multiple of every target's double lanes (2, 4, 8)
    alignas(64) double px[3][kSize], py[3][kSize], pz[3][kSize], pw[3][kSize];  // per vertex k, per lane
    alignas(64) double cx[3][kSize], cy[3][kSize], cz[3][kSize], cw[3][kSize];
    std::uint32_t indices_valid = 0;  // bit t: lane t's three indices are below vertex_count
    std::uint32_t needs_setup = 0;    // bit t: lane t goes on to setup_clip_triangle

    // Vertex k of lane t in clip space, as fetch_clip_triangle gives it.
    glm::dvec4 clip(int t, int k) const { return {cx[k][t], cy[k][t], cz[k][t], cw[k][t]}; }
};

// Fetches triangles [first, first + count) (0 < count <= kSize) into the batch's lanes
// [0, count): positions as doubles, (x, y, z, 1) for 3 components. Lanes with an index out of
// range, and lanes past count, get a finite position and no indices_valid bit.
void gather_triangle_batch(const TriangleInput& in, std::size_t first, int count, TriangleBatch& batch);

// Transforms a gathered batch's lanes [0, count) to clip space (transform_to_clip's operations)
// and decides each: invalid (an index out of range, or a non-finite clip x, y or w), or
// unclipped_fate. Counts the triangles rejected (invalid, outside, degenerate, backfacing) in
// `stats` and sets needs_setup for the others. Every kernel gives the same clip coordinates,
// counts and bits.
using ClassifyBatchKernel = void (*)(const TriangleInput& in, double near_w, int count, TriangleBatch& batch, RasterStats& stats);
void classify_triangle_batch_reference(const TriangleInput& in, double near_w, int count, TriangleBatch& batch, RasterStats& stats);
// The reference or the SIMD kernel, following select_isa.
ClassifyBatchKernel selected_classify_kernel();

// Sets up triangles [begin, end) of the input in batches and hands every triangle of their
// clipped fans that covers a sample's bounding box to emit(const RasterTriangle&), in input
// order; the statistics are those of fetch_clip_triangle and setup_clip_triangle, triangle
// by triangle.
template <typename Emit>
void setup_triangle_range(const TriangleInput& in, std::size_t begin, std::size_t end, double near_w, double edge_margin, int sample_width,
                          int sample_height, RasterStats& stats, Emit&& emit) {
    const ClassifyBatchKernel classify = selected_classify_kernel();
    TriangleBatch batch;
    for (std::size_t first = begin; first < end; first += TriangleBatch::kSize) {
        const int count = int(std::min<std::size_t>(TriangleBatch::kSize, end - first));
        gather_triangle_batch(in, first, count, batch);
        classify(in, near_w, count, batch, stats);
        stats.triangles_in += std::uint64_t(count);
        for (std::uint32_t bits = batch.needs_setup; bits != 0; bits &= bits - 1) {
            const int t = __builtin_ctz(bits);
            const glm::dvec4 clip[3] = {batch.clip(t, 0), batch.clip(t, 1), batch.clip(t, 2)};
            const std::size_t index = first + std::size_t(t);
            const SetupResult setup = setup_clip_triangle(clip, in.shared_edges ? in.shared_edges[index] : 0, in.backface, near_w,
                                                          sample_width, sample_height, stats);
            for (int k = 0; k < setup.count; ++k) {
                RasterTriangle tri;
                if (setup_raster_triangle(setup.triangles[k], edge_margin, sample_width, sample_height, tri)) emit(tri);
            }
        }
    }
}

}  // namespace homcull::detail
