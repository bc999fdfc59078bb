#pragma once
// What the render paths share (render_triangles.cpp chooses among them): the bands of subtile
// rows that rendering splits the buffer into (render_binned.cpp, clustered_render.cpp), the
// chunks of render_binned's waves, the parts of a noted render (render_noted.cpp), and the
// clustered render's per-frame record of a cluster.
#include <homcull/occlusion_buffer.hpp>

#include <hwy/cache_control.h>

#include "buffer/buffer_state.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

namespace homcull {
namespace detail {

// Subtile rows rasterized per task (128 sample rows), the same whatever the threads: a
// triangle crossing into another band is set up once but entered once per band (16 rows gave
// more entries, 64 rows too few bands at 720p to share among threads).
constexpr int kBandSubtileRows = 32;
// The pyramid levels a band builds from its own rows, right after rasterizing them: the cells
// of level l span 2^l subtile rows, within one band while 2^l divides the band's rows. Built on
// the calling thread instead, they had to read every band's d0 from the other core's cache.
constexpr int kBandPyramidLevels = 5;
static_assert((1 << kBandPyramidLevels) == kBandSubtileRows, "a band's rows hold whole cells of its levels");

// A band reads set-up triangles in order (its bins' in render_binned, a cluster's in the
// clustered render), but they were written by whichever thread set them up, and a kernel call
// per triangle is too short for the hardware prefetcher to follow: they are prefetched this
// many triangles ahead (S1 at 1080p, two threads: 14.0 -> 13.2 ms; 2, 8 and 16 ahead were
// within noise of each other).
constexpr std::size_t kPrefetchTriangles = 8;
inline void prefetch_triangle(const RasterTriangle& tri) {
    const char* bytes = reinterpret_cast<const char*>(&tri);
    for (std::size_t offset = 0; offset < sizeof tri; offset += 64) hwy::Prefetch(bytes + offset);
}

// How far past a cluster being set up by another band a band looks for one to set up meanwhile
// (clustered_render.cpp, run_band).
constexpr std::size_t kSetUpAheadClusters = 16;
// The most set-up triangles a task list keeps for its bands (12 MB of RasterTriangle), so that
// a reserve for the largest draw stays bounded: the clusters nearest first until they fill it,
// the rest set up by each band that draws them (ClusterSetup::kEach, the same bits). Nearest
// first, the later clusters are mostly hidden and skipped before any set-up.
constexpr std::size_t kSetUpRoomTriangles = std::size_t(1) << 16;
// render_binned's chunks: triangles set up per task, and each chunk's room for its set-up
// triangles (clipping at the near plane or the guard band may give a triangle more than one; a
// chunk that needs more sets up again in every band). Waves hold at most kMaxWaveChunks chunks,
// so that the room for a wave is bounded whatever the input: reserve sizes it once.
constexpr std::size_t kChunkTriangles = 2048;
constexpr std::size_t kChunkRoom = kChunkTriangles + kChunkTriangles / 8;
static_assert(kChunkRoom <= 65536, "a band's entries number a chunk's triangles in 16 bits");
constexpr std::size_t kMaxWaveChunks = 32;
// A noted render: the triangles set up between two refreshes of the reference cells of the
// rows drawn into (draw_noted_part).
constexpr std::size_t kCellRefreshTriangles = 4096;

// The subtiles [x0, x1) x [y0, y1) that a render on one thread changed: only their pyramid cells
// are rebuilt after it, so that a render call costs what it draws, not the buffer's size (an
// engine draws its occluders object by object, one call each).
struct ChangedSubtiles {
    int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    // Adds a triangle's samples [i0, i1] x [j0, j1] (already within the buffer).
    void add(const RasterTriangle& tri, int subtiles_x, int subtiles_y) {
        const int tx0 = std::max(0, tri.i0 / OcclusionBuffer::kSubtileWidth);
        const int tx1 = std::min(subtiles_x, tri.i1 / OcclusionBuffer::kSubtileWidth + 1);
        const int ty0 = std::max(0, tri.j0 / OcclusionBuffer::kSubtileHeight);
        const int ty1 = std::min(subtiles_y, tri.j1 / OcclusionBuffer::kSubtileHeight + 1);
        if (tx0 >= tx1 || ty0 >= ty1) return;
        if (empty()) {
            x0 = tx0, x1 = tx1, y0 = ty0, y1 = ty1;
            return;
        }
        x0 = std::min(x0, tx0), x1 = std::max(x1, tx1), y0 = std::min(y0, ty0), y1 = std::max(y1, ty1);
    }
};

}  // namespace detail

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

// A cluster in view this frame: its box's samples [i0, i1] x [j0, j1] and nearest depth
// (detail::BufferState::prepare's), or, when `testable` is false (its box crosses the near plane or
// is not finite), every sample and no test.
struct detail::BufferState::PlacedCluster {
    float nearest_w;  // the order: nearest first (0 for untestable clusters), then by number
    std::uint32_t cluster;
    std::uint32_t draw;  // its draw: recorded_draws_[draw]
    int i0, i1, j0, j1;
    float d_near;
    bool testable;
    Backface backface;  // its triangles' (ClusteredInput::backfaces, or the draw's)
};

// Where a cluster's box lands this frame (detail::BufferState::place_cluster), one per cluster of
// the input, in its order.
struct detail::BufferState::ClusterPlace {
    PlacedCluster placed;  // when in view
    std::uint8_t fate;
    static constexpr std::uint8_t kInView = 0, kOutside = 1, kEmpty = 2;  // kEmpty: no triangles
};

// In a task list, a cluster in view is set up by the first band that claims it (state kNotSetUp
// -> kSettingUp), into its room in setup_triangles_ ([first, first + room): its triangle count),
// and drawn from there by the bands that find it kReady. A band finding it kSettingUp sets up
// later clusters meanwhile, or with none left sets it up for itself; when clipping gives it
// more triangles than its room, every band drawing it sets it up itself (kEach): the same
// triangles, so the same bits.
// A line of its own: the band tasks read and set the states of neighbouring clusters at once.
struct alignas(64) detail::BufferState::ClusterSetup {
    std::size_t first = 0, room = 0, count = 0;
    RasterStats stats;          // the setup's counts
    std::atomic<int> state{0};  // kNotSetUp, kSettingUp, kReady or kEach
    static constexpr int kNotSetUp = 0, kSettingUp = 1, kReady = 2, kEach = 3;
    ClusterSetup() = default;
    // Copied only on the calling thread, while no task runs (the vector grows in close_tasks).
    ClusterSetup(const ClusterSetup& o) : first(o.first), room(o.room), count(o.count), stats(o.stats), state(o.state.load()) {}
    ClusterSetup& operator=(const ClusterSetup& o) {
        first = o.first, room = o.room, count = o.count, stats = o.stats;
        state.store(o.state.load());
        return *this;
    }
};

}  // namespace homcull
