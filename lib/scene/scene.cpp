#include <homcull/error.hpp>
#include <homcull/scene.hpp>

#include "common/float_round.hpp"  // float_down, float_up
#include "scene/world_point.hpp"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace homcull {

const std::string* Object::extra(std::string_view key) const {
    for (const auto& [k, v] : extras)
        if (k == key) return &v;
    return nullptr;
}

std::size_t Scene::unique_triangle_count() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.triangle_count();
    return n;
}

std::size_t Scene::instanced_triangle_count() const {
    std::size_t n = 0;
    for (const auto& o : objects) n += triangle_count(o);
    return n;
}

Aabb Scene::bounds() const {
    Aabb b;
    for (const auto& o : objects) b.extend(o.world_bounds);
    return b;
}

glm::vec3 transform_point(const glm::dmat4& world, const glm::vec3& p) { return detail::world_point(world, p); }

Scene translated_scene(const Scene& scene, const glm::dvec3& offset) {
    Scene moved = scene;
    glm::dmat4 translation(1.0);
    translation[3] = glm::dvec4(offset, 1.0);
    for (Object& object : moved.objects) object.world = translation * object.world;
    moved.finalize();
    return moved;
}

glm::dvec3 scene_anchor(const Scene& scene) {
    const Aabb b = scene.bounds();
    if (b.empty()) return glm::dvec3(0.0);
    const glm::dvec3 centre = (glm::dvec3(b.min) + glm::dvec3(b.max)) * 0.5;
    if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z)) return glm::dvec3(0.0);
    return centre;
}

glm::vec3 transform_point_from(const glm::dmat4& world, const glm::vec3& p, const glm::dvec3& anchor) {
    return detail::world_point_from(world, p, anchor);
}

Aabb anchored_box(const Aabb& world_box, const glm::dvec3& anchor) {
    if (world_box.empty()) return world_box;
    // World boxes hold transform_point's floats, each within 2^-24 of its exact world position:
    // widened by 2^-23 of each bound (and the subtraction's 2^-53), the double bounds hold every
    // exact position, and float rounding is monotone, so the rounded anchored vertices of
    // transform_point_from lie within their float_down / float_up.
    Aabb b;
    for (int k = 0; k < 3; ++k) {
        const double lo = double(world_box.min[k]), hi = double(world_box.max[k]);
        b.min[k] = detail::float_down((lo - 0x1.0p-23 * std::abs(lo)) - anchor[k] - 0x1.0p-50 * (std::abs(lo) + std::abs(anchor[k])));
        b.max[k] = detail::float_up((hi + 0x1.0p-23 * std::abs(hi)) - anchor[k] + 0x1.0p-50 * (std::abs(hi) + std::abs(anchor[k])));
    }
    return b;
}

namespace {

// `text` with every byte that does not start or continue a valid UTF-8 sequence replaced by
// U+FFFD: names reach glTF and JSON, which hold only UTF-8 (an OBJ group name may be any bytes).
std::string valid_utf8(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    const auto* b = reinterpret_cast<const unsigned char*>(text.data());
    const std::size_t n = text.size();
    for (std::size_t i = 0; i < n;) {
        const unsigned char c = b[i];
        std::size_t length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        bool ok = length > 0 && i + length <= n;
        for (std::size_t k = 1; ok && k < length; ++k) ok = (b[i + k] & 0xC0) == 0x80;
        if (ok && length > 1) {  // no overlong forms, surrogates or code points past U+10FFFF
            std::uint32_t cp = c & (0xFFu >> (length + 1));
            for (std::size_t k = 1; k < length; ++k) cp = (cp << 6) | (b[i + k] & 0x3Fu);
            const std::uint32_t least[5] = {0, 0, 0x80, 0x800, 0x10000};
            ok = cp >= least[length] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF);
        }
        if (ok) {
            out.append(text, i, length);
            i += length;
        } else {
            out += "\xEF\xBF\xBD";
            ++i;
        }
    }
    return out;
}

}  // namespace

void Scene::finalize() {
    for (Mesh& mesh : meshes) mesh.name = valid_utf8(mesh.name);
    for (Object& object : objects) {
        object.name = valid_utf8(object.name);
        for (auto& [key, value] : object.extras) key = valid_utf8(key), value = valid_utf8(value);
    }
    // Each mesh's vertices in the order its indices first name them, each once. An object's
    // bounds from those are its bounds from every index (glm::min and glm::max keep the first
    // of equal values, -0 and +0 alike, and never take a NaN), for a fraction of the transforms
    // of a scene that places its meshes many times.
    std::vector<std::vector<std::uint32_t>> named_vertices(meshes.size());
    std::vector<std::uint8_t> named;
    for (std::size_t m = 0; m < meshes.size(); ++m) {
        const Mesh& mesh = meshes[m];
        if (mesh.indices.size() % 3 != 0)
            throw Error(source + ": mesh " + std::to_string(m) + " ('" + mesh.name +
                        "') has " + std::to_string(mesh.indices.size()) +
                        " indices, not a multiple of 3");
        named.assign(mesh.positions.size(), 0);
        for (std::uint32_t index : mesh.indices) {
            if (index >= mesh.positions.size())
                throw Error(source + ": mesh " + std::to_string(m) + " ('" + mesh.name +
                            "') uses vertex " + std::to_string(index) + " but has only " +
                            std::to_string(mesh.positions.size()) + " vertices");
            if (!named[index]) named[index] = 1, named_vertices[m].push_back(index);
        }
    }
    for (std::size_t i = 0; i < objects.size(); ++i) {
        Object& object = objects[i];
        if (object.mesh >= meshes.size())
            throw Error(source + ": object " + std::to_string(i) + " ('" + object.name +
                        "') names mesh " + std::to_string(object.mesh) + " but there are " +
                        std::to_string(meshes.size()));
        object.world_bounds = Aabb{};
        for (std::uint32_t index : named_vertices[object.mesh])
            object.world_bounds.extend(detail::world_point(object.world, meshes[object.mesh].positions[index]));
    }
}

}  // namespace homcull
