// homcull info: what a scene holds, object by object.
#include "commands.hpp"
#include "options.hpp"

#include <homcull/io/scene_io.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <memory>

namespace homcull::cli {
namespace {

struct InfoOptions {
    SceneChoice scene;
    bool json = false;
};

nlohmann::json vec3_json(const glm::vec3& v) { return {v.x, v.y, v.z}; }

void run_info(const InfoOptions& o) {
    const long long start = now_ns();
    const Scene scene = load_chosen_scene(o.scene);
    const double load_ms = elapsed_ms(start);
    const Aabb bounds = scene.bounds();
    if (o.json) {
        nlohmann::json objects = nlohmann::json::array();
        for (std::size_t id = 0; id < scene.objects.size(); ++id) {
            const Object& object = scene.objects[id];
            nlohmann::json extras = nlohmann::json::object();
            for (const auto& [k, v] : object.extras) extras[k] = v;
            nlohmann::json entry = {{"id", id}, {"name", object.name}, {"triangles", scene.triangle_count(object)},
                                    {"mesh", object.mesh}, {"extras", extras}};
            entry["aabb"] = object.world_bounds.empty() ? nlohmann::json(nullptr)
                            : nlohmann::json{{"min", vec3_json(object.world_bounds.min)}, {"max", vec3_json(object.world_bounds.max)}};
            objects.push_back(std::move(entry));
        }
        nlohmann::json out = {{"scene", scene.source},
                              {"objects", objects},
                              {"summary", {{"objects", scene.objects.size()},
                                           {"meshes", scene.meshes.size()},
                                           {"unique_triangles", scene.unique_triangle_count()},
                                           {"instanced_triangles", scene.instanced_triangle_count()},
                                           {"load_ms", load_ms}}}};
        out["summary"]["aabb"] = bounds.empty() ? nlohmann::json(nullptr)
                                 : nlohmann::json{{"min", vec3_json(bounds.min)}, {"max", vec3_json(bounds.max)}};
        fmt::print("{}\n", out.dump(1));
        return;
    }
    fmt::print("scene      {}\n", scene.source);
    fmt::print("objects    {}\nmeshes     {}\ntriangles  {} placed, {} stored\n", scene.objects.size(), scene.meshes.size(),
               scene.instanced_triangle_count(), scene.unique_triangle_count());
    if (!bounds.empty())
        fmt::print("bounds     ({:.3f}, {:.3f}, {:.3f}) .. ({:.3f}, {:.3f}, {:.3f})\n", bounds.min.x, bounds.min.y,
                   bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z);
    fmt::print("loaded in  {:.1f} ms\n\n", load_ms);
    fmt::print("{:>6}  {:<40} {:>9} {:>6}  {:<52}  {}\n", "id", "name", "triangles", "mesh", "world aabb", "extras");
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Object& object = scene.objects[id];
        const Aabb& b = object.world_bounds;
        const std::string box = b.empty() ? "(empty)"
            : fmt::format("({:.2f},{:.2f},{:.2f})..({:.2f},{:.2f},{:.2f})", b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z);
        std::string extras;
        for (const auto& [k, v] : object.extras) extras += (extras.empty() ? "" : " ") + k + "=" + v;
        fmt::print("{:>6}  {:<40} {:>9} {:>6}  {:<52}  {}\n", id, object.name, scene.triangle_count(object), object.mesh, box, extras);
    }
}

}  // namespace

void register_info(CLI::App& app) {
    auto options = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info", "List a scene's objects: ids, names, triangle counts, AABBs, extras");
    add_scene_option(*cmd, options->scene);
    cmd->add_flag("--json", options->json, "Print JSON on stdout");
    cmd->callback([options] { run_info(*options); });
}

}  // namespace homcull::cli
