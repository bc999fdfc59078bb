// Golden-image tests: the occlusion buffer and every pyramid level of a few views, compared
// with references under tests/golden/ on every instruction set, bit for bit. A difference
// fails with the numbers (OpenImageIO's ImageBufAlgo::compare, as idiff reports them) and a
// difference image next to the test's files.
//
// After an intended change, regenerate the references (scalar reference path) and review
// them before committing:
//   HOMCULL_UPDATE_GOLDENS=1 build/tests/homcull_tests --gtest_filter='Golden.*'
#include "exr_parts.hpp"
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/dumps.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/scene_culler.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace homcull {
namespace {

// The failure and warning thresholds of the comparison: the culler promises the same bits on
// every target, so any difference fails.
constexpr float kFailThreshold = 0.0f, kWarnThreshold = 0.0f;

struct GoldenCase {
    const char* name;   // tests/golden/<name>.exr
    const char* scene;  // gen:... or a file of the shared scenes
    Camera camera;
    Resolution display;
    int samples;
    DepthTest depth;
    bool clusters = false;  // SceneCullerConfig::occluder_clusters
};

Camera look(glm::dvec3 eye, glm::dvec3 target, double fov_y = 60.0, double near_plane = 0.1) {
    Camera c;
    c.eye = eye;
    c.target = target;
    c.fov_y_degrees = fov_y;
    c.near_plane = near_plane;
    return c;
}

std::vector<GoldenCase> golden_cases() {
    return {
        {"city", "gen:city:seed=2,blocks=3", look({-1, 1.7, -30}, {20, 3, 10}), {160, 90}, 1, DepthTest::masked},
        {"city_samples2", "gen:city:seed=2,blocks=3", look({-1, 1.7, -30}, {20, 3, 10}), {160, 90}, 2, DepthTest::masked},
        {"forest_deb", "gen:forest:seed=4,radius=40", look({0, 1.7, -35}, {3, 1.5, 0}), {160, 90}, 1, DepthTest::deb},
        {"fzk_haus", "fzk_haus.glb", look({-9, 4, 8}, {6, 2, -5}), {320, 180}, 1, DepthTest::masked},
        {"castle_c0", "intel_castle.glb", look({27, 2, -47}, {28.4258, 2.6111, -37.1211}, 36.0, 1.0), {320, 180}, 1,
         DepthTest::masked},
        {"castle_c0_clusters", "intel_castle.glb", look({27, 2, -47}, {28.4258, 2.6111, -37.1211}, 36.0, 1.0), {320, 180}, 1,
         DepthTest::masked, true},
    };
}

std::string golden_path(const GoldenCase& c) { return std::string(HOMCULL_SOURCE_DIR) + "/tests/golden/" + c.name + ".exr"; }

// The scene of a case, or "" with the reason it is skipped.
bool load_case_scene(const GoldenCase& c, Scene& scene, std::string& why) {
    if (std::strncmp(c.scene, "gen:", 4) == 0) {
        scene = load_scene(c.scene);
        return true;
    }
    const std::string file = test::shared_scene(c.scene);
    if (file.empty()) {
        why = std::string(c.scene) + " is not in " + test::shared_scenes_dir();
        return false;
    }
    scene = load_scene(file);
    return true;
}

// The frame's parts, culled on the instruction set selected now.
std::vector<DumpPart> render_case(const GoldenCase& c, const Scene& scene) {
    SceneCullerConfig config;
    config.display = c.display;
    config.samples = c.samples;
    config.maps.depth = c.depth;
    config.occluder_clusters = c.clusters;
    SceneCuller culler(scene, occluder_candidates(scene, OccluderFilter::size), config);
    std::vector<OccludeeAnswer> answers;
    culler.cull(c.camera, answers);
    return dump_parts(culler.buffer(), culler.maps());
}

struct Comparison {
    bool same = true;
    std::string report;                   // the numbers of every differing part
    std::vector<std::string> diff_images;  // written for the differing parts
};

using test::ExrPart;

// Compares every part of `current` with the part at the same place in `reference` (names must
// agree) with ImageBufAlgo::compare; writes |current - reference| as
// <diff_prefix>.<part>.exr where they differ.
Comparison compare_exr(const std::string& reference, const std::string& current, const std::string& diff_prefix) {
    Comparison result;
    std::vector<ExrPart> ref = test::read_exr_parts(reference), now = test::read_exr_parts(current);
    if (ref.size() != now.size()) {
        result.same = false;
        result.report += "the reference has " + std::to_string(ref.size()) + " parts, the dump " + std::to_string(now.size()) + "\n";
    }
    for (std::size_t k = 0; k < std::min(ref.size(), now.size()); ++k) {
        ExrPart& a = now[k];
        ExrPart& b = ref[k];
        if (a.name != b.name || a.width != b.width || a.height != b.height || a.channels != b.channels) {
            result.same = false;
            result.report += "part " + std::to_string(k) + ": " + a.name + " against the reference's " + b.name + " (name or size differs)\n";
            continue;
        }
        OIIO::ImageSpec spec(a.width, a.height, a.channels, OIIO::TypeDesc::FLOAT);
        const OIIO::ImageBuf image_now(spec, a.values.data()), image_ref(spec, b.values.data());
        const OIIO::ImageBufAlgo::CompareResults r = OIIO::ImageBufAlgo::compare(image_now, image_ref, kFailThreshold, kWarnThreshold);
        // compare() finds inf - inf = NaN "equal"; the culler's +inf ("no occluder") must match
        // as exactly as any value, so the bits are compared too.
        const bool bits = std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)) == 0;
        if (r.nfail == 0 && r.nwarn == 0 && bits) continue;
        result.same = false;
        const std::string diff = diff_prefix + "." + a.name + ".exr";
        const OIIO::ImageBuf difference = OIIO::ImageBufAlgo::absdiff(image_now, image_ref);
        difference.write(diff);
        result.diff_images.push_back(diff);
        char line[512];
        std::snprintf(line, sizeof line,
                      "%s: %llu pixels fail, %llu warn (thresholds %g, %g); max error %g at (%d, %d); mean %g; rms %g; "
                      "bits %s; difference image %s\n",
                      a.name.c_str(), (unsigned long long)r.nfail, (unsigned long long)r.nwarn, double(kFailThreshold),
                      double(kWarnThreshold), r.maxerror, r.maxx, r.maxy, r.meanerror, r.rms_error, bits ? "equal" : "differ",
                      diff.c_str());
        result.report += line;
    }
    return result;
}

TEST(Golden, BuffersAndPyramidsMatchTheReferencesOnEveryIsa) {
    const bool update = std::getenv("HOMCULL_UPDATE_GOLDENS") != nullptr;
    const std::string dir = test::temp_dir("golden");
    std::vector<std::string> skipped;
    for (const GoldenCase& c : golden_cases()) {
        SCOPED_TRACE(c.name);
        Scene scene;
        std::string why;
        if (!load_case_scene(c, scene, why)) {
            skipped.push_back(std::string(c.name) + ": " + why);
            continue;
        }
        if (update) {
            const test::ScopedIsa reference_isa("scalar");
            write_maps_exr(render_case(c, scene), golden_path(c));
            std::printf("[ golden   ] wrote %s\n", golden_path(c).c_str());
            continue;
        }
        ASSERT_TRUE(std::filesystem::exists(golden_path(c))) << golden_path(c) << " is missing; see this file's header";
        for (const std::string& isa : available_isas()) {
            const test::ScopedIsa selected(isa);
            const std::string current = dir + "/" + c.name + "." + isa + ".exr";
            write_maps_exr(render_case(c, scene), current);
            const Comparison r = compare_exr(golden_path(c), current, dir + "/" + c.name + "." + isa + ".diff");
            EXPECT_TRUE(r.same) << c.name << " on " << isa << " differs from " << golden_path(c) << ":\n" << r.report;
        }
    }
    std::string isas;
    for (const std::string& isa : available_isas()) isas += " " + isa;
    std::printf("[ golden   ] %zu cases, each on:%s\n", golden_cases().size() - skipped.size(), isas.c_str());
    for (const std::string& s : skipped) std::printf("[ golden   ] skipped %s\n", s.c_str());
}

// The comparison catches one changed reference pixel, and writes a difference image that shows it.
TEST(Golden, OneChangedReferencePixelFailsWithADifferenceImage) {
    const GoldenCase c = golden_cases().front();
    Scene scene;
    std::string why;
    ASSERT_TRUE(load_case_scene(c, scene, why));
    const std::string dir = test::temp_dir("golden_one_pixel");
    std::vector<DumpPart> parts = render_case(c, scene);
    write_maps_exr(parts, dir + "/current.exr");
    write_maps_exr(parts, dir + "/reference.exr");
    EXPECT_TRUE(compare_exr(dir + "/reference.exr", dir + "/current.exr", dir + "/same").same);
    // One pixel of one level: opacity.L2 at (5, 3), 0.25 more or less.
    bool changed = false;
    for (DumpPart& part : parts)
        if (part.name == "opacity.L2") {
            ASSERT_GT(part.width, 5);
            ASSERT_GT(part.height, 3);
            float& v = part.values[std::size_t(3 * part.width + 5)];
            v = v > 0.5f ? v - 0.25f : v + 0.25f;
            changed = true;
        }
    ASSERT_TRUE(changed) << "the dump has no part opacity.L2";
    write_maps_exr(parts, dir + "/reference.exr");
    const Comparison r = compare_exr(dir + "/reference.exr", dir + "/current.exr", dir + "/changed");
    EXPECT_FALSE(r.same);
    EXPECT_NE(r.report.find("opacity.L2: 1 pixels fail"), std::string::npos) << r.report;
    EXPECT_NE(r.report.find("at (5, 3)"), std::string::npos) << r.report;
    ASSERT_EQ(r.diff_images.size(), 1u) << r.report;
    OIIO::ImageBuf diff(r.diff_images.front());
    ASSERT_TRUE(diff.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << diff.geterror();
    float pixel = 0.0f;
    diff.getpixel(5, 3, &pixel, 1);
    EXPECT_FLOAT_EQ(pixel, 0.25f);
}

}  // namespace
}  // namespace homcull
