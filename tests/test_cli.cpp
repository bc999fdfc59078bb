// The homcull program end to end: exit codes, messages, JSON.
#include "support.hpp"

#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>
#include <utility>
#include <vector>
#include <sys/wait.h>

namespace homcull {
namespace {

struct CliRun {
    int exit_code;
    std::string out, err;
};

CliRun run_cli(const std::string& arguments) {
    // One folder per test and call: ctest runs tests in parallel processes.
    static int call = 0;
    const std::string dir = test::temp_dir(std::string("cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                                           "_" + std::to_string(call++));
    const std::string command = std::string(HOMCULL_CLI_PATH) + " " + arguments + " >" + dir + "/out 2>" + dir + "/err";
    const int status = std::system(command.c_str());
    auto slurp = [](const std::string& path) {
        std::FILE* f = std::fopen(path.c_str(), "rb");
        std::string text;
        if (!f) return text;
        std::array<char, 65536> buffer;
        for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), f)) > 0;) text.append(buffer.data(), n);
        std::fclose(f);
        return text;
    };
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir + "/out"), slurp(dir + "/err")};
}

#define EXPECT_MENTIONS(text, fragment) EXPECT_NE((text).find(fragment), std::string::npos) << (text)

const std::string kCityCamera = "--scene gen:city:seed=2,blocks=3 --eye -1,1.7,-30 --target 20,3,10 --resolution 96x54";

TEST(Cli, TruthJsonHasEveryObjectInTheDesignFormat) {
    const CliRun r = run_cli("truth " + kCityCamera + " --samples 2 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j["objects"].is_array());
    std::uint64_t samples = 0;
    for (std::size_t i = 0; i < j["objects"].size(); ++i) {
        const auto& o = j["objects"][i];
        EXPECT_EQ(o["id"], i);
        for (const char* key : {"name", "triangles", "in_frustum", "visible_samples", "robust_samples", "tie_samples", "result"})
            EXPECT_TRUE(o.contains(key)) << key;
        samples += o["visible_samples"].get<std::uint64_t>();
    }
    EXPECT_EQ(samples + j["summary"]["background_samples"].get<std::uint64_t>(), 96u * 54u * 4u);
    EXPECT_EQ(j["resolution"], nlohmann::json({96, 54}));
}

TEST(Cli, CullJsonHasEveryObjectStagesAndTruth) {
    const CliRun r = run_cli("cull " + kCityCamera + " --samples 2 --depth hzb --truth --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j["objects"].is_array());
    std::size_t occluded = 0;
    for (std::size_t i = 0; i < j["objects"].size(); ++i) {
        const auto& o = j["objects"][i];
        EXPECT_EQ(o["id"], i);
        for (const char* key : {"name", "triangles", "result", "level_of_visibility", "truth", "visible_samples", "robust_samples",
                                "tie_samples"})
            EXPECT_TRUE(o.contains(key)) << key;
        EXPECT_LE(o["robust_samples"].get<std::uint64_t>(), o["visible_samples"].get<std::uint64_t>());
        occluded += o["result"] == "occluded";
    }
    EXPECT_GT(occluded, 0u);
    EXPECT_EQ(j["summary"]["occluded"], occluded);
    EXPECT_EQ(j["buffer"], nlohmann::json({48, 27}));
    EXPECT_EQ(j["truth"]["false_culls"], 0);
    for (const char* stage : {"render", "maps", "tests"}) EXPECT_TRUE(j["timings_ms"].contains(stage)) << stage;
    EXPECT_TRUE(j["stats"].contains("triangles_in"));
    EXPECT_TRUE(j["overlap_exits"].contains("predictive_rejection"));
    // The configuration that made it, every option as given.
    ASSERT_TRUE(j.contains("config"));
    EXPECT_EQ(j["config"]["depth"], "hzb");
    EXPECT_EQ(j["config"]["back_faces"], "draw");
    EXPECT_EQ(j["config"]["occludee_parts"], 16);
}

// homcull sort: moving toothpicks in front of one camera, every frame checked against Embree.
TEST(Cli, SortPrintsLayersCyclesStagesAndTheCheck) {
    const CliRun r = run_cli("sort --scene gen:toothpicks:count=60,seed=3 --eye 0,3,22 --target 0,0,0 --fov-y 40 "
                             "--frames 4 --rounds 2 --resolution 160x120 --check --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["frames"].size(), 4u);
    for (const auto& f : j["frames"]) {
        std::size_t listed = 0;
        for (const auto& layer : f["layers"]) listed += layer.size();
        EXPECT_EQ(listed, f["sorted"].get<std::size_t>());
        EXPECT_EQ(f["check"]["violations"].get<int>(), 0);
        EXPECT_GE(f["total_ms"].get<double>(), 0.0);
        EXPECT_TRUE(f["stages_ms"].contains("order"));
    }
    EXPECT_GT(j["summary"]["check"]["true_edges"].get<int>(), 0);
    // A moving scene needs the toothpicks.
    EXPECT_NE(run_cli("sort --scene gen:city --eye 0,3,22 --target 0,0,0 --frames 3").exit_code, 0);
    // Toothpicks moving along a camera path: frame k seen by the path's camera k (repeated).
    const std::string path = test::temp_dir("cli_sort_path") + "/path.json";
    test::write_text(path, R"({"frames":[{"eye":[0,3,22],"target":[0,0,0]},{"eye":[22,3,0],"target":[0,0,0]}]})");
    const CliRun along = run_cli("sort --scene gen:toothpicks:count=40 --path " + path + " --frames 3 --rounds 1 --json");
    ASSERT_EQ(along.exit_code, 0) << along.err;
    const auto k = nlohmann::json::parse(along.out);
    ASSERT_EQ(k["frames"].size(), 3u);
    EXPECT_EQ(k["frames"][2]["camera"]["eye"], k["frames"][0]["camera"]["eye"]);
    EXPECT_NE(k["frames"][1]["camera"]["eye"], k["frames"][0]["camera"]["eye"]);
}

TEST(Cli, SoupCellsSplitLargeObjectsForEveryCommand) {
    // The city's objects hold 12 to a few hundred triangles: at 8, the larger ones split.
    CliRun r = run_cli("info --scene gen:city:seed=2,blocks=3 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::size_t whole = nlohmann::json::parse(r.out)["objects"].size();
    r = run_cli("info --scene gen:city:seed=2,blocks=3 --soup-cells 8 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::size_t cells = nlohmann::json::parse(r.out)["objects"].size();
    EXPECT_GT(cells, whole);
    r = run_cli("cull " + kCityCamera + " --soup-cells 8 --truth --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["objects"].size(), cells);
    EXPECT_EQ(j["truth"]["false_culls"], 0);
    EXPECT_MENTIONS(j["scene"].get<std::string>(), "soup cells");
}

// A call homcull must refuse: exit code 1 for what the library or a command checks (the message
// then names the problem), a CLI11 usage error (100 and above) for what an option's own check
// refuses; either way `message` is in what it prints on stderr.
constexpr int kUsageError = 100;
void expect_refused(const std::string& arguments, int exit_code, const std::string& message) {
    const CliRun r = run_cli(arguments);
    if (exit_code == kUsageError) EXPECT_GE(r.exit_code, kUsageError) << arguments;
    else EXPECT_EQ(r.exit_code, exit_code) << arguments;
    EXPECT_MENTIONS(r.err, message);
}

TEST(Cli, CullRejectsInconsistentOptions) {
    const std::string cull = "cull " + kCityCamera;
    expect_refused(cull + " --buffer 40x20", 1, "conservative culling needs");
    expect_refused(cull + " --mode approximate", 1, "--hole");
    expect_refused(cull + " --hole 4", 1, "--mode approximate");
    expect_refused(cull + " --mode approximate --hole 4 --distribution 9", 1, "distribution");
    expect_refused("cull --scene /nonexistent.glb --eye 0,0,0 --target 1,0,0", 1, "/nonexistent.glb");
    expect_refused(cull + " --depth zbuffer", kUsageError, "--depth");
    // accuracy's culling options belong to --scene; without it (S1) they would be ignored.
    expect_refused("accuracy --mode approximate --hole 4", 1, "--mode needs --scene");
    // Values out of range are refused, not wrapped or ignored.
    expect_refused(cull + " --budget -1", kUsageError, "--budget: must be a whole number >= 0");
    expect_refused(cull + " --coarsest-level -5", 1, "coarsest level must be -1");
    expect_refused("accuracy --scene gen:city:seed=2,blocks=3 --orbit 2 --walk 2", kUsageError, "excludes");
    // A bad size names the option it came from.
    expect_refused(cull + " --buffer 0x0", 1, "--buffer: expected WxH between 1x1 and 65536x65536");
    expect_refused(cull + " --deb 64x-3", 1, "--deb: expected WxH");

    // Approximate mode takes any buffer: by default the most samples per pixel (4, 2 or 1) that
    // fit within the display.
    CliRun r = run_cli(cull + " --buffer 40x20 --samples 2 --mode approximate --hole 2 --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["samples"], 2);
    r = run_cli(cull + " --buffer 24x12 --mode approximate --hole 2 --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["samples"], 4);
    r = run_cli(cull + " --buffer 40x20 --mode approximate --hole 2 --json");  // 4 x 4 would pass the 96 x 54 display
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["samples"], 2);
    // What those checks must still accept.
    r = run_cli(cull + " --budget 1000 --complexity 5e-1 --coarsest-level -1 --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    // A buffer whose samples can lie on the display's pixel centres gets those samples.
    r = run_cli(cull + " --buffer 48x27 --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["samples"], 2);
}

TEST(Cli, PathFileFramesDriveTheCamera) {
    const std::string dir = test::temp_dir("cli_path");
    CliRun r = run_cli("path --scene gen:city:blocks=3 --kind walk --frames 20 --out " + dir + "/walk.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_cli("truth --scene gen:city:blocks=3 --path " + dir + "/walk.json --frame 19 --resolution 64x36 --id-image " + dir +
            "/ids.png");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_MENTIONS(r.out, "ids.png");
    r = run_cli("truth --scene gen:city:blocks=3 --path " + dir + "/walk.json --frame 20 --resolution 64x36");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "frame 20 out of range (the path has 20 frames)");
    r = run_cli("path --scene gen:city:blocks=3 --kind orbit --frames 8");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["frames"].size(), 8u);
}

TEST(Cli, WalkReportsEveryFrameAndASummary) {
    const std::string dir = test::temp_dir("cli_walk");
    CliRun r = run_cli("path --scene gen:city:seed=2,blocks=3 --kind walk --frames 6 --out " + dir + "/walk.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* strategy : {"one-pass", "progressive", "temporal"}) {
        r = run_cli("walk --scene gen:city:seed=2,blocks=3 --path " + dir + "/walk.json --resolution 96x54 --strategy " + strategy +
                    " --json");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_MENTIONS(r.err, "frame 6/6");  // the progress bar
        const auto j = nlohmann::json::parse(r.out);
        ASSERT_EQ(j["frames"].size(), 6u);
        EXPECT_EQ(j["strategy"], strategy);
        for (const auto& frame : j["frames"]) {
            for (const char* key : {"objects_total", "objects_after_frustum", "objects_after_occlusion", "objects_exactly_visible",
                                    "triangles_total",
                                    "triangles_after_frustum", "triangles_after_occlusion", "triangles_exactly_visible", "false_culls",
                                    "missed_culls", "render_ms", "maps_ms", "tests_ms", "select_ms", "truth_ms", "timings_ms", "work"})
                EXPECT_TRUE(frame.contains(key)) << key;
            EXPECT_EQ(frame["false_culls"], 0);
            const auto& objects = frame["objects"];
            ASSERT_TRUE(objects.is_array());
            ASSERT_EQ(objects.size(), frame["objects_total"].get<std::size_t>());
            std::size_t kept = 0;
            for (const auto& o : objects) {
                for (const char* key : {"id", "name", "triangles", "result", "truth"}) EXPECT_TRUE(o.contains(key)) << key;
                kept += o["result"] == "visible";
            }
            EXPECT_EQ(frame["objects_after_occlusion"].get<double>(), double(kept));
        }
        for (const char* key : {"cull_ms", "render_ms", "objects_after_occlusion", "false_culls"}) {
            EXPECT_TRUE(j["summary"][key].contains("mean")) << key;
            EXPECT_TRUE(j["summary"][key].contains("max")) << key;
        }
        EXPECT_EQ(j["summary"]["total_false_culls"], 0);
        EXPECT_EQ(j["summary"]["frames"], 6);
    }
    r = run_cli("walk --scene gen:city:blocks=3 --path " + dir + "/missing.json");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "missing.json");
    r = run_cli("walk --scene gen:city:blocks=3 --path " + dir + "/walk.json --strategy twice");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_MENTIONS(r.err, "--strategy");
    // Camera cuts: limits out of range are errors that name them; inf turns the step's off, and
    // the summary counts the frames without history (the first at least).
    for (const char* bad : {"--cut-step -1", "--cut-step nan"}) {
        r = run_cli("walk --scene gen:city:blocks=3 --path " + dir + "/walk.json --resolution 96x54 --truth off --quiet " + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
        EXPECT_MENTIONS(r.err, "step") << bad;
    }
    r = run_cli("walk --scene gen:city:blocks=3 --path " + dir + "/walk.json --resolution 96x54 --truth off --quiet --cut-turn 181");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_MENTIONS(r.err, "--cut-turn");
    r = run_cli("walk --scene gen:city:blocks=3 --path " + dir + "/walk.json --resolution 96x54 --truth off --quiet --json "
                "--cut-step inf --cut-turn 180 --back-faces cull --sample-depth off");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json walked = nlohmann::json::parse(r.out);
    EXPECT_EQ(walked["summary"]["frames_without_history"], 1);
    // The configuration that made the walk, every option as given.
    ASSERT_TRUE(walked.contains("config"));
    EXPECT_EQ(walked["config"]["back_faces"], "cull");
    EXPECT_EQ(walked["config"]["sample_depth"], "off");
    EXPECT_EQ(walked["config"]["cut_turn"], 180.0);
    r = run_cli("walk --scene gen:city:blocks=3 --path " + dir + "/walk.json --resolution 96x54 --truth off --quiet");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_MENTIONS(r.out, "cull_ms");
}

TEST(Cli, BakeInShardsMergeAndWalkWithTheBakedRanking) {
    const std::string dir = test::temp_dir("cli_bake");
    const std::string scene = "--scene gen:city:seed=2,blocks=3";
    CliRun r = run_cli("bake " + scene + " --spacing 4 --rays 128 --quiet --out " + dir + "/whole.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_MENTIONS(r.out, "points in");
    for (const char* shard : {"0", "1"}) {
        r = run_cli("bake " + scene + " --spacing 4 --rays 128 --shard " + shard + "/2 --out " + dir + "/part" + shard + ".json");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_MENTIONS(r.err, "baking column");  // progress
    }
    r = run_cli("bake --merge " + dir + "/part1.json " + dir + "/part0.json --out " + dir + "/merged.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto whole = nlohmann::json::parse(std::ifstream(dir + "/whole.json"));
    const auto merged = nlohmann::json::parse(std::ifstream(dir + "/merged.json"));
    EXPECT_EQ(whole, merged);

    r = run_cli("path " + scene + " --frames 4 --out " + dir + "/walk.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_cli("walk " + scene + " --path " + dir + "/walk.json --resolution 96x54 --rank baked --grid " + dir +
                "/merged.json --budget 500 --lod on --quiet --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["rank"], "baked");
    EXPECT_EQ(j["lod"], "on");
    EXPECT_EQ(j["summary"]["total_false_culls"], 0);
    EXPECT_LE(j["summary"]["occluder_triangles"]["max"].get<double>(), 500.0);

    // Bad input: a shard beyond its count, a missing shard, a ranking without its grid, a shard as a grid.
    for (const char* bad : {"2/2", "1/-3", "4294967297/4294967298", "1/", "x/2", "0/2/"}) {
        r = run_cli("bake " + scene + " --shard " + bad + " --out " + dir + "/x.json");
        EXPECT_EQ(r.exit_code, 1) << bad;
        EXPECT_MENTIONS(r.err, "--shard");
    }
    r = run_cli("bake --merge " + dir + "/part0.json --out " + dir + "/x.json");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "shard files are missing");
    r = run_cli("walk " + scene + " --path " + dir + "/walk.json --rank baked");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "--grid");
    r = run_cli("walk " + scene + " --path " + dir + "/walk.json --rank baked --grid " + dir + "/part0.json");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "merge the shards first");
}

TEST(Cli, ExportThenInfoGivesTheSameScene) {
    const std::string dir = test::temp_dir("cli_export");
    CliRun r = run_cli("export --scene gen:forest:radius=15 --out " + dir + "/forest.glb");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto generated = nlohmann::json::parse(run_cli("info --scene gen:forest:radius=15 --json").out);
    r = run_cli("info --scene " + dir + "/forest.glb --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto loaded = nlohmann::json::parse(r.out);
    EXPECT_EQ(loaded["objects"], generated["objects"]);
}

// Files that cannot be written are errors naming the file and why, never "wrote X": a folder as
// the path, a full disk (/dev/full), a missing folder (export and path alike).
TEST(Cli, OutputsThatCannotBeWrittenAreErrors) {
    const std::string dir = test::temp_dir("cli_unwritable");
    const std::string forest = "--scene gen:forest:radius=15";
    expect_refused("export " + forest + " --out " + dir, 1, dir + ": cannot write the scene: it is a folder");
    expect_refused("export " + forest + " --out /dev/full", 1, "/dev/full: cannot write the scene");
    expect_refused("path " + forest + " --kind orbit --frames 3 --out /dev/full", 1, "/dev/full: cannot write the camera path");
    expect_refused("export " + forest + " --out " + dir + "/missing/forest.glb", 1, "the folder " + dir + "/missing does not exist");
    expect_refused("path " + forest + " --kind orbit --frames 3 --out " + dir + "/missing/path.json", 1,
                   "the folder " + dir + "/missing does not exist");
    EXPECT_FALSE(std::filesystem::exists(dir + "/missing"));
}

// accuracy --random views from free space, with the culler's scene moved by --offset and judged
// against the unmoved truth; the options are refused where they mean nothing.
TEST(Cli, AccuracyOnAMovedSceneFromRandomViews) {
    const CliRun r = run_cli("accuracy --scene gen:city:seed=2,blocks=3 --random 3 --seed 4 --resolution 160x90 --offset 1e5,0,1e5 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["views"], 3);
    EXPECT_EQ(j["offset"][0], 1e5);
    EXPECT_EQ(j["false_culls"], 0);
    EXPECT_GT(j["hidden_in_frustum"].get<int>(), 0);
    expect_refused("accuracy --random 3", 1, "--random needs --scene");
    expect_refused("accuracy --scene gen:city:seed=2,blocks=3 --random 2 --walk 2", kUsageError, "excludes");
    expect_refused("accuracy --scene gen:city:seed=2,blocks=3 --random 2 --offset 1,2", 1, "--offset");
    expect_refused("accuracy --scene gen:city:seed=2,blocks=3 --random 2 --offset 1e39,0,0", 1, "beyond the float range");
}

// A node matrix that takes finite vertices to infinity is said, not silent.
TEST(Cli, InfiniteWorldVerticesAreReported) {
    const std::string dir = test::temp_dir("cli_infinite");
    Scene scene = generate_scene("city:blocks=1,cars=0");
    scene.objects[2].world = glm::dmat4(1e39);
    scene.objects[2].world[3][3] = 1.0;
    scene.finalize();
    save_glb(scene, dir + "/huge.glb");
    const CliRun r = run_cli("info --scene " + dir + "/huge.glb");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_MENTIONS(r.err, "1 object with vertices that become infinite in world space (first: object 2");
}

// homcull bench: the issue's command and JSON keys on both workloads (a buffer small enough to
// be quick; it times, so only the keys and their sense are checked), the scalar comparison,
// and its bad options.
TEST(Cli, BenchPrintsItsTimingsAndRefusesBadOptions) {
    const std::string s1 = std::string(HOMCULL_SOURCE_DIR) + "/../shared/workloads/s1";
    const std::string castle = test::shared_scene("intel_castle.glb");
    if (!std::filesystem::exists(s1 + "/rects_ndc_xmin_ymin_xmax_ymax_wmin_f32.bin") || castle.empty())
        GTEST_SKIP() << "the shared workload S1 or the castle is missing";
    CliRun r = run_cli("bench --workload s1 --s1 " + s1 + " --resolution 64x36 --samples 2 --threads 2 --repeat 1 --vs-scalar --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    nlohmann::json j = nlohmann::json::parse(r.out);
    for (const char* key : {"ms", "min_ms", "mtris_per_s", "rect_tests_per_s", "rect_single_calls_per_s", "speedup_vs_scalar"})
        EXPECT_GT(j[key].get<double>(), 0.0) << key;
    EXPECT_EQ(j["samples"], 2);
    EXPECT_EQ(j["threads"], 2);
    EXPECT_GT(j["scalar"]["ms"].get<double>(), 0.0);
    EXPECT_GT(j["rects_occluded"].get<std::size_t>(), 0u);
    EXPECT_EQ(j["stats"]["triangles_in"], 100000);

    const std::string views = std::string(HOMCULL_SOURCE_DIR) + "/data/views/castle.json";
    r = run_cli("bench --workload castle --scene " + castle + " --views " + views + " --resolution 128x72 --clusters 124 --repeat 1 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["triangles"], 48700);
    EXPECT_GT(j["clusters"].get<int>(), 0);
    EXPECT_GT(j["views"].size(), 1u);
    EXPECT_EQ(j["ms"], j["views"][0]["ms"]);  // view C0's at the top
    EXPECT_EQ(j["min_ms"], j["views"][0]["min_ms"]);

    const std::string small = " --s1 " + s1 + " --resolution 64x36 --repeat 1";
    expect_refused("bench --workload nonsense" + small, 1, "unknown workload 'nonsense'");
    expect_refused("bench --isa bogus" + small, 1, "unknown instruction set 'bogus'");
    expect_refused("bench --threads 0" + small, 1, "--threads must be in [1, 256]");
    expect_refused("bench --threads 300" + small, 1, "--threads must be in [1, 256]");
    expect_refused("bench --samples 3" + small, 1, "samples per pixel axis must be 1, 2 or 4");
    expect_refused("bench --clusters 124" + small, 1, "--clusters is for --workload castle");
    expect_refused("bench --workload castle --clusters 7" + small, 1, "bench: --clusters 7: max_triangles must be a multiple of 4");
    expect_refused("bench --s1 " + s1 + " --repeat -1", 1, "--repeat must be at least 1");
    expect_refused("bench --s1 " + s1 + " --resolution 0x0", 1, "--resolution: expected WxH");
}

// homcull bench --workload frame: whole frames of the scene culler per view, with their stages
// and their accuracy against Embree, from random viewpoints and along a walk of a generated
// city (small and quick: only the keys, their sense and the zero false culls are checked).
TEST(Cli, FrameBenchReportsTimesStagesAndAccuracyPerView) {
    for (const std::string views : {"--random 3", "--walk 3"}) {
        const CliRun r = run_cli("bench --workload frame --scene gen:city:seed=2,blocks=3 " + views +
                                 " --resolution 160x90 --repeat 2 --occludees box --clusters 64 --occluders all --min-occluder-size 0.001 --json");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const nlohmann::json j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["workload"], "frame");
        EXPECT_EQ(j["display"][0], 160);
        EXPECT_EQ(j["config"]["occludees"], "box");
        EXPECT_EQ(j["config"]["occluders"], "all");
        EXPECT_EQ(j["config"]["clusters"], "on");
        EXPECT_EQ(j["config"]["min_occluder_size"], 0.001);
        // cull's defaults beside the configuration, for readers that name what differs (frontier_plot.py).
        EXPECT_EQ(j["defaults"]["occluders"], "role");
        EXPECT_EQ(j["defaults"]["min_occluder_size"], 0.0);
        // What loading costs, once: the scene file (generated here), then the culler's preparation.
        EXPECT_GE(j["load_ms"].get<double>(), 0.0);
        EXPECT_GT(j["setup_ms"].get<double>(), 0.0);
        ASSERT_EQ(j["per_view"].size(), 3u) << views;
        for (const nlohmann::json& v : j["per_view"]) {
            EXPECT_GT(v["frame_ms"].get<double>(), 0.0);
            EXPECT_LE(v["frame_min_ms"].get<double>(), v["frame_ms"].get<double>());
            for (const char* stage : {"select", "render", "maps", "tests"}) EXPECT_GE(v["stages_ms"][stage].get<double>(), 0.0) << stage;
            EXPECT_EQ(v["false_culls"], 0) << views;
            EXPECT_GE(v["efficiency"].get<double>(), 0.0);
            EXPECT_LE(v["efficiency"].get<double>(), 1.0);
            EXPECT_LE(v["culled_outright"].get<std::size_t>(), v["hidden_outright"].get<std::size_t>());
            // The occluders' bound: a conservative culler culls no object its occluders cannot hide,
            // so every object hidden outright is culled, or missed with the bound saying why.
            const nlohmann::json& bound = v["occluder_bound"];
            EXPECT_EQ(bound["hidden_outright"], v["hidden_outright"]);
            EXPECT_LE(v["culled_outright"].get<std::size_t>(), bound["hideable"].get<std::size_t>()) << views;
            EXPECT_EQ(bound["missed_hideable"].get<std::size_t>() + bound["missed_not_hideable"].get<std::size_t>(),
                      v["hidden_outright"].get<std::size_t>() - v["culled_outright"].get<std::size_t>())
                << views;
            EXPECT_GT(bound["occluders_drawn"].get<std::size_t>(), 0u);
        }
        EXPECT_TRUE(j["summary"].contains("occluder_bound"));
        EXPECT_EQ(j["summary"]["views"], 3);
        EXPECT_EQ(j["summary"]["false_culls"], 0);
        EXPECT_GE(j["summary"]["frame_ms"]["max"].get<double>(), j["summary"]["frame_ms"]["mean"].get<double>());
    }
    expect_refused("bench --workload frame --scene gen:city --random 2 --walk 2", 1, "give exactly one of --views P, --walk N and --random N");
    expect_refused("bench --workload frame --scene gen:city --random 2 --vs-scalar", 1, "--vs-scalar and --sample-depth are for s1 and castle");
    expect_refused("bench --workload s1 --walk 3", 1, "--walk is for --workload frame");
    expect_refused("bench --workload castle --back-faces cull", 1, "--back-faces is for --workload frame");
    expect_refused("bench --workload frame --scene gen:city --random 2 --repeat -1", 1, "--repeat must be at least 1");
    expect_refused("bench --workload frame --scene /nonexistent.glb --random 2", 1, "/nonexistent.glb");
}

// bench --workload frame --scaling: one thread, two threads and two single-threaded copies at once
// (the machine's ceiling), with the ratios' spreads and each kind's stages; and --complexity
// reaching the culler's configuration. Only the keys and their sense are checked: the figures
// are the machine's.
TEST(Cli, FrameBenchScalingReportsTheThreadsBesideTheMachinesCeiling) {
    expect_refused("bench --workload frame --scene gen:city --random 2 --scaling", 1, "give --threads N with N >= 2, got 1");
    expect_refused("bench --workload s1 --complexity 2", 1, "--complexity is for --workload frame");
    expect_refused("bench --workload castle --occluders all", 1, "--occluders is for --workload frame");
    expect_refused("bench --workload castle --min-occluder-size 0.1", 1, "--min-occluder-size is for --workload frame");
    expect_refused("bench --workload frame --scene gen:city --random 2 --min-occluder-size -1", 105, "--min-occluder-size");
    expect_refused("bench --workload frame --scene gen:city --random 2 --occluders some", 105, "--occluders");
    expect_refused("bench --workload frame --scene gen:city --random 2 --complexity -1", 105, "--complexity");
    // NaN is no number at least 0 (CLI11's own check let it through), in bench, cull and bake alike.
    expect_refused("bench --workload frame --scene gen:city --random 2 --complexity nan", 105,
                   "--complexity: must be a number at least 0 (inf allowed), got nan");
    expect_refused("cull --scene gen:city --eye 0,2,0 --target 1,2,0 --min-occluder-size nan", 105, "got nan");
    expect_refused("cull --scene gen:city --eye 0,2,0 --target 1,2,0 --min-occluder-size -inf", 105, "got -inf");
    expect_refused("bake --scene gen:city --spacing nan --out x.json", 105, "--spacing");
    if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one hardware thread: no ceiling to measure";
    const CliRun r = run_cli("bench --workload frame --scene gen:city:seed=2,blocks=3 --random 2 --resolution 160x90 --repeat 2 "
                             "--occludees box --threads 2 --scaling --complexity 0 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["config"]["complexity"], 0.0);
    const nlohmann::json& s = j["scaling"];
    EXPECT_EQ(s["threads"], 2);
    EXPECT_EQ(s["rounds"], 2);
    EXPECT_GT(s["speedup"].get<double>(), 0.0);
    EXPECT_GT(s["ceiling"].get<double>(), 0.0);
    for (const nlohmann::json* spread : {&s["per_round"]["speedup"], &s["per_round"]["ceiling"], &s["cross_core_round_trip_ns"]}) {
        EXPECT_GT((*spread)["min"].get<double>(), 0.0);
        EXPECT_LE((*spread)["min"].get<double>(), (*spread)["median"].get<double>());
        EXPECT_LE((*spread)["median"].get<double>(), (*spread)["max"].get<double>());
    }
    for (const char* kind : {"one_thread", "threads", "copies_at_once"}) EXPECT_GT(s["frame_ms_mean"][kind].get<double>(), 0.0) << kind;
    for (const char* series : {"speedup", "ceiling", "cross_core_round_trip_ns"}) EXPECT_EQ(s["rounds_in_order"][series].size(), 2u) << series;
    for (const char* kind : {"one_thread", "threads"})
        for (const char* stage : {"select", "render", "maps", "tests"}) EXPECT_GE(s["stages_ms_mean"][kind][stage].get<double>(), 0.0);
}

TEST(Cli, BadInputExitsWithOneAndSaysWhatIsWrong) {
    CliRun r = run_cli("info --scene /nonexistent/scene.glb");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "/nonexistent/scene.glb: no such file");
    r = run_cli("truth --scene gen:city --resolution 64x36");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "no camera");
    r = run_cli("truth " + kCityCamera + " --resolution 0x10");
    EXPECT_NE(r.exit_code, 0);
    r = run_cli("truth --scene gen:city --eye 0,1,0 --target 0,1,0 --resolution 64x36");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "same point");
    r = run_cli("truth --scene gen:city --eye 0,1 --target 0,1,0");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "--eye: expected three numbers");
    r = run_cli("truth --scene gen:city --eye 0,1,0 --target 5,1,0 --resolution wide");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "expected WxH");
    r = run_cli("truth --scene gen:village --eye 0,1,0 --target 5,1,0");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MENTIONS(r.err, "unknown generated scene 'village'");
    r = run_cli("frobnicate");
    EXPECT_NE(r.exit_code, 0);
}

}  // namespace
}  // namespace homcull
