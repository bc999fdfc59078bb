#pragma once
// The occlusion maps' state and the implementation of their calls. homcull/occlusion_maps.hpp
// states the contracts and OcclusionMaps forwards each call here (occlusion_maps_calls.cpp).
// Private to the library.
#include <homcull/occlusion_maps.hpp>

#include "buffer/min_pyramid.hpp"

#include <cstdint>
#include <vector>

namespace homcull::detail {

struct MapKernels;
struct RectQuery;

class MapsState {
public:
    // The calls of OcclusionMaps, with its contracts.
    MapsState(const OcclusionBuffer& buffer, const OcclusionMapsConfig& config);
    void clear();
    void set_near_w(float near_w);
    void add_occluder_box(const Aabb& box, const std::array<float, 16>& model_to_clip);
    void build(const OcclusionBuffer& buffer);
    OccludeeAnswer test_rect(const ScreenRect& rect) const;
    OccludeeAnswer test_aabb(const Aabb& box, const std::array<float, 16>& model_to_clip) const;
    OccludeeAnswer test_aabb_by_rectangle(const Aabb& box, const std::array<float, 16>& model_to_clip) const;
    double hole_budget() const;
    OccludeeAnswer test_rect_within(const ScreenRect& rect, double& budget) const;
    // test_rect_within's work, for callers already under a StandardFloatMode (each guard reads
    // MXCSR, a few nanoseconds of every box test).
    OccludeeAnswer answer_rect(const ScreenRect& rect, double& budget) const;
    const OcclusionMapsConfig& config() const { return config_; }
    int levels() const { return int(levels_.size()); }
    int level_width(int k) const { return levels_[std::size_t(k)].width; }
    int level_height(int k) const { return levels_[std::size_t(k)].height; }
    const std::uint32_t* covered_samples(int k) const { return need_pyramid(), covered_.data() + levels_[std::size_t(k)].offset; }
    std::uint32_t cell_samples(int k, int x, int y) const;
    float opacity(int k, int x, int y) const;
    double opacity_threshold(int k) const { return opacity_threshold_[std::size_t(k)]; }
    double transparency_threshold(int k) const { return transparency_threshold_[std::size_t(k)]; }
    const float* farthest_depth(int k) const { return need_pyramid(), hzb_.empty() ? nullptr : hzb_.data() + levels_[std::size_t(k)].offset; }
    const float* nearest_depth(int k) const { return need_pyramid(), nbz_.empty() ? nullptr : nbz_.data() + levels_[std::size_t(k)].offset; }
    const std::vector<float>& depth_estimation() const { return deb_; }
    float plane_depth() const { return need_pyramid(), plane_; }
    void build_pyramid();

    using Level = detail::PyramidLevel;
    OcclusionMapsConfig config_;
    const OcclusionBuffer* built_ = nullptr;     // the buffer of the last build()
    // PyramidBuild::lazy where the buffer's depth test decides alone (conservative, masked):
    // build() then makes covered_sums_ instead of the pyramids, until build_pyramid().
    bool buffer_decides_ = false;
    bool pyramid_built_ = false;
    // Covered samples summed over subtiles [0, tx) x [0, ty), at ty * (subtiles_x + 1) + tx.
    std::vector<std::uint32_t> covered_sums_;
    int sums_width_ = 0;
    const MapKernels* built_with_ = nullptr;     // the kernels it ran: its buffer's instruction set's
    int width_ = 0, height_ = 0, samples_ = 1;  // buffer pixels and samples per axis
    float near_w_ = 0.1f;
    double samples_per_display_pixel_ = 1.0;
    std::vector<Level> levels_;
    std::vector<std::uint32_t> covered_;
    std::vector<float> hzb_, nbz_, deb_;
    float plane_ = 0.0f;
    std::vector<double> opacity_threshold_, transparency_threshold_;
    int start_max_level_ = 0;

    // The samples of cell (x, y) of level k, clipped to the buffer: [x0, x1] x [y0, y1].
    struct CellSpan {
        int x0, x1, y0, y1;
    };
    CellSpan cell_span(int k, int x, int y) const;
    struct OverlapQuery;
    bool overlap_cell(OverlapQuery& q, int k, int x, int y) const;
    void overlap(int i0, int i1, int j0, int j1, double budget, OccludeeAnswer& answer, double& uncovered) const;
    bool depth_hidden(int i0, int i1, int j0, int j1, float d_near) const;
    void make_pyramid();
    void need_pyramid() const;  // throws unless pyramid_built_
    void sum_covered_samples();
    std::uint64_t uncovered_by_sums(int i0, int i1, int j0, int j1) const;  // from covered_sums_ and the border subtiles' masks
    OccludeeAnswer buffer_answer(const RectQuery& q) const;
    const OcclusionBuffer& built() const;
};

}  // namespace homcull::detail
