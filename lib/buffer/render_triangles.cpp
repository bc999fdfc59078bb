// A render of triangles (render(TriangleInput), render_frame): the checks, the vertex cache,
// the draw order, and the choice of a render path (choose_triangle_path). The paths: on one
// thread straight through (render_serial, here), a clip-space soup through its cell notes
// (render_noted.cpp), with a job system binned by bands (render_binned.cpp). Every path gives
// the same bits.
#include <homcull/error.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "buffer/render_bands.hpp"
#include "common/float_mode.hpp"
#include "common/run_tasks.hpp"
#include "raster/draw_order.hpp"
#include "raster/rasterize.hpp"
#include "raster/reference_cells.hpp"
#include "raster/triangle_batch.hpp"

#include <algorithm>

namespace homcull {

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

detail::TrianglePath detail::choose_triangle_path(const TriangleInput& in, bool job_system, bool cells_kept) {
    const bool noted = in.clip_space && in.order == DrawOrder::nearest_first && cells_kept;
    if (noted) return job_system ? TrianglePath::noted_parts : TrianglePath::noted;
    return job_system ? TrianglePath::binned : TrianglePath::serial;
}

void detail::BufferState::render_rows(const TriangleInput& given, const ParallelFor& parallel, bool clear_first) {
    detail::check_triangle_input(given, "render");
    check_projection(given.orthographic, "render");
    detail::check_draw_order(given);
    if (given.shared_edges && !given.edge_apexes)
        throw Error("render: shared_edges needs edge_apexes (compute_shared_edges writes both): each flag is kept only where its "
                    "neighbour lies across the edge in this view");
    TriangleInput identity;
    const TriangleInput& in = detail::with_clip_space_matrix(given, identity);
    if (clear_first) stats_ = RasterStats{};
    detail::VertexClip storage;
    const detail::VertexClip* cache = transform_vertices(in, parallel, storage) ? &storage : nullptr;
    if (!draw_order_) draw_order_ = detail::make_hooked<detail::DrawOrderScratch>();
    // Cell notes fit a buffer whose cells fit a byte a side, and the instruction set has the
    // refresh kernel (the scalar reference sets triangles up one by one, without cells).
    const detail::CellNoteSpec note_spec{sample_width_, sample_height_, reference_cells_width_, detail::reference_cells_height(subtiles_y_),
                                         config_.near_w, in.backface};
    const bool cells_kept = detail::hidden_skip_enabled() && kernels_->raster.refresh_cells &&
                            note_spec.cells_width <= detail::kMaxNotedCellsPerSide && note_spec.cells_height <= detail::kMaxNotedCellsPerSide;
    const detail::TrianglePath path = detail::choose_triangle_path(in, parallel.run != nullptr, cells_kept);
    detail::DrawOrderScratch& scratch = *draw_order_;
    TriangleInput sorted;
    detail::DrawList list;
    if (path == detail::TrianglePath::noted || path == detail::TrianglePath::noted_parts) {
        detail::sort_noting_cells(kernels_->raster, in, config_.near_w, parallel, scratch, note_spec, list);
        if (path == detail::TrianglePath::noted_parts) render_parts(in, parallel, clear_first, list);
        else render_noted(in, clear_first, list);
        return;
    }
    // Nearest first (TriangleInput::order): with a vertex cache, the triangles the setup would
    // skip are left out (the sorted copy has the same vertices, so the cache serves it too); on
    // one thread, a list of numbers where the input allows.
    RasterStats skipped;
    const bool is_sorted = cache ? detail::sort_nearest_first_leaving_out(kernels_->raster, in, *cache, config_.near_w, parallel, scratch, sorted, skipped)
                                 : detail::sort_nearest_first(kernels_->raster, in, nullptr, config_.near_w, parallel, scratch, sorted,
                                                              path == detail::TrianglePath::serial ? &list : nullptr);
    const TriangleInput& drawn = is_sorted ? sorted : in;
    stats_ += skipped;
    if (path == detail::TrianglePath::binned) render_binned(drawn, parallel, cache, clear_first);
    else render_serial(drawn, cache, clear_first, list);
}

// One thread: each triangle is rasterized over the whole buffer as soon as it is set up, in
// input order; nothing is binned. Every subtile sees the triangles in the same order as in
// render_binned and the noted paths, so all give the same bits.
void detail::BufferState::render_serial(const TriangleInput& in, const detail::VertexClip* cache, bool clear_first, detail::DrawList list) {
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

}  // namespace homcull
