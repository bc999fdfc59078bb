// libFuzzer target: the conservativeness property against the exact oracle (exact_oracle.hpp).
// The bytes give a small buffer and a few occluder triangles (float positions, any finite value,
// under a matrix that may translate large model coordinates back near the eye, perspective or
// orthographic), sometimes a closed mesh with its shared-edge flags and a backface rule, queries,
// and the instruction set. Every claimed sample must be backed by an occluder at or nearer than the claim,
// and every rectangle and occludee triangle answered occluded must be hidden at every sample
// centre, and one answered view_culled seen at none, exactly; any violation traps.
#include "../exact_oracle.hpp"
#include "fuzz_input.hpp"

#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <vector>

namespace {

using homcull::fuzz::Bytes;

// A finite float from the bytes: as it comes when finite, else a small value made from it.
float finite(Bytes& in) {
    const float f = in.take<float>();
    return std::isfinite(f) ? f : float(in.below(2001)) * 0.001f - 1.0f;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace homcull;
    static const std::vector<std::string> isas = available_isas();
    Bytes in(data, size);
    select_isa(isas[in.below(std::uint32_t(isas.size()))]);
    const int samples[3] = {1, 2, 4};
    BufferConfig config;
    config.width = 1 + int(in.below(24));
    config.height = 1 + int(in.below(16));
    config.samples = samples[in.below(3)];
    config.near_w = 0.01f + float(in.below(200)) * 0.01f;
    config.sample_depth = in.flag();

    // The matrix: clip (x, y, ., w) = (position - origin) for positions (x, y, w), or the cancelling
    // form x = (h + a) - h, y = (h + b) - h, w = 1 with one large h for positions (h, a, b).
    TriangleInput tri;
    std::vector<float> positions;
    const int triangles = 1 + int(in.below(8));
    if (in.flag()) {
        // h within the transform's guaranteed range (docs/occlusion-buffer.md): 2h <= 2^60 near_w.
        const float h = std::ldexp(1.0f + float(in.below(1u << 20)) * 0x1.0p-20f, int(in.below(52)));
        tri.model_to_clip = {1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -h, -h, 0, 1};
        for (int v = 0; v < 3 * triangles; ++v) positions.insert(positions.end(), {h, finite(in), finite(in)});
    } else {
        const float origin[3] = {finite(in), finite(in), finite(in)};
        tri.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, -origin[0], -origin[1], 0, -origin[2]};
        for (int v = 0; v < 3 * triangles; ++v) {
            const float x = finite(in), y = finite(in), w = finite(in);
            positions.insert(positions.end(), {x + origin[0], y + origin[1], w + origin[2]});
        }
    }
    // Sometimes a closed mesh as well: an octahedron of 6 vertices from the bytes, its 8 faces
    // consistently wound, its shared edges flagged (compute_shared_edges) and drawn with any
    // backface rule, so that silhouettes, folds and degenerate neighbours meet the flags.
    std::vector<std::uint8_t> shared;
    std::vector<std::uint32_t> apexes;
    const Backface backfaces[3] = {Backface::none, Backface::cw, Backface::ccw};
    tri.backface = Backface::none;
    const bool closed = in.flag();
    if (closed) {
        float v[6][3];
        for (auto& p : v) {
            const bool on_vertex = in.flag();  // a repeated vertex: degenerate faces and neighbours
            for (int k = 0; k < 3; ++k) p[k] = finite(in);
            if (on_vertex) std::copy(std::begin(v[0]), std::end(v[0]), p);
        }
        const float* origin = &tri.model_to_clip[12];
        const bool cancelling = tri.model_to_clip[4] == 1.0f;  // the (h, a, b) form: x = a, y = b, w = 1
        const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
        for (const auto& f : faces)
            for (int k : f) {
                if (cancelling) positions.insert(positions.end(), {-origin[0], v[k][0], v[k][1]});
                else positions.insert(positions.end(), {v[k][0] - origin[0], v[k][1] - origin[1], v[k][2] - origin[3]});
            }
        tri.backface = backfaces[in.below(3)];
    }
    // Sometimes orthographic (BufferConfig::orthographic): the same positions to clip (x, y, z, 1),
    // z = the position's third coordinate less the origin's (the cancelling form: w = 1, z = 0).
    if (in.flag()) {
        config.orthographic = tri.orthographic = true;
        if (tri.model_to_clip[4] != 1.0f) {
            const float o[3] = {-tri.model_to_clip[12], -tri.model_to_clip[13], -tri.model_to_clip[15]};
            tri.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -o[0], -o[1], -o[2], 1};
        }
    }
    tri.positions = positions.data();
    tri.vertex_count = positions.size() / 3;
    tri.triangle_count = positions.size() / 9;
    if (closed) {
        shared.resize(tri.triangle_count);
        apexes.resize(3 * tri.triangle_count);
        compute_shared_edges(positions.data(), 12, tri.vertex_count, nullptr, tri.triangle_count, shared.data(), apexes.data());
        tri.shared_edges = shared.data();
        tri.edge_apexes = apexes.data();
    }

    OcclusionBuffer buffer(config);
    buffer.render_frame(tri);
    const std::vector<test::ExactTriangle> occluders = test::exact_triangles(tri);
    if (test::unbacked_claims(buffer, occluders) != 0) __builtin_trap();
    const int sw = buffer.sample_width(), sh = buffer.sample_height();
    const float near_w = buffer.config().near_w;  // an orthographic buffer's is its near plane's
    for (int q = 0; q < 4 && in.left() >= 20; ++q) {
        const ScreenRect r{finite(in), finite(in), finite(in), finite(in), finite(in)};
        const Visibility v = buffer.test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min);
        // occluded: hidden at every sample centre; view_culled: no sample centre at all
        if (v == Visibility::occluded && !test::rect_truly_hidden(occluders, r, sw, sh, near_w)) __builtin_trap();
        if (v == Visibility::view_culled && !test::rect_truly_hidden({}, r, sw, sh, near_w)) __builtin_trap();
    }
    if (in.left() >= 36) {
        TriangleInput occludee = tri;
        occludee.shared_edges = nullptr, occludee.edge_apexes = nullptr;
        std::vector<float> p;
        for (int k = 0; k < 9; ++k) p.push_back(finite(in));
        occludee.positions = p.data();
        occludee.vertex_count = 3;
        occludee.triangle_count = 1;
        const Visibility v = buffer.test_triangles(occludee).visibility;
        const std::vector<test::ExactTriangle> exact = test::exact_triangles(occludee);
        if (v == Visibility::occluded && !test::triangles_truly_hidden(occluders, exact, sw, sh, near_w)) __builtin_trap();
        if (v == Visibility::view_culled && !test::triangles_truly_hidden({}, exact, sw, sh, near_w)) __builtin_trap();
    }
    return 0;
}
