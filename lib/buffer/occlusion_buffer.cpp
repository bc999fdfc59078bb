#include <homcull/error.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "common/float_mode.hpp"
#include "buffer/render_bands.hpp"
#include "common/run_tasks.hpp"
#include "raster/draw_order.hpp"
#include "raster/rasterize.hpp"
#include "raster/reference_cells.hpp"
#include "raster/triangle_batch.hpp"

#include <hwy/cache_control.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
using detail::kBandPyramidLevels;
using detail::kBandSubtileRows;
using detail::kCellRefreshTriangles;
using detail::kChunkTriangles;
using detail::kMaxWaveChunks;

}  // namespace

detail::BufferState::~BufferState() = default;

detail::BufferState::BufferState(const BufferConfig& config) { configure(config); }

const char* buffer_config_problem(const BufferConfig& config) noexcept {
    if (config.width < 1 || config.height < 1 || config.width > 65536 || config.height > 65536)
        return "the resolution must be between 1x1 and 65536x65536";
    if (config.samples != 1 && config.samples != 2 && config.samples != 4) return "samples per pixel axis must be 1, 2 or 4";
    // Depths are stored as float 1/w: below 2^-126 (subnormal) 1/near_w overflows float, and the
    // draw order's and the cells' float depths stop agreeing with the setup's double ones.
    if (!config.orthographic && (!(config.near_w >= 0x1.0p-126f) || !std::isfinite(config.near_w)))
        return "near_w must be a finite number of at least 2^-126 (1.2e-38)";
    if (!(config.edge_margin >= 0.0 && config.edge_margin < 0.5)) return "the edge margin must be in [0, 0.5) samples";
    const double sample_width = double(config.width) * config.samples, sample_height = double(config.height) * config.samples;
    if (sample_width * sample_height > double(1 << 28)) return "more than 2^28 samples; lower the resolution or the samples";
    if (sample_width > double(1 << 22) || sample_height > double(1 << 22))  // sample coordinates stay exact in float (conservative_depth)
        return "more than 2^22 samples in a row or column; lower the resolution or the samples";
    if (config.isa && !detail::find_isa_choice(config.isa))
        return "the instruction set is not one this machine and build can run (available_isas(), or \"best\")";
    return nullptr;
}

namespace {

void validate_config(const BufferConfig& config) {
    if (const char* problem = buffer_config_problem(config))
        throw Error(std::string("occlusion buffer: ") + problem + " (got " + std::to_string(config.width) + "x" + std::to_string(config.height) +
                    " pixels, " + std::to_string(config.samples) + " samples per axis, near_w " + std::to_string(config.near_w) +
                    (config.isa ? std::string(", instruction set '") + config.isa + "'" : std::string()) + ")");
}

}  // namespace

// The sizes of a buffer's arrays for a configuration.
struct detail::BufferSizes {
    int sample_width, sample_height, subtiles_x, subtiles_y;
    std::size_t stride, plane, sample_depth_stride, sample_depth, bands, pyramid, levels, cells_width, cells_height, cells;
    // The deferred per-sample depth's arrays (raster/sample_depth_tiles.hpp): 0 without per-sample depth.
    int depth_units_x, depth_units_y, depth_tiles_x, depth_tiles_y, depth_groups;
    std::uint32_t depth_word_capacity, depth_entry_capacity;
    std::size_t depth_units, depth_tiles, depth_words, depth_entries;
};

namespace {

detail::BufferSizes buffer_sizes(const BufferConfig& config) {
    detail::BufferSizes z{};
    z.sample_width = config.width * config.samples;
    z.sample_height = config.height * config.samples;
    z.subtiles_x = (z.sample_width + kW - 1) / kW;
    z.subtiles_y = (z.sample_height + kH - 1) / kH;
    z.stride = std::size_t(z.subtiles_x + detail::kMaxSimdLanes - 1 + detail::kMaxSimdLanes - 1) / detail::kMaxSimdLanes * detail::kMaxSimdLanes;
    z.plane = z.stride * std::size_t(z.subtiles_y);
    z.sample_depth_stride = std::size_t(z.sample_width) + detail::kMaxSimdLanes;
    z.sample_depth = config.sample_depth ? z.sample_depth_stride * std::size_t(z.sample_height) : 0;
    if (config.sample_depth) {
        z.depth_units_x = (z.sample_width + detail::kDepthUnitWidth - 1) / detail::kDepthUnitWidth;
        z.depth_units_y = (z.sample_height + detail::kDepthUnitHeight - 1) / detail::kDepthUnitHeight;
        z.depth_tiles_x = (z.sample_width + detail::kDepthTileWidth - 1) / detail::kDepthTileWidth;
        z.depth_tiles_y = (z.sample_height + detail::kDepthTileHeight - 1) / detail::kDepthTileHeight;
        z.depth_groups = (z.subtiles_y + detail::kDepthGroupSubtileRows - 1) / detail::kDepthGroupSubtileRows;
        z.depth_word_capacity = detail::depth_word_capacity(z.subtiles_x);
        z.depth_entry_capacity = detail::depth_entry_capacity(z.subtiles_x);
        z.depth_units = std::size_t(z.depth_units_x) * std::size_t(z.depth_units_y);
        z.depth_tiles = std::size_t(z.depth_tiles_x) * std::size_t(z.depth_tiles_y);
        z.depth_words = std::size_t(z.depth_groups) * z.depth_word_capacity;
        z.depth_entries = std::size_t(z.depth_groups) * z.depth_entry_capacity;
    }
    z.bands = std::size_t((z.subtiles_y + kBandSubtileRows - 1) / kBandSubtileRows);
    z.levels = 1;
    std::size_t size = std::size_t(z.subtiles_x) * std::size_t(z.subtiles_y);
    for (int w = z.subtiles_x, h = z.subtiles_y; w > 1 || h > 1; ++z.levels) {
        w = (w + 1) / 2, h = (h + 1) / 2;
        size += std::size_t(w) * std::size_t(h);
    }
    z.pyramid = size + detail::kMaxSimdLanes;  // padded: ScanRect loads whole vectors of a level's row
    z.cells_width = std::size_t(detail::reference_cells_width(z.subtiles_x));
    z.cells_height = std::size_t(detail::reference_cells_height(z.subtiles_y));
    z.cells = std::size_t(detail::kCellTables) * z.cells_width * z.cells_height;
    return z;
}

}  // namespace

// Room in the arrays whose size follows the configuration (reserve keeps their contents).
// depth_tiles_ points into some of them, and a reserve that throws part way through may have
// moved those before it: however this ends, depth_tiles_ points at the arrays as they are.
void detail::BufferState::reserve_arrays(const detail::BufferSizes& z) {
    struct PointDepthTilesOnExit {
        BufferState& state;
        ~PointDepthTilesOnExit() { state.point_depth_tiles(); }
    } point_on_exit{*this};
    d0_.reserve(z.plane), d1_.reserve(z.plane), mask_.reserve(z.plane), covered_.reserve(z.plane);
    sample_depth_.reserve(z.sample_depth);
    depth_unit_state_.reserve(z.depth_units), depth_tile_head_.reserve(z.depth_tiles);
    depth_groups_.reserve(std::size_t(z.depth_groups));
    depth_words_.reserve(z.depth_words), depth_entries_.reserve(z.depth_entries);
    band_updated_.reserve(z.bands), band_seconds_.reserve(z.bands);
    levels_.reserve(z.levels), level_offset_.reserve(z.levels), level_width_.reserve(z.levels);
    pyramid_.reserve(z.pyramid);
    reference_cells_.reserve(z.cells);
    cell_row_load_.reserve(z.cells_height);
}

// Everything that can fail (the checks, then every allocation: reserve keeps a vector's
// contents) comes before anything changes, so that a configuration that throws leaves the buffer
// as it was. Arrays that already hold enough keep their memory.
void detail::BufferState::configure(const BufferConfig& config) {
    validate_config(config);
    const detail::BufferSizes z = buffer_sizes(config);
    reserve_arrays(z);

    const detail::IsaChoice& isa = config.isa ? *detail::find_isa_choice(config.isa) : detail::default_isa_choice();
    config_ = config;
    config_.isa = isa.name;
    kernels_ = &detail::buffer_kernels(isa);
    isa_ = &isa;
    if (config.orthographic) config_.near_w = detail::kOrthographicNearW;  // the near plane, z = -1
    sample_width_ = z.sample_width, sample_height_ = z.sample_height;
    subtiles_x_ = z.subtiles_x, subtiles_y_ = z.subtiles_y;
    stride_ = z.stride;
    d0_.assign(z.plane, 0.0f);
    d1_.assign(z.plane, 0.0f);
    mask_.assign(z.plane, 0u);
    covered_.assign(z.plane, 0u);
    sample_depth_stride_ = z.sample_depth_stride;
    sample_depth_.assign(z.sample_depth, 0.0f);
    deferred_sample_depth_ = config.sample_depth && detail::deferred_sample_depth_enabled();
    depth_unit_state_.assign(z.depth_units, detail::kDepthUnitStale);
    depth_tile_head_.assign(z.depth_tiles, detail::kNoDepthEntry);
    depth_groups_.assign(std::size_t(z.depth_groups), detail::DepthGroupCursor{});
    depth_words_.resize(z.depth_words);
    depth_entries_.resize(z.depth_entries);
    depth_tiles_ = {};
    depth_tiles_.sample_height = z.sample_height;
    depth_tiles_.units_x = z.depth_units_x, depth_tiles_.units_y = z.depth_units_y;
    depth_tiles_.tiles_x = z.depth_tiles_x, depth_tiles_.tiles_y = z.depth_tiles_y, depth_tiles_.groups = z.depth_groups;
    depth_tiles_.word_capacity = z.depth_word_capacity, depth_tiles_.entry_capacity = z.depth_entry_capacity;
    band_updated_.assign(z.bands, 0);
    band_seconds_.assign(z.bands, 0.0f);
    levels_.clear();
    levels_.push_back({subtiles_x_, subtiles_y_, 0});  // level 0: a contiguous copy of the subtiles' d0
    std::size_t size = std::size_t(subtiles_x_) * std::size_t(subtiles_y_);
    while (levels_.back().width > 1 || levels_.back().height > 1) {
        const detail::PyramidLevel& below = levels_.back();
        levels_.push_back({(below.width + 1) / 2, (below.height + 1) / 2, size});
        size += std::size_t(levels_.back().width) * std::size_t(levels_.back().height);
    }
    pyramid_.assign(z.pyramid, 0.0f);
    reference_cells_width_ = int(z.cells_width);
    reference_cells_.assign(z.cells, 0.0f);
    reference_cells_current_ = false;
    cell_row_load_.assign(z.cells_height, 0u);
    level_offset_.clear(), level_width_.clear();
    for (const detail::PyramidLevel& l : levels_) {
        level_offset_.push_back(std::int32_t(l.offset));
        level_width_.push_back(l.width);
    }
    point_depth_tiles();
    stats_ = RasterStats{};
}

void detail::BufferState::point_depth_tiles() {
    detail::SampleDepthTiles& t = depth_tiles_;
    const bool kept = deferred_sample_depth_ && !sample_depth_.empty();
    t.depth = kept ? sample_depth_.data() : nullptr;
    t.stride = sample_depth_stride_;
    t.unit_state = kept ? depth_unit_state_.data() : nullptr;
    t.tile_head = kept ? depth_tile_head_.data() : nullptr;
    t.words = kept ? depth_words_.data() : nullptr;
    t.entries = kept ? depth_entries_.data() : nullptr;
    t.group = kept ? depth_groups_.data() : nullptr;
    t.fill_unit = kernels_ ? kernels_->raster.fill_depth_unit : nullptr;  // none before the first configure's end
}

void detail::BufferState::set_near_w(float near_w) {
    BufferConfig config = config_;
    config.near_w = near_w;
    validate_config(config);
    if (!config_.orthographic) config_.near_w = near_w;  // an orthographic buffer's is its near plane's
    clear();
}

// Sized as the renders size them (render_rows, transform_vertices, sort_nearest_first,
// render_serial, render_clusters), for the largest input and buffer: those on one thread then
// find every array large enough.
void detail::BufferState::reserve(const BufferReserve& r) {
    BufferConfig largest = config_;
    largest.width = std::max(config_.width, r.max_width);
    largest.height = std::max(config_.height, r.max_height);
    validate_config(largest);
    const detail::BufferSizes z = buffer_sizes(largest);
    reserve_arrays(z);

    const auto at_least = [](auto& v, std::size_t n) {
        if (v.size() < n) v.resize(n);
    };
    // Triangle input: the draw order's scratch, the vertex cache and the noted render's part.
    const std::size_t n = r.max_triangles, tasks = (n + detail::kDrawOrderTask - 1) / detail::kDrawOrderTask;
    if (n > 0) {
        if (!draw_order_) draw_order_ = detail::make_hooked<detail::DrawOrderScratch>();
        detail::DrawOrderScratch& d = *draw_order_;
        at_least(d.bucket, n);
        at_least(d.data, 12 * n);  // a soup of 4 floats a vertex: its largest copy
        at_least(d.shared_edges, n);
        at_least(d.edge_apexes, 3 * n);
        at_least(d.placed_at, n);
        at_least(d.count, tasks * detail::kDrawOrderBuckets);
        at_least(d.excluded, tasks * detail::kDrawOrderBuckets);
        at_least(d.start, tasks * detail::kDrawOrderClasses);
        at_least(d.skipped, tasks);
        at_least(d.noted, n);
        at_least(d.sorted_notes, n);
        if (noted_parts_.empty()) noted_parts_.resize(1);
        at_least(noted_parts_[0].undecided, kCellRefreshTriangles);
    }
    if (r.max_vertices > 0) {
        if (!draw_order_) draw_order_ = detail::make_hooked<detail::DrawOrderScratch>();
        at_least(draw_order_->vertex_code, r.max_vertices);
        at_least(vertex_clip_, 4 * (r.max_vertices + detail::kVertexClipPadding));
        at_least(vertex_outcode_, r.max_vertices);
    }
    // Triangle input with a job system: the waves (render_binned) and, for a clip-space soup,
    // one part of the rows per thread (render_parts).
    if (n > 0 && r.max_threads > 0) {
        reserve_waves(std::min((n + kChunkTriangles - 1) / kChunkTriangles, kMaxWaveChunks), z.bands);
        const std::size_t parts = std::min(r.max_threads, z.cells_height);
        at_least(reference_cells_, parts * z.cells);
        if (noted_parts_.size() < parts) noted_parts_.resize(parts);
        for (NotedPart& part : noted_parts_) at_least(part.undecided, kCellRefreshTriangles);
    }
    // Clustered input: one draw on one thread, or a task list (render_clusters, close_tasks).
    at_least(cluster_places_, r.max_clusters);
    placed_clusters_.reserve(std::max(r.max_clusters, r.max_task_list_clusters));
    recorded_draws_.reserve(std::max<std::size_t>(1, r.max_task_list_draws));
    band_stats_.reserve(z.bands);
    band_ran_.reserve(z.bands), band_order_.reserve(z.bands);
    cluster_row_runs_.reserve(z.bands);
    if (r.max_clusters > 0 || r.max_task_list_clusters > 0) {
        const std::size_t plane = r.max_cluster_vertices + detail::kVertexClipPadding;
        at_least(band_vertex_clip_, z.bands * 4 * plane);
        at_least(band_vertex_outcode_, z.bands * plane);
    }
    at_least(cluster_setups_, r.max_task_list_clusters);
    at_least(setup_triangles_, std::min(r.max_task_list_triangles, kSetUpRoomTriangles));
}

void detail::BufferState::check_projection(bool orthographic, const char* caller) const {
    if (orthographic != config_.orthographic)
        throw Error(std::string(caller) + (config_.orthographic ? ": the buffer is orthographic and the input is not (TriangleInput, ClusteredInput::orthographic)"
                                                               : ": the input is orthographic and the buffer is not (BufferConfig::orthographic)"));
}

void detail::BufferState::clear() {
    reference_cells_current_ = false;
    clear_rows(0, subtiles_y_);
    std::fill(pyramid_.begin(), pyramid_.end(), 0.0f);
    stats_ = RasterStats{};
}

void detail::BufferState::clear_rows(int row_begin, int row_end) {
    const auto zero = [](auto& plane, std::size_t begin, std::size_t end) {
        std::fill(plane.begin() + std::ptrdiff_t(begin), plane.begin() + std::ptrdiff_t(end), 0);
    };
    const std::size_t begin = std::size_t(row_begin) * stride_, end = std::size_t(row_end) * stride_;
    zero(d0_, begin, end);
    zero(d1_, begin, end);
    zero(mask_, begin, end);
    zero(covered_, begin, end);
    if (deferred_sample_depth_) {
        // Whole groups: rows begin at a multiple of kDepthGroupSubtileRows wherever a render
        // clears them (bands, parts of rows, the whole buffer). Were one not to, the group's
        // rows above it would lose their per-sample depth (0: no bound), which only costs culling.
        detail::reset_sample_depth_rows(depth_tiles_, row_begin / detail::kDepthGroupSubtileRows * detail::kDepthGroupSubtileRows, row_end);
    } else if (!sample_depth_.empty()) {
        zero(sample_depth_, std::size_t(row_begin * kH) * sample_depth_stride_,
             std::size_t(std::min(row_end * kH, sample_height_)) * sample_depth_stride_);
    }
}

void detail::BufferState::build_pyramid_rows(int row_begin, int row_end, int last_level) {
    for (int ty = row_begin; ty < row_end; ++ty)
        std::copy_n(d0_.begin() + std::ptrdiff_t(at(0, ty)), subtiles_x_, pyramid_.begin() + std::ptrdiff_t(ty) * subtiles_x_);
    for (int level = 1; level <= last_level; ++level)
        reduce_pyramid_rows(level, row_begin >> level, std::min(levels_[std::size_t(level)].height, (row_end + (1 << level) - 1) >> level));
}

void detail::BufferState::reduce_pyramid_above_bands() {
    for (int level = kBandPyramidLevels + 1; level < int(levels_.size()); ++level) reduce_pyramid_rows(level, 0, levels_[std::size_t(level)].height);
}

void detail::BufferState::build_pyramid_rect(int x0, int x1, int y0, int y1) {
    if (x0 >= x1 || y0 >= y1) return;
    for (int ty = y0; ty < y1; ++ty)
        std::copy_n(d0_.begin() + std::ptrdiff_t(at(x0, ty)), x1 - x0, pyramid_.begin() + std::ptrdiff_t(ty) * subtiles_x_ + x0);
    for (int level = 1; level < int(levels_.size()); ++level)
        reduce_pyramid_cells(level, x0 >> level, ((x1 - 1) >> level) + 1, y0 >> level, ((y1 - 1) >> level) + 1);
}

void detail::BufferState::reduce_pyramid_rows(int level, int y_begin, int y_end) {
    reduce_pyramid_cells(level, 0, levels_[std::size_t(level)].width, y_begin, y_end);
}

void detail::BufferState::reduce_pyramid_cells(int level, int x_begin, int x_end, int y_begin, int y_end) {
    const detail::PyramidLevel& below = levels_[std::size_t(level) - 1];
    const detail::PyramidLevel& here = levels_[std::size_t(level)];
    for (int y = y_begin; y < y_end; ++y) {
        const float* row0 = pyramid_.data() + below.offset + std::size_t(2 * y) * std::size_t(below.width);
        const float* row1 = 2 * y + 1 < below.height ? row0 + below.width : row0;
        detail::reduce_min_row(row0, row1, x_begin, x_end, below.width, pyramid_.data() + here.offset + std::size_t(y) * std::size_t(here.width));
    }
}

void detail::BufferState::read_pyramid(std::vector<float>& cells) const {
    const detail::PyramidLevel& top = levels_.back();
    cells.assign(pyramid_.begin(), pyramid_.begin() + std::ptrdiff_t(top.offset + std::size_t(top.width) * std::size_t(top.height)));
}

detail::RasterTarget detail::BufferState::raster_target(int row_begin, int row_end) {
    const detail::SubtilePlanes planes{d0_.data(),
                                       d1_.data(),
                                       mask_.data(),
                                       covered_.data(),
                                       stride_,
                                       sample_depth_.empty() || deferred_sample_depth_ ? nullptr : sample_depth_.data(),
                                       sample_depth_stride_};
    return {planes,
            sample_width_,
            sample_height_,
            row_begin,
            row_end,
            kernels_->raster.rows,
            detail::hidden_skip_enabled(),
            kernels_->raster.hidden_test,
            deferred_sample_depth_ ? &depth_tiles_ : nullptr};
}

void detail::BufferState::build_changed_pyramid(bool cleared, const detail::ChangedSubtiles& changed) {
    if (cleared) build_pyramid_rows(0, subtiles_y_, int(levels_.size()) - 1);
    else build_pyramid_rect(changed.x0, changed.x1, changed.y0, changed.y1);
}

OcclusionBuffer::Subtile detail::BufferState::subtile(int tx, int ty) const {
    const std::size_t i = at(tx, ty);
    return {d0_[i], d1_[i], mask_[i], covered_[i]};
}

std::vector<OcclusionBuffer::Subtile> detail::BufferState::subtiles() const {
    std::vector<Subtile> all;
    all.reserve(std::size_t(subtiles_x_) * std::size_t(subtiles_y_));
    for (int ty = 0; ty < subtiles_y_; ++ty)
        for (int tx = 0; tx < subtiles_x_; ++tx) all.push_back(subtile(tx, ty));
    return all;
}

void detail::BufferState::read_coverage(std::vector<std::uint8_t>& covered) const {
    covered.assign(std::size_t(sample_width_) * std::size_t(sample_height_), 0);
    for (int y = 0; y < sample_height_; ++y)
        for (int x = 0; x < sample_width_; ++x) {
            const Subtile s = subtile(x / kW, y / kH);
            covered[std::size_t(y) * std::size_t(sample_width_) + std::size_t(x)] = (s.covered >> ((y % kH) * kW + x % kW)) & 1u;
        }
}

void detail::BufferState::read_depth(std::vector<float>& w) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    if (deferred_sample_depth_) detail::ensure_all_depth_units(depth_tiles_);
    w.assign(std::size_t(sample_width_) * std::size_t(sample_height_), INFINITY);
    for (int y = 0; y < sample_height_; ++y)
        for (int x = 0; x < sample_width_; ++x) {
            const Subtile s = subtile(x / kW, y / kH);
            const bool in_mask = (s.mask >> ((y % kH) * kW + x % kW)) & 1u;
            const std::size_t at = std::size_t(y) * std::size_t(sample_width_) + std::size_t(x);
            float d = in_mask ? std::max(s.d0, s.d1) : s.d0;
            if (!sample_depth_.empty()) d = std::max(d, sample_depth_[std::size_t(y) * sample_depth_stride_ + std::size_t(x)]);
            w[at] = d > 0.0f ? 1.0f / d : INFINITY;
        }
}

void detail::BufferState::read_sample_depth(std::vector<float>& d) const {
    d.clear();
    if (sample_depth_.empty()) return;
    if (deferred_sample_depth_) detail::ensure_all_depth_units(depth_tiles_);
    d.reserve(std::size_t(sample_width_) * std::size_t(sample_height_));
    for (int y = 0; y < sample_height_; ++y) {
        const auto row = sample_depth_.begin() + std::ptrdiff_t(std::size_t(y) * sample_depth_stride_);
        d.insert(d.end(), row, row + sample_width_);
    }
}

std::array<float, 16> clip_from_world(const Camera& camera, double aspect) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    return float_matrix(projection_matrix(camera, aspect) * view_matrix(camera));
}

std::array<float, 16> float_matrix(const glm::dmat4& m) {
    std::array<float, 16> out{};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[std::size_t(4 * c + r)] = float(m[c][r]);
    return out;
}

}  // namespace homcull
