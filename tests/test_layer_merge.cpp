// The subtile merge rule (raster/layer_merge.hpp) on its own: against a model that keeps every
// sample's nearest occluder, over random sequences of triangles, it stays conservative, never
// lowers d0 and keeps its invariants; and on hand-made cases it keeps what the quick mask of
// masked occlusion culling loses.
#include "raster/layer_merge.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

namespace homcull::detail {
namespace {

// What the layers say of sample s: d0, or max(d0, d1) in the working layer (subtile_hides).
float layer_bound(const SubtileLayers& l, int s) {
    return (l.mask >> s) & 1u ? std::max(l.d0, l.d1) : l.d0;
}

// Expects the layers (d0, d1, mask).
void expect_layers(const SubtileLayers& got, float d0, float d1, std::uint32_t mask) {
    EXPECT_EQ(got.d0, d0);
    EXPECT_EQ(got.d1, d1);
    EXPECT_EQ(got.mask, mask);
}

// Merges as the row update does: only a triangle in front of d0 enters.
SubtileLayers draw(const SubtileLayers& l, std::uint32_t m, float d_tri, std::uint32_t valid) {
    return d_tri > l.d0 ? merge_triangle_into_layers(l, m, d_tri, valid) : l;
}

TEST(LayerMerge, StaysBehindEverySamplesNearestOccluderAndNeverLowersD0) {
    std::mt19937 rng(20261206);
    std::uniform_real_distribution<float> depth(0.001f, 1.0f);
    // Whole subtiles and the buffer's edge subtiles (columns or rows outside the samples).
    const std::uint32_t valids[] = {0xFFFFFFFFu, 0x0F0F0F0Fu, 0x0000FFFFu, 0x000000FFu, 0x00010101u};
    long layers_kept = 0, promoted = 0;
    for (int run = 0; run < 4000; ++run) {
        const std::uint32_t valid = valids[run % 5];
        SubtileLayers layers{0.0f, 0.0f, 0u};
        float nearest[32] = {};  // per sample: the nearest triangle covering it (0: none)
        const int triangles = 1 + int(rng() % 24);
        for (int t = 0; t < triangles; ++t) {
            std::uint32_t m = std::uint32_t(rng()) & valid;
            if (rng() % 3 == 0) m |= std::uint32_t(rng()) & valid;  // larger ones too
            if (m == 0) continue;
            const float d_tri = depth(rng);
            for (int s = 0; s < 32; ++s)
                if ((m >> s) & 1u) nearest[s] = std::max(nearest[s], d_tri);
            const SubtileLayers before = layers;
            layers = draw(layers, m, d_tri, valid);
            ASSERT_GE(layers.d0, before.d0) << "run " << run;
            ASSERT_EQ(layers.mask & ~valid, 0u) << "run " << run;
            if (layers.mask != 0) {
                ASSERT_GT(layers.d1, layers.d0) << "run " << run;
            }
            bool all_covered = true;
            for (int s = 0; s < 32; ++s) {
                if (!((valid >> s) & 1u)) continue;
                ASSERT_LE(layer_bound(layers, s), nearest[s]) << "run " << run << " sample " << s;
                all_covered = all_covered && nearest[s] > 0.0f;
            }
            // d0 > 0 only once every sample has an occluder (the hidden-triangle skip's premise).
            if (layers.d0 > 0.0f) {
                ASSERT_TRUE(all_covered) << "run " << run;
            }
        }
        layers_kept += layers.mask != 0;
        promoted += layers.d0 > 0.0f;
    }
    // The runs reach both kinds of state.
    EXPECT_GT(layers_kept, 1000);
    EXPECT_GT(promoted, 1000);
}

TEST(LayerMerge, AFartherTriangleDoesNotPullTheNearerLayerBack) {
    // d0 = 0.5 everywhere, the upper half at 0.8; a triangle at 0.6 covers the lower half. The
    // quick mask merges it (2 x 0.8 - (0.6 + 0.5) > 0): a full layer at min(0.8, 0.6), so
    // d0 = 0.6 and the upper half back at 0.6. The merge raises d0 as far and keeps the upper
    // half at 0.8 above it.
    const SubtileLayers layers{0.5f, 0.8f, 0x0000FFFFu};
    expect_layers(merge_triangle_into_layers(layers, 0xFFFF0000u, 0.6f, 0xFFFFFFFFu), 0.6f, 0.8f, 0x0000FFFFu);
}

TEST(LayerMerge, AFartherTriangleLeavesANearLayerThatLiesMuchFartherAboveD0) {
    // d0 = 0.2, the left half at 0.9; a triangle at 0.3 over one sample row of the right half.
    // The quick mask merges it (2 x 0.9 - (0.3 + 0.2) > 0): the left half falls back to 0.3.
    // Here the layer stays at 0.9 (0.7 above d0, more than twice 0.1), and the triangle's
    // samples keep d0.
    const SubtileLayers layers{0.2f, 0.9f, 0x0F0F0F0Fu};
    expect_layers(merge_triangle_into_layers(layers, 0x000000F0u, 0.3f, 0xFFFFFFFFu), 0.2f, 0.9f, 0x0F0F0F0Fu);
    // At 0.6 (0.4 above d0, 0.8 twice over: more than the layer's 0.7), both at 0.6.
    expect_layers(merge_triangle_into_layers(layers, 0x000000F0u, 0.6f, 0xFFFFFFFFu), 0.2f, 0.6f, 0x0F0F0FFFu);
}

TEST(LayerMerge, APartlyCoveredSubtileKeepsEveryCoveredSampleSoThatD0RisesWhenFull) {
    // Nothing under the right half yet (d0 = 0); the left half at 0.3. A triangle at 0.95 over
    // two sample rows of the right half: it lies more than twice as far above d0 as the two
    // together (0.95 against 2 x 0.3), but taking it alone would let the left half down to 0,
    // so that d0 could not rise when the rest is covered (the quick mask does: 0.95 - 0.3 > 0.3).
    // The layer keeps every covered sample at 0.3 instead.
    const SubtileLayers layers{0.0f, 0.3f, 0x0F0F0F0Fu};
    const SubtileLayers merged = merge_triangle_into_layers(layers, 0xF0F00000u, 0.95f, 0xFFFFFFFFu);
    expect_layers(merged, 0.0f, 0.3f, 0xFFFF0F0Fu);
    // The last samples covered at 0.5: d0 rises to 0.3, and the new triangle's samples stay
    // above it. (After the quick mask's first step, which let the left half down, its layer is
    // not full now, and d0 stays 0.)
    expect_layers(merge_triangle_into_layers(merged, 0x0000F0F0u, 0.5f, 0xFFFFFFFFu), 0.3f, 0.5f, 0x0000F0F0u);
}

}  // namespace
}  // namespace homcull::detail
