// homcull walk: cull a scene along a camera path, frame after frame with one culler (so the
// temporal strategy has its history), and report Zhang's culling graph per frame against
// Embree ground truth, with the time of every stage.
#include "commands.hpp"
#include "cull_options.hpp"
#include "cull_report.hpp"
#include "frame_dump.hpp"
#include "options.hpp"
#include "walk_report.hpp"

#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/walkthrough.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

namespace homcull::cli {
namespace {

struct WalkCommandOptions {
    SceneChoice scene;
    std::string path;
    CullOptions cull;
    std::string isa = "best", truth = "on", dump;
    int threads = 1;
    bool json = false, quiet = false;
};

// A frame's figures by name, in print order: what the summary averages and maximizes.
std::vector<std::pair<const char*, double>> frame_figures(const WalkFrame& f) {
    std::vector<std::pair<const char*, double>> v = {
        {"objects_total", double(f.objects.total)},
        {"objects_after_frustum", double(f.objects.after_frustum)},
        {"objects_after_occlusion", double(f.objects.after_occlusion)},
        {"triangles_total", double(f.triangles.total)},
        {"triangles_after_frustum", double(f.triangles.after_frustum)},
        {"triangles_after_occlusion", double(f.triangles.after_occlusion)},
        {"occluder_objects", double(f.work.occluder_objects)},
        {"occluder_triangles", double(f.work.occluder_triangles)},
        {"select_ms", f.ms.select_ms},
        {"render_ms", f.ms.render_ms},
        {"maps_ms", f.ms.maps_ms},
        {"tests_ms", f.ms.test_ms},
        {"cull_ms", f.ms.select_ms + f.ms.render_ms + f.ms.maps_ms + f.ms.test_ms},
        {"frame_ms", f.frame_ms}};
    if (f.has_truth) {
        v.insert(v.end(), {{"objects_exactly_visible", double(f.objects.exactly_visible)},
                           {"triangles_exactly_visible", double(f.triangles.exactly_visible)},
                           {"false_culls", double(f.truth.false_culls)},
                           {"hidden_in_frustum", double(f.truth.hidden_in_frustum)},
                           {"missed_culls", double(f.truth.missed_culls())},
                           {"truth_ms", f.truth_ms}});
    }
    return v;
}

void print_progress(std::size_t done, std::size_t total) {
    constexpr int kWidth = 30;
    const int filled = int(kWidth * done / std::max<std::size_t>(total, 1));
    fmt::print(stderr, "\r[{}{}] frame {}/{}", std::string(std::size_t(filled), '#'), std::string(std::size_t(kWidth - filled), '.'),
               done, total);
    if (done == total) fmt::print(stderr, "\n");
    std::fflush(stderr);
}

void run_walk(const WalkCommandOptions& o) {
    select_isa(o.isa);
    SceneCullerConfig config = scene_culler_config(o.cull, o.threads);
    if (!o.dump.empty()) prepare_dump_folder(o.dump);
    const Scene scene = load_chosen_scene(o.scene);
    const CullResources resources = prepare_cull_resources(o.cull, scene, config);
    const CameraPath path = read_camera_path(o.path);
    if (path.frames.empty()) throw Error("camera path " + o.path + " has no frames");
    const ParallelFor parallel = command_job_system(o.threads);
    SceneCuller culler(scene, resources.occluders, config, parallel);
    const bool temporal = config.strategy == CullStrategy::temporal;  // its frames without history are counted
    std::unique_ptr<RayScene> rays;
    if (o.truth == "on") rays = std::make_unique<RayScene>(scene);
    TruthOptions truth_options;
    truth_options.resolution = config.display;

    nlohmann::json frames = nlohmann::json::array();
    std::vector<WalkFrame> measured;
    std::vector<OccludeeAnswer> answers;
    for (std::size_t k = 0; k < path.frames.size(); ++k) {
        const Camera& camera = path.frames[k];
        TruthResult truth;
        if (rays) truth = compute_ground_truth(*rays, scene, camera, truth_options);
        const WalkFrame f = measure_walk_frame(scene, culler, camera, rays ? &truth : nullptr, answers, parallel);
        measured.push_back(f);
        if (k == 0 && !o.dump.empty()) {
            // The first frame's buffer, maps and overlay, for the report.
            std::unique_ptr<RayScene> own;
            if (!rays) own = std::make_unique<RayScene>(scene);
            write_frame_dump(culler, rays ? *rays : *own, camera, answers, o.dump + "/frame0", /*print_to_stderr=*/true);
        }
        if (o.json) {
            nlohmann::json objects = nlohmann::json::array();
            for (std::size_t id = 0; id < scene.objects.size(); ++id)
                objects.push_back(object_result_json(scene, id, answers[id], rays ? &truth : nullptr));
            nlohmann::json frame = {{"frame", k}, {"camera", camera_json(camera)}, {"objects", std::move(objects)}};
            for (const auto& [name, value] : frame_figures(f)) frame[name] = value;
            frame["timings_ms"] = timings_json(f.ms);
            frame["work"] = work_json(f.work);
            frames.push_back(std::move(frame));
        } else {
            fmt::print("frame {:4}: objects {} / {} in frustum / {} kept{}; occluders {} tris; {:.3f} ms (render {:.3f}, maps {:.3f}, "
                       "tests {:.3f}){}{}\n",
                       k, f.objects.total, f.objects.after_frustum, f.objects.after_occlusion,
                       f.has_truth ? fmt::format(" / {} visible", f.objects.exactly_visible) : "", f.work.occluder_triangles,
                       f.ms.select_ms + f.ms.render_ms + f.ms.maps_ms + f.ms.test_ms, f.ms.render_ms, f.ms.maps_ms, f.ms.test_ms,
                       f.has_truth ? fmt::format("; false culls {}, missed {} of {} hidden", f.truth.false_culls, f.truth.missed_culls(),
                                                 f.truth.hidden_in_frustum)
                                   : "",
                       temporal && !f.work.used_history ? "; no history (first frame or camera cut)" : "");
        }
        if (!o.quiet) print_progress(k + 1, path.frames.size());
    }

    // Summary: mean and max of every figure, and the path's totals.
    nlohmann::json summary = {{"frames", measured.size()}};
    auto names = frame_figures(measured.front());
    std::vector<double> sum(names.size(), 0.0), most(names.size(), 0.0);
    for (const WalkFrame& f : measured) {
        const auto figures = frame_figures(f);  // once per frame
        for (std::size_t i = 0; i < figures.size(); ++i) {
            sum[i] += figures[i].second;
            most[i] = std::max(most[i], figures[i].second);
        }
    }
    for (std::size_t i = 0; i < names.size(); ++i)
        summary[names[i].first] = {{"mean", sum[i] / double(measured.size())}, {"max", most[i]}};
    std::size_t without_history = 0;  // temporal: the first frame and the camera cuts
    for (const WalkFrame& f : measured) without_history += temporal && !f.work.used_history;
    if (temporal) summary["frames_without_history"] = without_history;
    CullingTally tally;
    for (const WalkFrame& f : measured) tally += f.truth;
    const double efficiency = tally.efficiency();
    if (rays) {
        summary["total_false_culls"] = tally.false_culls;
        summary["total_robust_false_culls"] = tally.robust_false_culls;
        summary["efficiency"] = efficiency;
        summary["hidden_through_ties"] = tally.hidden_through_ties;
        summary["missed_through_ties"] = tally.hidden_through_ties - tally.culled_through_ties;
        summary["robust_efficiency"] = tally.robust_efficiency();
    }
    if (!o.dump.empty()) {
        const std::vector<std::pair<std::string, std::string>> settings = {
            {"scene", scene.source},
            {"path", o.path + " (" + std::to_string(measured.size()) + " frames)"},
            {"strategy", o.cull.strategy},
            {"occluders", o.cull.occluders + ", rank " + o.cull.rank + ", budget " + std::to_string(o.cull.budget) +
                              (o.cull.min_occluder_size > 0.0 ? fmt::format(", at least {:g} sr", o.cull.min_occluder_size) : "") +
                              ", LOD " + o.cull.lod},
            {"display", std::to_string(config.display.width) + "x" + std::to_string(config.display.height) + ", " + o.cull.mode +
                            ", depth " + o.cull.depth},
            {"efficiency", rays ? fmt::format("{:.1f} % of the hidden objects culled, {} false culls", 100.0 * efficiency, tally.false_culls)
                                : "no ground truth (--truth off)"}};
        for (const std::string& file : write_walk_report(o.dump, "homcull walk: " + scene.source, settings, measured, summary, "frame0"))
            fmt::print(stderr, "wrote      {}\n", file);
    }
    if (o.json) {
        const nlohmann::json out = {{"scene", scene.source},
                                    {"path", o.path},
                                    {"strategy", o.cull.strategy},
                                    {"rank", o.cull.rank},
                                    {"grid", o.cull.grid},
                                    {"lod", o.cull.lod},
                                    {"budget", o.cull.budget},
                                    {"hierarchy", o.cull.hierarchy},
                                    {"display", {config.display.width, config.display.height}},
                                    {"buffer", {culler.buffer().config().width, culler.buffer().config().height}},
                                    {"samples", culler.buffer().config().samples},
                                    {"mode", o.cull.mode},
                                    {"depth", o.cull.depth},
                                    {"isa", selected_isa()},
                                    {"occluder_candidates", {{"objects", culler.occluder_objects()}, {"triangles", culler.occluder_triangles()}}},
                                    {"config", cull_config_json(o.cull)},
                                    {"frames", std::move(frames)},
                                    {"summary", std::move(summary)}};
        fmt::print("{}\n", out.dump(1));
        return;
    }
    fmt::print("\n{}: {} frames, strategy {}, {} occluder candidates ({} triangles)\n", scene.source, measured.size(), o.cull.strategy,
               culler.occluder_objects(), culler.occluder_triangles());
    fmt::print("{:<28}{:>14}{:>14}\n", "figure", "mean", "max");
    for (const auto& [name, value] : names) {
        (void)value;
        fmt::print("{:<28}{:>14.3f}{:>14.3f}\n", name, summary[name]["mean"].get<double>(), summary[name]["max"].get<double>());
    }
    if (temporal)
        fmt::print("frames without history (the first, camera cuts): {} of {}\n", without_history, measured.size());
    if (rays) {
        fmt::print("false culls {} ({} seen by robust samples); culled {} of {} hidden objects ({:.1f} %)\n", tally.false_culls,
                   tally.robust_false_culls, tally.culled_hidden, tally.hidden_in_frustum, 100.0 * efficiency);
        fmt::print("hidden only through ties: {} (missed {}); hidden outright: culled {:.1f} %\n", tally.hidden_through_ties,
                   tally.hidden_through_ties - tally.culled_through_ties, 100.0 * tally.robust_efficiency());
    }
}

}  // namespace

void register_walk(CLI::App& app) {
    auto o = std::make_shared<WalkCommandOptions>();
    CLI::App* cmd = app.add_subcommand("walk", "Cull a scene along a camera path and report the culling graph per frame against Embree "
                                               "ground truth");
    add_scene_option(*cmd, o->scene);
    cmd->add_option("--path", o->path, "Camera path file (JSON, see `homcull path`)")->required();
    add_cull_options(*cmd, o->cull);
    cmd->add_option("--truth", o->truth, "on: cast Embree ground truth per frame (exactly visible, false and missed culls); off: only "
                                         "the culler")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    cmd->add_option("--threads", o->threads, "Prepare the culler and cull with this many threads (TBB); 1 = the calling thread")
        ->capture_default_str()->check(CLI::Range(1, 256));
    cmd->add_option("--isa", o->isa, "Instruction set: best, scalar (the reference path), or one of available_isas()")
        ->capture_default_str();
    cmd->add_flag("--quiet", o->quiet, "No progress bar on stderr");
    cmd->add_option("--dump", o->dump, "Write a report into this folder: report.html with the culling graph and time plots "
                                       "(PNG), the summary, and the first frame's dump (frame0/: maps.exr, PNGs, overlay.png)");
    cmd->add_flag("--json", o->json, "Print JSON on stdout: {\"frames\":[{\"objects\":[...], figures...}], \"summary\":{...}}");
    cmd->callback([o] { run_walk(*o); });
}

}  // namespace homcull::cli
