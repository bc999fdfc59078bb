// homcull bench: speed of the occlusion buffer on fixed workloads (not a test: it times).
// A render is timed as an engine's frame calls it: render_frame, the clear included.
//   s1:     ../shared/workloads/s1, the 100k triangles and 1M rectangles Intel MOC was measured on
//   castle: the castle's role=occluder nodes from the views of data/views/castle.json
//   frame:  whole frames of the scene culler, with efficiency and false culls against Embree
//           (bench_frame.cpp)
#include "bench_frame.hpp"
#include "commands.hpp"
#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/io/workload_s1.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/world_triangles.hpp>

#include <fmt/core.h>
#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>

namespace homcull::cli {
namespace {

struct BenchOptions {
    std::string workload = "s1", resolution, isa = "best";  // resolution: 1920x1080 (s1, castle) or 1280x720 (frame)
    std::string s1_folder = "../shared/workloads/s1", scene = "../shared/scenes/intel_castle.glb", views;
    int samples = 1, threads = 1, repeat = 0, clusters = 0;
    bool clusters_given = false;  // frame: without --clusters, the culler's default (clusters)
    bool json = false, sample_depth = false, vs_scalar = false, scaling = false;
    std::string frame_option_given;  // the first option for --workload frame only that was given
    int walk = 0, random = 0;  // frame: views from a walk or random viewpoints instead of --views
    std::uint64_t seed = 1;
    // frame: the culler's options that bench passes on (cull's, with cull's defaults; bench's
    // own --resolution, --samples and --clusters fill the others).
    CullOptions frame;
};

constexpr const char* kCastleViews = "data/views/castle.json";

void run_frame_workload(const BenchOptions& o) {
    if (o.vs_scalar || o.sample_depth) throw Error("bench --workload frame: --vs-scalar and --sample-depth are for s1 and castle");
    if (o.clusters < 0) throw Error("bench: --clusters must be 0 (off) or more, got " + std::to_string(o.clusters));
    if (o.repeat < 0) throw Error("bench: --repeat must be at least 1 (0: the workload's default), got " + std::to_string(o.repeat));
    FrameBenchOptions f;
    f.scene = o.scene;
    f.views = o.views.empty() && o.walk == 0 && o.random == 0 ? kCastleViews : o.views;
    f.walk = o.walk, f.random = o.random, f.seed = o.seed;
    f.rounds = o.repeat > 0 ? o.repeat : 15;
    f.threads = o.threads;
    f.isa = o.isa;
    f.json = o.json;
    f.cull = o.frame;
    f.cull.resolution = o.resolution.empty() ? "1280x720" : o.resolution;
    f.cull.samples = o.samples;
    if (o.clusters_given) f.cull.clusters = o.clusters > 0 ? "on" : "off";
    f.scaling = o.scaling;
    run_frame_bench(f);
}


// The timings of one workload under the selected instruction set: the render (median `ms`,
// fastest `min_ms`), and on S1 the rectangle tests too. The inputs are loaded once by the
// caller (S1 or the castle's occluders and views, the clusters built).
struct BenchInputs {
    const WorkloadS1* s1 = nullptr;
    const CameraPath* views = nullptr;
    const WorldTriangles* occluders = nullptr;
    const OccluderClusters* clusters = nullptr;  // castle with --clusters
};

nlohmann::json time_workload(const BenchOptions& o, const BufferConfig& base, const ParallelFor& parallel, const BenchInputs& inputs) {
    nlohmann::json out;
    BufferConfig config = base;
    if (inputs.s1) {
        const WorkloadS1& s1 = *inputs.s1;
        config.near_w = 1.0f;  // the near clip plane MOC was measured with
        OcclusionBuffer buffer(config);
        const TriangleInput in = s1.occluder_input();
        std::vector<double> render_ms, test_ms, single_ms;
        const int repeat = o.repeat > 0 ? o.repeat : 5;
        const auto* rects = reinterpret_cast<const ScreenRect*>(s1.rects.data());
        std::vector<Visibility> answers(s1.rect_count());
        // The batch call, split into tasks for the job system (queries are thread-safe).
        struct RectJob {
            const OcclusionBuffer* buffer;
            const ScreenRect* rects;
            Visibility* answers;
            std::size_t count, per_task;
        } job{&buffer, rects, answers.data(), s1.rect_count(), 16384};
        const std::size_t tasks = (job.count + job.per_task - 1) / job.per_task;
        const auto run_rect_task = [](void* data, std::size_t t) {
            const RectJob& j = *static_cast<RectJob*>(data);
            const std::size_t begin = t * j.per_task, n = std::min(j.per_task, j.count - begin);
            j.buffer->test_rects(j.rects + begin, n, j.answers + begin);
        };
        std::size_t occluded = 0;
        for (int r = 0; r < repeat; ++r) {
            long long start = now_ns();
            buffer.render_frame(in, parallel);
            render_ms.push_back(elapsed_ms(start));
            start = now_ns();
            if (parallel.run) parallel.run(parallel.user, tasks, run_rect_task, &job);
            else
                for (std::size_t t = 0; t < tasks; ++t) run_rect_task(&job, t);
            test_ms.push_back(elapsed_ms(start));
            occluded = std::size_t(std::count(answers.begin(), answers.end(), Visibility::occluded));
        }
        // One call per rectangle, on this thread: the rate of the plain test_rect. In a loop of
        // its own: between two renders, 70 ms of it on one thread let a job system's workers
        // fall asleep, and the next render waited about 0.2 ms for them to wake (TBB, two
        // threads), a cost of the benchmark's order rather than of the render.
        for (int r = 0; r < repeat; ++r) {
            const long long start = now_ns();
            std::size_t hidden = 0;
            for (std::size_t k = 0; k < s1.rect_count(); ++k)
                hidden += buffer.test_rect(rects[k].ndc_min_x, rects[k].ndc_min_y, rects[k].ndc_max_x, rects[k].ndc_max_y, rects[k].w_min) ==
                          Visibility::occluded;
            single_ms.push_back(elapsed_ms(start));
            if (hidden != occluded) throw Error("bench: test_rect and test_rects disagree");
        }
        const double ms = median(render_ms), rect_ms = median(test_ms);
        out["ms"] = ms;
        out["min_ms"] = *std::min_element(render_ms.begin(), render_ms.end());  // steadier on a loaded machine
        out["mtris_per_s"] = double(s1.occluder_count()) / (ms * 1e3);
        out["rect_ms"] = rect_ms;
        out["rect_min_ms"] = *std::min_element(test_ms.begin(), test_ms.end());
        out["rect_tests_per_s"] = double(s1.rect_count()) / (rect_ms * 1e-3);
        out["rect_single_call_ms"] = median(single_ms);
        out["rect_single_calls_per_s"] = double(s1.rect_count()) / (median(single_ms) * 1e-3);
        out["rects_occluded"] = occluded;
        out["runs"] = repeat;
        out["stats"] = stats_json(buffer.stats());
        return out;
    }
    const WorldTriangles& occluders = *inputs.occluders;
    const int repeat = o.repeat > 0 ? o.repeat : 21;
    nlohmann::json per_view = nlohmann::json::array();
    for (const Camera& view : inputs.views->frames) {
        config.near_w = float(view.near_plane);
        OcclusionBuffer buffer(config);
        const TriangleInput in = occluders.input(clip_from_world(view, Resolution{config.width, config.height}.aspect()), Backface::cw);
        const ClusteredInput clustered_in{inputs.clusters, in.model_to_clip, in.backface};
        std::vector<double> ms;
        for (int r = 0; r < repeat; ++r) {
            const long long start = now_ns();
            if (inputs.clusters) buffer.render_frame(clustered_in, parallel);
            else buffer.render_frame(in, parallel);
            ms.push_back(elapsed_ms(start));
        }
        per_view.push_back({{"ms", median(ms)}, {"min_ms", *std::min_element(ms.begin(), ms.end())}, {"stats", stats_json(buffer.stats())}});
    }
    // The first view's (C0's) figures at the top, as S1's.
    out["ms"] = per_view.empty() ? 0.0 : per_view.front()["ms"].get<double>();
    out["min_ms"] = per_view.empty() ? 0.0 : per_view.front()["min_ms"].get<double>();
    out["mtris_per_s"] = double(occluders.triangle_count()) / (out["ms"].get<double>() * 1e3);
    out["triangles"] = occluders.triangle_count();
    out["views"] = per_view;
    out["runs"] = repeat;
    return out;
}

void run_bench(const BenchOptions& o) {
    if (o.workload == "frame") return run_frame_workload(o);
    if (o.workload != "s1" && o.workload != "castle") throw Error("bench: unknown workload '" + o.workload + "' (s1, castle or frame)");
    // Refused rather than ignored: s1 and castle time the buffer alone, which none of these reach.
    if (!o.frame_option_given.empty()) throw Error("bench: " + o.frame_option_given + " is for --workload frame");
    if (o.clusters != 0 && o.workload != "castle") throw Error("bench: --clusters is for --workload castle");
    if (o.clusters < 0) throw Error("bench: --clusters must be 0 (the triangles as one input) or triangles per cluster, got " +
                                    std::to_string(o.clusters));
    ClusterLimits limits;  // --clusters N: at most N triangles and min(N, 255) vertices per cluster
    limits.max_triangles = std::size_t(o.clusters);
    limits.max_vertices = std::min<std::size_t>(255, std::size_t(o.clusters));
    if (o.clusters > 0) check_cluster_limits(limits, ("bench: --clusters " + std::to_string(o.clusters)).c_str());  // before the scene is loaded
    if (o.threads < 1 || o.threads > 256) throw Error("bench: --threads must be in [1, 256], got " + std::to_string(o.threads));
    if (o.repeat < 0) throw Error("bench: --repeat must be at least 1 (0: the workload's default), got " + std::to_string(o.repeat));
    select_isa(o.isa);  // checks the name; "best" names the best one in the JSON
    // One thread: the library's serial path. More: TBB limited to that many threads.
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(o.threads));
    const ParallelFor parallel = command_job_system(o.threads);
    const Resolution res = parse_resolution(o.resolution.empty() ? "1920x1080" : o.resolution);
    BufferConfig config;
    config.width = res.width;
    config.height = res.height;
    config.samples = o.samples;
    config.sample_depth = o.sample_depth;
    config.isa = o.isa.c_str();
    nlohmann::json out = {{"workload", o.workload}, {"resolution", {res.width, res.height}}, {"samples", o.samples},
                          {"threads", o.threads}, {"isa", selected_isa()}, {"sample_depth", o.sample_depth}};

    BenchInputs inputs;
    std::unique_ptr<WorkloadS1> s1;
    std::unique_ptr<Scene> castle;
    std::unique_ptr<CameraPath> views;
    std::unique_ptr<WorldTriangles> occluders;
    OccluderClusters clustered;
    if (o.workload == "s1") {
        s1 = std::make_unique<WorkloadS1>(load_workload_s1(o.s1_folder));
        inputs.s1 = s1.get();
    } else {
        castle = std::make_unique<Scene>(load_scene(o.scene));
        views = std::make_unique<CameraPath>(read_camera_path(o.views.empty() ? kCastleViews : o.views));
        occluders = std::make_unique<WorldTriangles>(gather_world_triangles(*castle, objects_with_role(*castle, "occluder")));
        inputs.views = views.get();
        inputs.occluders = occluders.get();
        // --clusters N: the occluders split into clusters of at most N triangles first (timed
        // apart: it is done once, when the scene is loaded), and rendered as such.
        if (o.clusters > 0) {
            const long long start = now_ns();
            clustered = build_occluder_clusters(occluders->positions.data(), 3 * sizeof(float), occluders->positions.size() / 3,
                                                occluders->indices.data(), occluders->triangle_count(), occluders->shared_edges.data(), occluders->edge_apexes.data(),
                                                limits);
            out["cluster_build_ms"] = elapsed_ms(start);
            out["clusters"] = clustered.clusters.size();
            inputs.clusters = &clustered;
        }
    }
    out.update(time_workload(o, config, parallel, inputs));
    if (o.vs_scalar) {
        // The same workload on the scalar reference path, with the same threads and runs.
        BufferConfig scalar_config = config;
        scalar_config.isa = "scalar";
        const nlohmann::json scalar = time_workload(o, scalar_config, parallel, inputs);
        nlohmann::json& s = out["scalar"];
        for (const char* key : {"ms", "min_ms", "mtris_per_s", "rect_tests_per_s", "rect_single_calls_per_s"})
            if (scalar.contains(key)) s[key] = scalar[key];
        out["speedup_vs_scalar"] = scalar["ms"].get<double>() / out["ms"].get<double>();
    }
    if (o.json) {
        fmt::print("{}\n", out.dump(1));
        return;
    }
    fmt::print("workload {} at {}x{}, {}x{} samples, {} thread(s), {}: {:.2f} ms ({:.2f} Mtri/s)\n", o.workload, res.width,
               res.height, o.samples, o.samples, o.threads, selected_isa(), out["ms"].get<double>(), out["mtris_per_s"].get<double>());
    if (out.contains("rect_tests_per_s"))
        fmt::print("rectangle tests: {:.1f} ms for 1M ({:.1f} M/s batched; {:.1f} M/s one call each, one thread), {} occluded\n",
                   out["rect_ms"].get<double>(), out["rect_tests_per_s"].get<double>() * 1e-6,
                   out["rect_single_calls_per_s"].get<double>() * 1e-6, out["rects_occluded"].get<std::size_t>());
    if (o.vs_scalar)
        fmt::print("scalar reference path: {:.2f} ms, {:.2f}x slower\n", out["scalar"]["ms"].get<double>(),
                   out["speedup_vs_scalar"].get<double>());
}

}  // namespace

void register_bench(CLI::App& app) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* cmd = app.add_subcommand("bench", "Time the occlusion buffer (s1, castle) or whole culled frames (frame) on a fixed "
                                                "workload; a benchmark, not a test");
    cmd->add_option("--workload", o->workload,
                    "s1 (../shared/workloads/s1), castle (role=occluder nodes, data/views/castle.json), or frame (whole frames of the "
                    "scene culler on --scene, per view: time, stages, efficiency and false culls against Embree)")
        ->capture_default_str();
    cmd->add_option("--resolution", o->resolution,
                    "Occlusion buffer resolution WxH (pixels; default 1920x1080); frame: the display (default 1280x720)");
    cmd->add_option("--samples", o->samples, "S x S samples per pixel (1, 2 or 4)")->capture_default_str();
    cmd->add_option("--threads", o->threads, "Threads (1 to 256)")->capture_default_str();
    cmd->add_option("--isa", o->isa, "Instruction set: best, scalar (the reference path), or one of available_isas()")
        ->capture_default_str();
    cmd->add_option("--repeat", o->repeat, "Runs to take the median of (0 = 5 for s1, 21 for castle, 15 rounds over the views for frame)");
    cmd->add_option("--s1", o->s1_folder, "Folder of workload S1")->capture_default_str();
    cmd->add_option("--scene", o->scene, "Scene for --workload castle and frame (frame: any scene file or gen:...)")->capture_default_str();
    cmd->add_option("--clusters", o->clusters,
                    "castle: split the occluders into clusters of at most N triangles (a multiple of 4, <= 512) and render those "
                    "(OccluderClusters); 0 (castle's default) = the triangles as one input. frame: without it, clusters (cull's "
                    "default); N > 0 draws the occluders as clusters (cull --clusters on), 0 every triangle (cull --clusters off)")
        ->capture_default_str()
        ->each([o](const std::string&) { o->clusters_given = true; });
    cmd->add_option("--views", o->views, "Camera path with the views for --workload castle and frame (default data/views/castle.json)");
    cmd->add_option("--walk", o->walk, "frame: a walk of N frames through the scene instead of --views (walk_path)")->check(CLI::Range(1, 100000));
    cmd->add_option("--random", o->random, "frame: N random viewpoints in the scene's free space instead of --views (random_views)")
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--seed", o->seed, "frame: seed of --walk or --random")->capture_default_str();
    cmd->add_option("--occludees", o->frame.occludees, "frame: how objects are tested, as cull --occludees: box, rects, samples or auto")
        ->capture_default_str();
    cmd->add_option("--closed-back-faces", o->frame.closed_back_faces, "frame: skip or draw the back faces of closed occluder meshes (cull --closed-back-faces)")
        ->capture_default_str()->check(CLI::IsMember({"skip", "draw"}));
    cmd->add_option("--back-faces", o->frame.back_faces,
                    "frame: draw or cull every occluder triangle facing away from the eye (cull --back-faces)")
        ->capture_default_str()->check(CLI::IsMember({"draw", "cull"}));
    cmd->add_option("--merge-coplanar", o->frame.merge_coplanar,
                    "frame: re-triangulate each occluder's exactly coplanar regions when loading, or not (cull --merge-coplanar)")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    cmd->add_option("--occludee-parts", o->frame.occludee_parts, "frame: parts per object with a box each (cull --occludee-parts)")
        ->capture_default_str()->check(CLI::Range(0, 64));
    cmd->add_option("--pyramid", o->frame.pyramid, "frame: lazy or always build the maps' pyramids (cull --pyramid)")
        ->capture_default_str()->check(CLI::IsMember({"lazy", "always"}));
    cmd->add_option("--occluders", o->frame.occluders,
                    "frame: the occluder candidates, role, all or auto (cull --occluders); with --complexity, the objects "
                    "cheap for their surface among every object: --occluders all --complexity 0.25")
        ->capture_default_str()->check(CLI::IsMember({"role", "all", "auto"}));
    cmd->add_option("--complexity", o->frame.complexity,
                    "frame: drop occluder candidates with more than F times the median triangles per unit of their surface "
                    "(cull --complexity); 0: keep all")
        ->capture_default_str()->check(kAtLeastZero);
    cmd->add_option("--min-occluder-size", o->frame.min_occluder_size,
                    "frame: draw only the occluder candidates whose box looks at least this large from the eye, in square "
                    "radians (cull --min-occluder-size); 0: every one")
        ->capture_default_str()->check(kAtLeastZero);
    cmd->add_flag("--scaling", o->scaling,
                  "frame, --threads N >= 2: also time one thread, N threads and N single-threaded copies at once (the "
                  "machine's ceiling) in alternation, and report the threads' speed-up beside the ceiling and beside the time a "
                  "cache line takes between two cores and back");
    cmd->add_flag("--sample-depth", o->sample_depth, "Also keep a depth per sample (BufferConfig::sample_depth)");
    cmd->add_flag("--vs-scalar", o->vs_scalar,
                  "Also time the scalar reference path (same threads and runs): \"scalar\" and \"speedup_vs_scalar\" (its median "
                  "over this one's)");
    cmd->add_flag("--json", o->json, "Print JSON on stdout");
    cmd->callback([o, cmd] {
        for (const char* name : {"--walk", "--random", "--seed", "--occludees", "--closed-back-faces", "--back-faces", "--merge-coplanar",
                                 "--occludee-parts", "--pyramid", "--occluders", "--complexity", "--min-occluder-size", "--scaling"})
            if (o->frame_option_given.empty() && cmd->count(name) > 0) o->frame_option_given = name;
        run_bench(*o);
    });
}

}  // namespace homcull::cli
