// homcull cull: per-object answers of the hierarchical occlusion maps from one camera.
#include "commands.hpp"
#include "cull_options.hpp"
#include "cull_report.hpp"
#include "frame_dump.hpp"
#include "options.hpp"

#include <homcull/io/scene_io.hpp>
#include <homcull/truth/culling_accuracy.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/occluder_bound.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>

namespace homcull::cli {
namespace {

struct CullCommandOptions {
    SceneChoice scene;
    CameraOptions camera;
    CullOptions cull;
    std::string isa = "best", dump;
    bool json = false, truth = false;
    int threads = 1, repeat = 1;
};

void run_cull(const CullCommandOptions& o) {
    select_isa(o.isa);
    const Camera camera = resolve_camera(o.camera);
    SceneCullerConfig config = scene_culler_config(o.cull, o.threads);
    if (!o.dump.empty()) prepare_dump_folder(o.dump);
    long long start = now_ns();
    const Scene scene = load_chosen_scene(o.scene);
    const double load_ms = elapsed_ms(start);
    const ParallelFor parallel = command_job_system(o.threads);
    start = now_ns();
    const CullResources resources = prepare_cull_resources(o.cull, scene, config);
    const std::vector<std::uint32_t>& occluders = resources.occluders;
    SceneCuller culler(scene, occluders, config, parallel);
    const double setup_ms = elapsed_ms(start);
    std::vector<OccludeeAnswer> answers;
    // Each repeat forgets the one before it: the temporal strategy would otherwise draw exactly the
    // occluders it found visible in the same view, a frame no walk or cut has.
    SceneCullTimings best;
    for (int r = 0; r < o.repeat; ++r) {
        culler.reset_history();
        culler.cull(camera, answers, parallel);
        const SceneCullTimings& t = culler.timings();
        best = r == 0 ? t : SceneCullTimings{std::min(best.select_ms, t.select_ms), std::min(best.render_ms, t.render_ms),
                                             std::min(best.maps_ms, t.maps_ms), std::min(best.test_ms, t.test_ms)};
    }

    // Optional ground truth at the display's pixel centres.
    TruthResult truth;
    double truth_ms = 0.0;
    start = now_ns();
    std::unique_ptr<RayScene> rays;
    if (o.truth || !o.dump.empty()) rays = std::make_unique<RayScene>(scene);
    if (o.truth) {
        TruthOptions truth_options;
        truth_options.resolution = config.display;
        truth = compute_ground_truth(*rays, scene, camera, truth_options);
        truth_ms = elapsed_ms(start);
    }
    if (!o.dump.empty()) write_frame_dump(culler, *rays, camera, answers, o.dump, /*print_to_stderr=*/o.json);

    CullingTally tally;
    if (o.truth) tally_answers(scene, truth, answers, camera, tally);
    // The occluders' bound: which of the objects hidden outright the occluders this frame drew
    // could hide at all (truth/occluder_bound.hpp), and so which misses selection would mend.
    OccluderBoundTally bound;
    double bound_ms = 0.0;
    if (o.truth) {
        const OccluderBound b = occluder_bound(*rays, scene, camera, config.display, culler.drawn_occluders());
        bound = tally_bound(truth, b, answers);
        bound_ms = b.trace_ms;
    }
    std::size_t counts[3] = {};
    std::uint64_t triangles = 0, after_frustum = 0, after_occlusion = 0;
    nlohmann::json objects = nlohmann::json::array();
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const OccludeeAnswer& a = answers[id];
        const std::uint64_t n = scene.triangle_count(scene.objects[id]);
        ++counts[int(a.visibility)];
        triangles += n;
        after_frustum += a.visibility != Visibility::view_culled ? n : 0;
        after_occlusion += a.visibility == Visibility::visible ? n : 0;
        objects.push_back(object_result_json(scene, id, a, o.truth ? &truth : nullptr));
    }
    const SceneCullTimings& ms = best;
    if (o.json) {
        nlohmann::json exits;
        for (int e = 0; e < 7; ++e) exits[overlap_exit_name(OverlapExit(e))] = culler.overlap_exits().count[e];  // not_run: --pyramid lazy
        nlohmann::json out = {
            {"scene", scene.source},
            {"camera", camera_json(camera)},
            {"display", {config.display.width, config.display.height}},
            {"buffer", {culler.buffer().config().width, culler.buffer().config().height}},
            {"samples", culler.buffer().config().samples},
            {"isa", selected_isa()},
            {"mode", o.cull.mode},
            {"hole", config.maps.hole_pixels},
            {"depth", o.cull.depth},
            {"occluders", {{"choice", o.cull.occluders}, {"objects", culler.occluder_objects()},
                           {"triangles", culler.occluder_triangles()}}},
            {"objects", objects},
            {"summary", {{"objects", scene.objects.size()}, {"visible", counts[0]}, {"occluded", counts[1]}, {"view_culled", counts[2]},
                         {"triangles", triangles}, {"triangles_after_frustum", after_frustum},
                         {"triangles_after_occlusion", after_occlusion}}},
            {"timings_ms", {{"load", load_ms}, {"setup", setup_ms}, {"select", ms.select_ms}, {"render", ms.render_ms},
                            {"maps", ms.maps_ms}, {"tests", ms.test_ms}}},
            {"work", work_json(culler.work())},
            {"strategy", o.cull.strategy},
            {"config", cull_config_json(o.cull)},
            {"stats", stats_json(culler.buffer().stats())},
            {"overlap_exits", exits}};
        if (o.truth) {
            out["truth"] = {{"false_culls", tally.false_culls},   {"robust_false_culls", tally.robust_false_culls},
                            {"hidden_in_frustum", tally.hidden_in_frustum}, {"culled_hidden", tally.culled_hidden},
                            {"missed_culls", tally.missed_culls()}, {"efficiency", tally.efficiency()},
                            {"hidden_through_ties", tally.hidden_through_ties}, {"culled_through_ties", tally.culled_through_ties},
                            {"robust_efficiency", tally.robust_efficiency()},
                            {"false_cull_reports", tally.false_cull_reports}, {"trace_ms", truth_ms},
                            {"occluder_bound", occluder_bound_json(bound)}};
            out["truth"]["occluder_bound"]["occluders_drawn"] = culler.drawn_occluders().size();
            out["truth"]["occluder_bound"]["trace_ms"] = bound_ms;
        }
        fmt::print("{}\n", out.dump(1));
        return;
    }
    fmt::print("scene      {} ({} objects)\n", scene.source, scene.objects.size());
    fmt::print("display    {}x{}, buffer {}x{} with {}x{} samples, {} mode{}, depth {}\n", config.display.width,
               config.display.height, culler.buffer().config().width, culler.buffer().config().height, culler.buffer().config().samples,
               culler.buffer().config().samples, o.cull.mode, o.cull.mode == "approximate" ? fmt::format(" (hole {} px)", o.cull.hole) : "",
               o.cull.depth);
    fmt::print("occluders  {} objects, {} triangles ({})\n", culler.occluder_objects(), culler.occluder_triangles(), o.cull.occluders);
    fmt::print("answers    {} visible, {} occluded, {} view-culled\n", counts[0], counts[1], counts[2]);
    fmt::print("triangles  {} in all, {} after frustum culling, {} after occlusion culling\n", triangles, after_frustum,
               after_occlusion);
    fmt::print("time       load {:.1f} ms, setup {:.1f} ms; render {:.3f} ms, maps {:.3f} ms, tests {:.3f} ms\n", load_ms, setup_ms,
               ms.render_ms, ms.maps_ms, ms.test_ms);
    if (o.truth) {
        fmt::print("truth      {} false culls; culled {} of {} hidden objects ({:.1f} %; {} of them hidden only through ties); "
                   "trace {:.0f} ms\n",
                   tally.false_culls, tally.culled_hidden, tally.hidden_in_frustum, 100.0 * tally.efficiency(), tally.hidden_through_ties,
                   truth_ms);
        fmt::print("bound      the {} occluders drawn could hide {} of the {} objects hidden outright ({:.1f} %); of the misses, {} "
                   "they could hide, {} they could not; trace {:.0f} ms\n",
                   culler.drawn_occluders().size(), bound.hideable, bound.hidden, 100.0 * bound.efficiency_bound(), bound.missed_hideable,
                   bound.missed_not_hideable, bound_ms);
        for (const std::string& line : tally.false_cull_reports) fmt::print("false cull: {}\n", line);
    }
    fmt::print("(--json lists every object)\n");
}

}  // namespace

void register_cull(CLI::App& app) {
    auto o = std::make_shared<CullCommandOptions>();
    CLI::App* cmd = app.add_subcommand("cull", "Occlusion culling of a scene's objects from one camera (hierarchical occlusion maps)");
    add_scene_option(*cmd, o->scene);
    add_camera_options(*cmd, o->camera);
    add_cull_options(*cmd, o->cull);
    cmd->add_option("--threads", o->threads, "Prepare the culler and cull with this many threads (TBB); 1 = the calling thread")
        ->capture_default_str()->check(CLI::Range(1, 256));
    cmd->add_option("--isa", o->isa, "Instruction set: best, scalar (the reference path), or one of available_isas()")
        ->capture_default_str();
    cmd->add_option("--repeat", o->repeat, "Cull this many times and report each stage's fastest time")
        ->capture_default_str()->check(CLI::Range(1, 1000));
    cmd->add_flag("--truth", o->truth, "Also cast Embree ground truth at the display's pixel centres and count false culls");
    cmd->add_flag("--json", o->json, "Print JSON on stdout");
    cmd->add_option("--dump", o->dump, "Also write the frame's debug dump into this folder (as homcull dump: maps.exr, PNGs, overlay.png)");
    cmd->callback([o] { run_cull(*o); });
}

}  // namespace homcull::cli
