// Occludee parts (occludee_parts.hpp): median splits of each mesh's triangle centres, then
// each object's part boxes under its transform.
#include "scene/occludee_parts.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

namespace homcull::detail {
namespace {

// The key a triangle is split by: its centre on one axis, +inf when not finite (so that the
// order stays strict and weak; such an object gets no parts anyway), then its number.
using SplitKey = std::pair<float, std::uint32_t>;

// Splits triangles [begin, end) of `order` into `parts` groups, appending each group's first
// position to `part_begin`: halves at the median centre on the axis where the centres spread
// most, the parts shared between the halves.
void split(std::vector<std::uint32_t>& order, const std::vector<glm::vec3>& centres, std::size_t begin, std::size_t end, int parts,
           std::vector<std::uint32_t>& part_begin) {
    if (parts < 2 || end - begin < 2) {
        part_begin.push_back(std::uint32_t(begin));
        return;
    }
    Aabb spread;
    for (std::size_t i = begin; i < end; ++i)
        if (std::isfinite(centres[order[i]].x + centres[order[i]].y + centres[order[i]].z)) spread.extend(centres[order[i]]);
    int axis = 0;
    if (!spread.empty()) {
        const glm::vec3 size = spread.max - spread.min;
        axis = size.y > size[axis] ? 1 : 0;
        axis = size.z > size[axis] ? 2 : axis;
    }
    const auto key = [&](std::uint32_t t) {
        const float c = centres[t][axis];
        return SplitKey{std::isfinite(c) ? c : INFINITY, t};
    };
    const std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(middle), order.begin() + std::ptrdiff_t(end),
                     [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    split(order, centres, begin, middle, parts / 2, part_begin);
    split(order, centres, middle, end, parts - parts / 2, part_begin);
}

}  // namespace

void OccludeeParts::build(const Scene& scene, int max_parts, std::size_t triangle_limit, const glm::dvec3& anchor) {
    object_first_.assign(scene.objects.size() + 1, 0);
    mesh_indices_.clear(), mesh_first_index_.clear(), mesh_first_part_.assign(1, 0), mesh_part_begin_.clear();
    boxes_.clear(), part_first_triangle_.clear(), part_triangle_count_.clear();
    if (max_parts < 2) return;

    std::vector<glm::vec3> centres;
    std::vector<std::uint32_t> order;
    for (const Mesh& mesh : scene.meshes) {
        mesh_first_index_.push_back(mesh_indices_.size());
        const std::size_t n = mesh.triangle_count();
        if (n >= 2 && n <= triangle_limit) {
            centres.resize(n);
            for (std::size_t t = 0; t < n; ++t)
                centres[t] = (mesh.positions[mesh.indices[3 * t]] + mesh.positions[mesh.indices[3 * t + 1]] +
                              mesh.positions[mesh.indices[3 * t + 2]]) / 3.0f;
            order.resize(n);
            std::iota(order.begin(), order.end(), 0u);
            split(order, centres, 0, n, max_parts, mesh_part_begin_);
            mesh_part_begin_.push_back(std::uint32_t(n));
            for (std::uint32_t t : order) mesh_indices_.insert(mesh_indices_.end(), mesh.indices.begin() + 3 * t, mesh.indices.begin() + 3 * t + 3);
        } else {
            mesh_part_begin_.push_back(std::uint32_t(n));  // no parts: a lone end
        }
        mesh_first_part_.push_back(std::uint32_t(mesh_part_begin_.size()));
    }

    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        object_first_[id + 1] = object_first_[id];
        const Object& object = scene.objects[id];
        const Mesh& mesh = scene.meshes[object.mesh];
        const std::uint32_t* part_begin = mesh_part_begin_.data() + mesh_first_part_[object.mesh];
        const std::uint32_t parts = mesh_first_part_[object.mesh + 1] - mesh_first_part_[object.mesh] - 1;
        if (parts < 2) continue;
        const std::uint32_t* indices = mesh_indices_.data() + mesh_first_index_[object.mesh];
        const std::size_t first_box = boxes_.size();
        bool finite = true;
        for (std::uint32_t p = 0; p < parts && finite; ++p) {
            // As Scene::finalize bounds the object: transform_point's floats, then anchored_box's widening.
            Aabb world;
            for (std::uint32_t i = 3 * part_begin[p]; i < 3 * part_begin[p + 1]; ++i) {
                const glm::vec3 w = transform_point(object.world, mesh.positions[indices[i]]);
                finite = finite && std::isfinite(w.x + w.y + w.z);
                world.extend(w);
            }
            boxes_.push_back(anchored_box(world, anchor));
            part_first_triangle_.push_back(part_begin[p]);
            part_triangle_count_.push_back(part_begin[p + 1] - part_begin[p]);
        }
        if (!finite) {  // a box would say nothing: the object keeps its own box alone
            boxes_.resize(first_box), part_first_triangle_.resize(first_box), part_triangle_count_.resize(first_box);
            continue;
        }
        object_first_[id + 1] = std::uint32_t(boxes_.size());
    }
}

}  // namespace homcull::detail
