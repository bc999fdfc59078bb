// detail::BufferState::render(ClusteredInput): clusters decided by their boxes, nearest first,
// band by band (see occlusion_buffer.hpp and occluder_clusters.hpp).
#include <homcull/error.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "buffer/rect_queries.hpp"
#include "buffer/render_bands.hpp"
#include "common/run_tasks.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_batch.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <new>
#include <string>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
constexpr std::size_t kClustersPerPlacementTask = 64;
using detail::kBandPyramidLevels;
using detail::kBandSubtileRows;

// A cluster as the triangle pipeline takes it: its own vertices, its local 16-bit indices.
TriangleInput cluster_input(const OccluderClusters& clusters, const OccluderCluster& c, const ClusteredInput& in, Backface backface) {
    TriangleInput t;
    t.positions = clusters.positions.data() + 3 * std::size_t(c.first_vertex);
    t.position_components = 3;
    t.position_stride = 3 * sizeof(float);
    t.vertex_count = c.vertex_count;
    t.indices = clusters.indices.data() + 3 * std::size_t(c.first_triangle);
    t.indices_16bit = true;
    t.triangle_count = c.triangle_count;
    t.model_to_clip = in.model_to_clip;
    t.backface = backface;
    t.orthographic = in.orthographic;
    t.shared_edges = (in.shared_edges ? in.shared_edges : clusters.shared_edges.data()) + c.first_triangle;
    t.edge_apexes = (in.shared_edges ? in.edge_apexes : clusters.edge_apexes.data()) + 3 * std::size_t(c.first_triangle);
    return t;
}

}  // namespace

// Runs in job-system tasks, which must not throw: every check that can fail stays in
// render_clusters' serial loop, before the tasks.
void detail::BufferState::place_cluster(const OccluderCluster& c, std::uint32_t number, const std::array<float, 16>& model_to_clip,
                                    Backface backface, ClusterPlace& out) const noexcept {
    out.fate = ClusterPlace::kInView;
    if (c.triangle_count == 0) {
        out.fate = ClusterPlace::kEmpty;
        return;
    }
    out.placed = {0.0f, number, 0, 0, sample_width_ - 1, 0, sample_height_ - 1, 0.0f, false, backface};  // untestable: every sample, no test
    ScreenRect rect;
    Visibility decided = Visibility::visible;
    detail::RectQuery q;
    if (c.bounded && detail::box_rectangle(*kernels_, &c.bounds.min.x, &c.bounds.max.x, model_to_clip, config_.near_w, config_.orthographic, rect,
                                              decided) &&
        prepare(rect.ndc_min_x, rect.ndc_min_y, rect.ndc_max_x, rect.ndc_max_y, rect.w_min, q, decided))
        out.placed = {rect.w_min, number, 0, q.i0, q.i1, q.j0, q.j1, q.d_near, true, backface};
    else if (decided != Visibility::visible)  // outside the view, or between sample centres
        out.fate = ClusterPlace::kOutside;
}

void detail::BufferState::render(const ClusteredInput& input, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    render_clusters(input, parallel, false);
}

void detail::BufferState::render_frame(const ClusteredInput& input, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    render_clusters(input, parallel, true);
}

std::size_t detail::BufferState::place_clusters(const ClusteredInput& in, const ParallelFor& parallel) {
    if (!in.clusters) throw Error("render: ClusteredInput::clusters is null");
    check_projection(in.orthographic, "render");
    const OccluderClusters& clusters = *in.clusters;
    if (in.shared_edges && !in.edge_apexes) throw Error("render: ClusteredInput::shared_edges needs edge_apexes");
    if (clusters.edge_apexes.size() != 3 * clusters.shared_edges.size())
        throw Error("render: OccluderClusters::edge_apexes must hold three per triangle (build_occluder_clusters makes them)");
    if (clusters.clusters.size() > std::size_t(UINT32_MAX)) throw Error("render: more than 2^32 - 1 clusters");

    // Every cluster is checked before anything is drawn (a render that throws changes nothing).
    const std::size_t count = in.cluster_ids ? in.cluster_count : clusters.clusters.size();
    for (std::size_t n = 0; n < count; ++n) {
        const std::size_t k = in.cluster_ids ? in.cluster_ids[n] : n;
        if (k >= clusters.clusters.size())
            throw Error("render: cluster number " + std::to_string(k) + " is not below the cluster count " +
                        std::to_string(clusters.clusters.size()));
        const OccluderCluster& c = clusters.clusters[k];
        if (std::size_t(c.first_vertex) + c.vertex_count > clusters.positions.size() / 3 ||
            std::size_t(c.first_triangle) + c.triangle_count > clusters.shared_edges.size() ||
            3 * (std::size_t(c.first_triangle) + c.triangle_count) > clusters.indices.size())
            throw Error("render: cluster " + std::to_string(k) + " reaches past the OccluderClusters' positions, indices or flags");
    }

    // Each cluster's box on the screen: its samples and nearest depth (the rectangle tests'
    // preparation, so that "hidden" means what test_aabb means by it), or outside the view. With
    // a job system, in tasks: the castle's 393 boxes took 0.04 ms of a 0.46 ms two-thread render.
    if (cluster_places_.size() < count) cluster_places_.resize(count);
    struct PlaceJob {
        detail::BufferState* self;
        const ClusteredInput* in;
        std::size_t count;
    } place_job{this, &in, count};
    const auto place_task = [](void* data, std::size_t task) {
        const PlaceJob& j = *static_cast<PlaceJob*>(data);
        const OccluderClusters& set = *j.in->clusters;
        for (std::size_t n = task * kClustersPerPlacementTask; n < std::min(j.count, (task + 1) * kClustersPerPlacementTask); ++n) {
            const std::size_t k = j.in->cluster_ids ? j.in->cluster_ids[n] : n;
            j.self->place_cluster(set.clusters[k], std::uint32_t(k), j.in->model_to_clip, j.in->backfaces ? j.in->backfaces[n] : j.in->backface,
                                  j.self->cluster_places_[n]);
        }
    };
    const std::size_t place_tasks = (count + kClustersPerPlacementTask - 1) / kClustersPerPlacementTask;
    detail::run_tasks(parallel, place_tasks, place_task, &place_job);
    return count;
}

// The draw's clusters in view (cluster_places_' first `count`), in input order, then nearest
// first, after those placed_clusters_ already holds; the others counted in `stats`. Allocates
// before it changes anything.
void detail::BufferState::append_placed(const ClusteredInput& in, std::size_t count, RasterStats& stats) {
    const auto room_for = [](auto& v, std::size_t more) {  // doubling: many small draws append in linear time
        if (v.capacity() < v.size() + more) v.reserve(std::max(v.size() + more, 2 * v.capacity()));
    };
    room_for(placed_clusters_, count);
    room_for(recorded_draws_, 1);
    const std::uint32_t draw = std::uint32_t(recorded_draws_.size());
    recorded_draws_.push_back(in);
    const std::size_t first = placed_clusters_.size();
    for (std::size_t n = 0; n < count; ++n) {
        ClusterPlace& place = cluster_places_[n];
        if (place.fate == ClusterPlace::kEmpty) continue;
        if (place.fate == ClusterPlace::kOutside) {
            ++stats.clusters_outside;
            continue;
        }
        place.placed.draw = draw;
        placed_clusters_.push_back(place.placed);
        const OccluderCluster& c = in.clusters->clusters[place.placed.cluster];
        task_list_vertices_ = std::max(task_list_vertices_, std::size_t(c.vertex_count));
    }
    std::sort(placed_clusters_.begin() + std::ptrdiff_t(first), placed_clusters_.end(), [](const PlacedCluster& a, const PlacedCluster& b) {
        return a.nearest_w < b.nearest_w || (a.nearest_w == b.nearest_w && a.cluster < b.cluster);
    });
}

// What the serial loop and the band tasks share: a band's rows, whether a band draws a cluster,
// a cluster's setup.
struct detail::BufferState::ClusterPass {
    detail::BufferState& b;
    detail::HiddenTestKernel hidden_test = b.kernels_->raster.hidden_test;
    detail::FrontEndKernels kernels = b.kernels_->raster.front_end;

    std::size_t plane() const { return b.task_list_vertices_ + detail::kVertexClipPadding; }
    // Scratch for one cluster's transformed vertices (triangle_batch.hpp's cache), one per band.
    detail::VertexClip cache(std::size_t band) const {
        double* clip = b.band_vertex_clip_.data() + band * 4 * plane();
        return detail::VertexClip{clip, clip + plane(), clip + 2 * plane(), clip + 3 * plane(), b.band_vertex_outcode_.data() + band * plane()};
    }
    void band_rows(std::size_t band, int& row_begin, int& row_end) const {
        row_begin = int(band) * kBandSubtileRows;
        row_end = std::min(row_begin + kBandSubtileRows, b.subtiles_y_);
    }
    // Whether a band draws a cluster (its box reaches the band and is not hidden there),
    // counting the answer in the band's statistics `stats`.
    bool draws(const PlacedCluster& p, std::size_t band, const detail::SubtilePlanes& planes, RasterStats& stats) const {
        int row_begin, row_end;
        band_rows(band, row_begin, row_end);
        int ty0, ty1;
        if (!detail::subtile_rows_within(p.j0, p.j1, row_begin, row_end, ty0, ty1)) return false;
        if (p.testable && hidden_test(planes, p.i0 / kW, p.i1 / kW, ty0, ty1, p.d_near)) {
            ++stats.cluster_bands_hidden;
            return false;
        }
        ++stats.cluster_bands_drawn;
        return true;
    }
    // No per-triangle hidden test in the setup (drawn_into null): the cluster's box just passed
    // one, and of its triangles fewer are hidden (on castle C0, 29 % against 65 % drawn as one
    // input), too few to pay for the test (0.729 -> 0.743 ms).
    template <typename Emit>
    void set_up(const PlacedCluster& p, const detail::VertexClip& cache, RasterStats& stats, Emit&& emit) const {
        const ClusteredInput& in = b.recorded_draws_[p.draw];
        const TriangleInput t = cluster_input(*in.clusters, in.clusters->clusters[p.cluster], in, p.backface);
        kernels.transform_vertices(t, double(b.config_.near_w), 0, t.vertex_count, cache);
        detail::setup_triangle_range(t, &cache, 0, t.triangle_count, b.config_.near_w, b.config_.edge_margin, b.sample_width_,
                                     b.sample_height_, nullptr, stats, kernels, emit);
    }
};

void detail::BufferState::render_clusters(const ClusteredInput& in, const ParallelFor& parallel, bool clear_first) {
    if (task_list_ != TaskList::none) throw Error("render: a task list is open (begin_tasks without finish_tasks)");
    if (parallel.run) {  // a task list of one draw, its tasks run by the job system
        begin_tasks(clear_first);
        try {
            record(in, parallel);
            // As many tasks as threads, each taking the next band from a counter: the longest
            // bands first (close_tasks), each thread one when it is free.
            struct Job {
                detail::BufferState* self;
                std::size_t tasks;
                std::atomic<std::size_t> next{0};
            } job{this, close_tasks()};
            const std::size_t takers = parallel.threads == 0 ? job.tasks : std::min(job.tasks, parallel.threads);
            detail::run_tasks(parallel, takers, [](void* data, std::size_t) {
                Job& j = *static_cast<Job*>(data);
                for (std::size_t i = j.next++; i < j.tasks; i = j.next++) j.self->run_task(i);
            }, &job);
        } catch (...) {
            finish_tasks(std::nothrow);  // what ran stays, with a pyramid to match
            throw;
        }
        finish_tasks();
        return;
    }

    // One thread: each cluster is set up once and rasterized in the runs of bands that draw it.
    // The statistics are the bands': its triangles' counts once per band drawing it.
    const std::size_t count = place_clusters(in, parallel);
    placed_clusters_.clear();
    recorded_draws_.clear();
    task_list_vertices_ = 0;
    RasterStats frame;
    append_placed(in, count, frame);
    const std::size_t bands = band_updated_.size();
    const ClusterPass pass{*this};
    if (band_vertex_clip_.size() < 4 * pass.plane()) band_vertex_clip_.resize(4 * pass.plane());
    if (band_vertex_outcode_.size() < pass.plane()) band_vertex_outcode_.resize(pass.plane());
    band_stats_.assign(bands, RasterStats{});
    if (clear_first) stats_ = RasterStats{};  // after every check and allocation: a render that throws changes nothing
    reference_cells_current_ = false;         // the noted renders' cells no longer hold d0

    if (clear_first) clear_rows(0, subtiles_y_);
    const detail::RasterTarget whole = raster_target(0, subtiles_y_);
    const detail::VertexClip cache = pass.cache(0);
    auto& runs = cluster_row_runs_;  // subtile rows [first, second)
    RasterStats serial;
    detail::ChangedSubtiles changed;
    for (const PlacedCluster& p : placed_clusters_) {
        runs.clear();
        std::uint64_t drawn = 0;
        for (std::size_t band = std::size_t(p.j0 / kH / kBandSubtileRows); band <= std::size_t(p.j1 / kH / kBandSubtileRows); ++band) {
            if (!pass.draws(p, band, whole.planes, band_stats_[band])) continue;
            ++drawn;
            int row_begin, row_end;
            pass.band_rows(band, row_begin, row_end);
            if (!runs.empty() && runs.back().second == row_begin) runs.back().second = row_end;
            else runs.emplace_back(row_begin, row_end);
        }
        if (runs.empty()) continue;
        RasterStats stats;
        pass.set_up(p, cache, stats, [&](const detail::RasterTriangle& tri) {
            detail::RasterTarget target = whole;
            for (const auto& [row_begin, row_end] : runs) {
                target.row_begin = row_begin, target.row_end = row_end;
                const std::uint64_t n = target.kernel(target, tri);
                serial.subtiles_updated += n;
                if (n != 0) changed.add(tri, subtiles_x_, subtiles_y_);
            }
        });
        for (std::uint64_t k = 0; k < drawn; ++k) serial += stats;
    }
    band_stats_[0] += serial;
    build_changed_pyramid(clear_first, changed);
    stats_ += frame;
    for (const RasterStats& s : band_stats_) stats_ += s;
}

// ---- Task lists ------------------------------------------------------------------------------

void detail::BufferState::begin_tasks(bool clear_first) {
    if (task_list_ != TaskList::none) throw Error("begin_tasks: a task list is already open (finish_tasks closes it)");
    task_list_ = TaskList::recording;
    task_list_clears_ = clear_first;
    task_list_stats_ = RasterStats{};
    task_list_vertices_ = 0;
    placed_clusters_.clear();
    recorded_draws_.clear();
}

void detail::BufferState::record(const ClusteredInput& draw, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;
    if (task_list_ != TaskList::recording) throw Error("record: no task list is recording (begin_tasks, then record before close_tasks)");
    const std::size_t count = place_clusters(draw, parallel);
    append_placed(draw, count, task_list_stats_);
}

std::size_t detail::BufferState::close_tasks() {
    if (task_list_ != TaskList::recording) throw Error("close_tasks: no task list is recording (begin_tasks first)");
    // Every allocation first (a close that throws leaves the list recording; finish_tasks drops it).
    const std::size_t bands = band_updated_.size();
    const ClusterPass pass{*this};
    std::size_t room = 0;
    for (const PlacedCluster& p : placed_clusters_) room += recorded_draws_[p.draw].clusters->clusters[p.cluster].triangle_count;
    room = std::min(room, kSetUpRoomTriangles);
    if (band_vertex_clip_.size() < bands * 4 * pass.plane()) band_vertex_clip_.resize(bands * 4 * pass.plane());
    if (band_vertex_outcode_.size() < bands * pass.plane()) band_vertex_outcode_.resize(bands * pass.plane());
    if (setup_triangles_.size() < room) setup_triangles_.resize(room);
    if (cluster_setups_.size() < placed_clusters_.size()) cluster_setups_.resize(placed_clusters_.size());
    band_stats_.assign(bands, RasterStats{});
    band_ran_.assign(bands, 0);
    band_order_.resize(bands);
    for (std::size_t band = 0; band < bands; ++band) band_order_[band] = std::uint32_t(band);
    std::sort(band_order_.begin(), band_order_.end(), [&](std::uint32_t a, std::uint32_t b) {  // std::stable_sort would allocate
        return band_seconds_[a] > band_seconds_[b] || (band_seconds_[a] == band_seconds_[b] && a < b);
    });

    // Each cluster's room in order while they fit (kSetUpRoomTriangles); the others are set up
    // by every band that draws them.
    std::size_t first = 0;
    for (std::size_t k = 0; k < placed_clusters_.size(); ++k) {
        const PlacedCluster& p = placed_clusters_[k];
        ClusterSetup& s = cluster_setups_[k];
        const std::size_t triangles = recorded_draws_[p.draw].clusters->clusters[p.cluster].triangle_count;
        const bool fits = first + triangles <= room;
        s.first = first, s.room = fits ? triangles : 0, s.count = 0;
        s.stats = RasterStats{};
        s.state.store(fits ? ClusterSetup::kNotSetUp : ClusterSetup::kEach, std::memory_order_relaxed);
        first += s.room;
    }
    if (task_list_clears_) stats_ = RasterStats{};
    reference_cells_current_ = false;  // the noted renders' cells no longer hold d0
    task_list_ = TaskList::closed;
    return bands;
}

// Task `index` draws the index-th longest band of the last task list (close_tasks' order): the
// bands cost what their rows hold, which moves little from frame to frame, and threads that take
// the tasks in turn then finish together (on castle view C0 the longest of the six bands took
// 30 % of the render, and taken last it left the other thread idle).
void detail::BufferState::run_task(std::size_t index) noexcept {
    if (task_list_ != TaskList::closed || index >= band_order_.size()) return;  // finish_tasks reports the bands that did not run
    run_band(band_order_[index]);
}

// Band `band` walks the clusters in order and decides on its own rows, as the serial loop does.
// A cluster is set up by the first band that comes to it, its triangles kept for the bands that
// come to it later; a band that comes to it while it is being set up sets up the next ones
// meanwhile, and only when there are none sets it up again for itself (as one that outgrows its
// room is). No bins, no task waits for another, and few clusters are set up twice.
void detail::BufferState::run_band(std::size_t band) noexcept {
    const auto start = std::chrono::steady_clock::now();
    const detail::StandardFloatMode mode;
    const ClusterPass pass{*this};
    int row_begin, row_end;
    pass.band_rows(band, row_begin, row_end);
    if (task_list_clears_) clear_rows(row_begin, row_end);
    const detail::RasterTarget target = raster_target(row_begin, row_end);
    const detail::VertexClip cache = pass.cache(band);
    // Counted here and stored once at the end: the bands' statistics lie side by side, and a
    // count per triangle in them would bounce their cache lines between the threads.
    RasterStats stats;
    const auto draw = [&](const detail::RasterTriangle& tri) { stats.subtiles_updated += target.kernel(target, tri); };
    // Sets cluster k up into its room if no band has claimed it: whether this band did. Its state
    // is read before the exchange: most clusters a band draws are set up already, and an exchange
    // would take the line from the thread that set it up.
    const auto claim_and_set_up = [&](std::size_t k) {
        ClusterSetup& s = cluster_setups_[k];
        int expected = s.state.load(std::memory_order_acquire);
        if (expected != ClusterSetup::kNotSetUp ||
            !s.state.compare_exchange_strong(expected, ClusterSetup::kSettingUp, std::memory_order_acquire))
            return false;
        std::size_t made = 0;
        pass.set_up(placed_clusters_[k], cache, s.stats, [&](const detail::RasterTriangle& tri) {
            if (made < s.room) setup_triangles_[s.first + made] = tri;
            ++made;
        });
        s.count = made;
        s.state.store(made <= s.room ? ClusterSetup::kReady : ClusterSetup::kEach, std::memory_order_release);
        return true;
    };
    // While another band sets cluster k up: one of the next clusters reaching this band's rows,
    // not claimed yet, set up meanwhile (the bands that share the horizon's clusters walk them in
    // the same order; waiting, the one behind idled at every cluster, and setting each up again
    // it did the work twice: castle C2, 13 to 19 of 40 clusters). Whether there was one.
    const auto set_up_ahead = [&](std::size_t k) {
        const std::size_t end = std::min(placed_clusters_.size(), k + 1 + kSetUpAheadClusters);
        for (std::size_t n = k + 1; n < end; ++n) {
            int ty0, ty1;
            const PlacedCluster& next = placed_clusters_[n];
            if (detail::subtile_rows_within(next.j0, next.j1, row_begin, row_end, ty0, ty1) && claim_and_set_up(n)) return true;
        }
        return false;
    };
    for (std::size_t k = 0; k < placed_clusters_.size(); ++k) {
        const PlacedCluster& p = placed_clusters_[k];
        if (!pass.draws(p, band, target.planes, stats)) continue;
        ClusterSetup& s = cluster_setups_[k];
        claim_and_set_up(k);
        int state = s.state.load(std::memory_order_acquire);
        while (state == ClusterSetup::kSettingUp && set_up_ahead(k)) state = s.state.load(std::memory_order_acquire);
        // Still being set up by another band (nothing left to set up meanwhile), or too large for
        // its room: set up here, drawn as it comes.
        if (state == ClusterSetup::kSettingUp || state == ClusterSetup::kEach) {
            RasterStats own;
            pass.set_up(p, cache, own, draw);
            stats += own;
            continue;
        }
        stats += s.stats;  // the setup's counts once per band that draws the cluster, as on one thread
        const detail::RasterTriangle* triangles = setup_triangles_.data() + s.first;
        for (std::size_t t = 0; t < s.count; ++t) {
            if (t + kPrefetchTriangles < s.count) prefetch_triangle(triangles[t + kPrefetchTriangles]);
            draw(triangles[t]);
        }
    }
    band_stats_[band] = stats;
    build_pyramid_rows(row_begin, row_end, std::min(kBandPyramidLevels, int(levels_.size()) - 1));
    band_ran_[band] = 1;
    band_seconds_[band] = std::chrono::duration<float>(std::chrono::steady_clock::now() - start).count();
}

std::size_t detail::BufferState::finish_tasks(std::nothrow_t) noexcept {
    if (task_list_ == TaskList::none) return 0;
    if (task_list_ == TaskList::recording) {  // nothing ran: the buffer is as it was
        task_list_ = TaskList::none;
        return band_updated_.size();
    }
    const ClusterPass pass{*this};
    std::size_t missing = 0;
    for (std::size_t band = 0; band < band_updated_.size(); ++band) {
        if (band < band_ran_.size() && band_ran_[band]) continue;
        ++missing;
        if (!task_list_clears_) continue;  // its rows, and their pyramid cells, are as they were
        int row_begin, row_end;  // a frame's rows hold none of the frame before
        pass.band_rows(band, row_begin, row_end);
        clear_rows(row_begin, row_end);
        build_pyramid_rows(row_begin, row_end, std::min(kBandPyramidLevels, int(levels_.size()) - 1));
    }
    reduce_pyramid_above_bands();
    stats_ += task_list_stats_;
    for (const RasterStats& s : band_stats_) stats_ += s;
    task_list_ = TaskList::none;
    return missing;
}

void detail::BufferState::finish_tasks() {
    if (task_list_ == TaskList::none) throw Error("finish_tasks: no task list is open");
    const bool closed = task_list_ == TaskList::closed;
    const std::size_t bands = band_updated_.size(), missing = finish_tasks(std::nothrow);
    if (!closed) throw Error("finish_tasks: the task list was not closed (close_tasks); nothing was drawn");
    if (missing != 0)
        throw Error("finish_tasks: " + std::to_string(missing) + " of the " + std::to_string(bands) +
                    " tasks did not run; the buffer holds those that did");
}

}  // namespace homcull
