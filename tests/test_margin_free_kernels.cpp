// The SIMD margin-free rule (FrontEndKernels::margin_free, raster/shared_edge_rule_simd.cpp)
// against the scalar rule it must match bit for bit (raster/shared_edge_rule.hpp).
#include "raster/raster_kernels.hpp"
#include "raster/shared_edge_rule.hpp"
#include "support.hpp"

#include <homcull/isa.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

namespace homcull::detail {
namespace {

// Every lane as margin_free_edges decides it, on every instruction set: random triangles and
// apexes, and the cases the rule exists for (corners on sample centres, slivers, neighbours
// folded onto the same side, vertices behind the eye or beyond the guard band, non-finite ones).
TEST(MarginFreeKernels, DecideEveryLaneAsTheScalarRule) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(-1.2, 1.2), w_of(0.05, 50.0);
    const int width = 97, height = 61;
    const double near_w = 0.1, edge_margin = 0x1.0p-10;
    const auto vertex = [&](int kind) {
        const double w = w_of(rng);
        glm::dvec4 v{unit(rng) * w, unit(rng) * w, 0.0, w};
        if (kind == 1) {  // on a sample centre
            const double i = std::floor((unit(rng) + 1.0) * 0.5 * width) + 0.5, j = std::floor((unit(rng) + 1.0) * 0.5 * height) + 0.5;
            v.x = (i / width * 2.0 - 1.0) * w, v.y = (1.0 - j / height * 2.0) * w;
        } else if (kind == 2) {
            v.w = -v.w;  // behind the eye
        } else if (kind == 3) {
            v.x *= 100.0;  // beyond the guard band
        } else if (kind == 4) {
            v.y = NAN;
        }
        return v;
    };
    long decided = 0, partly_kept = 0;
    for (const std::string& isa : available_isas()) {
        const MarginFreeKernel kernel = raster_kernels(isa_choice(isa)).front_end.margin_free;
        if (isa == "scalar") {  // the reference decides lane by lane
            EXPECT_EQ(kernel, nullptr);
            continue;
        }
        ASSERT_NE(kernel, nullptr) << isa;
        for (int round = 0; round < 3000; ++round) {
            MarginFreeLanes lanes{};
            lanes.count = 1 + int(rng() % kMarginFreeLanes);
            glm::dvec4 own[kMarginFreeLanes][3], apex[kMarginFreeLanes][3];
            for (int t = 0; t < lanes.count; ++t) {
                const int shape = int(rng() % 8);
                for (int k = 0; k < 3; ++k) own[t][k] = vertex(rng() % 6 == 0 ? int(rng() % 5) : 0);
                if (shape == 1) own[t][2] = own[t][0] + (own[t][1] - own[t][0]) * 0.5 + glm::dvec4(1e-9, 0.0, 0.0, 0.0);  // a sliver
                for (int k = 0; k < 3; ++k) {
                    // The apex across edge k: mostly on the other side (as in a mesh), sometimes
                    // folded onto the same side, barely across, or anywhere.
                    const glm::dvec4 mid = (own[t][k] + own[t][(k + 1) % 3]) * 0.5, opposite = own[t][(k + 2) % 3];
                    const double s = shape == 2 ? 0.5 : shape == 3 ? -1e-7 : -1.0;
                    apex[t][k] = mid + (opposite - mid) * s;
                    if (rng() % 10 == 0) apex[t][k] = vertex(int(rng() % 5));
                    lanes.ox[k][t] = own[t][k].x, lanes.oy[k][t] = own[t][k].y, lanes.ow[k][t] = own[t][k].w;
                    lanes.ax[k][t] = apex[t][k].x, lanes.ay[k][t] = apex[t][k].y, lanes.aw[k][t] = apex[t][k].w;
                }
                lanes.flags[t] = std::uint8_t(rng() % 8);
            }
            std::uint8_t kept[kMarginFreeLanes];
            kernel(lanes, near_w, edge_margin, width, height, kept);
            for (int t = 0; t < lanes.count; ++t) {
                const std::uint8_t expected = margin_free_edges(own[t], apex[t], 7, lanes.flags[t], near_w, edge_margin, width, height);
                ASSERT_EQ(int(kept[t]), int(expected)) << isa << ", round " << round << ", lane " << t;
                ++decided;
                partly_kept += expected != 0 && expected != lanes.flags[t];
            }
        }
    }
    if (decided > 0) {
        EXPECT_GT(partly_kept, 100) << "too few lanes keeping only some of their flags to mean anything";
    }
}

}  // namespace
}  // namespace homcull::detail
