#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "raster/rasterize.hpp"
#include "raster/triangle_setup.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
constexpr std::size_t kChunkTriangles = 2048;  // triangles set up per task
constexpr int kBandSubtileRows = 4;           // subtile rows rasterized per task (16 sample rows)

}  // namespace

// Set-up triangles of one chunk of the input, and per band the ones that touch it, in order.
struct OcclusionBuffer::Chunk {
    std::vector<detail::ScreenTriangle> triangles;
    std::vector<std::vector<std::uint32_t>> bins;
    RasterStats stats;
};

OcclusionBuffer::~OcclusionBuffer() = default;
OcclusionBuffer::OcclusionBuffer(OcclusionBuffer&&) noexcept = default;
OcclusionBuffer& OcclusionBuffer::operator=(OcclusionBuffer&&) noexcept = default;

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
    band_touched_.assign(std::size_t((subtiles_y_ + kBandSubtileRows - 1) / kBandSubtileRows), 0);
}

void OcclusionBuffer::clear() {
    std::fill(subtiles_.begin(), subtiles_.end(), Subtile{});
    stats_ = RasterStats{};
}

namespace {

void run_tasks(const ParallelFor& parallel, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    if (parallel.run) parallel.run(parallel.user, count, task, data);
    else
        for (std::size_t i = 0; i < count; ++i) task(data, i);
}

}  // namespace

void OcclusionBuffer::render(const TriangleInput& in, const ParallelFor& parallel) {
    if (in.triangle_count == 0) return;
    if (in.position_components != 3 && in.position_components != 4) throw Error("render: positions must have 3 or 4 components");
    if (!in.positions || in.position_stride < sizeof(float) * std::size_t(in.position_components))
        throw Error("render: positions missing, or stride smaller than one position");
    if (!in.indices && in.vertex_count < in.triangle_count * 3)
        throw Error("render: without indices, vertex_count must be at least 3 * triangle_count");

    const std::size_t chunk_count = (in.triangle_count + kChunkTriangles - 1) / kChunkTriangles;
    const std::size_t bands = band_touched_.size();
    if (chunks_.size() < chunk_count) chunks_.resize(chunk_count);

    struct Job {
        OcclusionBuffer* self;
        const TriangleInput* in;
        std::size_t chunk_count, bands;
    } job{this, &in, chunk_count, bands};

    // Phase 1: set up and bin each chunk.
    run_tasks(parallel, chunk_count, [](void* data, std::size_t c) {
        const Job& j = *static_cast<Job*>(data);
        OcclusionBuffer& b = *j.self;
        Chunk& chunk = b.chunks_[c];
        chunk.triangles.clear();
        chunk.stats = RasterStats{};
        if (chunk.bins.size() < j.bands) chunk.bins.resize(j.bands);
        for (auto& bin : chunk.bins) bin.clear();
        const std::size_t end = std::min(j.in->triangle_count, (c + 1) * kChunkTriangles);
        for (std::size_t t = c * kChunkTriangles; t < end; ++t) {
            const detail::SetupResult setup =
                detail::setup_triangle(*j.in, t, b.config_.near_w, b.sample_width_, b.sample_height_, chunk.stats);
            for (int k = 0; k < setup.count; ++k) {
                const detail::ScreenTriangle& tri = setup.triangles[k];
                const double min_y = std::min({tri.p[0].y, tri.p[1].y, tri.p[2].y});
                const double max_y = std::max({tri.p[0].y, tri.p[1].y, tri.p[2].y});
                const int j0 = std::max(0, int(std::ceil(min_y - 0.5)));
                const int j1 = std::min(b.sample_height_ - 1, int(std::floor(max_y - 0.5)));
                if (j0 > j1) continue;
                const auto index = std::uint32_t(chunk.triangles.size());
                chunk.triangles.push_back(tri);
                for (int band = j0 / (kH * kBandSubtileRows); band <= j1 / (kH * kBandSubtileRows); ++band)
                    chunk.bins[std::size_t(band)].push_back(index);
            }
        }
    }, &job);

    // Phase 2: rasterize each band, chunk by chunk in order.
    run_tasks(parallel, bands, [](void* data, std::size_t band) {
        const Job& j = *static_cast<Job*>(data);
        OcclusionBuffer& b = *j.self;
        const int row_begin = int(band) * kBandSubtileRows;
        const detail::RasterTarget target{b.subtiles_.data(), b.subtiles_x_, b.subtiles_y_, b.sample_width_, b.sample_height_,
                                          b.config_.edge_margin, row_begin, std::min(row_begin + kBandSubtileRows, b.subtiles_y_)};
        std::uint64_t touched = 0;
        for (std::size_t c = 0; c < j.chunk_count; ++c) {
            const Chunk& chunk = b.chunks_[c];
            for (std::uint32_t index : chunk.bins[band]) touched += detail::rasterize_triangle(target, chunk.triangles[index]);
        }
        b.band_touched_[band] = touched;
    }, &job);

    for (std::size_t c = 0; c < chunk_count; ++c) {
        const RasterStats& s = chunks_[c].stats;
        stats_.triangles_in += s.triangles_in;
        stats_.invalid += s.invalid;
        stats_.outside += s.outside;
        stats_.near_clipped += s.near_clipped;
        stats_.too_large += s.too_large;
        stats_.backface_culled += s.backface_culled;
        stats_.degenerate += s.degenerate;
        stats_.rasterized += s.rasterized;
    }
    for (std::uint64_t touched : band_touched_) stats_.subtiles_touched += touched;
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
    const glm::dvec4 base = detail::transform_to_clip(m, box_min[0], box_min[1], box_min[2], 1.0);
    const glm::dvec4 ex = detail::transform_to_clip(m, double(box_max[0]) - double(box_min[0]), 0, 0, 0);
    const glm::dvec4 ey = detail::transform_to_clip(m, 0, double(box_max[1]) - double(box_min[1]), 0, 0);
    const glm::dvec4 ez = detail::transform_to_clip(m, 0, 0, double(box_max[2]) - double(box_min[2]), 0);
    double min_x = HUGE_VAL, max_x = -HUGE_VAL, min_y = HUGE_VAL, max_y = -HUGE_VAL, min_w = HUGE_VAL;
    int behind = 0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4 c = base + ((k & 1) ? ex : glm::dvec4(0)) + ((k & 2) ? ey : glm::dvec4(0)) + ((k & 4) ? ez : glm::dvec4(0));
        if (!detail::finite_clip(c)) return Visibility::visible;
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
