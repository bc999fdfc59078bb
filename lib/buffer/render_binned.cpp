// A render with a job system: the triangles set up in chunks and drawn by bands of subtile
// rows, in waves (render_binned below). render_triangles.cpp chooses this path.
#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "buffer/render_bands.hpp"
#include "common/run_tasks.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_batch.hpp"

#include <algorithm>

namespace homcull {
namespace {

constexpr int kH = OcclusionBuffer::kSubtileHeight;
using detail::kBandPyramidLevels;
using detail::kBandSubtileRows;
using detail::kChunkRoom;
using detail::kChunkTriangles;
using detail::kMaxWaveChunks;
// The chunks of the first wave; each later wave has twice as many chunks as the one before, up
// to kMaxWaveChunks. S1 at 1080p, two threads: one wave
// 6.88 ms; a first wave of 2, 4 or 8 chunks 5.06, 5.07, 5.18 ms.
constexpr std::size_t kFirstWaveChunks = 4;
}  // namespace

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
// free; only the speed depends on them. (A clip-space soup with cell notes goes to
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

}  // namespace homcull
