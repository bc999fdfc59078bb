#pragma once
// The per-sample depth (BufferConfig::sample_depth), computed where a query reads it.
//
// The occludee triangle tests read the per-sample depth only in subtiles where the layers leave
// samples unhidden: on the castle's views about 1 % of the subtiles, on OpenArena's about 3 %.
// Writing it for every covered sample of every occluder triangle cost about as much as the rest
// of the render. So the row loops list each drawn triangle's rows (its depth plane and the
// coverage intervals they computed) in the tiles they reach, and the first query that reads a
// unit of a tile writes that unit's samples from the tile's list.
//
// The values are the same bits as writing every triangle at once (the row loops' eager
// update): a sample holds the maximum, over the triangles drawn into its rows, of
// conservative_depth at the sample, and a maximum does not depend on the order. Rows the row
// loop skipped as hidden behind the reference layer (hidden_behind_reference_layer) are neither
// listed nor written, as before.
//
// Layout: lists per tile of kDepthTileSubtilesX x kDepthTileSubtilesY subtiles (64 x 16
// samples), each entry with the subtiles its record reaches in the tile; samples filled per unit
// of kDepthUnitSubtilesX x kDepthUnitSubtilesY subtiles (16 x 4 samples: a query reads about 3 of
// a tile's 32 subtiles, and filling whole tiles did ten times the writes needed); per group of
// kDepthGroupSubtileRows subtile rows an arena of records and entries of fixed size. A triangle
// that does not fit its groups' arenas is written at once by the row loop, into units zeroed
// first: the same values, at the eager cost. Renders that run at the same time write disjoint
// rows whose bounds are multiples of kDepthGroupSubtileRows (bands, parts of rows), so each
// group, tile and unit has one writer during a render; queries run after renders, and fill units
// under an atomic state (several threads may query at once).
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <thread>

namespace homcull::detail {

constexpr int kDepthTileSubtilesX = 8, kDepthTileSubtilesY = 4;
constexpr int kDepthTileWidth = kDepthTileSubtilesX * kSubtileWidth;    // 64 samples
constexpr int kDepthTileHeight = kDepthTileSubtilesY * kSubtileHeight;  // 16 samples
constexpr int kDepthUnitSubtilesX = 2, kDepthUnitSubtilesY = 1;
constexpr int kDepthUnitWidth = kDepthUnitSubtilesX * kSubtileWidth;    // 16 samples
constexpr int kDepthUnitHeight = kDepthUnitSubtilesY * kSubtileHeight;  // 4 samples
static_assert(kDepthUnitWidth % kMaxSimdLanes == 0, "vectors aligned to a unit's columns never write past them");
static_assert(kDepthTileSubtilesX % kDepthUnitSubtilesX == 0 && kDepthTileSubtilesY % kDepthUnitSubtilesY == 0, "tiles of whole units");
constexpr int kDepthGroupSubtileRows = 8;
static_assert(kDepthGroupSubtileRows % kDepthTileSubtilesY == 0, "a group holds whole tiles");

// Unit states. A unit's samples are stale (last frame's) until a render writes a triangle into
// it at once (zeroed first) or a query fills it (zeroed first when stale, then its tile's list).
// Only queries fill (through filling, under an atomic compare-and-swap); renders touch only their
// own rows' units, with no query running.
constexpr std::uint8_t kDepthUnitStale = 0, kDepthUnitZeroed = 1, kDepthUnitFilling = 2, kDepthUnitFilled = 3;
constexpr std::uint32_t kNoDepthEntry = 0xFFFFFFFFu;

struct DepthTileEntry {
    std::uint32_t record;  // the record's first word in its group's arena
    std::uint32_t next;    // the tile's next entry, kNoDepthEntry at the end
    // The subtiles of the tile the record reaches, relative to the tile: columns [x0, x1], rows
    // [y0, y1]; a fill passes over the entries that miss its unit without reading the record.
    std::uint8_t x0, x1, y0, y1;
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

// A group's arena cursor and flag. Every record written moves the cursor; the bands of one render
// run on different threads, so each group's lies in a cache line of its own (side by side, the
// groups' counts shared a line that the threads took from each other at every record).
struct alignas(64) DepthGroupCursor {
    std::uint32_t words = 0, entries = 0;  // taken in the group's arena
    std::uint8_t filled = 0;               // whether a query may have filled one of its units since its rows were last reset
};

struct SampleDepthTiles;
// Applies every record of a unit's tile that reaches the unit to its samples (this instruction
// set's kernel).
using FillDepthUnitKernel = void (*)(const SampleDepthTiles& tiles, int ux, int uy);

// A buffer's per-sample depth and its bookkeeping (the arrays belong to the buffer).
struct SampleDepthTiles {
    float* depth;          // per sample, rows `stride` apart (padded by kMaxSimdLanes)
    std::size_t stride;
    int sample_height;
    int units_x, units_y, tiles_x, tiles_y, groups;
    std::uint8_t* unit_state;      // per unit, row-major
    std::uint32_t* tile_head;      // per tile, row-major: its first entry (in its group's arena)
    std::int32_t* words;           // the records, group g's from g * word_capacity
    DepthTileEntry* entries;       // group g's from g * entry_capacity
    DepthGroupCursor* group;       // per group
    std::uint32_t word_capacity, entry_capacity;
    FillDepthUnitKernel fill_unit;

    std::uint8_t& state(int ux, int uy) const { return unit_state[std::size_t(uy) * std::size_t(units_x) + std::size_t(ux)]; }
};

// Room per group: 48 words per subtile of the group's rows (a record of 8 sample rows for every
// subtile), and four entries per subtile (a large triangle takes one in every tile it crosses).
// Fuller groups write at once.
inline std::uint32_t depth_word_capacity(int subtiles_x) { return std::uint32_t(subtiles_x) * kDepthGroupSubtileRows * 48 + 1024; }
inline std::uint32_t depth_entry_capacity(int subtiles_x) { return std::uint32_t(subtiles_x) * kDepthGroupSubtileRows * 4 + 256; }

// Forgets what subtile rows [row_begin, row_end) held: their units stale, their tiles' lists and
// the arenas of their groups empty (row_begin a multiple of kDepthGroupSubtileRows; row_end too,
// or the last row).
inline void reset_sample_depth_rows(const SampleDepthTiles& t, int row_begin, int row_end) {
    if (!t.unit_state || row_begin >= row_end) return;
    const int unit_row_end = std::min(t.units_y, (row_end + kDepthUnitSubtilesY - 1) / kDepthUnitSubtilesY);
    for (int uy = row_begin / kDepthUnitSubtilesY; uy < unit_row_end; ++uy)
        std::fill_n(t.unit_state + std::size_t(uy) * std::size_t(t.units_x), t.units_x, kDepthUnitStale);
    const int tile_row_end = std::min(t.tiles_y, (row_end + kDepthTileSubtilesY - 1) / kDepthTileSubtilesY);
    for (int ty = row_begin / kDepthTileSubtilesY; ty < tile_row_end; ++ty)
        std::fill_n(t.tile_head + std::size_t(ty) * std::size_t(t.tiles_x), t.tiles_x, kNoDepthEntry);
    const int group_end = std::min(t.groups, (row_end + kDepthGroupSubtileRows - 1) / kDepthGroupSubtileRows);
    for (int g = row_begin / kDepthGroupSubtileRows; g < group_end; ++g) t.group[g] = DepthGroupCursor{};
}

// Zeroes a unit's samples (the last column of units ends at the rows' padding).
inline void zero_depth_unit(const SampleDepthTiles& t, int ux, int uy) {
    const int row_end = std::min(t.sample_height, (uy + 1) * kDepthUnitHeight);
    const std::size_t x0 = std::size_t(ux) * kDepthUnitWidth, width = std::min<std::size_t>(kDepthUnitWidth, t.stride - x0);
    for (int row = uy * kDepthUnitHeight; row < row_end; ++row) std::fill_n(t.depth + std::size_t(row) * t.stride + x0, width, 0.0f);
}

// Calls visit(record) for every record of unit (ux, uy)'s tile that reaches the unit.
template <typename Visit>
void for_each_in_depth_unit(const SampleDepthTiles& t, int ux, int uy, Visit&& visit) {
    constexpr int kUnitsX = kDepthTileSubtilesX / kDepthUnitSubtilesX, kUnitsY = kDepthTileSubtilesY / kDepthUnitSubtilesY;
    const int tx = ux / kUnitsX, ty = uy / kUnitsY;
    const int x0 = (ux % kUnitsX) * kDepthUnitSubtilesX, x1 = x0 + kDepthUnitSubtilesX - 1;
    const int y0 = (uy % kUnitsY) * kDepthUnitSubtilesY, y1 = y0 + kDepthUnitSubtilesY - 1;
    const int group = ty * kDepthTileSubtilesY / kDepthGroupSubtileRows;
    const std::int32_t* words = t.words + std::size_t(group) * t.word_capacity;
    const DepthTileEntry* entries = t.entries + std::size_t(group) * t.entry_capacity;
    for (std::uint32_t e = t.tile_head[std::size_t(ty) * std::size_t(t.tiles_x) + std::size_t(tx)]; e != kNoDepthEntry;) {
        const DepthTileEntry& entry = entries[e];
        if (entry.x0 <= x1 && entry.x1 >= x0 && entry.y0 <= y1 && entry.y1 >= y0) visit(words + entry.record);
        e = entry.next;
    }
}

// A record's header and intervals.
inline DepthRowsRecord depth_record_header(const std::int32_t* record) {
    DepthRowsRecord r;
    std::memcpy(&r, record, sizeof r);
    return r;
}
inline const std::int32_t* depth_record_first(const std::int32_t* record) { return record + kDepthRecordHeaderWords; }
inline const std::int32_t* depth_record_last(const std::int32_t* record, int rows) { return record + kDepthRecordHeaderWords + rows; }

// Makes unit (ux, uy) hold its samples' depth before a query reads it: fills it (zeroed first
// when stale), or waits while another thread fills it.
inline void ensure_depth_unit(const SampleDepthTiles& t, int ux, int uy) {
    std::uint8_t* state = &t.state(ux, uy);
    // C++17 has no atomic_ref, and the states live in the buffer's plain arrays (resized with
    // the buffer, which std::atomic elements cannot be): the GCC and Clang builtins, as
    // std::atomic_ref would compile to.
    for (;;) {
        std::uint8_t seen = __atomic_load_n(state, __ATOMIC_ACQUIRE);
        if (seen == kDepthUnitFilled) return;
        if (seen == kDepthUnitFilling) {
            std::this_thread::yield();
            continue;
        }
        if (__atomic_compare_exchange_n(state, &seen, kDepthUnitFilling, false, __ATOMIC_ACQUIRE, __ATOMIC_ACQUIRE)) {
            // Written once per group and frame: a store per fill would bounce the line between
            // the querying threads.
            std::uint8_t* filled = &t.group[uy * kDepthUnitSubtilesY / kDepthGroupSubtileRows].filled;
            if (!__atomic_load_n(filled, __ATOMIC_RELAXED)) __atomic_store_n(filled, std::uint8_t(1), __ATOMIC_RELAXED);
            if (seen == kDepthUnitStale) zero_depth_unit(t, ux, uy);
            t.fill_unit(t, ux, uy);
            __atomic_store_n(state, kDepthUnitFilled, __ATOMIC_RELEASE);
            return;
        }
    }
}

// The unit of subtile (tx, ty), made ready (ensure_depth_unit).
inline void ensure_depth_subtile(const SampleDepthTiles& t, int tx, int ty) {
    ensure_depth_unit(t, tx / kDepthUnitSubtilesX, ty / kDepthUnitSubtilesY);
}

// Every unit made ready (read-backs of the whole per-sample depth).
inline void ensure_all_depth_units(const SampleDepthTiles& t) {
    for (int uy = 0; uy < t.units_y; ++uy)
        for (int ux = 0; ux < t.units_x; ++ux) ensure_depth_unit(t, ux, uy);
}

// Whether a triangle about to be drawn into subtile rows [ty0, ty1] goes into the tiles' lists
// (record_sample_depth with each chunk's intervals): whether every group's arena it reaches has
// room (a large triangle takes an entry in each of its tiles, which costs less than writing its
// samples: most lie in units no query reads). Otherwise the row loop writes it at once, and this
// zeroes its stale units first.
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
        room = t.group[group].words + words <= t.word_capacity && t.group[group].entries + entries <= t.entry_capacity;
    }
    if (room) return true;
    const int ux0 = tri.i0 / kDepthUnitWidth, ux1 = std::min(t.units_x - 1, tri.i1 / kDepthUnitWidth);
    for (int uy = ty0 / kDepthUnitSubtilesY; uy <= ty1 / kDepthUnitSubtilesY; ++uy)
        for (int ux = ux0; ux <= ux1; ++ux) {
            std::uint8_t& state = t.state(ux, uy);
            if (state == kDepthUnitStale) zero_depth_unit(t, ux, uy), state = kDepthUnitZeroed;
        }
    return false;
}

// Lists the sample rows [row0, row0 + rows) of a triangle being drawn (list_sample_depth said so)
// with their intervals [first[r], last[r]] within columns [i0, i1]: a record in each group's arena
// the rows with samples reach, and an entry in each of their tiles' lists. Units already filled
// (a query read them since the frame began) take the record at once through
// apply(record, ux, uy).
template <typename Apply>
void record_sample_depth(const SampleDepthTiles& t, const PreparedTriangle& plane, int i0, int i1, int row0, int rows,
                         const std::int32_t* first, const std::int32_t* last, Apply&& apply) {
    constexpr int kGroupRows = kDepthGroupSubtileRows * kSubtileHeight;
    int begin = 0, end = rows;  // the rows with samples
    while (begin < end && first[begin] > last[begin]) ++begin;
    while (end > begin && first[end - 1] > last[end - 1]) --end;
    const int sx0 = i0 / kSubtileWidth, sx1 = std::min(t.units_x * kDepthUnitSubtilesX - 1, i1 / kSubtileWidth);  // subtile columns
    const bool one_tile_column = sx0 / kDepthTileSubtilesX == sx1 / kDepthTileSubtilesX;
    for (int r = begin; r < end;) {
        const int row = row0 + r, group = row / kGroupRows;
        const int n = std::min(end - r, (group + 1) * kGroupRows - row);
        DepthGroupCursor& cursor = t.group[group];
        const bool any_filled = cursor.filled != 0;
        std::int32_t* words = t.words + std::size_t(group) * t.word_capacity;
        const std::uint32_t record = cursor.words;
        cursor.words = record + kDepthRecordHeaderWords + 2 * std::uint32_t(n);
        const DepthRowsRecord header{plane, row, n};
        std::memcpy(words + record, &header, sizeof header);
        std::memcpy(words + record + kDepthRecordHeaderWords, first + r, sizeof(std::int32_t) * std::size_t(n));
        std::memcpy(words + record + kDepthRecordHeaderWords + n, last + r, sizeof(std::int32_t) * std::size_t(n));
        DepthTileEntry* entries = t.entries + std::size_t(group) * t.entry_capacity;
        for (int ty = row / kDepthTileHeight; ty <= (row + n - 1) / kDepthTileHeight; ++ty) {
            // The entries of a tile row reach the subtiles its rows' intervals hold, not the
            // triangle's bounding box: a fill visits only records that may write its unit (on
            // the walks, two thirds to four fifths of those it visited wrote nothing there).
            // Rows without samples (first > last) only widen the bounds, which stay within the
            // triangle's columns: no branch per row. A triangle within one tile column keeps its
            // bounding box (its scan would cost more than the visits it saves).
            const int tile_row_begin = std::max(row, ty * kDepthTileHeight), tile_row_end = std::min(row + n, (ty + 1) * kDepthTileHeight);
            int lo = i0, hi = i1;
            if (!one_tile_column) {
                lo = i1, hi = i0;
                for (int k = tile_row_begin - row0; k < tile_row_end - row0; ++k) lo = std::min(lo, first[k]), hi = std::max(hi, last[k]);
            }
            const int cx0 = std::max(sx0, lo / kSubtileWidth), cx1 = std::min(sx1, hi / kSubtileWidth);
            const int sy0 = tile_row_begin / kSubtileHeight, sy1 = (tile_row_end - 1) / kSubtileHeight;  // subtile rows
            for (int tx = cx0 / kDepthTileSubtilesX; tx <= cx1 / kDepthTileSubtilesX; ++tx) {
                const int bx0 = tx * kDepthTileSubtilesX, by0 = ty * kDepthTileSubtilesY;
                const int x0 = std::max(cx0, bx0), x1 = std::min(cx1, bx0 + kDepthTileSubtilesX - 1);
                const int y0 = std::max(sy0, by0), y1 = std::min(sy1, by0 + kDepthTileSubtilesY - 1);
                const std::uint32_t e = cursor.entries++;
                std::uint32_t& head = t.tile_head[std::size_t(ty) * std::size_t(t.tiles_x) + std::size_t(tx)];
                entries[e] = {record, head, std::uint8_t(x0 - bx0), std::uint8_t(x1 - bx0), std::uint8_t(y0 - by0), std::uint8_t(y1 - by0)};
                head = e;
                if (!any_filled) continue;
                for (int uy = y0 / kDepthUnitSubtilesY; uy <= y1 / kDepthUnitSubtilesY; ++uy)  // units whose fill is past
                    for (int ux = x0 / kDepthUnitSubtilesX; ux <= x1 / kDepthUnitSubtilesX; ++ux)
                        if (t.state(ux, uy) == kDepthUnitFilled) apply(words + record, ux, uy);
            }
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
// intervals within the unit, kept where larger (update_sample_depth's operations).
void apply_depth_record_reference(const SampleDepthTiles& t, const std::int32_t* record, int ux, int uy);
void fill_depth_unit_reference(const SampleDepthTiles& t, int ux, int uy);

}  // namespace homcull::detail
