#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/soup_subdivision.hpp>
#include <homcull/tbb_parallel_for.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

namespace homcull::cli {

const CLI::Validator kAtLeastZero(
    [](const std::string& text) {
        // The whole text a number as CLI11 then reads it into a double (strtod's syntax: "inf"
        // included), without CLI11's internal CLI::detail, which is no part of its interface.
        char* end = nullptr;
        const double v = text.empty() ? 0.0 : std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || !(v >= 0.0))
            return "must be a number at least 0 (inf allowed), got " + text;
        return std::string();
    },
    "NUMBER >= 0");

void add_scene_option(CLI::App& app, SceneChoice& scene, bool required, const std::string& help) {
    auto* option = app.add_option("--scene", scene.file, help);
    if (required) option->required();
    app.add_option("--soup-cells", scene.soup_cells,
                   "Split objects with more than T triangles into cells of at most T (Zhang's subdivision of polygon soups); "
                   "object ids then refer to the cells. 0: objects as the scene has them")
        ->capture_default_str();
}

Scene load_chosen_scene(const SceneChoice& scene) {
    Scene loaded = load_scene(scene.file);
    if (scene.soup_cells == 0) return loaded;
    return subdivide_polygon_soups(loaded, SoupSubdivision{scene.soup_cells});
}

void add_camera_options(CLI::App& app, CameraOptions& o) {
    auto* eye = app.add_option("--eye", o.eye, "Camera position x,y,z");
    auto* target = app.add_option("--target", o.target, "Point the camera looks at x,y,z");
    auto* up = app.add_option("--up", o.up, "Up direction x,y,z")->capture_default_str();
    auto* fov = app.add_option("--fov-y", o.fov_y, "Vertical field of view, degrees")->capture_default_str();
    auto* near_opt = app.add_option("--near", o.near_plane, "Near plane distance (view depth)")->capture_default_str();
    auto* far_opt = app.add_option("--far", o.far_plane, "Far plane distance (view depth)")->capture_default_str();
    auto* path = app.add_option("--path", o.path, "Camera path file (JSON, see README); use with --frame");
    auto* frame = app.add_option("--frame", o.frame, "Frame of --path to use (from 0)")->capture_default_str();
    frame->needs(path);
    for (auto* single : {eye, target, up, fov, near_opt, far_opt}) single->excludes(path);
}

Camera resolve_camera(const CameraOptions& o) {
    if (!o.path.empty()) {
        const CameraPath path = read_camera_path(o.path);
        if (o.frame < 0 || std::size_t(o.frame) >= path.frames.size())
            throw Error(o.path + ": frame " + std::to_string(o.frame) + " out of range (the path has " +
                        std::to_string(path.frames.size()) + " frames)");
        return path.frames[std::size_t(o.frame)];
    }
    if (o.eye.empty() || o.target.empty())
        throw Error("no camera: give --eye and --target (and optionally --up, --fov-y, --near, --far), or --path");
    Camera c;
    c.eye = parse_vec3(o.eye, "--eye");
    c.target = parse_vec3(o.target, "--target");
    c.up = parse_vec3(o.up, "--up");
    c.fov_y_degrees = o.fov_y;
    c.near_plane = o.near_plane;
    c.far_plane = o.far_plane;
    validate_camera(c);
    return c;
}

glm::dvec3 parse_vec3(const std::string& text, const char* what) {
    glm::dvec3 v;
    const char* p = text.c_str();
    for (int k = 0; k < 3; ++k) {
        char* end = nullptr;
        v[k] = std::strtod(p, &end);
        const char expected = k < 2 ? ',' : '\0';
        if (end == p || *end != expected || !std::isfinite(v[k]))
            throw Error(std::string(what) + ": expected three numbers x,y,z, got '" + text + "'");
        p = end + 1;
    }
    return v;
}

nlohmann::json camera_json(const Camera& c) {
    return {{"eye", {c.eye.x, c.eye.y, c.eye.z}},
            {"target", {c.target.x, c.target.y, c.target.z}},
            {"up", {c.up.x, c.up.y, c.up.z}},
            {"fov_y", c.fov_y_degrees},
            {"near", c.near_plane},
            {"far", c.far_plane}};
}

nlohmann::json stats_json(const RasterStats& s) {
    return {{"triangles_in", s.triangles_in}, {"invalid", s.invalid},   {"outside", s.outside},
            {"near_clipped", s.near_clipped}, {"too_large", s.too_large}, {"backface_culled", s.backface_culled},
            {"degenerate", s.degenerate},     {"rasterized", s.rasterized}, {"subtiles_updated", s.subtiles_updated},
            {"clusters_outside", s.clusters_outside}, {"cluster_bands_hidden", s.cluster_bands_hidden},
            {"cluster_bands_drawn", s.cluster_bands_drawn}};
}

Resolution parse_resolution(const std::string& text, const std::string& option) {
    const std::string expected = option + ": expected WxH between 1x1 and 65536x65536, such as 1920x1080, got '" + text + "'";
    char* end = nullptr;
    const long w = std::strtol(text.c_str(), &end, 10);
    if (end == text.c_str() || (*end != 'x' && *end != 'X' && *end != ',')) throw Error(expected);
    const char* rest = end + 1;
    const long h = std::strtol(rest, &end, 10);
    if (end == rest || *end != '\0') throw Error(expected);
    const auto to_int = [](long v) { return int(std::max(-1L, std::min(v, 1L << 30))); };  // out of range either way
    const Resolution r{to_int(w), to_int(h)};
    try {
        validate_resolution(r);  // the one definition of a valid size
    } catch (const Error&) {
        throw Error(expected);
    }
    return r;
}

long long now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double elapsed_ms(long long start_ns) { return double(now_ns() - start_ns) * 1e-6; }

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

ParallelFor command_job_system(int threads) {
    if (threads <= 1) return {};
    const ParallelFor parallel = tbb_parallel_for();
    parallel.run(parallel.user, 64, [](void*, std::size_t) {}, nullptr);
    return parallel;
}

}  // namespace homcull::cli
