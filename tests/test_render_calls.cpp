// Many render calls into one buffer, as an engine draws its occluders object by object: each
// call rebuilds only the pyramid cells over the subtiles it changed and starts a noted soup from
// the reference cells the last call left. Both must leave what a full rebuild would.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "buffer/buffer_state.hpp"   // choose_triangle_path
#include "raster/rasterize.hpp"  // set_hidden_skip

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace homcull {
namespace {

void expect_pyramid_and_answers_exact(const OcclusionBuffer& b, const std::string& where) {
    std::vector<float> pyramid;
    b.read_pyramid(pyramid);
    EXPECT_TRUE(pyramid == test::pyramid_by_definition(b)) << where;
    const std::vector<ScreenRect> rects = test::random_screen_rects(7, 400);
    EXPECT_TRUE(test::rect_answers(b, rects) == test::rect_answers(b, rects, /*exhaustive=*/true)) << where;
}

// A clip-space soup (the noted path, whose calls reuse the reference cells) drawn in calls of a
// few triangles: the same buffer as with the hidden-triangle skip off (which reads no cells),
// and a pyramid that matches it after every call.
TEST(RenderCalls, SoupDrawnInManySmallCallsKeepsCellsAndPyramidExact) {
    const std::vector<float> xyzw = test::random_clip_triangles(3, 3000, 0.3f);
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        OcclusionBuffer skipping(test::buffer_config(203, 117, 2, 1.0f)), oracle(test::buffer_config(203, 117, 2, 1.0f));
        std::mt19937_64 rng(11);
        std::size_t calls = 0;
        for (std::size_t first = 0; first < xyzw.size() / 12; ++calls) {
            const std::size_t count = std::min<std::size_t>(1 + rng() % 40, xyzw.size() / 12 - first);
            std::vector<float> part(xyzw.begin() + std::ptrdiff_t(12 * first), xyzw.begin() + std::ptrdiff_t(12 * (first + count)));
            const TriangleInput in = test::clip_space_input(part);
            skipping.render(in);
            detail::set_hidden_skip(false);
            oracle.render(in);
            detail::set_hidden_skip(true);
            first += count;
            if (calls % 16 == 0) expect_pyramid_and_answers_exact(skipping, isa + " after call " + std::to_string(calls));
        }
        EXPECT_TRUE(test::same_subtiles(skipping, oracle)) << isa;
        expect_pyramid_and_answers_exact(skipping, isa + " at the end");
        // A near wall over the whole view, a clear, then more calls: the cells start again from
        // the cleared buffer, not from the wall (which would hide every triangle).
        const std::vector<float> wall = {-2, -2, 0, 1.5f, 2, -2, 0, 1.5f, 2, 2, 0, 1.5f, -2, -2, 0, 1.5f, 2, 2, 0, 1.5f, -2, 2, 0, 1.5f};
        skipping.render(test::clip_space_input(wall));
        skipping.clear();
        oracle.clear();
        const std::vector<float> more = test::random_clip_triangles(4, 200, 0.5f);
        skipping.render(test::clip_space_input(more));
        detail::set_hidden_skip(false);
        oracle.render(test::clip_space_input(more));
        detail::set_hidden_skip(true);
        EXPECT_TRUE(test::same_subtiles(skipping, oracle)) << isa;
        expect_pyramid_and_answers_exact(skipping, isa + " after a clear");
    }
}

// Meshes drawn as clusters, instance by instance, between soups: the pyramid follows every call.
TEST(RenderCalls, ClustersAndIndexedCallsKeepThePyramidExact) {
    // A grid of quads in the plane z = 0, drawn at several places and depths.
    std::vector<float> positions;
    std::vector<std::uint32_t> indices;
    const int n = 6;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) positions.insert(positions.end(), {float(x) / n - 0.5f, float(y) / n - 0.5f, 0.0f});
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const std::uint32_t a = std::uint32_t(y * (n + 1) + x), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
            indices.insert(indices.end(), {a, b, d, a, d, c});
        }
    const std::size_t triangles = indices.size() / 3;
    std::vector<std::uint8_t> shared(triangles);
    std::vector<std::uint32_t> apexes(3 * triangles);
    compute_shared_edges(positions.data(), 12, positions.size() / 3, indices.data(), triangles, shared.data(), apexes.data());
    const OccluderClusters clusters =
        build_occluder_clusters(positions.data(), 12, positions.size() / 3, indices.data(), triangles, shared.data(), apexes.data(), {16, 8});
    OcclusionBuffer buffer(test::buffer_config(160, 90, 1, 0.5f));
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> place(-1.5f, 1.5f), depth(1.0f, 30.0f), size(0.05f, 0.8f);
    for (int call = 0; call < 120; ++call) {
        // Scale s, at NDC (x, y) and depth w: clip = (s w px + x w, s w py + y w, 0, w).
        const float s = size(rng), x = place(rng), y = place(rng), w = depth(rng);
        ClusteredInput in;
        in.clusters = &clusters;
        in.model_to_clip = {s * w, 0, 0, 0, 0, s * w, 0, 0, 0, 0, 0, 0, x * w, y * w, 0, w};
        in.backface = Backface::none;
        buffer.render(in);
        if (call % 10 == 0) expect_pyramid_and_answers_exact(buffer, "after clustered call " + std::to_string(call));
    }
    expect_pyramid_and_answers_exact(buffer, "at the end");
}

// The render path is chosen by one function from the input's declared form and the caller's
// job system, never guessed from the data: a clip-space soup goes through its cell notes only
// when it says so (TriangleInput::clip_space), and gives the bits of the same triangles drawn
// through the identity matrix, on one thread and with a job system, on every instruction set.
TEST(RenderCalls, ClipSpaceSoupsSayWhatTheyAreAndGiveTheIdentityMatrixBits) {
    using detail::TrianglePath;
    const std::vector<float> xyzw = test::random_clip_triangles(21, 20000, 0.3f);
    TriangleInput soup = test::clip_space_input(xyzw);
    EXPECT_EQ(detail::choose_triangle_path(soup, false, true), TrianglePath::noted);
    EXPECT_EQ(detail::choose_triangle_path(soup, true, true), TrianglePath::noted_parts);
    EXPECT_EQ(detail::choose_triangle_path(soup, false, false), TrianglePath::serial);  // no cells: the scalar reference
    TriangleInput plain = soup;
    plain.clip_space = false;  // the same floats and the identity matrix: no longer taken for a soup
    EXPECT_EQ(detail::choose_triangle_path(plain, false, true), TrianglePath::serial);
    EXPECT_EQ(detail::choose_triangle_path(plain, true, true), TrianglePath::binned);
    TriangleInput as_given = soup;
    as_given.order = DrawOrder::as_given;  // notes come with the sort
    EXPECT_EQ(detail::choose_triangle_path(as_given, false, true), TrianglePath::serial);
    // model_to_clip is not read: a soup with a matrix of garbage draws as with the identity.
    TriangleInput ignored = soup;
    ignored.model_to_clip = {3, 1, 4, 1, 5, 9, 2, 6, 5, 3, 5, 8, 9, 7, 9, 3};
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        for (const bool threads : {false, true}) {
            const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
            OcclusionBuffer noted(test::buffer_config(257, 131, 2, 1.0f)), through_matrix(test::buffer_config(257, 131, 2, 1.0f)),
                garbage(test::buffer_config(257, 131, 2, 1.0f));
            noted.render_frame(soup, parallel);
            through_matrix.render_frame(plain, parallel);
            garbage.render_frame(ignored, parallel);
            EXPECT_TRUE(test::same_subtiles(noted, through_matrix)) << isa << (threads ? ", job system" : "");
            EXPECT_TRUE(test::same_pyramid(noted, through_matrix)) << isa << (threads ? ", job system" : "");
            EXPECT_TRUE(noted.stats() == through_matrix.stats()) << isa << (threads ? ", job system" : "");
            EXPECT_TRUE(test::same_subtiles(noted, garbage)) << isa << (threads ? ", job system" : "");
        }
    }
    // A soup that breaks the form is refused, naming it, before anything changes.
    std::vector<std::uint32_t> indices(3 * soup.triangle_count);
    for (std::size_t k = 0; k < indices.size(); ++k) indices[k] = std::uint32_t(k);
    std::vector<std::uint8_t> flags(soup.triangle_count, 0);
    std::vector<std::uint32_t> apexes(3 * soup.triangle_count, kNoApex);
    std::vector<TriangleInput> broken(4, soup);
    broken[0].position_components = 3;
    broken[1].indices = indices.data();
    broken[2].shared_edges = flags.data(), broken[2].edge_apexes = apexes.data();
    broken[3].position_stride = 20;
    OcclusionBuffer buffer(test::buffer_config(64, 32, 1, 1.0f));
    for (const TriangleInput& in : broken) {
        try {
            buffer.render(in);
            ADD_FAILURE() << "a broken clip_space input was drawn";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("clip_space"), std::string::npos) << e.what();
        }
        EXPECT_EQ(buffer.stats().triangles_in, 0u);
        EXPECT_THROW((void)buffer.test_triangles(in), Error);
    }
}

}  // namespace
}  // namespace homcull
