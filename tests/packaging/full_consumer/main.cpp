// Generates a city, saves and reloads it, and casts ground-truth rays: every target linked.
#include <homcull/generate.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/truth/ground_truth.hpp>

#include <cstdio>

int main(int argc, char** argv) {
    const homcull::Scene city = homcull::generate_scene("city:blocks=2");
    const std::string file = argc > 1 ? argv[1] : "city.glb";
    homcull::save_glb(city, file);
    const homcull::Scene loaded = homcull::load_scene(file);
    homcull::Camera camera;
    camera.eye = {-60, 30, -60};
    camera.target = {0, 0, 0};
    const homcull::RayScene rays(loaded);
    homcull::TruthOptions options;
    options.resolution = {64, 36};
    const homcull::TruthResult truth = homcull::compute_ground_truth(rays, loaded, camera, options);
    std::size_t visible = 0;
    for (const auto& v : truth.objects) visible += v.visible_samples > 0;
    std::printf("consumer: %zu objects, %zu visible\n", loaded.objects.size(), visible);
    return visible > 0 ? 0 : 1;
}
