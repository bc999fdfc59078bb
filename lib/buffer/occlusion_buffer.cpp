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
constexpr std::size_t kChunkTriangles = 2048;  // triangles set up per task
// A chunk's room for its set-up triangles: clipping at the near plane or the guard band may give
// a triangle more than one; a chunk that needs more sets up again in every band (render_binned).
constexpr std::size_t kChunkRoom = kChunkTriangles + kChunkTriangles / 8;
static_assert(kChunkRoom <= 65536, "a band's entries number a chunk's triangles in 16 bits");
// The chunks of the first wave of a render with a job system (render_binned); each later wave
// has twice as many chunks as the one before, up to kMaxWaveChunks, so that the room for a wave
// is bounded whatever the input: reserve sizes it once. S1 at 1080p, two threads: one wave
// 6.88 ms; a first wave of 2, 4 or 8 chunks 5.06, 5.07, 5.18 ms.
constexpr std::size_t kFirstWaveChunks = 4;
constexpr std::size_t kMaxWaveChunks = 32;
// One thread: the triangles set up between two refreshes of the reference cells of the rows
// drawn into (render_serial).
constexpr std::size_t kCellRefreshTriangles = 4096;
// A band reads its bins' triangles in order, but they were written by whichever thread set up
// their chunk, and a kernel call per triangle is too short for the hardware prefetcher to
// follow: they are prefetched this many triangles ahead (S1 at 1080p, two threads: 14.0 ->
// 13.2 ms; 2, 8 and 16 ahead were within noise of each other).
constexpr std::size_t kPrefetchTriangles = 8;

void prefetch_triangle(const detail::RasterTriangle& tri) {
    const char* bytes = reinterpret_cast<const char*>(&tri);
    for (std::size_t offset = 0; offset < sizeof tri; offset += 64) hwy::Prefetch(bytes + offset);
}

}  // namespace

// A chunk of the input in a wave of render_binned: its triangles set up once into its slot of
// wave_triangles_ (kChunkRoom each), and per band the numbers of those the band reaches, in
// order, in its slot of wave_entries_ (kChunkRoom per band: a band reaches each triangle at most
// once). Everything has a fixed size, so that the tasks never allocate. (Copying each triangle
// into a bin of every band it reaches reads better, castle C0 at 1080p on two threads 5 % faster,
// but needs room without bound, and the bins grew inside the tasks.)
struct detail::BufferState::Chunk {
    RasterStats stats;
    std::uint32_t count = 0;  // triangles set up into the room
    bool overflow = false;    // clipping gave more than kChunkRoom: every band sets the chunk up itself
};

// A part of a noted render's rows (draw_noted_part) and its scratch: room for a slice's
// undecided triangles, and its statistics.
struct detail::BufferState::NotedPart {
    detail::Vector<std::uint32_t> undecided;
    RasterStats stats;
    detail::ChangedSubtiles changed;  // the subtiles its render changed
    int row_begin = 0, row_end = 0;  // its subtile rows in the render under way
    bool drawn = false;              // its task ran (render_parts)
};

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
    z.bands = std::size_t((z.subtiles_y + kBandSubtileRows - 1) / kBandSubtileRows);
    z.levels = 1;
    std::size_t size = std::size_t(z.subtiles_x) * std::size_t(z.subtiles_y);
    for (int w = z.subtiles_x, h = z.subtiles_y; w > 1 || h > 1; ++z.levels) {
        w = (w + 1) / 2, h = (h + 1) / 2;
        size += std::size_t(w) * std::size_t(h);
    }
    z.pyramid = size + detail::kMaxSimdLanes;  // padded: RectScan loads whole vectors of a level's row
    z.cells_width = std::size_t(detail::reference_cells_width(z.subtiles_x));
    z.cells_height = std::size_t(detail::reference_cells_height(z.subtiles_y));
    z.cells = std::size_t(detail::kCellTables) * z.cells_width * z.cells_height;
    return z;
}

}  // namespace

// Room in the arrays whose size follows the configuration (reserve keeps their contents).
void detail::BufferState::reserve_arrays(const detail::BufferSizes& z) {
    d0_.reserve(z.plane), d1_.reserve(z.plane), mask_.reserve(z.plane), covered_.reserve(z.plane);
    sample_depth_.reserve(z.sample_depth);
    band_updated_.reserve(z.bands);
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
    band_updated_.assign(z.bands, 0);
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
    stats_ = RasterStats{};
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
        at_least(d.listed_notes, n);
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
    band_ran_.reserve(z.bands);
    cluster_row_runs_.reserve(z.bands);
    if (r.max_clusters > 0 || r.max_task_list_clusters > 0) {
        const std::size_t plane = r.max_cluster_vertices + detail::kVertexClipPadding;
        at_least(band_vertex_clip_, z.bands * 4 * plane);
        at_least(band_vertex_outcode_, z.bands * plane);
    }
    at_least(cluster_setups_, r.max_task_list_clusters);
    at_least(setup_triangles_, r.max_task_list_triangles);
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
    if (!sample_depth_.empty())
        zero(sample_depth_, std::size_t(row_begin * kH) * sample_depth_stride_,
             std::size_t(std::min(row_end * kH, sample_height_)) * sample_depth_stride_);
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
    for (int y = y_begin; y < y_end; ++y)
        for (int x = x_begin; x < x_end; ++x) {
            float m = min_d0(level - 1, 2 * x, 2 * y);
            if (2 * x + 1 < below.width) m = std::min(m, min_d0(level - 1, 2 * x + 1, 2 * y));
            if (2 * y + 1 < below.height) {
                m = std::min(m, min_d0(level - 1, 2 * x, 2 * y + 1));
                if (2 * x + 1 < below.width) m = std::min(m, min_d0(level - 1, 2 * x + 1, 2 * y + 1));
            }
            pyramid_[here.offset + std::size_t(y) * std::size_t(here.width) + std::size_t(x)] = m;
        }
}

void detail::BufferState::read_pyramid(std::vector<float>& cells) const {
    const detail::PyramidLevel& top = levels_.back();
    cells.assign(pyramid_.begin(), pyramid_.begin() + std::ptrdiff_t(top.offset + std::size_t(top.width) * std::size_t(top.height)));
}

detail::ReferenceCells detail::BufferState::start_reference_cells(bool clear_first, std::size_t part, int row_begin, int row_end,
                                                               bool cells_current) {
    const int height = detail::reference_cells_height(subtiles_y_);
    const std::size_t size = std::size_t(reference_cells_width_) * std::size_t(height);  // of the cells (table (0, 0))
    float* first = reference_cells_.data() + part * std::size_t(detail::kCellTables) * size;
    const detail::ReferenceCells cells{first, reference_cells_width_, height};
    const std::size_t width = std::size_t(reference_cells_width_);
    const std::size_t own_begin = std::size_t(row_begin >> detail::kReferenceCellShift) * width;
    const std::size_t own_end = std::min(size, std::size_t(((row_end - 1) >> detail::kReferenceCellShift) + 1) * width);
    // One part over every row, and the cells still those the last noted render on one thread
    // left (nothing else drew since): they are this buffer's, as a refresh would compute them.
    if (cells_current && !clear_first && part == 0 && row_begin == 0 && row_end == subtiles_y_) return cells;
    std::fill(first, first + own_begin, std::numeric_limits<float>::infinity());
    std::fill(first + own_end, first + size, std::numeric_limits<float>::infinity());
    if (clear_first) {
        std::fill(first + own_begin, first + own_end, 0.0f);  // d0 >= 0 everywhere
    } else {
        const detail::SubtilePlanes planes{d0_.data(), d1_.data(), mask_.data(), covered_.data(), stride_, nullptr, 0};
        kernels_->raster.refresh_cells(planes, subtiles_x_, subtiles_y_, int(own_begin / width), int(own_end / width), cells);
    }
    detail::update_cell_blocks(cells, 0, height);  // every row: the infinite ones too
    return cells;
}

void detail::BufferState::refresh_reference_cells(const detail::ReferenceCells& cells, int row_begin, int row_end) {
    if (!cells.min_d0 || row_begin >= row_end) return;
    const detail::SubtilePlanes planes{d0_.data(), d1_.data(), mask_.data(), covered_.data(), stride_, nullptr, 0};
    const int cell_row_begin = row_begin >> detail::kReferenceCellShift, cell_row_end = ((row_end - 1) >> detail::kReferenceCellShift) + 1;
    kernels_->raster.refresh_cells(planes, subtiles_x_, subtiles_y_, cell_row_begin, cell_row_end, cells);
    detail::update_cell_blocks(cells, cell_row_begin, cell_row_end);
}

detail::RasterTarget detail::BufferState::raster_target(int row_begin, int row_end) {
    const detail::SubtilePlanes planes{d0_.data(),
                                       d1_.data(),
                                       mask_.data(),
                                       covered_.data(),
                                       stride_,
                                       sample_depth_.empty() ? nullptr : sample_depth_.data(),
                                       sample_depth_stride_};
    return {planes, sample_width_, sample_height_, row_begin, row_end, kernels_->raster.rows, detail::hidden_skip_enabled(), kernels_->raster.hidden_test};
}

bool detail::BufferState::transform_vertices(const TriangleInput& in, const ParallelFor& parallel, detail::VertexClip& cache) {
    if (!detail::use_vertex_cache(in)) return false;
    const std::size_t plane = in.vertex_count + detail::kVertexClipPadding;
    if (vertex_clip_.size() < 4 * plane) vertex_clip_.resize(4 * plane);
    if (vertex_outcode_.size() < in.vertex_count) vertex_outcode_.resize(in.vertex_count);
    double* planes = vertex_clip_.data();
    cache = {planes, planes + plane, planes + 2 * plane, planes + 3 * plane, vertex_outcode_.data()};
    const detail::TransformVerticesKernel transform = kernels_->raster.front_end.transform_vertices;
    constexpr std::size_t kVerticesPerTask = 16384;
    // The kernel stores whole vectors (up to 8 vertices) past a task's end: only the last task
    // may have a partial vector, into the cache's padding, never into the next task's vertices.
    static_assert(kVerticesPerTask % detail::kVertexClipPadding == 0, "tasks of whole vectors");
    const std::size_t tasks = (in.vertex_count + kVerticesPerTask - 1) / kVerticesPerTask;
    struct Job {
        const TriangleInput* in;
        const detail::VertexClip* cache;
        detail::TransformVerticesKernel transform;
        double near_w;
    } job{&in, &cache, transform, double(config_.near_w)};
    const auto task = [](void* data, std::size_t k) {
        const Job& j = *static_cast<Job*>(data);
        j.transform(*j.in, j.near_w, k * kVerticesPerTask, std::min(j.in->vertex_count, (k + 1) * kVerticesPerTask), *j.cache);
    };
    detail::run_tasks(parallel, tasks, task, &job);
    return true;
}

void detail::BufferState::render(const TriangleInput& in, const ParallelFor& parallel) {
    if (in.triangle_count == 0) return;
    const detail::StandardFloatMode mode;  // float_mode.hpp
    render_rows(in, parallel, false);
}

void detail::BufferState::render_frame(const TriangleInput& in, const ParallelFor& parallel) {
    if (in.triangle_count == 0) {
        clear();
        return;
    }
    const detail::StandardFloatMode mode;  // float_mode.hpp
    render_rows(in, parallel, true);
}

void detail::BufferState::render_rows(const TriangleInput& in, const ParallelFor& parallel, bool clear_first) {
    detail::check_triangle_input(in, "render");
    check_projection(in.orthographic, "render");
    detail::check_draw_order(in);
    if (in.shared_edges && !in.edge_apexes)
        throw Error("render: shared_edges needs edge_apexes (compute_shared_edges writes both): each flag is kept only where its "
                    "neighbour lies across the edge in this view");
    if (clear_first) stats_ = RasterStats{};
    detail::VertexClip storage;
    const detail::VertexClip* cache = transform_vertices(in, parallel, storage) ? &storage : nullptr;
    // Nearest first (TriangleInput::order): the sorted copy has the same vertices, so the cache
    // serves it too.
    if (!draw_order_) draw_order_ = detail::make_hooked<detail::DrawOrderScratch>();
    TriangleInput sorted;
    detail::DrawList list;  // the order as a list of numbers, when the input allows (one thread, or a clip-space soup)
    RasterStats skipped;    // the triangles the sort leaves out (with a vertex cache)
    // Cell records with the list of a clip-space soup, when the buffer keeps cells and they fit a byte.
    const detail::CellRecordSpec record_spec{sample_width_, sample_height_, reference_cells_width_,
                                             detail::reference_cells_height(subtiles_y_), config_.near_w, in.backface};
    const bool note = detail::hidden_skip_enabled() && kernels_->raster.refresh_cells &&
                      record_spec.cells_width <= detail::kMaxNotedCellsPerSide && record_spec.cells_height <= detail::kMaxNotedCellsPerSide;
    const TriangleInput& drawn = detail::sort_nearest_first(kernels_->raster, in, cache, config_.near_w, parallel, *draw_order_, sorted, &list, &skipped,
                                                            note ? &record_spec : nullptr, !parallel.run)
                                     ? sorted
                                     : in;
    stats_ += skipped;
    if (parallel.run && list.notes) render_parts(drawn, parallel, clear_first, list);
    else if (parallel.run) render_binned(drawn, parallel, cache, clear_first);
    else render_serial(drawn, cache, clear_first, list);
}

// One thread: each triangle is rasterized over the whole buffer as soon as it is set up, in
// input order; nothing is binned. Every subtile sees the triangles in the same order as in
// render_binned and render_parts, so all give the same bits. With cell records (a clip-space
// soup drawn nearest first, reference_cells.hpp), the buffer is one part (draw_noted_part).
void detail::BufferState::render_serial(const TriangleInput& in, const detail::VertexClip* cache, bool clear_first, detail::DrawList list) {
    if (list.notes) {
        if (noted_parts_.empty()) noted_parts_.resize(1);
        if (noted_parts_[0].undecided.size() < kCellRefreshTriangles) noted_parts_[0].undecided.resize(kCellRefreshTriangles);
        // Not current while the cells are being changed (should the render stop half-way).
        const bool cells_current = std::exchange(reference_cells_current_, false);
        draw_noted_part(in, list, clear_first, 0, 0, subtiles_y_, cells_current);
        // Every slice refreshed the cells of the rows it changed: they hold the buffer's d0 now,
        // and the next noted render on one thread starts from them.
        reference_cells_current_ = true;
        stats_ += noted_parts_[0].stats;
        build_changed_pyramid(clear_first, noted_parts_[0].changed);
        return;
    }
    reference_cells_current_ = false;
    if (clear_first) clear_rows(0, subtiles_y_);
    const detail::RasterTarget target = raster_target(0, subtiles_y_);
    std::uint64_t updated = 0;
    RasterStats stats;
    detail::ChangedSubtiles changed;
    detail::setup_triangle_range(in, cache, 0, in.triangle_count, config_.near_w, config_.edge_margin, sample_width_, sample_height_, &target,
                                 stats, kernels_->raster.front_end, [&](const detail::RasterTriangle& tri) {
                                     const std::uint64_t n = target.kernel(target, tri);
                                     updated += n;
                                     if (n != 0) changed.add(tri, subtiles_x_, subtiles_y_);
                                 }, list);
    stats.subtiles_updated = updated;
    stats_ += stats;
    build_changed_pyramid(clear_first, changed);
}

void detail::BufferState::build_changed_pyramid(bool cleared, const detail::ChangedSubtiles& changed) {
    if (cleared) build_pyramid_rows(0, subtiles_y_, int(levels_.size()) - 1);
    else build_pyramid_rect(changed.x0, changed.x1, changed.y0, changed.y1);
}

// The list is taken in slices of kCellRefreshTriangles: a noted triangle hidden behind the
// part's cells (every noted triangle outside its rows, whose cells are infinite) is dropped
// unread, the others go through the setup and are drawn into the part's rows, and the cells of
// the rows the slice changed are refreshed after it. Every part counts the triangles it drops
// as the setup counts a hidden one (triangles_in and rasterized), and the setup counts the
// others as it would for the whole buffer (a triangle outside the target's rows is hidden
// there): so each part's statistics are the whole render's, but for subtiles_updated.
void detail::BufferState::draw_noted_part(const TriangleInput& in, detail::DrawList list, bool clear_first, std::size_t part, int row_begin,
                                      int row_end, bool cells_current) {
    NotedPart& scratch = noted_parts_[part];
    scratch.drawn = true;
    scratch.changed = {};
    if (clear_first) clear_rows(row_begin, row_end);
    const detail::RasterTarget target = raster_target(row_begin, row_end);
    const detail::ReferenceCells cells = start_reference_cells(clear_first, part, row_begin, row_end, cells_current);
    RasterStats stats;
    int changed_begin = row_end, changed_end = row_begin;  // the subtile rows changed since the last refresh
    // The triangles drawn per cell row of the part, counted here and copied out at the end: the
    // parts' counts share cache lines of cell_row_load_.
    const int first_cell_row = row_begin >> detail::kReferenceCellShift, cell_row_end = ((row_end - 1) >> detail::kReferenceCellShift) + 1;
    std::uint32_t load[detail::kMaxNotedCellsPerSide] = {};  // a noted render's buffer has at most that many cell rows
    const auto draw = [&](const detail::RasterTriangle& tri) {
        const std::uint64_t n = target.kernel(target, tri);
        stats.subtiles_updated += n;
        const int first_row = std::max(row_begin, tri.j0 / kH);
        ++load[(first_row >> detail::kReferenceCellShift) - first_cell_row];
        if (n != 0) {
            scratch.changed.add(tri, subtiles_x_, subtiles_y_);
            changed_begin = std::min(changed_begin, first_row);
            changed_end = std::max(changed_end, std::min(row_end, tri.j1 / kH + 1));
        }
    };
    for (std::size_t begin = 0; begin < in.triangle_count; begin += kCellRefreshTriangles) {
        const std::size_t end = std::min(in.triangle_count, begin + kCellRefreshTriangles);
        detail::setup_noted_range(in, cells, list, begin, end, scratch.undecided.data(), config_.near_w, config_.edge_margin, sample_width_,
                                  sample_height_, &target, stats, kernels_->raster.front_end, kernels_->raster.drop_hidden, draw);
        refresh_reference_cells(cells, changed_begin, changed_end);
        changed_begin = row_end, changed_end = row_begin;
    }
    std::copy(load, load + (cell_row_end - first_cell_row), cell_row_load_.begin() + first_cell_row);
    scratch.stats = stats;
}

// With a job system and cell records: the rows split into parts, one task each, every part
// drawing the whole list into its own rows with its own cells (draw_noted_part). Nothing is
// binned and there is one parallel run: the noted triangles outside a part cost it a note
// read, and a triangle reaching two parts is set up by both. The bounds lie on cell rows,
// placed so that each part drew about as many triangles in the last noted render (equal rows
// the first time); they change no bit, only the balance. Part 0's statistics are the render's.
// S1 at 1080p, two threads: 4.30 -> 3.02 ms against render_binned's waves (see
// docs/occlusion-buffer.md, "Threads").
void detail::BufferState::render_parts(const TriangleInput& in, const ParallelFor& parallel, bool clear_first, detail::DrawList list) {
    reference_cells_current_ = false;  // each part's copy has the other parts' rows infinite
    const int cell_rows = detail::reference_cells_height(subtiles_y_);
    const std::size_t parts = std::min(parallel.threads ? parallel.threads : 2, std::size_t(cell_rows));  // cell_rows >= 1
    const std::size_t cells_size = std::size_t(detail::kCellTables) * std::size_t(reference_cells_width_) * std::size_t(cell_rows);
    if (reference_cells_.size() < parts * cells_size) reference_cells_.resize(parts * cells_size);
    if (noted_parts_.size() < parts) noted_parts_.resize(parts);
    for (std::size_t p = 0; p < parts; ++p) {
        NotedPart& part = noted_parts_[p];
        if (part.undecided.size() < kCellRefreshTriangles) part.undecided.resize(kCellRefreshTriangles);
        part.drawn = false;
    }
    // The bounds: part p ends at the first cell row where the load so far reaches (p + 1) / parts
    // of the total, leaving each part at least one row.
    std::uint64_t total = 0;
    for (const std::uint32_t load : cell_row_load_) total += load;
    int cell_row = 0;
    std::uint64_t load_so_far = 0;
    for (std::size_t p = 0; p < parts; ++p) {
        NotedPart& part = noted_parts_[p];
        part.row_begin = cell_row << detail::kReferenceCellShift;
        const int rows_left_for_others = int(parts - p - 1);
        if (p + 1 == parts) {
            cell_row = cell_rows;
        } else if (total == 0) {
            cell_row = int((p + 1) * std::size_t(cell_rows) / parts);
        } else {
            do load_so_far += cell_row_load_[std::size_t(cell_row++)];
            while (cell_row < cell_rows - rows_left_for_others && load_so_far * parts < (p + 1) * total);
        }
        part.row_end = std::min(subtiles_y_, cell_row << detail::kReferenceCellShift);
    }
    std::fill(cell_row_load_.begin(), cell_row_load_.end(), 0u);

    struct Job {
        detail::BufferState* self;
        const TriangleInput* in;
        detail::DrawList list;
        bool clear_first;
    } job{this, &in, list, clear_first};
    try {
        detail::run_tasks(parallel, parts, [](void* data, std::size_t p) {
            const Job& j = *static_cast<Job*>(data);
            detail::BufferState& b = *j.self;
            const NotedPart& part = b.noted_parts_[p];
            b.draw_noted_part(*j.in, j.list, j.clear_first, p, part.row_begin, part.row_end);
            b.build_pyramid_rows(part.row_begin, part.row_end, std::min(detail::kReferenceCellShift, int(b.levels_.size()) - 1));
        }, &job);
    } catch (...) {
        // The job system failed (the tasks themselves allocate nothing and do not throw): the
        // parts it ran are drawn. The rows of the others still hold what was there before; in
        // a render_frame that was the frame before, which must not hide anything of this one:
        // they are cleared. The pyramid is rebuilt to match; the statistics count no part.
        for (std::size_t p = 0; p < parts; ++p)
            if (clear_first && !noted_parts_[p].drawn) clear_rows(noted_parts_[p].row_begin, noted_parts_[p].row_end);
        build_pyramid_rows(0, subtiles_y_, int(levels_.size()) - 1);
        throw;
    }
    // Above the parts' levels (their bounds are multiples of 2^kReferenceCellShift rows).
    for (int level = detail::kReferenceCellShift + 1; level < int(levels_.size()); ++level)
        reduce_pyramid_rows(level, 0, levels_[std::size_t(level)].height);
    stats_ += noted_parts_[0].stats;
    for (std::size_t p = 1; p < parts; ++p) stats_.subtiles_updated += noted_parts_[p].stats.subtiles_updated;
}

// Room for waves of `slots` chunks over `bands` bands (render_binned), kept when it is enough.
void detail::BufferState::reserve_waves(std::size_t slots, std::size_t bands) {
    if (chunks_.size() < slots) chunks_.resize(slots);
    if (wave_triangles_.size() < slots * kChunkRoom) wave_triangles_.resize(slots * kChunkRoom);
    if (wave_entry_counts_.size() < slots * bands) wave_entry_counts_.resize(slots * bands);
    if (wave_entries_.size() < slots * bands * kChunkRoom) wave_entries_.resize(slots * bands * kChunkRoom);
}

// With a job system, the triangles go in waves of chunks: in each, phase 1 sets up and bins
// the wave's chunks in parallel, then phase 2 rasterizes bands of subtile rows in parallel,
// each band its triangles in input order. The first wave is small and the waves double: drawn
// nearest first, the first waves fill most of the buffer, and phase 1 of the later ones drops
// the triangles already hidden in it before their edges are set up and they are binned
// (hidden_in_target, as on one thread). Dropping them changes no bit, so the waves' sizes are
// free; only the speed depends on them. (A clip-space soup with cell records goes to
// render_parts instead.) The waves' room is allocated here, on the calling thread, when a
// reserve did not: the tasks allocate nothing.
void detail::BufferState::render_binned(const TriangleInput& in, const ParallelFor& parallel, const detail::VertexClip* cache, bool clear_first) {
    reference_cells_current_ = false;
    const std::size_t chunk_count = (in.triangle_count + kChunkTriangles - 1) / kChunkTriangles;
    const std::size_t bands = band_updated_.size();
    reserve_waves(std::min(chunk_count, kMaxWaveChunks), bands);
    std::fill(band_updated_.begin(), band_updated_.end(), std::uint64_t(0));

    struct Job {
        detail::BufferState* self;
        const TriangleInput* in;
        const detail::VertexClip* cache;
        std::size_t first_chunk, end_chunk, bands;
        const detail::RasterTarget* drawn_into;  // phase 1's: the whole buffer, or null while nothing is drawn
        bool clear_first, last_wave;
    };
    const detail::RasterTarget whole = raster_target(0, subtiles_y_);
    std::size_t drawn_chunks = 0;  // the chunks of the waves drawn so far
    try {
        // At least one wave, so that render_frame clears and builds the pyramid whatever the count.
        for (std::size_t first = 0, wave_chunks = kFirstWaveChunks; first == 0 || first < chunk_count;
             first += wave_chunks, wave_chunks = std::min(2 * wave_chunks, kMaxWaveChunks)) {
            const std::size_t end = std::min(chunk_count, first + wave_chunks);
            const bool nothing_drawn = first == 0 && clear_first;  // the buffer still holds the last frame
            Job job{this, &in, cache, first, end, bands, nothing_drawn ? nullptr : &whole, first == 0 && clear_first, end == chunk_count};

            detail::run_tasks(parallel, end - first, [](void* data, std::size_t slot) {
                const Job& j = *static_cast<Job*>(data);
                detail::BufferState& b = *j.self;
                const std::size_t c = j.first_chunk + slot;
                Chunk& chunk = b.chunks_[slot];
                chunk = Chunk{};
                detail::RasterTriangle* room = b.wave_triangles_.data() + slot * kChunkRoom;
                std::uint16_t* counts = b.wave_entry_counts_.data() + slot * j.bands;
                std::uint16_t* entries = b.wave_entries_.data() + slot * j.bands * kChunkRoom;
                std::fill(counts, counts + j.bands, std::uint16_t(0));
                const auto bin = [&](const detail::RasterTriangle& tri) {
                    if (chunk.count == kChunkRoom) {
                        chunk.overflow = true;  // the setup goes on, for the statistics
                        return;
                    }
                    room[chunk.count] = tri;
                    for (int band = tri.j0 / (kH * kBandSubtileRows); band <= tri.j1 / (kH * kBandSubtileRows); ++band)
                        entries[std::size_t(band) * kChunkRoom + counts[band]++] = std::uint16_t(chunk.count);
                    ++chunk.count;
                };
                const std::size_t end_triangle = std::min(j.in->triangle_count, (c + 1) * kChunkTriangles);
                detail::setup_triangle_range(*j.in, j.cache, c * kChunkTriangles, end_triangle, b.config_.near_w, b.config_.edge_margin,
                                             b.sample_width_, b.sample_height_, j.drawn_into, chunk.stats, b.kernels_->raster.front_end, bin);
            }, &job);

            detail::run_tasks(parallel, bands, [](void* data, std::size_t band) {
                const Job& j = *static_cast<Job*>(data);
                detail::BufferState& b = *j.self;
                const int row_begin = int(band) * kBandSubtileRows, row_end = std::min(row_begin + kBandSubtileRows, b.subtiles_y_);
                if (j.clear_first) b.clear_rows(row_begin, row_end);
                const detail::RasterTarget target = b.raster_target(row_begin, row_end);
                std::uint64_t updated = 0;
                for (std::size_t slot = 0; slot < j.end_chunk - j.first_chunk; ++slot) {
                    const Chunk& chunk = b.chunks_[slot];
                    if (chunk.overflow) {
                        // The same triangles in the same order as the room would have held.
                        const std::size_t c = j.first_chunk + slot;
                        RasterStats ignored;
                        detail::setup_triangle_range(*j.in, j.cache, c * kChunkTriangles, std::min(j.in->triangle_count, (c + 1) * kChunkTriangles),
                                                     b.config_.near_w, b.config_.edge_margin, b.sample_width_, b.sample_height_, nullptr,
                                                     ignored, b.kernels_->raster.front_end, [&](const detail::RasterTriangle& tri) {
                                                         if (tri.j0 < row_end * kH && tri.j1 >= row_begin * kH) updated += target.kernel(target, tri);
                                                     });
                        continue;
                    }
                    const detail::RasterTriangle* room = b.wave_triangles_.data() + slot * kChunkRoom;
                    const std::size_t count = b.wave_entry_counts_[slot * j.bands + band];
                    const std::uint16_t* entries = b.wave_entries_.data() + (slot * j.bands + band) * kChunkRoom;
                    for (std::size_t k = 0; k < count; ++k) {
                        if (k + kPrefetchTriangles < count) prefetch_triangle(room[entries[k + kPrefetchTriangles]]);
                        updated += target.kernel(target, room[entries[k]]);
                    }
                }
                b.band_updated_[band] += updated;
                if (j.last_wave) b.build_pyramid_rows(row_begin, row_end, std::min(kBandPyramidLevels, int(b.levels_.size()) - 1));
            }, &job);
            for (std::size_t slot = 0; slot < end - first; ++slot) stats_ += chunks_[slot].stats;
            drawn_chunks = end;
        }
    } catch (...) {
        // The job system failed (input errors throw before any wave, and the tasks allocate
        // nothing). After the first wave, the buffer keeps the waves drawn, a partial but
        // conservative render, with their statistics. Before that some bands may still hold
        // the frame before, which must not hide anything of this one: a render_frame then
        // leaves the buffer clear. Either way the pyramid is rebuilt to match, so that no test
        // reads a pyramid of the frame before.
        if (clear_first && drawn_chunks == 0) clear_rows(0, subtiles_y_);
        else for (std::uint64_t updated : band_updated_) stats_.subtiles_updated += updated;
        build_pyramid_rows(0, subtiles_y_, int(levels_.size()) - 1);
        throw;
    }
    reduce_pyramid_above_bands();
    for (std::uint64_t updated : band_updated_) stats_.subtiles_updated += updated;
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
