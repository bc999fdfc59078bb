#pragma once
// The per-sample depth (BufferConfig::sample_depth), computed where a query reads it.
//
// The occludee triangle tests read the per-sample depth only in subtiles where the layers leave
// samples unhidden: on the castle's views about 1 % of the subtiles, on OpenArena's about 3 %.
// Writing it for every covered sample of every occluder triangle cost about as much as the rest
// of the render. So the row loops list each drawn triangle's rows (its depth plane and the
// coverage intervals they computed) in the tiles they reach, and the first query that reads a
// tile writes that tile's samples from its list.
//
// The values are the same bits as writing every triangle at once (the row loops' eager
// update): a sample holds the maximum, over the triangles drawn into its rows, of
// conservative_depth at the sample, and a maximum does not depend on the order. Rows the row
// loop skipped as hidden behind the reference layer (hidden_behind_reference_layer) are neither
// listed nor written, as before.
//
// Layout: tiles of kDepthTileSubtilesX x kDepthTileSubtilesY subtiles (64 x 16 samples), each
// with a list of entries, and per group of kDepthGroupSubtileRows subtile rows an arena of
// records and entries of fixed size. A triangle that does not fit its groups' arenas is written
// at once by the row loop, into tiles zeroed first: the same values, at the eager cost. Renders
// that run at the same time write disjoint rows whose bounds are multiples of
// kDepthGroupSubtileRows (bands, parts of rows), so each group and tile has one writer during a
// render; queries run after renders, and fill tiles under an atomic state (several threads may
// query at once).
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <thread>

namespace homcull::detail {

constexpr int kDepthTileSubtilesX = 8, kDepthTileSubtilesY = 4;
constexpr int kDepthTileWidth = kDepthTileSubtilesX * kSubtileWidth;    // 64 samples
constexpr int kDepthTileHeight = kDepthTileSubtilesY * kSubtileHeight;  // 16 samples
static_assert(kDepthTileWidth % kMaxSimdLanes == 0, "vectors aligned to a tile's columns never write past them");
constexpr int kDepthGroupSubtileRows = 8;
static_assert(kDepthGroupSubtileRows % kDepthTileSubtilesY == 0, "a group holds whole tiles");

// Tile states. A tile's samples are stale (last frame's) until a render writes a triangle into
// it at once (zeroed first) or a query fills it (zeroed first when stale, then its list). Only
// queries fill (through filling, under an atomic compare-and-swap); renders touch only their
// own rows' tiles, with no query running.
constexpr std::uint8_t kDepthTileStale = 0, kDepthTileZeroed = 1, kDepthTileFilling = 2, kDepthTileFilled = 3;
constexpr std::uint32_t kNoDepthEntry = 0xFFFFFFFFu;

struct DepthTileEntry {
    std::uint32_t record;  // the record's first word in its group's arena
    std::uint32_t next;    // the tile's next entry, kNoDepthEntry at the end
};

// A record: a drawn triangle's depth plane and the coverage intervals of some of its sample rows
// (those of one row-loop chunk within one group), as the row loop computed them; then
// first[rows] and last[rows] follow it in the arena. The fill needs nothing else, and
// recomputing the intervals cost as much as the writes they save.
struct DepthRowsRecord {
    PreparedTriangle plane;
    std::int32_t row0, rows;
};
constexpr std::uint32_t kDepthRecordHeaderWords = (sizeof(DepthRowsRecord) + 3) / 4;

struct SampleDepthTiles;
// Applies every triangle of a tile's list to its samples (this instruction set's kernel).
using FillDepthTileKernel = void (*)(const SampleDepthTiles& tiles, int tx, int ty);

// A buffer's per-sample depth and its bookkeeping (the arrays belong to the buffer).
struct SampleDepthTiles {
    float* depth;          // per sample, rows `stride` apart (padded by kMaxSimdLanes)
    std::size_t stride;
    int sample_width, sample_height;
    int tiles_x, tiles_y, groups;
    std::uint8_t* tile_state;      // per tile, row-major
    std::uint32_t* tile_head;      // per tile, row-major: its first entry (in its group's arena)
    std::int32_t* words;           // the records, group g's from g * word_capacity
    DepthTileEntry* entries;       // group g's from g * entry_capacity
    std::uint32_t* group_words;    // per group: words taken
    std::uint32_t* group_entries;  // per group: entries taken
    std::uint8_t* any_filled;      // whether a query may have filled a tile since the whole buffer was last reset
    std::uint32_t word_capacity, entry_capacity;
    FillDepthTileKernel fill_tile;

    std::uint8_t& state(int tx, int ty) const { return tile_state[std::size_t(ty) * std::size_t(tiles_x) + std::size_t(tx)]; }
};

// Room per group: 24 words per subtile of the group's rows (about a record of 8 sample rows for
// every two subtiles), and an entry per two subtiles (the castle's drawn triangles reach about
// 1.5 tiles each). Fuller groups write at once.
inline std::uint32_t depth_word_capacity(int subtiles_x) { return std::uint32_t(subtiles_x) * kDepthGroupSubtileRows * 24 + 1024; }
inline std::uint32_t depth_entry_capacity(int subtiles_x) { return std::uint32_t(subtiles_x) * kDepthGroupSubtileRows + 256; }

// Forgets what subtile rows [row_begin, row_end) held: their tiles empty, their lists and the
// arenas of their groups (row_begin a multiple of kDepthGroupSubtileRows; row_end too, or the
// last row).
inline void reset_sample_depth_rows(const SampleDepthTiles& t, int row_begin, int row_end) {
    if (!t.tile_state || row_begin >= row_end) return;
    const int tile_row_end = std::min(t.tiles_y, (row_end + kDepthTileSubtilesY - 1) / kDepthTileSubtilesY);
    for (int ty = row_begin / kDepthTileSubtilesY; ty < tile_row_end; ++ty) {
        std::fill_n(t.tile_state + std::size_t(ty) * std::size_t(t.tiles_x), t.tiles_x, kDepthTileStale);
        std::fill_n(t.tile_head + std::size_t(ty) * std::size_t(t.tiles_x), t.tiles_x, kNoDepthEntry);
    }
    const int group_end = std::min(t.groups, (row_end + kDepthGroupSubtileRows - 1) / kDepthGroupSubtileRows);
    for (int g = row_begin / kDepthGroupSubtileRows; g < group_end; ++g) t.group_words[g] = 0, t.group_entries[g] = 0;
    if (row_begin == 0 && tile_row_end == t.tiles_y) *t.any_filled = 0;
}

// Zeroes a tile's samples (the last column of tiles ends at the rows' padding).
inline void zero_depth_tile(const SampleDepthTiles& t, int tx, int ty) {
    const int row_end = std::min(t.sample_height, (ty + 1) * kDepthTileHeight);
    const std::size_t x0 = std::size_t(tx) * kDepthTileWidth, width = std::min<std::size_t>(kDepthTileWidth, t.stride - x0);
    for (int row = ty * kDepthTileHeight; row < row_end; ++row) std::fill_n(t.depth + std::size_t(row) * t.stride + x0, width, 0.0f);
}

// Calls visit(record) for every record in tile (tx, ty)'s list.
template <typename Visit>
void for_each_in_depth_tile(const SampleDepthTiles& t, int tx, int ty, Visit&& visit) {
    const int group = ty * kDepthTileSubtilesY / kDepthGroupSubtileRows;
    const std::int32_t* words = t.words + std::size_t(group) * t.word_capacity;
    const DepthTileEntry* entries = t.entries + std::size_t(group) * t.entry_capacity;
    for (std::uint32_t e = t.tile_head[std::size_t(ty) * std::size_t(t.tiles_x) + std::size_t(tx)]; e != kNoDepthEntry; e = entries[e].next)
        visit(words + entries[e].record);
}

// A record's header and intervals.
inline DepthRowsRecord depth_record_header(const std::int32_t* record) {
    DepthRowsRecord r;
    std::memcpy(&r, record, sizeof r);
    return r;
}
inline const std::int32_t* depth_record_first(const std::int32_t* record) { return record + kDepthRecordHeaderWords; }
inline const std::int32_t* depth_record_last(const std::int32_t* record, int rows) { return record + kDepthRecordHeaderWords + rows; }

// Makes tile (tx, ty) hold its samples' depth before a query reads it: fills it (zeroed first
// when stale), or waits while another thread fills it.
inline void ensure_depth_tile(const SampleDepthTiles& t, int tx, int ty) {
    std::uint8_t* state = &t.state(tx, ty);
    // C++17 has no atomic_ref, and the states live in the buffer's plain arrays (resized with
    // the buffer, which std::atomic elements cannot be): the GCC and Clang builtins, as
    // std::atomic_ref would compile to.
    for (;;) {
        std::uint8_t seen = __atomic_load_n(state, __ATOMIC_ACQUIRE);
        if (seen == kDepthTileFilled) return;
        if (seen == kDepthTileFilling) {
            std::this_thread::yield();
            continue;
        }
        if (__atomic_compare_exchange_n(state, &seen, kDepthTileFilling, false, __ATOMIC_ACQUIRE, __ATOMIC_ACQUIRE)) {
            __atomic_store_n(t.any_filled, std::uint8_t(1), __ATOMIC_RELAXED);
            if (seen == kDepthTileStale) zero_depth_tile(t, tx, ty);
            t.fill_tile(t, tx, ty);
            __atomic_store_n(state, kDepthTileFilled, __ATOMIC_RELEASE);
            return;
        }
    }
}

// The tile of subtile (tx, ty), made ready (ensure_depth_tile).
inline void ensure_depth_subtile(const SampleDepthTiles& t, int tx, int ty) {
    ensure_depth_tile(t, tx / kDepthTileSubtilesX, ty / kDepthTileSubtilesY);
}

// Every tile made ready (read-backs of the whole per-sample depth).
inline void ensure_all_depth_tiles(const SampleDepthTiles& t) {
    for (int ty = 0; ty < t.tiles_y; ++ty)
        for (int tx = 0; tx < t.tiles_x; ++tx) ensure_depth_tile(t, tx, ty);
}

// Whether a triangle about to be drawn into subtile rows [ty0, ty1] goes into the tiles' lists
// (record_sample_depth with each chunk's intervals): whether every group's arena it reaches has
// room (a large triangle takes an entry in each of its tiles, which costs less than writing its
// samples: most lie in tiles no query reads). Otherwise the row loop writes it at once, and this
// zeroes its stale tiles first.
inline bool list_sample_depth(const SampleDepthTiles& t, const RasterTriangle& tri, int ty0, int ty1) {
    constexpr int kH = kSubtileHeight;
    const int tx0 = tri.i0 / kDepthTileWidth, tx1 = std::min(t.tiles_x - 1, tri.i1 / kDepthTileWidth);
    bool room = true;
    for (int group = ty0 / kDepthGroupSubtileRows; group <= ty1 / kDepthGroupSubtileRows && room; ++group) {
        const int gy0 = std::max(ty0, group * kDepthGroupSubtileRows), gy1 = std::min(ty1, group * kDepthGroupSubtileRows + kDepthGroupSubtileRows - 1);
        const int rows = std::min(tri.j1, gy1 * kH + kH - 1) - std::max(tri.j0, gy0 * kH) + 1;
        // A chunk boundary may split the group's rows into two records.
        const std::uint32_t words = 2 * kDepthRecordHeaderWords + 2 * std::uint32_t(std::max(rows, 0));
        const std::uint32_t entries = 2 * std::uint32_t((gy1 / kDepthTileSubtilesY - gy0 / kDepthTileSubtilesY + 1) * (tx1 - tx0 + 1));
        room = t.group_words[group] + words <= t.word_capacity && t.group_entries[group] + entries <= t.entry_capacity;
    }
    if (room) return true;
    for (int ty = ty0 / kDepthTileSubtilesY; ty <= ty1 / kDepthTileSubtilesY; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            std::uint8_t& state = t.state(tx, ty);
            if (state == kDepthTileStale) zero_depth_tile(t, tx, ty), state = kDepthTileZeroed;
        }
    return false;
}

// Lists the sample rows [row0, row0 + rows) of a triangle being drawn (list_sample_depth said so)
// with their intervals [first[r], last[r]] within columns [i0, i1]: a record in each group's arena
// the rows with samples reach, and an entry in each of their tiles' lists. Tiles already filled
// (a query read them since the frame began) take the record at once through apply(record, tx, ty).
template <typename Apply>
void record_sample_depth(const SampleDepthTiles& t, const PreparedTriangle& plane, int i0, int i1, int row0, int rows,
                         const std::int32_t* first, const std::int32_t* last, Apply&& apply) {
    constexpr int kGroupRows = kDepthGroupSubtileRows * kSubtileHeight;
    int begin = 0, end = rows;  // the rows with samples
    while (begin < end && first[begin] > last[begin]) ++begin;
    while (end > begin && first[end - 1] > last[end - 1]) --end;
    const int tx0 = i0 / kDepthTileWidth, tx1 = std::min(t.tiles_x - 1, i1 / kDepthTileWidth);
    const bool any_filled = *t.any_filled != 0;
    for (int r = begin; r < end;) {
        const int row = row0 + r, group = row / kGroupRows;
        const int n = std::min(end - r, (group + 1) * kGroupRows - row);
        std::int32_t* words = t.words + std::size_t(group) * t.word_capacity;
        const std::uint32_t record = t.group_words[group];
        t.group_words[group] = record + kDepthRecordHeaderWords + 2 * std::uint32_t(n);
        const DepthRowsRecord header{plane, row, n};
        std::memcpy(words + record, &header, sizeof header);
        std::memcpy(words + record + kDepthRecordHeaderWords, first + r, sizeof(std::int32_t) * std::size_t(n));
        std::memcpy(words + record + kDepthRecordHeaderWords + n, last + r, sizeof(std::int32_t) * std::size_t(n));
        DepthTileEntry* entries = t.entries + std::size_t(group) * t.entry_capacity;
        for (int ty = row / kDepthTileHeight; ty <= (row + n - 1) / kDepthTileHeight; ++ty)
            for (int tx = tx0; tx <= tx1; ++tx) {
                const std::uint32_t e = t.group_entries[group]++;
                std::uint32_t& head = t.tile_head[std::size_t(ty) * std::size_t(t.tiles_x) + std::size_t(tx)];
                entries[e] = {record, head};
                head = e;
                if (any_filled && t.state(tx, ty) == kDepthTileFilled) apply(words + record, tx, ty);  // its fill is past
            }
        r += n;
    }
}

// Whether buffers configured from now on compute the per-sample depth where it is read (the
// default) or write it for every triangle as it is drawn (the same bits; kept for the tests that
// compare the two).
void set_deferred_sample_depth(bool enabled);
bool deferred_sample_depth_enabled();

// The reference's fill and its one-record step: conservative_depth at each sample of a record's
// intervals within the tile, kept where larger (update_sample_depth's operations).
void apply_depth_record_reference(const SampleDepthTiles& t, const std::int32_t* record, int tx, int ty);
void fill_depth_tile_reference(const SampleDepthTiles& t, int tx, int ty);

}  // namespace homcull::detail
