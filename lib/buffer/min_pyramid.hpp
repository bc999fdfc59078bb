#pragma once
// Min pyramids stored level after level in one array (the buffer's farthest-d0 pyramid over
// subtiles, the occlusion maps' hzb and nbz over pixels): level k + 1 holds the minimum of
// 2 x 2 cells of level k. The pruned range search of Greene, Kass, Miller, "Hierarchical
// Z-buffer visibility" (SIGGRAPH 1993), shared by both.
#include <homcull/occlusion_buffer.hpp>

#include <algorithm>
#include <cstddef>

namespace homcull::detail {

// One level of a pyramid stored level after level in one array: width x height cells from
// `offset` on, row-major.
struct PyramidLevel {
    int width, height;
    std::size_t offset;
};

// Cells [begin, end) of a row of the level above, from rows row0 and row1 of the level below
// (row1 = row0 at an odd bottom edge), whose rows are below_width cells long: each the minimum
// of its 2 x 2 children (a missing right child repeats the left one). The one reduction of
// every min pyramid (the maps' SIMD kernel computes the same minima in lanes).
inline void reduce_min_row(const float* row0, const float* row1, int begin, int end, int below_width, float* out) {
    for (int x = begin; x < end; ++x) {
        const std::size_t a = std::size_t(2 * x), b = std::size_t(std::min(2 * x + 1, below_width - 1));
        out[x] = std::min(std::min(row0[a], row0[b]), std::min(row1[a], row1[b]));
    }
}

// Whether every level-0 cell of [x0, x1] x [y0, y1] under cell (x, y) of level k holds more
// than d: a cell whose minimum is above d is done; one inside the range whose minimum is not
// above d contains such a cell.
inline bool min_pyramid_above(const float* data, const PyramidLevel* levels, int k, int x, int y, int x0, int y0, int x1, int y1,
                              float d) {
    const int cx0 = x << k, cy0 = y << k, cx1 = ((x + 1) << k) - 1, cy1 = ((y + 1) << k) - 1;
    if (cx1 < x0 || cx0 > x1 || cy1 < y0 || cy0 > y1) return true;
    const PyramidLevel& l = levels[k];
    if (data[l.offset + std::size_t(y) * std::size_t(l.width) + std::size_t(x)] > d) return true;
    if (k == 0 || (cx0 >= x0 && cx1 <= x1 && cy0 >= y0 && cy1 <= y1)) return false;
    const PyramidLevel& below = levels[k - 1];
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
            if (2 * x + dx < below.width && 2 * y + dy < below.height &&
                !min_pyramid_above(data, levels, k - 1, 2 * x + dx, 2 * y + dy, x0, y0, x1, y1, d))
                return false;
    return true;
}

// The lowest level (below `level_count`) where [x0, x1] x [y0, y1] (0 <= x0 <= x1, 0 <= y0 <=
// y1) spans at most 2 x 2 cells: coarse_level_by_search's answer without the search. With span
// the larger of x1 - x0 and y1 - y0, and b = floor(log2(span)) (0 for a span below 2): at a level
// k < b a cell is at most span / 2 wide, so the range spans 3 cells or more; at b + 1 a cell is
// wider than span, so it spans at most 2. So the level is b or b + 1 (one test), capped. (A
// search level by level takes a variable shift per level, which single test_rect calls paid
// for; the batches' SIMD coarse stage still counts the levels, one vector op per level for 16
// rectangles.)
inline int coarse_level(int x0, int x1, int y0, int y1, int level_count) {
    const unsigned span = unsigned(std::max(x1 - x0, y1 - y0));
    int k = 0;
#if defined(__GNUC__) || defined(__clang__)
    k = 31 - __builtin_clz(span | 1u);  // 0 for a span of 0 or 1
#else
    for (unsigned s = span; s >= 2; s >>= 1) ++k;
#endif
    // Without a branch: whether b or b + 1 is about even on S1's rectangles, and a branch on
    // it was mispredicted often enough to be most of this function's cost on single test_rect calls.
    k += int(((x1 >> k) - (x0 >> k) > 1) | ((y1 >> k) - (y0 >> k) > 1));
    return std::min(k, level_count - 1);
}

// Whether every level-0 cell of [x0, x1] x [y0, y1] holds more than d, searched from the
// coarse level down.
inline bool min_pyramid_range_above(const float* data, const PyramidLevel* levels, int level_count, int x0, int y0, int x1, int y1,
                                    float d) {
    const int k = coarse_level(x0, x1, y0, y1, level_count);
    for (int y = y0 >> k; y <= y1 >> k; ++y)
        for (int x = x0 >> k; x <= x1 >> k; ++x)
            if (!min_pyramid_above(data, levels, k, x, y, x0, y0, x1, y1, d)) return false;
    return true;
}

}  // namespace homcull::detail
