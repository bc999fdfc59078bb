#include "exact_oracle.hpp"

#include <cmath>
#include <cstring>

namespace homcull::test {
namespace {

mpq_class exact(double v) { return mpq_class(v); }  // exact: every finite double is a rational

std::array<mpq_class, 3> cross(const std::array<mpq_class, 3>& a, const std::array<mpq_class, 3>& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

}  // namespace

namespace {
// Some occluder at the sample at w >= near_w with exact 1/w >= target: first through the double
// filter with the float just below the target (a hit there is not yet enough), then exactly.
bool hidden_at(const std::vector<ExactTriangle>& occluders, const ExactSample& s, const mpq_class& inverse_near, const mpq_class& target) {
    const double inverse_near_d = inverse_near.get_d();
    const float rounded = float(target.get_d());
    const float above = std::nextafter(std::nextafter(rounded, HUGE_VALF), HUGE_VALF), below = std::nextafter(rounded, 0.0f);
    for (const ExactTriangle& t : occluders)  // clearly nearer than the target: no rationals needed
        if (hit_at_or_nearer(t, s, inverse_near, inverse_near_d, above)) return true;
    mpq_class hit;
    for (const ExactTriangle& t : occluders)
        if (hit_at_or_nearer(t, s, inverse_near, inverse_near_d, below) && exact_hit(t, s, inverse_near, hit) && hit >= target) return true;
    return false;
}
}  // namespace

bool exact_clip_triangle(const TriangleInput& in, std::size_t t, std::array<std::array<mpq_class, 3>, 3>& clip) {
    const auto* bytes = static_cast<const unsigned char*>(in.positions);
    for (int k = 0; k < 3; ++k) {
        std::size_t v = 3 * t + std::size_t(k);
        if (in.indices) {
            v = in.indices_16bit ? static_cast<const std::uint16_t*>(in.indices)[3 * t + std::size_t(k)]
                                 : static_cast<const std::uint32_t*>(in.indices)[3 * t + std::size_t(k)];
        }
        if (v >= in.vertex_count) return false;
        float p[4] = {0.0f, 0.0f, 0.0f, 1.0f};
        std::memcpy(p, bytes + v * in.position_stride, std::size_t(in.position_components) * sizeof(float));
        for (float c : p)
            if (!std::isfinite(c)) return false;
        mpq_class row[4];  // x, y, z, w
        for (int r = 0; r < 4; ++r) {
            row[r] = 0;
            for (int c = 0; c < 4; ++c) {
                const float m = in.model_to_clip[std::size_t(4 * c + r)];
                if (!std::isfinite(m)) return false;
                row[r] += exact(m) * exact(p[c]);
            }
        }
        if (in.orthographic) {
            // The orthographic representative (x, y, w) / h, h = (3w - z) / 2, exactly: the same
            // point with 1/w' the depth (3 - z/w) / 2. The buffer drops points with w <= 0 or
            // h < 2^-8 w; so does the oracle (a dropped occluder backs no claim, and a dropped
            // occludee makes the buffer answer visible).
            const mpq_class h = (3 * row[3] - row[2]) / 2;
            if (!(row[3] > 0) || h < row[3] / 256) return false;
            for (int r : {0, 1, 3}) row[r] /= h;
        }
        clip[std::size_t(k)] = {row[0], row[1], row[3]};
    }
    return true;
}

ExactTriangle exact_triangle(const std::array<std::array<mpq_class, 3>, 3>& c) {
    // M's columns are the vertices; the rows of M^-1 are (c1 x c2, c2 x c0, c0 x c1) / det.
    ExactTriangle tri;
    for (int k = 0; k < 3; ++k) {
        const std::array<mpq_class, 3> row = cross(c[std::size_t((k + 1) % 3)], c[std::size_t((k + 2) % 3)]);
        for (int i = 0; i < 3; ++i) tri.adjugate[k][i] = row[std::size_t(i)];
    }
    tri.det = c[0][0] * tri.adjugate[0][0] + c[0][1] * tri.adjugate[0][1] + c[0][2] * tri.adjugate[0][2];
    tri.flat = sgn(tri.det) == 0;
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) tri.adjugate_d[k][i] = tri.adjugate[k][i].get_d();
    tri.det_d = tri.det.get_d();
    return tri;
}

ExactSample exact_sample(int i, int j, int sample_width, int sample_height) {
    ExactSample s;
    s.x = mpq_class(2 * i + 1, sample_width) - 1;
    s.y = 1 - mpq_class(2 * j + 1, sample_height);
    s.x.canonicalize();
    s.y.canonicalize();
    s.x_d = s.x.get_d();
    s.y_d = s.y.get_d();
    return s;
}

bool exact_hit(const ExactTriangle& tri, const ExactSample& s, const mpq_class& inverse_near_w, mpq_class& inverse_w) {
    if (tri.flat) return false;
    const int sign = sgn(tri.det);
    mpq_class sum = 0;
    for (int k = 0; k < 3; ++k) {
        const mpq_class a = tri.adjugate[k][0] * s.x + tri.adjugate[k][1] * s.y + tri.adjugate[k][2];
        if (sgn(a) * sign < 0) return false;
        sum += a;
    }
    if (sgn(sum) * sign <= 0) return false;  // the plane is met behind the eye, or not at all
    inverse_w = sum / tri.det;
    return inverse_w <= inverse_near_w;
}

bool hit_at_or_nearer(const ExactTriangle& tri, const ExactSample& s, const mpq_class& inverse_near_w, double inverse_near_d, float d) {
    if (tri.flat) return false;
    // The filter: every rounded input (adjugate entries, sample coordinates, det) is within 2^-53
    // of itself; a_k's three products and two sums add a few more such errors. 2^-48 of the terms'
    // magnitudes bounds them all; any answer within the bound goes to the rationals.
    const double sign = tri.det_d > 0.0 ? 1.0 : -1.0;
    double sum = 0.0, sum_error = 0.0;
    bool certain = std::isfinite(tri.det_d) && tri.det_d != 0.0;
    for (int k = 0; k < 3 && certain; ++k) {
        const double* row = tri.adjugate_d[k];
        const double a = row[0] * s.x_d + row[1] * s.y_d + row[2];
        const double error = 0x1.0p-48 * (std::abs(row[0] * s.x_d) + std::abs(row[1] * s.y_d) + std::abs(row[2]));
        if (!std::isfinite(a) || !std::isfinite(error)) certain = false;
        else if (a * sign < -error) return false;  // certainly outside edge k
        else if (a * sign <= error) certain = false;
        sum += a;
        sum_error += error;
    }
    if (certain) {
        // Inside every edge for sure; 1/w = sum / det, with the relative error below.
        const double inverse_w = sum / tri.det_d;
        const double relative = (sum_error + 0x1.0p-50 * std::abs(sum)) / std::abs(sum) + 0x1.0p-50;
        const double lo = inverse_w * (1.0 - 2.0 * relative), hi = inverse_w * (1.0 + 2.0 * relative);
        if (std::isfinite(inverse_w) && relative < 0x1.0p-20 && inverse_w > 0.0) {
            if (lo > inverse_near_d * (1.0 + 0x1.0p-40)) return false;  // before the near plane
            if (hi < double(d)) return false;                          // farther than the claim
            if (hi <= inverse_near_d * (1.0 - 0x1.0p-40) && lo >= double(d)) return true;
        }
    }
    mpq_class inverse_w;
    return exact_hit(tri, s, inverse_near_w, inverse_w) && inverse_w >= exact(d);
}

std::vector<ExactTriangle> exact_triangles(const TriangleInput& in) {
    std::vector<ExactTriangle> out;
    std::array<std::array<mpq_class, 3>, 3> clip;
    for (std::size_t t = 0; t < in.triangle_count; ++t)
        if (exact_clip_triangle(in, t, clip)) {
            ExactTriangle tri = exact_triangle(clip);
            if (!tri.flat) out.push_back(std::move(tri));
        }
    return out;
}

mpq_class nearest_inverse_w(const std::vector<ExactTriangle>& tris, const ExactSample& s, const mpq_class& inverse_near_w) {
    mpq_class best = 0, d;
    for (const ExactTriangle& t : tris)
        if (exact_hit(t, s, inverse_near_w, d) && d > best) best = d;
    return best;
}

std::vector<float> claimed_inverse_w(const OcclusionBuffer& buffer) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    const int width = buffer.sample_width(), height = buffer.sample_height();
    std::vector<float> sample_depth;
    buffer.read_sample_depth(sample_depth);
    std::vector<float> claims(std::size_t(width) * std::size_t(height), 0.0f);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const OcclusionBuffer::Subtile s = buffer.subtile(x / kW, y / kH);
            const bool in_mask = (s.mask >> ((y % kH) * kW + x % kW)) & 1u;
            const std::size_t at = std::size_t(y) * std::size_t(width) + std::size_t(x);
            float d = in_mask ? std::max(s.d0, s.d1) : s.d0;
            if (!sample_depth.empty()) d = std::max(d, sample_depth[at]);
            claims[at] = d;
        }
    return claims;
}

long unbacked_claims(const OcclusionBuffer& buffer, const std::vector<ExactTriangle>& occluders, int* first) {
    const int width = buffer.sample_width(), height = buffer.sample_height();
    const mpq_class inverse_near = 1 / exact(buffer.config().near_w);
    const double inverse_near_d = inverse_near.get_d();
    const std::vector<float> claims = claimed_inverse_w(buffer);
    long unbacked = 0;
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const float d = claims[std::size_t(j) * std::size_t(width) + std::size_t(i)];
            if (!(d > 0.0f)) continue;
            const ExactSample s = exact_sample(i, j, width, height);
            bool backed = false;
            for (const ExactTriangle& t : occluders)
                if (hit_at_or_nearer(t, s, inverse_near, inverse_near_d, d)) {
                    backed = true;
                    break;
                }
            if (!backed && unbacked++ == 0 && first) *first = j * width + i;
        }
    return unbacked;
}

bool rect_truly_hidden(const std::vector<ExactTriangle>& occluders, const ScreenRect& r, int width, int height, float near_w) {
    const mpq_class inverse_near = 1 / exact(near_w), inverse_w_min = 1 / exact(r.w_min);
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const ExactSample s = exact_sample(i, j, width, height);
            if (s.x < exact(r.ndc_min_x) || s.x > exact(r.ndc_max_x) || s.y < exact(r.ndc_min_y) || s.y > exact(r.ndc_max_y)) continue;
            if (!hidden_at(occluders, s, inverse_near, inverse_w_min)) return false;
        }
    return true;
}

bool triangles_truly_hidden(const std::vector<ExactTriangle>& occluders, const std::vector<ExactTriangle>& occludee, int width,
                            int height, float near_w) {
    const mpq_class inverse_near = 1 / exact(near_w);
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const ExactSample s = exact_sample(i, j, width, height);
            bool maybe_seen = false;
            for (const ExactTriangle& t : occludee) maybe_seen = maybe_seen || hit_at_or_nearer(t, s, inverse_near, inverse_near.get_d(), 0.0f);
            if (!maybe_seen) continue;
            const mpq_class seen = nearest_inverse_w(occludee, s, inverse_near);
            if (seen == 0) continue;
            if (!hidden_at(occluders, s, inverse_near, seen)) return false;
        }
    return true;
}

}  // namespace homcull::test
