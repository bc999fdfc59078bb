#pragma once
// The coarse stage of the batched rectangle tests (detail::BufferState::test_rects), shared by
// the scalar path (detail::BufferState::prepare and the start of test_rect) and the SIMD kernel
// in rect_queries_simd.cpp, which must decide exactly the rectangles the scalar path decides
// at that stage, with the same answers.
#include <homcull/occlusion_buffer.hpp>

#include "buffer/buffer_state.hpp"
#include "buffer/min_pyramid.hpp"
#include "common/float_round.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace homcull::detail {

// What the coarse stage reads of a buffer.
struct CoarseRectView {
    const float* pyramid;               // all levels, level l at level_offset[l], rows of level_width[l]
    const std::int32_t* level_offset;
    const std::int32_t* level_width;
    int levels;
    int sample_width, sample_height;
    float near_w;
};

// A rectangle test after detail::BufferState::prepare: the samples [i0, i1] x [j0, j1] whose
// centres lie in it, and its nearest 1/w rounded up (an occluder hides it where its bound is
// above d_near).
struct RectQuery {
    int i0, i1, j0, j1;
    float d_near;
};

// An occludee's nearest 1/w from its w_min >= near_w >= 2^-126: rounded up and raised by a
// relative 2^-20. 1/w_min is positive, finite and within float's range, so rounding it up is
// one step of its bits where float() rounded it down: float_up without its branches, which
// were mispredicted about half the time on S1's rectangles.
inline float nearest_depth_bound(float w_min) {
    const double inverse = 1.0 / double(w_min);
    const float nearest = float(inverse);
    std::uint32_t bits;
    std::memcpy(&bits, &nearest, sizeof bits);
    bits += std::uint32_t(double(nearest) < inverse);
    float up;
    std::memcpy(&up, &bits, sizeof up);
    return up * (1.0f + 0x1.0p-20f);
}

// The subtiles [tx0, tx1] x [ty0, ty1] a prepared rectangle reaches. Its samples are never
// negative (prepare_rect clamps them at 0), so the division is a shift, not the few instructions
// of a signed division, on single test_rect calls' path to their coarse check.
struct SubtileRange {
    int tx0, tx1, ty0, ty1;
};
inline SubtileRange subtile_range(const RectQuery& q) {
    constexpr unsigned kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    return {int(unsigned(q.i0) / kW), int(unsigned(q.i1) / kW), int(unsigned(q.j0) / kH), int(unsigned(q.j1) / kH)};
}

// What the rectangle tests do before reading the buffer (detail::BufferState::prepare, and
// the single test_rect's SIMD kernel, which inlines it compiled for its instruction set): the
// samples whose centres lie in the rectangle and its nearest 1/w, rounded up and raised by a
// relative 2^-20; or, returning false, the answer when it needs no buffer (invalid input or
// before the near plane: visible; outside the view: view-culled; between sample centres:
// occluded). The batches' SIMD coarse stage repeats these operations in lanes.
inline bool prepare_rect(const CoarseRectView& view, const ScreenRect& r, RectQuery& q, Visibility& decided) {
    if (!std::isfinite(r.ndc_min_x) || !std::isfinite(r.ndc_min_y) || !std::isfinite(r.ndc_max_x) || !std::isfinite(r.ndc_max_y) ||
        !std::isfinite(r.w_min) || !(r.ndc_min_x <= r.ndc_max_x) || !(r.ndc_min_y <= r.ndc_max_y)) {
        decided = Visibility::visible;  // nothing to reason with: never cull
        return false;
    }
    if (r.w_min < view.near_w) {
        decided = Visibility::visible;
        return false;
    }
    if (r.ndc_max_x < -1.0f || r.ndc_min_x > 1.0f || r.ndc_max_y < -1.0f || r.ndc_min_y > 1.0f) {
        decided = Visibility::view_culled;
        return false;
    }
    const double sx0 = (double(r.ndc_min_x) + 1.0) * 0.5 * view.sample_width, sx1 = (double(r.ndc_max_x) + 1.0) * 0.5 * view.sample_width;
    const double sy0 = (1.0 - double(r.ndc_max_y)) * 0.5 * view.sample_height, sy1 = (1.0 - double(r.ndc_min_y)) * 0.5 * view.sample_height;
    sample_span(sx0, sx1, view.sample_width, q.i0, q.i1);
    sample_span(sy0, sy1, view.sample_height, q.j0, q.j1);
    if (q.i0 > q.i1 || q.j0 > q.j1) {
        decided = Visibility::occluded;  // covers no sample: invisible at every sample
        return false;
    }
    q.d_near = nearest_depth_bound(r.w_min);
    return true;
}

// The coarse check of a prepared rectangle: at the level where its subtile range spans at
// most 2 x 2 cells, the minimum d0 of the four corner cells (one to four distinct cells, read
// without a branch; a repeated one changes no minimum) is at most any covered subtile's bound,
// so d_near below it hides the rectangle. The batches' SIMD coarse stage reads the same cells.
inline bool coarse_rect_hides(const CoarseRectView& view, const RectQuery& q) {
    const auto [tx0, tx1, ty0, ty1] = subtile_range(q);
    const int level = coarse_level(tx0, tx1, ty0, ty1, view.levels);
    const int x0 = tx0 >> level, x1 = tx1 >> level, y0 = ty0 >> level, y1 = ty1 >> level;
    const float* cells = view.pyramid + view.level_offset[level];
    const std::size_t width = std::size_t(view.level_width[level]);
    const float* row0 = cells + std::size_t(y0) * width;
    const float* row1 = cells + std::size_t(y1) * width;
    const float coarse = std::min(std::min(row0[x0], row0[x1]), std::min(row1[x0], row1[x1]));
    return q.d_near < coarse;
}

// The subtile planes (OcclusionBuffer's layout, rows padded for full-vector loads).
struct SubtileView {
    const float* d0;
    const float* d1;
    const std::uint32_t* mask;
    std::size_t stride;
    const float* sample_depth;  // per sample, rows of sample_stride; null when the buffer keeps none
    std::size_t sample_stride;
    // The farthest-d0 pyramid (level 0: the subtiles' d0), padded at the end for whole-vector
    // loads of any row.
    const float* pyramid;
    const PyramidLevel* levels;
    int level_count;
    // The per-sample depth's units, when computed where read (sample_depth_tiles.hpp): a reader
    // makes a subtile's unit ready (ensure_depth_subtile) before reading sample_depth there.
    const SampleDepthTiles* sample_tiles = nullptr;
};

// A buffer's views, inline so that kernels given the buffer read its fields where they need
// them instead of copying views on every call.
inline CoarseRectView BufferState::coarse_view() const {
    return {pyramid_.data(), level_offset_.data(), level_width_.data(), int(levels_.size()), sample_width_, sample_height_, config_.near_w};
}
inline SubtileView BufferState::subtile_view() const {
    return {d0_.data(),           d1_.data(),      mask_.data(),   stride_, sample_depth_.empty() ? nullptr : sample_depth_.data(),
            sample_depth_stride_, pyramid_.data(), levels_.data(), int(levels_.size()), deferred_sample_depth_ ? &depth_tiles_ : nullptr};
}

// Which of the samples `samples` of subtile (tx, ty) an occludee at 1/w `d_near` may be seen
// at by the layers: those whose layer bound (d0, or max(d0, d1) in the working layer's mask)
// is not above d_near.
inline std::uint32_t subtile_unhidden_samples(const SubtileView& v, int tx, int ty, std::uint32_t samples, float d_near) {
    const std::size_t i = std::size_t(ty) * v.stride + std::size_t(tx);
    if (d_near < v.d0[i]) return 0;
    const std::uint32_t layer = v.mask[i];
    std::uint32_t visible = samples & ~layer;
    if (!(d_near < std::max(v.d0[i], v.d1[i]))) visible |= samples & layer;
    return visible;
}

// Whether subtile (tx, ty) hides the rectangle's samples in it (the rectangle reaches the
// subtile, so it has some): its bound there is d0, or max(d0, d1) when they all lie in the
// working layer's mask.
inline bool subtile_hides(const SubtileView& v, int tx, int ty, const RectQuery& q) {
    return subtile_unhidden_samples(v, tx, ty, subtile_rect_bits(tx, ty, q.i0, q.i1, q.j0, q.j1), q.d_near) == 0;
}

// The rectangle's interior subtiles [ix0, ix1] x [iy0, iy1] (all their samples in it, so their
// bound is d0); empty ranges when it has none.
struct InteriorSubtiles {
    int ix0, ix1, iy0, iy1;
};
inline InteriorSubtiles interior_subtiles(const RectQuery& q) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    const auto [tx0, tx1, ty0, ty1] = subtile_range(q);
    return {q.i0 % kW == 0 ? tx0 : tx0 + 1, q.i1 % kW == kW - 1 ? tx1 : tx1 - 1, q.j0 % kH == 0 ? ty0 : ty0 + 1,
            q.j1 % kH == kH - 1 ? ty1 : ty1 - 1};
}

// Both stages for one rectangle, compiled per instruction set: prepare_rect, the coarse check
// and the exact scan (ScanRect, the subtile rows in SIMD: occluded when every subtile the
// rectangle reaches hides it) in one dispatch (single test_rect calls). None for the scalar
// choice, whose test_rect searches the pyramid instead (the answers are the same).
using RectOneKernel = Visibility (*)(const BufferState& buffer, const ScreenRect& rect);
// The coarse check and the exact scan of a prepared rectangle in one dispatch
// (detail::BufferState::test_prepared_rect). None for the scalar choice.
using RectPreparedKernel = Visibility (*)(const BufferState& buffer, const RectQuery& q);

// The eight corners of a box under a model-to-clip matrix, by the incremental corner transform
// (Zhang: the base corner plus the three transformed edge vectors), in double. Returns a bound
// on the error of every corner coordinate against the exact transform of the float box: each of
// the four transforms is accurate to about 2^-52 of its result (transform_to_clip), and the
// three sums of a corner round by at most 2^-53 of their terms each.
double box_corners(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip, glm::dvec4 corners[8]);
// What box_corners builds the corners from: the base corner (box_min transformed), the three
// edge vectors, and that error bound. Corner k is base + (k & 1 ? edge[0] : 0) + (k & 2 ?
// edge[1] : 0) + (k & 4 ? edge[2] : 0), added in that order (the SIMD kernel adds the same).
struct BoxEdges {
    glm::dvec4 base, edge[3];
    double error;
};
BoxEdges box_edges(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip);

// How far points' NDC bounds may move when each of their clip coordinates may be off by
// `error`: at most error (1 + |ndc|) / (w - error) for a point at w, plus the division's own
// rounding. Infinite when the error reaches the nearest w.
double ndc_error_bound(double error, double max_abs_ndc, double min_w);


// The screen rectangle of a box under a model-to-clip matrix (incremental corner transform:
// base corner plus three edge vectors), widened by the corners' error bound and rounded
// outwards, with its nearest w lowered by that bound and rounded down; or,
// returning false, the answer when it needs none (non-finite corners: visible; entirely
// before the near plane: view-culled; crossing it: view-culled when wholly beside the view
// (beside_the_view), else visible).
// orthographic: the buffer's BufferConfig::orthographic, whose corners are taken as their
// orthographic representatives (orthographic_corners).
bool box_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip, float near_w,
                   bool orthographic, ScreenRect& rect, Visibility& decided);
// Whether a box's clip-space corners (box_corners, with their error bound) all lie outside one
// of the view's four side planes, by more than their error and the matrix's rounding (terms:
// clip_term_bounds).
bool beside_the_view(const glm::dvec4 corners[8], double error, const glm::dvec4& terms);
// Per clip row, the sum of its terms' magnitudes over the box: |m_row,j| max(|min_j|, |max_j|)
// over j, plus |m_row,3|.
glm::dvec4 clip_term_bounds(const float box_min[3], const float box_max[3], const std::array<float, 16>& m);
// box_rectangle's last step, from the corners' NDC bounds and nearest w (every corner finite
// and at or beyond the near plane) and their error bound: the rectangle widened and rounded
// outwards, or false (visible) when the bound leaves none. Shared with the SIMD kernel
// (box_rectangle_simd.cpp), which finds the bounds in lanes.
bool rectangle_from_bounds(double min_x, double max_x, double min_y, double max_y, double min_w, double error, ScreenRect& rect,
                           Visibility& decided);
// box_rectangle for a perspective matrix (orthographic false), its corners in SIMD lanes: the
// same rectangle or answer. None for the scalar choice: BufferKernels::box_rectangle.
using BoxRectangleKernel = bool (*)(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip,
                                    float near_w, ScreenRect& rect, Visibility& decided);

// Replaces the eight corners by their orthographic representatives (triangle_setup.hpp) and
// returns a bound on the error of their coordinates, from `error`, the corners' own bound
// (box_corners); infinite when the corners come too near h = 0 to bound it (or beyond twice
// the far distance, where the representatives are NaN).
double orthographic_corners(glm::dvec4 corners[8], double error);

// The coarse stage's code for a rectangle it leaves to the exact stage.
constexpr std::uint8_t kUndecided = 0xFF;

// The batched tests of rectangles [0, count), count <= kRectBlock, in an instruction set's
// SIMD lanes: the coarse stage in SIMD lanes (repeating prepare() and test_rect's coarse check), then
// the exact scan (ScanRect, which test_rect's kernel runs too) of the ones it leaves open: the
// answers of test_rect. None for the scalar choice: BufferKernels::rect_block.
constexpr std::size_t kRectBlock = 256;
using RectBlockKernel = void (*)(const CoarseRectView& view, const SubtileView& subtiles, const ScreenRect* rects, std::size_t count,
                                 Visibility* results);

}  // namespace homcull::detail
