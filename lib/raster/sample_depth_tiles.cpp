#include "raster/sample_depth_tiles.hpp"

#include <algorithm>
#include <atomic>

namespace homcull::detail {

namespace {
std::atomic<bool> deferred{true};
}  // namespace

void set_deferred_sample_depth(bool enabled) { deferred = enabled; }
bool deferred_sample_depth_enabled() { return deferred; }

void apply_depth_record_reference(const SampleDepthTiles& t, const std::int32_t* record, int ux, int uy) {
    const DepthRowsRecord r = depth_record_header(record);
    const std::int32_t *first = depth_record_first(record), *last = depth_record_last(record, r.rows);
    const int x0 = ux * kDepthUnitWidth, x1 = x0 + kDepthUnitWidth - 1;
    const int begin = std::max(r.row0, uy * kDepthUnitHeight), end = std::min({r.row0 + r.rows, (uy + 1) * kDepthUnitHeight, t.sample_height});
    for (int row = begin; row < end; ++row) {
        float* depth = t.depth + std::size_t(row) * t.stride;
        const int k = row - r.row0;
        for (int x = std::max(first[k], x0); x <= std::min(last[k], x1); ++x) depth[x] = std::max(depth[x], conservative_depth(r.plane, x, row));
    }
}

void fill_depth_unit_reference(const SampleDepthTiles& t, int ux, int uy) {
    for_each_in_depth_unit(t, ux, uy, [&](const std::int32_t* record) { apply_depth_record_reference(t, record, ux, uy); });
}

}  // namespace homcull::detail
