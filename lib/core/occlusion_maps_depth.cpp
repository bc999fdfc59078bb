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
#include <homcull/occlusion_maps.hpp>

#include "core/rect_tests.hpp"
#include "raster/rasterize.hpp"
#include "raster/triangle_setup.hpp"

#include <algorithm>
#include <cmath>

namespace homcull {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// The depth estimation buffer cell of sample i on a grid of `samples` samples and `cells` cells.
int deb_cell(int i, int samples, int cells) { return int(std::int64_t(i) * cells / samples); }

}  // namespace

void OcclusionMaps::clear() { std::fill(deb_.begin(), deb_.end(), INFINITY); }

// Zhang 6.2.1: the far rectangle of an occluder's box, the box's screen rectangle at its
// farthest depth, lowers every depth estimation buffer cell it touches to that depth.
void OcclusionMaps::add_occluder_box(const Aabb& box, const std::array<float, 16>& m) {
    const int gw = config_.deb_width, gh = config_.deb_height;
    const int sample_width = width_ * samples_, sample_height = height_ * samples_;
    double min_x = HUGE_VAL, max_x = -HUGE_VAL, min_y = HUGE_VAL, max_y = -HUGE_VAL, max_w = -HUGE_VAL;
    bool finite = true, crosses_near = false;
    int in_front = 0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4 c = detail::transform_to_clip(m, (k & 1) ? box.max.x : box.min.x, (k & 2) ? box.max.y : box.min.y,
                                                       (k & 4) ? box.max.z : box.min.z, 1.0);
        if (!detail::finite_clip(c)) {
            finite = false;
            break;
        }
        max_w = std::max(max_w, c.w);
        if (c.w < double(near_w_)) {
            crosses_near = true;
            continue;
        }
        ++in_front;
        min_x = std::min(min_x, c.x / c.w), max_x = std::max(max_x, c.x / c.w);
        min_y = std::min(min_y, c.y / c.w), max_y = std::max(max_y, c.y / c.w);
    }
    if (finite && in_front == 0) return;  // entirely before the near plane: draws nothing
    int cx0 = 0, cx1 = gw - 1, cy0 = 0, cy1 = gh - 1;
    float depth = 0.0f;  // no bound
    if (finite) {
        depth = detail::float_down(1.0 / max_w);
        if (!crosses_near) {  // its projection lies in the corners' rectangle (slightly widened)
            const double slack = 1.0 / 256.0;
            int i0, i1, j0, j1;
            detail::sample_span((min_x + 1.0) * 0.5 * sample_width - slack, (max_x + 1.0) * 0.5 * sample_width + slack, sample_width, i0,
                                i1);
            detail::sample_span((1.0 - max_y) * 0.5 * sample_height - slack, (1.0 - min_y) * 0.5 * sample_height + slack, sample_height,
                                j0, j1);
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

// Whether every cell of level k's pyramid within cell (x, y) and the pixel range
// [x0, x1] x [y0, y1] (level-0 units) holds more than d: a cell whose minimum is above d is
// done, one inside the range whose minimum is not above d has such a pixel.
bool OcclusionMaps::min_pyramid_above(const std::vector<float>& pyramid, int k, int x, int y, int x0, int y0, int x1, int y1,
                                      float d) const {
    const int cx0 = x << k, cy0 = y << k, cx1 = ((x + 1) << k) - 1, cy1 = ((y + 1) << k) - 1;
    if (cx1 < x0 || cx0 > x1 || cy1 < y0 || cy0 > y1) return true;
    const Level& l = levels_[std::size_t(k)];
    if (pyramid[l.offset + std::size_t(y) * std::size_t(l.width) + std::size_t(x)] > d) return true;
    if (k == 0 || (cx0 >= x0 && cx1 <= x1 && cy0 >= y0 && cy1 <= y1)) return false;
    const Level& below = levels_[std::size_t(k) - 1];
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
            if (2 * x + dx < below.width && 2 * y + dy < below.height &&
                !min_pyramid_above(pyramid, k - 1, 2 * x + dx, 2 * y + dy, x0, y0, x1, y1, d))
                return false;
    return true;
}

bool OcclusionMaps::depth_hidden(const OcclusionBuffer& buffer, int i0, int i1, int j0, int j1, float d_near) const {
    const bool approximate = config_.hole_pixels > 0.0;
    switch (config_.depth) {
    case DepthTest::masked: {
        if (!approximate) return buffer.test_prepared_rect({i0, i1, j0, j1, d_near}) == Visibility::occluded;
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
        const int x0 = i0 / samples_, x1 = i1 / samples_, y0 = j0 / samples_, y1 = j1 / samples_;
        int k = 0;  // the level where the pixel range spans at most 2 x 2 cells
        while (k + 1 < int(levels_.size()) && ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1)) ++k;
        for (int y = y0 >> k; y <= y1 >> k; ++y)
            for (int x = x0 >> k; x <= x1 >> k; ++x)
                if (!min_pyramid_above(pyramid, k, x, y, x0, y0, x1, y1, d_near)) return false;
        return true;
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
