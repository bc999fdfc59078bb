// The raised-vertex depth bound (lib/buffer/raised_vertex_plane.hpp) on its own: random screen
// triangles, many of them thin or nearly edge-on, whose vertices are moved to the corners of
// their allowed boxes (on screen and in depth). The moved triangle's depth, exact in long
// double, must stay under the bound at every sample centre it covers, some of them outside our
// triangle. Fails when the bound drops the vertices' depth error or the gradient times their
// screen error; not when it drops the term for negative barycentrics, which the gradient term
// covered in every case tried.
#include "buffer/raised_vertex_plane.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace homcull {
namespace {

long double cross(long double ax, long double ay, long double bx, long double by, long double px, long double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

TEST(RaisedVertexPlane, BoundsEveryPerturbedTriangle) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uint64_t checked = 0, outside_ours = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        // A triangle in a 64 x 64 sample window: a long thin one half of the time.
        detail::OrientedTriangle t{};
        const double cx = 64.0 * unit(rng), cy = 64.0 * unit(rng), length = 2.0 + 60.0 * unit(rng);
        const double angle = 6.283185307179586 * unit(rng), width = unit(rng) < 0.5 ? 0.05 + 0.5 * unit(rng) : 2.0 + 20.0 * unit(rng);
        t.v[0] = {cx, cy};
        t.v[1] = {cx + length * std::cos(angle), cy + length * std::sin(angle)};
        t.v[2] = {t.v[1].x - width * std::sin(angle), t.v[1].y + width * std::cos(angle)};
        for (double& d : t.d) d = std::pow(10.0, -2.0 + 3.0 * unit(rng));  // 1/w from 0.01 to 10
        t.area2 = (t.v[1].x - t.v[0].x) * (t.v[2].y - t.v[0].y) - (t.v[1].y - t.v[0].y) * (t.v[2].x - t.v[0].x);
        if (t.area2 < 0.0) {
            std::swap(t.v[1], t.v[2]);
            std::swap(t.d[1], t.d[2]);
            t.area2 = -t.area2;
        }
        if (!(t.area2 > 1e-6)) continue;
        double sx[3], sy[3], dd[3];
        for (int k = 0; k < 3; ++k) {
            sx[k] = 1e-3 * unit(rng), sy[k] = 1e-3 * unit(rng);
            dd[k] = t.d[k] * 1e-5 * unit(rng);
        }
        const double pad_x = *std::max_element(sx, sx + 3) + 1e-3, pad_y = *std::max_element(sy, sy + 3) + 1e-3;
        const detail::RaisedVertexPlane bound = detail::raised_vertex_plane(t, sx, sy, dd, pad_x, pad_y);
        if (!bound.usable) continue;
        for (int corner = 0; corner < 8; ++corner) {
            long double px[3], py[3], pd[3];
            for (int k = 0; k < 3; ++k) {  // each vertex to a random corner of its box
                px[k] = t.v[k].x + (unit(rng) < 0.5 ? -sx[k] : sx[k]);
                py[k] = t.v[k].y + (unit(rng) < 0.5 ? -sy[k] : sy[k]);
                pd[k] = t.d[k] + (unit(rng) < 0.5 ? -dd[k] : dd[k]);
            }
            const long double area = cross(px[0], py[0], px[1], py[1], px[2], py[2]);
            if (area <= 0) continue;
            const int i0 = std::max(0, int(std::floor(std::min({px[0], px[1], px[2]})))), i1 = int(std::ceil(std::max({px[0], px[1], px[2]})));
            const int j0 = std::max(0, int(std::floor(std::min({py[0], py[1], py[2]})))), j1 = int(std::ceil(std::max({py[0], py[1], py[2]})));
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) {
                    const long double x = i + 0.5L, y = j + 0.5L;
                    const long double l0 = cross(px[1], py[1], px[2], py[2], x, y) / area;
                    const long double l1 = cross(px[2], py[2], px[0], py[0], x, y) / area;
                    const long double l2 = 1 - l0 - l1;
                    if (l0 < 0 || l1 < 0 || l2 < 0) continue;  // not covered by the moved triangle
                    const long double exact = l0 * pd[0] + l1 * pd[1] + l2 * pd[2];
                    ASSERT_LE(exact, (long double)bound.at(i, j)) << "trial " << trial << ", sample " << i << ", " << j;
                    ++checked;
                    const long double m0 = cross(t.v[1].x, t.v[1].y, t.v[2].x, t.v[2].y, x, y);
                    const long double m1 = cross(t.v[2].x, t.v[2].y, t.v[0].x, t.v[0].y, x, y);
                    const long double m2 = cross(t.v[0].x, t.v[0].y, t.v[1].x, t.v[1].y, x, y);
                    outside_ours += m0 < 0 || m1 < 0 || m2 < 0;
                }
        }
    }
    std::printf("raised-vertex bound: %llu samples checked, %llu of them outside the unmoved triangle\n",
                (unsigned long long)checked, (unsigned long long)outside_ours);
    EXPECT_GT(checked, 100000u);
    EXPECT_GT(outside_ours, 100u);
}

}  // namespace
}  // namespace homcull
