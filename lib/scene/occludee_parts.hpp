#pragma once
// Occludees as a few boxes each instead of one: each mesh's triangles are split, when the scene
// culler is made, into up to `max_parts` parts by their centres (median splits on the longest
// axis, as a bounding-volume hierarchy's top levels are built), and each object gets the box of
// every part under its transform. The boxes are far tighter than the object's own box for
// L-shaped, hollow or sprawling objects. An object is hidden when every part's box is; where a
// part's box is visible, only that part's triangles need a closer test. Every box holds its
// part's triangles as ground truth places them (widened as anchored_box widens object boxes),
// so a hidden box hides them all. Private to the scene layer.
#include <homcull/parallel_for.hpp>
#include <homcull/scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull::detail {

class OccludeeParts {
public:
    // Parts for the objects with at most triangle_limit triangles (the others get none); boxes
    // relative to `anchor`. max_parts below 2: no parts at all. Allocates (load time). With a job
    // system, the meshes' splits and the objects' boxes run in its tasks: the same parts.
    void build(const Scene& scene, int max_parts, std::size_t triangle_limit, const glm::dvec3& anchor, const ParallelFor& parallel = {});

    // The parts of object `id`: [first(id), first(id) + count(id)) index part_box and the
    // per-part triangle ranges; count is 0 for an object without parts.
    std::uint32_t first(std::size_t id) const { return object_first_[id]; }
    std::uint32_t count(std::size_t id) const { return object_first_[id + 1] - object_first_[id]; }
    const Aabb& box(std::uint32_t part) const { return boxes_[part]; }
    // Part `part`'s triangles: `triangle_count` triangles of indices(mesh), from first_triangle
    // (indices into the mesh's positions, reordered part by part).
    std::uint32_t first_triangle(std::uint32_t part) const { return part_first_triangle_[part]; }
    std::uint32_t triangle_count(std::uint32_t part) const { return part_triangle_count_[part]; }
    const std::uint32_t* indices(std::uint32_t mesh) const { return mesh_indices_.data() + mesh_first_index_[mesh]; }

private:
    // Per mesh: its triangles' indices reordered part by part, and its parts' triangle ranges.
    std::vector<std::uint32_t> mesh_indices_;
    std::vector<std::size_t> mesh_first_index_;
    std::vector<std::uint32_t> mesh_first_part_;  // into mesh_part_begin_ (one more entry than meshes)
    std::vector<std::uint32_t> mesh_part_begin_;  // each part's first triangle, then the mesh's triangle count
    // Per object: its parts (the mesh's, placed).
    std::vector<std::uint32_t> object_first_;
    std::vector<Aabb> boxes_;
    std::vector<std::uint32_t> part_first_triangle_, part_triangle_count_;
};

}  // namespace homcull::detail
