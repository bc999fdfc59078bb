// Occluder LODs: weld, split into parts, and per closed part simplify (meshoptimizer), shrink
// and verify containment (Embree). The steps and the guarantee are explained in
// homcull/truth/occluder_lod_build.hpp and homcull/occluder_lod.hpp.
#include <embree3/rtcore.h>
#include <meshoptimizer.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <homcull/error.hpp>
#include <homcull/truth/occluder_lod_build.hpp>
#include <limits>
#include <memory>
#include <mutex>
#include <string>

namespace homcull {
namespace {

constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; }

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

glm::dvec3 triangle_cross(const std::vector<glm::vec3>& positions, const std::uint32_t* corner) {
    const glm::dvec3 a(positions[corner[0]]), b(positions[corner[1]]), c(positions[corner[2]]);
    return glm::cross(b - a, c - a);  // twice the area, along the CCW normal
}

// ---- Step 1: weld and split into parts ---------------------------------------------------------

struct TriangleMesh {
    std::vector<glm::vec3> positions;
    std::vector<std::uint32_t> indices;
};

// Equal positions welded into one vertex; invalid_geometry or empty, else built.
LodStatus weld(const Mesh& mesh, TriangleMesh& out) {
    if (mesh.indices.size() % 3 != 0) return LodStatus::invalid_geometry;
    if (mesh.indices.empty()) return LodStatus::empty;
    for (std::uint32_t i : mesh.indices)
        if (i >= mesh.positions.size() || !finite(mesh.positions[i])) return LodStatus::invalid_geometry;
    // By bytes, after turning -0 into +0 so that the two zeros weld. Unused non-finite
    // positions become 0: no triangle sees them.
    std::vector<glm::vec3> positions(mesh.positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v)
        positions[v] = finite(mesh.positions[v]) ? mesh.positions[v] + glm::vec3(0.0f) : glm::vec3(0.0f);
    std::vector<unsigned> remap(positions.size());
    const std::size_t unique = meshopt_generateVertexRemap(remap.data(), nullptr, positions.size(), positions.data(),
                                                           positions.size(), sizeof(glm::vec3));
    out.positions.resize(unique);
    meshopt_remapVertexBuffer(out.positions.data(), positions.data(), positions.size(), sizeof(glm::vec3),
                              remap.data());
    out.indices.resize(mesh.indices.size());
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) out.indices[i] = remap[mesh.indices[i]];
    return LodStatus::built;
}

// Triangles linked through shared vertices, as a mesh of its own. Parts are simplified and
// checked one by one: a part inside another, or crossing it, is still a solid of its own,
// while the mesh as a whole is not one by parity (points inside both parts are even).
struct Part {
    TriangleMesh mesh;
    bool degenerate = false;  // has a zero-area triangle
    bool closed = false;      // every directed edge once, its reverse once; nothing degenerate
};

// A zero-area triangle adds no surface but can make the edge count look closed (a sliver
// over a T-junction), so a part holding one is not trusted.
bool has_zero_area_triangle(const TriangleMesh& mesh) {
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        if (triangle_cross(mesh.positions, &mesh.indices[t]) == glm::dvec3(0.0)) return true;
    return false;
}

bool is_closed(const TriangleMesh& mesh) {
    std::vector<std::uint64_t> directed;
    directed.reserve(mesh.indices.size());
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) directed.push_back(edge_key(mesh.indices[t + k], mesh.indices[t + (k + 1) % 3]));
    std::sort(directed.begin(), directed.end());
    if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return false;
    for (std::uint64_t e : directed)
        if (!std::binary_search(directed.begin(), directed.end(), edge_key(std::uint32_t(e), std::uint32_t(e >> 32))))
            return false;
    return true;
}

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

std::vector<Part> split_into_parts(const TriangleMesh& welded) {
    std::vector<std::uint32_t> parent(welded.positions.size());
    for (std::uint32_t v = 0; v < parent.size(); ++v) parent[v] = v;
    for (std::size_t i = 0; i < welded.indices.size(); ++i) {
        const std::uint32_t a = find_root(parent, welded.indices[i]);
        const std::uint32_t b = find_root(parent, welded.indices[i - i % 3]);
        parent[a] = b;
    }
    std::vector<std::uint32_t> part_of_root(welded.positions.size(), kUnset), local(welded.positions.size(), kUnset);
    std::vector<Part> parts;
    for (std::size_t t = 0; t < welded.indices.size(); t += 3) {
        std::uint32_t& p = part_of_root[find_root(parent, welded.indices[t])];
        if (p == kUnset) {
            p = std::uint32_t(parts.size());
            parts.emplace_back();
        }
        TriangleMesh& mesh = parts[p].mesh;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = welded.indices[t + std::size_t(k)];
            if (local[v] == kUnset) {
                local[v] = std::uint32_t(mesh.positions.size());
                mesh.positions.push_back(welded.positions[v]);
            }
            mesh.indices.push_back(local[v]);
        }
    }
    for (Part& part : parts) {
        part.degenerate = has_zero_area_triangle(part.mesh);
        part.closed = !part.degenerate && is_closed(part.mesh);
    }
    return parts;
}

// ---- Steps 2 and 3: simplify and shrink --------------------------------------------------------

// Each vertex's normal as the sum of its triangles' unit normals weighted by the triangle's
// angle at the vertex (Thürmer and Wüthrich, "Computing vertex normals from polygonal facets",
// 1998). Unlike area weights it does not depend on how a flat region is cut into triangles,
// so a vertex on an edge between two faces moves off both. Triangles have non-zero area here.
std::vector<glm::dvec3> angle_weighted_normals(const TriangleMesh& mesh) {
    std::vector<glm::dvec3> normals(mesh.positions.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const std::uint32_t* corner = &mesh.indices[t];
        const glm::dvec3 unit = glm::normalize(triangle_cross(mesh.positions, corner));
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 p(mesh.positions[corner[k]]);
            const glm::dvec3 to_next = glm::dvec3(mesh.positions[corner[(k + 1) % 3]]) - p;
            const glm::dvec3 to_prev = glm::dvec3(mesh.positions[corner[(k + 2) % 3]]) - p;
            normals[corner[k]] +=
                unit * std::atan2(glm::length(glm::cross(to_next, to_prev)), glm::dot(to_next, to_prev));
        }
    }
    return normals;
}

// Simplified indices (into the part's positions) with the simplifier's error bounded by
// `max_error` model units. meshopt_simplify collapses edges in the order of Garland and
// Heckbert's quadric error, keeps the mesh's topology, and moves no vertex.
std::vector<std::uint32_t> simplify(const TriangleMesh& o, double target_ratio, double max_error) {
    const std::size_t triangles = o.indices.size() / 3;
    const std::size_t target = std::max<std::size_t>(1, std::size_t(double(triangles) * target_ratio)) * 3;
    const float scale = meshopt_simplifyScale(&o.positions[0].x, o.positions.size(), sizeof(glm::vec3));
    std::vector<std::uint32_t> out(o.indices.size());
    // meshoptimizer's error is relative to the mesh's extent (its scale).
    const float relative_error = scale > 0.0f ? float(max_error / double(scale)) : 0.0f;
    out.resize(meshopt_simplify(out.data(), o.indices.data(), o.indices.size(), &o.positions[0].x, o.positions.size(),
                                sizeof(glm::vec3), target, relative_error, 0, nullptr));
    return out;
}

// The simplified triangles as a compact mesh, each vertex moved `margin` into the solid along
// O's normal there (S's vertices are O's; S's own normals can be nonsense where the
// simplifier left slivers). `sign` is -1 for outward-facing parts, +1 for inside-out ones.
// Triangles of zero area are dropped: they cover nothing, and a ray tracer can report a hit
// with a meaningless distance on one (Embree does, on the collinear slivers the simplifier
// leaves along straight creases). False when a vertex has no usable normal or, in float, did
// not move by at least half the margin.
bool shrink(const TriangleMesh& o, const std::vector<glm::dvec3>& normals, const std::vector<std::uint32_t>& indices,
            double margin, double sign, TriangleMesh& out) {
    std::vector<glm::vec3> moved(o.positions.size());
    std::vector<std::uint8_t> done(o.positions.size(), 0);
    for (std::uint32_t v : indices) {
        if (done[v]) continue;
        done[v] = 1;
        const double length = glm::length(normals[v]);
        if (!(length > 0.0) || !std::isfinite(length)) return false;
        moved[v] = glm::vec3(glm::dvec3(o.positions[v]) + normals[v] * (sign * margin / length));
        if (!(glm::length(glm::dvec3(moved[v]) - glm::dvec3(o.positions[v])) >= 0.5 * margin)) return false;
    }
    std::vector<std::uint32_t> compact(o.positions.size(), kUnset);
    out.positions.clear();
    out.indices.clear();
    for (std::size_t t = 0; t < indices.size(); t += 3) {
        if (triangle_cross(moved, &indices[t]) == glm::dvec3(0.0)) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = indices[t + std::size_t(k)];
            if (compact[v] == kUnset) {
                compact[v] = std::uint32_t(out.positions.size());
                out.positions.push_back(moved[v]);
            }
            out.indices.push_back(compact[v]);
        }
    }
    return !out.indices.empty();
}

// ---- Step 4: verify containment with Embree ----------------------------------------------------

// Embree reports errors through a device callback; the first one is kept and thrown at the end.
struct EmbreeErrors {
    std::mutex mutex;
    std::string first;
};

void record_error(void* user, RTCError code, const char* message) {
    auto* errors = static_cast<EmbreeErrors*>(user);
    std::lock_guard<std::mutex> lock(errors->mutex);
    if (errors->first.empty())
        errors->first = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

// One triangle mesh as an Embree scene, robust (no shortcuts that could miss a hit on an
// edge) and accepting context filters (the parity count).
class TriangleScene {
public:
    TriangleScene(RTCDevice device, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices)
        : scene_(rtcNewScene(device)) {
        if (!scene_) return;
        rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (!geometry) return;
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
        auto* triangles = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), indices.size() / 3));
        if (vertices && triangles) {
            for (std::size_t v = 0; v < positions.size(); ++v) {
                vertices[3 * v + 0] = positions[v].x;
                vertices[3 * v + 1] = positions[v].y;
                vertices[3 * v + 2] = positions[v].z;
            }
            std::copy(indices.begin(), indices.end(), triangles);
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(scene_, geometry);
            ok_ = true;
        }
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene_);
    }
    ~TriangleScene() {
        if (scene_) rtcReleaseScene(scene_);
    }
    TriangleScene(const TriangleScene&) = delete;
    TriangleScene& operator=(const TriangleScene&) = delete;

    bool ok() const { return ok_; }

    // Whether the segment from a to b meets a triangle.
    bool segment_hits(const glm::vec3& a, const glm::vec3& b) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray = make_ray(a, b - a, 1.0f);
        rtcOccluded1(scene_, &context, &ray);
        return ray.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
    }

    // How many distinct triangles the ray from `origin` along `direction` crosses.
    std::size_t crossings(const glm::vec3& origin, const glm::vec3& direction) const {
        HitCollector collector;
        rtcInitIntersectContext(&collector.context);
        collector.context.filter = collect_and_reject;
        RTCRayHit rh{};
        rh.ray = make_ray(origin, direction, std::numeric_limits<float>::infinity());
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &collector.context, &rh);
        std::sort(collector.triangles.begin(), collector.triangles.end());
        return std::size_t(std::unique(collector.triangles.begin(), collector.triangles.end()) -
                           collector.triangles.begin());
    }

private:
    // The context a filter function sees, extended with the triangles it was shown.
    struct HitCollector {
        RTCIntersectContext context;  // first, so that the filter can cast back
        std::vector<unsigned> triangles;
    };
    // Records each hit and rejects it, so that traversal goes on to every triangle on the ray.
    // A triangle could be shown twice (Embree does not promise otherwise), hence the unique().
    static void collect_and_reject(const RTCFilterFunctionNArguments* args) {
        auto* collector = reinterpret_cast<HitCollector*>(args->context);
        for (unsigned i = 0; i < args->N; ++i) {
            if (args->valid[i] == 0) continue;
            collector->triangles.push_back(RTCHitN_primID(args->hit, args->N, i));
            args->valid[i] = 0;
        }
    }
    static RTCRay make_ray(const glm::vec3& origin, const glm::vec3& direction, float t_far) {
        RTCRay ray{};
        ray.org_x = origin.x;
        ray.org_y = origin.y;
        ray.org_z = origin.z;
        ray.dir_x = direction.x;
        ray.dir_y = direction.y;
        ray.dir_z = direction.z;
        ray.tnear = 0.0f;
        ray.tfar = t_far;
        ray.mask = 0xFFFFFFFFu;
        ray.flags = 0;
        return ray;
    }

    RTCScene scene_ = nullptr;
    bool ok_ = false;
};

// Undirected edges of a triangle list, each once, as (low << 32) | high.
std::vector<std::uint64_t> undirected_edges(const std::vector<std::uint32_t>& indices) {
    std::vector<std::uint64_t> edges;
    edges.reserve(indices.size());
    for (std::size_t t = 0; t < indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = indices[t + k], b = indices[t + (k + 1) % 3];
            edges.push_back(a < b ? edge_key(a, b) : edge_key(b, a));
        }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    return edges;
}

bool no_edge_meets(const TriangleMesh& edges_of, const TriangleScene& triangles) {
    for (std::uint64_t e : undirected_edges(edges_of.indices))
        if (triangles.segment_hits(edges_of.positions[e >> 32], edges_of.positions[std::uint32_t(e)])) return false;
    return true;
}

// Three directions off every axis and every diagonal, so that rays do not run along the
// planes of axis-aligned architecture.
const glm::vec3 kParityDirections[3] = {
    glm::normalize(glm::vec3(0.5383f, 0.7217f, 0.4351f)),
    glm::normalize(glm::vec3(-0.6911f, 0.2273f, -0.6862f)),
    glm::normalize(glm::vec3(0.1709f, -0.8893f, 0.4241f)),
};

bool inside_by_parity(const glm::vec3& p, const TriangleScene& o) {
    for (const glm::vec3& direction : kParityDirections)
        if (o.crossings(p, direction) % 2 != 1) return false;
    return true;
}

// (a), (b) and (c) of the header: S's surface does not cross O's, and S's vertices are inside.
bool contained(const TriangleMesh& o, const TriangleScene& o_scene, const TriangleMesh& s, RTCDevice device) {
    for (const glm::vec3& p : s.positions)
        if (!inside_by_parity(p, o_scene)) return false;  // the cheapest way to fail first
    const TriangleScene s_scene(device, s.positions, s.indices);
    return s_scene.ok() && no_edge_meets(s, o_scene) && no_edge_meets(o, s_scene);
}

// "Far larger" than the rounding: the margin is at least this many times the rounding.
constexpr double kMarginOverRounding = 16.0;

// ---- Steps 2 to 4 per part -------------------------------------------------------------------

// The attempts, in order; the first whose result passes the check replaces the part. Smaller
// margins first, since they give up less occlusion; within a margin, the smaller triangle
// target first. The simplifier's error bound is half the shrink, so that where it cuts across
// the surface the shrink can pull it back inside. meshoptimizer's error is a quadric error
// (the root of the area-weighted mean squared distance to the collapsed triangles' planes),
// not a maximum distance, so the bound is a hint and the check decides. The larger margins
// matter on the castle: its curved stones and mouldings only simplify with an error of about
// 1 % of their size (56 meshes get an LOD with margins up to 16x, 16 with up to 4x).
struct Attempt {
    double ratio_factor;     // times LodOptions::target_ratio, at most 1
    double margin_factor;    // times LodOptions::margin
    double error_of_margin;  // the simplifier's error bound, as a fraction of the shrink
};
constexpr Attempt kAttempts[] = {{1.0, 1.0, 0.5}, {2.0, 1.0, 0.5},  {1.0, 4.0, 0.5},
                                 {2.0, 4.0, 0.5}, {1.0, 16.0, 0.5}, {2.0, 16.0, 0.5}};

struct PartResult {
    bool reduced = false;     // some attempt kept at most LodOptions::max_kept_ratio of them
    bool simplified = false;  // and one of them passed the check: `lod` holds it
    TriangleMesh lod;
    double margin = 0.0;
};

// `min_margin`: the shrink must be at least this, in model units (transform rounding).
PartResult simplify_part(const TriangleMesh& o, const LodOptions& options, double min_margin, RTCDevice device) {
    PartResult result;
    Aabb box;
    double volume6 = 0.0;  // six times the signed volume: negative when the part faces inward
    for (std::size_t t = 0; t < o.indices.size(); t += 3) {
        volume6 += glm::dot(glm::dvec3(o.positions[o.indices[t]]), triangle_cross(o.positions, &o.indices[t]));
        for (int k = 0; k < 3; ++k) box.extend(o.positions[o.indices[t + std::size_t(k)]]);
    }
    const double sign = volume6 < 0.0 ? 1.0 : -1.0;
    const double diagonal = glm::length(glm::dvec3(box.extent()));
    // The shrunk positions are floats too: the margin must also be far above their rounding.
    const double largest = std::max(glm::length(glm::dvec3(box.min)), glm::length(glm::dvec3(box.max)));
    min_margin = std::max(min_margin, kMarginOverRounding * std::ldexp(largest, -24));
    const std::vector<glm::dvec3> normals = angle_weighted_normals(o);
    const std::size_t triangles = o.indices.size() / 3;
    std::unique_ptr<TriangleScene> o_scene;  // built when first needed
    for (const Attempt& attempt : kAttempts) {
        const double margin = std::max(options.margin * attempt.margin_factor * diagonal, min_margin);
        const std::vector<std::uint32_t> indices =
            simplify(o, std::min(1.0, options.target_ratio * attempt.ratio_factor), margin * attempt.error_of_margin);
        if (indices.empty() || double(indices.size() / 3) > options.max_kept_ratio * double(triangles)) continue;
        result.reduced = true;
        TriangleMesh s;
        if (!shrink(o, normals, indices, margin, sign, s)) continue;
        if (!o_scene) o_scene = std::make_unique<TriangleScene>(device, o.positions, o.indices);
        if (!o_scene->ok() || !contained(o, *o_scene, s, device)) continue;
        result.simplified = true;
        result.lod = std::move(s);
        result.margin = margin;
        return result;
    }
    return result;
}

// ---- Step 5: the margin against transform rounding --------------------------------------------

// How far float rounding of transform_point can move S relative to O, in model units, for
// one placement: each world coordinate rounds by at most 2^-24 of its magnitude (the double
// arithmetic before it is 2^29 times finer), a vertex by sqrt(3) times the largest, and both
// S's and O's vertices move. ||L^-1||_F bounds how much a world distance shrinks back to the
// model. Infinite for a singular or non-finite transform.
double rounding_in_model_units(const glm::dmat4& world, const glm::vec3& box_min, const glm::vec3& box_max) {
    const glm::dmat3 linear(world);
    const double det = glm::determinant(linear);
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return std::numeric_limits<double>::infinity();
    const glm::dmat3 inverse = glm::inverse(linear);
    double frobenius2 = 0.0;
    for (int c = 0; c < 3; ++c) frobenius2 += glm::dot(inverse[c], inverse[c]);
    double largest = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p{(corner & 1) ? box_max.x : box_min.x, (corner & 2) ? box_max.y : box_min.y,
                           (corner & 4) ? box_max.z : box_min.z};
        const glm::dvec3 w = glm::dvec3(world * glm::dvec4(p, 1.0));
        largest = std::max({largest, std::abs(w.x), std::abs(w.y), std::abs(w.z)});
    }
    const double result = 2.0 * std::sqrt(3.0) * std::ldexp(largest, -24) * std::sqrt(frobenius2);
    return std::isfinite(result) ? result : std::numeric_limits<double>::infinity();
}

// ---- One mesh ------------------------------------------------------------------------------

struct MeshResult {
    LodStatus status = LodStatus::not_requested;
    bool closed = false;  // the whole mesh: one or more parts, every one closed
    OccluderLod lod;
};

void append(const TriangleMesh& part, Mesh& mesh) {
    const auto base = std::uint32_t(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), part.positions.begin(), part.positions.end());
    for (std::uint32_t i : part.indices) mesh.indices.push_back(base + i);
}

// `rounding`: the worst transform rounding of the mesh's placements, model units.
MeshResult build_one(const Mesh& mesh, std::uint32_t mesh_id, double rounding, const LodOptions& options,
                     RTCDevice device) {
    MeshResult result;
    TriangleMesh welded;
    result.status = weld(mesh, welded);
    if (result.status != LodStatus::built) return result;
    const std::vector<Part> parts = split_into_parts(welded);
    result.closed = std::all_of(parts.begin(), parts.end(), [](const Part& p) { return p.closed; });
    const bool any_closed = std::any_of(parts.begin(), parts.end(), [](const Part& p) { return p.closed; });
    const bool any_degenerate = std::any_of(parts.begin(), parts.end(), [](const Part& p) { return p.degenerate; });
    const std::size_t triangles = mesh.triangle_count();
    if (!any_closed) {
        result.status = any_degenerate ? LodStatus::degenerate_triangle : LodStatus::not_closed;
        return result;
    }
    if (!std::isfinite(rounding)) {
        result.status = LodStatus::bad_transform;
        return result;
    }
    if (triangles < options.min_triangles) {
        result.status = LodStatus::too_small;
        return result;
    }

    std::vector<PartResult> simplified(parts.size());
    auto worth_simplifying = [&](const Part& part) {
        return part.closed && part.mesh.indices.size() / 3 >= options.min_part_triangles;
    };
    if (std::none_of(parts.begin(), parts.end(), worth_simplifying)) {
        result.status = LodStatus::too_small;
        return result;
    }
    tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t p) {
        if (worth_simplifying(parts[p]))
            simplified[p] = simplify_part(parts[p].mesh, options, kMarginOverRounding * rounding, device);
    });

    OccluderLod& lod = result.lod;
    lod.mesh.name = mesh.name + " (occluder LOD)";
    lod.source_mesh = mesh_id;
    bool reduced = false;
    for (std::size_t p = 0; p < parts.size(); ++p) {
        reduced = reduced || simplified[p].reduced;
        if (simplified[p].simplified) {
            append(simplified[p].lod, lod.mesh);
            const auto margin = float(simplified[p].margin);
            lod.margin = lod.parts_simplified == 0 ? margin : std::min(lod.margin, margin);
            ++lod.parts_simplified;
        } else {
            append(parts[p].mesh, lod.mesh);  // as it is: hides exactly what it hid
            ++lod.parts_kept;
        }
    }
    if (lod.parts_simplified == 0) {
        result.status = reduced ? LodStatus::not_contained : LodStatus::not_reduced;
    } else if (double(lod.mesh.triangle_count()) > options.max_kept_ratio * double(triangles)) {
        result.status = LodStatus::not_reduced;
    } else {
        result.status = LodStatus::built;
    }
    if (result.status != LodStatus::built) result.lod = {};
    return result;
}

void validate(const Scene& scene, const std::vector<std::uint32_t>& objects, const LodOptions& options) {
    if (!(options.target_ratio > 0.0 && options.target_ratio <= 1.0))
        throw Error("occluder LOD: target ratio must be in (0, 1]");
    if (!(options.max_kept_ratio > 0.0 && options.max_kept_ratio <= 1.0))
        throw Error("occluder LOD: max kept ratio must be in (0, 1]");
    if (!(options.margin > 0.0 && options.margin <= 0.1))
        throw Error("occluder LOD: margin must be in (0, 0.1] of a part's box diagonal");
    for (std::uint32_t id : objects) {
        if (id >= scene.objects.size())
            throw Error(scene.source + ": occluder LOD: object id " + std::to_string(id) + " out of range");
        if (scene.objects[id].mesh >= scene.meshes.size())
            throw Error(scene.source + ": occluder LOD: object " + std::to_string(id) + " names no mesh");
    }
}

// The box of the positions a mesh's triangles use (indices out of range are skipped: such a
// mesh gets no LOD anyway).
Aabb used_box(const Mesh& mesh) {
    Aabb box;
    for (std::uint32_t i : mesh.indices)
        if (i < mesh.positions.size()) box.extend(mesh.positions[i]);
    return box;
}

struct DeviceDeleter {
    void operator()(RTCDeviceTy* device) const { rtcReleaseDevice(device); }
};

}  // namespace

OccluderLods build_occluder_lods(const Scene& scene, const std::vector<std::uint32_t>& objects,
                                 const LodOptions& options) {
    validate(scene, objects, options);
    const auto start = std::chrono::steady_clock::now();

    // The meshes to simplify, each with the worst rounding of the objects placing it.
    std::vector<double> rounding(scene.meshes.size(), -1.0);
    for (std::uint32_t id : objects) {
        const Object& object = scene.objects[id];
        const Aabb box = used_box(scene.meshes[object.mesh]);
        const double r = box.empty() ? 0.0 : rounding_in_model_units(object.world, box.min, box.max);
        rounding[object.mesh] = std::max(rounding[object.mesh], r);
    }
    std::vector<std::uint32_t> meshes;
    for (std::uint32_t m = 0; m < scene.meshes.size(); ++m)
        if (rounding[m] >= 0.0) meshes.push_back(m);

    EmbreeErrors errors;
    const std::unique_ptr<RTCDeviceTy, DeviceDeleter> device(rtcNewDevice(nullptr));
    if (!device)
        throw Error("Embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device.get(), record_error, &errors);
    std::vector<MeshResult> results(meshes.size());
    // One task per mesh, and per part within it: sizes vary by orders of magnitude.
    tbb::parallel_for(std::size_t(0), meshes.size(), [&](std::size_t i) {
        results[i] = build_one(scene.meshes[meshes[i]], meshes[i], rounding[meshes[i]], options, device.get());
    });
    if (!errors.first.empty()) throw Error("occluder LOD of " + scene.source + ": " + errors.first);

    OccluderLods lods;
    lods.lod_of_mesh.assign(scene.meshes.size(), -1);
    lods.status_of_mesh.assign(scene.meshes.size(), LodStatus::not_requested);
    lods.meshes_considered = meshes.size();
    for (std::size_t i = 0; i < meshes.size(); ++i) {
        MeshResult& r = results[i];
        lods.status_of_mesh[meshes[i]] = r.status;
        lods.meshes_closed += r.closed;
        if (r.status != LodStatus::built) continue;
        lods.lod_of_mesh[meshes[i]] = std::int32_t(lods.lods.size());
        lods.triangles_before += scene.meshes[meshes[i]].triangle_count();
        lods.triangles_after += r.lod.mesh.triangle_count();
        lods.lods.push_back(std::move(r.lod));
    }
    lods.meshes_with_lod = lods.lods.size();
    lods.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return lods;
}

}  // namespace homcull
