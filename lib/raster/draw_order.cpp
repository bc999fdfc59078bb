#include "raster/draw_order.hpp"

#include "common/run_tasks.hpp"
#include "raster/raster_kernels.hpp"

#include "raster/triangle_setup.hpp"

#include <homcull/error.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

namespace homcull::detail {
namespace {

// A bucket per 2^kDrawOrderBucketShift float bits of w: 2^(23 - 17) = 64 buckets per doubling
// of w, about 1.1 % of w each, from near_w up to 2^16 near_w (kDrawOrderBuckets - 1 buckets);
// farther triangles share the bucket before the last, which holds those with an index out of
// range or a w that is not a number. A fixed scale, not the input's range, so that a task can
// bucket its triangles without waiting for the others.
constexpr std::uint32_t kLastBucket = kDrawOrderBuckets - 1;
// A bit of bucket[t] above the buckets: triangle t is left out of the sorted copy (counted by
// the sort instead of the setup).
constexpr std::uint32_t kSkippedTriangle = 0x8000;
static_assert(kDrawOrderBuckets <= kSkippedTriangle, "buckets fit below the flag");
static_assert(((kLastBucket - 1) >> (23 - kDrawOrderBucketShift)) == 15, "the scale reaches 2^16 near_w");

std::uint32_t float_bits(float f) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    return bits;
}

// The bucket of a nearest clip w (not a NaN) in front of near_w > 0: from the bits of
// float(max(w, near_w)), which increase with w for positive floats (+inf included).
std::uint32_t depth_bucket(double w, std::uint32_t near_bits, double near_w) {
    // Clamped to the largest float first: converting a larger double to float is undefined.
    const double clamped = std::min(std::max(w, near_w), double(std::numeric_limits<float>::max()));
    const std::uint32_t steps = (float_bits(float(clamped)) - near_bits) >> kDrawOrderBucketShift;
    return std::min(steps, kLastBucket - 1);
}

// Clip w of a position of 3 or 4 components (transform_to_clip; its other rows are dead code).
template <int kComponents>
double clip_w(const std::array<float, 16>& m, const unsigned char* vertex) {
    float p[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    std::memcpy(p, vertex, kComponents * sizeof(float));
    return transform_to_clip(m, p[0], p[1], p[2], p[3]).w;
}

// Buckets triangles [begin, end) into bucket[t] and counts them per bucket into count[].
// `w_of(v)` is vertex v's clip w.
template <typename Index, typename W>
void bucket_triangles(const Index* indices, std::size_t begin, std::size_t end, std::size_t vertex_count, double near_w, W&& w_of,
                      std::uint16_t* bucket, std::uint32_t* count) {
    const std::uint32_t near_bits = float_bits(float(near_w));
    for (std::size_t t = begin; t < end; ++t) {
        const std::uint32_t v0 = vertex_index(indices, t, 0), v1 = vertex_index(indices, t, 1), v2 = vertex_index(indices, t, 2);
        std::uint32_t b = kLastBucket;
        if (v0 < vertex_count && v1 < vertex_count && v2 < vertex_count) {
            const double w0 = w_of(v0), w1 = w_of(v1), w2 = w_of(v2);
            // (std::min would hide a NaN in its second argument.)
            if (!std::isnan(w0) && !std::isnan(w1) && !std::isnan(w2)) b = depth_bucket(std::min(std::min(w0, w1), w2), near_bits, near_w);
        }
        bucket[t] = std::uint16_t(b);
        ++count[b];
    }
}

// Per vertex of the cache, what bucket_triangles and gather_cached_batch read of it in one
// word: depth_bucket of its w (kVertexNaN when w is NaN) and its outcode above.
constexpr std::uint32_t kVertexBucketBits = 0x3FF, kVertexNaN = 0x400;
constexpr int kVertexOutcodeShift = 16;
static_assert(kLastBucket <= kVertexBucketBits, "a bucket fits its bits");
void code_vertices(const VertexClip& cache, double near_w, std::size_t begin, std::size_t end, std::uint32_t* code) {
    const std::uint32_t near_bits = float_bits(float(near_w));
    for (std::size_t v = begin; v < end; ++v) {
        const double w = cache.w[v];
        const std::uint32_t b = std::isnan(w) ? kVertexNaN : depth_bucket(w, near_bits, near_w);
        code[v] = b | std::uint32_t(cache.outcode[v]) << kVertexOutcodeShift;
    }
}

// bucket_triangles from the vertices' codes, leaving out the triangles gather_cached_batch
// would skip (an index out of range, a vertex not finite, all three beyond one frustum plane):
// they are marked kSkippedTriangle in bucket[t], counted per bucket into excluded[] as well as
// count[] (the bucket depth_bucket gives the nearest w is the smallest of the vertices',
// as it increases with w), and into `skipped` as that setup counts them.
template <typename Index>
void bucket_from_codes(const Index* indices, std::size_t begin, std::size_t end, std::size_t vertex_count, const std::uint32_t* code,
                       std::uint16_t* bucket, std::uint32_t* count, std::uint32_t* excluded, RasterStats& skipped) {
    std::uint64_t invalid = 0, outside = 0;
    for (std::size_t t = begin; t < end; ++t) {
        const std::uint32_t v0 = vertex_index(indices, t, 0), v1 = vertex_index(indices, t, 1), v2 = vertex_index(indices, t, 2);
        std::uint32_t b = kLastBucket;
        bool skip = true;
        if (v0 < vertex_count && v1 < vertex_count && v2 < vertex_count) {
            const std::uint32_t c0 = code[v0], c1 = code[v1], c2 = code[v2];
            const std::uint32_t any = c0 | c1 | c2, all = c0 & c1 & c2;
            const bool not_finite = ((any >> kVertexOutcodeShift) & kNotFinite) != 0;
            const bool beyond = ((all >> kVertexOutcodeShift) & kOutsidePlanes) != 0;
            if (!(any & kVertexNaN)) b = std::min(std::min(c0 & kVertexBucketBits, c1 & kVertexBucketBits), c2 & kVertexBucketBits);
            invalid += not_finite;
            outside += beyond;  // (a vertex not finite has no plane bits)
            skip = not_finite || beyond;
        } else {
            ++invalid;
        }
        bucket[t] = std::uint16_t(b | (skip ? kSkippedTriangle : 0u));
        ++count[b];
        excluded[b] += skip;
    }
    skipped.triangles_in += invalid + outside;
    skipped.invalid += invalid;
    skipped.outside += outside;
}

void bucket_range(const RasterKernels& kernels, const TriangleInput& in, const VertexClip* cache, const std::uint32_t* vertex_code, double near_w, std::size_t begin,
                  std::size_t end, std::uint16_t* bucket, std::uint32_t* count, std::uint32_t* excluded, RasterStats& skipped,
                  const CellNoteSpec* spec, CellNote* noted) {
    if (vertex_code) {
        with_typed_indices(in, [&](const auto* indices) {
            bucket_from_codes(indices, begin, end, in.vertex_count, vertex_code, bucket, count, excluded, skipped);
        });
        return;
    }
    // Without a vertex cache, in float lanes, a triangle per lane: S1's kind of input (no
    // indices, vertices packed), and indexed inputs whose positions are floats that 32-bit
    // offsets reach. (With a cache, its w is read: gathering the positions instead made castle
    // view C0 1.33 -> 1.45 ms.) Which pass an input takes depends only on the input (and
    // use_vertex_cache, which depends on it), so its order is the same on every instruction set
    // and with any job system.
    const std::array<float, 16>& m = in.model_to_clip;
    const float row[4] = {m[3], m[7], m[11], m[15]};
    const auto* positions = static_cast<const float*>(in.positions);
    const bool float_aligned = reinterpret_cast<std::uintptr_t>(in.positions) % alignof(float) == 0 && in.position_stride % sizeof(float) == 0;
    const std::size_t stride = in.position_stride / sizeof(float);
    // (An orthographic input's w' needs its z too: it takes the double pass.)
    if (!cache && !in.orthographic && !in.indices && float_aligned && stride == std::size_t(in.position_components)) {
        kernels.bucket_packed_soup(positions, in.position_components, begin, end, row, float(near_w), bucket, count, spec, noted);
        return;
    }
    if (!cache && !in.orthographic && in.indices && float_aligned && in.vertex_count > 0 && in.vertex_count <= (std::size_t(1) << 31) / stride) {
        kernels.bucket_indexed(positions, stride, in.position_components, in.indices, in.indices_16bit, in.vertex_count, begin, end, row, float(near_w),
                       bucket, count);
        return;
    }
    // Otherwise in double: from the vertex cache, or transformed here.
    with_typed_indices(in, [&](const auto* indices) {
        const unsigned char* bytes = static_cast<const unsigned char*>(in.positions);
        const std::size_t byte_stride = in.position_stride;
        const auto with = [&](auto&& w_of) { bucket_triangles(indices, begin, end, in.vertex_count, near_w, w_of, bucket, count); };
        if (cache) with([&](std::uint32_t v) { return cache->w[v]; });
        else if (in.orthographic) with([&](std::uint32_t v) {
            float p[4];
            read_position(in, v, p);
            return input_to_clip(in, p[0], p[1], p[2], p[3]).w;
        });
        else if (in.position_components == 4) with([&](std::uint32_t v) { return clip_w<4>(in.model_to_clip, bytes + v * byte_stride); });
        else with([&](std::uint32_t v) { return clip_w<3>(in.model_to_clip, bytes + v * byte_stride); });
    });
}

// Copies each triangle t of [begin, end) to position start[c]++ of the sorted copy, c the depth
// class of its bucket (sort_nearest_first): `copy(t, p)` copies one, with a size known at
// compile time (a copy of run-time size went through a library call per triangle).
template <typename Copy>
void place_triangles(std::size_t begin, std::size_t end, const std::uint16_t* bucket, const std::uint8_t* class_of, std::uint32_t* start,
                     bool some_skipped, Copy&& copy) {
    if (!some_skipped) {
        for (std::size_t t = begin; t < end; ++t) copy(t, std::size_t(start[class_of[bucket[t]]]++));
        return;
    }
    for (std::size_t t = begin; t < end; ++t)
        if (!(bucket[t] & kSkippedTriangle)) copy(t, std::size_t(start[class_of[bucket[t]]]++));
}

void place_range(const TriangleInput& in, bool listed, bool some_skipped, std::size_t begin, std::size_t end, const std::uint16_t* bucket,
                 const std::uint8_t* class_of, std::uint32_t* start, std::uint32_t* data, std::uint8_t* shared_edges,
                 std::uint32_t* edge_apexes, std::uint32_t* placed_at, const CellNote* noted, TriangleNote* sorted_notes) {
    if (listed && noted) {  // the notes with the triangles' numbers: the list of a noted soup
        place_triangles(begin, end, bucket, class_of, start, some_skipped,
                        [&](std::size_t t, std::size_t p) { sorted_notes[p] = {noted[t], std::uint32_t(t)}; });
        return;
    }
    if (listed) {  // the triangles' numbers only (DrawList): shared-edge flags stay the input's
        place_triangles(begin, end, bucket, class_of, start, some_skipped,
                        [&](std::size_t t, std::size_t p) { data[p] = std::uint32_t(t); });
        return;
    }
    const auto place = [&](auto&& copy) {
        if (shared_edges) {  // the flags and their apexes follow their triangles (soups: remap_soup_apexes after)
            place_triangles(begin, end, bucket, class_of, start, some_skipped, [&](std::size_t t, std::size_t p) {
                copy(t, p);
                shared_edges[p] = in.shared_edges[t];
                std::memcpy(edge_apexes + 3 * p, in.edge_apexes + 3 * t, 3 * sizeof(std::uint32_t));
                if (placed_at) placed_at[t] = std::uint32_t(p);
            });
        } else {
            place_triangles(begin, end, bucket, class_of, start, some_skipped, copy);
        }
    };
    const unsigned char* positions = static_cast<const unsigned char*>(in.positions);
    const std::size_t stride = in.position_stride;
    // Without indices, each triangle's 3 vertices packed: 3 or 4 floats each.
    const auto soup = [&](auto components) {
        constexpr std::size_t kWords = decltype(components)::value;
        if (stride == kWords * sizeof(float))
            place([&](std::size_t t, std::size_t p) { std::memcpy(data + 3 * kWords * p, positions + 3 * t * stride, 3 * kWords * sizeof(float)); });
        else
            place([&](std::size_t t, std::size_t p) {
                for (std::size_t k = 0; k < 3; ++k) std::memcpy(data + (3 * p + k) * kWords, positions + (3 * t + k) * stride, kWords * sizeof(float));
            });
    };
    if (in.indices && in.indices_16bit) {
        const auto* indices = static_cast<const std::uint16_t*>(in.indices);
        auto* out = reinterpret_cast<std::uint16_t*>(data);
        place([&](std::size_t t, std::size_t p) { std::memcpy(out + 3 * p, indices + 3 * t, 3 * sizeof(std::uint16_t)); });
    } else if (in.indices) {
        const auto* indices = static_cast<const std::uint32_t*>(in.indices);
        place([&](std::size_t t, std::size_t p) { std::memcpy(data + 3 * p, indices + 3 * t, 3 * sizeof(std::uint32_t)); });
    } else if (in.position_components == 4) {
        soup(std::integral_constant<std::size_t, 4>{});
    } else {
        soup(std::integral_constant<std::size_t, 3>{});
    }
}

// A sorted copy of a soup numbers its vertices anew (3p + k for the triangle placed at p): its
// apexes, copied as the input numbers them, are renumbered so. An apex that is no triangle's
// vertex in the copy becomes kNoApex (its flag is then dropped at render).
void remap_soup_apexes(std::uint32_t* edge_apexes, const std::uint32_t* placed_at, std::size_t count) {
    for (std::size_t i = 0; i < 3 * count; ++i) {
        const std::uint32_t v = edge_apexes[i];
        edge_apexes[i] = v < 3 * count ? 3 * placed_at[v / 3] + v % 3 : kNoApex;
    }
}

}  // namespace

void check_draw_order(const TriangleInput& in) {
    if (in.order == DrawOrder::nearest_first && in.triangle_count > std::size_t(std::numeric_limits<std::uint32_t>::max()))
        throw Error("render: DrawOrder::nearest_first sorts at most 2^32 - 1 triangles per call; split the input or use DrawOrder::as_given");
}

namespace {

// What one counting sort does (the three entry points below): `skip_by` leaves out the
// triangles its outcodes skip; `listed` places numbers (or, with `note_spec`, notes) instead of
// copies. Returns the triangles left out.
struct SortJob {
    const RasterKernels* kernels;
    const TriangleInput* in;
    const VertexClip* cache;    // where the clip w comes from (null: computed)
    const VertexClip* skip_by;  // the cache whose outcodes leave triangles out, or null
    double near_w;
    DrawOrderScratch* scratch;
    bool listed;
    const CellNoteSpec* note_spec;  // null: no notes
};

std::size_t counting_sort(SortJob job, const ParallelFor& parallel, RasterStats* skipped) {
    const TriangleInput& in = *job.in;
    DrawOrderScratch& scratch = *job.scratch;
    const std::size_t n = in.triangle_count;
    const bool listed = job.listed, noting = job.note_spec != nullptr;
    const std::size_t tasks = (n + kDrawOrderTask - 1) / kDrawOrderTask;
    const std::size_t words = noting        ? 0
                              : listed      ? n
                              : in.indices ? (in.indices_16bit ? (3 * n + 1) / 2 : 3 * n)
                                           : 3 * n * std::size_t(in.position_components);
    if (scratch.bucket.size() < n) scratch.bucket.resize(n);
    if (scratch.data.size() < words) scratch.data.resize(words);
    const bool copies_flags = in.shared_edges && !listed;
    if (copies_flags && scratch.shared_edges.size() < n) scratch.shared_edges.resize(n);
    if (copies_flags && scratch.edge_apexes.size() < 3 * n) scratch.edge_apexes.resize(3 * n);
    if (copies_flags && !in.indices && scratch.placed_at.size() < n) scratch.placed_at.resize(n);
    if (scratch.count.size() < tasks * kDrawOrderBuckets) scratch.count.resize(tasks * kDrawOrderBuckets);
    if (scratch.excluded.size() < tasks * kDrawOrderBuckets) scratch.excluded.resize(tasks * kDrawOrderBuckets);
    if (scratch.start.size() < tasks * kDrawOrderClasses) scratch.start.resize(tasks * kDrawOrderClasses);
    if (scratch.skipped.size() < tasks) scratch.skipped.resize(tasks);
    if (noting && scratch.noted.size() < n) scratch.noted.resize(n);
    if (noting && scratch.sorted_notes.size() < n) scratch.sorted_notes.resize(n);
    std::fill_n(scratch.count.begin(), tasks * kDrawOrderBuckets, 0u);
    std::fill_n(scratch.excluded.begin(), tasks * kDrawOrderBuckets, 0u);
    std::fill_n(scratch.skipped.begin(), tasks, RasterStats{});

    if (job.skip_by) {  // each vertex's bucket and outcode in a word, read by its triangles
        if (scratch.vertex_code.size() < in.vertex_count) scratch.vertex_code.resize(in.vertex_count);
        run_tasks(parallel, (in.vertex_count + kDrawOrderTask - 1) / kDrawOrderTask, [](void* data, std::size_t k) {
            const SortJob& j = *static_cast<const SortJob*>(data);
            code_vertices(*j.skip_by, j.near_w, k * kDrawOrderTask, std::min(j.in->vertex_count, (k + 1) * kDrawOrderTask),
                          j.scratch->vertex_code.data());
        }, &job);
    }
    const auto run = [&](void (*task)(void*, std::size_t)) { run_tasks(parallel, tasks, task, &job); };
    run([](void* data, std::size_t k) {
        const SortJob& j = *static_cast<const SortJob*>(data);
        DrawOrderScratch& s = *j.scratch;
        bucket_range(*j.kernels, *j.in, j.cache, j.skip_by ? s.vertex_code.data() : nullptr, j.near_w, k * kDrawOrderTask,
                     std::min(j.in->triangle_count, (k + 1) * kDrawOrderTask), s.bucket.data(), s.count.data() + k * kDrawOrderBuckets,
                     s.excluded.data() + k * kDrawOrderBuckets, s.skipped[k], j.note_spec, j.note_spec ? s.noted.data() : nullptr);
    });
    // The triangles left out, counted as the setup would have (in any task order: sums).
    std::size_t left_out = 0;
    for (std::size_t k = 0; k < tasks; ++k) {
        left_out += std::size_t(scratch.skipped[k].triangles_in);
        if (skipped) *skipped += scratch.skipped[k];
    }

    // The classes: bad triangles (the last bucket) alone in the last class; the other buckets
    // grouped into the classes before it, a new class starting after the bucket where the
    // running count reaches its share, (c + 1) m / (kDrawOrderClasses - 1) for class c of m
    // good triangles (a bucket is never split). Triangles left out count here too, so that
    // leaving them out does not change the order of the others; their places are not counted.
    std::fill_n(scratch.start.begin(), tasks * kDrawOrderClasses, 0u);
    std::uint64_t good = 0;
    for (std::uint32_t b = 0; b < kLastBucket; ++b)
        for (std::size_t k = 0; k < tasks; ++k) good += scratch.count[k * kDrawOrderBuckets + b];
    constexpr std::uint32_t kGoodClasses = kDrawOrderClasses - 1;
    std::uint64_t running = 0;
    std::uint32_t c = 0;
    for (std::uint32_t b = 0; b < kDrawOrderBuckets; ++b) {
        if (b == kLastBucket) c = kGoodClasses;
        scratch.class_of[b] = std::uint8_t(c);
        for (std::size_t k = 0; k < tasks; ++k) {
            const std::uint32_t count = scratch.count[k * kDrawOrderBuckets + b];
            scratch.start[k * kDrawOrderClasses + c] += count - scratch.excluded[k * kDrawOrderBuckets + b];
            running += count;
        }
        if (c + 1 < kGoodClasses && running * kGoodClasses >= std::uint64_t(c + 1) * good) ++c;
    }
    std::uint32_t sum = 0;
    for (std::uint32_t cls = 0; cls < kDrawOrderClasses; ++cls)
        for (std::size_t k = 0; k < tasks; ++k) {
            std::uint32_t& s = scratch.start[k * kDrawOrderClasses + cls];
            const std::uint32_t count = s;
            s = sum;
            sum += count;
        }
    run([](void* data, std::size_t k) {
        const SortJob& j = *static_cast<const SortJob*>(data);
        DrawOrderScratch& s = *j.scratch;
        place_range(*j.in, j.listed, j.skip_by != nullptr, k * kDrawOrderTask, std::min(j.in->triangle_count, (k + 1) * kDrawOrderTask),
                    s.bucket.data(), s.class_of, s.start.data() + k * kDrawOrderClasses, s.data.data(),
                    j.in->shared_edges && !j.listed ? s.shared_edges.data() : nullptr, s.edge_apexes.data(),
                    j.in->shared_edges && !j.listed && !j.in->indices ? s.placed_at.data() : nullptr, j.note_spec ? s.noted.data() : nullptr,
                    s.sorted_notes.data());
    });
    if (copies_flags && !in.indices) remap_soup_apexes(scratch.edge_apexes.data(), scratch.placed_at.data(), n);
    return left_out;
}

// `sorted`: the input as the copy in scratch draws it (indices, or a soup's positions, and
// the flags), left_out triangles fewer.
void point_at_copy(const TriangleInput& in, DrawOrderScratch& scratch, std::size_t left_out, TriangleInput& sorted) {
    const std::size_t n = in.triangle_count;
    sorted = in;
    sorted.order = DrawOrder::as_given;
    sorted.triangle_count = n - left_out;
    sorted.shared_edges = in.shared_edges ? scratch.shared_edges.data() : nullptr;
    sorted.edge_apexes = in.shared_edges ? scratch.edge_apexes.data() : nullptr;
    if (in.indices) {
        sorted.indices = scratch.data.data();
    } else {
        sorted.positions = scratch.data.data();
        sorted.position_stride = std::size_t(in.position_components) * sizeof(float);
        sorted.vertex_count = 3 * n;
    }
}

}  // namespace

bool sort_nearest_first(const RasterKernels& kernels, const TriangleInput& in, const VertexClip* cache, double near_w,
                        const ParallelFor& parallel, DrawOrderScratch& scratch, TriangleInput& sorted, DrawList* list) {
    if (list) *list = DrawList{};
    if (in.order == DrawOrder::as_given || in.triangle_count == 0) return false;
    check_draw_order(in);
    const bool listed = list && !cache && gather_listed_ready(in, 0, std::size_t(TriangleBatch::kSize));
    const std::size_t left_out = counting_sort({&kernels, &in, cache, nullptr, near_w, &scratch, listed, nullptr}, parallel, nullptr);
    if (listed) {
        sorted = in;
        sorted.order = DrawOrder::as_given;
        list->order = scratch.data.data();
        return true;
    }
    point_at_copy(in, scratch, left_out, sorted);
    return true;
}

bool sort_nearest_first_leaving_out(const RasterKernels& kernels, const TriangleInput& in, const VertexClip& cache, double near_w,
                                    const ParallelFor& parallel, DrawOrderScratch& scratch, TriangleInput& sorted, RasterStats& skipped) {
    if (in.order == DrawOrder::as_given || in.triangle_count == 0) return false;
    check_draw_order(in);
    const std::size_t left_out = counting_sort({&kernels, &in, &cache, &cache, near_w, &scratch, false, nullptr}, parallel, &skipped);
    point_at_copy(in, scratch, left_out, sorted);
    return true;
}

bool sort_noting_cells(const RasterKernels& kernels, const TriangleInput& soup, double near_w, const ParallelFor& parallel,
                       DrawOrderScratch& scratch, const CellNoteSpec& spec, DrawList& list) {
    list = DrawList{};
    if (soup.order == DrawOrder::as_given || soup.triangle_count == 0) return false;
    check_draw_order(soup);
    counting_sort({&kernels, &soup, nullptr, nullptr, near_w, &scratch, true, &spec}, parallel, nullptr);
    list.notes = scratch.sorted_notes.data();
    return true;
}

}  // namespace homcull::detail
