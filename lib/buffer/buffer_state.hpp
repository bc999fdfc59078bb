#pragma once
// The occlusion buffer's state and the implementation of its calls. homcull/occlusion_buffer.hpp
// states the contracts and OcclusionBuffer forwards each call here (occlusion_buffer_calls.cpp),
// so that the installed header does not change with the implementation. Private to the
// library; the occlusion maps read a buffer through OcclusionBuffer::state(), read-only.
#include <homcull/occlusion_buffer.hpp>

#include <cstddef>
#include "buffer/min_pyramid.hpp"
#include "raster/sample_depth_tiles.hpp"

#include <cstdint>
#include <new>
#include <utility>

namespace homcull {
struct OccluderCluster;
}

namespace homcull::detail {
struct RectQuery;
struct SubtileView;
struct CoarseRectView;
struct RasterTarget;
struct VertexClip;
struct DrawList;
struct RasterTriangle;
struct DrawOrderScratch;
struct ReferenceCells;
struct CellNote;
struct ChangedSubtiles;
struct BufferSizes;
struct BufferKernels;
struct IsaChoice;

// The paths a render of triangles takes, all giving the same bits. One function chooses:
// - serial: one thread, each triangle set up and drawn over the whole buffer, in (sorted) order;
// - noted: one thread, a clip-space soup (TriangleInput::clip_space) drawn nearest first
//   through its cell notes, dropping most hidden triangles unread (render_noted.cpp);
// - noted_parts: the same with a job system, a task per part of the rows;
// - binned: a job system, chunks set up in tasks, then bands of rows drawn in tasks
//   (render_binned.cpp).
// The noted paths need the buffer to keep reference cells (`cells_kept`: the hidden-triangle
// skip on, an instruction set with the refresh kernel, cells that fit a note).
enum class TrianglePath : std::uint8_t { serial, noted, noted_parts, binned };
TrianglePath choose_triangle_path(const TriangleInput& in, bool job_system, bool cells_kept);

class BufferState {
public:
    using Subtile = OcclusionBuffer::Subtile;
    using TriangleTest = OcclusionBuffer::TriangleTest;
    static constexpr int kSubtileWidth = OcclusionBuffer::kSubtileWidth, kSubtileHeight = OcclusionBuffer::kSubtileHeight;

    // The calls of OcclusionBuffer, with its contracts.
    explicit BufferState(const BufferConfig& config);
    void configure(const BufferConfig& config);
    void set_near_w(float near_w);
    void reserve(const BufferReserve& reserve);
    void clear();
    void render(const TriangleInput& input, const ParallelFor& parallel = {});
    void render_frame(const TriangleInput& input, const ParallelFor& parallel = {});
    void render(const ClusteredInput& input, const ParallelFor& parallel = {});
    void render_frame(const ClusteredInput& input, const ParallelFor& parallel = {});
    void begin_tasks(bool clear_first = false);
    void record(const ClusteredInput& draw, const ParallelFor& parallel = {});
    std::size_t close_tasks();
    void run_task(std::size_t index) noexcept;
    void finish_tasks();
    std::size_t finish_tasks(std::nothrow_t) noexcept;
    Visibility test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const;
    Visibility test_rect_exhaustive(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const;
    Visibility test_aabb(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip) const;
    void test_rects(const ScreenRect* rects, std::size_t count, Visibility* results) const;
    void test_aabbs(const Aabb* boxes, std::size_t count, const std::array<float, 16>& model_to_clip, Visibility* results) const;
    // The same without the exact view test (exact_view_test.hpp): for callers that make their own
    // from a view they hold (the scene culler's frustum, the C API's double matrices).
    Visibility test_aabb_by_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip) const;
    void test_aabbs_by_rectangle(const Aabb* boxes, std::size_t count, const std::array<float, 16>& model_to_clip, Visibility* results) const;
    // OcclusionBuffer::test_triangles; with `solid` (seen_solid.hpp), the triangles that the
    // eye certainly sees from behind are passed over like those outside the view.
    TriangleTest test_triangles(const TriangleInput& occludee, std::uint64_t tolerated_samples = 0, std::size_t first_triangle = 0,
                                const OcclusionBuffer::ClosedSolid* solid = nullptr) const;
    Subtile subtile(int tx, int ty) const;
    std::vector<Subtile> subtiles() const;
    void read_coverage(std::vector<std::uint8_t>& covered) const;
    void read_depth(std::vector<float>& w) const;
    void read_sample_depth(std::vector<float>& d) const;
    void read_pyramid(std::vector<float>& cells) const;
    const BufferConfig& config() const { return config_; }
    int sample_width() const { return sample_width_; }
    int sample_height() const { return sample_height_; }
    const RasterStats& stats() const { return stats_; }
    int subtiles_x() const { return subtiles_x_; }
    int subtiles_y() const { return subtiles_y_; }
    ~BufferState();
    // Throws homcull::Error when an input's projection is not the buffer's.
    void check_projection(bool orthographic, const char* caller) const;

    BufferConfig config_;
    // The kernels of the instruction set config_.isa names, for every render, task and query.
    const BufferKernels* kernels_ = nullptr;
    const IsaChoice* isa_ = nullptr;  // the choice they were resolved for
    int sample_width_ = 0, sample_height_ = 0;
    int subtiles_x_ = 0, subtiles_y_ = 0;
    // The subtiles as four planes (structure of arrays, so that SIMD kernels load a run of
    // subtiles as one vector per field), row-major with a padded row stride: a full vector
    // load starting at any subtile of a row stays within the row's padding.
    std::size_t stride_ = 0;
    Vector<float> d0_, d1_;
    Vector<std::uint32_t> mask_, covered_;
    Vector<float> sample_depth_;  // 1/w per sample, row-major; empty unless config_.sample_depth
    // Its row stride: the width plus room for a whole vector from any sample of the row, so that
    // the SIMD kernel's vectors never reach into the next row (another band's, on another thread).
    std::size_t sample_depth_stride_ = 0;
    // The per-sample depth computed where queries read it (raster/sample_depth_tiles.hpp), when
    // config_.sample_depth and deferred_sample_depth_enabled() at configure: its units' states, its
    // tiles' lists, and per group of rows the records and list entries with their counts.
    bool deferred_sample_depth_ = false;
    Vector<std::uint8_t> depth_unit_state_;
    Vector<std::uint32_t> depth_tile_head_;
    Vector<DepthGroupCursor> depth_groups_;
    Vector<std::int32_t> depth_words_;
    Vector<DepthTileEntry> depth_entries_;
    SampleDepthTiles depth_tiles_{};  // points into the arrays above (set by point_depth_tiles whenever they may have moved)
    void point_depth_tiles();
    std::size_t at(int tx, int ty) const { return std::size_t(ty) * stride_ + std::size_t(tx); }
    RasterStats stats_;

    // Farthest-depth pyramid: level l >= 1 holds, per cell of 2^l x 2^l subtiles, the minimum
    // d0; brought up to date at the end of render() (on one thread, over the subtiles it changed).
    Vector<PyramidLevel> levels_;
    Vector<float> pyramid_;
    Vector<std::int32_t> level_offset_, level_width_;  // levels_ as arrays, for SIMD gathers
    // Level 0 for subtile rows [row_begin, row_end) and levels 1..last_level above them (row_begin
    // a multiple of 2^last_level: each cell's subtiles are then among these rows).
    void build_pyramid_rows(int row_begin, int row_end, int last_level);
    // Rows [y_begin, y_end) of pyramid level `level` >= 1 from the level below.
    void reduce_pyramid_rows(int level, int y_begin, int y_end);
    // Room for the arrays sized by the configuration (configure, reserve): allocation only.
    void reserve_arrays(const BufferSizes& sizes);
    // Every level's cells over the subtiles [x0, x1) x [y0, y1): after a render on one thread,
    // the subtiles it changed (nothing when the rectangle is empty).
    void build_pyramid_rect(int x0, int x1, int y0, int y1);
    // After a render on one thread: the whole pyramid when it cleared the buffer first, else the
    // cells over the subtiles it changed.
    void build_changed_pyramid(bool cleared, const ChangedSubtiles& changed);
    // Cells [x_begin, x_end) x [y_begin, y_end) of pyramid level `level` >= 1 from the level below.
    void reduce_pyramid_cells(int level, int x_begin, int x_end, int y_begin, int y_end);
    // Zeroes the subtiles (and per-sample depths) of subtile rows [row_begin, row_end).
    void clear_rows(int row_begin, int row_end);
    // Shared by the rectangle tests: the sample range and nearest 1/w, or a decided answer.
    bool prepare(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min, RectQuery& q,
                 Visibility& decided) const;
    Visibility test_prepared_rect(const RectQuery& q) const;
    SubtileView subtile_view() const;
    CoarseRectView coarse_view() const;

    // Rendering triangles (render_triangles.cpp chooses the path: choose_triangle_path).
    RasterTarget raster_target(int row_begin, int row_end);
    // clear_first: render_frame, which clears the rows where it rasterizes them.
    void render_rows(const TriangleInput& in, const ParallelFor& parallel, bool clear_first);
    void render_serial(const TriangleInput& in, const VertexClip* cache, bool clear_first, DrawList list);
    // A clip-space soup through its cell notes (render_noted.cpp): on one thread, or in parts of
    // rows with a job system.
    void render_noted(const TriangleInput& in, bool clear_first, DrawList list);
    void render_parts(const TriangleInput& in, const ParallelFor& parallel, bool clear_first, DrawList list);
    // Part `part` of a noted render: the list's triangles drawn into subtile rows [row_begin,
    // row_end) with that part's cells; its statistics counted as for the whole buffer.
    void draw_noted_part(const TriangleInput& in, DrawList list, bool clear_first, std::size_t part, int row_begin, int row_end,
                         bool cells_current = false);
    // With a job system (render_binned.cpp).
    void render_binned(const TriangleInput& in, const ParallelFor& parallel, const VertexClip* cache, bool clear_first);
    // Transforms an indexed input's vertices to clip space into the scratch below and points
    // `cache` at it (triangle_batch.hpp); false when transforming them triangle by triangle is cheaper.
    bool transform_vertices(const TriangleInput& in, const ParallelFor& parallel, VertexClip& cache);

    // Clustered input (clustered_render.cpp). With a job system a render is a task list of one
    // draw (begin_tasks ... finish_tasks).
    void render_clusters(const ClusteredInput& in, const ParallelFor& parallel, bool clear_first);
    // Checks a draw and places its clusters (cluster_places_), throwing before anything changes.
    std::size_t place_clusters(const ClusteredInput& in, const ParallelFor& parallel);
    void append_placed(const ClusteredInput& in, std::size_t count, RasterStats& stats);
    struct ClusterPass;
    struct PlacedCluster;
    struct ClusterPlace;
    struct ClusterSetup;
    enum class TaskList : std::uint8_t { none, recording, closed };
    TaskList task_list_ = TaskList::none;
    bool task_list_clears_ = false;
    RasterStats task_list_stats_;               // the recorded draws' clusters outside the view
    std::size_t task_list_vertices_ = 0;        // the most vertices of a cluster recorded (the band caches' size)
    Vector<ClusteredInput> recorded_draws_;  // PlacedCluster::draw numbers them
    Vector<std::uint8_t> band_ran_;     // per band: its task ran (finish_tasks checks them all)
    // Task i of a closed list draws band band_order_[i]: the bands by their time in the last task
    // list (band_seconds_), longest first, so that threads taking tasks in turn finish together.
    Vector<std::uint32_t> band_order_;
    Vector<float> band_seconds_;
    void run_band(std::size_t band) noexcept;
    Vector<RasterTriangle> setup_triangles_;  // each ClusterSetup's room, one after the other
    // Where a cluster's box lands (in view, outside, or no triangles). In job-system tasks: noexcept.
    void place_cluster(const OccluderCluster& c, std::uint32_t number, const std::array<float, 16>& model_to_clip, Backface backface,
                       ClusterPlace& out) const noexcept;
    // After the bands: the pyramid levels above those each band built (kBandPyramidLevels).
    void reduce_pyramid_above_bands();

    // The smallest d0 of each cell of 8 x 8 subtiles, valid only while a render draws
    // (raster/reference_cells.hpp): a copy per part of the rows (render_parts; one thread: one
    // part), the other parts' rows infinite in each. Sized with the buffer for one part.
    Vector<float> reference_cells_;
    int reference_cells_width_ = 0;
    struct NotedPart;
    Vector<NotedPart> noted_parts_;
    // Per cell row: the triangles the last noted render drew there (each at its first row in its
    // part), which places the next render's part bounds.
    Vector<std::uint32_t> cell_row_load_;
    // The cells of part 0 hold the buffer's d0 over every row: the last render was a noted one on
    // one thread and nothing changed the buffer since. The next such render then starts from them
    // instead of recomputing them all (a render call costs what it draws).
    bool reference_cells_current_ = false;
    // At the start of a render with cell records (which render_rows asks the sort for only when
    // hidden triangles are skipped and the instruction set has a refresh kernel): part `part`'s
    // cells, those of subtile rows [row_begin, row_end) zeroed when the render clears the buffer
    // first, else computed from d0, and the others infinite (every noted triangle is hidden
    // there: another part draws them).
    // cells_current: part 0's cells already hold d0 (reference_cells_current_ when the render began).
    ReferenceCells start_reference_cells(bool clear_first, std::size_t part, int row_begin, int row_end, bool cells_current);
    // Refreshes the cells holding subtile rows [row_begin, row_end).
    void refresh_reference_cells(const ReferenceCells& cells, int row_begin, int row_end);

    // Render scratch, reused across frames (grown, never shrunk).
    // The waves of render_binned: per chunk slot of a wave its record, its set-up triangles and,
    // per band, their numbers (render_binned's Chunk).
    struct Chunk;
    Vector<Chunk> chunks_;
    Vector<RasterTriangle> wave_triangles_;
    Vector<std::uint16_t> wave_entry_counts_, wave_entries_;
    void reserve_waves(std::size_t slots, std::size_t bands);
    Vector<std::uint64_t> band_updated_;
    Vector<double> vertex_clip_;           // four planes of vertex_count + padding
    Vector<std::uint8_t> vertex_outcode_;
    HookPtr<DrawOrderScratch> draw_order_;  // raster/draw_order.hpp; made by the first render
    Vector<ClusterPlace> cluster_places_;    // each input cluster's box this frame
    Vector<PlacedCluster> placed_clusters_;  // the frame's clusters in view, nearest first
    Vector<RasterStats> band_stats_;
    Vector<std::pair<int, int>> cluster_row_runs_;  // one thread: the subtile rows a cluster is drawn in
    Vector<ClusterSetup> cluster_setups_;  // task lists: one per cluster in view
    Vector<double> band_vertex_clip_;         // per band: four planes of a cluster's vertices + padding
    Vector<std::uint8_t> band_vertex_outcode_;

};

}  // namespace homcull::detail
