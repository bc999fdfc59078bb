// Hierarchical occlusion maps: the opacity pyramid and the hierarchical overlap test (Zhang
// 1998, ch. 5), and the answers that combine overlap and depth. The depth maps are in
// occlusion_maps_depth.cpp.
//
// The pyramid stores covered-sample counts, not averaged opacities: level k + 1 sums 2 x 2
// cells of level k, so a cell's opacity is exactly its covered share (the 2 x 2 average where
// all four children exist, the area-weighted one at odd borders), and the overlap test can
// reason with whole samples: a cell with n samples, c covered, of which r lie in the
// rectangle, leaves between max(0, r - c) and min(r, n - c) uncovered samples in it.
#include <homcull/error.hpp>
#include <homcull/occlusion_maps.hpp>

#include "buffer/buffer_kernels.hpp"
#include "buffer/buffer_state.hpp"
#include "buffer/exact_view_test.hpp"
#include "hom/map_kernels.hpp"
#include "hom/maps_state.hpp"
#include "common/float_mode.hpp"
#include "hom/opacity_pyramid.hpp"
#include "buffer/rect_queries.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

}  // namespace

detail::MapsState::MapsState(const OcclusionBuffer& buffer, const OcclusionMapsConfig& config) : config_(config) {
    if (buffer.config().orthographic) throw Error("occlusion maps: orthographic buffers are not supported (their depth maps would need clip z)");
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const BufferConfig& b = buffer.config();
    width_ = b.width;
    height_ = b.height;
    samples_ = b.samples;
    near_w_ = b.near_w;
    if (config.display_width < 1 || config.display_height < 1)
        throw Error("occlusion maps: the display resolution must be at least 1x1");
    if (!(config.hole_pixels >= 0.0) || !std::isfinite(config.hole_pixels))
        throw Error("occlusion maps: the hole size must be a finite number of pixels >= 0");
    if (!(config.distribution >= 1.0 && config.distribution <= 4.0))
        throw Error("occlusion maps: the distribution factor D must be in [1, 4]");
    if (!(config.transparency >= 0.0 && config.transparency < 1.0))
        throw Error("occlusion maps: the transparency threshold must be in [0, 1)");
    if (config.min_size < 1) throw Error("occlusion maps: the minimum pyramid size must be at least 1");
    if (config.depth_pyramids != DepthPyramids::needed && config.depth_pyramids != DepthPyramids::both)
        throw Error("occlusion maps: depth_pyramids must be DepthPyramids::needed or ::both");
    if (config.deb_width < 1 || config.deb_height < 1 || config.deb_width > 4096 || config.deb_height > 4096)
        throw Error("occlusion maps: the depth estimation buffer must have 1 to 4096 cells per axis");

    std::size_t size = 0;
    int w = width_, h = height_;
    for (;;) {
        levels_.push_back({w, h, size});
        size += std::size_t(w) * std::size_t(h);
        if (w <= config.min_size && h <= config.min_size) break;
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    const int last = int(levels_.size()) - 1;
    if (config.finest_level < 0 || config.finest_level > last)
        throw Error("occlusion maps: finest level " + std::to_string(config.finest_level) + " outside the pyramid's 0.." +
                    std::to_string(last));
    start_max_level_ = config.coarsest_level == -1 ? last : config.coarsest_level;
    if (start_max_level_ < config.finest_level || start_max_level_ > last)
        throw Error("occlusion maps: coarsest level must be -1 (the last) or in [finest level, " + std::to_string(last) + "], got " +
                    std::to_string(config.coarsest_level));
    covered_.assign(size, 0u);
    const bool both = config.depth_pyramids == DepthPyramids::both;
    if (both || config.depth == DepthTest::hzb || config.depth == DepthTest::plane) hzb_.assign(size, 0.0f);
    if (both || config.depth == DepthTest::nbz) nbz_.assign(size, 0.0f);
    deb_.assign(std::size_t(config.deb_width) * std::size_t(config.deb_height), INFINITY);
    buffer_decides_ = config.pyramid == PyramidBuild::lazy && config.hole_pixels == 0.0 && config.depth == DepthTest::masked;
    if (config.pyramid != PyramidBuild::lazy && config.pyramid != PyramidBuild::always)
        throw Error("occlusion maps: pyramid must be PyramidBuild::lazy or ::always");
    if (buffer_decides_) {
        sums_width_ = buffer.subtiles_x() + 1;
        covered_sums_.assign(std::size_t(sums_width_) * std::size_t(buffer.subtiles_y() + 1), 0u);
    }

    // Display pixels per buffer pixel (m0 x m0) and samples per display pixel (area).
    const double m0x = double(config.display_width) / double(width_), m0y = double(config.display_height) / double(height_);
    samples_per_display_pixel_ = double(buffer.sample_width()) * double(buffer.sample_height()) /
                                 (double(config.display_width) * double(config.display_height));
    // Zhang 5.4: T0 = 1 - D L / (4 m0^2), T(k+1) = 1 - D (1 - Tk) / 4; transparency
    // t(k+1) = D tk / 4. With L = 0 every opacity threshold is 1: only full cells are opaque.
    const bool approximate = config.hole_pixels > 0.0;
    double opacity = 1.0 - config.distribution * config.hole_pixels / (4.0 * m0x * m0y);
    double transparency = approximate ? config.transparency : 0.0;
    for (std::size_t k = 0; k < levels_.size(); ++k) {
        opacity_threshold_.push_back(std::clamp(opacity, 0.0, 1.0));
        transparency_threshold_.push_back(transparency);
        opacity = 1.0 - config.distribution * (1.0 - opacity) / 4.0;
        transparency = config.distribution * transparency / 4.0;
    }
}

detail::MapsState::CellSpan detail::MapsState::cell_span(int k, int x, int y) const {
    return {(x << k) * samples_, std::min((x + 1) << k, width_) * samples_ - 1, (y << k) * samples_,
            std::min((y + 1) << k, height_) * samples_ - 1};
}

std::uint32_t detail::MapsState::cell_samples(int k, int x, int y) const {
    const CellSpan c = cell_span(k, x, y);
    return std::uint32_t(c.x1 - c.x0 + 1) * std::uint32_t(c.y1 - c.y0 + 1);
}

float detail::MapsState::opacity(int k, int x, int y) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    need_pyramid();
    const Level& l = levels_[std::size_t(k)];
    return float(covered_[l.offset + std::size_t(y) * std::size_t(l.width) + std::size_t(x)]) / float(cell_samples(k, x, y));
}

void detail::MapsState::build(const OcclusionBuffer& buffer) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    if (buffer.config().width != width_ || buffer.config().height != height_ || buffer.config().samples != samples_)
        throw Error("occlusion maps: build() needs a buffer shaped like the one the maps were made for");
    built_ = &buffer;
    pyramid_built_ = false;
    if (buffer_decides_) {
        built_with_ = &detail::map_kernels(*buffer.state().isa_);
        sum_covered_samples();
        return;
    }
    make_pyramid();
}

void detail::MapsState::build_pyramid() {
    if (!pyramid_built_) make_pyramid();  // built() throws before the first build()
}

void detail::MapsState::need_pyramid() const {
    if (!pyramid_built_)
        throw Error(built_ ? "occlusion maps: the pyramids were left out (PyramidBuild::lazy): call build_pyramid() first"
                           : "occlusion maps: read before build()");
}

void detail::MapsState::make_pyramid() {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const OcclusionBuffer& buffer = built();
    // Level 0: per buffer pixel, its covered samples, and the farthest and nearest bound of
    // those samples (a sample in a subtile's working mask is bounded by max(d0, d1), any
    // other by d0; see OcclusionBuffer). Pixels without covered samples get +inf ("no
    // occluder"): the depth maps ignore the background, the overlap test decides coverage.
    // Depth pyramids not made (depth_pyramids) are null here: the kernels skip them.
    float* const hzb = hzb_.empty() ? nullptr : hzb_.data();
    float* const nbz = nbz_.empty() ? nullptr : nbz_.data();
    const detail::BufferState& state = buffer.state();
    const detail::Level0Maps level0{state.covered_.data(), state.mask_.data(), state.d0_.data(), state.d1_.data(),
                                    state.stride_,         buffer.subtiles_x(), buffer.subtiles_y(), width_,
                                    height_,                samples_,            covered_.data(),      hzb,
                                    nbz};
    const detail::MapKernels& kernels = detail::map_kernels(*state.isa_);  // the buffer's instruction set
    built_with_ = &kernels;
    const detail::Level0Kernel level0_kernel = kernels.level0;
    detail::level0_reference(level0, level0_kernel ? level0_kernel(level0) : 0);
    // Levels 1..: sums of covered samples, minimum (farthest) of the depth maps.
    const detail::PyramidRowKernel reduce = kernels.reduce_row;
    for (std::size_t k = 1; k < levels_.size(); ++k) {
        const Level& below = levels_[k - 1];
        const Level& here = levels_[k];
        for (int y = 0; y < here.height; ++y) {
            // The two rows of children; at an odd bottom edge the second repeats the first
            // (minima unaffected, counted once).
            const int y0 = 2 * y, y1 = std::min(2 * y + 1, below.height - 1);
            const std::size_t r0 = below.offset + std::size_t(y0) * std::size_t(below.width);
            const std::size_t r1 = below.offset + std::size_t(y1) * std::size_t(below.width);
            const std::size_t out = here.offset + std::size_t(y) * std::size_t(here.width);
            const auto at = [](float* pyramid, std::size_t i) { return pyramid ? pyramid + i : nullptr; };
            const detail::PyramidRows rows{covered_.data() + r0, covered_.data() + r1, at(hzb, r0), at(hzb, r1),
                                           at(nbz, r0),          at(nbz, r1),          y1 != y0,    covered_.data() + out,
                                           at(hzb, out),         at(nbz, out)};
            const int pairs = below.width / 2;  // output cells with both children columns
            const int done = reduce ? reduce(rows, pairs) : 0;
            detail::reduce_pyramid_row_reference(rows, done, here.width, below.width);
        }
    }
    const Level& top = levels_.back();
    plane_ = hzb ? *std::min_element(hzb_.begin() + std::ptrdiff_t(top.offset), hzb_.end()) : INFINITY;
    pyramid_built_ = true;
}

const OcclusionBuffer& detail::MapsState::built() const {
    if (!built_) throw Error("occlusion maps: test before build()");
    return *built_;
}

// The overlap test's state: the rectangle in samples, the hole budget left (samples that may
// stay uncovered), and how the test ended.
struct detail::MapsState::OverlapQuery {
    int i0, i1, j0, j1;
    double budget;
    OverlapExit exit = OverlapExit::passed;
};

namespace {

// Uncovered samples of [i0, i1] x [j0, j1] (exact, from the coverage masks).
std::uint32_t uncovered_samples(const OcclusionBuffer& b, int i0, int i1, int j0, int j1) {
    std::uint32_t count = 0;
    for (int ty = j0 / kH; ty <= j1 / kH; ++ty)
        for (int tx = i0 / kW; tx <= i1 / kW; ++tx) {
            count += detail::bit_count(detail::subtile_rect_bits(tx, ty, i0, i1, j0, j1) & ~b.subtile(tx, ty).covered);
        }
    return count;
}

}  // namespace

// One cell of the hierarchical overlap test (Zhang 5.3, Fig. 5.3). Returns false when the
// rectangle is rejected (not inside the occluders' projection, within the hole budget).
bool detail::MapsState::overlap_cell(OverlapQuery& q, int k, int x, int y) const {
    const CellSpan cell = cell_span(k, x, y);
    const int ox0 = std::max(cell.x0, q.i0), ox1 = std::min(cell.x1, q.i1), oy0 = std::max(cell.y0, q.j0), oy1 = std::min(cell.y1, q.j1);
    if (ox0 > ox1 || oy0 > oy1) return true;  // the rectangle misses this cell
    const Level& l = levels_[std::size_t(k)];
    const double n = double(cell_samples(k, x, y));
    const double c = double(covered_[l.offset + std::size_t(y) * std::size_t(l.width) + std::size_t(x)]);
    const double r = double(ox1 - ox0 + 1) * double(oy1 - oy0 + 1);
    const double holes = n - c;
    if (holes == 0.0) return true;  // opaque: nothing to add
    const double opacity = c / n;
    // Transparency threshold: a cell this empty counts as empty (approximate mode).
    if (opacity <= transparency_threshold_[std::size_t(k)]) {  // 0 in conservative mode: an empty cell
        if (r > q.budget) {
            q.exit = OverlapExit::transparent_cell;
            return false;
        }
        q.budget -= r;
        return true;
    }
    // At least max(0, r - c) holes lie in the rectangle. The rectangle holding the whole cell
    // (conservative rejection: at or below the transparency threshold 1 - budget / n) or more
    // holes than fit outside the rectangle (predictive rejection) is decided here.
    const double least = std::max(0.0, r - c);
    if (least > q.budget) {
        q.exit = r == n ? OverlapExit::conservative_rejection : OverlapExit::predictive_rejection;
        return false;
    }
    const double most = std::min(r, holes);
    // Opaque enough for this level (Zhang's opacity threshold), and its holes fit the budget.
    if (opacity >= opacity_threshold_[std::size_t(k)] && most <= q.budget) {
        q.budget -= most;
        return true;
    }
    if (least == most) {  // the count is known: a transparent cell, or one the rectangle holds
        q.budget -= least;
        return true;
    }
    if (k == config_.finest_level) {
        if (k == 0 && samples_ > 1) {  // one pixel: count its samples in the rectangle
            const double exact = double(uncovered_samples(*built_, ox0, ox1, oy0, oy1));
            if (exact > q.budget) {
                q.exit = OverlapExit::samples;
                return false;
            }
            q.budget -= exact;
            return true;
        }
        if (most > q.budget) {  // cannot look closer: charge every hole it may have
            q.exit = OverlapExit::finest_level;
            return false;
        }
        q.budget -= most;
        return true;
    }
    const Level& below = levels_[std::size_t(k) - 1];
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            const int cx = 2 * x + dx, cy = 2 * y + dy;
            if (cx < below.width && cy < below.height && !overlap_cell(q, k - 1, cx, cy)) return false;
        }
    return true;
}

void detail::MapsState::overlap(int i0, int i1, int j0, int j1, double budget, OccludeeAnswer& answer, double& uncovered) const {
    // Start at the finest level whose cells are at least as large as the rectangle's smaller
    // side, within the active levels.
    const int smaller_side = std::min(i1 - i0 + 1, j1 - j0 + 1);
    int k = config_.finest_level;
    while (k < start_max_level_ && (samples_ << k) < smaller_side) ++k;
    const Level& l = levels_[std::size_t(k)];
    const int px0 = i0 / samples_ >> k, px1 = i1 / samples_ >> k, py0 = j0 / samples_ >> k, py1 = j1 / samples_ >> k;

    // Level of visibility estimate at the start level: each cell's uncovered share, spread
    // evenly over it, times the rectangle's part of it.
    const double rect_samples = double(i1 - i0 + 1) * double(j1 - j0 + 1);
    double estimate = 0.0;
    for (int y = py0; y <= py1; ++y)
        for (int x = px0; x <= px1; ++x) {
            const CellSpan cell = cell_span(k, x, y);  // holds part of the rectangle
            const double r =
                double(std::min(cell.x1, i1) - std::max(cell.x0, i0) + 1) * double(std::min(cell.y1, j1) - std::max(cell.y0, j0) + 1);
            const double n = double(cell_samples(k, x, y));
            estimate += r * (n - double(covered_[l.offset + std::size_t(y) * std::size_t(l.width) + std::size_t(x)])) / n;
        }
    answer.level_of_visibility = float(std::clamp(estimate / rect_samples, 0.0, 1.0));

    OverlapQuery q{i0, i1, j0, j1, budget};
    for (int y = py0; y <= py1 && q.exit == OverlapExit::passed; ++y)
        for (int x = px0; x <= px1; ++x)
            if (!overlap_cell(q, k, x, y)) break;
    answer.overlap_exit = std::uint8_t(q.exit);
    uncovered = budget - q.budget;
}

double detail::MapsState::hole_budget() const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    return std::floor(config_.hole_pixels * samples_per_display_pixel_);
}

namespace {

// The answer for an occludee decided before any map is asked (see OcclusionBuffer::prepare).
OccludeeAnswer decided_answer(Visibility v) {
    OccludeeAnswer answer;
    answer.visibility = v;
    answer.level_of_visibility = v == Visibility::visible ? 1.0f : 0.0f;
    return answer;
}

}  // namespace

OccludeeAnswer detail::MapsState::test_rect(const ScreenRect& rect) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    double budget = hole_budget();
    return answer_rect(rect, budget);
}

OccludeeAnswer detail::MapsState::test_rect_within(const ScreenRect& rect, double& budget) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    return answer_rect(rect, budget);
}

OccludeeAnswer detail::MapsState::answer_rect(const ScreenRect& rect, double& budget) const {
    detail::RectQuery q;
    Visibility decided;
    if (!built().state().prepare(rect.ndc_min_x, rect.ndc_min_y, rect.ndc_max_x, rect.ndc_max_y, rect.w_min, q, decided))
        return decided_answer(decided);
    if (!pyramid_built_) return buffer_answer(q);  // PyramidBuild::lazy: the buffer decides alone
    OccludeeAnswer answer;
    double uncovered = 0.0;
    overlap(q.i0, q.i1, q.j0, q.j1, budget, answer, uncovered);
    if (answer.overlap_exit != std::uint8_t(OverlapExit::passed)) return answer;  // visible
    if (!depth_hidden(q.i0, q.i1, q.j0, q.j1, q.d_near)) {
        answer.level_of_visibility = 1.0f;  // in front of the occluders somewhere: no estimate
        return answer;
    }
    answer.visibility = Visibility::occluded;
    budget -= uncovered;  // the holes this answer tolerated are spent
    answer.level_of_visibility = float(uncovered / (double(q.i1 - q.i0 + 1) * double(q.j1 - q.j0 + 1)));
    return answer;
}

OccludeeAnswer detail::MapsState::test_aabb(const Aabb& box, const std::array<float, 16>& m) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    OccludeeAnswer answer = test_aabb_by_rectangle(box, m);
    if (answer.visibility == Visibility::visible &&
        detail::ExactViewTest(m, built().config().near_w, false).visible_box(&box.min.x, &box.max.x) == Visibility::view_culled)
        answer = decided_answer(Visibility::view_culled);
    return answer;
}

OccludeeAnswer detail::MapsState::test_aabb_by_rectangle(const Aabb& box, const std::array<float, 16>& m) const {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    ScreenRect r;
    Visibility decided;
    if (!detail::box_rectangle(*built().state().kernels_, &box.min.x, &box.max.x, m, built().config().near_w, false, r, decided))
        return decided_answer(decided);
    double budget = hole_budget();
    return answer_rect(r, budget);
}

}  // namespace homcull
