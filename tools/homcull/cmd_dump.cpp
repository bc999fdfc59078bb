// homcull dump: one culled frame's occlusion buffer and hierarchical occlusion maps as a
// multi-part EXR (DIR/maps.exr) and colormapped PNGs (DIR/<part>.png, DIR/colormaps.json).
#include "commands.hpp"
#include "cull_options.hpp"
#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/dumps.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/tbb_parallel_for.hpp>

#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <system_error>

namespace homcull::cli {
namespace {

struct DumpCommandOptions {
    SceneChoice scene;
    CameraOptions camera;
    CullOptions cull;
    std::string out;
    int threads = 1;
};

void run_dump(const DumpCommandOptions& o) {
    const Camera camera = resolve_camera(o.camera);
    SceneCullerConfig config = scene_culler_config(o.cull);
    // Fail on the output folder before spending time on the scene.
    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec || !std::filesystem::is_directory(o.out)) throw Error(o.out + ": cannot create the output folder" + (ec ? " (" + ec.message() + ")" : ""));

    const Scene scene = load_chosen_scene(o.scene);
    const CullResources resources = prepare_cull_resources(o.cull, scene, config);
    SceneCuller culler(scene, resources.occluders, config);
    std::vector<OccludeeAnswer> answers;
    const ParallelFor parallel = o.threads > 1 ? tbb_parallel_for() : ParallelFor{};
    culler.cull(camera, answers, parallel);

    // The parts are read once and written twice, so the EXR and the PNGs show the same frame.
    long long start = now_ns();
    const std::vector<DumpPart> parts = dump_parts(culler.buffer(), culler.maps());
    const std::string exr = o.out + "/maps.exr";
    write_maps_exr(parts, exr);
    const double exr_ms = elapsed_ms(start);
    start = now_ns();
    const std::vector<ColormapPng> pngs = write_colormap_pngs(parts, o.out);
    const double png_ms = elapsed_ms(start);

    const OcclusionBuffer& buffer = culler.buffer();
    fmt::print("scene      {} ({} objects)\n", scene.source, scene.objects.size());
    fmt::print("buffer     {}x{} pixels of {}x{} samples; {} pyramid levels; depth {}\n", buffer.config().width,
               buffer.config().height, config.samples, config.samples, culler.maps().levels(), o.cull.depth);
    fmt::print("wrote      {} ({} parts, {} bytes, {:.0f} ms)\n", exr, parts.size(), std::filesystem::file_size(exr), exr_ms);
    for (const ColormapPng& p : pngs) {
        const std::string range = p.finite ? fmt::format("[{:.5g}, {:.5g}]", p.range_min, p.range_max) : "no finite values";
        fmt::print("wrote      {} ({}x{}, range {}{})\n", p.path, p.width, p.height, range,
                   p.no_occluder ? fmt::format(", {} px no occluder", p.no_occluder) : "");
    }
    fmt::print("wrote      {}/colormaps.json (every PNG's range; {:.0f} ms for the PNGs)\n", o.out, png_ms);
    if (!pngs.empty() && !pngs.front().text_drawn) fmt::print("note       legend text not drawn: {}\n", pngs.front().note);
}

}  // namespace

void register_dump(CLI::App& app) {
    auto o = std::make_shared<DumpCommandOptions>();
    CLI::App* cmd = app.add_subcommand("dump", "Cull one frame and write its occlusion buffer and pyramids as a multi-part EXR and PNGs");
    add_scene_option(*cmd, o->scene);
    add_camera_options(*cmd, o->camera);
    add_cull_options(*cmd, o->cull);
    cmd->add_option("--out", o->out, "Output folder (created if missing): maps.exr, <part>.png, colormaps.json")->required();
    cmd->add_option("--threads", o->threads, "Render with this many threads (TBB); 1 = the calling thread")
        ->capture_default_str()->check(CLI::Range(1, 256));
    cmd->callback([o] { run_dump(*o); });
}

}  // namespace homcull::cli
