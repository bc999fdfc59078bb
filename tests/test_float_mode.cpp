// The library computes in IEEE round-to-nearest with subnormals kept (common/float_mode.hpp),
// whatever floating-point mode the calling thread or the job system's threads run in: the same
// bits with flush-to-zero, denormals-are-zero or rounding toward zero set, and each thread's
// mode given back.
#include "common/float_mode.hpp"
#include "support.hpp"

#include <homcull/occlusion_buffer.hpp>

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

namespace homcull {
namespace {

#if defined(__SSE2__) || defined(_M_X64)
constexpr unsigned kFlushToZero = 0x8040u;  // FTZ and DAZ
constexpr unsigned kTowardZero = 0x6000u;    // rounding toward zero
constexpr unsigned kControl = 0xFFC0u;

// A job system whose one worker thread runs in flush-to-zero (as oneTBB's workers did after
// Embree's ray queries): every task of a call on that thread, in order. It counts the tasks
// after which the worker's own mode was not given back.
std::size_t worker_mode_lost = 0;
void run_on_flushing_thread(void* /* user */, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    std::thread worker([&] {
        _mm_setcsr(_mm_getcsr() | kFlushToZero);
        const unsigned mode = _mm_getcsr() & kControl;
        for (std::size_t i = 0; i < count; ++i) {
            task(data, i);
            worker_mode_lost += (_mm_getcsr() & kControl) != mode;
        }
    });
    worker.join();
}

// The triangle of HiddenTriangleSkip.TrianglesWithoutADepthBoundStillCover: 1/w below the
// smallest float, its depth plane in subnormals. Drawn on a flushing worker it changed 34
// subtiles of a 64 x 48 buffer.
std::vector<float> far_triangle() {
    const float w = 1e38f;
    return {-0.5f * w, -0.5f * w, 0.0f, w, 0.9f * w, -0.5f * w, 0.0f, w, 0.0f, 0.9f * w, 0.0f, w};
}

struct Result {
    std::vector<OcclusionBuffer::Subtile> subtiles;
    std::vector<Visibility> answers;
};

// caller_mode: MXCSR control bits set on the calling thread for the calls (0: the default).
Result render_and_test(const ParallelFor& parallel, unsigned caller_mode) {
    const unsigned before = _mm_getcsr();
    _mm_setcsr(before | caller_mode);
    const std::vector<float> xyzw = far_triangle();
    TriangleInput in = test::clip_space_input(xyzw);
    in.model_to_clip = {1e30f, 0, 0, 0, 0, 1e30f, 0, 0, 0, 0, 1e30f, 0, 0, 0, 0, 1e30f};
    in.clip_space = false;  // drawn through that matrix
    OcclusionBuffer buffer(test::buffer_config(64, 300, 1, 1.0f));  // 3 bands of subtile rows: tasks on the job system
    buffer.render_frame(in, parallel);
    Result r{buffer.subtiles(), {}};
    // A wall over the whole view at w = 2.5e38, its 1/w subnormal, and rectangles in front of
    // it and behind it, their 1/w normal (w = 2, 1e37) or subnormal (from 1e38 on): with
    // denormals-are-zero both are 0 and nothing would be behind the wall.
    const float wall_w = 2.5e38f;
    const std::vector<float> wall = {-wall_w, -wall_w, 0, wall_w, wall_w, -wall_w, 0, wall_w, wall_w, wall_w, 0, wall_w,
                                     -wall_w, -wall_w, 0, wall_w, wall_w, wall_w,  0, wall_w, -wall_w, wall_w, 0, wall_w};
    OcclusionBuffer walled(test::buffer_config(64, 48, 1, 1.0f));
    walled.render_frame(test::clip_space_input(wall), parallel);
    for (const OcclusionBuffer* b : {&buffer, &walled})
        for (float w : {2.0f, 1e37f, 1e38f, 2e38f, 3e38f, 3.4e38f}) {
            const ScreenRect rect{-0.2f, -0.2f, 0.1f, 0.1f, w};
            r.answers.push_back(b->test_rect(rect.ndc_min_x, rect.ndc_min_y, rect.ndc_max_x, rect.ndc_max_y, rect.w_min));
            Visibility batch;
            b->test_rects(&rect, 1, &batch);
            r.answers.push_back(batch);
            // The same rectangle as a flat box, (x, y, z) -> clip (x, y, 0, z).
            const Aabb box{glm::vec3(rect.ndc_min_x * w, rect.ndc_min_y * w, w), glm::vec3(rect.ndc_max_x * w, rect.ndc_max_y * w, w)};
            b->test_aabbs(&box, 1, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0}, &batch);
            r.answers.push_back(batch);
        }
    EXPECT_EQ(_mm_getcsr() & kControl, (before | caller_mode) & kControl) << "the caller's mode is given back";
    _mm_setcsr(before);
    return r;
}

bool same(const Result& a, const Result& b) {
    if (a.answers != b.answers || a.subtiles.size() != b.subtiles.size()) return false;
    for (std::size_t i = 0; i < a.subtiles.size(); ++i)
        if (a.subtiles[i].d0 != b.subtiles[i].d0 || a.subtiles[i].d1 != b.subtiles[i].d1 || a.subtiles[i].mask != b.subtiles[i].mask ||
            a.subtiles[i].covered != b.subtiles[i].covered)
            return false;
    return true;
}

TEST(FloatMode, FlushToZeroOnTheCallerOrTheJobSystemChangesNoBit) {
    const ParallelFor flushing{run_on_flushing_thread, nullptr};
    const Result reference = render_and_test({}, 0);
    // The wall hides the rectangles behind it (w = 3e38 and 3.4e38) and no other: 6 rectangles,
    // each tested as a rectangle, in a batch and as a box.
    const std::vector<Visibility> behind_wall(reference.answers.end() - 18, reference.answers.end());
    for (std::size_t k = 0; k < 18; ++k)
        EXPECT_EQ(behind_wall[k], k >= 12 ? Visibility::occluded : Visibility::visible) << "rectangle " << k / 3 << " of the wall";
    EXPECT_TRUE(same(render_and_test({}, kFlushToZero), reference)) << "flush-to-zero on the calling thread";
    EXPECT_TRUE(same(render_and_test({}, kTowardZero), reference)) << "rounding toward zero on the calling thread";
    worker_mode_lost = 0;
    EXPECT_TRUE(same(render_and_test(flushing, 0), reference)) << "flush-to-zero on the job system's thread";
    EXPECT_TRUE(same(render_and_test(flushing, kFlushToZero | kTowardZero), reference)) << "on both";
    EXPECT_EQ(worker_mode_lost, 0u) << "the job system's threads get their mode back after each task";
}
#else
TEST(FloatMode, FlushToZeroOnTheCallerOrTheJobSystemChangesNoBit) { GTEST_SKIP() << "x86 only (MXCSR)"; }
#endif

}  // namespace
}  // namespace homcull
