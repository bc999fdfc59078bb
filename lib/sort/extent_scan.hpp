#pragma once
// The inner loop of the extent trees' queries: which of a leaf's extents overlap a query box
// and lie nearer than a distance. A scalar reference and a SIMD kernel per instruction set
// (common/isa_choice.hpp); both write the matching ids in the columns' order, so every
// instruction set gives the same candidates in the same order.
#include "common/isa_choice.hpp"

#include <cstdint>

namespace homcull::sort_detail {

struct Extent {
    float lo[3], hi[3];  // the direction box: components of the unit directions to the object
    float nearest = 0;   // distance from the eye to the bounding sphere (0 when it holds the eye)
};

// Whether two extents' boxes overlap (the nearest distances aside).
inline bool boxes_overlap(const Extent& a, const Extent& b) {
    for (int k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
    return true;
}

// Extents as structure of arrays. Every column holds at least kExtentColumnPadding entries
// past the last extent (any values): a kernel may load whole vectors there and masks them off.
inline constexpr std::uint32_t kExtentColumnPadding = 64;
struct ExtentColumns {
    const float* lo[3];
    const float* hi[3];
    const float* nearest;
    const std::uint32_t* ids;
};

// Writes to `out` the ids of extents [first, first + count) with nearest < farthest whose box
// overlaps `box` (as boxes_overlap), in order; returns how many. `out` has room for count +
// kExtentColumnPadding ids (a kernel may store whole vectors past the last id it keeps).
using ExtentScan = std::uint32_t (*)(const ExtentColumns& columns, std::uint32_t first, std::uint32_t count, const Extent& box,
                                     float farthest, std::uint32_t* out);

std::uint32_t extent_scan_reference(const ExtentColumns& columns, std::uint32_t first, std::uint32_t count, const Extent& box,
                                    float farthest, std::uint32_t* out);

// The scan for an instruction set choice (the reference for the scalar choice).
ExtentScan extent_scan_for(const detail::IsaChoice& choice);

}  // namespace homcull::sort_detail
