#include <homcull/error.hpp>
#include <homcull/scene_culler.hpp>

#include "core/rect_tests.hpp"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
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
    b.sample_depth = c.sample_depth && resolved_occludee_shape(c) == OccludeeShape::samples;
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
      maps_(buffer_, maps_config(config)) {
    if (resolved_occludee_shape(config) != OccludeeShape::samples) return;
    occludee_first_vertex_.assign(scene.objects.size(), kNotGathered);
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Object& object = scene.objects[id];
        if (scene.triangle_count(object) > config.triangle_test_limit) continue;
        occludee_first_vertex_[id] = occludee_positions_.size() / 3;
        append_world_positions(scene, object, occludee_positions_);
    }
}

OccludeeShape resolved_occludee_shape(const SceneCullerConfig& config) {
    if (config.occludees != OccludeeShape::automatic) return config.occludees;
    return config.maps.depth == DepthTest::masked ? OccludeeShape::samples : OccludeeShape::rectangles;
}

void SceneCuller::cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    validate_camera(camera);
    // The near plane is the camera's: rebuild the buffer only when it changes.
    if (buffer_.config().near_w != float(camera.near_plane)) {
        buffer_ = OcclusionBuffer(scene_buffer_config(config_, float(camera.near_plane)));
        maps_ = OcclusionMaps(buffer_, maps_config(config_));
    }
    const auto clip = clip_from_world(camera, config_.display.aspect());
    const glm::dmat4 clip_double = projection_matrix(camera, config_.display.aspect()) * view_matrix(camera);
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
    const OccludeeShape shape = resolved_occludee_shape(config_);
    for (std::size_t id = 0; id < scene_->objects.size(); ++id) {
        const Aabb& box = scene_->objects[id].world_bounds;
        if (box.empty()) {
            answers[id] = {Visibility::view_culled, 0.0f, 0};
            continue;
        }
        answers[id] = maps_.test_aabb(box, clip);
        ++exits_.count[answers[id].overlap_exit];
        const Object& object = scene_->objects[id];
        if (answers[id].visibility != Visibility::visible || scene_->triangle_count(object) > config_.triangle_test_limit) continue;
        if (shape == OccludeeShape::rectangles && triangle_rectangles_hidden(object, clip_double)) {
            answers[id].visibility = Visibility::occluded;
            answers[id].level_of_visibility = 0.0f;  // the holes its triangles tolerated are not estimated
        } else if (shape == OccludeeShape::samples && triangle_samples_hidden(id, clip, answers[id].level_of_visibility)) {
            answers[id].visibility = Visibility::occluded;
        }
    }
    timings_.test_ms = ms_since(start);
}

namespace {

// Whether a triangle given by its clip-space corners is hidden at every sample: its screen
// rectangle at its nearest w (w is affine on the triangle, so its nearest point is a corner)
// tested against the maps; when that rectangle is not hidden, the four halves-of-edges
// sub-triangles (clip space is linear on the triangle, so they tile it exactly) are tried, down
// to `depth` more levels. A corner before the near plane makes it visible. The rectangles
// share the object's hole budget (approximate mode).
bool triangle_hidden(const OcclusionMaps& maps, float near_w, const glm::dvec4 c[3], int depth, double& budget) {
    const detail::ClipBounds b = detail::clip_bounds(c, 3, double(near_w));
    if (!b.finite || b.behind > 0) return false;
    // Widened by 2^-20 of the magnitudes: world_bounds and ground truth round the world
    // transform to float, this does not.
    const double slack_x = 0x1.0p-20 * (1.0 + std::abs(b.min_x) + std::abs(b.max_x));
    const double slack_y = 0x1.0p-20 * (1.0 + std::abs(b.min_y) + std::abs(b.max_y));
    const ScreenRect r{detail::float_down(b.min_x - slack_x), detail::float_down(b.min_y - slack_y), detail::float_up(b.max_x + slack_x),
                       detail::float_up(b.max_y + slack_y), detail::float_down(b.min_w * (1.0 - 0x1.0p-20))};
    if (maps.test_rect_within(r, budget).visibility != Visibility::visible) return true;
    if (depth == 0) return false;
    const glm::dvec4 m01 = (c[0] + c[1]) * 0.5, m12 = (c[1] + c[2]) * 0.5, m20 = (c[2] + c[0]) * 0.5;
    const glm::dvec4 parts[4][3] = {{c[0], m01, m20}, {m01, c[1], m12}, {m20, m12, c[2]}, {m01, m12, m20}};
    for (const auto& part : parts)
        if (!triangle_hidden(maps, near_w, part, depth - 1, budget)) return false;
    return true;
}

}  // namespace

// Every triangle hidden (see triangle_hidden), corners transformed in double as ground truth
// transforms them.
bool SceneCuller::triangle_rectangles_hidden(const Object& object, const glm::dmat4& clip_from_world) const {
    const Mesh& mesh = scene_->meshes[object.mesh];
    const glm::dmat4 m = clip_from_world * object.world;
    double budget = maps_.hole_budget();  // approximate mode: L pixels of holes for the whole object
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        glm::dvec4 c[3];
        for (int k = 0; k < 3; ++k) c[k] = m * glm::dvec4(glm::dvec3(mesh.positions[mesh.indices[3 * t + std::size_t(k)]]), 1.0);
        if (!triangle_hidden(maps_, buffer_.config().near_w, c, 3, budget)) return false;
    }
    return true;
}

// The object's triangles sample by sample (OcclusionBuffer::test_triangles), tolerating the
// maps' hole budget in approximate mode; its level of visibility is then the share of its
// samples left visible.
bool SceneCuller::triangle_samples_hidden(std::size_t id, const std::array<float, 16>& clip_from_world, float& level_of_visibility) const {
    const std::size_t first = occludee_first_vertex_[id];
    if (first == kNotGathered) return false;
    const Mesh& mesh = scene_->meshes[scene_->objects[id].mesh];
    TriangleInput in;
    in.positions = occludee_positions_.data() + 3 * first;
    in.vertex_count = mesh.positions.size();
    in.indices = mesh.indices.data();
    in.triangle_count = mesh.triangle_count();
    in.model_to_clip = clip_from_world;
    in.backface = Backface::none;
    const OcclusionBuffer::TriangleTest r = buffer_.test_triangles(in, std::uint64_t(maps_.hole_budget()));
    if (r.visibility == Visibility::visible) return false;
    level_of_visibility = r.samples > 0 ? float(double(r.visible_samples) / double(r.samples)) : 0.0f;
    return true;
}

}  // namespace homcull
