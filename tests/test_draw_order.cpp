// The nearest-first draw order (raster/draw_order.hpp, TriangleInput::order): the sorted copy
// holds every triangle once with its flags, depth classes come nearest first and keep input
// order within, bad triangles come last, every instruction set sorts alike, the list of
// numbers a render on one thread reads instead follows the copy, and a render in that order
// equals a render of the same triangles handed over in that order.
#include "raster/draw_order.hpp"
#include "raster/raster_kernels.hpp"
#include "support.hpp"

#include <homcull/occlusion_buffer.hpp>
#include <homcull/tbb_parallel_for.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace homcull::detail {
namespace {

// The kernels of the instruction set select_isa chose (test::ScopedIsa): those a buffer made now would run.
const RasterKernels& default_kernels() { return raster_kernels(default_isa_choice()); }

// One input of a given kind, with the storage it points into.
struct Input {
    std::vector<float> positions;
    std::vector<std::uint32_t> indices32;
    std::vector<std::uint16_t> indices16;
    std::vector<std::uint8_t> shared;
    std::vector<std::uint32_t> apexes;
    TriangleInput in;
};

enum class Kind { soup4, soup3, strided_soup3, indexed32, indexed16 };
const Kind kKinds[] = {Kind::soup4, Kind::soup3, Kind::strided_soup3, Kind::indexed32, Kind::indexed16};
std::string name(Kind k) {
    const char* names[] = {"packed soup of 4 floats", "packed soup of 3 floats", "soup of 3 floats in 20-byte strides", "32-bit indices",
                           "16-bit indices"};
    return names[int(k)];
}

// n random triangles in front of the camera, w from near_w / 2 to 1000 near_w (some in front of
// near_w, some past the buckets' 2^16 near_w when `far`), some with a NaN coordinate or an
// index out of range when `bad`, under a matrix that scales w by 2.
Input make_input(Kind kind, std::size_t n, std::mt19937_64& rng, bool bad, bool far = false) {
    Input r;
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const bool indexed = kind == Kind::indexed32 || kind == Kind::indexed16;
    const std::size_t vertices = indexed ? std::min<std::size_t>(n, 60000) : 3 * n;
    const std::size_t components = kind == Kind::soup4 ? 4 : 3, stride = kind == Kind::strided_soup3 ? 5 : components;
    r.positions.resize(vertices * stride);
    for (std::size_t v = 0; v < vertices; ++v) {
        float* p = &r.positions[v * stride];
        p[0] = 2.0f * unit(rng) - 1.0f, p[1] = 2.0f * unit(rng) - 1.0f;
        // z is the depth (the matrix below makes w = 2 z): log-uniform in [0.25, 500].
        p[2] = 0.25f * std::pow(2000.0f, unit(rng));
        if (far && v % 7 == 0) p[2] = 1e9f;
        if (components == 4) p[3] = 1.0f;
        if (bad && v % 53 == 5) p[v % 3] = NAN;
    }
    if (indexed) {
        std::uniform_int_distribution<std::uint32_t> vertex(0, std::uint32_t(vertices - 1));
        r.indices32.resize(3 * n);
        for (std::uint32_t& i : r.indices32) i = vertex(rng);
        if (bad)
            for (std::size_t t = 11; t < n; t += 61) r.indices32[3 * t + 1] = std::uint32_t(vertices + t);
        if (kind == Kind::indexed16) r.indices16.assign(r.indices32.begin(), r.indices32.end());
    }
    r.shared.resize(n);
    for (std::uint8_t& s : r.shared) s = std::uint8_t(rng() % 8);
    r.apexes.resize(3 * n);
    for (std::uint32_t& a : r.apexes) a = std::uint32_t(rng() % (vertices + 2));  // sometimes no vertex
    TriangleInput& in = r.in;
    in.positions = r.positions.data();
    in.position_components = int(components);
    in.position_stride = stride * sizeof(float);
    in.vertex_count = vertices;
    in.triangle_count = n;
    if (kind == Kind::indexed32) in.indices = r.indices32.data();
    if (kind == Kind::indexed16) in.indices = r.indices16.data(), in.indices_16bit = true;
    in.shared_edges = r.shared.data();
    in.edge_apexes = r.apexes.data();
    in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0};  // clip w = 2 z
    return r;
}

// Triangle t of an input as comparable words: its indices, or its positions' float bits; and
// its flags.
std::vector<std::uint32_t> triangle_words(const TriangleInput& in, std::size_t t) {
    std::vector<std::uint32_t> words;
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = vertex_index(in, t, k);
        if (in.indices) {
            words.push_back(v);
        } else {
            const unsigned char* p = static_cast<const unsigned char*>(in.positions) + std::size_t(v) * in.position_stride;
            for (int c = 0; c < in.position_components; ++c) {
                std::uint32_t bits;
                std::memcpy(&bits, p + std::size_t(c) * sizeof(float), sizeof bits);
                words.push_back(bits);
            }
        }
    }
    words.push_back(in.shared_edges ? in.shared_edges[t] : 0xFFu);
    // The apexes, as the vertex they name: its number with indices, else its position's bits (a
    // sorted soup numbers its vertices anew); kNoApex past the triangles' vertices.
    for (int k = 0; in.edge_apexes && k < 3; ++k) {
        const std::uint32_t apex = in.edge_apexes[3 * t + std::size_t(k)];
        if (in.indices) {
            words.push_back(apex);
        } else if (apex >= 3 * in.triangle_count) {
            words.push_back(kNoApex);
        } else {
            std::uint32_t bits[4] = {};
            std::memcpy(bits, static_cast<const unsigned char*>(in.positions) + std::size_t(apex) * in.position_stride,
                        std::size_t(in.position_components) * sizeof(float));
            words.insert(words.end(), bits, bits + in.position_components);
        }
    }
    return words;
}

// The nearest clip w of triangle t, in double; NaN for a bad triangle.
double nearest_w(const TriangleInput& in, std::size_t t) {
    double nearest = INFINITY;
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = vertex_index(in, t, k);
        if (v >= in.vertex_count) return NAN;
        float p[4];
        read_position(in, v, p);
        const double w = transform_to_clip(in.model_to_clip, p[0], p[1], p[2], p[3]).w;
        if (std::isnan(w)) return NAN;
        nearest = std::min(nearest, w);
    }
    return nearest;
}

// The bucket of a nearest w as the draw order defines it: 2^-17 of the float bits of
// max(w, near_w) above near_w's. (The SIMD pass computes w in float: it may land one bucket
// off at a boundary.)
int bucket_of(double w, double near_w) {
    if (std::isnan(w)) return int(kDrawOrderBuckets) - 1;
    const float f = float(std::max(w, near_w)), n = float(near_w);
    std::uint32_t bits, near_bits;
    std::memcpy(&bits, &f, sizeof bits);
    std::memcpy(&near_bits, &n, sizeof near_bits);
    return int(std::min<std::uint32_t>((bits - near_bits) >> kDrawOrderBucketShift, kDrawOrderBuckets - 2));
}

// Checks that `sorted` holds each triangle of `in` once, with its flags, and returns for each
// sorted position the input triangle it holds.
std::vector<std::size_t> input_positions(const TriangleInput& in, const TriangleInput& sorted, const std::string& where) {
    EXPECT_EQ(sorted.triangle_count, in.triangle_count) << where;
    EXPECT_EQ(sorted.order, DrawOrder::as_given) << where;
    std::multimap<std::vector<std::uint32_t>, std::size_t> by_words;
    for (std::size_t t = 0; t < in.triangle_count; ++t) by_words.emplace(triangle_words(in, t), t);
    std::vector<std::size_t> from(sorted.triangle_count, 0);
    for (std::size_t p = 0; p < sorted.triangle_count; ++p) {
        const auto it = by_words.find(triangle_words(sorted, p));
        if (it == by_words.end()) {
            ADD_FAILURE() << where << ": sorted triangle " << p << " is not an input triangle (or is there twice)";
            return {};
        }
        from[p] = it->second;
        by_words.erase(it);
    }
    return from;
}

// Checks a sorted copy of `in`: every triangle once with its flags; nearest class first and
// input order within a class (a triangle placed before one of a nearer bucket, by more than the
// float rounding's one bucket, shares its class, so it comes first in the input too); bad
// triangles last; and with fewer triangles than classes, every bucket a class of its own, so
// the order is by bucket throughout.
void check_order(const TriangleInput& in, const TriangleInput& sorted, double near_w, const std::string& where) {
    const std::size_t n = in.triangle_count;
    const std::vector<std::size_t> from = input_positions(in, sorted, where);
    ASSERT_EQ(from.size(), n) << where;
    std::vector<long> latest_input(kDrawOrderBuckets, -1);  // per bucket, the latest input number placed so far
    std::size_t out_of_bucket_order = 0;
    bool bad_seen = false;
    for (std::size_t p = 0; p < n; ++p) {
        const double w = nearest_w(in, from[p]);
        const int b = bucket_of(w, near_w);
        for (int farther = b + 2; farther < int(kDrawOrderBuckets); ++farther) {
            if (latest_input[std::size_t(farther)] < 0) continue;
            ++out_of_bucket_order;
            ASSERT_LT(latest_input[std::size_t(farther)], long(from[p])) << where << ": position " << p;
        }
        latest_input[std::size_t(b)] = std::max(latest_input[std::size_t(b)], long(from[p]));
        ASSERT_FALSE(bad_seen && !std::isnan(w)) << where << ": a good triangle at " << p << " after a bad one";
        bad_seen = bad_seen || std::isnan(w);
    }
    if (n < kDrawOrderClasses) {
        EXPECT_EQ(out_of_bucket_order, 0u) << where;
    }
}

TEST(DrawOrder, HoldsEveryTriangleOnceNearestClassFirstAndInInputOrderWithin) {
    std::mt19937_64 rng(3);
    const double near_w = 1.0;
    for (const Kind kind : kKinds)
        for (const std::size_t n : {std::size_t(1), std::size_t(31), std::size_t(5000), std::size_t(40000)})
            for (const bool threads : {false, true}) {
                const std::string where = name(kind) + ", " + std::to_string(n) + " triangles" + (threads ? ", job system" : "");
                const Input input = make_input(kind, n, rng, /*bad=*/true, /*far=*/n == 5000);
                DrawOrderScratch scratch;
                TriangleInput sorted;
                ASSERT_TRUE(sort_nearest_first(default_kernels(), input.in, nullptr, near_w, threads ? test::parallel_jobs() : ParallelFor{}, scratch, sorted));
                check_order(input.in, sorted, near_w, where);
            }
}

// Indexed meshes with at most two vertices per triangle are sorted from the render's vertex
// cache (clip w in double, as the selected instruction set transformed it): the same
// properties.
TEST(DrawOrder, SortsFromTheVertexCache) {
    std::mt19937_64 rng(4);
    for (const Kind kind : {Kind::indexed32, Kind::indexed16}) {
        const Input input = make_input(kind, 30000, rng, /*bad=*/true);
        ASSERT_TRUE(use_vertex_cache(input.in));
        const std::size_t plane = input.in.vertex_count + kVertexClipPadding;
        std::vector<double> planes(4 * plane);
        std::vector<std::uint8_t> outcodes(input.in.vertex_count);
        const VertexClip cache{planes.data(), planes.data() + plane, planes.data() + 2 * plane, planes.data() + 3 * plane, outcodes.data()};
        default_kernels().front_end.transform_vertices(input.in, 1.0, 0, input.in.vertex_count, cache);
        DrawOrderScratch scratch;
        TriangleInput sorted;
        ASSERT_TRUE(sort_nearest_first(default_kernels(), input.in, &cache, 1.0, {}, scratch, sorted));
        check_order(input.in, sorted, 1.0, name(kind) + ", from the cache");
    }
}

// Given statistics to count into, the sort from the vertex cache leaves out the triangles the
// setup would skip by their indices and outcodes, counted as the setup counts them, and keeps
// the others in the order the full sort gives them.
TEST(DrawOrder, FromTheVertexCacheLeavesOutWhatTheSetupWouldSkipWithoutReorderingTheRest) {
    std::mt19937_64 rng(8);
    for (const Kind kind : {Kind::indexed32, Kind::indexed16}) {
        Input input = make_input(kind, 30000, rng, /*bad=*/true);
        for (std::size_t v = 0; v < input.in.vertex_count; v += 2) input.positions[3 * v] = 1e3f;  // half the vertices beyond x = w
        ASSERT_TRUE(use_vertex_cache(input.in));
        const TriangleInput& in = input.in;
        const std::size_t plane = in.vertex_count + kVertexClipPadding;
        std::vector<double> planes(4 * plane);
        std::vector<std::uint8_t> outcodes(in.vertex_count);
        const VertexClip cache{planes.data(), planes.data() + plane, planes.data() + 2 * plane, planes.data() + 3 * plane, outcodes.data()};
        default_kernels().front_end.transform_vertices(in, 1.0, 0, in.vertex_count, cache);
        // What the setup keeps and counts.
        RasterStats expected;
        std::vector<bool> kept(in.triangle_count, false);
        std::size_t kept_count = 0;
        TriangleBatch batch{};
        for (std::size_t first = 0; first < in.triangle_count;) {
            first = gather_cached_batch(in, cache, first, in.triangle_count, batch, expected);
            for (int t = 0; t < batch.count; ++t) kept[batch.triangle[t]] = true, ++kept_count;
        }
        ASSERT_GT(expected.invalid, 0u);
        ASSERT_GT(expected.outside, 1000u);
        for (const bool threads : {false, true}) {
            const std::string where = name(kind) + (threads ? ", job system" : "");
            const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
            DrawOrderScratch all_scratch, left_scratch;
            TriangleInput all, left;
            RasterStats skipped;
            ASSERT_TRUE(sort_nearest_first(default_kernels(), in, &cache, 1.0, parallel, all_scratch, all));
            ASSERT_TRUE(sort_nearest_first_leaving_out(default_kernels(), in, cache, 1.0, parallel, left_scratch, left, skipped));
            EXPECT_EQ(skipped.invalid, expected.invalid) << where;
            EXPECT_EQ(skipped.outside, expected.outside) << where;
            EXPECT_EQ(skipped.triangles_in, in.triangle_count - kept_count) << where;
            ASSERT_EQ(left.triangle_count, kept_count) << where;
            const std::vector<std::size_t> from = input_positions(in, all, where);
            ASSERT_EQ(from.size(), in.triangle_count) << where;
            std::size_t p = 0;
            for (const std::size_t t : from) {
                if (!kept[t]) continue;
                ASSERT_EQ(triangle_words(left, p), triangle_words(in, t)) << where << ", position " << p;
                ++p;
            }
        }
    }
}

// A render nearest first counts what a render as given counts (the triangles the sort leaves
// out included), but for the subtiles updated: indexed input with a vertex cache, triangles
// outside the view and invalid ones, on one thread and with a job system.
TEST(DrawOrder, ARenderFromTheCacheNearestFirstCountsAsARenderAsGiven) {
    std::mt19937_64 rng(10);
    Input input = make_input(Kind::indexed32, 30000, rng, /*bad=*/true);
    for (std::size_t v = 0; v < input.in.vertex_count; v += 2) input.positions[3 * v] = 1e3f;  // half the vertices beyond x = w
    TriangleInput in = input.in;
    ASSERT_TRUE(use_vertex_cache(in));
    in.model_to_clip = {0.5f, 0, 0, 0, 0, 0.5f, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0};
    for (const bool threads : {false, true}) {
        const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
        OcclusionBuffer nearest_first(test::buffer_config(320, 180, 2, 0.1f)), as_given(test::buffer_config(320, 180, 2, 0.1f));
        nearest_first.render_frame(in, parallel);
        TriangleInput unsorted = in;
        unsorted.order = DrawOrder::as_given;
        as_given.render_frame(unsorted, parallel);
        RasterStats a = nearest_first.stats(), b = as_given.stats();
        EXPECT_EQ(a.triangles_in, in.triangle_count);
        EXPECT_GT(a.outside, 1000u);
        EXPECT_GT(a.invalid, 0u);
        a.subtiles_updated = b.subtiles_updated = 0;
        EXPECT_TRUE(a == b) << (threads ? "job system" : "one thread");
    }
    // Every triangle left out: the frame is cleared and counted, on one thread and with a job
    // system, over a buffer that held the frame above.
    for (const bool threads : {false, true}) {
        const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
        OcclusionBuffer buffer(test::buffer_config(320, 180, 2, 0.1f)), cleared(test::buffer_config(320, 180, 2, 0.1f));
        TriangleInput inside = in;
        for (std::size_t v = 0; v < in.vertex_count; ++v) input.positions[3 * v] = 0.0f;
        buffer.render_frame(inside, parallel);
        for (std::size_t v = 0; v < in.vertex_count; ++v) input.positions[3 * v] = 1e9f;  // beyond x = w
        buffer.render_frame(in, parallel);
        cleared.clear();
        EXPECT_TRUE(test::same_subtiles(buffer, cleared)) << (threads ? "job system" : "one thread");
        EXPECT_EQ(buffer.stats().triangles_in, in.triangle_count);
        EXPECT_EQ(buffer.stats().outside + buffer.stats().invalid, in.triangle_count);
    }
}

TEST(DrawOrder, TrianglesInFrontOfTheNearPlaneComeFirstAndTiesKeepInputOrder) {
    // Five triangles: w = 8, 0.5 (in front of near_w = 1, so as near), 8, 1, 3: drawn 0.5 and 1
    // (one bucket, input order), then 3, then the two at 8 in input order.
    const float ws[] = {8.0f, 0.5f, 8.0f, 1.0f, 3.0f};
    std::vector<float> xyzw;
    for (std::size_t t = 0; t < 5; ++t)
        for (int k = 0; k < 3; ++k) xyzw.insert(xyzw.end(), {float(t), float(k), 0.0f, ws[t] * (k == 0 ? 1.0f : 1.5f)});
    const TriangleInput in = test::clip_space_input(xyzw);
    DrawOrderScratch scratch;
    TriangleInput sorted;
    ASSERT_TRUE(sort_nearest_first(default_kernels(), in, nullptr, 1.0, {}, scratch, sorted));
    const float* p = static_cast<const float*>(sorted.positions);
    std::vector<int> order;
    for (std::size_t t = 0; t < 5; ++t) order.push_back(int(p[12 * t]));  // each triangle's x is its input number
    EXPECT_EQ(order, (std::vector<int>{1, 3, 4, 0, 2}));

    TriangleInput as_given = in;
    as_given.order = DrawOrder::as_given;
    EXPECT_FALSE(sort_nearest_first(default_kernels(), as_given, nullptr, 1.0, {}, scratch, sorted));
}

// Every kind of input, with a partial last vector in the SIMD passes (20,005 triangles).
TEST(DrawOrder, EveryInstructionSetSortsAlike) {
    std::mt19937_64 rng(5);
    for (const Kind kind : kKinds) {
        const Input input = make_input(kind, 20005, rng, /*bad=*/true);
        std::vector<std::uint32_t> first;
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            DrawOrderScratch scratch;
            TriangleInput sorted;
            ASSERT_TRUE(sort_nearest_first(default_kernels(), input.in, nullptr, 1.0, {}, scratch, sorted));
            check_order(input.in, sorted, 1.0, name(kind) + ", " + isa);
            const std::size_t n = input.in.triangle_count;
            const std::size_t words = kind == Kind::indexed16 ? (3 * n + 1) / 2 : kind == Kind::indexed32 ? 3 * n
                                                                                   : 3 * n * std::size_t(input.in.position_components);
            const std::vector<std::uint32_t> data(scratch.data.begin(), scratch.data.begin() + std::ptrdiff_t(words));
            if (first.empty()) first = data;
            EXPECT_TRUE(data == first) << name(kind) << ", " << isa;
        }
    }
}

// On one thread (a DrawList given), a soup of 4 floats per vertex is sorted as a list of
// numbers instead of a copy: the input itself, its own flags, and the list in the copy's order.
// Other inputs, and a soup with a vertex cache, still get the copy and no list.
TEST(DrawOrder, OneThreadSortsSoupsOfFourFloatsAsAListInTheCopysOrder) {
    std::mt19937_64 rng(6);
    for (const Kind kind : kKinds)
        for (const std::size_t n : {std::size_t(1), std::size_t(31), std::size_t(20005)}) {
            const std::string where = name(kind) + ", " + std::to_string(n) + " triangles";
            const Input input = make_input(kind, n, rng, /*bad=*/true);
            DrawOrderScratch copy_scratch, list_scratch;
            TriangleInput copy, listed;
            DrawList list;
            ASSERT_TRUE(sort_nearest_first(default_kernels(), input.in, nullptr, 1.0, {}, copy_scratch, copy)) << where;
            ASSERT_TRUE(sort_nearest_first(default_kernels(), input.in, nullptr, 1.0, {}, list_scratch, listed, &list)) << where;
            if (kind != Kind::soup4) {
                EXPECT_EQ(list.order, nullptr) << where;
                EXPECT_TRUE(std::equal(copy_scratch.data.begin(), copy_scratch.data.end(), list_scratch.data.begin())) << where;
                continue;
            }
            ASSERT_NE(list.order, nullptr) << where;
            EXPECT_EQ(listed.positions, input.in.positions) << where;
            EXPECT_EQ(listed.shared_edges, input.in.shared_edges) << where;
            EXPECT_EQ(listed.order, DrawOrder::as_given) << where;
            const std::vector<std::size_t> from = input_positions(input.in, copy, where);
            ASSERT_EQ(from.size(), n) << where;
            for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(list.order[k], from[k]) << where << ", position " << k;
        }
    // With a vertex cache there is no list (the setup reads the cache).
    const Input input = make_input(Kind::soup4, 100, rng, /*bad=*/false);
    std::vector<double> planes(4 * (input.in.vertex_count + kVertexClipPadding));
    std::vector<std::uint8_t> outcodes(input.in.vertex_count);
    const std::size_t plane = input.in.vertex_count + kVertexClipPadding;
    const VertexClip cache{planes.data(), planes.data() + plane, planes.data() + 2 * plane, planes.data() + 3 * plane, outcodes.data()};
    default_kernels().front_end.transform_vertices(input.in, 1.0, 0, input.in.vertex_count, cache);
    DrawOrderScratch scratch;
    TriangleInput sorted;
    DrawList list;
    ASSERT_TRUE(sort_nearest_first(default_kernels(), input.in, &cache, 1.0, {}, scratch, sorted, &list));
    EXPECT_EQ(list.order, nullptr);
}

// Rendering nearest first gives the bits of rendering, as given, the triangles in the order the
// sort chose (on one thread through the list, with a job system from the copy); and it updates
// fewer subtiles than rendering them as they come (random in depth): more triangles are found
// hidden.
TEST(DrawOrder, ARenderNearestFirstIsTheRenderOfTheSortedTriangles) {
    std::mt19937_64 rng(9);
    Input input = make_input(Kind::soup4, 30000, rng, /*bad=*/false);
    for (std::size_t v = 0; v < input.in.vertex_count; ++v) input.positions[4 * v + 2] *= 0.02f;  // w in [0.01, 20]
    TriangleInput in = input.in;
    in.model_to_clip = {0.5f, 0, 0, 0, 0, 0.5f, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0};  // within the view
    DrawOrderScratch scratch;
    TriangleInput sorted;
    ASSERT_TRUE(sort_nearest_first(default_kernels(), in, nullptr, 0.1, {}, scratch, sorted));
    for (const bool threads : {false, true}) {
        const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
        OcclusionBuffer nearest_first(test::buffer_config(320, 180, 2, 0.1f)), of_sorted(test::buffer_config(320, 180, 2, 0.1f)),
            as_given(test::buffer_config(320, 180, 2, 0.1f));
        nearest_first.render_frame(in, parallel);
        of_sorted.render_frame(sorted, parallel);
        TriangleInput unsorted = in;
        unsorted.order = DrawOrder::as_given;
        as_given.render_frame(unsorted, parallel);
        EXPECT_TRUE(test::same_subtiles(nearest_first, of_sorted)) << (threads ? "job system" : "one thread");
        EXPECT_EQ(nearest_first.stats().rasterized, as_given.stats().rasterized);
        EXPECT_LT(nearest_first.stats().subtiles_updated, as_given.stats().subtiles_updated);  // more triangles found hidden
    }
}

}  // namespace
}  // namespace homcull::detail
