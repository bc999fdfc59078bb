#include <homcull/error.hpp>
#include <homcull/truth/answer_overlay.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <cmath>

namespace homcull {
namespace {

constexpr std::uint32_t kBlue = 0x3C6EDC, kGrey = 0xC8C8C8, kMagenta = 0xFF00FF, kOrange = 0xFF8C00, kSlate = 0x46465A,
                        kYellow = 0xFFE000;

void put(std::vector<std::uint8_t>& rgb, int w, int h, int x, int y, std::uint32_t colour) {
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    const std::size_t i = 3 * (std::size_t(y) * std::size_t(w) + std::size_t(x));
    rgb[i] = std::uint8_t(colour >> 16);
    rgb[i + 1] = std::uint8_t((colour >> 8) & 0xFF);
    rgb[i + 2] = std::uint8_t(colour & 0xFF);
}

// Pixel i (row-major) as `colour` times `light`, each channel rounded.
void put_shaded(std::vector<std::uint8_t>& rgb, std::size_t i, std::uint32_t colour, float light) {
    for (int c = 0; c < 3; ++c) rgb[3 * i + std::size_t(c)] = std::uint8_t(std::lround(float((colour >> (16 - 8 * c)) & 0xFF) * light));
}

// Outlines: the neighbour to the right or below shows another object.
bool on_outline(const std::vector<std::uint32_t>& ids, int w, int h, int x, int y) {
    const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
    return (x + 1 < w && ids[i + 1] != ids[i]) || (y + 1 < h && ids[i + std::size_t(w)] != ids[i]);
}

// The objects' ids given to colour, checked against the scene's object count.
void check_ids(const std::vector<std::uint32_t>& ids, std::size_t objects, const char* what) {
    for (std::uint32_t id : ids)
        if (id >= objects) throw Error(std::string(what) + " " + std::to_string(id) + " is not an object");
}

// A straight line of pixels (DDA), clipped to the image.
void line(std::vector<std::uint8_t>& rgb, int w, int h, double x0, double y0, double x1, double y1, std::uint32_t colour) {
    const int steps = int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0))));
    for (int k = 0; k <= std::min(steps, 100000); ++k) {
        const double t = steps ? double(k) / steps : 0.0;
        put(rgb, w, h, int(std::lround(x0 + t * (x1 - x0))), int(std::lround(y0 + t * (y1 - y0))), colour);
    }
}

}  // namespace

AnswerOverlay render_answer_overlay(const RayScene& rays, const Camera& camera, Resolution resolution,
                                    const std::vector<OccludeeAnswer>& answers, const std::vector<std::uint32_t>& drawn) {
    validate_camera(camera);
    validate_resolution(resolution);
    if (answers.size() != rays.object_count()) throw Error("answer overlay: the answers are not for this scene");
    check_ids(drawn, answers.size(), "answer overlay: drawn occluder");
    std::vector<std::uint8_t> is_drawn(answers.size(), 0);
    for (std::uint32_t id : drawn) is_drawn[id] = 1;
    const int w = resolution.width, h = resolution.height;
    const double aspect = resolution.aspect();
    const CameraBasis basis = camera_basis(camera);
    std::vector<std::uint32_t> ids(std::size_t(w) * std::size_t(h), kNoObject);
    std::vector<float> shade(ids.size(), 0.0f);
    // The same rays as ground truth: pixel centres, t from the near to the far plane.
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const glm::dvec2 ndc = pixel_to_ndc(resolution, x + 0.5, y + 0.5);
                const glm::vec3 d(ray_direction(camera, basis, aspect, ndc));
                const RayHit hit = rays.intersect(ray_origin(camera, basis, aspect, ndc), d, float(camera.near_plane), float(camera.far_plane));
                const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                ids[i] = hit.object;
                const float n = glm::length(hit.normal) * glm::length(d);
                if (hit.hit() && n > 0.0f) shade[i] = std::abs(glm::dot(hit.normal, d)) / n;
            }
    });

    AnswerOverlay out;
    out.width = w;
    out.height = h;
    out.rgb.assign(ids.size() * 3, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const std::uint32_t id = ids[i];
            if (id == kNoObject) continue;
            const bool culled = answers[id].visibility != Visibility::visible;
            const std::uint32_t colour = culled ? kMagenta : is_drawn[id] ? kBlue : kGrey;
            float light = culled ? 1.0f : 0.35f + 0.65f * shade[i];
            if (!culled && on_outline(ids, w, h, x, y)) light *= 0.6f;
            put_shaded(out.rgb, i, colour, light);
            if (culled) {
                ++out.false_cull_pixels;
                out.false_culls.push_back(id);
            }
        }
    std::sort(out.false_culls.begin(), out.false_culls.end());
    out.false_culls.erase(std::unique(out.false_culls.begin(), out.false_culls.end()), out.false_culls.end());
    return out;
}

AnswerOverlay render_answer_map(const RayScene& rays, const Aabb& bounds, const Camera& camera, Resolution display,
                                const std::vector<OccludeeAnswer>& answers, const std::vector<std::uint32_t>& drawn,
                                const std::vector<std::uint32_t>& false_culls, int width) {
    validate_camera(camera);
    validate_resolution(display);
    if (answers.size() != rays.object_count()) throw Error("answer map: the answers are not for this scene");
    if (bounds.empty() || width < 16 || width > 8192) throw Error("answer map: an empty scene or a width outside 16 .. 8192");
    check_ids(drawn, answers.size(), "answer map: drawn occluder");
    check_ids(false_culls, answers.size(), "answer map: falsely culled object");
    std::vector<std::uint32_t> colour_of(answers.size());
    for (std::size_t id = 0; id < answers.size(); ++id)
        colour_of[id] = answers[id].visibility == Visibility::visible ? kGrey
                        : answers[id].visibility == Visibility::occluded ? kOrange : kSlate;
    for (std::uint32_t id : drawn) colour_of[id] = kBlue;
    for (std::uint32_t id : false_culls) colour_of[id] = kMagenta;
    const double sx = std::max(double(bounds.extent().x), 1e-9), sz = std::max(double(bounds.extent().z), 1e-9);
    const double min_x = double(bounds.min.x), min_z = double(bounds.min.z);
    const int w = width, h = std::clamp(int(std::lround(width * sz / sx)), 16, 8192);
    AnswerOverlay out;
    out.width = w;
    out.height = h;
    out.rgb.assign(std::size_t(w) * std::size_t(h) * 3, 0);
    const float top = bounds.max.y + 1.0f + 0.01f * float(sx + sz);
    std::vector<std::uint32_t> ids(std::size_t(w) * std::size_t(h), kNoObject);
    std::vector<float> shade(ids.size(), 0.0f);
    // Image x grows with world x, image y with world z (north up is -z).
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const glm::vec3 from(float(min_x + (x + 0.5) * sx / w), top, float(min_z + (y + 0.5) * sz / h));
                const RayHit hit = rays.intersect(from, {0.0f, -1.0f, 0.0f}, 0.0f, std::numeric_limits<float>::infinity());
                const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                ids[i] = hit.object;
                const float n = glm::length(hit.normal);
                if (hit.hit() && n > 0.0f) shade[i] = std::abs(hit.normal.y) / n;
            }
    });
    // Outlines between objects, so that neighbours of one colour (a roof on the ground) read apart.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            if (ids[i] == kNoObject) continue;
            const float light = (0.45f + 0.55f * shade[i]) * (on_outline(ids, w, h, x, y) ? 0.6f : 1.0f);
            put_shaded(out.rgb, i, colour_of[ids[i]], light);
        }
    // The frustum's horizontal edges from the eye, to the far plane or the map's edge.
    const glm::dvec3 forward = camera.target - camera.eye;
    const double heading = std::atan2(forward.z, forward.x);
    const double half = std::atan(std::tan(glm::radians(camera.fov_y_degrees) / 2.0) * display.aspect());
    const double reach = std::min(camera.far_plane, 2.0 * (sx + sz));
    const auto to_image = [&](double wx, double wz) { return glm::dvec2((wx - min_x) / sx * w, (wz - min_z) / sz * h); };
    const glm::dvec2 eye = to_image(camera.eye.x, camera.eye.z);
    for (const double a : {heading - half, heading + half}) {
        const glm::dvec2 end = to_image(camera.eye.x + reach * std::cos(a), camera.eye.z + reach * std::sin(a));
        line(out.rgb, w, h, eye.x, eye.y, end.x, end.y, kYellow);
    }
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) put(out.rgb, w, h, int(eye.x) + dx, int(eye.y) + dy, kYellow);
    out.false_culls = false_culls;
    return out;
}

}  // namespace homcull
