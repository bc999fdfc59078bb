// homcull dump: one culled frame's occlusion buffer and hierarchical occlusion maps as a
// multi-part EXR (DIR/maps.exr) and colormapped PNGs (DIR/<part>.png, DIR/colormaps.json), and
// the scene coloured by the answers (DIR/overlay.png, false culls in magenta).
#include "commands.hpp"
#include "cull_options.hpp"
#include "frame_dump.hpp"
#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>

#include <fmt/core.h>

#include <memory>

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
    SceneCullerConfig config = scene_culler_config(o.cull, o.threads);
    prepare_dump_folder(o.out);  // fail on the folder before spending time on the scene
    const Scene scene = load_chosen_scene(o.scene);
    const CullResources resources = prepare_cull_resources(o.cull, scene, config);
    const ParallelFor parallel = command_job_system(o.threads);
    SceneCuller culler(scene, resources.occluders, config, parallel);
    std::vector<OccludeeAnswer> answers;
    culler.cull(camera, answers, parallel);
    fmt::print("scene      {} ({} objects); depth {}\n", scene.source, scene.objects.size(), o.cull.depth);
    const RayScene rays(scene);
    write_frame_dump(culler, rays, camera, answers, o.out, /*print_to_stderr=*/false);
}

}  // namespace

void register_dump(CLI::App& app) {
    auto o = std::make_shared<DumpCommandOptions>();
    CLI::App* cmd = app.add_subcommand("dump", "Cull one frame and write its occlusion buffer and pyramids as a multi-part EXR and PNGs");
    add_scene_option(*cmd, o->scene);
    add_camera_options(*cmd, o->camera);
    add_cull_options(*cmd, o->cull);
    cmd->add_option("--out", o->out, "Output folder (created if missing): maps.exr, <part>.png, colormaps.json, overlay.png")->required();
    cmd->add_option("--threads", o->threads, "Prepare the culler and cull with this many threads (TBB); 1 = the calling thread")
        ->capture_default_str()->check(CLI::Range(1, 256));
    cmd->callback([o] { run_dump(*o); });
}

}  // namespace homcull::cli
