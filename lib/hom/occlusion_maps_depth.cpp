// The depth half of the occlusion test (Zhang 1998, ch. 6): is the occludee behind the
// occluders where the overlap test found them? Depth is 1/w (larger is nearer) throughout; an
// occludee with nearest 1/w d_near is behind an occluder bound b where b > d_near.
//
// Which combinations never hide a visible occludee, given an overlap test that passed
// conservatively (every sample of the rectangle covered):
//   masked, hzb, plane: every covered sample's bound is a lower bound of the nearest occluder
//     depth there (OcclusionBuffer's layers), and the test takes the minimum over the
//     rectangle's pixels, so each sample is hidden;
//   deb: a covered sample lies in the far rectangle of the box of the occluder covering it,
//     and its cell holds at most that box's farthest depth;
//   nbz: keeps each pixel's nearest covered depth, so a pixel whose samples lie on two
//     occluders at different depths claims the nearer one for the farther one's samples: an
//     occludee between them is hidden there while visible (a test builds exactly that case).
//     With one sample per pixel it equals hzb.
// In approximate mode holes are tolerated, and the depth maps ignore uncovered samples.
#include <homcull/error.hpp>
#include <homcull/occlusion_maps.hpp>

#include "buffer/buffer_state.hpp"
#include "hom/maps_state.hpp"
#include "common/float_mode.hpp"
#include "buffer/min_pyramid.hpp"
#include "buffer/rect_queries.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// The depth estimation buffer cell of sample i on a grid of `samples` samples and `cells` cells.
int deb_cell(int i, int samples, int cells) { return int(std::int64_t(i) * cells / samples); }

}  // namespace

void detail::MapsState::clear() { std::fill(deb_.begin(), deb_.end(), INFINITY); }

void detail::MapsState::set_near_w(float near_w) {
    if (!(near_w > 0.0f) || !std::isfinite(near_w)) throw Error("occlusion maps: the near plane must be finite and positive");
    near_w_ = near_w;
    clear();
}

// Zhang 6.2.1: the far rectangle of an occluder's box, the box's screen rectangle at its
// farthest depth, lowers every depth estimation buffer cell it touches to that depth.
void detail::MapsState::add_occluder_box(const Aabb& box, const std::array<float, 16>& m) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    const int gw = config_.deb_width, gh = config_.deb_height;
    const int sample_width = width_ * samples_, sample_height = height_ * samples_;
    glm::dvec4 corners[8];
    const double error = detail::box_corners(&box.min.x, &box.max.x, m, corners);
    detail::ClipBounds b = detail::clip_bounds(corners, 8, double(near_w_));
    // The far depth raised by the corners' error bound (so that it stays a bound of the exact
    // box's farthest w); the rectangle's slack below is far larger than their NDC error, unless
    // the bound is not small, when the box bounds no cell.
    b.max_w += error;
    if (b.finite && b.behind == 0 && !(detail::ndc_error_bound(error, std::max({-b.min_x, b.max_x, -b.min_y, b.max_y}), b.min_w) < 0x1.0p-30))
        b.behind = 1;
    if (b.finite && b.behind == 8) return;  // entirely before the near plane: draws nothing
    int cx0 = 0, cx1 = gw - 1, cy0 = 0, cy1 = gh - 1;
    float depth = 0.0f;  // no bound
    if (b.finite) {
        depth = detail::float_down(1.0 / b.max_w);
        if (b.behind == 0) {  // its projection lies in the corners' rectangle (slightly widened)
            const double slack = 1.0 / 256.0;
            int i0, i1, j0, j1;
            detail::sample_span((b.min_x + 1.0) * 0.5 * sample_width - slack, (b.max_x + 1.0) * 0.5 * sample_width + slack, sample_width,
                                i0, i1);
            detail::sample_span((1.0 - b.max_y) * 0.5 * sample_height - slack, (1.0 - b.min_y) * 0.5 * sample_height + slack,
                                sample_height, j0, j1);
            if (i0 > i1 || j0 > j1) return;  // covers no sample
            cx0 = deb_cell(i0, sample_width, gw), cx1 = deb_cell(i1, sample_width, gw);
            cy0 = deb_cell(j0, sample_height, gh), cy1 = deb_cell(j1, sample_height, gh);
        }
    }
    for (int y = cy0; y <= cy1; ++y)
        for (int x = cx0; x <= cx1; ++x) {
            float& cell = deb_[std::size_t(y) * std::size_t(gw) + std::size_t(x)];
            cell = std::min(cell, depth);
        }
}

bool detail::MapsState::depth_hidden(int i0, int i1, int j0, int j1, float d_near) const {
    const OcclusionBuffer& buffer = *built_;
    const bool approximate = config_.hole_pixels > 0.0;
    switch (config_.depth) {
    case DepthTest::masked: {
        if (!approximate) return buffer.state().test_prepared_rect({i0, i1, j0, j1, d_near}) == Visibility::occluded;
        // Holes tolerated: every covered sample of the rectangle must be behind its bound.
        for (int ty = j0 / kH; ty <= j1 / kH; ++ty)
            for (int tx = i0 / kW; tx <= i1 / kW; ++tx) {
                const OcclusionBuffer::Subtile t = buffer.subtile(tx, ty);
                const std::uint32_t bits = detail::subtile_rect_bits(tx, ty, i0, i1, j0, j1) & t.covered;
                if ((bits & ~t.mask) && !(t.d0 > d_near)) return false;
                if ((bits & t.mask) && !(std::max(t.d0, t.d1) > d_near)) return false;
            }
        return true;
    }
    case DepthTest::hzb:
    case DepthTest::nbz: {
        const std::vector<float>& pyramid = config_.depth == DepthTest::hzb ? hzb_ : nbz_;
        return detail::min_pyramid_range_above(pyramid.data(), levels_.data(), int(levels_.size()), i0 / samples_, j0 / samples_,
                                               i1 / samples_, j1 / samples_, d_near);
    }
    case DepthTest::plane:
        return plane_ != INFINITY && plane_ > d_near;
    case DepthTest::deb: {
        const int gw = config_.deb_width, gh = config_.deb_height;
        const int sw = width_ * samples_, sh = height_ * samples_;
        for (int y = deb_cell(j0, sh, gh); y <= deb_cell(j1, sh, gh); ++y)
            for (int x = deb_cell(i0, sw, gw); x <= deb_cell(i1, sw, gw); ++x) {
                const float cell = deb_[std::size_t(y) * std::size_t(gw) + std::size_t(x)];
                if (cell == INFINITY || !(cell > d_near)) return false;  // no occluder box here, or not behind it
            }
        return true;
    }
    }
    return false;
}

}  // namespace homcull
