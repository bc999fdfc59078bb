// Ground truth for visibility sorting (homcull/truth/sort_truth.hpp): the occlusion edges that
// Embree's every-hit rays give, and the check of a sort against them.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/truth/sort_truth.hpp>

#include <gtest/gtest.h>

#include <algorithm>

namespace homcull {
namespace {

bool has_edge(const SortTruth& truth, std::uint32_t front, std::uint32_t back) {
    return std::any_of(truth.edges.begin(), truth.edges.end(),
                       [&](const OcclusionEdge& e) { return e.front == front && e.back == back && e.rays > 0; });
}

// Three quads one behind the other, all across the view: a ray meets them in order, so the
// edges are 0 -> 1 and 1 -> 2 (0 -> 2 follows from them); every ray shows both.
TEST(SortTruth, StackedQuadsGiveTheEdgesBetweenNeighboursAlongTheRays) {
    Scene scene;
    for (int k = 0; k < 3; ++k) {
        const float z = -2.0f - 2.0f * float(k);
        test::add_quad(scene, "quad" + std::to_string(k), {-50, -50, z}, {50, -50, z}, {50, 50, z}, {-50, 50, z});
    }
    const RayScene rays(scene);
    const Camera camera = test::camera_down_minus_z();
    const Resolution display{32, 18};
    const SortTruth truth = occlusion_edges(rays, scene.objects.size(), camera, display);
    ASSERT_EQ(truth.edges.size(), 2u);
    EXPECT_TRUE(has_edge(truth, 0, 1));
    EXPECT_TRUE(has_edge(truth, 1, 2));
    EXPECT_EQ(truth.rays, 32u * 18u);
    EXPECT_GE(truth.hits, 3u * truth.rays);  // more where a ray meets a quad's diagonal, in both triangles
    EXPECT_EQ(truth.edges[0].rays, truth.rays);

    // Front to back: right; back to front: both edges violated; one layer: right, but a
    // grouping of three objects without a cycle.
    EXPECT_EQ(check_sort(truth, {0, 1, 2}).violations, 0u);
    const SortCheck reversed = check_sort(truth, {2, 1, 0});
    EXPECT_EQ(reversed.violations, 2u);
    EXPECT_EQ(reversed.violating.size(), 2u);
    const SortCheck grouped = check_sort(truth, {0, 0, 0});
    EXPECT_EQ(grouped.violations, 0u);
    EXPECT_EQ(grouped.grouped_layers, 1u);
    EXPECT_EQ(grouped.needless_layers, 1u);
    EXPECT_EQ(grouped.needlessly_grouped, 3u);
    // An object left out: its edges are counted apart, never as violations.
    const SortCheck partial = check_sort(truth, {0, kUnsorted, 1});
    EXPECT_EQ(partial.violations, 0u);
    EXPECT_EQ(partial.unsorted_edges, 2u);
}

// A binary cycle: object 0 is a near quad on the left and a far one on the right, object 1 a
// quad between them across the view. Rays on the left see 0 then 1, on the right 1 then 0:
// only one layer holding both sorts them, and that grouping is needed.
TEST(SortTruth, InterlockedObjectsGiveATrueCycle) {
    Scene scene;
    test::add_interlocked_pair(scene);
    const RayScene rays(scene);
    const SortTruth truth = occlusion_edges(rays, scene.objects.size(), test::camera_down_minus_z(), {40, 20});
    EXPECT_TRUE(has_edge(truth, 0, 1));
    EXPECT_TRUE(has_edge(truth, 1, 0));
    EXPECT_EQ(check_sort(truth, {0, 1}).violations, 1u);
    EXPECT_EQ(check_sort(truth, {1, 0}).violations, 1u);
    const SortCheck together = check_sort(truth, {0, 0});
    EXPECT_EQ(together.violations, 0u);
    EXPECT_EQ(together.grouped_layers, 1u);
    EXPECT_EQ(together.needless_layers, 0u);
    EXPECT_EQ(together.needlessly_grouped, 0u);
}

TEST(SortTruth, InvalidInputIsAnError) {
    Scene scene;
    test::add_box(scene, "box", {-1, -1, -4}, {1, 1, -2});
    const RayScene rays(scene);
    Camera orthographic = test::camera_down_minus_z();
    orthographic.ortho_height = 10.0;
    EXPECT_THROW(occlusion_edges(rays, 1, orthographic, {8, 8}), Error);
    EXPECT_THROW(occlusion_edges(rays, 2, test::camera_down_minus_z(), {8, 8}), Error);
    EXPECT_THROW(occlusion_edges(rays, 1, test::camera_down_minus_z(), {0, 8}), Error);
    // A box alone: rays cross its near and far faces, one object: no edge.
    EXPECT_TRUE(occlusion_edges(rays, 1, test::camera_down_minus_z(), {8, 8}).edges.empty());
}

}  // namespace
}  // namespace homcull
