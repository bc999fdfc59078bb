// Workload S1 (../shared/workloads/s1): no false culls against an exact double-precision
// depth at the same sample centres, and no more missed culls than Intel MOC (DESIGN.md:
// 3.6 % of hidden rectangles at 1080p, 17.6 % at 360p). Drawn nearest first (the default
// DrawOrder), homcull misses 1.44 % and 3.51 %; the test allows 2 % and 5 %, so that losing the
// draw order (3.48 % and 15.9 % in S1's own order) fails it.
#include "support.hpp"

#include <homcull/io/workload_s1.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/error.hpp>
#include <homcull/truth/exact_depth.hpp>

#include <gtest/gtest.h>

#include <filesystem>

namespace homcull {
namespace {

RectAccuracy measure(const WorkloadS1& s1, int width, int height, int samples) {
    OcclusionBuffer buffer(test::buffer_config(width, height, samples, 1.0f));
    buffer.render(s1.occluder_input(), test::parallel_jobs());
    const ExactDepth exact =
        exact_depth_of_triangles(s1.occluders.data(), s1.occluder_count(), buffer.sample_width(), buffer.sample_height(), true);
    const RectAccuracy a = count_rect_accuracy(buffer, exact, s1.rects.data(), s1.rect_count());
    std::printf("[ s1       ] %dx%d, S = %d: %zu truly hidden, %zu false culls, %zu missed (%.2f %%)\n", width, height, samples,
                a.truly_hidden, a.false_culls, a.missed_culls, 100.0 * double(a.missed_culls) / double(a.truly_hidden));
    return a;
}

TEST(S1Accuracy, NoFalseCullsAndFewerMissesThanMoc) {
    const std::string folder = std::string(HOMCULL_SOURCE_DIR) + "/../shared/workloads/s1";
    if (!std::filesystem::exists(folder + "/rects_ndc_xmin_ymin_xmax_ymax_wmin_f32.bin"))
        GTEST_SKIP() << folder << " is missing (the shared workload S1)";
    const WorkloadS1 s1 = load_workload_s1(folder);
    const RectAccuracy high = measure(s1, 480, 270, 4);  // the samples of a 1920x1080 display
    EXPECT_EQ(high.false_culls, 0u);
    EXPECT_LE(double(high.missed_culls), 0.02 * double(high.truly_hidden));
    const RectAccuracy low = measure(s1, 640, 360, 1);
    EXPECT_EQ(low.false_culls, 0u);
    EXPECT_LE(double(low.missed_culls), 0.05 * double(low.truly_hidden));
}

// The oracle itself on bad input: errors for a bad grid or vertex, defined answers for any
// rectangle (huge coordinates once converted unclamped doubles to int).
TEST(S1Accuracy, ExactDepthOracleOnBadInput) {
    EXPECT_THROW(ExactDepth(-2, 3), Error);
    EXPECT_THROW(ExactDepth(4, 0), Error);
    ExactDepth exact(16, 8);
    const float good[3][4] = {{-2, -2, 0, 2}, {2, -2, 0, 2}, {0, 2, 0, 2}};
    const float nan_vertex[4] = {NAN, 0, 0, 1};
    EXPECT_THROW(exact.add_triangle(good[0], good[1], nan_vertex, false), Error);
    const float huge[3][4] = {{-1e30f, -1e30f, 0, 1}, {1e30f, -1e30f, 0, 1}, {0, 1e30f, 0, 1}};
    exact.add_triangle(huge[0], huge[1], huge[2], false);  // covers everything at w = 1
    exact.finish();
    EXPECT_TRUE(exact.hidden(-1e30f, -1e30f, 1e30f, 1e30f, 2.0f));
    EXPECT_FALSE(exact.hidden(-1e30f, -1e30f, 1e30f, 1e30f, 0.5f));
    EXPECT_FALSE(exact.hidden(NAN, -1, 1, 1, 2.0f));
    EXPECT_FALSE(exact.hidden(1, -1, -1, 1, 2.0f));  // inverted
}

}  // namespace
}  // namespace homcull
