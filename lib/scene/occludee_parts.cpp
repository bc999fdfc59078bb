// Occludee parts (occludee_parts.hpp): median splits of each mesh's triangle centres, then
// each object's part boxes under its transform.
#include "scene/occludee_parts.hpp"

#include "common/run_tasks.hpp"
#include "scene/world_point.hpp"

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
// most, the parts shared between the halves. `keyed` (as long as `order`): room for the keys,
// selected in place (the triangles' centres read once per level, not at every comparison).
void split(std::vector<std::uint32_t>& order, const std::vector<glm::vec3>& centres, std::size_t begin, std::size_t end, int parts,
           std::vector<std::uint32_t>& part_begin, std::vector<SplitKey>& keyed) {
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
    for (std::size_t i = begin; i < end; ++i) {
        const float c = centres[order[i]][axis];
        keyed[i] = SplitKey{std::isfinite(c) ? c : INFINITY, order[i]};
    }
    const std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(keyed.begin() + std::ptrdiff_t(begin), keyed.begin() + std::ptrdiff_t(middle), keyed.begin() + std::ptrdiff_t(end));
    for (std::size_t i = begin; i < end; ++i) order[i] = keyed[i].second;
    split(order, centres, begin, middle, parts / 2, part_begin, keyed);
    split(order, centres, middle, end, parts - parts / 2, part_begin, keyed);
}

}  // namespace

void OccludeeParts::build(const Scene& scene, int max_parts, std::size_t triangle_limit, const glm::dvec3& anchor,
                          const ParallelFor& parallel) {
    object_first_.assign(scene.objects.size() + 1, 0);
    mesh_indices_.clear(), mesh_first_index_.clear(), mesh_first_part_.assign(1, 0), mesh_part_begin_.clear();
    boxes_.clear(), part_first_triangle_.clear(), part_triangle_count_.clear();
    if (max_parts < 2) return;

    // Each mesh's split in a task of its own, then the meshes' in their order.
    struct MeshSplit {
        std::vector<std::uint32_t> indices, part_begin;
        // Each part's vertices, once each: part p's are vertices[vertex_begin[p], vertex_begin[p + 1]).
        std::vector<std::uint32_t> vertices, vertex_begin;
    };
    std::vector<MeshSplit> splits(scene.meshes.size());
    for_each_index(parallel, scene.meshes.size(), 4, [&](std::size_t m) {
        const Mesh& mesh = scene.meshes[m];
        const std::size_t n = mesh.triangle_count();
        MeshSplit& out = splits[m];
        if (n >= 2 && n <= triangle_limit) {
            std::vector<glm::vec3> centres(n);
            for (std::size_t t = 0; t < n; ++t)
                centres[t] = (mesh.positions[mesh.indices[3 * t]] + mesh.positions[mesh.indices[3 * t + 1]] +
                              mesh.positions[mesh.indices[3 * t + 2]]) / 3.0f;
            std::vector<std::uint32_t> order(n);
            std::iota(order.begin(), order.end(), 0u);
            std::vector<SplitKey> keyed(n);
            split(order, centres, 0, n, max_parts, out.part_begin, keyed);
            out.indices.resize(3 * n);
            std::uint32_t* indices = out.indices.data();
            for (std::uint32_t t : order) indices = std::copy_n(mesh.indices.begin() + 3 * std::ptrdiff_t(t), 3, indices);
            std::vector<std::uint32_t> last_part(mesh.positions.size(), ~0u);
            out.vertex_begin.push_back(0);
            for (std::uint32_t p = 0; p < out.part_begin.size(); ++p) {
                const std::uint32_t end = p + 1 < out.part_begin.size() ? out.part_begin[p + 1] : std::uint32_t(n);
                for (std::size_t i = 3 * std::size_t(out.part_begin[p]); i < 3 * std::size_t(end); ++i)
                    if (last_part[out.indices[i]] != p) last_part[out.indices[i]] = p, out.vertices.push_back(out.indices[i]);
                out.vertex_begin.push_back(std::uint32_t(out.vertices.size()));
            }
        }
        out.part_begin.push_back(std::uint32_t(n));  // after the parts' beginnings; alone: no parts
    });
    for (const MeshSplit& split : splits) {
        mesh_first_index_.push_back(mesh_indices_.size());
        mesh_indices_.insert(mesh_indices_.end(), split.indices.begin(), split.indices.end());
        mesh_part_begin_.insert(mesh_part_begin_.end(), split.part_begin.begin(), split.part_begin.end());
        mesh_first_part_.push_back(std::uint32_t(mesh_part_begin_.size()));
    }

    // Each object's part boxes in its own slots, objects in tasks; those with a vertex that is
    // not finite are then left out (a box would say nothing: the object keeps its own box alone).
    const auto mesh_parts = [&](std::uint32_t mesh) { return mesh_first_part_[mesh + 1] - mesh_first_part_[mesh] - 1; };
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const std::uint32_t parts = mesh_parts(scene.objects[id].mesh);
        object_first_[id + 1] = object_first_[id] + (parts < 2 ? 0 : parts);
    }
    boxes_.resize(object_first_.back()), part_first_triangle_.resize(object_first_.back()), part_triangle_count_.resize(object_first_.back());
    std::vector<std::uint8_t> finite(scene.objects.size(), 1);
    for_each_index(parallel, scene.objects.size(), 16, [&](std::size_t id) {
        const Object& object = scene.objects[id];
        const Mesh& mesh = scene.meshes[object.mesh];
        const std::uint32_t* part_begin = mesh_part_begin_.data() + mesh_first_part_[object.mesh];
        const std::uint32_t parts = object_first_[id + 1] - object_first_[id];
        if (parts == 0) return;
        // As Scene::finalize bounds the object: transform_point's floats, then anchored_box's
        // widening; a part's box from its vertices, each once.
        const MeshSplit& split = splits[object.mesh];
        for (std::uint32_t p = 0; p < parts; ++p) {
            Aabb box;
            for (std::uint32_t i = split.vertex_begin[p]; i < split.vertex_begin[p + 1]; ++i) {
                const glm::vec3 w = world_point(object.world, mesh.positions[split.vertices[i]]);
                if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) finite[id] = 0;
                box.extend(w);
            }
            boxes_[object_first_[id] + p] = anchored_box(box, anchor);
            part_first_triangle_[object_first_[id] + p] = part_begin[p];
            part_triangle_count_[object_first_[id] + p] = part_begin[p + 1] - part_begin[p];
        }
    });
    if (std::find(finite.begin(), finite.end(), 0) == finite.end()) return;
    std::uint32_t kept = 0;
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const std::uint32_t first = object_first_[id], count = object_first_[id + 1] - first;
        object_first_[id] = kept;
        if (!finite[id]) continue;
        for (std::uint32_t p = first; p < first + count; ++p, ++kept)
            boxes_[kept] = boxes_[p], part_first_triangle_[kept] = part_first_triangle_[p], part_triangle_count_[kept] = part_triangle_count_[p];
    }
    object_first_.back() = kept;
    boxes_.resize(kept), part_first_triangle_.resize(kept), part_triangle_count_.resize(kept);
}

}  // namespace homcull::detail
