// libFuzzer target: the occlusion buffer's whole input surface. The bytes choose a configuration
// (any size, samples, near plane, margin), a TriangleInput (3 or 4 components, any stride, 16- or
// 32-bit indices in or out of range, any matrix, backface rule, draw order, shared-edge flags) whose
// positions are the raw bytes (NaN, infinities, huge and denormal values included), a render with
// or without a job system, and queries. Invalid configurations and inputs must be refused with
// homcull::Error; everything else must run without a crash, a sanitizer report or another exception,
// and the job system's render must give the serial render's bits.
#include "fuzz_input.hpp"

#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <algorithm>
#include <random>
#include <vector>

namespace {

using homcull::fuzz::Bytes;

void run_reversed(void*, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    for (std::size_t i = count; i-- > 0;) task(data, i);
}

bool same(const homcull::OcclusionBuffer& a, const homcull::OcclusionBuffer& b) {
    const auto x = a.subtiles(), y = b.subtiles();
    for (std::size_t i = 0; i < x.size(); ++i)
        if (x[i].d0 != y[i].d0 || x[i].d1 != y[i].d1 || x[i].mask != y[i].mask || x[i].covered != y[i].covered) return false;
    return a.stats() == b.stats();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace homcull;
    Bytes in(data, size);
    BufferConfig config;
    config.width = 1 + int(in.below(200));
    config.height = 1 + int(in.below(120));
    const int samples[4] = {1, 2, 4, 3};  // 3 must be refused
    config.samples = samples[in.below(4)];
    config.near_w = in.take<float>();
    if (in.flag()) config.near_w = 0.05f + float(in.below(1000)) * 0.01f;
    config.edge_margin = in.flag() ? in.take<double>() : 1.0 / 1024.0;
    config.sample_depth = in.flag();

    TriangleInput tri;
    tri.position_components = in.flag() ? 4 : 3;
    const std::size_t min_stride = std::size_t(tri.position_components) * 4;
    tri.position_stride = in.flag() ? min_stride : 4 * in.below(12);  // sometimes too small
    tri.backface = Backface(in.below(3));
    tri.order = in.flag() ? DrawOrder::nearest_first : DrawOrder::as_given;
    for (float& m : tri.model_to_clip) m = in.take<float>();
    if (in.flag()) tri.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const bool indexed = in.flag(), sixteen = in.flag(), flags = in.flag();
    const std::size_t triangles = in.below(64);
    std::vector<std::uint32_t> indices32;
    std::vector<std::uint16_t> indices16;
    std::vector<std::uint8_t> shared;
    const std::size_t vertex_count = indexed ? in.below(48) : 3 * triangles;
    for (std::size_t i = 0; indexed && i < 3 * triangles; ++i) {
        const std::uint32_t v = in.below(std::uint32_t(vertex_count) + 2);  // sometimes out of range
        indices32.push_back(v);
        indices16.push_back(std::uint16_t(v));
    }
    for (std::size_t t = 0; flags && t < triangles; ++t) shared.push_back(in.take<std::uint8_t>());
    std::vector<std::uint32_t> apexes;  // any vertex, sometimes none
    for (std::size_t i = 0; flags && i < 3 * triangles; ++i) apexes.push_back(in.below(std::uint32_t(vertex_count) + 2));
    // Positions: the rest of the bytes, repeated to fill what the input needs.
    const std::size_t stride = std::max<std::size_t>(tri.position_stride, 4);
    std::vector<unsigned char> positions(std::max<std::size_t>(1, vertex_count) * stride + 16, 0);
    for (std::size_t i = 0; i < positions.size() && in.left() > 0; ++i) positions[i] = in.rest()[i % in.left()];
    tri.positions = positions.data();
    tri.vertex_count = vertex_count;
    tri.triangle_count = triangles;
    tri.indices = !indexed ? nullptr : sixteen ? static_cast<const void*>(indices16.data()) : static_cast<const void*>(indices32.data());
    tri.indices_16bit = sixteen;
    tri.shared_edges = flags ? shared.data() : nullptr;
    tri.edge_apexes = flags ? apexes.data() : nullptr;

    try {
        OcclusionBuffer serial(config), threaded(config);
        serial.render_frame(tri);
        threaded.render_frame(tri, ParallelFor{run_reversed, nullptr, 3});
        if (!same(serial, threaded)) __builtin_trap();
        // Queries: rectangles and boxes from the same bytes, occludee triangles the input itself.
        const float* f = reinterpret_cast<const float*>(positions.data());
        (void)serial.test_rect(f[0], f[1], f[2], f[3], f[4 % (positions.size() / 4)]);
        const float lo[3] = {f[0], f[1], f[2]}, hi[3] = {f[3 % (positions.size() / 4)], f[1], f[0]};
        (void)serial.test_aabb(lo, hi, tri.model_to_clip);
        (void)serial.test_triangles(tri, in.below(4), in.below(8));
        std::vector<float> depth;
        serial.read_depth(depth);
    } catch (const Error&) {
        // a configuration or an input the buffer refuses, with its reason
    }
    return 0;
}
