// The per-sample depth computed where queries read it (raster/sample_depth_tiles.hpp) must hold
// the same bits as writing every drawn triangle's samples at once
// (set_deferred_sample_depth(false) is the oracle): after one render, after queries that fill
// some tiles and a second render into the same frame (whose triangles then go into the filled
// tiles at once), with arenas too small for the input (triangles written at once), on every
// instruction set, one thread and two; and queries from two threads at once answer as the oracle.
#include "raster/sample_depth_tiles.hpp"
#include "support.hpp"

#include <homcull/camera.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

namespace homcull::detail {
namespace {

// A buffer configured while set_deferred_sample_depth(deferred).
OcclusionBuffer make_buffer(int width, int height, float near_w, bool deferred) {
    set_deferred_sample_depth(deferred);
    OcclusionBuffer buffer(test::buffer_config(width, height, 1, near_w, /*sample_depth=*/true));
    set_deferred_sample_depth(true);
    return buffer;
}

// Every occludee triangle of `probe` tested one at a time: their answers and deciding triangles.
std::vector<std::size_t> probe_answers(const OcclusionBuffer& buffer, const TriangleInput& probe, std::size_t begin, std::size_t end) {
    std::vector<std::size_t> answers;
    for (std::size_t t = begin; t < end; ++t) {
        TriangleInput one = probe;
        one.triangle_count = t + 1;
        const OcclusionBuffer::TriangleTest r = buffer.test_triangles(one, 0, t);
        answers.push_back(std::size_t(r.visibility) * 1000003u + r.samples);
    }
    return answers;
}

void expect_same_depth(const OcclusionBuffer& deferred, const OcclusionBuffer& oracle, const std::string& where) {
    std::vector<float> a, b;
    deferred.read_sample_depth(a);
    oracle.read_sample_depth(b);
    ASSERT_FALSE(a.empty()) << where;
    std::size_t differing = 0, raised = 0;
    for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) differing += a[k] != b[k], raised += b[k] > 0.0f;
    EXPECT_EQ(a.size(), b.size()) << where;
    EXPECT_EQ(differing, 0u) << where;
    EXPECT_GT(raised, a.size() / 20) << where;  // the input drew something
    const auto sa = deferred.subtiles(), sb = oracle.subtiles();
    std::size_t layers = 0;
    for (std::size_t i = 0; i < sa.size(); ++i) layers += sa[i].d0 != sb[i].d0 || sa[i].d1 != sb[i].d1 || sa[i].mask != sb[i].mask;
    EXPECT_EQ(layers, 0u) << where;
    EXPECT_TRUE(deferred.stats() == oracle.stats()) << where;
}

// `first` then `second` drawn into one frame, with queries of `probe` in between (they fill the
// tiles they read), against the oracle doing the same.
void expect_same_bits(const TriangleInput& first, const TriangleInput& second, const TriangleInput& probe, int width, int height,
                      float near_w) {
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        for (bool threads : {false, true}) {
            const std::string where = isa + (threads ? ", two threads" : ", one thread");
            const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
            OcclusionBuffer deferred = make_buffer(width, height, near_w, true);
            OcclusionBuffer oracle = make_buffer(width, height, near_w, false);
            for (OcclusionBuffer* b : {&deferred, &oracle}) b->render_frame(first, parallel);
            const std::size_t probes = std::min<std::size_t>(probe.triangle_count, 400);
            EXPECT_EQ(probe_answers(deferred, probe, 0, probes), probe_answers(oracle, probe, 0, probes)) << where;
            for (OcclusionBuffer* b : {&deferred, &oracle}) b->render(second, parallel);
            EXPECT_EQ(probe_answers(deferred, probe, 0, probes), probe_answers(oracle, probe, 0, probes)) << where << ", second render";
            expect_same_depth(deferred, oracle, where);

            // Another frame into the same buffers: nothing of the first may remain.
            for (OcclusionBuffer* b : {&deferred, &oracle}) b->render_frame(second, parallel);
            expect_same_depth(deferred, oracle, where + ", next frame");
        }
    }
}

// The castle's occluders from view C0, in two halves; the probes are the first half's triangles.
TEST(DeferredSampleDepth, SameBitsAsWritingEveryTriangleOnTheCastle) {
    const std::string path = test::shared_scene("intel_castle.glb");
    if (path.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene scene = load_scene(path);
    const WorldTriangles occluders = gather_world_triangles(scene, objects_with_role(scene, "occluder"));
    const Camera c0 = test::castle_view_c0();  // DESIGN.md, "Castle view C0"
    const TriangleInput all = occluders.input(clip_from_world(c0, 1280.0 / 720.0), Backface::none);
    TriangleInput first = all, second = all;
    first.triangle_count = all.triangle_count / 2;
    second.indices = static_cast<const std::uint32_t*>(all.indices) + 3 * first.triangle_count;
    second.triangle_count = all.triangle_count - first.triangle_count;
    second.shared_edges = all.shared_edges ? all.shared_edges + first.triangle_count : nullptr;
    second.edge_apexes = all.edge_apexes ? all.edge_apexes + 3 * first.triangle_count : nullptr;
    expect_same_bits(first, second, first, 1280, 720, 1.0f);
}

// Many small clip-space triangles over few rows: more than a group's arena holds, so most are
// written at once into zeroed tiles, the rest listed.
TEST(DeferredSampleDepth, SameBitsWhenTheArenasOverflow) {
    const std::vector<float> many = test::random_clip_triangles(6, 60000, 0.05f);
    const std::vector<float> large = test::random_clip_triangles(7, 300, 1.5f);
    const TriangleInput first = test::clip_space_input(many), second = test::clip_space_input(large);
    expect_same_bits(first, second, second, 320, 180, 0.1f);
    expect_same_bits(second, first, first, 333, 97, 0.1f);  // odd sizes: tiles past the samples
}

// Queries from two threads at once fill the tiles they read under the tiles' states: the same
// answers as the oracle's.
TEST(DeferredSampleDepth, QueriesFromTwoThreadsAnswerAsTheOracle) {
    const std::vector<float> soup = test::random_clip_triangles(8, 4000, 0.3f);
    const TriangleInput input = test::clip_space_input(soup);
    OcclusionBuffer deferred = make_buffer(640, 360, 0.1f, true);
    OcclusionBuffer oracle = make_buffer(640, 360, 0.1f, false);
    deferred.render_frame(input);
    oracle.render_frame(input);
    const std::size_t n = 2000;
    const std::vector<std::size_t> expected = probe_answers(oracle, input, 0, n);
    std::vector<std::size_t> low, high;
    std::thread a([&] { low = probe_answers(deferred, input, 0, n / 2); });
    std::thread b([&] { high = probe_answers(deferred, input, n / 2, n); });
    a.join();
    b.join();
    low.insert(low.end(), high.begin(), high.end());
    EXPECT_EQ(low, expected);
    expect_same_depth(deferred, oracle, "after two threads' queries");
}

}  // namespace
}  // namespace homcull::detail
