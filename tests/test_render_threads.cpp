// Multithreaded rendering gives the same bits as serial rendering, whatever the order in
// which the caller's job system runs the tasks.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/tbb_parallel_for.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <new>
#include <numeric>
#include <random>
#include <thread>

namespace homcull {
namespace {

// Renders the buffers again with every available instruction set and expects the scalar
// reference's statistics and subtiles, buffer by buffer; leaves the best one selected.
template <typename RenderAll>
void expect_every_isa_gives(const std::vector<OcclusionBuffer>& reference, RenderAll&& render_all) {
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        std::vector<OcclusionBuffer> buffers;
        render_all(buffers);
        ASSERT_EQ(buffers.size(), reference.size());
        for (std::size_t k = 0; k < buffers.size(); ++k) {
            EXPECT_TRUE(reference[k].stats() == buffers[k].stats()) << isa << ", buffer " << k;
            EXPECT_TRUE(test::same_subtiles(reference[k], buffers[k])) << isa << ", buffer " << k;
        }
    }
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
    threaded.render(in, test::parallel_jobs());
    std::mt19937_64 order_rng(9);
    shuffled.render(in, ParallelFor{test::run_shuffled, &order_rng});
    EXPECT_TRUE(test::same_subtiles(serial, threaded));
    EXPECT_TRUE(test::same_subtiles(serial, shuffled));
    EXPECT_TRUE(test::same_pyramid(serial, threaded));
    EXPECT_TRUE(test::same_pyramid(serial, shuffled));
    EXPECT_EQ(serial.stats().subtiles_updated, threaded.stats().subtiles_updated);
    EXPECT_EQ(serial.stats().rasterized, shuffled.stats().rasterized);
    // A second frame into the same buffers reuses the scratch and still agrees.
    serial.clear();
    threaded.clear();
    serial.render(in);
    threaded.render(in, test::parallel_jobs());
    EXPECT_TRUE(test::same_subtiles(serial, threaded));
}

// With a job system an indexed input is set up in chunks, each into a room of fixed size so
// that the tasks never allocate. Here every triangle crosses the near plane and is clipped into
// two, more than a chunk's room holds: every band then sets such a chunk up itself, and the bits
// are still those of one thread.
TEST(RenderThreads, ChunksClippedBeyondTheirRoomGiveTheSameBits) {
    std::mt19937_64 rng(21);
    std::uniform_real_distribution<float> ndc(-0.9f, 0.9f), far_w(2.0f, 40.0f), size(0.02f, 0.2f);
    std::vector<float> xyzw;
    std::vector<std::uint32_t> indices;
    for (std::uint32_t t = 0; t < 7000; ++t) {
        const float cx = ndc(rng), cy = ndc(rng), r = size(rng);
        const float w[3] = {0.5f, far_w(rng), far_w(rng)};  // the first vertex behind the near plane (w = 1)
        for (int k = 0; k < 3; ++k)
            xyzw.insert(xyzw.end(), {(cx + r * float(k == 1) - r * float(k == 2)) * w[k], (cy + r * float(k == 2)) * w[k], 0.0f, w[k]});
        indices.insert(indices.end(), {3 * t + 2, 3 * t, 3 * t + 1});
    }
    TriangleInput in = test::clip_space_input(xyzw);
    in.clip_space = false;  // indexed: through the identity matrix
    in.indices = indices.data();
    in.triangle_count = indices.size() / 3;
    BufferConfig config;
    config.width = 301;
    config.height = 517;  // five bands
    config.near_w = 1.0f;
    OcclusionBuffer serial(config), threaded(config), shuffled(config);
    serial.render_frame(in);
    threaded.render_frame(in, test::parallel_jobs());
    std::mt19937_64 order_rng(4);
    shuffled.render_frame(in, ParallelFor{test::run_shuffled, &order_rng});
    EXPECT_EQ(serial.stats().near_clipped, in.triangle_count);
    EXPECT_EQ(serial.stats().rasterized, in.triangle_count);  // each into a quad: a fan of two triangles
    for (const OcclusionBuffer* other : {&threaded, &shuffled}) {
        EXPECT_TRUE(serial.stats() == other->stats());
        EXPECT_TRUE(test::same_subtiles(serial, *other));
        EXPECT_TRUE(test::same_pyramid(serial, *other));
    }
}

// render_frame is clear() then render(): the same bits with and without a job system, over a
// buffer that still holds another frame, and the same statistics. With more than 8,192
// triangles a render with a job system goes in several waves, the later ones dropping what
// the earlier ones hid; render() after that adds to the frame, its first wave already testing
// against it.
TEST(RenderThreads, RenderFrameIsClearThenRender) {
    const std::vector<float> first = test::random_clip_triangles(21, 7000, 0.4f), second = test::random_clip_triangles(22, 30000, 0.3f);
    const std::vector<float> third = test::random_clip_triangles(23, 20000, 0.2f);
    BufferConfig config;
    config.width = 301;  // odd sizes: partial subtiles, a last band of a few rows, odd pyramid levels
    config.height = 277;
    config.samples = 2;
    config.near_w = 1.0f;
    config.sample_depth = true;
    std::mt19937_64 order_rng(5);
    for (const ParallelFor& parallel : {ParallelFor{}, test::parallel_jobs(), ParallelFor{test::run_shuffled, &order_rng}}) {
        OcclusionBuffer reference(config), framed(config);
        reference.render(test::clip_space_input(first));
        framed.render(test::clip_space_input(first), parallel);
        reference.clear();
        reference.render(test::clip_space_input(second));
        framed.render_frame(test::clip_space_input(second), parallel);
        EXPECT_TRUE(test::same_subtiles(reference, framed));
        EXPECT_TRUE(test::same_pyramid(reference, framed));
        EXPECT_EQ(reference.stats().rasterized, framed.stats().rasterized);
        EXPECT_EQ(reference.stats().triangles_in, framed.stats().triangles_in);
        EXPECT_EQ(reference.stats().subtiles_updated, framed.stats().subtiles_updated);
        reference.render(test::clip_space_input(third));
        framed.render(test::clip_space_input(third), parallel);
        EXPECT_TRUE(test::same_subtiles(reference, framed));
        EXPECT_TRUE(test::same_pyramid(reference, framed));
        EXPECT_TRUE(reference.stats() == framed.stats());
        // No triangles: an empty frame.
        TriangleInput none = test::clip_space_input(second);
        none.triangle_count = 0;
        framed.render_frame(none, parallel);
        OcclusionBuffer empty(config);
        EXPECT_TRUE(test::same_subtiles(empty, framed));
        EXPECT_TRUE(test::same_pyramid(empty, framed));
        EXPECT_EQ(framed.stats().triangles_in, 0u);
    }
}

// Input render() refuses leaves the last frame in place.
TEST(RenderThreads, RenderFrameThrowsBeforeClearing) {
    BufferConfig config;
    config.width = 64;
    config.height = 48;
    config.near_w = 1.0f;
    OcclusionBuffer buffer(config), reference(config);
    const std::vector<float> xyzw = test::random_clip_triangles(3, 500, 0.5f);
    buffer.render(test::clip_space_input(xyzw));
    reference.render(test::clip_space_input(xyzw));
    TriangleInput bad = test::clip_space_input(xyzw);
    bad.position_components = 2;
    EXPECT_THROW(buffer.render_frame(bad, test::parallel_jobs()), Error);
    EXPECT_TRUE(test::same_subtiles(reference, buffer));
    EXPECT_TRUE(test::same_pyramid(reference, buffer));
}

// A job system that runs tasks in order on the calling thread and throws std::bad_alloc at
// its throw_at-th call, as a bin growing out of memory would in the middle of a render; with
// run_some, that call first runs the first half of its tasks (a job system failing part-way).
struct FailingJobs {
    int calls = 0, throw_at = 0;
    bool run_some = false;
    static void run(void* user, std::size_t count, void (*task)(void*, std::size_t), void* data) {
        auto& self = *static_cast<FailingJobs*>(user);
        const bool fail = ++self.calls == self.throw_at;
        for (std::size_t k = 0; k < (fail ? (self.run_some ? count / 2 : 0) : count); ++k) task(data, k);
        if (fail) throw std::bad_alloc();
    }
};

// Whether the buffer's pyramid is its d0 (level 0) and the minimum of 2 x 2 cells above.
bool pyramid_matches_subtiles(const OcclusionBuffer& buffer) {
    std::vector<float> cells;
    buffer.read_pyramid(cells);
    const int w0 = buffer.subtiles_x(), h0 = buffer.subtiles_y();
    std::size_t offset = 0;
    for (int ty = 0; ty < h0; ++ty)
        for (int tx = 0; tx < w0; ++tx)
            if (cells[offset + std::size_t(ty) * std::size_t(w0) + std::size_t(tx)] != buffer.subtile(tx, ty).d0) return false;
    for (int w = w0, h = h0; w > 1 || h > 1;) {
        const int upper_w = (w + 1) / 2, upper_h = (h + 1) / 2;
        const std::size_t upper = offset + std::size_t(w) * std::size_t(h);
        for (int y = 0; y < upper_h; ++y)
            for (int x = 0; x < upper_w; ++x) {
                float m = std::numeric_limits<float>::infinity();
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx)
                        if (2 * x + dx < w && 2 * y + dy < h)
                            m = std::min(m, cells[offset + std::size_t(2 * y + dy) * std::size_t(w) + std::size_t(2 * x + dx)]);
                if (cells[upper + std::size_t(y) * std::size_t(upper_w) + std::size_t(x)] != m) return false;
            }
        offset = upper;
        w = upper_w, h = upper_h;
    }
    return offset + 1 == cells.size();
}

// A render that fails part-way leaves a pyramid that matches what the buffer holds, and no
// subtile farther than the whole frame puts it (nothing of the last frame may hide what is
// now visible) once drawing began, whichever call of the job system fails and whether it ran
// some tasks first.
// A clip-space soup is drawn in parts of rows (one parallel run after the sort's two); with
// shared-edge flags (all zero: the same triangles) the same soup goes in waves (two runs each).
TEST(RenderThreads, ARenderFailingPartWayLeavesAMatchingConservativeBuffer) {
    const std::vector<float> last = test::random_clip_triangles(31, 3000, 0.4f, 0.5f), frame = test::random_clip_triangles(32, 30000, 0.3f);
    BufferConfig config;
    config.width = 301;
    config.height = 277;
    config.samples = 2;
    config.near_w = 1.0f;
    for (const bool in_parts : {true, false}) {
        TriangleInput in = test::clip_space_input(frame);
        in.clip_space = in_parts;  // else the same triangles through the identity matrix: the binned path
        OcclusionBuffer whole(config);
        whole.render(test::clip_space_input(last));
        whole.render_frame(in);
        for (const bool run_some : {false, true}) {
            int failures = 0;
            for (int throw_at = 1; throw_at <= 12; ++throw_at) {
                OcclusionBuffer buffer(config);
                buffer.render(test::clip_space_input(last));
                FailingJobs jobs;
                jobs.throw_at = throw_at;
                jobs.run_some = run_some;
                try {
                    buffer.render_frame(in, ParallelFor{&FailingJobs::run, &jobs, 2});
                } catch (const std::bad_alloc&) {
                    ++failures;
                }
                const std::string where = std::string(in_parts ? "parts" : "waves") + (run_some ? ", some tasks run" : "") + ", call " +
                                          std::to_string(throw_at) + " failed";
                EXPECT_TRUE(pyramid_matches_subtiles(buffer)) << where;
                bool conservative = true;
                for (int ty = 0; ty < buffer.subtiles_y(); ++ty)
                    for (int tx = 0; tx < buffer.subtiles_x(); ++tx)
                        conservative = conservative && buffer.subtile(tx, ty).d0 <= whole.subtile(tx, ty).d0;
                // (A failure in the sort's two calls, before anything is drawn, leaves the last
                // frame whole, as input render_frame refuses does.)
                EXPECT_TRUE(throw_at <= 2 || conservative) << where;
            }
            if (in_parts) {
                EXPECT_EQ(failures, 3);  // the sort's two calls and the parts'
            } else {
                EXPECT_GE(failures, 6);  // the sort's two calls, and at least two of the three waves' two each
                EXPECT_LT(failures, 12);  // and a render that did not fail
            }
        }
    }
}

// Queries are thread-safe while no render is in flight: four threads asking every kind of
// question at once, each in its own order, get the answers one thread gets. (It compares
// answers; it is not a data-race detector.)
TEST(RenderThreads, QueriesFromManyThreadsAnswerAsOneThread) {
    const test::CityStreet street;
    const Scene& city = street.city;
    const auto clip = street.clip(320.0 / 180.0);
    OcclusionBuffer buffer(test::buffer_config(320, 180, 1, float(street.camera.near_plane), /*sample_depth=*/true));
    buffer.render(street.occluders.input(clip));

    const std::vector<ScreenRect> rects = test::random_screen_rects(21, 3000);
    std::vector<Aabb> boxes;
    std::vector<WorldTriangles> objects;
    for (std::uint32_t id = 0; id < city.objects.size(); ++id) {
        boxes.push_back(city.objects[id].world_bounds);
        objects.push_back(gather_world_triangles(city, {id}));
    }
    // Every answer, in the order `start` rotates the questions by.
    struct Answers {
        std::vector<Visibility> rect, rects, box, boxes, triangles;
        std::vector<std::uint64_t> samples;
    };
    const auto ask = [&](std::size_t start) {
        Answers a;
        a.rect.resize(rects.size());
        a.rects.resize(rects.size());
        a.box.resize(boxes.size());
        a.boxes.resize(boxes.size());
        a.triangles.resize(objects.size());
        a.samples.resize(objects.size());
        for (std::size_t n = 0; n < rects.size(); ++n) {
            const std::size_t k = (n + start) % rects.size();
            a.rect[k] = buffer.test_rect(rects[k].ndc_min_x, rects[k].ndc_min_y, rects[k].ndc_max_x, rects[k].ndc_max_y, rects[k].w_min);
        }
        buffer.test_rects(rects.data(), rects.size(), a.rects.data());
        for (std::size_t n = 0; n < boxes.size(); ++n) {
            const std::size_t k = (n + start) % boxes.size();
            a.box[k] = buffer.test_aabb(&boxes[k].min.x, &boxes[k].max.x, clip);
        }
        buffer.test_aabbs(boxes.data(), boxes.size(), clip, a.boxes.data());
        for (std::size_t n = 0; n < objects.size(); ++n) {
            const std::size_t k = (n + start) % objects.size();
            const OcclusionBuffer::TriangleTest t = buffer.test_triangles(objects[k].input(clip));
            a.triangles[k] = t.visibility;
            a.samples[k] = t.samples;
        }
        return a;
    };
    const Answers one = ask(0);
    EXPECT_GT(std::count(one.box.begin(), one.box.end(), Visibility::occluded), 0);  // both answers are exercised
    EXPECT_GT(std::count(one.box.begin(), one.box.end(), Visibility::visible), 0);
    constexpr int kThreads = 4;
    std::vector<Answers> many(kThreads);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) threads.emplace_back([&, t] { many[std::size_t(t)] = ask(std::size_t(t) * 997); });
    for (std::thread& t : threads) t.join();
    for (const Answers& a : many) {
        EXPECT_EQ(a.rect, one.rect);
        EXPECT_EQ(a.rects, one.rect);
        EXPECT_EQ(a.box, one.box);
        EXPECT_EQ(a.boxes, one.box);
        EXPECT_EQ(a.triangles, one.triangles);
        EXPECT_EQ(a.samples, one.samples);
    }
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
    threaded.render(occluders.input(clip), test::parallel_jobs());
    EXPECT_TRUE(test::same_subtiles(serial, threaded));
    EXPECT_TRUE(test::same_pyramid(serial, threaded));
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

// A name select_isa cannot take throws and changes nothing: the selection stays, and the list of
// available instruction sets is the CPU's whatever is selected.
TEST(Isa, ANameThatCannotBeSelectedLeavesTheSelectionAsItWas) {
    const std::vector<std::string> isas = available_isas();
    ASSERT_EQ(isas.front(), "scalar");
    for (const std::string& selected : isas) {
        select_isa(selected);
        EXPECT_THROW(select_isa("bogus"), Error) << selected;
        EXPECT_EQ(selected_isa(), selected);
        for (const char* name : {"avx512", "avx2", "sse4", "sve2_128", "sve_256", "sve2", "sve", "neon", "emu128"})
            if (std::find(isas.begin(), isas.end(), name) == isas.end()) {  // not on this machine or in this build
                EXPECT_THROW(select_isa(name), Error) << selected << " then " << name;
                EXPECT_EQ(selected_isa(), selected) << name;
            }
        EXPECT_EQ(available_isas(), isas) << selected;
    }
    select_isa("best");
    if (isas.size() > 1) {
        EXPECT_EQ(selected_isa(), isas[1]);  // the widest: listed first after scalar
    }
}

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
        // Depths 1/w near the largest float (w from 1e-37, near_w the smallest it may be, 2^-126):
        // the float bounds of the depth plane (float_down, float_up) at the float range's end,
        // and planes too steep for float.
        std::vector<float> tiny_w = xyzw;
        for (float& v : tiny_w) v *= 1e-37f;
        config.width = 301;
        config.height = 173;
        config.near_w = 0x1.0p-126f;
        out.emplace_back(config);
        out.back().render(test::clip_space_input(tiny_w));
    };
    const test::ScopedIsa reference_isa("scalar");
    std::vector<OcclusionBuffer> reference;
    render_all(reference);
    EXPECT_GT(reference.back().stats().rasterized, 10000u);
    EXPECT_GT(reference.back().stats().subtiles_updated, 15000u);  // the street merges triangles into many subtiles
    const std::vector<std::string> isas = available_isas();
    EXPECT_GE(isas.size(), 2u) << "no SIMD instruction set available";
    for (const std::string& isa : isas) {
        const test::ScopedIsa selected(isa);
        EXPECT_EQ(selected_isa(), isa);
        std::vector<OcclusionBuffer> buffers;
        render_all(buffers);
        for (std::size_t k = 0; k < buffers.size(); ++k)
            EXPECT_TRUE(test::same_subtiles(reference[k], buffers[k])) << isa << ", buffer " << k;
    }
    EXPECT_THROW(select_isa("mmx"), Error);
}

}  // namespace
}  // namespace homcull

namespace homcull {
namespace {

// The setup front end decides batches of triangles in SIMD lanes (invalid, outside,
// degenerate, backfacing) and hands the rest to the one-triangle setup; indexed input with at
// most two vertices per triangle first transforms every vertex once, with its outcode. Every
// instruction set counts every statistic as the scalar reference does and gives its bits, with
// and without the vertex cache, and both give the same, on input that reaches every fate:
// vertices behind the eye, beyond the guard band and far outside, huge, collinear, NaN and
// Inf, indices out of range, 16- and 32-bit indices, 4 components with a padded stride, each
// backface mode, and counts that are not a multiple of the batch. Drawn as given: the
// nearest-first order reads the cache's double w but gathers float w without a cache, so the
// two may order triangles apart at a bucket's edge (raster/draw_order.hpp); the front end's
// promise is the same bits for the same order.
TEST(Isa, SetupFrontEndCountsAndDrawsAsTheReference) {
    std::mt19937_64 rng(77);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), w(0.2f, 40.0f);
    // kUsed vertices referenced; the input may declare kUsed + kUnused (then more than two
    // vertices per triangle: no vertex cache).
    constexpr std::size_t kUsed = 3001, kUnused = 40000, kStride = 6;  // x, y, z, w and two floats of padding
    std::vector<float> vertices((kUsed + kUnused) * kStride, 1.0f);
    for (std::size_t v = 0; v < kUsed; ++v) {
        const float wv = (v % 97 == 0) ? -w(rng) : w(rng);  // some behind the eye
        const float spread = v % 13 == 0 ? 200.0f : v % 29 == 0 ? 1e12f : 1.3f;  // beyond the guard band, too large
        float* p = &vertices[v * kStride];
        p[0] = unit(rng) * spread * wv, p[1] = unit(rng) * spread * wv, p[2] = 0.0f, p[3] = wv;
        if (v % 211 == 0) p[v % 2] = std::numeric_limits<float>::quiet_NaN();
        if (v % 223 == 0) p[3] = std::numeric_limits<float>::infinity();
    }
    // Triangles of nearby vertices (small, some collinear), with indices out of range now and then.
    constexpr std::size_t kTriangles = 20011;
    std::vector<std::uint32_t> indices32;
    std::vector<std::uint16_t> indices16;
    for (std::size_t t = 0; t < kTriangles; ++t) {
        const std::uint32_t a = std::uint32_t(rng() % (kUsed - 2));
        std::uint32_t tri[3] = {a, a + 1 + std::uint32_t(t % 2), a + 2 - std::uint32_t(t % 2)};
        if (t % 89 == 0) tri[2] = tri[1];  // zero area
        for (int k = 0; k < 3; ++k) {
            const bool out_of_range = t % 101 == 0 && std::size_t(k) == t % 3;
            indices32.push_back(out_of_range ? 0xFFFFFFF0u : tri[k]);
            indices16.push_back(out_of_range ? std::uint16_t(65535) : std::uint16_t(tri[k]));
        }
    }

    TriangleInput in;
    in.positions = vertices.data();
    in.position_components = 4;
    in.position_stride = kStride * sizeof(float);
    in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    in.order = DrawOrder::as_given;
    // Buffers in pairs: the same triangles with kUsed vertices declared (vertex cache when
    // there are at least half as many triangles) and with kUsed + kUnused (none).
    auto render_all = [&](std::vector<OcclusionBuffer>& out) {
        for (const Backface backface : {Backface::none, Backface::cw, Backface::ccw})
            for (const bool sixteen : {false, true})
                for (const std::size_t count : {kTriangles, std::size_t(7)})
                    for (const std::size_t vertex_count : {kUsed, kUsed + kUnused}) {
                        TriangleInput input = in;
                        input.backface = backface;
                        input.indices_16bit = sixteen;
                        input.indices = sixteen ? static_cast<const void*>(indices16.data()) : indices32.data();
                        input.triangle_count = count;
                        input.vertex_count = vertex_count;
                        out.emplace_back(test::buffer_config(203, 117, 2, 0.5f));
                        out.back().render(input);
                    }
    };
    const test::ScopedIsa reference_isa("scalar");
    std::vector<OcclusionBuffer> reference;
    render_all(reference);
    RasterStats all;
    for (const OcclusionBuffer& b : reference) all += b.stats();
    // Every fate is reached.
    EXPECT_GT(all.invalid, 0u);
    EXPECT_GT(all.outside, 0u);
    EXPECT_GT(all.near_clipped, 0u);
    EXPECT_GT(all.too_large, 0u);
    EXPECT_GT(all.backface_culled, 0u);
    EXPECT_GT(all.degenerate, 0u);
    EXPECT_GT(all.rasterized, 1000u);
    for (std::size_t k = 0; k < reference.size(); k += 2) {  // with and without the vertex cache
        EXPECT_TRUE(reference[k].stats() == reference[k + 1].stats()) << "buffer " << k;
        EXPECT_TRUE(test::same_subtiles(reference[k], reference[k + 1])) << "buffer " << k;
    }
    expect_every_isa_gives(reference, render_all);
}

// Triangle soups (no indices, 4 floats per vertex), which the SIMD targets gather 16
// triangles at a time with a transpose (gather_direct_ready): NaN, infinite, behind-the-eye and
// huge vertices, padding between vertices, a partial last batch, and inputs the fast gather
// must leave to the generic one (x, y, z only; positions not aligned as floats); under the
// identity (TransformBatch's shortcut, with a z alone not finite and signed zeros) and under
// another matrix. Every instruction set gives the scalar reference's statistics and bits.
TEST(Isa, TriangleSoupsGiveTheReferenceBits) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), w(0.2f, 40.0f);
    constexpr std::size_t kTriangles = 3001, kStride = 6;  // x, y, z, w and two floats of padding
    std::vector<float> vertices(3 * kTriangles * kStride, 0.0f);
    for (std::size_t v = 0; v < 3 * kTriangles; ++v) {
        const std::size_t t = v / 3;
        const float wv = (v % 97 == 0) ? -w(rng) : w(rng);
        const float spread = v % 13 == 0 ? 200.0f : v % 29 == 0 ? 1e12f : 0.3f;
        float* p = &vertices[v * kStride];
        // Each triangle near a random centre, so that most are small and on screen.
        const float cx = float(std::sin(double(t))), cy = float(std::cos(double(t * 7)));
        p[0] = (cx + unit(rng) * spread) * wv, p[1] = (cy + unit(rng) * spread) * wv, p[2] = 0.0f, p[3] = wv;
        if (v % 211 == 0) p[v % 2] = std::numeric_limits<float>::quiet_NaN();
        if (v % 223 == 0) p[3] = std::numeric_limits<float>::infinity();
        // Only z not finite: the identity's product makes x NaN (0 * z), so must its shortcut.
        if (v % 227 == 0) p[2] = (v % 2 == 0 ? 1.0f : -1.0f) * std::numeric_limits<float>::infinity();
        if (v % 229 == 0) p[2] = std::numeric_limits<float>::quiet_NaN();
        if (v % 7 == 0) p[v % 3 == 0 ? 0 : 1] = -0.0f;  // zeros whose sign the product may change
    }
    // The same vertices one byte further on: floats no longer aligned.
    std::vector<unsigned char> misaligned(vertices.size() * sizeof(float) + 1);
    std::memcpy(misaligned.data() + 1, vertices.data(), vertices.size() * sizeof(float));

    auto render_all = [&](std::vector<OcclusionBuffer>& out) {
        for (const int components : {4, 3})
            for (const bool aligned : {true, false})
                for (const bool identity : {true, false}) {
                    TriangleInput in;
                    in.positions = aligned ? static_cast<const void*>(vertices.data()) : misaligned.data() + 1;
                    in.position_components = components;
                    in.position_stride = kStride * sizeof(float);
                    in.vertex_count = 3 * kTriangles;
                    in.triangle_count = kTriangles;  // not a multiple of 16
                    // The identity (positions in clip space: TransformBatch's shortcut), and
                    // a matrix that is not (the product).
                    in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
                    if (!identity) in.model_to_clip = {1.5f, 0, 0, 0, 0, -1.25f, 0, 0, 0, 0, 1, 0, 0.25f, 0, 0, 1};
                    in.backface = Backface::none;
                    out.emplace_back(test::buffer_config(203, 117, 2, 0.5f));
                    out.back().render(in);
                }
    };
    const test::ScopedIsa reference_isa("scalar");
    std::vector<OcclusionBuffer> reference;
    render_all(reference);
    const RasterStats& stats = reference.front().stats();
    EXPECT_GT(stats.invalid, 0u);
    EXPECT_GT(stats.outside, 0u);
    EXPECT_GT(stats.near_clipped, 0u);
    EXPECT_GT(stats.too_large, 0u);
    EXPECT_GT(stats.rasterized, 1000u);
    EXPECT_TRUE(reference[0].stats() == reference[2].stats());  // alignment changes nothing
    EXPECT_TRUE(test::same_subtiles(reference[0], reference[2]));
    expect_every_isa_gives(reference, render_all);
}

// The vertex cache as engines feed it: packed x, y, z positions (the deinterleaving path), a
// perspective camera's matrix (no exact products), more vertices than one transform task,
// serial and with TBB. Every instruction set gives the scalar reference's statistics and bits,
// and the reference gives the same without the cache.
TEST(Isa, VertexCacheOnPackedPositionsWithThreadsGivesTheReferenceBits) {
    std::mt19937_64 rng(91);
    std::uniform_real_distribution<float> coordinate(-30.0f, 30.0f), jitter(-0.6f, 0.6f);
    constexpr std::size_t kVertices = 40009, kTriangles = 60013,
                          kUnused = 90000;  // 40,009 vertices: three transform tasks; with the unused ones, more than 2 per triangle
    std::vector<float> positions;
    for (std::size_t v = 0; v < kVertices + kUnused; ++v)
        positions.insert(positions.end(), {coordinate(rng), coordinate(rng), coordinate(rng) - 40.0f});
    std::vector<std::uint32_t> indices;
    for (std::size_t t = 0; t < kTriangles; ++t) {
        const std::uint32_t a = std::uint32_t(rng() % kVertices);
        // Small triangles: neighbours in space are not neighbours in the array, so move two
        // vertices near the first by reusing close indices' positions.
        const std::uint32_t b = std::uint32_t((a + 1) % kVertices), c = std::uint32_t((a + 2) % kVertices);
        for (std::uint32_t k : {b, c})
            for (int axis = 0; axis < 3; ++axis)
                positions[3 * k + std::size_t(axis)] = positions[3 * a + std::size_t(axis)] + jitter(rng);
        indices.insert(indices.end(), {a, b, c});
    }
    Camera camera;
    camera.eye = {3, 2, 5};
    camera.target = {-2, -1, -40};
    TriangleInput in;
    in.positions = positions.data();
    in.vertex_count = kVertices;
    in.indices = indices.data();
    in.triangle_count = kTriangles;
    in.model_to_clip = clip_from_world(camera, 331.0 / 197.0);
    in.backface = Backface::cw;
    const ParallelFor tbb = test::parallel_jobs();
    auto render = [&](std::size_t vertex_count, const ParallelFor& parallel, DrawOrder order = DrawOrder::nearest_first) {
        TriangleInput input = in;
        input.vertex_count = vertex_count;
        input.order = order;
        OcclusionBuffer buffer(test::buffer_config(331, 197, 2, float(camera.near_plane), true));
        buffer.render(input, parallel);
        return buffer;
    };
    const test::ScopedIsa reference_isa("scalar");
    const OcclusionBuffer reference = render(kVertices, {});
    EXPECT_GT(reference.stats().rasterized, 10000u);
    EXPECT_GT(reference.stats().outside + reference.stats().backface_culled, 10000u);
    // With and without the cache (more than two vertices per triangle: none), drawn as given: the
    // nearest-first order may differ at a bucket's edge between the cache's double w and the
    // float w gathered without it (raster/draw_order.hpp).
    const OcclusionBuffer cached = render(kVertices, {}, DrawOrder::as_given);
    const OcclusionBuffer without_cache = render(kVertices + kUnused, {}, DrawOrder::as_given);
    EXPECT_TRUE(cached.stats() == without_cache.stats());
    EXPECT_TRUE(test::same_subtiles(cached, without_cache));
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        for (const bool threads : {false, true}) {
            const OcclusionBuffer b = render(kVertices, threads ? tbb : ParallelFor{});
            EXPECT_TRUE(reference.stats() == b.stats()) << isa << (threads ? ", TBB" : ", serial");
            EXPECT_TRUE(test::same_subtiles(reference, b)) << isa << (threads ? ", TBB" : ", serial");
        }
    }
}

// The scene culler tests the objects left by its traversal in tasks of the job system (one-pass
// and temporal, whose buffer no longer changes): the same answers, levels and counts as on one
// thread, for boxes, parts and occludee triangles, with threads and in a shuffled task order.
// One-pass and temporal culls with a job system traverse the hierarchy in tasks: the same
// answers, node tests and object tests as the front-to-back traversal on one thread.
TEST(RenderThreads, SceneCullerTraversalInTasksAnswersAsOneThread) {
    CityOptions city;
    city.blocks = 5;
    const Scene scene = generate_city(city);
    const std::vector<std::uint32_t> occluders = occluder_candidates(scene, OccluderFilter::role);
    std::vector<Camera> cameras;
    for (int k = 0; k < 6; ++k) {
        Camera c;
        c.eye = {-60.0 + 24.0 * k, 1.7 + 3.0 * (k % 2), -50.0 + 15.0 * k};
        c.target = {10.0 * (k % 3), 2.0, 20.0 - 8.0 * k};
        cameras.push_back(c);
    }
    std::mt19937_64 order(9);
    const ParallelFor shuffled{&test::run_shuffled, &order, 2};
    for (const CullStrategy strategy : {CullStrategy::one_pass, CullStrategy::temporal})
        for (const OccludeeShape shape : {OccludeeShape::box, OccludeeShape::automatic}) {
            SceneCullerConfig config;
            config.display = {320, 180};
            config.strategy = strategy;
            config.occludees = shape;
            SceneCuller serial(scene, occluders, config), threaded(scene, occluders, config), reordered(scene, occluders, config);
            std::vector<OccludeeAnswer> a, b, c;
            std::size_t hidden = 0;
            for (const Camera& camera : cameras) {
                serial.cull(camera, a);
                threaded.cull(camera, b, test::thread_jobs(2));
                reordered.cull(camera, c, shuffled);
                for (std::size_t id = 0; id < a.size(); ++id) {
                    ASSERT_EQ(a[id].visibility, b[id].visibility) << "object " << id;
                    ASSERT_EQ(a[id].level_of_visibility, b[id].level_of_visibility) << "object " << id;
                    ASSERT_EQ(a[id].overlap_exit, b[id].overlap_exit) << "object " << id;
                    ASSERT_EQ(a[id].visibility, c[id].visibility) << "object " << id;
                    hidden += a[id].visibility == Visibility::occluded;
                }
                EXPECT_GT(serial.work().nodes_tested, 0u);
                EXPECT_EQ(serial.work().nodes_tested, threaded.work().nodes_tested);
                EXPECT_EQ(serial.work().nodes_tested, reordered.work().nodes_tested);
                EXPECT_EQ(serial.work().objects_tested, threaded.work().objects_tested);
                EXPECT_EQ(serial.work().objects_tested, reordered.work().objects_tested);
                EXPECT_EQ(serial.work().occludee_parts_tested, threaded.work().occludee_parts_tested);
                EXPECT_EQ(serial.work().occludee_parts_tested, reordered.work().occludee_parts_tested);
            }
            EXPECT_GT(hidden, 0u) << "no object hidden: the views test nothing";
        }
}

}  // namespace
}  // namespace homcull
