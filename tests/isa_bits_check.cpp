// A standalone check that every instruction set available gives the scalar reference path's
// bits and answers, needing only homcull::core (no Embree, TBB, OpenImageIO or GoogleTest):
// scripts/check-neon.sh --run builds it for aarch64 and runs it under qemu, where the test
// suite cannot run, so that NEON, SVE and SVE2 are checked as SSE4, AVX2 and AVX-512 are by
// the suite (Isa.*). It renders random clip-space soups, a generated city as one indexed input
// and as clusters, at 1, 2 and 4 samples per axis, with and without per-sample depth, on one
// thread and through a job system; then asks the buffer rectangles, boxes and occludee
// triangles, and the occlusion maps rectangles under every depth test. Prints one line per
// instruction set and exits 1 on any difference, or when an instruction set named on the
// command line is not available.
#include <homcull/camera.hpp>
#include <homcull/generate.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/occlusion_maps.hpp>
#include <homcull/world_triangles.hpp>

#include "inputs.hpp"

#include <array>
#include <cstdio>
#include <cstring>
#include <exception>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace homcull;

// What one instruction set makes and answers for one configuration, flattened to compare.
struct Outcome {
    std::vector<float> subtile_floats, depth;
    std::vector<std::uint32_t> subtile_masks;
    std::vector<std::uint64_t> stats;
    std::vector<int> answers;
    std::vector<float> levels;

    bool operator==(const Outcome& o) const {
        // Bit patterns, so that NaN or -0 differences count too.
        const auto same_floats = [](const std::vector<float>& a, const std::vector<float>& b) {
            if (a.size() != b.size()) return false;
            for (std::size_t i = 0; i < a.size(); ++i) {
                std::uint32_t x, y;
                std::memcpy(&x, &a[i], 4);
                std::memcpy(&y, &b[i], 4);
                if (x != y) return false;
            }
            return true;
        };
        return same_floats(subtile_floats, o.subtile_floats) && same_floats(depth, o.depth) && same_floats(levels, o.levels) &&
               subtile_masks == o.subtile_masks && stats == o.stats && answers == o.answers;
    }
};

struct Inputs {
    std::vector<float> soup;
    Scene city;
    WorldTriangles occluders;
    OccluderClusters clusters;
    std::array<float, 16> clip{};
    std::vector<ScreenRect> rects;
    std::vector<Aabb> boxes;
    std::vector<WorldTriangles> objects;
};

Outcome run(const Inputs& in, int samples, bool sample_depth, bool job_system) {
    BufferConfig config;
    config.width = 157 * 4 / samples;  // odd sizes: partial subtiles at the right and bottom
    config.height = 93 * 4 / samples;
    config.samples = samples;
    config.near_w = 0.1f;
    config.sample_depth = sample_depth;
    OcclusionBuffer buffer(config);
    const ParallelFor parallel = job_system ? ParallelFor{&test::run_backwards, nullptr, 2} : ParallelFor{};
    Outcome o;
    const auto record = [&] {
        for (const OcclusionBuffer::Subtile& s : buffer.subtiles()) {
            o.subtile_floats.insert(o.subtile_floats.end(), {s.d0, s.d1});
            o.subtile_masks.insert(o.subtile_masks.end(), {s.mask, s.covered});
        }
        std::vector<float> read_back;
        buffer.read_depth(read_back);
        o.depth.insert(o.depth.end(), read_back.begin(), read_back.end());
        const RasterStats& s = buffer.stats();
        o.stats.insert(o.stats.end(), {s.triangles_in, s.invalid, s.outside, s.near_clipped, s.too_large, s.backface_culled, s.degenerate,
                                       s.rasterized, s.subtiles_updated});
        std::vector<Visibility> v(in.rects.size());
        buffer.test_rects(in.rects.data(), in.rects.size(), v.data());
        for (std::size_t k = 0; k < v.size(); ++k) {
            const ScreenRect& r = in.rects[k];
            o.answers.push_back(int(v[k]));
            o.answers.push_back(int(buffer.test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min)));
        }
        v.resize(in.boxes.size());
        buffer.test_aabbs(in.boxes.data(), in.boxes.size(), in.clip, v.data());
        for (const Visibility a : v) o.answers.push_back(int(a));
        for (const WorldTriangles& object : in.objects) {
            const OcclusionBuffer::TriangleTest t = buffer.test_triangles(object.input(in.clip, Backface::none));
            o.answers.insert(o.answers.end(), {int(t.visibility), int(t.samples), int(t.visible_samples), int(t.deciding_triangle)});
        }
        for (const DepthTest depth : {DepthTest::masked, DepthTest::hzb, DepthTest::nbz, DepthTest::plane}) {
            OcclusionMapsConfig mc;
            mc.display_width = config.width * samples;
            mc.display_height = config.height * samples;
            mc.depth = depth;
            OcclusionMaps maps(buffer, mc);
            maps.build(buffer);
            for (const ScreenRect& r : in.rects) {
                const OccludeeAnswer a = maps.test_rect(r);
                o.answers.insert(o.answers.end(), {int(a.visibility), int(a.overlap_exit)});
                o.levels.push_back(a.level_of_visibility);
            }
        }
    };
    const TriangleInput soup_input = test::clip_space_input(in.soup);
    buffer.render_frame(soup_input, parallel);
    record();
    buffer.render_frame(in.occluders.input(in.clip), parallel);
    record();
    buffer.render_frame(ClusteredInput{&in.clusters, in.clip, Backface::cw}, parallel);
    record();
    return o;
}

}  // namespace

// Arguments: the instruction sets to check (default: every one available but scalar).
int main(int argc, char** argv) {
    try {
        Inputs in;
        in.soup = test::random_clip_triangles(7, 6000, 0.3f);
        const test::CityStreet street;
        in.city = street.city;
        in.occluders = street.occluders;
        in.clusters = build_occluder_clusters(in.occluders.positions.data(), 3 * sizeof(float), in.occluders.positions.size() / 3,
                                              in.occluders.indices.data(), in.occluders.triangle_count(),
                                              in.occluders.shared_edges.data(), in.occluders.edge_apexes.data(), ClusterLimits{});
        in.clip = street.clip(157.0 / 93.0);
        in.rects = test::random_screen_rects(3, 2000);
        for (std::uint32_t id = 0; id < in.city.objects.size(); ++id) {
            in.boxes.push_back(in.city.objects[id].world_bounds);
            if (id % 3 == 0) in.objects.push_back(gather_world_triangles(in.city, {id}));
        }

        const std::vector<std::string> available = available_isas();
        std::printf("isa_bits_check: available:");
        for (const std::string& isa : available) std::printf(" %s", isa.c_str());
        std::printf("\n");
        std::vector<std::string> isas(argv + 1, argv + argc);
        if (isas.empty())
            for (const std::string& isa : available)
                if (isa != "scalar") isas.push_back(isa);
        for (const std::string& isa : isas) select_isa(isa);  // each must be available: throws otherwise
        // Each configuration's scalar outcome once, then every instruction set's against it.
        std::vector<int> different(isas.size(), 0);
        int configurations = 0;
        for (const int samples : {1, 2, 4})
            for (const bool sample_depth : {false, true})
                for (const bool job_system : {false, true}) {
                    select_isa("scalar");
                    const Outcome reference = run(in, samples, sample_depth, job_system);
                    ++configurations;
                    for (std::size_t k = 0; k < isas.size(); ++k) {
                        select_isa(isas[k]);
                        if (run(in, samples, sample_depth, job_system) == reference) continue;
                        ++different[k];
                        std::printf("isa_bits_check: %s differs from scalar: samples %d, per-sample depth %s, %s\n", isas[k].c_str(), samples,
                                    sample_depth ? "on" : "off", job_system ? "job system" : "one thread");
                    }
                }
        int failures = 0;
        for (std::size_t k = 0; k < isas.size(); ++k) {
            std::printf("isa_bits_check: %s: %d of %d configurations give the scalar reference's bits and answers\n", isas[k].c_str(),
                        configurations - different[k], configurations);
            failures += different[k];
        }
        select_isa("best");
        return failures == 0 && !isas.empty() ? 0 : 1;  // no instruction set to check is a failure too
    } catch (const std::exception& e) {
        std::fprintf(stderr, "isa_bits_check: %s\n", e.what());
        return 1;
    }
}
