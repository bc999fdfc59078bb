// The float row rule (prepare_float_row_edges, float_sample_row_interval) against the double
// rule it stands in for: on every row, the float interval lies inside the double interval
// (so it inherits its conservative coverage) and loses at most one sample at each end. And the
// rows the row loop passes over (rows_reaching_columns) against both rules.
#include "raster/rasterize.hpp"
#include "support.hpp"

#include <homcull/camera.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <cstdio>
#include <random>

namespace homcull::detail {
namespace {

struct RuleComparison {
    long rows = 0, samples_double = 0, samples_float = 0, triangles_in_float = 0, triangles = 0;
};

// Sets the triangle up both ways (setup_raster_triangle gives the float form when it can;
// the double form comes from the same edges) and compares every row.
void compare_rules(const ScreenTriangle& tri, int width, int height, RuleComparison& out) {
    RasterTriangle raster;
    if (!setup_raster_triangle(tri, 1.0 / 1024.0, width, height, raster)) return;
    ++out.triangles;
    OrientedTriangle oriented;
    ASSERT_TRUE(orient_triangle(tri, oriented));
    TriangleEdges edges = edge_functions(oriented);
    for (int k = 0; k < 3; ++k) edges.threshold[k] = edge_threshold(edges.shared[k], 1.0 / 1024.0, edges.sa[k], edges.sb[k]);
    FloatRowEdges float_edges;
    const bool in_float = prepare_float_row_edges(edges, raster.i0, raster.i1, float_edges);
    ASSERT_EQ(in_float, raster.plane.float_rows);
    if (!in_float) return;
    ++out.triangles_in_float;
    for (int row = raster.j0; row <= raster.j1; ++row) {
        std::int32_t df, dl, ff, fl;
        sample_row_interval(edges, row, raster.i0, raster.i1, df, dl);
        float_sample_row_interval(float_edges, row, raster.i0, raster.i1, ff, fl);
        ++out.rows;
        out.samples_double += std::max(0, dl - df + 1);
        out.samples_float += std::max(0, fl - ff + 1);
        if (ff > fl) {  // empty in float: the double interval may hold at most two samples
            ASSERT_LE(dl - df + 1, 2) << "row " << row;
            continue;
        }
        ASSERT_GE(ff, df) << "row " << row << ": float interval starts outside the double one";
        ASSERT_LE(fl, dl) << "row " << row << ": float interval ends outside the double one";
        ASSERT_LE(ff - df, 1) << "row " << row;
        ASSERT_LE(dl - fl, 1) << "row " << row;
    }
}

// Random triangles: three vertices within `offset` of a centre drawn from centre_x and
// centre_y; trials with trial % horizontal_every == 0 get a nearly horizontal edge (its
// endpoints' y apart by flatness times an offset), those with trial % vertical_every == 1 a
// nearly vertical one.
struct Flatness {
    int horizontal_every, vertical_every;
    double flatness;
};
ScreenTriangle random_triangle(std::mt19937_64& rng, std::uniform_real_distribution<double>& centre_x,
                               std::uniform_real_distribution<double>& centre_y, std::uniform_real_distribution<double>& offset, int trial,
                               const Flatness& f) {
    ScreenTriangle tri;
    const double cx = centre_x(rng), cy = centre_y(rng);
    for (int k = 0; k < 3; ++k) {
        tri.p[k] = {cx + offset(rng), cy + offset(rng)};
        tri.d[k] = 1.0;
    }
    if (trial % f.horizontal_every == 0) tri.p[1].y = tri.p[0].y + offset(rng) * f.flatness;
    if (trial % f.vertical_every == 1) tri.p[2].x = tri.p[0].x + offset(rng) * f.flatness;
    return tri;
}

TEST(FloatRowRule, LiesInsideTheDoubleRuleOnRandomTriangles) {
    std::mt19937_64 rng(7);
    const int width = 1920, height = 1080;
    // on_screen: the triangles up to 300 samples across; flat: those with a nearly horizontal
    // edge (slopes of 10^4 samples per row round too coarsely in float: they keep double).
    RuleComparison c, on_screen, flat;
    for (double size : {2.0, 8.0, 40.0, 300.0, 3000.0}) {
        std::uniform_real_distribution<double> centre_x(-0.2 * width, 1.2 * width), centre_y(-0.2 * height, 1.2 * height);
        std::uniform_real_distribution<double> offset(-size, size);
        for (int trial = 0; trial < 4000; ++trial) {
            const ScreenTriangle tri = random_triangle(rng, centre_x, centre_y, offset, trial, {4, 8, 1e-4});
            compare_rules(tri, width, height, trial % 4 == 0 ? flat : size <= 300.0 ? on_screen : c);
            if (HasFatalFailure()) return;
        }
    }
    // The float rule takes nearly all triangles up to a few hundred samples across (not all of
    // the larger ones: an edge starting thousands of samples off the screen keeps double), and
    // loses little coverage.
    std::printf("[ float    ] %ld of %ld triangles up to 300 samples across, %ld of %ld larger ones, %ld of %ld with a flat edge; "
                "samples kept %.5f, %.5f\n",
                on_screen.triangles_in_float, on_screen.triangles, c.triangles_in_float, c.triangles, flat.triangles_in_float, flat.triangles,
                double(on_screen.samples_float) / double(on_screen.samples_double), double(c.samples_float) / double(c.samples_double));
    EXPECT_GT(on_screen.triangles_in_float, on_screen.triangles * 95 / 100);
    EXPECT_GT(c.triangles_in_float, 0);
    EXPECT_GT(double(on_screen.samples_float), 0.995 * double(on_screen.samples_double));
    EXPECT_GT(double(c.samples_float), 0.995 * double(c.samples_double));
}

TEST(FloatRowRule, SharedHorizontalAndFarEdgesKeepTheDoubleRule) {
    const auto setup = [](ScreenTriangle tri) {
        RasterTriangle raster;
        EXPECT_TRUE(setup_raster_triangle(tri, 1.0 / 1024.0, 640, 480, raster));
        return raster.plane.float_rows;
    };
    ScreenTriangle tri{{{10.3, 20.7}, {50.1, 22.9}, {30.6, 60.2}}, {1.0, 1.0, 1.0}};
    EXPECT_TRUE(setup(tri));
    ScreenTriangle shared = tri;
    shared.shared = 2;  // one edge shared with a drawn neighbour: both must compute the same bits
    EXPECT_FALSE(setup(shared));
    ScreenTriangle horizontal = tri;
    horizontal.p[1].y = horizontal.p[0].y;
    EXPECT_FALSE(setup(horizontal));
    ScreenTriangle far = tri;
    far.p[2] = {-60000.0, 5.0};  // an edge starts far beyond the screen: float would round too coarsely
    EXPECT_FALSE(setup(far));
}

// rows_reaching_columns, which the SIMD row loop and the occludee tests use to pass over the rows
// of a large triangle that hold no sample in its columns: outside the rows it gives, every row's
// interval is empty by the rule the triangle takes (double with its shared edges, or float, or
// the occludee tests' outer edges pushed out by a pad), for triangles of
// every size placed anywhere around the view, with nearly horizontal or vertical edges, shared
// edges and vertices far beyond the screen. It must also pass over a good share of the rows of
// the large triangles partly beside the view, or the row loop would gain nothing.
TEST(RowsReachingColumns, NoRowOutsideHoldsASample) {
    std::mt19937_64 rng(11);
    const int width = 1283, height = 721;
    long rows = 0, rows_outside = 0, large_rows = 0, large_rows_outside = 0, triangles_in_float = 0, triangles = 0;
    long outer_rows = 0, outer_rows_outside = 0;
    std::uniform_real_distribution<double> pad_samples(0.0, 3.0);
    for (double size : {3.0, 40.0, 500.0, 5000.0, 200000.0}) {
        std::uniform_real_distribution<double> centre_x(-0.5 * width, 1.5 * width), centre_y(-0.5 * height, 1.5 * height);
        std::uniform_real_distribution<double> offset(-size, size);
        std::uniform_int_distribution<int> shared_bits(0, 7);
        for (int trial = 0; trial < 3000; ++trial) {
            ScreenTriangle tri = random_triangle(rng, centre_x, centre_y, offset, trial, {5, 7, 1e-5});
            if (trial % 3 == 2) tri.shared = std::uint8_t(shared_bits(rng));
            // The occludee tests' outer edges: pushed out by a pad's support, over the padded box.
            OrientedTriangle oriented;
            if (orient_triangle(tri, oriented)) {
                TriangleEdges outer = edge_functions(oriented);
                const double pad = pad_samples(rng);
                for (int k = 0; k < 3; ++k) {
                    outer.shared[k] = false;
                    outer.threshold[k] = -(std::abs(outer.sa[k]) + std::abs(outer.sb[k])) * pad;
                }
                const glm::dvec2* v = oriented.v;
                int i0, i1, j0, j1;
                sample_span(std::min({v[0].x, v[1].x, v[2].x}) - pad, std::max({v[0].x, v[1].x, v[2].x}) + pad, width, i0, i1);
                sample_span(std::min({v[0].y, v[1].y, v[2].y}) - pad, std::max({v[0].y, v[1].y, v[2].y}) + pad, height, j0, j1);
                int row_lo = 0, row_hi = -1;
                const bool any = rows_reaching_columns(outer, i0, i1, j0, j1, row_lo, row_hi);
                for (int row = j0; row <= j1 && i0 <= i1; ++row) {
                    const bool outside = !any || row < row_lo || row > row_hi;
                    outer_rows += 1, outer_rows_outside += outside;
                    if (!outside) continue;
                    std::int32_t first = 0, last = -1;
                    sample_row_interval(outer, row, i0, i1, first, last);
                    ASSERT_GT(first, last) << "outer edges: row " << row << " holds samples [" << first << ", " << last << "] outside rows ["
                                           << row_lo << ", " << row_hi << "] (size " << size << ", trial " << trial << ")";
                }
            }
            RasterTriangle raster;
            if (!setup_raster_triangle(tri, 1.0 / 1024.0, width, height, raster)) continue;
            ++triangles;
            triangles_in_float += raster.plane.float_rows;
            int row_lo = 0, row_hi = -1;
            const bool any = rows_reaching_columns(raster, row_lo, row_hi);
            if (any) {
                ASSERT_LE(raster.j0, row_lo);
                ASSERT_LE(row_lo, row_hi);
                ASSERT_LE(row_hi, raster.j1);
            }
            for (int row = raster.j0; row <= raster.j1; ++row) {
                const bool outside = !any || row < row_lo || row > row_hi;
                ++rows;
                rows_outside += outside;
                if (size >= 500.0) ++large_rows, large_rows_outside += outside;
                if (!outside) continue;
                std::int32_t first = 0, last = -1;
                if (raster.plane.float_rows) float_sample_row_interval(raster.float_edges, row, raster.i0, raster.i1, first, last);
                else sample_row_interval(raster.edges, row, raster.i0, raster.i1, first, last);
                ASSERT_GT(first, last) << "row " << row << " holds samples [" << first << ", " << last << "] outside rows [" << row_lo
                                       << ", " << row_hi << "] (size " << size << ", trial " << trial << ", float " << raster.plane.float_rows
                                       << ")";
            }
        }
    }
    std::printf("[ rows     ] %ld triangles (%ld by the float rule): %ld of %ld rows passed over, %ld of %ld of those 500 samples "
                "across and more; outer edges %ld of %ld\n",
                triangles, triangles_in_float, rows_outside, rows, large_rows_outside, large_rows, outer_rows_outside, outer_rows);
    EXPECT_GT(triangles_in_float, triangles / 4);
    EXPECT_GT(large_rows_outside, large_rows / 10);
    EXPECT_GT(outer_rows_outside, outer_rows / 10);
}

// The float rule on a real scene against Embree: fzk_haus's triangles drawn without their
// shared-edge flags, so that every triangle has three silhouette edges and takes the float
// rule (unless an edge is flat or starts far off the screen). Wherever the buffer claims an
// occluder, a ray through the sample's centre must hit something at or before the buffer's
// depth bound (the ray parameter is the view depth; 10^-5 absorbs Embree's float rounding).
TEST(FloatRowRule, ClaimedSamplesOfARealSceneAreBehindEmbreeHits) {
    const std::string path = test::shared_scene("fzk_haus.glb");
    if (path.empty()) GTEST_SKIP() << "fzk_haus.glb is missing from " << test::shared_scenes_dir();
    const Scene scene = load_scene(path);
    const RayScene rays(scene);
    const WorldTriangles occluders = gather_world_triangles(scene, objects_with_role(scene, ""));
    Camera camera;
    camera.eye = {-12, 3, 10};
    camera.target = {6, 2, -5};
    long claimed = 0;
    for (const auto& [width, height, samples] : {std::tuple{640, 360, 1}, {160, 90, 4}}) {
        OcclusionBuffer buffer(test::buffer_config(width, height, samples, float(camera.near_plane)));
        TriangleInput in = occluders.input(clip_from_world(camera, double(width) / double(height)), Backface::none);
        in.shared_edges = nullptr;
        buffer.render(in);
        claimed += test::expect_claims_behind_embree_hits(rays, camera, buffer, "fzk_haus, S = " + std::to_string(samples));
    }
    EXPECT_GT(claimed, 40000);  // the house covers about an eighth of both sample grids
}

}  // namespace
}  // namespace homcull::detail
