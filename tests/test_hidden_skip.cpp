// The early skip of triangles hidden behind the reference layer (hidden_behind_reference_layer,
// nearest_conservative_depth): it must change no bit of the buffer, of its per-sample depth,
// and no statistic.
#include "raster/raster_kernels.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_batch.hpp"
#include "support.hpp"

#include <homcull/camera.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/io/workload_s1.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace homcull::detail {
namespace {

// nearest_conservative_depth is the largest conservative_depth over its box, on random
// triangles of every size and depth slope (steep ones included, and planes too steep for float),
// over random boxes within their sample bounds.
TEST(HiddenTriangleSkip, NearestDepthIsTheLargestOverTheBox) {
    std::mt19937_64 rng(11);
    const int width = 1920, height = 1080;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    long boxes = 0, samples = 0;
    for (double size : {3.0, 30.0, 300.0}) {
        for (int trial = 0; trial < 3000; ++trial) {
            ScreenTriangle tri;
            const double cx = unit(rng) * width, cy = unit(rng) * height;
            for (int k = 0; k < 3; ++k) {
                tri.p[k] = {cx + (unit(rng) - 0.5) * 2.0 * size, cy + (unit(rng) - 0.5) * 2.0 * size};
                // 1/w from 10^-4 to 10, some planes nearly flat, some steep (a grazing wall)
                tri.d[k] = std::pow(10.0, -4.0 + 5.0 * unit(rng));
            }
            if (trial % 3 == 0) tri.d[1] = tri.d[2] = tri.d[0] * (1.0 + 1e-7 * unit(rng));
            if (trial % 97 == 0) tri.d[2] = 1e30;  // too steep for float: the farthest vertex alone
            RasterTriangle raster;
            if (!setup_raster_triangle(tri, 1.0 / 1024.0, width, height, raster)) continue;
            std::uniform_int_distribution<int> column(raster.i0, raster.i1), row(raster.j0, raster.j1);
            for (int b = 0; b < 4; ++b) {
                int c0 = column(rng), c1 = column(rng), r0 = row(rng), r1 = row(rng);
                if (c0 > c1) std::swap(c0, c1);
                if (r0 > r1) std::swap(r0, r1);
                c1 = std::min(c1, c0 + 63);  // enough samples to meet every rounding, few enough to be quick
                r1 = std::min(r1, r0 + 63);
                const float nearest = nearest_conservative_depth(raster.plane, c0, c1, r0, r1);
                bool reached = false;
                for (int r = r0; r <= r1; ++r)
                    for (int c = c0; c <= c1; ++c) {
                        const float d = conservative_depth(raster.plane, c, r);
                        ASSERT_LE(d, nearest) << "sample (" << c << ", " << r << ") of box [" << c0 << ", " << c1 << "] x [" << r0 << ", "
                                              << r1 << "]";
                        reached = reached || d == nearest;
                        ++samples;
                    }
                EXPECT_TRUE(reached);  // attained at a corner: the largest, not a looser bound
                ++boxes;
            }
        }
    }
    EXPECT_GT(boxes, 20000);
    EXPECT_GT(samples, 1000000);
}

// The setup's lanes compute each unclipped triangle's nearest depth over its whole box
// (BatchSetup::nearest, which the setup tests against the reference layer before it sets up
// the edges) as nearest_conservative_depth of the triangle it assembles, to the bit, on every
// instruction set: random triangles of every size and depth slope, either orientation, some
// flat, some reaching beyond the screen (a box clamped to the grid). (Planes too steep for
// float need a w below the near plane, which clipping handles: no lane of this setup has one.)
TEST(HiddenTriangleSkip, SetupLanesComputeTheBoxNearestDepth) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), depth(0.0, 1.0);
    const int width = 640, height = 360;
    long compared = 0, clamped = 0;
    for (const std::string& isa : available_isas()) {
        if (isa == "scalar") continue;  // the reference sets every triangle up one by one
        const FrontEndKernels& kernels = raster_kernels(isa_choice(isa)).front_end;
        ASSERT_TRUE(kernels.setup_planes && kernels.setup_edges) << isa;
        for (int round = 0; round < 400; ++round) {
            TriangleBatch batch{};
            batch.count = TriangleBatch::kSize;
            const double size = round % 3 == 0 ? 0.01 : round % 3 == 1 ? 0.2 : 1.5;
            const double limit = round % 4 == 3 ? 2.5 : 1.0;  // beyond the screen (in the guard band): a box clamped to the grid
            for (int t = 0; t < batch.count; ++t) {
                const double cx = unit(rng) * 0.9, cy = unit(rng) * 0.9;
                for (int k = 0; k < 3; ++k) {
                    const double w = round % 5 == 0 ? 7.0 : std::pow(10.0, 3.0 * depth(rng));  // 1 to 1000, or flat
                    const double x = std::clamp(cx + unit(rng) * size, -limit, limit), y = std::clamp(cy + unit(rng) * size, -limit, limit);
                    batch.cx[k][t] = x * w, batch.cy[k][t] = y * w, batch.cz[k][t] = 0.0, batch.cw[k][t] = w;
                }
                batch.triangle[t] = std::size_t(t);
            }
            batch.indices_valid = (1u << batch.count) - 1u;
            RasterStats stats;
            kernels.classify(Backface::none, 0.5, batch, stats);
            BatchSetup setup;
            kernels.setup_planes(batch, width, height, setup);
            kernels.setup_edges(batch.count, 1.0 / 1024.0, batch.simple, batch.simple, setup);
            for (int t = 0; t < batch.count; ++t) {
                RasterTriangle tri;
                if (!((batch.simple >> t) & 1u) || !assemble_raster_triangle(setup, t, 0, 1.0 / 1024.0, tri)) continue;
                const float expected = nearest_conservative_depth(tri.plane, tri.i0, tri.i1, tri.j0, tri.j1);
                ASSERT_EQ(std::memcmp(&setup.nearest[t], &expected, sizeof(float)), 0)
                    << isa << ", round " << round << ", lane " << t << ": " << setup.nearest[t] << " against " << expected;
                ++compared;
                clamped += tri.i0 == 0 || tri.j0 == 0 || tri.i1 == width - 1 || tri.j1 == height - 1;
            }
        }
    }
    if (available_isas().size() > 1) {
        EXPECT_GT(compared, 5000);
        EXPECT_GT(clamped, 500);  // boxes at the grid's edge
    }
}

// The layers, the per-sample depth and the statistics are the same with and without the skip
// (set_hidden_skip(false) is the oracle), on every instruction set, one thread and two, with
// and without per-sample depth.
void expect_same_with_and_without_skip(const TriangleInput& in, int width, int height, int samples, float near_w) {
    ASSERT_GT(in.triangle_count, 0u);
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        for (bool sample_depth : {false, true})
            for (bool threads : {false, true}) {
                const std::string where = isa + (threads ? ", two threads" : ", one thread") + (sample_depth ? ", per-sample depth" : "");
                const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
                OcclusionBuffer skipping(test::buffer_config(width, height, samples, near_w, sample_depth));
                OcclusionBuffer oracle(test::buffer_config(width, height, samples, near_w, sample_depth));
                skipping.render_frame(in, parallel);
                set_hidden_skip(false);
                oracle.render_frame(in, parallel);
                set_hidden_skip(true);
                const auto a = skipping.subtiles(), b = oracle.subtiles();
                ASSERT_EQ(a.size(), b.size());
                std::size_t differing = 0;
                for (std::size_t i = 0; i < a.size(); ++i)
                    differing += a[i].d0 != b[i].d0 || a[i].d1 != b[i].d1 || a[i].mask != b[i].mask || a[i].covered != b[i].covered;
                EXPECT_EQ(differing, 0u) << where;
                std::vector<float> depth_a, depth_b;
                skipping.read_sample_depth(depth_a);
                oracle.read_sample_depth(depth_b);
                EXPECT_TRUE(depth_a == depth_b) << where;
                EXPECT_EQ(depth_a.empty(), !sample_depth);
                // Why the skip leaves the per-sample depth alone: every sample's depth is at or in
                // front of its subtile's d0 (d0 is the least of the merge's bounds, each the depth
                // of a triangle covering the sample at the corner the subtile took, which is at
                // most its depth at the sample, by the same monotone roundings as
                // nearest_conservative_depth: layer_merge.hpp).
                std::size_t below_d0 = 0;
                const int sw = skipping.sample_width();
                for (std::size_t k = 0; k < depth_a.size(); ++k) {
                    const int x = int(k % std::size_t(sw)), y = int(k / std::size_t(sw));
                    below_d0 += depth_a[k] < skipping.subtile(x / OcclusionBuffer::kSubtileWidth, y / OcclusionBuffer::kSubtileHeight).d0;
                }
                EXPECT_EQ(below_d0, 0u) << where;
                EXPECT_TRUE(skipping.stats() == oracle.stats()) << where;
            }
    }
}

// Workload S1: 100,000 triangles drawn in an order that leaves about 70 % of them hidden
// behind what is already drawn, most of them skipped.
TEST(HiddenTriangleSkip, ChangesNoBitOnS1) {
    const std::string folder = std::string(HOMCULL_SOURCE_DIR) + "/../shared/workloads/s1";
    if (!std::filesystem::exists(folder + "/occluders_clip_xyzw_f32.bin"))
        GTEST_SKIP() << folder << " is missing (the shared workload S1)";
    const WorkloadS1 s1 = load_workload_s1(folder);
    expect_same_with_and_without_skip(s1.occluder_input(), 480, 270, 4, 1.0f);  // MOC's near plane
    expect_same_with_and_without_skip(s1.occluder_input(), 640, 360, 1, 1.0f);
}

// The castle's occluders from view C0 of DESIGN.md: meshes with shared edges (the double row
// rule), near-clipped triangles.
TEST(HiddenTriangleSkip, ChangesNoBitOnTheCastle) {
    const std::string path = test::shared_scene("intel_castle.glb");
    if (path.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene scene = load_scene(path);
    const WorldTriangles occluders = gather_world_triangles(scene, objects_with_role(scene, "occluder"));
    const Camera c0 = test::castle_view_c0();  // DESIGN.md, "Castle view C0"
    expect_same_with_and_without_skip(occluders.input(clip_from_world(c0, 1280.0 / 720.0), Backface::cw), 1280, 720, 1, 1.0f);
}

// A triangle so far away that its depth bound rounds to 0 in float ("no bound": it leaves the
// depth alone) still adds its samples to `covered`. The skip must not take the empty buffer's
// d0 = 0 for a layer in front of it.
TEST(HiddenTriangleSkip, TrianglesWithoutADepthBoundStillCover) {
    const float w = 1e38f;  // times 10^30 below: w = 10^68, 1/w below the smallest float
    const std::vector<float> xyzw = {-0.5f * w, -0.5f * w, 0.0f, w, 0.9f * w, -0.5f * w, 0.0f, w, 0.0f, 0.9f * w, 0.0f, w};
    TriangleInput in = test::clip_space_input(xyzw);
    in.model_to_clip = {1e30f, 0, 0, 0, 0, 1e30f, 0, 0, 0, 0, 1e30f, 0, 0, 0, 0, 1e30f};
    in.clip_space = false;  // drawn through that matrix
    OcclusionBuffer buffer(test::buffer_config(64, 48, 1, 1.0f));
    buffer.render_frame(in);
    ASSERT_EQ(buffer.stats().rasterized, 1u);
    std::size_t covered = 0;
    for (const auto& s : buffer.subtiles()) {
        EXPECT_EQ(s.d0, 0.0f);
        covered += s.covered != 0;
    }
    EXPECT_GT(covered, 20u);
    expect_same_with_and_without_skip(in, 64, 48, 1, 1.0f);
}

}  // namespace
}  // namespace homcull::detail
