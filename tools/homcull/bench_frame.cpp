// homcull bench --workload frame (bench_frame.hpp).
#include "bench_frame.hpp"

#include "bench_scaling.hpp"

#include "cull_report.hpp"
#include "options.hpp"
#include "stage_times.hpp"

#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/truth/culling_accuracy.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/occluder_bound.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/truth/walk_path.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <vector>

namespace homcull::cli {
namespace {

// What one view measured: every round's times, and the answers scored against Embree.
struct ViewFigures {
    std::vector<double> frame;
    CullingTally tally;
    std::size_t counts[3] = {};  // visible, occluded, view-culled
};

CameraPath frame_bench_views(const FrameBenchOptions& o, const RayScene& rays, const Scene& scene) {
    if (!o.views.empty()) return read_camera_path(o.views);
    if (o.walk > 0) {
        WalkOptions w;
        w.frames = o.walk;
        w.seed = o.seed;
        return walk_path(rays, scene, w);
    }
    return random_views(rays, scene, o.random, o.seed);
}

nlohmann::json accuracy_json(const CullingTally& t) {
    const std::size_t hidden_outright = t.hidden_in_frustum - t.hidden_through_ties;
    return {{"efficiency", t.robust_efficiency()},
            {"efficiency_plain", t.efficiency()},
            {"false_culls", t.false_culls},
            {"robust_false_culls", t.robust_false_culls},
            {"hidden_outright", hidden_outright},
            {"culled_outright", t.culled_hidden - t.culled_through_ties},
            {"hidden_in_frustum", t.hidden_in_frustum},
            {"culled_hidden", t.culled_hidden}};
}

}  // namespace

void run_frame_bench(const FrameBenchOptions& o) {
    if (o.rounds < 1 || o.rounds > 10000) throw Error("bench --workload frame: --repeat must be in [1, 10000], got " + std::to_string(o.rounds));
    if (o.threads < 1 || o.threads > 256) throw Error("bench: --threads must be in [1, 256], got " + std::to_string(o.threads));
    if (int(!o.views.empty()) + int(o.walk > 0) + int(o.random > 0) != 1)
        throw Error("bench --workload frame: give exactly one of --views P, --walk N and --random N");
    if (o.scaling) check_scaling_threads(o.threads);
    select_isa(o.isa);
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(o.threads));
    const ParallelFor parallel = command_job_system(o.threads);
    SceneCullerConfig config = scene_culler_config(o.cull, o.threads);
    long long start = now_ns();
    const Scene scene = load_chosen_scene(SceneChoice{o.scene, 0});
    const double load_ms = elapsed_ms(start);
    const RayScene rays(scene);
    const CameraPath path = frame_bench_views(o, rays, scene);
    if (path.frames.empty()) throw Error("bench --workload frame: the camera path has no views");
    // What an engine pays once, when the scene loads: the occluders chosen, then the culler's
    // own preparation (clusters, shared edges, occludee parts, closed meshes, the hierarchy).
    start = now_ns();
    const CullResources resources = prepare_cull_resources(o.cull, scene, config);
    SceneCuller culler(scene, resources.occluders, config, parallel);
    const double setup_ms = elapsed_ms(start);

    // One untimed cull per view (the scratch grows to the largest frame), then the timed rounds,
    // the views interleaved so that the machine's load spreads over all of them alike. A walk's
    // frames follow one another and the temporal strategy keeps its history along them (from
    // the walk's start at every round); other views are unrelated, each culled without history,
    // so that a view's figures do not depend on the view before it.
    const std::size_t views = path.frames.size();
    const bool consecutive = o.walk > 0;
    const auto forget_before = [&](std::size_t v) {
        if (!consecutive || v == 0) culler.reset_history();
    };
    const auto cull_view = [&](std::size_t v, std::vector<OccludeeAnswer>& answers) {
        forget_before(v);
        culler.cull(path.frames[v], answers, parallel);
    };
    std::vector<ViewFigures> figures(views);
    std::vector<StageTimes> stages(views);
    std::vector<OccludeeAnswer> answers;
    for (std::size_t v = 0; v < views; ++v) cull_view(v, answers);
    for (int r = 0; r < o.rounds; ++r)
        for (std::size_t v = 0; v < views; ++v) {
            forget_before(v);
            start = now_ns();
            culler.cull(path.frames[v], answers, parallel);
            const double frame_ms = elapsed_ms(start);
            const SceneCullTimings& t = culler.timings();
            ViewFigures& f = figures[v];
            f.frame.push_back(frame_ms);
            stages[v].add(t);
        }

    // The answers of each view, against Embree at the display's pixel centres (not timed).
    TruthOptions truth_options;
    truth_options.resolution = config.display;
    CullingTally total;
    OccluderBoundTally total_bound;
    nlohmann::json per_view = nlohmann::json::array();
    std::vector<double> frame_medians;
    for (std::size_t v = 0; v < views; ++v) {
        const Camera& camera = path.frames[v];
        cull_view(v, answers);
        const TruthResult truth = compute_ground_truth(rays, scene, camera, truth_options);
        ViewFigures& f = figures[v];
        tally_answers(scene, truth, answers, camera, f.tally);
        // What the occluders this frame drew could hide at all (truth/occluder_bound.hpp).
        const OccluderBoundTally bound =
            tally_bound(truth, occluder_bound(rays, scene, camera, config.display, culler.drawn_occluders()), answers);
        total_bound += bound;
        for (const OccludeeAnswer& a : answers) ++f.counts[int(a.visibility)];
        total += f.tally;
        frame_medians.push_back(median(f.frame));
        nlohmann::json view = {{"view", v},
                               {"camera", camera_json(camera)},
                               {"frame_ms", frame_medians.back()},
                               {"frame_min_ms", *std::min_element(f.frame.begin(), f.frame.end())},
                               {"stages_ms", stages[v].medians()},
                               {"answers", {{"visible", f.counts[0]}, {"occluded", f.counts[1]}, {"view_culled", f.counts[2]}}}};
        view.update(accuracy_json(f.tally));
        view["occluder_bound"] = occluder_bound_json(bound);
        view["occluder_bound"]["occluders_drawn"] = culler.drawn_occluders().size();
        per_view.push_back(std::move(view));
    }
    double mean_frame = 0.0;
    for (const double ms : frame_medians) mean_frame += ms / double(views);
    const double worst_frame = *std::max_element(frame_medians.begin(), frame_medians.end());
    const nlohmann::json scaling =
        o.scaling ? measure_thread_scaling(scene, resources.occluders, config, path, o.rounds, o.threads, parallel) : nlohmann::json();
    nlohmann::json summary = {{"views", views},
                              {"frame_ms", {{"mean", mean_frame}, {"max", worst_frame}, {"median", median(frame_medians)}}},
                              {"stages_ms_mean", stage_means(stages)}};
    summary.update(accuracy_json(total));
    summary["occluder_bound"] = occluder_bound_json(total_bound);
    const std::string source = !o.views.empty() ? o.views : o.walk > 0 ? "walk:" + std::to_string(o.walk) + ",seed=" + std::to_string(o.seed)
                                                                        : "random:" + std::to_string(o.random) + ",seed=" + std::to_string(o.seed);
    if (o.json) {
        nlohmann::json out = {
            {"workload", "frame"},
            {"scene", scene.source},
            {"views_from", source},
            {"display", {config.display.width, config.display.height}},
            {"buffer", {culler.buffer().config().width, culler.buffer().config().height}},
            {"samples", culler.buffer().config().samples},
            {"isa", culler.buffer().config().isa},
            {"threads", o.threads},
            {"rounds", o.rounds},
            {"load_ms", load_ms},
            {"setup_ms", setup_ms},
            {"config", cull_config_json(o.cull)},
            {"defaults", cull_config_json(CullOptions{})},  // cull's: what a reader of "config" compares against
            {"per_view", per_view},
            {"summary", summary}};
        if (o.scaling) out["scaling"] = scaling;
        fmt::print("{}\n", out.dump(1));
        return;
    }
    fmt::print("frame bench: {} ({} objects), {} views from {}, {}x{} display, {} rounds, {} thread(s), {}; load {:.1f} ms, "
               "setup {:.1f} ms\n",
               scene.source, scene.objects.size(), views, source, config.display.width, config.display.height, o.rounds, o.threads,
               culler.buffer().config().isa, load_ms, setup_ms);
    fmt::print("view  frame ms  (select  render    maps   tests)  efficiency (plain)  occluders' bound  false culls\n");
    for (const nlohmann::json& v : per_view)
        fmt::print("{:4}  {:8.3f}  ({:6.3f} {:7.3f} {:7.3f} {:7.3f})  {:8.1f} % ({:5.1f} %)  {:13.1f} %  {}\n", v["view"].get<std::size_t>(),
                   v["frame_ms"].get<double>(), v["stages_ms"]["select"].get<double>(), v["stages_ms"]["render"].get<double>(),
                   v["stages_ms"]["maps"].get<double>(), v["stages_ms"]["tests"].get<double>(), 100.0 * v["efficiency"].get<double>(),
                   100.0 * v["efficiency_plain"].get<double>(), 100.0 * v["occluder_bound"]["efficiency_bound"].get<double>(),
                   v["false_culls"].get<std::size_t>());
    fmt::print("all   mean {:.3f} ms, worst {:.3f} ms; efficiency {:.1f} % of {} objects hidden outright ({:.1f} % of all hidden); "
               "{} false culls; the occluders drawn could hide {:.1f} %\n",
               mean_frame, worst_frame, 100.0 * total.robust_efficiency(), total.hidden_in_frustum - total.hidden_through_ties,
               100.0 * total.efficiency(), total.false_culls, 100.0 * total_bound.efficiency_bound());
    if (o.scaling) {
        const nlohmann::json& ms = scaling.at("frame_ms_mean");
        const nlohmann::json& trip = scaling.at("cross_core_round_trip_ns");
        fmt::print("scaling, {} rounds: {} threads {:.2f}x one thread (mean frame {:.3f} against {:.3f} ms); the machine's ceiling, "
                   "{} copies at once: {:.2f}x ({:.3f} ms); a line between two cores and back: {:.0f} ns ({:.0f}-{:.0f})\n",
                   o.rounds, o.threads, scaling.at("speedup").get<double>(), ms["threads"].get<double>(), ms["one_thread"].get<double>(),
                   o.threads, scaling.at("ceiling").get<double>(), ms["copies_at_once"].get<double>(), trip["median"].get<double>(),
                   trip["min"].get<double>(), trip["max"].get<double>());
    }
}

}  // namespace homcull::cli
