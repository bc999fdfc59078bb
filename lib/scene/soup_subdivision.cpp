// Zhang's subdivision of polygon soups into objects (Zhang 1998, sec. 8.2.1): the box of an
// object's triangle centres is split into M x N x P cells, recursively, until every cell holds
// at most max_triangles triangles; each cell becomes an object.
//
// Where: centres are taken in world space, from the same rounded positions ground truth and
// the culler use (transform_point). The culler tests world boxes, so cells must be compact and
// roughly cubic in the world: cells cut in model space would come out skewed and stretched
// under a rotation or a non-uniform scale, and their world boxes would overlap more. The price
// is that instances of one mesh are split one by one, each into meshes of its own.
//
// M x N x P: an axis is halved when its extent is at least half the longest extent, so each
// level splits into 2, 4 or 8 cells and the longest axis is always halved. A long box is cut
// along its length only until its proportions come within 2:1, and from then on every cell
// stays within 2:1 (all axes in [L/2, L] become [L/4, L/2]): cells end up roughly cubic
// whatever the model's shape. This is the idea behind choosing a uniform grid's cell counts in
// proportion to the box's extents (Zhang's M x N x P; ray-tracing grids are sized alike),
// applied one level at a time so that dense regions are refined and empty ones never are.
//
// Each level recomputes the box of the centres it holds (not the parent's box halved), so a
// cell is split as tightly as its triangles allow. The smallest and the largest centre along
// the longest axis always land in different halves, so every split makes progress; a cell
// stops when its centres coincide or at kMaxDepth levels (centres spread like 2^-k would
// otherwise peel off a few triangles per level), and is kept even if large.
#include <homcull/soup_subdivision.hpp>

#include <homcull/error.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace homcull {
namespace {

constexpr int kMaxDepth = 48;  // levels; bounds the work at 48 passes over an object's triangles

struct CellRange {
    std::size_t begin = 0, end = 0;  // into CellSplitter::order
    std::string path;                // "xyz" digits per level, joined by '.'
};

// Recursive M x N x P split of triangle ids by their centres.
class CellSplitter {
public:
    CellSplitter(const std::vector<glm::dvec3>& centres, std::size_t max_triangles)
        : centres_(centres), max_triangles_(max_triangles), order_(centres.size()), scratch_(centres.size()) {
        for (std::size_t t = 0; t < order_.size(); ++t) order_[t] = std::uint32_t(t);
        split(0, order_.size(), 0, std::string());
    }

    // Triangle ids, cell after cell, each cell's in increasing order.
    const std::vector<std::uint32_t>& order() const { return order_; }
    // The cells in the order of their paths.
    const std::vector<CellRange>& cells() const { return cells_; }

private:
    const std::vector<glm::dvec3>& centres_;
    std::size_t max_triangles_;
    std::vector<std::uint32_t> order_, scratch_;
    std::vector<CellRange> cells_;

    void split(std::size_t begin, std::size_t end, int depth, const std::string& path) {
        if (end - begin <= max_triangles_ || depth == kMaxDepth) return keep(begin, end, path);
        // The box of the finite centres: a non-finite centre (a vertex transformed to infinity
        // or NaN) cannot be placed, and goes to the low half of every split below.
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (std::size_t i = begin; i < end; ++i) {
            const glm::dvec3& c = centres_[order_[i]];
            if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;
            lo = glm::min(lo, c);
            hi = glm::max(hi, c);
        }
        const glm::dvec3 extent = hi - lo;
        const double longest = std::max({extent.x, extent.y, extent.z});
        if (!(longest > 0.0)) return keep(begin, end, path);  // no finite centre, or all equal
        bool halve[3];
        for (int axis = 0; axis < 3; ++axis) halve[axis] = extent[axis] > 0.0 && extent[axis] >= 0.5 * longest;

        // Child code 4x + 2y + z: the order of the digits "xyz" in the paths. The test is
        // (c - lo) * 2 >= extent rather than c >= lo + extent / 2, whose rounding can put the
        // midpoint on lo and send every centre to the high half.
        auto child_of = [&](std::uint32_t t) {
            const glm::dvec3& c = centres_[t];
            int code = 0;
            for (int axis = 0; axis < 3; ++axis)
                code = 2 * code + (halve[axis] && (c[axis] - lo[axis]) * 2.0 >= extent[axis] ? 1 : 0);
            return code;
        };
        // Stable counting sort into the eight children: each child keeps its triangles in order.
        std::array<std::size_t, 9> first{};
        for (std::size_t i = begin; i < end; ++i) ++first[std::size_t(child_of(order_[i])) + 1];
        for (std::size_t k = 1; k < first.size(); ++k) first[k] += first[k - 1];
        std::array<std::size_t, 8> next{};
        for (std::size_t k = 0; k < next.size(); ++k) next[k] = begin + first[k];
        for (std::size_t i = begin; i < end; ++i) scratch_[next[std::size_t(child_of(order_[i]))]++] = order_[i];
        std::copy(scratch_.begin() + std::ptrdiff_t(begin), scratch_.begin() + std::ptrdiff_t(end),
                  order_.begin() + std::ptrdiff_t(begin));

        for (std::size_t k = 0; k < 8; ++k) {
            if (first[k] == first[k + 1]) continue;
            std::string child_path = path.empty() ? path : path + '.';
            for (int bit = 2; bit >= 0; --bit) child_path += char('0' + ((k >> bit) & 1));
            split(begin + first[k], begin + first[k + 1], depth + 1, child_path);
        }
    }

    void keep(std::size_t begin, std::size_t end, const std::string& path) { cells_.push_back({begin, end, path}); }
};

// Throws unless the object can be split safely: its mesh and every index exist.
void check_object(const Scene& scene, std::size_t id) {
    const Object& object = scene.objects[id];
    const std::string what = scene.source + ": object " + std::to_string(id) + " ('" + object.name + "')";
    if (object.mesh >= scene.meshes.size())
        throw Error(what + " names mesh " + std::to_string(object.mesh) + " but there are " +
                    std::to_string(scene.meshes.size()));
    const Mesh& mesh = scene.meshes[object.mesh];
    if (mesh.indices.size() % 3 != 0)
        throw Error(what + ": its mesh '" + mesh.name + "' has " + std::to_string(mesh.indices.size()) +
                    " indices, not a multiple of 3");
    if (mesh.triangle_count() > std::numeric_limits<std::uint32_t>::max())
        throw Error(what + " has too many triangles to split (" + std::to_string(mesh.triangle_count()) + ")");
    for (std::uint32_t index : mesh.indices)
        if (index >= mesh.positions.size())
            throw Error(what + ": its mesh '" + mesh.name + "' uses vertex " + std::to_string(index) + " but has only " +
                        std::to_string(mesh.positions.size()) + " vertices");
}

// World-space triangle centres, from the rounded world positions (transform_point) that ground
// truth and the culler see.
std::vector<glm::dvec3> world_centres(const Mesh& mesh, const glm::dmat4& world) {
    std::vector<glm::vec3> positions(mesh.positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v) positions[v] = transform_point(world, mesh.positions[v]);
    std::vector<glm::dvec3> centres(mesh.triangle_count());
    for (std::size_t t = 0; t < centres.size(); ++t)
        centres[t] = (glm::dvec3(positions[mesh.indices[3 * t]]) + glm::dvec3(positions[mesh.indices[3 * t + 1]]) +
                      glm::dvec3(positions[mesh.indices[3 * t + 2]])) /
                     3.0;
    return centres;
}

// Builds cell meshes holding only the vertices their triangles use, in increasing original
// index, so that the compaction costs O(k log k) per cell of k triangles, never O(vertices).
class CellMeshBuilder {
public:
    explicit CellMeshBuilder(const Mesh& mesh) : mesh_(mesh), new_index_(mesh.positions.size(), kUnused) {}

    Mesh build(std::string name, const std::uint32_t* triangles, std::size_t count) {
        used_.clear();
        for (std::size_t i = 0; i < count; ++i)
            for (int corner = 0; corner < 3; ++corner) {
                const std::uint32_t v = mesh_.indices[3 * std::size_t(triangles[i]) + std::size_t(corner)];
                if (new_index_[v] == kUnused) {
                    new_index_[v] = 0;  // seen; numbered below
                    used_.push_back(v);
                }
            }
        std::sort(used_.begin(), used_.end());
        Mesh cell;
        cell.name = std::move(name);
        cell.positions.reserve(used_.size());
        for (std::uint32_t v : used_) {
            new_index_[v] = std::uint32_t(cell.positions.size());
            cell.positions.push_back(mesh_.positions[v]);
        }
        cell.indices.reserve(3 * count);
        for (std::size_t i = 0; i < count; ++i)
            for (int corner = 0; corner < 3; ++corner)
                cell.indices.push_back(new_index_[mesh_.indices[3 * std::size_t(triangles[i]) + std::size_t(corner)]]);
        for (std::uint32_t v : used_) new_index_[v] = kUnused;
        return cell;
    }

private:
    static constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
    const Mesh& mesh_;
    std::vector<std::uint32_t> new_index_;  // kUnused outside build()
    std::vector<std::uint32_t> used_;
};

// The original's extras with "soup_cell" set to the cell's path, keys kept sorted.
std::vector<std::pair<std::string, std::string>> cell_extras(const Object& object, const std::string& path) {
    std::vector<std::pair<std::string, std::string>> extras;
    for (const auto& extra : object.extras)
        if (extra.first != "soup_cell") extras.push_back(extra);
    const auto at = std::lower_bound(extras.begin(), extras.end(), std::string("soup_cell"),
                                     [](const auto& extra, const std::string& key) { return extra.first < key; });
    extras.insert(at, {"soup_cell", path});
    return extras;
}

struct Cell {
    Object object;  // its mesh id is set when the scene is assembled
    Mesh mesh;
};

// The object's cells, or nothing when it stays whole (small enough, or unsplittable).
std::optional<std::vector<Cell>> split_object(const Scene& scene, std::size_t id, std::size_t max_triangles) {
    check_object(scene, id);
    const Object& object = scene.objects[id];
    const Mesh& mesh = scene.meshes[object.mesh];
    const CellSplitter splitter(world_centres(mesh, object.world), max_triangles);
    if (splitter.cells().size() < 2) return std::nullopt;
    CellMeshBuilder builder(mesh);
    std::vector<Cell> cells;
    cells.reserve(splitter.cells().size());
    for (const CellRange& range : splitter.cells()) {
        Cell cell;
        cell.object.name = object.name + '#' + range.path;
        cell.object.world = object.world;
        cell.object.extras = cell_extras(object, range.path);
        cell.mesh = builder.build(cell.object.name, splitter.order().data() + range.begin, range.end - range.begin);
        cells.push_back(std::move(cell));
    }
    return cells;
}

}  // namespace

Scene subdivide_polygon_soups(const Scene& scene, const SoupSubdivision& options) {
    std::vector<std::optional<std::vector<Cell>>> cells_of(scene.objects.size());
    bool any_split = false;
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Object& object = scene.objects[id];
        if (object.mesh >= scene.meshes.size()) check_object(scene, id);  // throws
        if (options.max_triangles == 0 || scene.triangle_count(object) <= options.max_triangles) continue;
        cells_of[id] = split_object(scene, id, options.max_triangles);
        any_split = any_split || cells_of[id].has_value();
    }

    // A mesh stays unless every object that used it was split (unused meshes stay too).
    std::vector<char> used_whole(scene.meshes.size(), 0), used_split(scene.meshes.size(), 0);
    for (std::size_t id = 0; id < scene.objects.size(); ++id)
        (cells_of[id] ? used_split : used_whole)[scene.objects[id].mesh] = 1;
    Scene result;
    result.source = scene.source;
    if (any_split) result.source += " (soup cells <= " + std::to_string(options.max_triangles) + " triangles)";
    std::vector<std::uint32_t> new_mesh_id(scene.meshes.size(), 0);
    for (std::size_t m = 0; m < scene.meshes.size(); ++m)
        if (used_whole[m] || !used_split[m]) {
            new_mesh_id[m] = std::uint32_t(result.meshes.size());
            result.meshes.push_back(scene.meshes[m]);
        }
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        if (!cells_of[id]) {
            result.objects.push_back(scene.objects[id]);
            result.objects.back().mesh = new_mesh_id[scene.objects[id].mesh];
            continue;
        }
        for (Cell& cell : *cells_of[id]) {
            cell.object.mesh = std::uint32_t(result.meshes.size());
            result.meshes.push_back(std::move(cell.mesh));
            result.objects.push_back(std::move(cell.object));
        }
        cells_of[id].reset();  // free as we go
    }
    result.finalize();
    return result;
}

}  // namespace homcull
