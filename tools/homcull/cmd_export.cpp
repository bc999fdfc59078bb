// homcull export: write any scene homcull reads (a generated one included) as binary glTF.
#include "commands.hpp"
#include "options.hpp"

#include <homcull/io/scene_io.hpp>

#include <fmt/core.h>

#include <memory>

namespace homcull::cli {

void register_export(CLI::App& app) {
    struct Options {
        SceneChoice scene;
        std::string out;
    };
    auto o = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("export", "Write a scene (file or gen:...) as binary glTF, shared meshes kept shared");
    add_scene_option(*cmd, o->scene);
    cmd->add_option("--out", o->out, "Output .glb file")->required();
    cmd->callback([o] {
        const Scene scene = load_chosen_scene(o->scene);
        save_glb(scene, o->out);
        fmt::print("wrote {}: {} objects, {} meshes, {} triangles placed\n", o->out, scene.objects.size(),
                   scene.meshes.size(), scene.instanced_triangle_count());
    });
}

}  // namespace homcull::cli
