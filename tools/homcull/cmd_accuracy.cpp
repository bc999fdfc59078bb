// homcull accuracy: false and missed culls of the occlusion buffer.
//   S1 (default): workload S1's 1M rectangles against an exact double-precision depth at the
//                 same sample centres.
//   --scene F:    every object's AABB test against Embree ground truth at the display's pixel
//                 centres, from the frames of --path, or of a generated walk, orbit or random
//                 views. --offset X,Y,Z culls the scene moved by that much (from the views moved
//                 with it) and judges it against ground truth on the unmoved scene.
#include "commands.hpp"
#include "cull_options.hpp"
#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/io/workload_s1.hpp>
#include <homcull/truth/culling_accuracy.hpp>
#include <homcull/truth/walk_path.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/truth/exact_depth.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>

namespace homcull::cli {

namespace {

template <class Options>
void run_scene_accuracy(const Options& o) {
    SceneCullerConfig config = scene_culler_config(o.cull, 1);  // its views are culled on this thread
    const Scene scene = load_chosen_scene(o.scene);
    const CullResources resources = prepare_cull_resources(o.cull, scene, config);
    const RayScene rays(scene);
    const glm::dvec3 offset = o.offset.empty() ? glm::dvec3(0.0) : parse_vec3(o.offset, "--offset");
    CameraPath views;
    if (!o.path.empty()) views = read_camera_path(o.path);
    else if (o.random > 0) views = random_views(rays, scene, o.random, o.seed);
    else if (o.walk > 0) {
        WalkOptions walk;
        walk.frames = o.walk * 10;
        const CameraPath full = walk_path(rays, scene, walk);
        for (std::size_t k = 0; k < full.frames.size(); k += 10) views.frames.push_back(full.frames[k]);
    } else if (o.orbit > 0) {
        const Aabb b = scene.bounds();
        views = orbit_path(glm::dvec3(b.min), glm::dvec3(b.max), o.orbit);
    } else {
        throw Error("accuracy --scene needs views: --path P, --walk N, --orbit N or --random N");
    }
    // The culler's own scene: the same, or moved (its resources, the occluder list and LODs, are
    // by object id and model space, so they serve both).
    const Scene moved = offset == glm::dvec3(0.0) ? Scene{} : translated_scene(scene, offset);
    const Scene& culled_scene = offset == glm::dvec3(0.0) ? scene : moved;
    if (const Aabb b = culled_scene.bounds(); !b.empty() && !(std::isfinite(b.min.x) && std::isfinite(b.min.y) && std::isfinite(b.min.z) &&
                                                            std::isfinite(b.max.x) && std::isfinite(b.max.y) && std::isfinite(b.max.z)))
        throw Error("--offset " + o.offset + " moves the scene beyond the float range");
    SceneCuller culler(culled_scene, resources.occluders, config);
    const Resolution display = config.display;
    const BufferConfig& buffer = culler.buffer().config();
    CullingTally tally;
    for (std::size_t k = 0; k < views.frames.size(); ++k) {
        tally_culling(scene, rays, culler, views.frames[k], tally, offset);
        if (!o.json) fmt::print(stderr, "\rview {}/{}", k + 1, views.frames.size());
    }
    if (!o.json) fmt::print(stderr, "\n");
    if (o.json) {
        const double views_count = std::max(1, tally.views);
        fmt::print("{}\n", nlohmann::json{{"scene", scene.source}, {"offset", {offset.x, offset.y, offset.z}},
                                          {"display", {display.width, display.height}},
                                          {"buffer", {buffer.width, buffer.height}}, {"samples", buffer.samples},
                                          {"mode", o.cull.mode}, {"hole", config.maps.hole_pixels}, {"depth", o.cull.depth},
                                          {"views", tally.views}, {"occluder_triangles", culler.occluder_triangles()},
                                          {"ms_per_view", {{"render", tally.total_ms.render_ms / views_count},
                                                           {"maps", tally.total_ms.maps_ms / views_count},
                                                           {"tests", tally.total_ms.test_ms / views_count}}},
                                          {"visible", tally.visible}, {"hidden_in_frustum", tally.hidden_in_frustum},
                                          {"culled_hidden", tally.culled_hidden}, {"missed_culls", tally.missed_culls()},
                                          {"false_culls", tally.false_culls}, {"robust_false_culls", tally.robust_false_culls},
                                          {"efficiency", tally.efficiency()}, {"hidden_through_ties", tally.hidden_through_ties},
                                          {"culled_through_ties", tally.culled_through_ties},
                                          {"robust_efficiency", tally.robust_efficiency()}, {"false_cull_reports", tally.false_cull_reports}}
                                .dump(1));
        return;
    }
    fmt::print("{}: {} views at {}x{} (buffer {}x{}, {}x{} samples; {} mode, depth {}), {} occluder triangles\n", scene.source,
               tally.views, display.width, display.height, buffer.width, buffer.height, buffer.samples, buffer.samples, o.cull.mode,
               o.cull.depth, culler.occluder_triangles());
    const double views_count = std::max(1, tally.views);
    fmt::print("ms per view: render {:.3f}, maps {:.3f}, tests {:.3f}\n", tally.total_ms.render_ms / views_count,
               tally.total_ms.maps_ms / views_count, tally.total_ms.test_ms / views_count);
    fmt::print("false culls {} ({} seen by robust samples); culled {} of {} hidden objects ({:.1f} %), missed {}\n",
               tally.false_culls, tally.robust_false_culls, tally.culled_hidden, tally.hidden_in_frustum, 100.0 * tally.efficiency(),
               tally.missed_culls());
    fmt::print("hidden only through ties: {} (culled {}); hidden outright: culled {:.1f} %\n", tally.hidden_through_ties,
               tally.culled_through_ties, 100.0 * tally.robust_efficiency());
    for (const std::string& line : tally.false_cull_reports) fmt::print("false cull: {}\n", line);
}

}  // namespace

void register_accuracy(CLI::App& app) {
    struct Options {
        std::string resolution = "1920x1080", s1_folder = "../shared/workloads/s1";
        SceneChoice scene;
        std::string path;
        int samples = 0, walk = 0, orbit = 0, random = 0;  // samples 0: 1 on S1, automatic_samples with --scene
        std::uint64_t seed = 1;
        std::string offset;
        CullOptions cull;  // --scene
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("accuracy", "False and missed culls on workload S1's rectangles against exact depth");
    cmd->add_option("--resolution", o->resolution, "S1: buffer resolution WxH; --scene: display resolution WxH")->capture_default_str();
    cmd->add_option("--samples", o->samples,
                    "S x S samples per buffer pixel (1, 2 or 4; S1: default 1; --scene: the buffer is display / S, default as cull's)")
        ->check(CLI::IsMember({1, 2, 4}));
    cmd->add_option("--s1", o->s1_folder, "Folder of workload S1")->capture_default_str();
    add_scene_option(*cmd, o->scene, /*required=*/false, "Measure on a scene against Embree ground truth instead of S1");
    CLI::Option* path = cmd->add_option("--path", o->path, "--scene: camera path whose frames are the views");
    CLI::Option* walk = cmd->add_option("--walk", o->walk, "--scene: views from a generated walk (N views, every 10th frame)");
    CLI::Option* orbit = cmd->add_option("--orbit", o->orbit, "--scene: N views on an orbit");
    CLI::Option* random = cmd->add_option("--random", o->random, "--scene: N random views from the scene's free space, looking anywhere");
    cmd->add_option("--seed", o->seed, "--random: the views' seed")->capture_default_str();
    cmd->add_option("--offset", o->offset,
                    "--scene: cull the scene moved by x,y,z (views moved with it), judged against ground truth on the unmoved scene");
    path->excludes(walk)->excludes(orbit)->excludes(random);  // one source of views
    walk->excludes(orbit)->excludes(random);
    orbit->excludes(random);
    add_cull_options(*cmd, o->cull, /*with_display=*/false);  // --scene: --buffer, --mode, --hole, --depth, --occluders, ...
    cmd->add_flag("--json", o->json, "Print JSON on stdout");
    cmd->callback([o, cmd] {
        if (o->scene.file.empty())  // S1 has its own buffer and no scene: these would be silently ignored
            for (const char* name : {"--path", "--walk", "--orbit", "--buffer", "--mode", "--hole", "--distribution", "--transparency",
                                     "--soup-cells", "--depth", "--deb", "--finest-level", "--pyramid", "--occludee-parts", "--random", "--offset", "--coarsest-level", "--occludees", "--sample-depth", "--occluders", "--complexity", "--strategy", "--rank", "--grid", "--lod", "--budget", "--min-occluder-size", "--batch",
                                     "--hierarchy"})
                if (cmd->get_option(name)->count() > 0) throw Error(std::string("accuracy: ") + name + " needs --scene");
        if (!o->scene.file.empty()) {
            o->cull.resolution = o->resolution;
            o->cull.samples = o->samples;
            run_scene_accuracy(*o);
            return;
        }
        const Resolution res = parse_resolution(o->resolution);
        const WorkloadS1 s1 = load_workload_s1(o->s1_folder);
        BufferConfig config;
        config.width = res.width;
        config.height = res.height;
        config.samples = o->samples == 0 ? 1 : o->samples;
        config.near_w = 1.0f;
        OcclusionBuffer buffer(config);
        buffer.render(s1.occluder_input());
        const long long start = now_ns();
        const ExactDepth exact = exact_depth_of_triangles(s1.occluders.data(), s1.occluder_count(), buffer.sample_width(),
                                                          buffer.sample_height(), /*cull_clockwise=*/true);
        const double exact_ms = elapsed_ms(start);
        const RectAccuracy a = count_rect_accuracy(buffer, exact, s1.rects.data(), s1.rect_count());
        const std::size_t hidden = a.truly_hidden, culled = a.culled, false_culls = a.false_culls, missed = a.missed_culls;
        const double missed_share = hidden ? double(missed) / double(hidden) : 0.0;
        if (o->json) {
            fmt::print("{}\n", nlohmann::json{{"resolution", {res.width, res.height}}, {"samples", config.samples},
                                              {"rects", s1.rect_count()}, {"truly_hidden", hidden}, {"culled", culled},
                                              {"false_culls", false_culls}, {"missed_culls", missed},
                                              {"missed_share_of_hidden", missed_share}, {"exact_ms", exact_ms}}.dump(1));
            return;
        }
        fmt::print("S1 at {}x{}, {}x{} samples: {} of {} rectangles truly hidden; culled {}; false culls {}; missed {} ({:.2f} % of hidden)\n",
                   res.width, res.height, config.samples, config.samples, hidden, s1.rect_count(), culled, false_culls, missed,
                   100.0 * missed_share);
    });
}

}  // namespace homcull::cli
