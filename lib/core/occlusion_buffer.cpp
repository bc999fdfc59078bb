#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "raster/clip_polygon.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
// Guard band in NDC units: triangles reaching beyond |x/w| or |y/w| = 32 are clipped there, so
// that sample coordinates stay small enough for double edge functions to be exact to far
// below the coverage margin.
constexpr double kGuardBand = 32.0;

glm::dvec4 transform(const std::array<float, 16>& m, double x, double y, double z, double w) {
    // Column-major m[column * 4 + row]; one fixed order of operations.
    glm::dvec4 r;
    for (int row = 0; row < 4; ++row)
        r[row] = double(m[row]) * x + double(m[4 + row]) * y + double(m[8 + row]) * z + double(m[12 + row]) * w;
    return r;
}

bool finite4(const glm::dvec4& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.w);
}

}  // namespace

OcclusionBuffer::OcclusionBuffer(const BufferConfig& config) : config_(config) {
    validate_resolution({config.width, config.height});
    if (config.samples != 1 && config.samples != 2 && config.samples != 4)
        throw Error("occlusion buffer: samples per pixel axis must be 1, 2 or 4, got " + std::to_string(config.samples));
    if (!(config.near_w > 0.0f) || !std::isfinite(config.near_w)) throw Error("occlusion buffer: near_w must be a positive number");
    if (!(config.edge_margin >= 0.0 && config.edge_margin < 0.5)) throw Error("occlusion buffer: edge margin must be in [0, 0.5) samples");
    sample_width_ = config.width * config.samples;
    sample_height_ = config.height * config.samples;
    if (double(sample_width_) * sample_height_ > double(1 << 28))
        throw Error("occlusion buffer: more than 2^28 samples; lower the resolution or the samples");
    subtiles_x_ = (sample_width_ + kW - 1) / kW;
    subtiles_y_ = (sample_height_ + kH - 1) / kH;
    subtiles_.assign(std::size_t(subtiles_x_) * std::size_t(subtiles_y_), Subtile{});
}

void OcclusionBuffer::clear() {
    std::fill(subtiles_.begin(), subtiles_.end(), Subtile{});
    stats_ = RasterStats{};
}

void OcclusionBuffer::render(const TriangleInput& in) {
    if (in.triangle_count == 0) return;
    if (in.position_components != 3 && in.position_components != 4) throw Error("render: positions must have 3 or 4 components");
    if (!in.positions || in.position_stride < sizeof(float) * std::size_t(in.position_components))
        throw Error("render: positions missing, or stride smaller than one position");
    if (!in.indices && in.vertex_count < in.triangle_count * 3)
        throw Error("render: without indices, vertex_count must be at least 3 * triangle_count");
    const auto* bytes = static_cast<const unsigned char*>(in.positions);
    const detail::RasterTarget target{subtiles_.data(), subtiles_x_, subtiles_y_, sample_width_, sample_height_, config_.edge_margin};
    const double near_w = config_.near_w;

    for (std::size_t t = 0; t < in.triangle_count; ++t) {
        ++stats_.triangles_in;
        std::uint32_t index[3];
        for (int k = 0; k < 3; ++k) {
            const std::size_t n = 3 * t + std::size_t(k);
            if (!in.indices) index[k] = std::uint32_t(n);
            else if (in.indices_16bit) index[k] = static_cast<const std::uint16_t*>(in.indices)[n];
            else index[k] = static_cast<const std::uint32_t*>(in.indices)[n];
        }
        if (index[0] >= in.vertex_count || index[1] >= in.vertex_count || index[2] >= in.vertex_count) {
            ++stats_.invalid;
            continue;
        }
        glm::dvec4 clip[3];
        bool valid = true;
        for (int k = 0; k < 3; ++k) {
            float p[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            std::memcpy(p, bytes + std::size_t(index[k]) * in.position_stride, sizeof(float) * std::size_t(in.position_components));
            clip[k] = transform(in.model_to_clip, p[0], p[1], p[2], p[3]);
            valid = valid && finite4(clip[k]);
        }
        if (!valid) {
            ++stats_.invalid;
            continue;
        }
        // Entirely outside one plane of the view frustum (or behind the near plane)?
        auto all = [&](auto outside) { return outside(clip[0]) && outside(clip[1]) && outside(clip[2]); };
        if (all([&](const glm::dvec4& c) { return c.w < near_w; }) || all([](const glm::dvec4& c) { return c.x > c.w; }) ||
            all([](const glm::dvec4& c) { return c.x < -c.w; }) || all([](const glm::dvec4& c) { return c.y > c.w; }) ||
            all([](const glm::dvec4& c) { return c.y < -c.w; })) {
            ++stats_.outside;
            continue;
        }
        double extent = 0.0, min_w = HUGE_VAL;
        for (const auto& c : clip) {
            extent = std::max({extent, std::abs(c.x), std::abs(c.y)});
            min_w = std::min(min_w, c.w);
        }
        if (extent > 0x1.0p28 * std::max(near_w, min_w)) {
            ++stats_.too_large;
            continue;
        }
        bool needs_clip = false;
        for (const auto& c : clip)
            needs_clip = needs_clip || c.w < near_w || std::abs(c.x) > kGuardBand * c.w || std::abs(c.y) > kGuardBand * c.w;
        const std::uint8_t shared_bits = in.shared_edges ? in.shared_edges[t] : 0;
        const detail::ClipVertex corners[3] = {{clip[0].x, clip[0].y, clip[0].w}, {clip[1].x, clip[1].y, clip[1].w},
                                               {clip[2].x, clip[2].y, clip[2].w}};
        detail::ClipPolygon poly;
        if (needs_clip) {
            poly = detail::clip_triangle(corners, shared_bits, near_w, kGuardBand);
        } else {
            for (int k = 0; k < 3; ++k) {
                poly.v[k] = corners[k];
                poly.shared[k] = (shared_bits >> k) & 1u;
            }
            poly.count = 3;
        }
        stats_.near_clipped += needs_clip;
        if (poly.count == 0) {
            ++stats_.outside;
            continue;
        }

        // Project to sample space (y down) with depth 1/w.
        detail::ScreenTriangle fan[detail::ClipPolygon::kMax];
        glm::dvec2 screen[detail::ClipPolygon::kMax];
        double depth[detail::ClipPolygon::kMax];
        for (int k = 0; k < poly.count; ++k) {
            const double inv_w = 1.0 / poly.v[k].z;
            screen[k] = {(poly.v[k].x * inv_w + 1.0) * 0.5 * sample_width_, (1.0 - poly.v[k].y * inv_w) * 0.5 * sample_height_};
            depth[k] = inv_w;
        }
        // Orientation and degeneracy from homogeneous determinants det[x y w] (w > 0 after
        // clipping): positive for counter-clockwise in NDC, and exactly zero for collinear
        // input, before any division rounds it. Summed over the polygon's fan, because clipping
        // may leave three consecutive vertices on one line.
        auto det3 = [](const detail::ClipVertex& a, const detail::ClipVertex& b, const detail::ClipVertex& c) {
            return a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
        };
        double det = 0.0;
        for (int k = 1; k + 1 < poly.count; ++k) det += det3(poly.v[0], poly.v[k], poly.v[k + 1]);
        if (det == 0.0) {
            ++stats_.degenerate;
            continue;
        }
        const bool ccw_in_ndc = det > 0.0;
        if ((in.backface == Backface::cw && !ccw_in_ndc) || (in.backface == Backface::ccw && ccw_in_ndc)) {
            ++stats_.backface_culled;
            continue;
        }
        // Fan triangles (0, k, k + 1): their diagonals are shared with each other.
        int triangles = 0;
        for (int k = 1; k + 1 < poly.count; ++k) {
            const bool first = k == 1, last = k + 2 == poly.count;
            const std::uint8_t bits = std::uint8_t((first ? poly.shared[0] : 1u) | (poly.shared[k] << 1) |
                                                   ((last ? poly.shared[k + 1] : 1u) << 2));
            fan[triangles++] = {{screen[0], screen[k], screen[k + 1]}, {depth[0], depth[k], depth[k + 1]}, bits};
        }
        for (int k = 0; k < triangles; ++k) stats_.subtiles_touched += detail::rasterize_triangle(target, fan[k]);
        ++stats_.rasterized;
    }
}

Visibility OcclusionBuffer::test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    if (!std::isfinite(ndc_min_x) || !std::isfinite(ndc_min_y) || !std::isfinite(ndc_max_x) || !std::isfinite(ndc_max_y) ||
        !std::isfinite(w_min) || !(ndc_min_x <= ndc_max_x) || !(ndc_min_y <= ndc_max_y))
        return Visibility::visible;  // nothing to reason with: never cull
    if (w_min < config_.near_w) return Visibility::visible;
    if (ndc_max_x < -1.0f || ndc_min_x > 1.0f || ndc_max_y < -1.0f || ndc_min_y > 1.0f) return Visibility::view_culled;

    // The samples whose centres lie in the rectangle.
    const double sx0 = (double(ndc_min_x) + 1.0) * 0.5 * sample_width_, sx1 = (double(ndc_max_x) + 1.0) * 0.5 * sample_width_;
    const double sy0 = (1.0 - double(ndc_max_y)) * 0.5 * sample_height_, sy1 = (1.0 - double(ndc_min_y)) * 0.5 * sample_height_;
    const int i0 = std::max(0, int(std::ceil(sx0 - 0.5))), i1 = std::min(sample_width_ - 1, int(std::floor(sx1 - 0.5)));
    const int j0 = std::max(0, int(std::ceil(sy0 - 0.5))), j1 = std::min(sample_height_ - 1, int(std::floor(sy1 - 0.5)));
    if (i0 > i1 || j0 > j1) return Visibility::occluded;  // covers no sample: invisible at every sample

    // Nearest 1/w of the occludee, rounded up and raised by a relative 2^-20.
    const double d = 1.0 / double(w_min);
    float d_near = float(d);
    if (double(d_near) < d) d_near = std::nextafter(d_near, std::numeric_limits<float>::infinity());
    d_near *= 1.0f + 0x1.0p-20f;

    for (int ty = j0 / kH; ty <= j1 / kH; ++ty) {
        std::uint32_t row_mask = 0;  // rectangle rows within this subtile row
        for (int j = 0; j < kH; ++j) {
            const int sy = ty * kH + j;
            if (sy >= j0 && sy <= j1) row_mask |= 0xFFu << (j * kW);
        }
        for (int tx = i0 / kW; tx <= i1 / kW; ++tx) {
            const int c0 = std::max(0, i0 - tx * kW), c1 = std::min(kW - 1, i1 - tx * kW);
            const std::uint32_t columns = ((1u << (c1 + 1)) - 1u) & ~((1u << c0) - 1u);
            std::uint32_t rect = 0;
            for (int j = 0; j < kH; ++j) rect |= columns << (j * kW);
            rect &= row_mask;
            const Subtile& s = subtiles_[std::size_t(ty) * std::size_t(subtiles_x_) + std::size_t(tx)];
            const float bound = (s.mask != 0 && (rect & ~s.mask) == 0) ? std::max(s.d0, s.d1) : s.d0;
            if (!(d_near < bound)) return Visibility::visible;
        }
    }
    return Visibility::occluded;
}

Visibility OcclusionBuffer::test_aabb(const float box_min[3], const float box_max[3], const std::array<float, 16>& m) const {
    // Incremental corner transform: the base corner plus the three transformed edge vectors.
    const glm::dvec4 base = transform(m, box_min[0], box_min[1], box_min[2], 1.0);
    const glm::dvec4 ex = transform(m, double(box_max[0]) - double(box_min[0]), 0, 0, 0);
    const glm::dvec4 ey = transform(m, 0, double(box_max[1]) - double(box_min[1]), 0, 0);
    const glm::dvec4 ez = transform(m, 0, 0, double(box_max[2]) - double(box_min[2]), 0);
    double min_x = HUGE_VAL, max_x = -HUGE_VAL, min_y = HUGE_VAL, max_y = -HUGE_VAL, min_w = HUGE_VAL;
    int behind = 0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4 c = base + ((k & 1) ? ex : glm::dvec4(0)) + ((k & 2) ? ey : glm::dvec4(0)) + ((k & 4) ? ez : glm::dvec4(0));
        if (!finite4(c)) return Visibility::visible;
        if (c.w < double(config_.near_w)) {
            ++behind;
            continue;
        }
        min_x = std::min(min_x, c.x / c.w), max_x = std::max(max_x, c.x / c.w);
        min_y = std::min(min_y, c.y / c.w), max_y = std::max(max_y, c.y / c.w);
        min_w = std::min(min_w, c.w);
    }
    if (behind == 8) return Visibility::view_culled;  // entirely before the near plane
    if (behind > 0) return Visibility::visible;       // crosses the near plane
    // Round the rectangle outwards and the depth towards the eye when going to float.
    const auto down = [](double v) { float f = float(v); return double(f) > v ? std::nextafter(f, -INFINITY) : f; };
    const auto up = [](double v) { float f = float(v); return double(f) < v ? std::nextafter(f, INFINITY) : f; };
    return test_rect(down(min_x), down(min_y), up(max_x), up(max_y), down(min_w));
}

void OcclusionBuffer::read_coverage(std::vector<std::uint8_t>& covered) const {
    covered.assign(std::size_t(sample_width_) * std::size_t(sample_height_), 0);
    for (int y = 0; y < sample_height_; ++y)
        for (int x = 0; x < sample_width_; ++x) {
            const Subtile& s = subtiles_[std::size_t(y / kH) * std::size_t(subtiles_x_) + std::size_t(x / kW)];
            covered[std::size_t(y) * std::size_t(sample_width_) + std::size_t(x)] = (s.covered >> ((y % kH) * kW + x % kW)) & 1u;
        }
}

void OcclusionBuffer::read_depth(std::vector<float>& w) const {
    w.assign(std::size_t(sample_width_) * std::size_t(sample_height_), INFINITY);
    for (int y = 0; y < sample_height_; ++y)
        for (int x = 0; x < sample_width_; ++x) {
            const Subtile& s = subtiles_[std::size_t(y / kH) * std::size_t(subtiles_x_) + std::size_t(x / kW)];
            const bool in_mask = (s.mask >> ((y % kH) * kW + x % kW)) & 1u;
            const float d = in_mask ? std::max(s.d0, s.d1) : s.d0;
            w[std::size_t(y) * std::size_t(sample_width_) + std::size_t(x)] = d > 0.0f ? 1.0f / d : INFINITY;
        }
}

std::array<float, 16> clip_from_world(const Camera& camera, double aspect) {
    const glm::dmat4 m = projection_matrix(camera, aspect) * view_matrix(camera);
    std::array<float, 16> out{};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[std::size_t(4 * c + r)] = float(m[c][r]);
    return out;
}

}  // namespace homcull
