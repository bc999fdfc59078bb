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

// The set-up triangles of one chunk of the input, copied into the bin of every band they
// touch, in order: each band then reads its triangles sequentially (binning by index made
// almost every read a cache miss).
struct OcclusionBuffer::Chunk {
    std::vector<std::vector<detail::ScreenTriangle>> bins;
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
    if (sample_width_ > (1 << 22) || sample_height_ > (1 << 22))  // sample coordinates stay exact in float (conservative_depth)
        throw Error("occlusion buffer: more than 2^22 samples in a row or column; lower the resolution or the samples");
    subtiles_x_ = (sample_width_ + kW - 1) / kW;
    subtiles_y_ = (sample_height_ + kH - 1) / kH;
    stride_ = std::size_t(subtiles_x_ + detail::kMaxSimdLanes - 1 + detail::kMaxSimdLanes - 1) / detail::kMaxSimdLanes *
              detail::kMaxSimdLanes;
    const std::size_t plane = stride_ * std::size_t(subtiles_y_);
    d0_.assign(plane, 0.0f);
    d1_.assign(plane, 0.0f);
    mask_.assign(plane, 0u);
    covered_.assign(plane, 0u);
    band_touched_.assign(std::size_t((subtiles_y_ + kBandSubtileRows - 1) / kBandSubtileRows), 0);
    levels_.push_back({subtiles_x_, subtiles_y_, 0});  // level 0: a contiguous copy of the subtiles' d0
    std::size_t size = std::size_t(subtiles_x_) * std::size_t(subtiles_y_);
    while (levels_.back().width > 1 || levels_.back().height > 1) {
        const Level& below = levels_.back();
        levels_.push_back({(below.width + 1) / 2, (below.height + 1) / 2, size});
        size += std::size_t(levels_.back().width) * std::size_t(levels_.back().height);
    }
    pyramid_.assign(size, 0.0f);
}

void OcclusionBuffer::clear() {
    std::fill(d0_.begin(), d0_.end(), 0.0f);
    std::fill(d1_.begin(), d1_.end(), 0.0f);
    std::fill(mask_.begin(), mask_.end(), 0u);
    std::fill(covered_.begin(), covered_.end(), 0u);
    std::fill(pyramid_.begin(), pyramid_.end(), 0.0f);
    stats_ = RasterStats{};
}

inline float OcclusionBuffer::min_d0(int level, int x, int y) const {
    const Level& l = levels_[std::size_t(level)];
    return pyramid_[l.offset + std::size_t(y) * std::size_t(l.width) + std::size_t(x)];
}

void OcclusionBuffer::build_pyramid() {
    for (int ty = 0; ty < subtiles_y_; ++ty)
        std::copy_n(d0_.begin() + std::ptrdiff_t(at(0, ty)), subtiles_x_, pyramid_.begin() + std::ptrdiff_t(ty) * subtiles_x_);
    for (std::size_t level = 1; level < levels_.size(); ++level) {
        const Level& below = levels_[level - 1];
        const Level& here = levels_[level];
        for (int y = 0; y < here.height; ++y)
            for (int x = 0; x < here.width; ++x) {
                float m = min_d0(int(level) - 1, 2 * x, 2 * y);
                if (2 * x + 1 < below.width) m = std::min(m, min_d0(int(level) - 1, 2 * x + 1, 2 * y));
                if (2 * y + 1 < below.height) {
                    m = std::min(m, min_d0(int(level) - 1, 2 * x, 2 * y + 1));
                    if (2 * x + 1 < below.width) m = std::min(m, min_d0(int(level) - 1, 2 * x + 1, 2 * y + 1));
                }
                pyramid_[here.offset + std::size_t(y) * std::size_t(here.width) + std::size_t(x)] = m;
            }
    }
}

namespace {

// std::nextafter(f, +infinity) for a non-negative finite float, without a libm call.
float next_float_up(float f) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    ++bits;
    std::memcpy(&f, &bits, sizeof bits);
    return f;
}

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
                int j0, j1;
                detail::sample_span(min_y, max_y, b.sample_height_, j0, j1);
                if (j0 > j1) continue;
                for (int band = j0 / (kH * kBandSubtileRows); band <= j1 / (kH * kBandSubtileRows); ++band)
                    chunk.bins[std::size_t(band)].push_back(tri);
            }
        }
    }, &job);

    // Phase 2: rasterize each band, chunk by chunk in order.
    run_tasks(parallel, bands, [](void* data, std::size_t band) {
        const Job& j = *static_cast<Job*>(data);
        OcclusionBuffer& b = *j.self;
        const int row_begin = int(band) * kBandSubtileRows;
        const detail::RasterTarget target{{b.d0_.data(), b.d1_.data(), b.mask_.data(), b.covered_.data(), b.stride_}, b.subtiles_x_, b.subtiles_y_, b.sample_width_, b.sample_height_,
                                          b.config_.edge_margin, row_begin, std::min(row_begin + kBandSubtileRows, b.subtiles_y_),
                                          detail::selected_rows_kernel()};
        std::uint64_t touched = 0;
        for (std::size_t c = 0; c < j.chunk_count; ++c) {
            const Chunk& chunk = b.chunks_[c];
            for (const detail::ScreenTriangle& tri : chunk.bins[band]) touched += detail::rasterize_triangle(target, tri);
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
    build_pyramid();
}

bool OcclusionBuffer::prepare(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min, RectQuery& q,
                              Visibility& decided) const {
    if (!std::isfinite(ndc_min_x) || !std::isfinite(ndc_min_y) || !std::isfinite(ndc_max_x) || !std::isfinite(ndc_max_y) ||
        !std::isfinite(w_min) || !(ndc_min_x <= ndc_max_x) || !(ndc_min_y <= ndc_max_y)) {
        decided = Visibility::visible;  // nothing to reason with: never cull
        return false;
    }
    if (w_min < config_.near_w) {
        decided = Visibility::visible;
        return false;
    }
    if (ndc_max_x < -1.0f || ndc_min_x > 1.0f || ndc_max_y < -1.0f || ndc_min_y > 1.0f) {
        decided = Visibility::view_culled;
        return false;
    }
    // The samples whose centres lie in the rectangle.
    const double sx0 = (double(ndc_min_x) + 1.0) * 0.5 * sample_width_, sx1 = (double(ndc_max_x) + 1.0) * 0.5 * sample_width_;
    const double sy0 = (1.0 - double(ndc_max_y)) * 0.5 * sample_height_, sy1 = (1.0 - double(ndc_min_y)) * 0.5 * sample_height_;
    detail::sample_span(sx0, sx1, sample_width_, q.i0, q.i1);
    detail::sample_span(sy0, sy1, sample_height_, q.j0, q.j1);
    if (q.i0 > q.i1 || q.j0 > q.j1) {
        decided = Visibility::occluded;  // covers no sample: invisible at every sample
        return false;
    }
    // Nearest 1/w of the occludee, rounded up and raised by a relative 2^-20.
    const double d = 1.0 / double(w_min);
    q.d_near = float(d);
    if (double(q.d_near) < d) q.d_near = next_float_up(q.d_near);
    q.d_near *= 1.0f + 0x1.0p-20f;
    return true;
}

// Whether subtile (tx, ty) hides the rectangle's samples in it.
bool OcclusionBuffer::subtile_hides(int tx, int ty, const RectQuery& q) const {
    const int c0 = std::max(0, q.i0 - tx * kW), c1 = std::min(kW - 1, q.i1 - tx * kW);
    const int r0 = std::max(0, q.j0 - ty * kH), r1 = std::min(kH - 1, q.j1 - ty * kH);
    const std::uint32_t columns = (0xFFu >> (kW - 1 - c1)) & (0xFFu << c0);
    std::uint32_t rect = 0;
    for (int j = r0; j <= r1; ++j) rect |= columns << (j * kW);
    const std::size_t i = at(tx, ty);
    const float bound = (mask_[i] != 0 && (rect & ~mask_[i]) == 0) ? std::max(d0_[i], d1_[i]) : d0_[i];
    return q.d_near < bound;
}

Visibility OcclusionBuffer::test_rect_exhaustive(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y,
                                                 float w_min) const {
    RectQuery q;
    Visibility decided;
    if (!prepare(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min, q, decided)) return decided;
    for (int ty = q.j0 / kH; ty <= q.j1 / kH; ++ty)
        for (int tx = q.i0 / kW; tx <= q.i1 / kW; ++tx)
            if (!subtile_hides(tx, ty, q)) return Visibility::visible;
    return Visibility::occluded;
}

// Is there a subtile in [x0, x1] x [y0, y1] (subtile units) within the pyramid cell whose d0
// is at or below d_near? Cells whose minimum is above d_near are pruned.
bool OcclusionBuffer::any_farther_or_equal(int level, int x, int y, int x0, int y0, int x1, int y1, float d_near) const {
    const int cx0 = x << level, cy0 = y << level, cx1 = ((x + 1) << level) - 1, cy1 = ((y + 1) << level) - 1;
    if (cx1 < x0 || cx0 > x1 || cy1 < y0 || cy0 > y1) return false;
    if (d_near < min_d0(level, x, y)) return false;
    if (level == 0 || (cx0 >= x0 && cx1 <= x1 && cy0 >= y0 && cy1 <= y1)) return true;
    const Level& below = levels_[std::size_t(level) - 1];
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
            if (2 * x + dx < below.width && 2 * y + dy < below.height &&
                any_farther_or_equal(level - 1, 2 * x + dx, 2 * y + dy, x0, y0, x1, y1, d_near))
                return true;
    return false;
}

Visibility OcclusionBuffer::test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    RectQuery q;
    Visibility decided;
    if (!prepare(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min, q, decided)) return decided;
    const int tx0 = q.i0 / kW, tx1 = q.i1 / kW, ty0 = q.j0 / kH, ty1 = q.j1 / kH;

    // Coarse check: the level where the subtile range spans at most 2 x 2 cells. Their minimum
    // d0 is at most any covered subtile's bound, so d_near below it hides the rectangle.
    int level = 0;
    while ((tx1 >> level) - (tx0 >> level) > 1 || (ty1 >> level) - (ty0 >> level) > 1) ++level;
    float coarse = INFINITY;
    for (int y = ty0 >> level; y <= ty1 >> level; ++y)
        for (int x = tx0 >> level; x <= tx1 >> level; ++x) coarse = std::min(coarse, min_d0(level, x, y));
    if (q.d_near < coarse) return Visibility::occluded;
    // Exact range check on d0 alone: if no subtile in the range has d0 <= d_near, every bound
    // (>= d0) is above d_near and the rectangle is hidden. Most hidden rectangles end here.
    bool any_at_or_behind = false;
    for (int y = ty0 >> level; y <= ty1 >> level && !any_at_or_behind; ++y)
        for (int x = tx0 >> level; x <= tx1 >> level && !any_at_or_behind; ++x)
            any_at_or_behind = any_farther_or_equal(level, x, y, tx0, ty0, tx1, ty1, q.d_near);
    if (!any_at_or_behind) return Visibility::occluded;

    // Interior subtiles (all their samples in the rectangle): their bound is d0, so the
    // rectangle is visible there iff some d0 <= d_near. Border subtiles: the exact test.
    const bool left_full = q.i0 % kW == 0, right_full = q.i1 % kW == kW - 1 && q.i1 < sample_width_;
    const bool top_full = q.j0 % kH == 0, bottom_full = q.j1 % kH == kH - 1;
    const int ix0 = left_full ? tx0 : tx0 + 1, ix1 = right_full ? tx1 : tx1 - 1;
    const int iy0 = top_full ? ty0 : ty0 + 1, iy1 = bottom_full ? ty1 : ty1 - 1;
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            if (ty >= iy0 && ty <= iy1 && tx >= ix0 && tx <= ix1) {  // skip the interior run
                tx = ix1;
                continue;
            }
            if (!subtile_hides(tx, ty, q)) return Visibility::visible;
        }
    if (ix0 <= ix1 && iy0 <= iy1)
        for (int y = ty0 >> level; y <= ty1 >> level; ++y)
            for (int x = tx0 >> level; x <= tx1 >> level; ++x)
                if (any_farther_or_equal(level, x, y, ix0, iy0, ix1, iy1, q.d_near)) return Visibility::visible;
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

OcclusionBuffer::Subtile OcclusionBuffer::subtile(int tx, int ty) const {
    const std::size_t i = at(tx, ty);
    return {d0_[i], d1_[i], mask_[i], covered_[i]};
}

std::vector<OcclusionBuffer::Subtile> OcclusionBuffer::subtiles() const {
    std::vector<Subtile> all;
    all.reserve(std::size_t(subtiles_x_) * std::size_t(subtiles_y_));
    for (int ty = 0; ty < subtiles_y_; ++ty)
        for (int tx = 0; tx < subtiles_x_; ++tx) all.push_back(subtile(tx, ty));
    return all;
}

void OcclusionBuffer::read_coverage(std::vector<std::uint8_t>& covered) const {
    covered.assign(std::size_t(sample_width_) * std::size_t(sample_height_), 0);
    for (int y = 0; y < sample_height_; ++y)
        for (int x = 0; x < sample_width_; ++x) {
            const Subtile s = subtile(x / kW, y / kH);
            covered[std::size_t(y) * std::size_t(sample_width_) + std::size_t(x)] = (s.covered >> ((y % kH) * kW + x % kW)) & 1u;
        }
}

void OcclusionBuffer::read_depth(std::vector<float>& w) const {
    w.assign(std::size_t(sample_width_) * std::size_t(sample_height_), INFINITY);
    for (int y = 0; y < sample_height_; ++y)
        for (int x = 0; x < sample_width_; ++x) {
            const Subtile s = subtile(x / kW, y / kH);
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
