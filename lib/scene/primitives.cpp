#include "scene/primitives.hpp"

namespace homcull::detail {
namespace {

void add_quad(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
}

}  // namespace

Mesh make_box_mesh() {
    Mesh m;
    m.name = "box";
    for (int k = 0; k < 8; ++k)
        m.positions.emplace_back((k & 1) ? 0.5f : -0.5f, (k & 2) ? 1.0f : 0.0f,
                                 (k & 4) ? 0.5f : -0.5f);
    // Vertex k has x = bit 0, y = bit 1, z = bit 2. Each face CCW seen from outside.
    add_quad(m, 0, 4, 6, 2);  // -x
    add_quad(m, 1, 3, 7, 5);  // +x
    add_quad(m, 0, 1, 5, 4);  // -y
    add_quad(m, 2, 6, 7, 3);  // +y
    add_quad(m, 0, 2, 3, 1);  // -z
    add_quad(m, 4, 5, 7, 6);  // +z
    return m;
}

Mesh make_ground_mesh() {
    Mesh m;
    m.name = "ground";
    m.positions = {{-0.5f, 0.0f, -0.5f}, {0.5f, 0.0f, -0.5f}, {0.5f, 0.0f, 0.5f}, {-0.5f, 0.0f, 0.5f}};
    add_quad(m, 0, 3, 2, 1);  // CCW seen from above
    return m;
}

Mesh make_tree_mesh() {
    Mesh m;
    m.name = "tree";
    // cos and sin of k * 60 degrees, written out so that no libm call enters the scene.
    const float s = 0.8660254037844386f;
    const float ring[6][2] = {{1, 0}, {0.5f, s}, {-0.5f, s}, {-1, 0}, {-0.5f, -s}, {0.5f, -s}};
    const float trunk_radius = 0.25f, trunk_height = 3.2f;
    for (int level = 0; level < 2; ++level)
        for (const auto& r : ring)
            m.positions.emplace_back(trunk_radius * r[0], level * trunk_height, -trunk_radius * r[1]);
    for (std::uint32_t k = 0; k < 6; ++k) {
        const std::uint32_t n = (k + 1) % 6;
        add_quad(m, k, n, 6 + n, 6 + k);  // side, CCW from outside (ring runs CCW seen from above)
    }
    for (std::uint32_t k = 1; k + 1 < 6; ++k) {
        m.indices.insert(m.indices.end(), {0, k + 1, k});                // bottom, facing down
        m.indices.insert(m.indices.end(), {6, 6 + k, 6 + k + 1});        // top, facing up
    }
    // Crown: octahedron.
    const float cy = 5.0f, cr = float(kTreeCrownRadius), ch = 2.5f;
    const std::uint32_t base = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {{cr, cy, 0}, {0, cy, -cr}, {-cr, cy, 0}, {0, cy, cr},
                                           {0, cy + ch, 0}, {0, cy - ch, 0}});
    for (std::uint32_t k = 0; k < 4; ++k) {
        const std::uint32_t a = base + k, b = base + (k + 1) % 4;
        m.indices.insert(m.indices.end(), {a, b, base + 4});  // upper half
        m.indices.insert(m.indices.end(), {b, a, base + 5});  // lower half
    }
    return m;
}

glm::dmat4 place(const glm::dvec3& position, const glm::dvec3& scale) {
    glm::dmat4 m(1.0);
    m[0][0] = scale.x;
    m[1][1] = scale.y;
    m[2][2] = scale.z;
    m[3] = glm::dvec4(position, 1.0);
    return m;
}

void add_object(Scene& scene, std::string name, std::uint32_t mesh, const glm::dmat4& world, const char* set,
                const char* role) {
    Object object;
    object.name = std::move(name);
    object.mesh = mesh;
    object.world = world;
    object.extras = {{"role", role}, {"set", set}};  // sorted, as glTF export writes them
    scene.objects.push_back(std::move(object));
}

}  // namespace homcull::detail
