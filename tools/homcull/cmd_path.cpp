// homcull path: camera paths for a scene (an orbit, or a walk through its free space).
#include "commands.hpp"
#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/walk_path.hpp>

#include <fmt/core.h>

#include <memory>

namespace homcull::cli {

void register_path(CLI::App& app) {
    struct Options {
        SceneChoice scene;
        std::string kind = "walk", out;
        int frames = 200;
        std::uint64_t seed = 1;
        double eye_height = 0.0, step = 0.0, fov_y = 60.0;
    };
    auto o = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("path", "Generate a camera path for a scene: an orbit, or a walk at eye height through free space");
    add_scene_option(*cmd, o->scene);
    cmd->add_option("--kind", o->kind, "orbit or walk")->capture_default_str()->check(CLI::IsMember({"orbit", "walk"}));
    cmd->add_option("--frames", o->frames, "Number of frames")->capture_default_str()->check(CLI::Range(1, 1000000));
    cmd->add_option("--seed", o->seed, "Random seed of the walk")->capture_default_str();
    cmd->add_option("--eye-height", o->eye_height, "Walk: eye above the floor (0 = 1.7, or 64 for scenes over 2,000 units)")
        ->capture_default_str();
    cmd->add_option("--step", o->step, "Walk: distance per frame (0 = eye height / 5)")->capture_default_str();
    cmd->add_option("--fov-y", o->fov_y, "Vertical field of view, degrees")->capture_default_str()->check(CLI::Range(1.0, 179.0));
    cmd->add_option("--out", o->out, "Output path file (JSON); stdout when left out");
    cmd->callback([o] {
        const Scene scene = load_chosen_scene(o->scene);
        CameraPath path;
        if (o->kind == "orbit") {
            const Aabb b = scene.bounds();
            if (b.empty()) throw Error(scene.source + ": the scene is empty");
            path = orbit_path(glm::dvec3(b.min), glm::dvec3(b.max), o->frames, o->fov_y);
        } else {
            WalkOptions w;
            w.frames = o->frames;
            w.seed = o->seed;
            w.eye_height = o->eye_height;
            w.step = o->step;
            w.fov_y_degrees = o->fov_y;
            const RayScene rays(scene);
            path = walk_path(rays, scene, w);
        }
        if (o->out.empty()) {
            fmt::print("{}", camera_path_to_json(path));
        } else {
            write_camera_path(path, o->out);
            fmt::print(stderr, "wrote {}: {} frames ({})\n", o->out, path.frames.size(), o->kind);
        }
    });
}

}  // namespace homcull::cli
