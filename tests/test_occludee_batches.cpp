// Occludee tests on every instruction set: single rectangle tests, batches of rectangles and
// batches of boxes all give the answers of the exhaustive scalar definition, including for
// invalid, huge, inverted and off-screen input.
#include "buffer/min_pyramid.hpp"
#include "buffer/rect_queries.hpp"
#include "support.hpp"

#include <homcull/occlusion_buffer.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace homcull {
namespace {

std::vector<ScreenRect> random_rects(std::uint64_t seed, int count) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> ndc(-1.3f, 1.3f), w(0.5f, 80.0f), size(0.0f, 0.6f), unit(0.0f, 1.0f);
    std::vector<ScreenRect> rects;
    for (int k = 0; k < count; ++k) {
        const float x0 = ndc(rng), y0 = ndc(rng);
        rects.push_back({x0, y0, x0 + size(rng) * unit(rng), y0 + size(rng) * unit(rng), w(rng)});
    }
    // Edge cases: non-finite, inverted, huge, off-screen, before the near plane, zero width.
    const float inf = INFINITY, nan = NAN;
    rects.push_back({nan, 0, 0.5f, 0.5f, 10});
    rects.push_back({0, 0, inf, 0.5f, 10});
    rects.push_back({0, 0, 0.5f, 0.5f, inf});
    rects.push_back({0.5f, 0, 0.2f, 0.5f, 10});
    rects.push_back({-1e30f, -1e30f, 1e30f, 1e30f, 50});
    rects.push_back({-1e30f, -1e30f, 1e30f, 1e30f, 1.0f});
    rects.push_back({1.5f, 0, 2.0f, 0.5f, 10});
    rects.push_back({0, 0, 0.5f, 0.5f, 0.25f});
    rects.push_back({0.1f, 0.1f, 0.1f, 0.1f, 60});
    rects.push_back({-1, -1, 1, 1, 3.0e38f});
    rects.push_back({-1, -1, 1, 1, std::numeric_limits<float>::max()});  // 1/w below float's normal range
    rects.push_back({-0.5f, -0.5f, 0.5f, 0.5f, 1.0f});                   // at the near plane
    return rects;
}

TEST(OccludeeBatches, EveryInstructionSetAnswersAsTheExhaustiveDefinition) {
    const std::vector<float> xyzw = test::random_clip_triangles(41, 8000, 0.5f, 1.3f);
    const std::vector<ScreenRect> rects = random_rects(5, 60000);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> coordinate(-30.0f, 30.0f), extent(0.0f, 8.0f);
    std::vector<Aabb> boxes;
    for (int k = 0; k < 5000; ++k) {
        Aabb b;
        b.min = {coordinate(rng), coordinate(rng), coordinate(rng) + 20.0f};
        b.max = b.min + glm::vec3(extent(rng), extent(rng), extent(rng));
        boxes.push_back(b);
    }
    boxes.push_back(Aabb{{-1, -1, -100}, {1, 1, 100}});  // crosses the near plane
    boxes.push_back(Aabb{{NAN, 0, 0}, {1, 1, 1}});
    // A camera at the origin looking down +z (clip w = z), 90 degrees.
    std::array<float, 16> m{};
    m[0] = 1, m[5] = 1, m[10] = 1, m[11] = 1, m[14] = -1;

    for (int samples : {1, 2, 4}) {
        BufferConfig config;
        config.width = 211;  // odd sizes: partial subtiles at the right and bottom
        config.height = 97;
        config.samples = samples;
        config.near_w = 1.0f;
        config.isa = "scalar";
        OcclusionBuffer buffer(config);
        buffer.render(test::clip_space_input(xyzw));
        std::vector<Visibility> expected, expected_boxes;
        for (const ScreenRect& r : rects)
            expected.push_back(buffer.test_rect_exhaustive(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min));
        for (const Aabb& b : boxes) expected_boxes.push_back(buffer.test_aabb(&b.min.x, &b.max.x, m));
        const auto occluded = std::count(expected.begin(), expected.end(), Visibility::occluded);
        EXPECT_GT(occluded, 10000) << "the test must exercise both answers";
        EXPECT_GT(std::count(expected.begin(), expected.end(), Visibility::visible), 2000);

        for (const std::string& isa : available_isas()) {
            // A buffer takes its kernels when it is made: one per instruction set.
            config.isa = isa.c_str();
            OcclusionBuffer isa_buffer(config);
            isa_buffer.render(test::clip_space_input(xyzw));
            const std::vector<Visibility> single = test::rect_answers(isa_buffer, rects);
            std::vector<Visibility> batch(rects.size()), box_batch(boxes.size());
            isa_buffer.test_rects(rects.data(), rects.size(), batch.data());
            isa_buffer.test_aabbs(boxes.data(), boxes.size(), m, box_batch.data());
            std::size_t single_wrong = 0, batch_wrong = 0, box_wrong = 0;
            for (std::size_t k = 0; k < rects.size(); ++k) {
                single_wrong += single[k] != expected[k];
                batch_wrong += batch[k] != expected[k];
            }
            for (std::size_t k = 0; k < boxes.size(); ++k) box_wrong += box_batch[k] != expected_boxes[k];
            EXPECT_EQ(single_wrong, 0u) << isa << ", samples " << samples;
            EXPECT_EQ(batch_wrong, 0u) << isa << ", samples " << samples;
            EXPECT_EQ(box_wrong, 0u) << isa << ", samples " << samples;
        }
    }
}

// A wall over the screen's left part, left of x = edge, and rectangles from the left border
// to just before the edge (hidden) or just past it (seen there only): every instruction set's
// single and batched tests must scan rows to their last subtile, past a vector's width (rows
// of 42 subtiles), in short rectangles (rows scanned directly) and tall ones (through the
// pyramid's cells).
TEST(OccludeeBatches, WideRectanglesAreScannedToTheirLastSubtile) {
    for (int samples : {1, 2, 4}) {
        BufferConfig config = test::buffer_config(333, 77, samples, 1.0f);
        for (float edge = -0.9f; edge < 0.95f; edge += 0.05f) {
            const float w = 2.0f;
            // One triangle (a shared edge may leave its samples to neither side): its right edge
            // vertical at x = edge, reaching far beyond the other borders.
            const std::vector<float> wall = {edge * w, -3.0f * w, 0, w, edge * w, 3.0f * w, 0, w, -9.0f * w, 0, 0, w};
            std::vector<ScreenRect> rects;
            std::vector<Visibility> designed;
            for (float height : {0.04f, 0.3f, 1.9f})
                for (float y0 : {-0.95f, -0.2f}) {
                    if (y0 + height > 1.0f) continue;
                    rects.push_back({-0.99f, y0, edge - 0.03f, y0 + height, 10.0f});
                    designed.push_back(Visibility::occluded);
                    rects.push_back({-0.99f, y0, edge + 0.03f, y0 + height, 10.0f});
                    designed.push_back(Visibility::visible);
                }
            for (const std::string& isa : available_isas()) {
                config.isa = isa.c_str();  // a buffer takes its kernels when it is made
                OcclusionBuffer buffer(config);
                buffer.render(test::clip_space_input(wall));
                const std::vector<Visibility> single = test::rect_answers(buffer, rects);
                std::vector<Visibility> batch(rects.size());
                buffer.test_rects(rects.data(), rects.size(), batch.data());
                const std::vector<Visibility> exhaustive = test::rect_answers(buffer, rects, true);
                for (std::size_t k = 0; k < rects.size(); ++k) {
                    EXPECT_EQ(single[k], designed[k]) << isa << ", samples " << samples << ", edge " << edge << ", rectangle " << k;
                    EXPECT_EQ(batch[k], designed[k]) << isa << ", samples " << samples << ", edge " << edge << ", rectangle " << k;
                    EXPECT_EQ(exhaustive[k], designed[k]) << isa << ", samples " << samples << ", edge " << edge << ", rectangle " << k;
                }
            }
        }
    }
}

// prepare_rect's nearest depth over w_min from the smallest near_w to the largest float (1/w in
// float's normal and subnormal ranges, exact or not): the smallest float at or above 1/w
// (nextafter where float() rounded down), raised by a relative 2^-20.
TEST(OccludeeBatches, NearestDepthIsOneOverWRoundedUp) {
    std::mt19937_64 rng(23);
    std::uniform_int_distribution<std::uint32_t> bits(0x00800000u, 0x7F7FFFFFu);  // 2^-126 .. FLT_MAX
    const detail::CoarseRectView view{nullptr, nullptr, nullptr, 0, 64, 32, 0x1.0p-126f};
    std::size_t differing = 0, checked = 0;
    for (int k = 0; k < 200000; ++k) {
        std::uint32_t b = bits(rng);
        if (k < 64) b = 0x00800000u + std::uint32_t(k) * 0x01000000u;  // powers of two: 1/w exact
        float w;
        std::memcpy(&w, &b, sizeof w);
        detail::RectQuery q;
        Visibility decided;
        ASSERT_TRUE(detail::prepare_rect(view, {-0.5f, -0.5f, 0.5f, 0.5f, w}, q, decided)) << w;
        const double inverse = 1.0 / double(w);
        float up = float(inverse);
        if (double(up) < inverse) up = std::nextafter(up, INFINITY);
        differing += q.d_near != up * (1.0f + 0x1.0p-20f);
        ++checked;
    }
    EXPECT_EQ(differing, 0u) << "of " << checked;
}

TEST(OccludeeBatches, EmptyBatchesAndBlockBoundaries) {
    BufferConfig config;
    config.width = 64;
    config.height = 32;
    OcclusionBuffer buffer(config);
    buffer.test_rects(nullptr, 0, nullptr);  // nothing to do, nothing touched
    buffer.test_aabbs(nullptr, 0, {}, nullptr);
    // Counts around the internal block sizes: every answer written, all "visible" on an empty buffer.
    for (std::size_t count : {1u, 7u, 255u, 256u, 257u, 513u}) {
        std::vector<ScreenRect> rects(count, ScreenRect{-0.5f, -0.5f, 0.5f, 0.5f, 10.0f});
        std::vector<Visibility> answers(count, Visibility::view_culled);
        buffer.test_rects(rects.data(), count, answers.data());
        EXPECT_EQ(std::count(answers.begin(), answers.end(), Visibility::visible), std::ptrdiff_t(count));
    }
}

// The level where [x0, x1] x [y0, y1] spans at most 2 x 2 cells, by visiting the levels from 0:
// the definition coarse_level is tested against.
int coarse_level_by_search(int x0, int x1, int y0, int y1, int level_count) {
    int k = 0;
    while (k + 1 < level_count && ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1)) ++k;
    return k;
}

// coarse_level computes what the search over the levels finds: every range of up to 300 cells
// from every start up to 70 (sides alike and not), every level count up to 12.
TEST(OccludeeBatches, CoarseLevelIsTheLevelTheSearchFinds) {
    int checked = 0;
    for (int levels = 1; levels <= 12; ++levels)
        for (int x0 = 0; x0 <= 70; ++x0)
            for (int width : {0, 1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 33, 63, 64, 65, 127, 128, 129, 255, 256, 300})
                for (int height : {0, 1, 2, 3, 6, 8, 13, 64, 200}) {
                    const int y0 = (x0 * 7) % 41;
                    ASSERT_EQ(detail::coarse_level(x0, x0 + width, y0, y0 + height, levels),
                              coarse_level_by_search(x0, x0 + width, y0, y0 + height, levels))
                        << x0 << " + " << width << ", " << y0 << " + " << height << ", " << levels << " levels";
                    ++checked;
                }
    EXPECT_EQ(checked, 12 * 71 * 23 * 9);
}

}  // namespace
}  // namespace homcull
