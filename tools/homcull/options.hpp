#pragma once
// Options several subcommands share: the scene, the camera, the display resolution.
#include <homcull/camera.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/parallel_for.hpp>
#include <homcull/scene.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace homcull::cli {

struct CameraOptions {
    std::string eye, target, up = "0,1,0";
    double fov_y = 60.0, near_plane = 0.1, far_plane = 10000.0;
    std::string path;
    int frame = 0;
};

// --scene F: a file (glTF/GLB, OBJ, PLY, IFC, ...) or gen:city / gen:forest[:options]; and
// --soup-cells T: objects with more than T triangles split into cells (Zhang's subdivision of
// polygon soups, soup_subdivision.hpp). Every command that names objects takes both, so that
// object ids agree between them.
struct SceneChoice {
    std::string file;
    std::size_t soup_cells = 0;  // 0: objects as the file has them
};
// required: --scene must be given (commands that can run without a scene pass false).
void add_scene_option(CLI::App& app, SceneChoice& scene, bool required = true,
                      const std::string& help = "Scene file (glTF/GLB, OBJ, PLY, IFC, ... anything assimp reads) or a generated "
                                                "scene: gen:city, gen:forest, with options such as gen:city:seed=3,blocks=10");
// Loads the scene, then splits its polygon soups when asked. Throws homcull::Error.
Scene load_chosen_scene(const SceneChoice& scene);
// --eye x,y,z --target x,y,z [--up x,y,z --fov-y D --near N --far F], or --path P [--frame K].
void add_camera_options(CLI::App& app, CameraOptions& options);
// Throws homcull::Error when the options do not make a valid camera.
Camera resolve_camera(const CameraOptions& options);

// A number >= 0 on the command line, infinity included; NaN refused (CLI11's NonNegativeNumber
// lets NaN through, since no comparison with it fails, and names its bound as 309 digits).
extern const CLI::Validator kAtLeastZero;

glm::dvec3 parse_vec3(const std::string& text, const char* what);
// "WxH" (also "W,H"), each in [1, 65536]; errors name `option` (the command-line option read).
Resolution parse_resolution(const std::string& text, const std::string& option = "--resolution");

// {"eye","target","up","fov_y","near","far"}: a camera as commands print it (the path format's fields).
nlohmann::json camera_json(const Camera& camera);

// The rasterizer's statistics as JSON, field by field.
nlohmann::json stats_json(const RasterStats& stats);

// Milliseconds since `start` (std::chrono::steady_clock).
double elapsed_ms(long long start_ns);
long long now_ns();
// The median of timings (the mean of the middle two for an even count; 0 for none).
double median(std::vector<double> v);

// The job system of a command's --threads: TBB's for more than one thread, its worker threads
// started now, so that a command's first cull or render does not count their start (an engine's
// job system has its threads already); for one, the calling thread.
ParallelFor command_job_system(int threads);

}  // namespace homcull::cli
