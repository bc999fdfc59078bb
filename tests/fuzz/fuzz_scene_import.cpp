// libFuzzer target: scene import (glTF, GLB, OBJ) from arbitrary bytes. The first byte picks the
// format; the rest is the file. Any input must load or fail with homcull::Error, never crash,
// leak, hang or throw anything else; a loaded scene must have finite or infinite bounds, its
// indices in range (Scene::finalize checks), and survive a save and reload.
#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

namespace {

std::string temp_path(const char* extension) {
    return "/tmp/homcull_fuzz_scene_" + std::to_string(::getpid()) + extension;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1 || size > (1u << 20)) return 0;
    static const char* const kExtensions[] = {".glb", ".gltf", ".obj"};
    const std::string path = temp_path(kExtensions[data[0] % 3]);
    {
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
    }
    try {
        const homcull::Scene scene = homcull::load_scene(path);
        for (const homcull::Object& o : scene.objects)
            if (o.mesh >= scene.meshes.size()) __builtin_trap();
        for (const homcull::Mesh& m : scene.meshes)
            for (std::uint32_t i : m.indices)
                if (i >= m.positions.size()) __builtin_trap();
        if (!scene.objects.empty()) {
            const std::string again = temp_path("_again.glb");
            try {
                homcull::save_glb(scene, again);
                const homcull::Scene reloaded = homcull::load_scene(again);
                if (reloaded.objects.size() != scene.objects.size()) __builtin_trap();
            } catch (const homcull::Error&) {
                // save_glb refuses what glTF cannot hold (an empty mesh): a clear error is fine
            }
            std::remove(again.c_str());
        }
    } catch (const homcull::Error&) {
    }
    std::remove(path.c_str());
    return 0;
}
