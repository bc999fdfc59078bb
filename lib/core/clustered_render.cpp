// OcclusionBuffer::render(ClusteredInput): clusters decided by their boxes, nearest first,
// band by band (see occlusion_buffer.hpp and occluder_clusters.hpp).
#include <homcull/error.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "core/rect_tests.hpp"
#include "core/render_bands.hpp"
#include "core/run_tasks.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_batch.hpp"

#include <algorithm>
#include <string>
#include <thread>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
constexpr std::size_t kClustersPerPlacementTask = 64;
using detail::kBandPyramidLevels;
using detail::kBandSubtileRows;

// A cluster as the triangle pipeline takes it: its own vertices, its local 16-bit indices.
TriangleInput cluster_input(const OccluderClusters& clusters, const OccluderCluster& c, const ClusteredInput& in) {
    TriangleInput t;
    t.positions = clusters.positions.data() + 3 * std::size_t(c.first_vertex);
    t.position_components = 3;
    t.position_stride = 3 * sizeof(float);
    t.vertex_count = c.vertex_count;
    t.indices = clusters.indices.data() + 3 * std::size_t(c.first_triangle);
    t.indices_16bit = true;
    t.triangle_count = c.triangle_count;
    t.model_to_clip = in.model_to_clip;
    t.backface = in.backface;
    t.shared_edges = (in.shared_edges ? in.shared_edges : clusters.shared_edges.data()) + c.first_triangle;
    t.edge_apexes = (in.shared_edges ? in.edge_apexes : clusters.edge_apexes.data()) + 3 * std::size_t(c.first_triangle);
    return t;
}

}  // namespace

// Runs in job-system tasks, which must not throw: every check that can fail stays in
// render_clusters' serial loop, before the tasks.
void OcclusionBuffer::place_cluster(const OccluderCluster& c, std::uint32_t number, const std::array<float, 16>& model_to_clip,
                                    ClusterPlace& out) const noexcept {
    out.fate = ClusterPlace::kInView;
    if (c.triangle_count == 0) {
        out.fate = ClusterPlace::kEmpty;
        return;
    }
    out.placed = {0.0f, number, 0, sample_width_ - 1, 0, sample_height_ - 1, 0.0f, false};  // untestable: every sample, no test
    ScreenRect rect;
    Visibility decided = Visibility::visible;
    detail::RectQuery q;
    if (c.bounded && detail::box_rectangle(&c.bounds.min.x, &c.bounds.max.x, model_to_clip, config_.near_w, rect, decided) &&
        prepare(rect.ndc_min_x, rect.ndc_min_y, rect.ndc_max_x, rect.ndc_max_y, rect.w_min, q, decided))
        out.placed = {rect.w_min, number, q.i0, q.i1, q.j0, q.j1, q.d_near, true};
    else if (decided != Visibility::visible)  // outside the view, or between sample centres
        out.fate = ClusterPlace::kOutside;
}

void OcclusionBuffer::render(const ClusteredInput& input, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    render_clusters(input, parallel, false);
}

void OcclusionBuffer::render_frame(const ClusteredInput& input, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    render_clusters(input, parallel, true);
}

void OcclusionBuffer::render_clusters(const ClusteredInput& in, const ParallelFor& parallel, bool clear_first) {
    if (!in.clusters) throw Error("render: ClusteredInput::clusters is null");
    const OccluderClusters& clusters = *in.clusters;
    if (in.shared_edges && !in.edge_apexes) throw Error("render: ClusteredInput::shared_edges needs edge_apexes");
    if (clusters.edge_apexes.size() != 3 * clusters.shared_edges.size())
        throw Error("render: OccluderClusters::edge_apexes must hold three per triangle (build_occluder_clusters makes them)");

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
        OcclusionBuffer* self;
        const ClusteredInput* in;
        std::size_t count;
    } place_job{this, &in, count};
    const auto place_task = [](void* data, std::size_t task) {
        const PlaceJob& j = *static_cast<PlaceJob*>(data);
        const OccluderClusters& set = *j.in->clusters;
        for (std::size_t n = task * kClustersPerPlacementTask; n < std::min(j.count, (task + 1) * kClustersPerPlacementTask); ++n) {
            const std::size_t k = j.in->cluster_ids ? j.in->cluster_ids[n] : n;
            j.self->place_cluster(set.clusters[k], std::uint32_t(k), j.in->model_to_clip, j.self->cluster_places_[n]);
        }
    };
    const std::size_t place_tasks = (count + kClustersPerPlacementTask - 1) / kClustersPerPlacementTask;
    detail::run_tasks(parallel, place_tasks, place_task, &place_job);

    // The clusters in view, in input order, then nearest first.
    placed_clusters_.clear();
    RasterStats frame;
    std::size_t most_vertices = 0, most_triangles = 0;  // of the clusters in view: the scratch below holds them
    for (std::size_t n = 0; n < count; ++n) {
        const ClusterPlace& place = cluster_places_[n];
        if (place.fate == ClusterPlace::kEmpty) continue;
        if (place.fate == ClusterPlace::kOutside) {
            ++frame.clusters_outside;
            continue;
        }
        placed_clusters_.push_back(place.placed);
        const OccluderCluster& c = clusters.clusters[place.placed.cluster];
        most_vertices = std::max(most_vertices, std::size_t(c.vertex_count));
        most_triangles = std::max(most_triangles, std::size_t(c.triangle_count));
    }
    std::sort(placed_clusters_.begin(), placed_clusters_.end(), [](const PlacedCluster& a, const PlacedCluster& b) {
        return a.nearest_w < b.nearest_w || (a.nearest_w == b.nearest_w && a.cluster < b.cluster);
    });

    // Scratch for one cluster's transformed vertices (triangle_batch.hpp's cache), one per band.
    const std::size_t bands = band_updated_.size();
    const std::size_t plane = most_vertices + detail::kVertexClipPadding;
    if (band_vertex_clip_.size() < bands * 4 * plane) band_vertex_clip_.resize(bands * 4 * plane);
    if (band_vertex_outcode_.size() < bands * plane) band_vertex_outcode_.resize(bands * plane);
    band_stats_.assign(bands, RasterStats{});
    if (parallel.run) {  // each cluster in view: a slot for its set-up triangles
        while (cluster_setups_.size() < placed_clusters_.size()) cluster_setups_.push_back(detail::make_hooked<ClusterSetup>());
        for (std::size_t k = 0; k < placed_clusters_.size(); ++k) {
            cluster_setups_[k]->state.store(ClusterSetup::kNotSetUp, std::memory_order_relaxed);
            // Room for a cluster's triangles (clipped fans may still add some): after the first
            // frames, the band tasks allocate nothing.
            cluster_setups_[k]->triangles.reserve(most_triangles);
        }
    }
    if (clear_first) stats_ = RasterStats{};  // after every check and allocation: a render that throws changes nothing
    reference_cells_current_ = false;  // the noted renders' cells no longer hold d0
    const auto cache_of = [&](std::size_t band) {
        double* clip = band_vertex_clip_.data() + band * 4 * plane;
        return detail::VertexClip{clip, clip + plane, clip + 2 * plane, clip + 3 * plane, band_vertex_outcode_.data() + band * plane};
    };
    const auto band_rows = [&](std::size_t band, int& row_begin, int& row_end) {
        row_begin = int(band) * kBandSubtileRows;
        row_end = std::min(row_begin + kBandSubtileRows, subtiles_y_);
    };
    // Whether a band draws a cluster (its box reaches the band and is not hidden there),
    // counting the answer in the band's statistics.
    const detail::HiddenTestKernel hidden_test = detail::selected_hidden_test();
    const auto band_draws = [&](const PlacedCluster& p, std::size_t band, const detail::SubtilePlanes& planes) {
        int row_begin, row_end;
        band_rows(band, row_begin, row_end);
        int ty0, ty1;
        if (!detail::subtile_rows_within(p.j0, p.j1, row_begin, row_end, ty0, ty1)) return false;
        if (p.testable && hidden_test(planes, p.i0 / kW, p.i1 / kW, ty0, ty1, p.d_near)) {
            ++band_stats_[band].cluster_bands_hidden;
            return false;
        }
        ++band_stats_[band].cluster_bands_drawn;
        return true;
    };
    const detail::FrontEndKernels kernels = detail::selected_front_end_kernels();
    // drawn_into: as setup_triangle_range's (null when the triangles are kept for other bands).
    const auto set_up = [&](const PlacedCluster& p, const detail::VertexClip& cache, const detail::RasterTarget* drawn_into,
                            RasterStats& stats, auto&& emit) {
        const TriangleInput t = cluster_input(clusters, clusters.clusters[p.cluster], in);
        kernels.transform_vertices(t, double(config_.near_w), 0, t.vertex_count, cache);
        detail::setup_triangle_range(t, &cache, 0, t.triangle_count, config_.near_w, config_.edge_margin, sample_width_, sample_height_,
                                     drawn_into, stats, emit);
    };

    if (parallel.run) {
        // Each band walks the clusters in order and decides on its own rows, as the serial loop
        // below does. A cluster is set up by the first band that draws it and its triangles
        // kept for the others (which wait for them: a band setting one up depends on no other
        // task, so the wait is short and cannot deadlock): no bins, and no cluster set up twice.
        struct Job {
            decltype(band_rows)* rows;
            decltype(band_draws)* draws;
            decltype(set_up)* set_up_cluster;
            decltype(cache_of)* band_cache;
            OcclusionBuffer* self;
            bool clear_first;
        } job{&band_rows, &band_draws, &set_up, &cache_of, this, clear_first};
        detail::run_tasks(parallel, bands, [](void* data, std::size_t band) {
            const Job& j = *static_cast<Job*>(data);
            OcclusionBuffer& b = *j.self;
            int row_begin, row_end;
            (*j.rows)(band, row_begin, row_end);
            if (j.clear_first) b.clear_rows(row_begin, row_end);
            const detail::RasterTarget target = b.raster_target(row_begin, row_end);
            const detail::VertexClip cache = (*j.band_cache)(band);
            RasterStats& stats = b.band_stats_[band];
            for (std::size_t k = 0; k < b.placed_clusters_.size(); ++k) {
                if (!(*j.draws)(b.placed_clusters_[k], band, target.planes)) continue;
                ClusterSetup& s = *b.cluster_setups_[k];
                int expected = ClusterSetup::kNotSetUp;
                if (s.state.compare_exchange_strong(expected, ClusterSetup::kSettingUp, std::memory_order_acquire)) {
                    try {
                        s.triangles.clear();
                        s.stats = RasterStats{};
                        (*j.set_up_cluster)(b.placed_clusters_[k], cache, nullptr, s.stats,
                                            [&](const detail::RasterTriangle& tri) { s.triangles.push_back(tri); });
                    } catch (...) {  // the bands waiting for it must not wait for ever
                        s.state.store(ClusterSetup::kFailed, std::memory_order_release);
                        throw;
                    }
                    s.state.store(ClusterSetup::kReady, std::memory_order_release);
                } else {
                    while ((expected = s.state.load(std::memory_order_acquire)) == ClusterSetup::kSettingUp) std::this_thread::yield();
                    if (expected == ClusterSetup::kFailed) return;  // another band throws: the render fails
                }
                stats += s.stats;  // the setup's counts once per band that draws the cluster, as on one thread
                for (const detail::RasterTriangle& tri : s.triangles) stats.subtiles_updated += target.kernel(target, tri);
            }
            b.build_pyramid_rows(row_begin, row_end, std::min(kBandPyramidLevels, int(b.levels_.size()) - 1));
        }, &job);
        reduce_pyramid_above_bands();
    } else {
        // One thread: each cluster is set up once and rasterized in the runs of bands that draw
        // it. The statistics are the bands': its triangles' counts once per band drawing it.
        if (clear_first) clear_rows(0, subtiles_y_);
        const detail::RasterTarget whole = raster_target(0, subtiles_y_);
        const detail::VertexClip cache = cache_of(0);
        auto& runs = cluster_row_runs_;  // subtile rows [first, second)
        RasterStats serial;
        detail::ChangedSubtiles changed;
        for (const PlacedCluster& p : placed_clusters_) {
            runs.clear();
            std::uint64_t drawn = 0;
            for (std::size_t band = std::size_t(p.j0 / kH / kBandSubtileRows); band <= std::size_t(p.j1 / kH / kBandSubtileRows); ++band) {
                if (!band_draws(p, band, whole.planes)) continue;
                ++drawn;
                int row_begin, row_end;
                band_rows(band, row_begin, row_end);
                if (!runs.empty() && runs.back().second == row_begin) runs.back().second = row_end;
                else runs.emplace_back(row_begin, row_end);
            }
            if (runs.empty()) continue;
            RasterStats stats;
            // No per-triangle hidden test in the setup (drawn_into null): the cluster's box just
            // passed one, and of its triangles fewer are hidden (on castle C0, 29 % against 65 %
            // drawn as one input), too few to pay for the test (0.729 -> 0.743 ms).
            set_up(p, cache, nullptr, stats, [&](const detail::RasterTriangle& tri) {
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
    }

    stats_ += frame;
    for (const RasterStats& s : band_stats_) stats_ += s;
}

}  // namespace homcull
