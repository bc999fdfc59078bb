// Generates a city, saves and reloads it, casts ground-truth rays and writes them as an id
// image: every target linked, and the installed image module (homcull_oiio.so) found.
#include <homcull/generate.hpp>
#include <homcull/io/id_image.hpp>
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
    options.keep_sample_ids = true;
    const homcull::TruthResult truth = homcull::compute_ground_truth(rays, loaded, camera, options);
    // The image module is loaded here, from the prefix the package was installed to.
    homcull::write_id_image(file + ".ids.png", truth.sample_width, truth.sample_height, truth.sample_ids);
    std::size_t visible = 0;
    for (const auto& v : truth.objects) visible += v.visible_samples > 0;
    std::printf("consumer: %zu objects, %zu visible\n", loaded.objects.size(), visible);
    return visible > 0 ? 0 : 1;
}
