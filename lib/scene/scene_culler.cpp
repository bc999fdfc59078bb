#include <homcull/error.hpp>
#include <homcull/scene_culler.hpp>

#include <chrono>
#include <string>

namespace homcull {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

OcclusionMapsConfig maps_config(const SceneCullerConfig& c) {
    OcclusionMapsConfig m = c.maps;
    m.display_width = c.display.width;
    m.display_height = c.display.height;
    return m;
}

}  // namespace

BufferConfig scene_buffer_config(const SceneCullerConfig& c, float near_w) {
    validate_resolution(c.display);
    if (c.samples != 1 && c.samples != 2 && c.samples != 4) throw Error("samples per buffer pixel axis must be 1, 2 or 4");
    BufferConfig b;
    b.samples = c.samples;
    b.near_w = near_w;
    if (c.buffer.width == 0 && c.buffer.height == 0) {
        if (c.display.width % c.samples != 0 || c.display.height % c.samples != 0)
            throw Error("the display resolution " + std::to_string(c.display.width) + "x" + std::to_string(c.display.height) +
                        " is not a multiple of the samples per axis (" + std::to_string(c.samples) + "): give --buffer");
        b.width = c.display.width / c.samples;
        b.height = c.display.height / c.samples;
    } else {
        validate_resolution(c.buffer);
        b.width = c.buffer.width;
        b.height = c.buffer.height;
    }
    const bool same_grid = b.width * c.samples == c.display.width && b.height * c.samples == c.display.height;
    if (c.maps.hole_pixels == 0.0 && !same_grid)
        throw Error("conservative culling needs the buffer's samples on the display's pixel centres: buffer x samples (" +
                    std::to_string(b.width * c.samples) + "x" + std::to_string(b.height * c.samples) + ") must equal the display (" +
                    std::to_string(c.display.width) + "x" + std::to_string(c.display.height) +
                    "); use a matching buffer or approximate mode");
    return b;
}

SceneCuller::SceneCuller(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config)
    : scene_(&scene),
      config_(config),
      occluder_ids_(occluders),
      occluders_(gather_world_triangles(scene, occluders)),
      buffer_(scene_buffer_config(config, 0.1f)),
      maps_(buffer_, maps_config(config)) {}

void SceneCuller::cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    validate_camera(camera);
    // The near plane is the camera's: rebuild the buffer only when it changes.
    if (buffer_.config().near_w != float(camera.near_plane)) {
        buffer_ = OcclusionBuffer(scene_buffer_config(config_, float(camera.near_plane)));
        maps_ = OcclusionMaps(buffer_, maps_config(config_));
    }
    const auto clip = clip_from_world(camera, config_.display.aspect());
    auto start = std::chrono::steady_clock::now();
    buffer_.clear();
    buffer_.render(occluders_.input(clip, config_.backface), parallel);
    timings_.render_ms = ms_since(start);

    start = std::chrono::steady_clock::now();
    maps_.clear();
    if (config_.maps.depth == DepthTest::deb)
        for (std::uint32_t id : occluder_ids_) maps_.add_occluder_box(scene_->objects[id].world_bounds, clip);
    maps_.build(buffer_);
    timings_.maps_ms = ms_since(start);

    start = std::chrono::steady_clock::now();
    answers.resize(scene_->objects.size());
    exits_ = {};
    for (std::size_t id = 0; id < scene_->objects.size(); ++id) {
        const Aabb& box = scene_->objects[id].world_bounds;
        if (box.empty()) {
            answers[id] = {Visibility::view_culled, 0.0f, 0};
            continue;
        }
        answers[id] = maps_.test_aabb(buffer_, box, clip);
        ++exits_.count[answers[id].overlap_exit];
    }
    timings_.test_ms = ms_since(start);
}

}  // namespace homcull
