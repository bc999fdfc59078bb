// Chooses how to read a scene from its name: a generator spec, glTF, or assimp.
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace homcull {
namespace {

// Finite model-space vertices can still land at infinity (a node matrix of 1e39, or a product
// of large scales): such an object's bounds are infinite, so it is never culled and never
// hides anything, but it is surely not what the file meant. Said once per scene, naming the
// first such object.
void warn_of_infinite_objects(const Scene& scene) {
    std::size_t count = 0, first = 0;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const Aabb& b = scene.objects[i].world_bounds;
        if (b.empty()) continue;
        const bool finite = std::isfinite(b.min.x) && std::isfinite(b.min.y) && std::isfinite(b.min.z) && std::isfinite(b.max.x) &&
                            std::isfinite(b.max.y) && std::isfinite(b.max.z);
        if (!finite && count++ == 0) first = i;
    }
    if (count > 0)
        std::fprintf(stderr,
                     "homcull: warning: %s: %zu object%s with vertices that become infinite in world space (first: object %zu, '%s'); "
                     "they are never culled and hide nothing\n",
                     scene.source.c_str(), count, count == 1 ? "" : "s", first, scene.objects[first].name.c_str());
}

Scene load_file(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    for (char& c : extension) c = char(std::tolower((unsigned char)c));
    if (extension == ".glb" || extension == ".gltf") return load_gltf(path);
    return load_with_assimp(path);
}

}  // namespace

Scene load_scene(const std::string& path_or_spec) {
    if (path_or_spec.rfind("gen:", 0) == 0) return generate_scene(path_or_spec.substr(4));
    Scene scene = load_file(path_or_spec);
    warn_of_infinite_objects(scene);
    return scene;
}

}  // namespace homcull
