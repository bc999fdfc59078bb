// Chooses how to read a scene from its name: a generator spec, glTF, or assimp.
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>

#include <cctype>
#include <filesystem>

namespace homcull {

Scene load_scene(const std::string& path_or_spec) {
    if (path_or_spec.rfind("gen:", 0) == 0) return generate_scene(path_or_spec.substr(4));
    std::string extension = std::filesystem::path(path_or_spec).extension().string();
    for (char& c : extension) c = char(std::tolower((unsigned char)c));
    if (extension == ".glb" || extension == ".gltf") return load_gltf(path_or_spec);
    return load_with_assimp(path_or_spec);
}

}  // namespace homcull
