// The conservativeness property: every "occluded" answer and every claimed sample is right at
// every sample centre, judged by an exact rational oracle (exact_oracle.hpp), on random and
// adversarial occluders: slivers, huge triangles across the near plane, vertices exactly on
// sample centres, w next to near_w, model coordinates up to 1e6 that the matrix brings back
// near the eye, extreme finite values. Every instruction set gives the scalar path's bits; the
// scalar path's claims and answers are checked against the oracle, at S = 1, 2 and 4, with and
// without per-sample depth, for rectangles, boxes and occludee triangles.
#include "exact_oracle.hpp"
#include "support.hpp"

#include "raster/rasterize.hpp"
#include "raster/triangle_setup.hpp"

#include <homcull/error.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <limits>
#include <random>
#include <string>

namespace homcull {
namespace {

// A model-to-clip matrix (column-major) mapping (x, y, z, 1) to clip (x, y, 0, z) after
// subtracting `origin`: positions are clip-space points plus the origin, rounded to float, and
// the exact geometry is what those floats and this matrix define. Orthographic: to clip
// (x, y, z, 1) after subtracting the origin (BufferConfig::orthographic).
std::array<float, 16> translated_projection(const float origin[3], bool orthographic = false) {
    if (orthographic) return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -origin[0], -origin[1], -origin[2], 1};
    return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, -origin[0], -origin[1], 0, -origin[2]};
}

struct Case {
    BufferConfig config;
    std::vector<float> positions;  // x, y, z per vertex (clip (x, y, ., w) = position - origin)
    float origin[3] = {0, 0, 0};
    std::uint32_t seed = 0;
    std::string kind;
    Backface backface = Backface::none;
    // With closed meshes among the triangles: the soup's shared edges (compute_shared_edges).
    std::vector<std::uint8_t> shared;
    std::vector<std::uint32_t> apexes;

    TriangleInput input() const {
        TriangleInput in;
        in.positions = positions.data();
        in.position_components = 3;
        in.position_stride = 12;
        in.vertex_count = positions.size() / 3;
        in.triangle_count = in.vertex_count / 3;
        in.model_to_clip = translated_projection(origin, config.orthographic);
        in.orthographic = config.orthographic;
        in.backface = backface;
        if (!shared.empty()) in.shared_edges = shared.data(), in.edge_apexes = apexes.data();
        return in;
    }
};

// Clip-space (x, y, w) points of the kinds that break rasterizers.
struct PointMaker {
    std::mt19937_64& rng;
    const BufferConfig& config;
    float uniform(float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); }
    // The NDC of a sample centre, times w: a vertex exactly on it (as far as float allows).
    void on_sample_centre(float w, float& x, float& y) {
        const int sw = config.width * config.samples, sh = config.height * config.samples;
        const int i = int(rng() % std::uint64_t(sw)), j = int(rng() % std::uint64_t(sh));
        x = float((2.0 * i + 1.0) / sw - 1.0) * w;
        y = float(1.0 - (2.0 * j + 1.0) / sh) * w;
    }
};

// The point a perspective case's clip (x, y, w) becomes in an orthographic one: the same spot
// on the screen (x/w, y/w; a vertex on a sample centre stays next to it) and clip z spreading w
// in [near_w, 20] over [-1, 1], so that what was behind the near plane stays there and the
// extremes stay extreme (up to 2^-10 of a w at 0). Some points then lie beyond twice the far
// distance, which an orthographic buffer drops.
void orthographic_point(float near_w, float& x, float& y, float& w) {
    const float safe_w = std::abs(w) < 0x1.0p-10f ? std::copysign(0x1.0p-10f, w) : w;
    x /= safe_w, y /= safe_w;
    w = -1.0f + (w - near_w) * (2.0f / 20.0f);
}

// A perspective case's clip (x, y, w) points, 3 floats each, as positions for
// translated_projection(origin 0, orthographic): unchanged, or through orthographic_point.
std::vector<float> positions_for(std::vector<float> xyw, bool orthographic, float near_w) {
    if (orthographic)
        for (std::size_t v = 0; v + 2 < xyw.size(); v += 3) orthographic_point(near_w, xyw[v], xyw[v + 1], xyw[v + 2]);
    return xyw;
}

Case make_case(std::uint32_t seed, bool orthographic = false) {
    std::mt19937_64 rng(seed);
    Case c;
    c.seed = seed;
    const int samples[3] = {1, 2, 4};
    c.config = test::buffer_config(5 + int(rng() % 36), 3 + int(rng() % 22), samples[rng() % 3], 0.05f + float(rng() % 100) * 0.01f,
                                   rng() % 2 == 0);
    const float case_near_w = c.config.near_w;  // the perspective case's, which the points are made for
    // A clip-space point (x, y, w) of the case, plus the origin, as a position.
    const auto push_vertex = [&](float x, float y, float w) {
        if (orthographic) orthographic_point(case_near_w, x, y, w);
        c.positions.insert(c.positions.end(), {x + c.origin[0], y + c.origin[1], w + c.origin[2]});
    };
    PointMaker make{rng, c.config};
    const float near_w = c.config.near_w;
    // The translation the matrix removes: none, or up to 1e6 (rounded to float as positions are).
    const int origin_kind = int(rng() % 3);
    if (origin_kind > 0) {
        const float scale = origin_kind == 1 ? 1e3f : 1e6f;
        for (float& o : c.origin) o = make.uniform(-scale, scale);
    }
    const int kinds = 7;
    const int triangles = 1 + int(rng() % 14);
    bool closed = false;
    for (int t = 0; t < triangles; ++t) {
        float x[3], y[3], w[3];
        const int kind = int(rng() % kinds);
        if (kind == 6) {  // a closed mesh (an octahedron), its equator on sample centres: silhouettes
            closed = true;
            const float w0 = make.uniform(near_w * 1.5f, 10.0f), r = make.uniform(0.05f, 0.9f) * w0, rz = make.uniform(0.0f, 1.0f) * w0;
            const float cx = make.uniform(-1.0f, 1.0f) * w0, cy = make.uniform(-1.0f, 1.0f) * w0;
            float v[6][3] = {{cx + r, cy, w0}, {cx - r, cy, w0}, {cx, cy + r, w0}, {cx, cy - r, w0}, {cx, cy, w0 + rz}, {cx, cy, w0 - rz}};
            for (int k = 0; k < 4; ++k)
                if (rng() % 2) make.on_sample_centre(v[k][2], v[k][0], v[k][1]);
            const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
            for (const auto& f : faces)
                for (int k : f) push_vertex(v[k][0], v[k][1], v[k][2]);
            continue;
        }
        const float cx = make.uniform(-1.3f, 1.3f), cy = make.uniform(-1.3f, 1.3f), r = make.uniform(0.01f, 1.5f);
        for (int k = 0; k < 3; ++k) {
            w[k] = make.uniform(near_w, 20.0f);
            const float angle = make.uniform(0.0f, 6.2831853f);
            x[k] = (cx + r * std::cos(angle)) * w[k];
            y[k] = (cy + r * std::sin(angle)) * w[k];
        }
        switch (kind) {
            case 0: break;  // plain
            case 1:         // a sliver: the third vertex on (almost) the line of the first two
                x[2] = x[0] + (x[1] - x[0]) * 0.5f + make.uniform(-1e-4f, 1e-4f) * w[2];
                y[2] = y[0] + (y[1] - y[0]) * 0.5f;
                w[2] = (w[0] + w[1]) * 0.5f;
                break;
            case 2:  // vertices on sample centres
                for (int k = 0; k < 3; ++k) make.on_sample_centre(w[k], x[k], y[k]);
                break;
            case 3:  // across the near plane, huge
                w[0] = make.uniform(-50.0f, near_w * 0.99f);
                x[0] = make.uniform(-1e4f, 1e4f);
                y[0] = make.uniform(-1e4f, 1e4f);
                break;
            case 4:  // w next to near_w
                for (int k = 0; k < 3; ++k) {
                    w[k] = std::nextafter(near_w, k == 0 ? 0.0f : HUGE_VALF);
                    make.on_sample_centre(w[k], x[k], y[k]);
                }
                break;
            case 5: {  // one vertex at an extreme finite value
                const float extremes[4] = {FLT_MAX, -FLT_MAX, 1e30f, 1e-30f};
                const float e = extremes[rng() % 4];
                const int which = int(rng() % 3);
                if (rng() % 2) w[which] = std::abs(e);
                else x[which] = e;
                break;
            }
        }
        for (int k = 0; k < 3; ++k) push_vertex(x[k], y[k], w[k]);
    }
    if (orthographic) {
        c.config.orthographic = true;
        c.config.near_w = 0.5f;  // what the buffer takes anyway: the oracle reads it from the config
    }
    if (closed) {
        const std::size_t count = c.positions.size() / 9;
        c.shared.resize(count);
        c.apexes.resize(3 * count);
        compute_shared_edges(c.positions.data(), 12, 3 * count, nullptr, count, c.shared.data(), c.apexes.data());
        const Backface modes[3] = {Backface::none, Backface::cw, Backface::ccw};
        c.backface = modes[rng() % 3];
    }
    c.kind = "seed " + std::to_string(seed) + (orthographic ? ", orthographic" : "") + (closed ? ", closed, backface " + std::to_string(int(c.backface)) : std::string()) + ", " +
             std::to_string(c.config.width) + "x" + std::to_string(c.config.height) + " S" +
             std::to_string(c.config.samples) + (c.config.sample_depth ? " sample depth" : "") + ", origin " +
             std::to_string(c.origin[0]);
    return c;
}

std::vector<ScreenRect> case_rects(std::uint32_t seed) {
    std::mt19937_64 rng(seed * 7919u + 1u);
    std::uniform_real_distribution<float> ndc(-1.1f, 1.0f), size(0.0f, 0.6f), w(0.05f, 25.0f);
    std::vector<ScreenRect> rects;
    for (int k = 0; k < 48; ++k) {
        const float x = ndc(rng), y = ndc(rng);
        rects.push_back({x, y, x + size(rng), y + size(rng), w(rng)});
    }
    return rects;
}

// Every case's claims and answers against the oracle, on every instruction set; the counts of
// claimed samples and occluded answers checked.
void check_cases_against_exact_arithmetic(bool orthographic, long& claims_checked, long& occluded_checked) {
    const std::vector<std::string> isas = available_isas();
    for (std::uint32_t seed = 1; seed <= 160; ++seed) {
        const Case c = make_case(seed, orthographic);
        const TriangleInput in = c.input();
        const test::ScopedIsa reference_isa("scalar");
        OcclusionBuffer reference(c.config);
        reference.render_frame(in);
        for (const std::string& isa : isas) {
            if (isa == "scalar") continue;
            const test::ScopedIsa selected(isa);
            OcclusionBuffer b(c.config);
            b.render_frame(in);
            ASSERT_TRUE(test::same_subtiles(reference, b)) << isa << ", " << c.kind;
        }
        const std::vector<test::ExactTriangle> occluders = test::exact_triangles(in);
        int first = -1;
        const long unbacked = test::unbacked_claims(reference, occluders, &first);
        ASSERT_EQ(unbacked, 0) << c.kind << ": first at sample " << first % reference.sample_width() << ", "
                               << first / reference.sample_width();
        std::vector<float> claims = test::claimed_inverse_w(reference);
        for (float d : claims) claims_checked += d > 0.0f;

        const int sw = reference.sample_width(), sh = reference.sample_height();
        // Rectangles.
        for (const ScreenRect& r : case_rects(seed)) {
            if (reference.test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min) != Visibility::occluded) continue;
            ++occluded_checked;
            ASSERT_TRUE(test::rect_truly_hidden(occluders, r, sw, sh, c.config.near_w))
                << c.kind << ": rect " << r.ndc_min_x << " " << r.ndc_min_y << " " << r.ndc_max_x << " " << r.ndc_max_y << " w " << r.w_min;
        }
        // Boxes in the model space of the occluders (the same matrix), and occludee triangles.
        std::mt19937_64 rng(seed * 31u + 7u);
        std::uniform_real_distribution<float> ndc(-1.2f, 1.2f), half(0.0f, 0.3f), w(0.05f, 25.0f), z(-1.3f, 3.2f);
        for (int k = 0; k < 16; ++k) {
            // Perspective: w from the eye, x and y scaled by it; orthographic: clip z itself.
            const float wc = orthographic ? z(rng) : w(rng), scale = orthographic ? 1.0f : wc;
            const float dw = half(rng), cx = ndc(rng) * scale, cy = ndc(rng) * scale, hx = half(rng) * scale, hy = half(rng) * scale;
            const float lo[3] = {cx - hx + c.origin[0], cy - hy + c.origin[1], wc + c.origin[2]};
            const float hi[3] = {cx + hx + c.origin[0], cy + hy + c.origin[1], wc + dw + c.origin[2]};
            if (reference.test_aabb(lo, hi, in.model_to_clip) != Visibility::occluded) continue;
            ++occluded_checked;
            // The box's faces as occludee triangles: hidden at every sample where they are seen.
            std::vector<float> box;
            const float corner[8][3] = {{lo[0], lo[1], lo[2]}, {hi[0], lo[1], lo[2]}, {lo[0], hi[1], lo[2]}, {hi[0], hi[1], lo[2]},
                                        {lo[0], lo[1], hi[2]}, {hi[0], lo[1], hi[2]}, {lo[0], hi[1], hi[2]}, {hi[0], hi[1], hi[2]}};
            const int faces[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 7, 5}, {4, 6, 7}, {0, 4, 5}, {0, 5, 1},
                                      {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
            for (const auto& f : faces)
                for (int v : f) box.insert(box.end(), corner[v], corner[v] + 3);
            TriangleInput box_in = in;
            box_in.shared_edges = nullptr, box_in.edge_apexes = nullptr;
            box_in.positions = box.data();
            box_in.vertex_count = 36;
            box_in.triangle_count = 12;
            ASSERT_TRUE(test::triangles_truly_hidden(occluders, test::exact_triangles(box_in), sw, sh, c.config.near_w))
                << c.kind << ": box " << k;
        }
        for (int k = 0; k < 16; ++k) {
            std::vector<float> tri;
            const float wc = orthographic ? z(rng) : w(rng), cx = ndc(rng), cy = ndc(rng), r = half(rng);
            for (int v = 0; v < 3; ++v) {
                // Perspective: x and y scaled by the vertex's w; orthographic: by nothing, z spread.
                const float wv = orthographic ? wc + 0.2f * half(rng) : wc * (1.0f + 0.2f * half(rng)), scale = orthographic ? 1.0f : wv;
                tri.insert(tri.end(), {(cx + r * float(v == 1)) * scale + c.origin[0], (cy + r * float(v == 2)) * scale + c.origin[1], wv + c.origin[2]});
            }
            TriangleInput occludee = in;
            occludee.shared_edges = nullptr, occludee.edge_apexes = nullptr;
            occludee.positions = tri.data();
            occludee.vertex_count = 3;
            occludee.triangle_count = 1;
            if (reference.test_triangles(occludee).visibility != Visibility::occluded) continue;
            ++occluded_checked;
            ASSERT_TRUE(test::triangles_truly_hidden(occluders, test::exact_triangles(occludee), sw, sh, c.config.near_w))
                << c.kind << ": occludee triangle " << k;
        }
    }
}

// The property over the cases in one projection, and that it is not vacuous: the cases claim
// samples and hide occludees.
void expect_cases_hold_against_exact_arithmetic(bool orthographic) {
    long claims_checked = 0, occluded_checked = 0;
    check_cases_against_exact_arithmetic(orthographic, claims_checked, occluded_checked);
    EXPECT_GT(claims_checked, 10000);
    EXPECT_GT(occluded_checked, 200);
    ::testing::Test::RecordProperty("claims_checked", std::to_string(claims_checked));
    ::testing::Test::RecordProperty("occluded_checked", std::to_string(occluded_checked));
}

TEST(Conservative, ClaimsAndAnswersHoldAtEverySampleCentreAgainstExactArithmetic) { expect_cases_hold_against_exact_arithmetic(false); }

// The same cases drawn with an orthographic projection (each clip point at the same spot on the
// screen, its depth from clip z): the same promises, against the same exact arithmetic on the
// orthographic representatives (exact_oracle.cpp), for rectangles, boxes and occludee triangles.
TEST(Conservative, OrthographicClaimsAndAnswersHoldAgainstExactArithmetic) { expect_cases_hold_against_exact_arithmetic(true); }

// Model coordinates near 2^k that the matrix brings back next to the eye: positions (h, a, b)
// with one large h, and x = (h + a) - h, y = (h + b) - h, w = 1 (column-major below).
std::array<float, 16> cancelling_matrix(float h) { return {1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -h, -h, 0, 1}; }

// The transform behind every claim must give a and b, not a and b rounded to h's spacing.
TEST(Conservative, TransformToClipIsAccurateWhereTheMatrixCancelsLargeCoordinates) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> small(-2.0f, 2.0f), mantissa(1.0f, 2.0f);
    for (int k = 20; k <= 100; k += 2) {
        for (int n = 0; n < 200; ++n) {
            const float h = std::ldexp(mantissa(rng), k), a = small(rng), b = small(rng);
            const glm::dvec4 c = detail::transform_to_clip(cancelling_matrix(h), h, a, b, 1.0);
            // Sum2's bound: 2^-53 of the result and (3 2^-53)^2 of the terms.
            ASSERT_LE(std::abs(c.x - double(a)), 0x1.0p-52 * std::abs(double(a)) + 0x1.0p-100 * double(h)) << "2^" << k << ", a = " << a;
            ASSERT_LE(std::abs(c.y - double(b)), 0x1.0p-52 * std::abs(double(b)) + 0x1.0p-100 * double(h)) << "2^" << k;
            ASSERT_EQ(c.w, 1.0);
        }
    }
}

// The same through the buffer: triangles of such vertices at 2^30 to 2^60, drawn on a 64 x 64
// buffer at w = 1, claim no sample that the exact geometry does not cover (the plain double sum
// claimed samples where no occluder is from 2^42 on). Orthographic too (w = 1 everywhere, z = 0).
TEST(Conservative, LargeCancellingCoordinatesClaimNoSampleOutsideTheOccluders) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> small(-1.2f, 1.2f), mantissa(1.0f, 2.0f);
    for (const bool orthographic : {false, true})
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            for (int k = 30; k <= 60; k += 2) {
                const float h = std::ldexp(mantissa(rng), k);
                BufferConfig config = test::buffer_config(64, 64, 1, 0.1f);
                config.orthographic = orthographic;
                OcclusionBuffer buffer(config);
                std::vector<float> positions;
                for (int v = 0; v < 3 * 12; ++v) positions.insert(positions.end(), {h, small(rng), small(rng)});
                TriangleInput in;
                in.positions = positions.data();
                in.vertex_count = positions.size() / 3;
                in.triangle_count = in.vertex_count / 3;
                in.model_to_clip = cancelling_matrix(h);
                in.backface = Backface::none;
                in.orthographic = orthographic;
                buffer.render_frame(in);
                EXPECT_GT(buffer.stats().rasterized, 0u);
                int first = -1;
                EXPECT_EQ(test::unbacked_claims(buffer, test::exact_triangles(in), &first), 0)
                    << (orthographic ? "orthographic, " : "") << isa << ", 2^" << k << ", sample " << first;
            }
        }
}

// A triangle whose w spans 10^33 down to behind the eye: the near-plane clip's interpolation
// parameter rounds to 1 and the clipped vertex lands at w = 0, not near_w, so the buffer claimed
// depths in front of the near plane (443 samples; found by fuzz_conservative). Such a triangle is
// too large to clip precisely, and is skipped.
TEST(Conservative, AWRangeTooLargeToClipClaimsNothing) {
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        // fuzz_conservative's case as it found it: clip = position - origin, origin (-0.0018, 1.7e-6, -6.7e16).
        const std::vector<float> positions = {-0.00182647293f, 1.6704563e-06f, 4.64922061e+33f, 29.6489086f, 3.56850887e-06f,
                                              -6.73231571e+16f, -3500.91016f, 1.6704563e-06f, -8.98869087e+20f};
        TriangleInput in;
        in.positions = positions.data();
        in.vertex_count = 3;
        in.triangle_count = 1;
        in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0.00182650844f, -1.6704563e-06f, 0, 6.73231571e+16f};
        in.backface = Backface::none;
        OcclusionBuffer buffer(test::buffer_config(17, 13, 4, 0.43f, true));
        buffer.render_frame(in);
        EXPECT_EQ(test::unbacked_claims(buffer, test::exact_triangles(in)), 0) << isa;
        EXPECT_EQ(buffer.stats().too_large, 1u) << isa;
    }
}

// A NaN bound (from extreme finite setup values) must bound nothing, never drop its bound: int(NaN)
// is undefined, and on x86 INT_MIN, which made the span or the row the whole range.
TEST(Conservative, NanBoundsGiveEmptySpansAndRows) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    int first = 0, last = 0;
    detail::sample_span(nan, 5.0, 64, first, last);
    EXPECT_GT(first, last);
    detail::sample_span(2.0, nan, 64, first, last);
    EXPECT_GT(first, last);
    detail::sample_span(2.0, 5.0, 64, first, last);  // and the finite case as before: centres 2.5 .. 4.5
    EXPECT_EQ(first, 2);
    EXPECT_EQ(last, 4);

    detail::TriangleEdges edges{};
    for (int k = 0; k < 3; ++k) {  // three edges keeping x > 0.5 (samples 1 and on)
        edges.ox[k] = 0.5, edges.oy[k] = 0.0, edges.sa[k] = 1.0, edges.sb[k] = 0.0, edges.inverse_sa[k] = 1.0;
        edges.threshold[k] = 0.0, edges.shared[k] = false;
    }
    std::int32_t row_first = 0, row_last = 0;
    detail::sample_row_interval(edges, 3, 0, 63, row_first, row_last);
    EXPECT_EQ(row_first, 1);
    EXPECT_EQ(row_last, 63);
    edges.ox[1] = nan;
    detail::sample_row_interval(edges, 3, 0, 63, row_first, row_last);
    EXPECT_GT(row_first, row_last);
}

// Depths below float's normal range (w beyond 2^126, 1/w subnormal): float roundings there err by
// up to 2^-150 however small the value, which the plane's relative error bound did not cover; a
// triangle at w = 3.4e38 claimed 76 samples nearer than it is (fuzz_conservative's find, kept
// as the seed subnormal_depth_plane). The plane now falls back to the smallest vertex depth.
TEST(Conservative, SubnormalDepthsClaimNoSampleNearerThanTheOccluder) {
    const std::vector<float> tri = {0x1.20fefep+7f, 0x1.400084p+68f, 0x1.fep+127f,  0x1.fefefep+127f, 0x1.fefefep+127f, 0x1.fefefep+127f,
                                    0x1.fefefep+127f, 0x1.fefefep-1f, 0x1.fefefep+127f};
    const float origin[3] = {0, 0, 0};
    TriangleInput in;
    in.positions = tri.data();
    in.vertex_count = 3;
    in.triangle_count = 1;
    in.model_to_clip = translated_projection(origin);
    in.backface = Backface::none;
    const std::vector<test::ExactTriangle> occluders = test::exact_triangles(in);
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        for (const int samples : {1, 4}) {
            OcclusionBuffer buffer(test::buffer_config(16, 16, samples, 1.99f));
            buffer.render_frame(in);
            EXPECT_EQ(buffer.stats().rasterized, 1u) << isa;
            std::vector<float> claims = test::claimed_inverse_w(buffer);
            EXPECT_GT(std::count_if(claims.begin(), claims.end(), [](float d) { return d > 0.0f; }), 10) << isa;
            EXPECT_EQ(test::unbacked_claims(buffer, occluders), 0) << isa << ", S = " << samples;
        }
    }
}

// Occludee triangles whose rounding hides part of them (fuzz_conservative's finds):
// - a sliver 3e-21 wide through sample centres, from model coordinates that the matrix cancels
//   (x = (h + a) - h): collinear in double, it was dropped as degenerate and the occludee answered
//   occluded in an empty buffer. It is now tested as its padded bounding box;
// - a triangle whose rounded x lies beyond w while its exact x does not (x = (2^51 + a) - 2^51
//   rounds to a multiple of 0.5, w = 0.78 exactly): it was passed over as beyond the side plane
//   and the occludee answered view_culled, though it covers the buffer's last column. The side
//   plane now takes the transform's rounding bound into account.
TEST(Conservative, OccludeeTrianglesHiddenByTheirRoundingAreTested) {
    const float h = 0x1.77777p+15f, t = 0x1.20202p-95f;
    TriangleInput sliver;
    const std::vector<float> sliver_positions = {0x1.9a9a9ap+27f, 0x1.20209ap-95f, t, t, t, t, t, t, 0x1.f6202p-69f};
    sliver.positions = sliver_positions.data();
    sliver.vertex_count = 3;
    sliver.triangle_count = 1;
    sliver.model_to_clip = cancelling_matrix(h);
    const float big = 0x1.0p51f;
    TriangleInput beside;
    const std::vector<float> beside_positions = {big, 0.77f, -0.5f, big, 0.76f, 0.5f, big, 0.77f, 0.5f};
    beside.positions = beside_positions.data();
    beside.vertex_count = 3;
    beside.triangle_count = 1;
    beside.model_to_clip = {1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -big, 0, 0, 0.78f};
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        const OcclusionBuffer empty(test::buffer_config(1, 5, 4, 0.72f, true));
        ASSERT_FALSE(test::triangles_truly_hidden({}, test::exact_triangles(sliver), empty.sample_width(), empty.sample_height(), 0.72f));
        EXPECT_EQ(empty.test_triangles(sliver).visibility, Visibility::visible) << isa;
        const OcclusionBuffer wide(test::buffer_config(16, 8, 4, 0.1f));
        ASSERT_FALSE(test::triangles_truly_hidden({}, test::exact_triangles(beside), wide.sample_width(), wide.sample_height(), 0.1f));
        EXPECT_EQ(wide.test_triangles(beside).visibility, Visibility::visible) << isa;
    }
}

// Shared edges decided per view (neighbour_across_edge). A triangle T = (a, b, c) whose edge a -> b
// runs at NDC y = 2^-100, just above the sample row at y = 0 (an odd sample height puts a row
// there): (1 - y) * 0.5 * height rounds the row onto the edge, so without its margin the edge
// claims the whole row, which T does not cover. That is right only when the neighbour across the
// edge covers the row: one below it (a closed mesh's far side, facing as T does) keeps the flag;
// one folded back above it (the view silhouette of a closed mesh: it faces away), a degenerate
// one (its apex on the edge's line) or a missing apex drops it. Drawn as a soup, indexed (with a
// vertex cache), as clusters, with back faces drawn or culled, on every instruction set, with
// perspective and orthographic projections (the same spots on the screen).
TEST(Conservative, SharedEdgesAtViewSilhouettesKeepTheirMargin) {
    const float e = 0x1.0p-100f;
    struct Neighbour {
        const char* name;
        float apex[3];  // clip (x, y, w)
        bool covers_row;
    };
    const Neighbour neighbours[] = {{"below (across the edge)", {0.0f, -0.5f, 1.0f}, true},
                                    {"folded above (a view silhouette)", {0.1f, 0.5f, 2.0f}, false},
                                    {"degenerate (apex on the edge's line)", {0.3f, e, 1.0f}, false}};
    long row_claims_kept[2] = {0, 0};
    for (const bool orthographic : {false, true})
        for (const Neighbour& n : neighbours)
            for (const Backface backface : {Backface::none, Backface::cw})
                for (const std::string& isa : available_isas()) {
                    const test::ScopedIsa selected(isa);
                    const std::string where = std::string(orthographic ? "orthographic, " : "") + n.name + ", backface " +
                                              std::to_string(int(backface)) + ", " + isa;
                    BufferConfig config = test::buffer_config(16, 15, 1, 0.1f);
                    config.orthographic = orthographic;
                    const std::array<float, 16> matrix = translated_projection(std::array<float, 3>{0, 0, 0}.data(), orthographic);
                    // T = (a, b, c), N = (b, a, apex); as a soup of 6 vertices and as 4 indexed ones.
                    const std::vector<float> soup = positions_for(
                        {-0.8f, e, 1, 0.8f, e, 1, 0, 0.8f, 1, 0.8f, e, 1, -0.8f, e, 1, n.apex[0], n.apex[1], n.apex[2]}, orthographic, 0.1f);
                    const std::vector<float> vertices =
                        positions_for({-0.8f, e, 1, 0.8f, e, 1, 0, 0.8f, 1, n.apex[0], n.apex[1], n.apex[2]}, orthographic, 0.1f);
                    const std::vector<std::uint32_t> indices = {0, 1, 2, 1, 0, 3};
                    std::uint8_t soup_flags[2], flags[2];
                    std::uint32_t soup_apexes[6], apexes[6];
                    compute_shared_edges(soup.data(), 12, 6, nullptr, 2, soup_flags, soup_apexes);
                    compute_shared_edges(vertices.data(), 12, 4, indices.data(), 2, flags, apexes);
                    ASSERT_EQ(soup_flags[0], 1u) << where;  // the flag is the mesh's: only the view can drop it
                    TriangleInput as_soup;
                    as_soup.positions = soup.data();
                    as_soup.vertex_count = 6;
                    as_soup.triangle_count = 2;
                    as_soup.model_to_clip = matrix;
                    as_soup.backface = backface;
                    as_soup.shared_edges = soup_flags;
                    as_soup.edge_apexes = soup_apexes;
                    as_soup.orthographic = orthographic;
                    TriangleInput indexed = as_soup;
                    indexed.positions = vertices.data();
                    indexed.vertex_count = 4;
                    indexed.indices = indices.data();
                    indexed.shared_edges = flags;
                    indexed.edge_apexes = apexes;
                    const OccluderClusters clusters = build_occluder_clusters(vertices.data(), 12, 4, indices.data(), 2, flags, apexes);
                    const std::vector<test::ExactTriangle> occluders = test::exact_triangles(as_soup);
                    OcclusionBuffer from_soup(config), from_indices(config), from_clusters(config);
                    from_soup.render_frame(as_soup);
                    from_indices.render_frame(indexed);
                    ClusteredInput clustered{&clusters, matrix, backface};
                    clustered.orthographic = orthographic;
                    from_clusters.render_frame(clustered);
                    ASSERT_TRUE(test::same_subtiles(from_soup, from_indices)) << where;
                    ASSERT_TRUE(test::same_subtiles(from_soup, from_clusters)) << where;
                    EXPECT_EQ(test::unbacked_claims(from_soup, occluders), 0) << where;
                    // The row at y = 0 (sample row 7) is claimed exactly when the neighbour covers it.
                    const std::vector<float> claims = test::claimed_inverse_w(from_soup);
                    int row_claims = 0;
                    for (int i = 0; i < from_soup.sample_width(); ++i) row_claims += claims[std::size_t(7 * from_soup.sample_width() + i)] > 0.0f;
                    if (n.covers_row) EXPECT_GT(row_claims, 10) << where;
                    else EXPECT_EQ(row_claims, 0) << where;
                    row_claims_kept[orthographic] += row_claims;
                    // Without its apex, the flag is dropped.
                    std::uint32_t no_apexes[6] = {kNoApex, kNoApex, kNoApex, kNoApex, kNoApex, kNoApex};
                    TriangleInput without = as_soup;
                    without.edge_apexes = no_apexes;
                    OcclusionBuffer margin(config);
                    margin.render_frame(without);
                    const std::vector<float> margin_claims = test::claimed_inverse_w(margin);
                    for (int i = 0; i < margin.sample_width(); ++i) EXPECT_EQ(margin_claims[std::size_t(7 * margin.sample_width() + i)], 0.0f) << where;
                }
    EXPECT_GT(row_claims_kept[0], 0);
    EXPECT_GT(row_claims_kept[1], 0);
}

// The ends of margin-free edges (margin_free_edges). Both cases put the sample centre at NDC (0, 0)
// (odd sample counts) a hair outside a triangle T whose margin-free edge the projection rounds
// onto it, with the neighbour across that edge facing as T does, so that the per-edge rule alone
// keeps the flag:
// - a neighbour too thin to cover the sample: N's apex 2^-102 below the edge at y = 2^-100;
// - a corner on the outline: T's vertex at (1e-30, 1e-30), both of its edges there shared with
//   neighbours across them, the sample in the vertical angle of T's corner, which no triangle
//   covers.
// Each must claim no sample the exact geometry leaves open, on every instruction set, with
// perspective and orthographic projections.
TEST(Conservative, MarginFreeEdgesClaimNothingPastThinNeighboursOrOutlineCorners) {
    const float e = 0x1.0p-100f, tiny = 1e-30f;
    struct Mesh {
        const char* name;
        std::vector<float> soup;  // clip (x, y, w), 3 vertices a triangle
    };
    const Mesh meshes[] = {
        {"thin neighbour", {-0.5f, e, 1, 0.5f, e, 1, 0, 0.5f, 1, 0.5f, e, 1, -0.5f, e, 1, 0.4f, e - 0x1.0p-102f, 1}},
        {"corner on the outline",
         {tiny, tiny, 1, 0.5f, 0.15f, 1, 0.15f, 0.5f, 1, 0.5f, 0.15f, 1, tiny, tiny, 1, 0.5f, -0.4f, 1, tiny, tiny, 1, 0.15f, 0.5f, 1, -0.4f, 0.5f, 1}},
    };
    for (const bool orthographic : {false, true})
        for (const Mesh& m : meshes) {
            const std::string what = std::string(orthographic ? "orthographic, " : "") + m.name;
            const std::array<float, 16> matrix = translated_projection(std::array<float, 3>{0, 0, 0}.data(), orthographic);
            const std::vector<float> soup = positions_for(m.soup, orthographic, 0.1f);
            const std::size_t triangles = soup.size() / 9;
            std::vector<std::uint8_t> flags(triangles);
            std::vector<std::uint32_t> apexes(3 * triangles);
            compute_shared_edges(soup.data(), 12, 3 * triangles, nullptr, triangles, flags.data(), apexes.data());
            ASSERT_NE(flags[0], 0u) << what;
            TriangleInput in;
            in.positions = soup.data();
            in.vertex_count = 3 * triangles;
            in.triangle_count = triangles;
            in.model_to_clip = matrix;
            in.backface = Backface::none;
            in.shared_edges = flags.data();
            in.edge_apexes = apexes.data();
            in.orthographic = orthographic;
            const std::vector<test::ExactTriangle> occluders = test::exact_triangles(in);
            for (const std::string& isa : available_isas()) {
                const test::ScopedIsa selected(isa);
                BufferConfig config = test::buffer_config(15, 15, 1, 0.1f);
                config.orthographic = orthographic;
                OcclusionBuffer buffer(config);
                buffer.render_frame(in);
                std::vector<float> claims = test::claimed_inverse_w(buffer);
                EXPECT_GT(std::count_if(claims.begin(), claims.end(), [](float d) { return d > 0.0f; }), 5) << what << ", " << isa;
                EXPECT_EQ(test::unbacked_claims(buffer, occluders), 0) << what << ", " << isa;
            }
        }
}

// A clipped sliver (fuzz_conservative's find): a triangle from w = 2.2e8 back past the near plane,
// about 1e-8 NDC wide, along the diagonal of sample centres. Its clipped polygon is drawn as a fan
// whose diagonals went without margin, though the fan triangle across them was far thinner than
// their rounding: 29 samples claimed on the diagonal, outside the exact sliver. Fan diagonals now
// pass margin_free_edges like shared edges.
TEST(Conservative, ClippedSliversClaimNoSampleAlongTheirFanDiagonals) {
    const std::vector<float> sliver = {-0x1.d70a3p-4f, -0x1.d70a38p-4f, 0x1.9a9a9ap+27f, 0x1.9a9a9ap+27f, 0x1.9a9a9ap+27f, 0x1.de267p-92f,
                                       -0x1p-67f, -0x1.d86948p-26f, -0x1.758b0ap-19f};
    TriangleInput in;
    in.positions = sliver.data();
    in.vertex_count = 3;
    in.triangle_count = 1;
    in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, -0x1.e9a31cp-112f, 0x1.da3008p-26f, 0, -0x1.84637ap-119f};
    in.backface = Backface::none;
    const std::vector<test::ExactTriangle> occluders = test::exact_triangles(in);
    for (const std::string& isa : available_isas()) {
        const test::ScopedIsa selected(isa);
        OcclusionBuffer buffer(test::buffer_config(16, 16, 4, 1.99f));
        buffer.render_frame(in);
        EXPECT_EQ(buffer.stats().near_clipped, 1u) << isa;
        EXPECT_EQ(test::unbacked_claims(buffer, occluders), 0) << isa;
    }
}

// Orthographic extremes, clip (x, y, z) with w = 1: a sliver one float step (6e-8) wide along the
// diagonal of sample centres crossing the near plane (z = -1), drawn as a clipped fan; a
// triangle reaching 10^33 behind the near plane; one reaching past twice the far distance
// (z > 1 - 2^-7, which an orthographic buffer drops). None claims a sample its exact geometry
// leaves open, on every instruction set and sample count.
TEST(Conservative, OrthographicExtremesClaimNoSampleOutsideTheOccluders) {
    struct Triangle {
        const char* name;
        std::vector<float> xyz;
    };
    const Triangle triangles[] = {
        {"sliver across the near plane", {-0.9f, 0.9f, -3.0f, 0.9f, -0.9f, 0.5f, std::nextafter(0.9f, 1.0f), -0.9f, 0.5f}},
        {"10^33 behind the near plane", {-0.5f, -0.5f, -1e33f, 0.5f, -0.5f, 0.0f, 0.0f, 0.5f, 0.0f}},
        {"past twice the far distance", {-0.7f, -0.6f, 0.99f, 0.6f, -0.5f, 1.5f, 0.0f, 0.7f, 0.98f}},
    };
    for (const Triangle& t : triangles) {
        TriangleInput in;
        in.positions = t.xyz.data();
        in.vertex_count = 3;
        in.triangle_count = 1;
        in.model_to_clip = translated_projection(std::array<float, 3>{0, 0, 0}.data(), true);
        in.backface = Backface::none;
        in.orthographic = true;
        const std::vector<test::ExactTriangle> occluders = test::exact_triangles(in);
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            for (const int samples : {1, 4}) {
                BufferConfig config = test::buffer_config(16, 16, samples, 0.5f);
                config.orthographic = true;
                OcclusionBuffer buffer(config);
                buffer.render_frame(in);
                EXPECT_EQ(test::unbacked_claims(buffer, occluders), 0) << t.name << ", " << isa << ", S = " << samples;
                if (t.name == triangles[0].name) {
                    EXPECT_EQ(buffer.stats().near_clipped, 1u) << isa;
                    EXPECT_EQ(buffer.stats().rasterized, 1u) << isa;
                }
            }
        }
    }
}

// Flags without apexes cannot be decided per view: render refuses them.
TEST(Conservative, SharedEdgesWithoutApexesAreRefused) {
    const std::vector<float> soup = {-0.8f, 0, 1, 0.8f, 0, 1, 0, 0.8f, 1};
    const std::uint8_t flags[1] = {1};
    TriangleInput in;
    in.positions = soup.data();
    in.vertex_count = 3;
    in.triangle_count = 1;
    in.model_to_clip = translated_projection(std::array<float, 3>{0, 0, 0}.data());
    in.shared_edges = flags;
    OcclusionBuffer buffer(test::buffer_config(8, 8, 1, 0.1f));
    EXPECT_THROW(buffer.render(in), Error);
}

}  // namespace
}  // namespace homcull
