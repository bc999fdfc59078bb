#pragma once
// Hierarchical occlusion maps (Hansong Zhang, "Effective Occlusion Culling for the Interactive
// Display of Arbitrary Models", UNC 1998, ch. 4-6; Zhang, Manocha, Hudson, Hoff, "Visibility
// Culling using Hierarchical Occlusion Maps", SIGGRAPH 1997) on top of the occlusion buffer.
//
// An occludee is hidden when two tests pass:
//   overlap: its screen rectangle lies inside the occluders' cumulative projection, asked of an
//            opacity pyramid built from the buffer's coverage masks (level 0: one value per
//            buffer pixel, covered samples / S^2; level k + 1: 2 x 2 cells of level k);
//   depth:   it lies behind the occluders there, asked of one of several depth
//            representations (DepthTest).
// Conservative mode (hole_pixels = 0) never hides an occludee that has a sample of the
// buffer's grid in its rectangle not covered by an occluder nearer than it. Approximate mode
// tolerates up to hole_pixels display pixels of holes in the rectangle. See
// docs/occlusion-maps.md for the thresholds, the early terminations and which overlap x
// depth combinations are conservative.
#include <homcull/occlusion_buffer.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace homcull {
namespace detail {
class MapsState;  // lib/hom/maps_state.hpp
}

enum class DepthTest : std::uint8_t {
    masked,  // the buffer's own per-subtile layers, per sample (MOC's test; conservative)
    hzb,     // per-pixel farthest depth of the covered samples + min pyramid (Greene; conservative)
    deb,     // depth estimation buffer: far rectangles of occluder boxes (Zhang; conservative)
    nbz,     // no-background Z-buffer: per-pixel nearest depth of the covered samples (Zhang;
             // NOT conservative when a pixel's samples lie on occluders at different depths)
    plane,   // one plane at the farthest covered depth (Zhang's single depth; conservative)
};

// Which of the two depth pyramids (farthest_depth, nearest_depth) build() makes. Each is a
// float per buffer pixel and its levels above: at 1280 x 720 the two took about two thirds of
// build()'s time (it is bound by writing its arrays) while the default depth test reads
// neither.
enum class DepthPyramids : std::uint8_t {
    needed,  // the one the depth test reads: hzb for DepthTest::hzb and ::plane, nbz for ::nbz, none
             // for ::masked and ::deb
    both,    // both, whatever the depth test (debug dumps, inspection)
};

// When build() makes the opacity pyramid and the depth pyramids. In conservative mode
// (hole_pixels = 0) with the masked depth test, the overlap test can hide nothing that the
// buffer's own depth test does not: that test finds a rectangle hidden only where every one of
// its samples is covered, by an occluder nearer than the occludee. So there, `lazy` skips the
// pyramids, which cost a pass over every buffer pixel (a fifth to a third of a whole frame with box
// occludees on the castle): build() then sums the covered samples per subtile (a summed-area
// table, Crow, "Summed-area tables for texture mapping", SIGGRAPH 1984), the tests ask the
// buffer (OcclusionBuffer::test_rect), report OverlapExit::not_run, and a visible occludee's
// level_of_visibility is the exact share of its rectangle's samples left uncovered (1 where they
// are all covered, the occludee then in front), not the pyramid's estimate. The pyramids are
// made when build_pyramid() asks for them (dumps, or to see the overlap test's exits). In every
// other mode, and with `always`, build() makes them.
enum class PyramidBuild : std::uint8_t {
    lazy,
    always,
};

struct OcclusionMapsConfig {
    // The display the answers must be right for, in pixels. A display pixel is
    // (buffer samples per axis) / (display pixels per axis) samples wide: the hole size and
    // the level-0 opacity thresholds are converted with it.
    int display_width = 0, display_height = 0;
    // Approximate culling (Zhang 5.4): the largest negligible hole, in display pixels (area).
    // 0 = conservative.
    double hole_pixels = 0.0;
    // Zhang's distribution factor D in [1, 4]: how spread out the holes of a pyramid cell are
    // assumed to be. It scales the per-level opacity thresholds (see opacity_threshold()).
    double distribution = 1.0;
    // Zhang's transparency threshold at level 0, in [0, 1): a cell at or below it counts as
    // empty (approximate mode only; 0 in conservative mode). Coarser levels use D * t / 4.
    double transparency = 0.0;
    // Active levels of the opacity pyramid: the overlap test never starts above
    // coarsest_level and never descends below finest_level (where it then charges the whole
    // cell's holes). -1: the pyramid's last level.
    int finest_level = 0, coarsest_level = -1;
    // The pyramid stops at the first level with both sides at most this many cells.
    int min_size = 4;
    // Depth estimation buffer cells (Zhang 6.2; 64 x 64 by default).
    int deb_width = 64, deb_height = 64;
    DepthTest depth = DepthTest::masked;
    DepthPyramids depth_pyramids = DepthPyramids::needed;
    PyramidBuild pyramid = PyramidBuild::lazy;
};

// What an occludee test answers. level_of_visibility estimates the share of the occludee's
// rectangle that is not covered by occluders in front of it (0: none, 1: all), from the
// opacity pyramid: an engine can pick a coarser level of detail for a barely visible object.
struct OccludeeAnswer {
    Visibility visibility = Visibility::visible;
    float level_of_visibility = 1.0f;
    // Which early termination decided the overlap test (OverlapExit), for statistics and tests.
    std::uint8_t overlap_exit = 0;
};

// How the overlap test ended.
enum class OverlapExit : std::uint8_t {
    not_run = 0,
    passed,                  // every cell visited was opaque enough, holes within the budget
    conservative_rejection,  // a cell the rectangle contains has more holes than the budget
    predictive_rejection,    // a cell partly in the rectangle has more holes than fit outside it
    transparent_cell,        // a cell at or below the transparency threshold
    finest_level,            // the finest active level, still uncertain: its holes charged
    samples,                 // decided by the coverage masks of one pixel
};

class OcclusionMaps {
public:
    // Allocates the pyramids for buffers shaped like `buffer` (its pixel grid and samples).
    // Throws homcull::Error on an invalid configuration.
    OcclusionMaps(const OcclusionBuffer& buffer, const OcclusionMapsConfig& config);

    // Per frame: clear() forgets the occluder boxes of the depth estimation buffer;
    // add_occluder_box() enters one (its far rectangle, Zhang 6.2.1); build() derives the
    // opacity pyramid and the depth pyramids it makes (OcclusionMapsConfig::depth_pyramids)
    // from a rendered buffer. No allocation.
    void clear();
    void add_occluder_box(const Aabb& box, const std::array<float, 16>& model_to_clip);
    void build(const OcclusionBuffer& buffer);
    // A new near plane, the buffer's after its set_near_w (occluder boxes are clipped there):
    // forgets the occluder boxes as clear() does; allocates nothing. Throws homcull::Error
    // unless near_w is finite and positive.
    void set_near_w(float near_w);
    // The pyramids of the last build()'s buffer, when build() left them out
    // (PyramidBuild::lazy); nothing to do when they are made. The tests then run the overlap
    // test as with PyramidBuild::always. Throws homcull::Error before the first build().
    void build_pyramid();
    // Whether the pyramids of the last build() are made: the accessors below that read them
    // (covered_samples, opacity, farthest_depth, nearest_depth, plane_depth) throw
    // homcull::Error until they are.
    bool pyramid_built() const;

    // Occludee tests, against the maps and the buffer of the last build(): the buffer must
    // outlive them and stay unchanged (render or clear it, then build() again). Thread-safe
    // with each other. Throws homcull::Error before the first build().
    OccludeeAnswer test_rect(const ScreenRect& rect) const;
    // A box: its screen rectangle as test_rect, and a box found visible that lies outside the
    // view volume is view_culled (OcclusionBuffer::test_aabb's exact view test).
    // test_aabb_by_rectangle leaves that test out, for callers that test boxes against a view
    // of their own first (the scene culler).
    OccludeeAnswer test_aabb(const Aabb& box, const std::array<float, 16>& model_to_clip) const;
    OccludeeAnswer test_aabb_by_rectangle(const Aabb& box, const std::array<float, 16>& model_to_clip) const;
    // One occludee tested as several rectangles (its triangles, say) must share one hole
    // budget, or each rectangle would tolerate L pixels of holes: test_rect_within starts from
    // `budget` (samples; hole_budget() for a fresh occludee) and, when it answers occluded,
    // subtracts the holes it tolerated. Conservative mode: the budget is 0 and stays 0.
    double hole_budget() const;
    OccludeeAnswer test_rect_within(const ScreenRect& rect, double& budget) const;

    const OcclusionMapsConfig& config() const;
    // The opacity pyramid, for dumps and tests: level k is level_width(k) x level_height(k)
    // cells of 2^k x 2^k buffer pixels; covered_samples(k) and cell_samples(k) row-major.
    int levels() const;
    int level_width(int k) const;
    int level_height(int k) const;
    const std::uint32_t* covered_samples(int k) const;
    // Samples in a cell of level k inside the buffer (border cells may have fewer).
    std::uint32_t cell_samples(int k, int x, int y) const;
    float opacity(int k, int x, int y) const;
    // Per-level thresholds in force (Zhang 5.4): a cell with opacity >= opacity_threshold(k)
    // is opaque enough; one with opacity <= transparency_threshold(k) counts as empty.
    double opacity_threshold(int k) const;
    double transparency_threshold(int k) const;
    // Depth maps as 1/w per cell (larger is nearer; +inf where no occluder covers anything):
    // the farthest (hzb) and nearest (nbz) depth of the covered samples of each pixel, with
    // their min pyramids on the opacity pyramid's levels, and the depth estimation buffer.
    // A pyramid the maps do not make (OcclusionMapsConfig::depth_pyramids) is null.
    const float* farthest_depth(int k) const;
    const float* nearest_depth(int k) const;
    const std::vector<float>& depth_estimation() const;
    // The farthest covered depth of the whole buffer (the plane test's): +inf when nothing is
    // covered, and when the maps make no hzb pyramid.
    float plane_depth() const;

    // The implementation (lib/hom/maps_state.hpp): not part of the interface.
    const detail::MapsState& state() const { return *state_; }

    // Moves leave the source with no state: it may then only be assigned to or destroyed.
    ~OcclusionMaps();
    OcclusionMaps(OcclusionMaps&&) noexcept;
    OcclusionMaps& operator=(OcclusionMaps&&) noexcept;

private:
    detail::HookPtr<detail::MapsState> state_;  // every pyramid, threshold and setting
};

}  // namespace homcull
