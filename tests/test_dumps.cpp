// Debug dumps (homcull/io/dumps.hpp, `homcull dump`): the multi-part EXR holds every buffer
// and pyramid level under its name, bit for bit as the library reports them; the PNGs have
// the promised size, colours and legend; errors name the file.
#include "exr_parts.hpp"
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/dumps.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/truth/answer_overlay.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

namespace homcull {
namespace {

// The view of tests/test_cli.cpp's city: streets with buildings in front of others and sky
// above, so the depth parts have both finite values and "no occluder".
Camera city_camera() {
    Camera c;
    c.eye = {-1.0, 1.7, -30.0};
    c.target = {20.0, 3.0, 10.0};
    return c;
}
constexpr int kDisplayW = 96, kDisplayH = 54;
const std::string kCityArguments = "--scene gen:city:seed=2,blocks=3 --eye -1,1.7,-30 --target 20,3,10 --resolution 96x54";

// One culled frame of the city, configured as `homcull dump` does with default options.
struct CityFrame {
    Scene scene = generate_scene("city:seed=2,blocks=3");
    std::vector<std::uint32_t> occluders = filter_by_complexity(scene, occluder_candidates(scene, OccluderFilter::role), 0.0);
    SceneCuller culler;
    explicit CityFrame(const SceneCullerConfig& config) : culler(scene, occluders, config) {
        std::vector<OccludeeAnswer> answers;
        culler.cull(city_camera(), answers);
    }
};

SceneCullerConfig city_config(int samples = 1, DepthTest depth = DepthTest::masked) {
    SceneCullerConfig config;
    config.display = {kDisplayW, kDisplayH};
    config.samples = samples;
    config.maps.depth = depth;
    config.maps.deb_width = 24;  // a deb smaller than the buffer, to see its own size
    config.maps.deb_height = 12;
    return config;
}

using test::ExrPart;

// What the buffer and the maps report, read through their own accessors (not dump_parts),
// in the documented part order.
std::vector<std::pair<std::string, std::vector<float>>> expected_parts(const OcclusionBuffer& buffer, const OcclusionMaps& maps) {
    std::vector<std::pair<std::string, std::vector<float>>> out;
    std::vector<std::uint8_t> covered;
    buffer.read_coverage(covered);
    out.emplace_back("buffer.coverage", std::vector<float>(covered.begin(), covered.end()));
    std::vector<float> depth;
    buffer.read_depth(depth);
    out.emplace_back("buffer.depth", depth);
    // Both depth pyramids, as maps making both give them (the culler's maps make only the one
    // their depth test reads, OcclusionMapsConfig::depth_pyramids; the dump has both). Where
    // the maps make one, it is that one.
    OcclusionMapsConfig with_both = maps.config();
    with_both.depth_pyramids = DepthPyramids::both;
    with_both.pyramid = PyramidBuild::always;  // the dump makes the pyramids that lazy maps leave out
    OcclusionMaps both(buffer, with_both);
    both.build(buffer);
    const OcclusionMaps& pyramids = maps.pyramid_built() ? maps : both;
    for (int k = 0; k < maps.levels(); ++k) {
        const std::size_t n = std::size_t(maps.level_width(k)) * std::size_t(maps.level_height(k));
        std::vector<float> opacity;
        for (int y = 0; y < maps.level_height(k); ++y)
            for (int x = 0; x < maps.level_width(k); ++x) opacity.push_back(pyramids.opacity(k, x, y));
        out.emplace_back("opacity.L" + std::to_string(k), opacity);
        out.emplace_back("maxz.L" + std::to_string(k), std::vector<float>(both.farthest_depth(k), both.farthest_depth(k) + n));
        out.emplace_back("nbz.L" + std::to_string(k), std::vector<float>(both.nearest_depth(k), both.nearest_depth(k) + n));
        if (maps.pyramid_built() && maps.farthest_depth(k)) {
            EXPECT_TRUE(std::equal(maps.farthest_depth(k), maps.farthest_depth(k) + n, both.farthest_depth(k)));
        }
        if (maps.pyramid_built() && maps.nearest_depth(k)) {
            EXPECT_TRUE(std::equal(maps.nearest_depth(k), maps.nearest_depth(k) + n, both.nearest_depth(k)));
        }
    }
    if (maps.config().depth == DepthTest::deb) out.emplace_back("deb", maps.depth_estimation());
    return out;
}

// Every part present in order, one FLOAT channel, and the same bits (memcmp: +inf and -0 too).
void expect_exr_matches(const std::string& path, const OcclusionBuffer& buffer, const OcclusionMaps& maps) {
    const std::vector<ExrPart> parts = test::read_exr_parts(path);
    const auto expected = expected_parts(buffer, maps);
    const std::size_t count = 2 + 3 * std::size_t(maps.levels()) + (maps.config().depth == DepthTest::deb ? 1 : 0);
    ASSERT_EQ(expected.size(), count);
    ASSERT_EQ(parts.size(), count);
    for (std::size_t i = 0; i < count; ++i) {
        SCOPED_TRACE(expected[i].first);
        EXPECT_EQ(parts[i].name, expected[i].first);
        EXPECT_EQ(parts[i].channels, 1);
        EXPECT_TRUE(parts[i].stored_as_float);
        ASSERT_EQ(parts[i].values.size(), expected[i].second.size());
        EXPECT_EQ(std::memcmp(parts[i].values.data(), expected[i].second.data(), parts[i].values.size() * sizeof(float)), 0);
    }
    // Sizes: samples for the buffer, the pyramid's cells per level.
    EXPECT_EQ(parts[0].width, buffer.sample_width());
    EXPECT_EQ(parts[0].height, buffer.sample_height());
    EXPECT_EQ(parts[2].width, maps.level_width(0));
    EXPECT_EQ(parts[2].height, maps.level_height(0));
}

TEST(Dumps, ExrHasEveryPartBitForBitWithTwoSamples) {
    const CityFrame frame(city_config(2));
    // The masked depth test reads neither depth pyramid: the culler's maps make none, the dump
    // still holds both.
    ASSERT_EQ(frame.culler.maps().farthest_depth(0), nullptr);
    ASSERT_EQ(frame.culler.maps().nearest_depth(0), nullptr);
    const std::string dir = test::temp_dir("dumps_exr_samples");
    write_maps_exr(frame.culler.buffer(), frame.culler.maps(), dir + "/maps.exr");
    expect_exr_matches(dir + "/maps.exr", frame.culler.buffer(), frame.culler.maps());
    // The view shows occluders and sky: depth parts hold finite values and +inf.
    std::vector<float> depth;
    frame.culler.buffer().read_depth(depth);
    EXPECT_GT(std::count_if(depth.begin(), depth.end(), [](float w) { return std::isfinite(w); }), 0);
    EXPECT_GT(std::count_if(depth.begin(), depth.end(), [](float w) { return std::isinf(w); }), 0);
}

TEST(Dumps, ExrHasTheDepthEstimationBufferWhenTheMapsUseIt) {
    const CityFrame frame(city_config(1, DepthTest::deb));
    const std::string dir = test::temp_dir("dumps_exr_deb");
    write_maps_exr(frame.culler.buffer(), frame.culler.maps(), dir + "/maps.exr");
    expect_exr_matches(dir + "/maps.exr", frame.culler.buffer(), frame.culler.maps());
    const std::vector<ExrPart> parts = test::read_exr_parts(dir + "/maps.exr");
    EXPECT_EQ(parts.back().name, "deb");
    EXPECT_EQ(parts.back().width, 24);
    EXPECT_EQ(parts.back().height, 12);
    // Filled by the occluder boxes, not left at "nothing".
    EXPECT_TRUE(std::any_of(parts.back().values.begin(), parts.back().values.end(), [](float d) { return std::isfinite(d); }));
}

bool have_legend_font() {
    for (const char* f : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"})
        if (std::filesystem::exists(f)) return true;
    return false;
}

TEST(Dumps, PngsHaveTheExpectedSizeColoursAndRanges) {
    const CityFrame frame(city_config(2));
    const std::string dir = test::temp_dir("dumps_png");
    const std::vector<DumpPart> parts = dump_parts(frame.culler.buffer(), frame.culler.maps());
    const std::vector<ColormapPng> pngs = write_colormap_pngs(parts, dir);
    ASSERT_EQ(pngs.size(), parts.size());
    for (std::size_t i = 0; i < parts.size(); ++i) {
        SCOPED_TRACE(parts[i].name);
        const ColormapPng size = colormap_png_size(parts[i].width, parts[i].height);
        EXPECT_EQ(pngs[i].path, dir + "/" + parts[i].name + ".png");
        EXPECT_EQ(pngs[i].width, size.width);
        EXPECT_EQ(pngs[i].height, size.height);
        EXPECT_GE(pngs[i].width, kMinPngWidth);
        EXPECT_EQ(pngs[i].height, parts[i].height * pngs[i].scale + kLegendHeight);
        auto in = OIIO::ImageInput::open(pngs[i].path);
        ASSERT_TRUE(in) << OIIO::geterror();
        EXPECT_EQ(in->spec().width, size.width);
        EXPECT_EQ(in->spec().height, size.height);
        EXPECT_EQ(in->spec().nchannels, 3);
        // Infinite depths are drawn in the no-occluder colour and left out of the range.
        const auto inf = std::find_if(parts[i].values.begin(), parts[i].values.end(), [](float v) { return std::isinf(v); });
        if (inf != parts[i].values.end()) {
            const std::size_t at = std::size_t(inf - parts[i].values.begin());
            const int x = int(at % std::size_t(parts[i].width)) * pngs[i].scale, y = int(at / std::size_t(parts[i].width)) * pngs[i].scale;
            std::vector<std::uint8_t> image(std::size_t(size.width) * std::size_t(size.height) * 3);
            ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, image.data())) << in->geterror();
            std::array<std::uint8_t, 3> rgb{};
            std::memcpy(rgb.data(), image.data() + (std::size_t(y) * std::size_t(size.width) + std::size_t(x)) * 3, 3);
            EXPECT_EQ(rgb, (std::array<std::uint8_t, 3>{kNoOccluderRgb[0], kNoOccluderRgb[1], kNoOccluderRgb[2]}));
            EXPECT_GT(pngs[i].no_occluder, 0u);
            EXPECT_TRUE(std::isfinite(pngs[i].range_min) && std::isfinite(pngs[i].range_max));
        }
        if (parts[i].colormap == DumpColormap::viridis) {
            EXPECT_EQ(pngs[i].range_min, 0.0);
            EXPECT_EQ(pngs[i].range_max, 1.0);
        }
        if (have_legend_font()) {
            EXPECT_TRUE(pngs[i].text_drawn) << pngs[i].note;
        }
        if (!pngs[i].text_drawn) {
            EXPECT_FALSE(pngs[i].note.empty());
        }
    }
    std::ifstream index_file(dir + "/colormaps.json");
    ASSERT_TRUE(index_file) << "colormaps.json missing";
    const auto index = nlohmann::json::parse(index_file);
    ASSERT_EQ(index.size(), parts.size());
    EXPECT_EQ(index[1]["part"], "buffer.depth");
    EXPECT_EQ(index[1]["colormap"], "magma");
    EXPECT_EQ(index[1]["range"][0].get<double>(), pngs[1].range_min);
    EXPECT_EQ(index[1]["no_occluder_pixels"].get<std::uint64_t>(), pngs[1].no_occluder);
}

TEST(Dumps, UnwritablePathsThrowNamingTheFile) {
    const CityFrame frame(city_config());
    const std::string missing = test::temp_dir("dumps_errors") + "/no/such/folder";
    for (const std::string& path : {missing + "/maps.exr", missing + "/part.png"}) {
        try {
            if (path.find(".exr") != std::string::npos)
                write_maps_exr(frame.culler.buffer(), frame.culler.maps(), path);
            else
                write_colormap_png(dump_parts(frame.culler.buffer(), frame.culler.maps())[0], path);
            ADD_FAILURE() << "no error for " << path;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
    }
    // A format that holds one image cannot hold a dump.
    EXPECT_THROW(write_maps_exr(frame.culler.buffer(), frame.culler.maps(), missing + "/maps.png"), Error);
}

// Runs `homcull <arguments>` (as tests/test_cli.cpp does), stdout and stderr into `dir`.
struct CliRun {
    int exit_code;
    std::string out, err;
};

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

CliRun run_command(const std::string& command, const std::string& dir) {
    const int status = std::system((command + " >" + dir + "/stdout 2>" + dir + "/stderr").c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir + "/stdout"), slurp(dir + "/stderr")};
}

TEST(Dumps, CliDumpWritesTheSameExrAndThePngs) {
    const std::string dir = test::temp_dir("dumps_cli");
    const std::string out = dir + "/dump";  // created by the command
    const CliRun r = run_command(std::string(HOMCULL_CLI_PATH) + " dump " + kCityArguments + " --samples 2 --out " + out, dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(out + "/maps.exr"), std::string::npos) << r.out;
    // The command's frame, bit for bit: the same frame culled here with the same settings.
    const CityFrame frame(city_config(2));
    expect_exr_matches(out + "/maps.exr", frame.culler.buffer(), frame.culler.maps());
    for (const DumpPart& part : dump_parts(frame.culler.buffer(), frame.culler.maps())) {
        SCOPED_TRACE(part.name);
        const std::string png = out + "/" + part.name + ".png";
        ASSERT_TRUE(std::filesystem::exists(png));
        EXPECT_NE(r.out.find(png), std::string::npos);
        auto in = OIIO::ImageInput::open(png);
        ASSERT_TRUE(in) << OIIO::geterror();
        const ColormapPng size = colormap_png_size(part.width, part.height);
        EXPECT_EQ(in->spec().width, size.width);
        EXPECT_EQ(in->spec().height, size.height);
    }
    EXPECT_TRUE(std::filesystem::exists(out + "/colormaps.json"));

    // oiiotool lists every part by name (-a: all subimages; without it, only the first's
    // metadata is printed).
    if (std::system("command -v oiiotool >/dev/null 2>&1") != 0) GTEST_SKIP() << "oiiotool not installed (openimageio-tools)";
    const CliRun info = run_command("oiiotool -a --info -v " + out + "/maps.exr", dir);
    ASSERT_EQ(info.exit_code, 0) << info.err;
    for (const DumpPart& part : dump_parts(frame.culler.buffer(), frame.culler.maps()))
        EXPECT_NE(info.out.find("name: \"" + part.name + "\""), std::string::npos) << part.name << "\n" << info.out;
    // Without -a, the first part's homcull:parts lists them all.
    const CliRun first = run_command("oiiotool --info -v " + out + "/maps.exr", dir);
    ASSERT_EQ(first.exit_code, 0) << first.err;
    for (const DumpPart& part : dump_parts(frame.culler.buffer(), frame.culler.maps()))
        EXPECT_NE(first.out.find(part.name), std::string::npos) << part.name << "\n" << first.out;
    EXPECT_NE(first.out.find("homcull:parts"), std::string::npos) << first.out;
}

TEST(Dumps, OverlayColoursEachAnswerAndShowsFalseCullsInMagenta) {
    const Scene scene = generate_scene("city:seed=2,blocks=3");
    const std::vector<std::uint32_t> occluders = occluder_candidates(scene, OccluderFilter::role);
    SceneCuller culler(scene, occluders, city_config());
    std::vector<OccludeeAnswer> answers;
    culler.cull(city_camera(), answers);
    const RayScene rays(scene);
    const Resolution display{kDisplayW, kDisplayH};
    // The culler's own answers: conservative, so nothing seen is culled.
    const AnswerOverlay right = render_answer_overlay(rays, city_camera(), display, answers, culler.drawn_occluders());
    ASSERT_EQ(right.rgb.size(), std::size_t(3 * kDisplayW * kDisplayH));
    EXPECT_EQ(right.false_cull_pixels, 0u);
    std::size_t blue = 0, grey = 0;
    for (std::size_t i = 0; i < right.rgb.size(); i += 3) {
        const int r = right.rgb[i], g = right.rgb[i + 1], b = right.rgb[i + 2];
        blue += b > r + 40 && b > g;
        grey += r == g && g == b && r > 0;
    }
    EXPECT_GT(blue, 0u) << "drawn occluders";
    EXPECT_GT(grey, 0u) << "kept objects";
    // Cull one object that is seen: it turns up as a false cull, in magenta.
    std::uint32_t seen = kNoObject;
    for (std::uint32_t id = 0; id < answers.size() && seen == kNoObject; ++id)
        if (answers[id].visibility == Visibility::visible &&
            std::find(culler.drawn_occluders().begin(), culler.drawn_occluders().end(), id) == culler.drawn_occluders().end())
            seen = id;
    ASSERT_NE(seen, kNoObject);
    std::vector<OccludeeAnswer> wrong = answers;
    wrong[seen].visibility = Visibility::occluded;
    const AnswerOverlay loud = render_answer_overlay(rays, city_camera(), display, wrong, culler.drawn_occluders());
    if (loud.false_cull_pixels == 0) GTEST_SKIP() << "object " << seen << " is visible to the culler but no pixel centre sees it";
    EXPECT_EQ(loud.false_culls, std::vector<std::uint32_t>{seen});
    std::size_t magenta = 0;
    for (std::size_t i = 0; i < loud.rgb.size(); i += 3) magenta += loud.rgb[i] == 255 && loud.rgb[i + 1] == 0 && loud.rgb[i + 2] == 255;
    EXPECT_EQ(magenta, loud.false_cull_pixels);
    EXPECT_THROW(render_answer_overlay(rays, city_camera(), display, {}, {}), Error);

    // From above: every kind of answer shows, and the frustum.
    const AnswerOverlay map =
        render_answer_map(rays, scene.bounds(), city_camera(), display, wrong, culler.drawn_occluders(), loud.false_culls, 400);
    EXPECT_EQ(map.width, 400);
    auto count = [&](auto is) {
        std::size_t n = 0;
        for (std::size_t i = 0; i < map.rgb.size(); i += 3) n += is(map.rgb[i], map.rgb[i + 1], map.rgb[i + 2]);
        return n;
    };
    EXPECT_GT(count([](int r, int g, int b) { return r > g + 40 && g > 40 && b == 0; }), 0u) << "occluded, orange";
    EXPECT_GT(count([](int r, int g, int b) { return r == 255 && g == 224 && b == 0; }), 0u) << "the frustum, yellow";
    EXPECT_GT(count([](int r, int g, int b) { return b > r + 40 && b > g; }), 0u) << "occluders, blue";
    EXPECT_GT(count([](int r, int g, int b) { return r > 100 && g == 0 && r == b; }), 0u) << "the false cull, magenta";
    // Ids that are not objects are an error, as for the overlay.
    const std::vector<std::uint32_t> not_an_object = {std::uint32_t(wrong.size())};
    EXPECT_THROW(render_answer_map(rays, scene.bounds(), city_camera(), display, wrong, not_an_object, {}, 400), Error);
    EXPECT_THROW(render_answer_map(rays, scene.bounds(), city_camera(), display, wrong, {}, not_an_object, 400), Error);
}

TEST(Dumps, CullDumpWritesTheMapsAndTheOverlay) {
    const std::string dir = test::temp_dir("dumps_cull");
    const CliRun r =
        run_command(std::string(HOMCULL_CLI_PATH) + " cull " + kCityArguments + " --truth --json --dump " + dir + "/frame", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << "the dump's lines go to stderr with --json:\n" << r.out;
    EXPECT_NE(r.err.find("0 false-cull pixels"), std::string::npos) << r.err;
    for (const char* file : {"maps.exr", "overlay.png", "overlay_top.png", "colormaps.json", "opacity.L0.png"})
        EXPECT_TRUE(std::filesystem::exists(dir + "/frame/" + file)) << file;
    auto in = OIIO::ImageInput::open(dir + "/frame/overlay.png");
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_EQ(in->spec().width, kDisplayW);
    EXPECT_EQ(in->spec().height, kDisplayH);
}

// A walk report of the city (`homcull path`, then `walk --dump DIR/report`); fails the test
// when a command fails.
void write_city_walk_report(const std::string& dir, int frames) {
    const std::string cli = std::string(HOMCULL_CLI_PATH);
    CliRun r = run_command(cli + " path --scene gen:city:seed=2,blocks=3 --frames " + std::to_string(frames) + " --out " + dir +
                               "/walk.json",
                           dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_command(cli + " walk --scene gen:city:seed=2,blocks=3 --path " + dir + "/walk.json --resolution 96x54 --quiet --dump " +
                        dir + "/report",
                    dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
}

TEST(Dumps, WalkReportShowsThePlotsTheSummaryAndTheFirstFrame) {
    const std::string dir = test::temp_dir("dumps_walk");
    ASSERT_NO_FATAL_FAILURE(write_city_walk_report(dir, 5));
    const std::string html = slurp(dir + "/report/report.html");
    ASSERT_FALSE(html.empty());
    for (const char* text : {"Culling graph", "Time per frame", "false culls", "efficiency"})
        EXPECT_NE(html.find(text), std::string::npos) << text;
    // Every image and link the page names exists.
    std::size_t images = 0;
    for (const char* attribute : {"src=\"", "href=\""}) {
        for (std::size_t at = html.find(attribute); at != std::string::npos; at = html.find(attribute, at + 1)) {
            const std::size_t begin = at + std::strlen(attribute), end = html.find('"', begin);
            const std::string file = html.substr(begin, end - begin);
            EXPECT_TRUE(std::filesystem::exists(dir + "/report/" + file)) << file;
            images += file.size() > 4 && file.compare(file.size() - 4, 4, ".png") == 0;
        }
    }
    EXPECT_GE(images, 4u);  // three plots and the overlay at least
    for (const char* plot : {"culling_graph.png", "objects_graph.png", "frame_ms.png"}) {
        auto in = OIIO::ImageInput::open(dir + "/report/" + plot);
        ASSERT_TRUE(in) << plot << ": " << OIIO::geterror();
        EXPECT_EQ(in->spec().width, 960);
        EXPECT_EQ(in->spec().height, 360);
    }
}

// The report renders in a real browser and every image on it loads: headless Chromium
// (Debian's chromium package, installed by scripts/install-deps.sh) runs the page's own
// image check and prints the DOM after it.
std::string chromium_command() {
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"})
        if (std::system((std::string("command -v ") + name + " >/dev/null 2>&1").c_str()) == 0) return name;
    return "";
}

TEST(Dumps, WalkReportRendersInHeadlessChromiumWithEveryImage) {
    const std::string browser = chromium_command();
    if (browser.empty()) GTEST_SKIP() << "no chromium (bash scripts/install-deps.sh installs it)";
    const std::string dir = test::temp_dir("dumps_chromium");
    ASSERT_NO_FATAL_FAILURE(write_city_walk_report(dir, 4));
    const std::string page = "file://" + std::filesystem::absolute(dir + "/report/report.html").string();
    const std::string headless = "timeout 120 " + browser + " --headless --no-sandbox --disable-gpu --user-data-dir=" + dir +
                                 "/profile --virtual-time-budget=5000 ";
    auto image_check = [&] {
        const CliRun dom = run_command(headless + "--dump-dom " + page, dir);
        EXPECT_EQ(dom.exit_code, 0) << dom.err;
        const std::size_t at = dom.out.find("id=\"image-check\">");
        if (at == std::string::npos) return std::string("no image check in the DOM:\n") + dom.out.substr(0, 2000);
        const std::size_t begin = at + std::strlen("id=\"image-check\">");
        return dom.out.substr(begin, dom.out.find('<', begin) - begin);
    };
    const std::string all = image_check();
    int loaded = -1, total = -2;
    ASSERT_EQ(std::sscanf(all.c_str(), "%d of %d images loaded", &loaded, &total), 2) << all;
    EXPECT_GE(total, 4);
    EXPECT_EQ(loaded, total) << all;
    // It renders: a screenshot of the page, not blank.
    const CliRun shot = run_command(headless + "--window-size=1000,1400 --screenshot=" + dir + "/shot.png " + page, dir);
    ASSERT_EQ(shot.exit_code, 0) << shot.err;
    OIIO::ImageBuf screenshot(dir + "/shot.png");
    ASSERT_TRUE(screenshot.read()) << screenshot.geterror();
    EXPECT_EQ(screenshot.spec().width, 1000);
    const auto stats = OIIO::ImageBufAlgo::computePixelStats(screenshot);
    EXPECT_GT(stats.max[0] - stats.min[0], 0.5f) << "a blank page";
    // The check can fail: a missing image is counted.
    std::filesystem::remove(dir + "/report/frame_ms.png");
    EXPECT_EQ(image_check(), std::to_string(total - 1) + " of " + std::to_string(total) + " images loaded");
}

TEST(Dumps, CliDumpFailsNamingAnUnusableFolder) {
    const std::string dir = test::temp_dir("dumps_cli_error");
    test::write_text(dir + "/file", "not a folder");
    const CliRun r = run_command(std::string(HOMCULL_CLI_PATH) + " dump " + kCityArguments + " --out " + dir + "/file/sub", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(dir + "/file/sub"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace homcull
