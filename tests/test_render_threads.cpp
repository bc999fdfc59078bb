// Multithreaded rendering gives the same bits as serial rendering, whatever the order in
// which the caller's job system runs the tasks.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

namespace homcull {
namespace {

// A "job system" that runs the tasks in a shuffled order on the calling thread.
void run_shuffled(void* user, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    std::vector<std::size_t> order(count);
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::shuffle(order.begin(), order.end(), *static_cast<std::mt19937_64*>(user));
    for (std::size_t i : order) task(data, i);
}

// The same subtiles, and the same read-back depth (which includes the per-sample depth when
// the buffers keep one).
bool same_subtiles(const OcclusionBuffer& a, const OcclusionBuffer& b) {
    const auto x = a.subtiles();
    const auto y = b.subtiles();
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i)
        if (x[i].d0 != y[i].d0 || x[i].d1 != y[i].d1 || x[i].mask != y[i].mask || x[i].covered != y[i].covered) return false;
    std::vector<float> depth_a, depth_b;
    a.read_depth(depth_a);
    b.read_depth(depth_b);
    return depth_a == depth_b;
}

TEST(RenderThreads, SameBitsWhateverTheThreadsAndTaskOrder) {
    // Many overlapping random triangles (more than one chunk) at several depths.
    const std::vector<float> xyzw = test::random_clip_triangles(5, 9000, 0.3f);
    const TriangleInput in = test::clip_space_input(xyzw);
    BufferConfig config;
    config.width = 333;
    config.height = 201;
    config.samples = 2;
    config.near_w = 1.0f;
    config.sample_depth = true;

    OcclusionBuffer serial(config), threaded(config), shuffled(config);
    serial.render(in);
    threaded.render(in, tbb_parallel_for());
    std::mt19937_64 order_rng(9);
    shuffled.render(in, ParallelFor{run_shuffled, &order_rng});
    EXPECT_TRUE(same_subtiles(serial, threaded));
    EXPECT_TRUE(same_subtiles(serial, shuffled));
    EXPECT_EQ(serial.stats().subtiles_touched, threaded.stats().subtiles_touched);
    EXPECT_EQ(serial.stats().rasterized, shuffled.stats().rasterized);
    // A second frame into the same buffers reuses the scratch and still agrees.
    serial.clear();
    threaded.clear();
    serial.render(in);
    threaded.render(in, tbb_parallel_for());
    EXPECT_TRUE(same_subtiles(serial, threaded));
}

TEST(RenderThreads, CityFromAboveSameBits) {
    const Scene city = generate_scene("city:seed=8,blocks=6");
    const WorldTriangles occluders = gather_world_triangles(city, objects_with_role(city, "occluder"));
    Camera c;
    c.eye = {-150, 80, -170};
    c.target = {0, 0, 0};
    BufferConfig config;
    config.width = 640;
    config.height = 360;
    config.near_w = float(c.near_plane);
    OcclusionBuffer serial(config), threaded(config);
    const auto clip = clip_from_world(c, 640.0 / 360.0);
    serial.render(occluders.input(clip));
    threaded.render(occluders.input(clip), tbb_parallel_for());
    EXPECT_TRUE(same_subtiles(serial, threaded));
}

}  // namespace
}  // namespace homcull

namespace homcull {
namespace {

// The pyramid-accelerated rectangle test answers exactly as the exhaustive definition.
TEST(RectTest, PyramidAnswersEqualExhaustiveOnes) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<float> ndc(-1.3f, 1.3f), w(1.0f, 80.0f), size(0.01f, 0.5f), unit(0.0f, 1.0f);
    for (int samples : {1, 2, 4}) {
        const std::vector<float> xyzw = test::random_clip_triangles(100 + std::uint64_t(samples), 6000, 0.5f, 1.3f);
        const TriangleInput in = test::clip_space_input(xyzw);
        BufferConfig config;
        config.width = 157;  // odd sizes: partial subtiles at the right and bottom
        config.height = 93;
        config.samples = samples;
        config.near_w = 1.0f;
        OcclusionBuffer buffer(config);
        buffer.render(in);
        std::size_t occluded = 0, mismatches = 0;
        for (int k = 0; k < 200000; ++k) {
            const float x0 = ndc(rng), y0 = ndc(rng);
            const float x1 = x0 + size(rng) * unit(rng) * 2, y1 = y0 + size(rng) * unit(rng) * 2, wq = w(rng);
            const Visibility fast = buffer.test_rect(x0, y0, x1, y1, wq);
            mismatches += fast != buffer.test_rect_exhaustive(x0, y0, x1, y1, wq);
            occluded += fast == Visibility::occluded;
        }
        EXPECT_EQ(mismatches, 0u) << "samples " << samples;
        EXPECT_GT(occluded, 20000u);  // the test exercises both answers
    }
}

}  // namespace
}  // namespace homcull

namespace homcull {
namespace {

// Every instruction set gives the scalar reference's bits: S1-like random triangles at every
// sample count, and a city seen from the street (shared edges, near clipping); with and
// without per-sample depth.
TEST(Isa, EveryInstructionSetGivesTheReferenceBits) {
    const std::vector<float> xyzw = test::random_clip_triangles(23, 20000, 0.4f);
    const Scene city = generate_scene("city:seed=8,blocks=6");
    const WorldTriangles occluders = gather_world_triangles(city, objects_with_role(city, ""));
    Camera street;
    street.eye = {-3, 1.7, -40};
    street.target = {20, 3, 10};
    auto render_all = [&](std::vector<OcclusionBuffer>& out) {
        for (int samples : {1, 2, 4}) {
            BufferConfig config;
            config.width = 301;
            config.height = 173;
            config.samples = samples;
            config.near_w = 1.0f;
            config.sample_depth = samples != 4;
            out.emplace_back(config);
            out.back().render(test::clip_space_input(xyzw));
        }
        BufferConfig config;
        config.width = 777;
        config.height = 333;
        config.near_w = float(street.near_plane);
        config.sample_depth = true;
        out.emplace_back(config);
        out.back().render(occluders.input(clip_from_world(street, 777.0 / 333.0), Backface::none));
    };
    select_isa("scalar");
    std::vector<OcclusionBuffer> reference;
    render_all(reference);
    const std::vector<std::string> isas = available_isas();
    EXPECT_GE(isas.size(), 2u) << "no SIMD instruction set available";
    for (const std::string& isa : isas) {
        select_isa(isa);
        EXPECT_EQ(selected_isa(), isa);
        std::vector<OcclusionBuffer> buffers;
        render_all(buffers);
        for (std::size_t k = 0; k < buffers.size(); ++k)
            EXPECT_TRUE(same_subtiles(reference[k], buffers[k])) << isa << ", buffer " << k;
    }
    select_isa("best");
    EXPECT_THROW(select_isa("mmx"), Error);
}

}  // namespace
}  // namespace homcull
