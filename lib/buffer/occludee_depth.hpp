#pragma once
// An occludee triangle's depth bound over a subtile's covered samples, and the test of one
// subtile row of an occludee triangle against the buffer's layers (OcclusionBuffer::
// test_triangles, occludee_triangles.cpp): a scalar reference and a SIMD kernel, a subtile per
// lane (occludee_rows_simd.cpp), which give the same masks and the same answers.
#include "buffer/raised_vertex_plane.hpp"
#include "buffer/rect_queries.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cstdint>

namespace homcull::detail {

// An upper bound of the triangle's 1/w at a sample, or over a rectangle of samples: the
// smaller of two bounds, each evaluated at the rectangle's corner where it is largest.
struct OccludeeDepth {
    static constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    PreparedTriangle plane{};   // usable when plane.has_plane
    float error = 0.0f;         // plane.error plus plane_error's absolute part, rounded up
    float z_vertex_max = 0.0f;  // the nearest vertex, rounded up
    float plane_raise = 1.0f;   // 1 + plane_error's relative part, rounded up
    float raise = 1.0f;         // final relative raise, rounded up: 1 + 2^-20 + the w rounding
    RaisedVertexPlane raised{};  // usable when raised.usable; evaluated in double

    // The plane-error bound at one sample.
    float plane_bound(int column, int row) const {
        float bound = z_vertex_max;
        if (plane.has_plane) {
            const float x = float(column) + 0.5f, y = float(row) + 0.5f;
            bound = std::min(bound, (((plane.a + plane.dzdy * y) + plane.dzdx * x) + error) * plane_raise);
        }
        return bound * raise;
    }
    // The raised-vertex bound at one sample, with the relative 2^-20 of `raise` for the ray's
    // rounding, rounded up to float.
    float raised_bound(int column, int row) const {
        return raised.usable ? float_up(raised.at(column, row) * (1.0 + 0x1.0p-20)) : HUGE_VALF;
    }
    float at(int column, int row) const { return std::min(plane_bound(column, row), raised_bound(column, row)); }
    // Over the samples of subtile (tx, ty) within the columns and rows of `c`.
    float over(int tx, int ty, const SubtileCoverage& c) const {
        const bool far_is_left = plane.has_plane && plane.far_is_left, far_is_top = plane.has_plane && plane.far_is_top;
        const float by_plane = plane_bound(tx * kW + (far_is_left ? c.column_hi : c.column_lo), ty * kH + (far_is_top ? c.row_hi : c.row_lo));
        const float by_vertices = raised_bound(tx * kW + (raised.dzdx > 0.0 ? c.column_hi : c.column_lo),
                                               ty * kH + (raised.dzdy > 0.0 ? c.row_hi : c.row_lo));
        return std::min(by_plane, by_vertices);
    }
};

// For the subtiles tx_begin + k, k in [0, count), of subtile row ty, whose sample rows hold the
// intervals [first[j], last[j]]: masks[k], the triangle's samples there (subtile_coverage), and
// unhidden[k], those of them the layers do not hide at depth.over (subtile_unhidden_samples).
// The kernels write up to kMaxSimdLanes entries past count.
// The samples of coverage `c` of subtile (tx, ty) that the layers do not hide at depth.over:
// what the row kernel computes per lane, and count_triangle per subtile of a narrow row.
inline std::uint32_t occludee_unhidden(const SubtileView& view, int tx, int ty, const SubtileCoverage& c, const OccludeeDepth& depth) {
    return c.mask ? subtile_unhidden_samples(view, tx, ty, c.mask, depth.over(tx, ty, c)) : 0u;
}

// What the row kernel tells of a run beside its masks: the covered samples of all its subtiles
// and whether any subtile has samples the layers leave unhidden. A run without any is counted
// at once, without a look at each subtile: most runs, as most of the triangles tested row by
// row are hidden (about two thirds of them on oa_thor's walk).
struct OccludeeRowSummary {
    std::uint32_t samples = 0;
    bool any_unhidden = false;
};

// What the kernel computes, subtile by subtile (Highway's one-lane target runs this).
inline OccludeeRowSummary occludee_row_reference(const SubtileView& view, int ty, const std::int32_t first[4], const std::int32_t last[4],
                                                 int tx_begin, int count, const OccludeeDepth& depth, std::uint32_t* masks,
                                                 std::uint32_t* unhidden) {
    OccludeeRowSummary summary;
    for (int k = 0; k < count; ++k) {
        const SubtileCoverage c = subtile_coverage(first, last, tx_begin + k);
        masks[k] = c.mask;
        unhidden[k] = occludee_unhidden(view, tx_begin + k, ty, c, depth);
        summary.samples += bit_count(c.mask);
        summary.any_unhidden = summary.any_unhidden || unhidden[k] != 0;
    }
    return summary;
}
using OccludeeRowKernel = OccludeeRowSummary (*)(const SubtileView& view, int ty, const std::int32_t first[4], const std::int32_t last[4],
                                                 int tx_begin, int count, const OccludeeDepth& depth, std::uint32_t* masks,
                                                 std::uint32_t* unhidden);
// (A SIMD kernel: BufferKernels::occludee_row.)

// Of the samples `unhidden` of subtile (tx, ty), those the per-sample depth (view.sample_depth,
// which must be non-null) does not hide either: the triangle's bound at the sample itself
// (depth.at) against the occluders' depth there. The reference, sample by sample.
inline std::uint32_t sample_depth_unhidden_reference(const SubtileView& view, int tx, int ty, std::uint32_t unhidden,
                                                     const OccludeeDepth& depth) {
    constexpr int kW = OccludeeDepth::kW;
    std::uint32_t left = 0;
    for (std::uint32_t bits = unhidden; bits != 0; bits &= bits - 1) {
        const int bit = __builtin_ctz(bits);
        const int x = tx * kW + bit % kW, y = ty * OccludeeDepth::kH + bit / kW;
        if (!(depth.at(x, y) < view.sample_depth[std::size_t(y) * view.sample_stride + std::size_t(x)])) left |= 1u << bit;
    }
    return left;
}
// The same with a sample per SIMD lane (BufferKernels::sample_depth_unhidden): the same bits.
using SampleDepthUnhiddenKernel = std::uint32_t (*)(const SubtileView& view, int tx, int ty, std::uint32_t unhidden,
                                                    const OccludeeDepth& depth);

}  // namespace homcull::detail
