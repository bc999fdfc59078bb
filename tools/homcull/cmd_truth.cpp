// homcull truth: exact per-object visibility by Embree ray casts.
#include "commands.hpp"
#include "options.hpp"

#include <homcull/io/id_image.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/ground_truth.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>

namespace homcull::cli {
namespace {

struct TruthCommandOptions {
    SceneChoice scene;
    CameraOptions camera;
    std::string resolution = "1280x720";
    int samples = 1;
    bool json = false;
    std::string id_image;
};

void run_truth(const TruthCommandOptions& o) {
    const Camera camera = resolve_camera(o.camera);
    TruthOptions options;
    options.resolution = parse_resolution(o.resolution);
    options.samples = o.samples;
    options.keep_sample_ids = !o.id_image.empty();

    long long start = now_ns();
    const Scene scene = load_chosen_scene(o.scene);
    const double load_ms = elapsed_ms(start);
    start = now_ns();
    const RayScene rays(scene);
    const double build_ms = elapsed_ms(start);
    const TruthResult truth = compute_ground_truth(rays, scene, camera, options);
    if (!o.id_image.empty()) write_id_image(o.id_image, truth.sample_width, truth.sample_height, truth.sample_ids);

    std::size_t in_frustum = 0, visible = 0;
    std::uint64_t hit_samples = 0;
    for (const auto& v : truth.objects) {
        in_frustum += v.in_frustum;
        visible += v.visible_samples > 0;
        hit_samples += v.visible_samples;
    }
    const std::uint64_t samples = std::uint64_t(truth.sample_width) * std::uint64_t(truth.sample_height);

    if (o.json) {
        nlohmann::json objects = nlohmann::json::array();
        for (std::size_t id = 0; id < scene.objects.size(); ++id) {
            const ObjectVisibility& v = truth.objects[id];
            objects.push_back({{"id", id}, {"name", scene.objects[id].name}, {"triangles", scene.triangle_count(scene.objects[id])},
                               {"in_frustum", v.in_frustum}, {"visible_samples", v.visible_samples},
                               {"robust_samples", v.robust_samples}, {"tie_samples", v.tie_samples},
                               {"result", truth_result_name(v)}});
        }
        nlohmann::json out = {
            {"scene", scene.source},
            {"camera", camera_json(camera)},
            {"resolution", {options.resolution.width, options.resolution.height}},
            {"samples", options.samples},
            {"objects", objects},
            {"summary", {{"objects", scene.objects.size()}, {"in_frustum", in_frustum}, {"visible", visible},
                         {"samples", samples}, {"background_samples", samples - hit_samples}, {"rays", truth.rays},
                         {"load_ms", load_ms}, {"build_ms", build_ms}, {"trace_ms", truth.trace_ms}}}};
        if (!o.id_image.empty()) out["id_image"] = o.id_image;
        fmt::print("{}\n", out.dump(1));
    } else {
        fmt::print("scene        {}\n", scene.source);
        fmt::print("display      {}x{}, {}x{} samples per pixel\n", options.resolution.width, options.resolution.height,
                   options.samples, options.samples);
        fmt::print("objects      {} in all, {} in the frustum, {} visible, {} hidden in the frustum\n",
                   scene.objects.size(), in_frustum, visible, in_frustum - visible);
        fmt::print("time         load {:.0f} ms, build {:.0f} ms, trace {:.0f} ms ({} rays, {:.1f} Mrays/s)\n", load_ms,
                   build_ms, truth.trace_ms, truth.rays, double(truth.rays) / (truth.trace_ms * 1e3));
        std::vector<std::size_t> order;
        for (std::size_t id = 0; id < truth.objects.size(); ++id)
            if (truth.objects[id].visible_samples > 0) order.push_back(id);
        std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
            return truth.objects[a].visible_samples > truth.objects[b].visible_samples;
        });
        const std::size_t shown = std::min<std::size_t>(order.size(), 25);
        if (shown > 0) fmt::print("\n{:>6}  {:<40} {:>9} {:>9}\n", "id", "name", "samples", "robust");
        for (std::size_t k = 0; k < shown; ++k) {
            const auto& v = truth.objects[order[k]];
            fmt::print("{:>6}  {:<40} {:>9} {:>9}\n", order[k], scene.objects[order[k]].name, v.visible_samples, v.robust_samples);
        }
        if (order.size() > shown) fmt::print("   ... {} more visible objects (--json lists every object)\n", order.size() - shown);
        if (!o.id_image.empty()) fmt::print("\nid image     {} ({}x{})\n", o.id_image, truth.sample_width, truth.sample_height);
    }
}

}  // namespace

void register_truth(CLI::App& app) {
    auto o = std::make_shared<TruthCommandOptions>();
    CLI::App* cmd = app.add_subcommand("truth", "Exact per-object visibility from a camera, by Embree ray casts through every sample");
    add_scene_option(*cmd, o->scene);
    add_camera_options(*cmd, o->camera);
    cmd->add_option("--resolution", o->resolution, "Display resolution WxH")->capture_default_str();
    cmd->add_option("--samples", o->samples, "S: SxS sub-samples per pixel on a regular grid (1 = pixel centre)")
        ->capture_default_str()->check(CLI::Range(1, 16));
    cmd->add_flag("--json", o->json, "Print JSON on stdout");
    cmd->add_option("--id-image", o->id_image,
                    "Write the object seen by every sample: PNG in colours, EXR/TIFF as uint32 id+1 (0 = nothing)");
    cmd->callback([o] { run_truth(*o); });
}

}  // namespace homcull::cli
