#pragma once
// An exact reference for screen-space workloads (S1): the nearest clip w of a set of
// triangles at every sample centre, computed in double, and "is this rectangle hidden?"
// answered from it exactly (per-row sparse tables of the maximum).
#include <homcull/occlusion_buffer.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

class ExactDepth {
public:
    // A grid of sample_width x sample_height samples with centres at (i + 0.5, j + 0.5).
    ExactDepth(int sample_width, int sample_height);

    // A triangle in clip space (x, y, z, w per vertex; z unused). Every vertex must have
    // w > 0 (throws homcull::Error otherwise: there is no clipping here). Closed triangles:
    // samples on an edge count as covered. Backface culling as OcclusionBuffer's Backface::cw
    // when cull_clockwise. Throws homcull::Error for a non-finite vertex or w <= 0.
    void add_triangle(const float* xyzw0, const float* xyzw1, const float* xyzw2, bool cull_clockwise);

    // Call once after the last triangle, before hidden().
    void finish();

    // True when every sample whose centre lies in the NDC rectangle (y up) has an occluder
    // strictly nearer than w_min (a rectangle with no sample inside is hidden too: nothing of
    // it can be seen at a sample). A non-finite or inverted rectangle is not hidden (the buffer
    // answers such input visible). Thread-safe after finish().
    bool hidden(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const;

    // Nearest w per sample (infinity where no triangle covers it), rounded up to float.
    const std::vector<float>& depth() const { return depth_; }

private:
    int width_, height_, levels_ = 0;
    std::vector<float> depth_;
    std::vector<float> row_max_;  // per row, per level: max over [i, i + 2^level)
};

// The exact depth of clip-space triangles (x, y, z, w per vertex, 12 floats a triangle).
ExactDepth exact_depth_of_triangles(const float* xyzw, std::size_t triangle_count, int sample_width, int sample_height,
                                    bool cull_clockwise);

// An occlusion buffer's rectangle answers against the exact ones: a false cull is a
// rectangle said hidden (occluded or view-culled) that is not; a missed cull the reverse.
struct RectAccuracy {
    std::size_t rects = 0, truly_hidden = 0, culled = 0, false_culls = 0, missed_culls = 0;
};
RectAccuracy count_rect_accuracy(const OcclusionBuffer& buffer, const ExactDepth& exact, const float* rects_xyxyw,
                                 std::size_t rect_count);

}  // namespace homcull
