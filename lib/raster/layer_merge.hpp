#pragma once
// How a subtile's two depth layers take a triangle: the merge of the row update
// (update_subtile_row_reference, and the SIMD kernel UpdateSubtileRows, which repeats these
// float operations lane by lane).
//
// A subtile keeps d0, a bound (1/w, larger is nearer) at or behind every one of its samples'
// occluders, and a working layer: the samples of `mask`, whose occluders lie at or in front of
// d1 (> d0 while the mask is not empty; 0 when it is). Masked occlusion culling (Hasselgren,
// Andersson and Akenine-Möller, "Masked Software Occlusion Culling", HPG 2016, §3.2) keeps the
// same fields and merges by its "quick mask": the layer is dropped for a triangle that lies
// farther in front of it than the layer lies in front of d0, otherwise the two merge at the
// farther depth, and a full layer becomes d0. This merge keeps depth the quick mask throws away:
// - a triangle behind the layer leaves the layer at its depth when the layer lies at least
//   twice as far above d0 as the two merged would (the quick mask always pulls it back);
// - when the layer and the triangle cover the subtile, d0 rises as the quick mask raises it,
//   and the nearer of the two stays above it as the working layer;
// - while the subtile has samples without an occluder, no covered sample is let down to d0, so
//   that d0 rises once the last ones are covered (the quick mask may drop the layer there).
// What the layers keep decides how many subtiles the occludee tests must take to the per-sample
// depth, whose units they then fill (sample_depth_tiles.hpp): on OpenArena's walks this merge
// leaves them about half as many as the quick mask did.
//
// Every sample's new bound is one that a class of samples had (below), so it stays at or behind
// its occluders; d0 never decreases (no class bound is below the old d0), which the
// hidden-triangle skip and the reference cells rely on (hidden_behind_reference_layer,
// reference_cells.hpp); and d0 stays 0 until every sample is covered.
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace homcull::detail {

// A subtile's layers: OcclusionBuffer::Subtile's d0, d1 and mask.
struct SubtileLayers {
    float d0, d1;
    std::uint32_t mask;
};

// The layers after a triangle covering samples m (a subset of `valid`, the subtile's samples
// inside the buffer, not empty) at depth d_tri > layers.d0 (the caller skips the others: they
// add nothing). After it, the samples fall into four classes, each with its bound: in the layer
// and under the triangle (d_near, the nearer of d1 and d_tri), in the layer only (d1), under the
// triangle only (d_tri), in neither (d0). The new d0 is the least bound of any sample.
inline SubtileLayers merge_triangle_into_layers(const SubtileLayers& layers, std::uint32_t m, float d_tri, std::uint32_t valid) {
    const std::uint32_t covered = layers.mask | m, neither = valid & ~covered;
    // The bound all covered samples share: the least of the classes' bounds, d1 (in the layer
    // only), d_tri (under the triangle only) and d_near (in both), which is above the other two
    // and counts only when neither single class has samples. (d1 is 0 when the mask is empty,
    // so the triangle is then the nearer.)
    const float d_near = std::max(layers.d1, d_tri);
    const float d_covered =
        std::min((layers.mask & ~m) != 0 ? layers.d1 : d_near, (m & ~layers.mask) != 0 ? d_tri : d_near);
    const float d0 = neither != 0 ? layers.d0 : d_covered;
    // While some sample has no occluder yet (the new d0 is 0), the layer keeps every covered
    // sample, at the depth they all share: a sample let down to d0 there would hold d0 at 0 once
    // the last samples are covered, where a full layer would have raised it.
    if (d0 == 0.0f) return {d0, d_covered, covered};
    // Two candidates for the layer: the nearer of the old layer and the triangle, alone at its
    // depth, or every covered sample at the depth they share (any other set of classes keeps
    // less: the class in both lies at d_near and shares it with the nearer one's other class;
    // with both single classes, d_covered). The nearer one alone wins when it lies at least
    // twice as far above d0 as all of them would (ties included), all of them when they lie
    // above d0 at all. (Weighing them by their sample counts too decides no more subtiles on
    // the walks, for two population counts per lane.)
    const std::uint32_t near = layers.d1 >= d_tri ? layers.mask : m;
    const float near_lift = d_near - d0, covered_lift = 2.0f * (d_covered - d0);
    if (near_lift > 0.0f && near_lift >= covered_lift) return {d0, d_near, near};
    if (covered_lift > 0.0f) return {d0, d_covered, covered};
    return {d0, 0.0f, 0u};
}

}  // namespace homcull::detail
