// Occluder LODs, the driver: validates the options, finds each mesh's worst transform rounding,
// and builds the meshes in parallel. Per mesh it welds and splits into parts (lod_mesh_parts);
// per closed part large enough it tries the attempts in order, each simplifying and shrinking
// (lod_simplify) and verifying containment (lod_containment), and keeps the first that passes;
// then it joins the parts into the LOD and decides its status. The steps and the guarantee are
// explained in homcull/truth/occluder_lod_build.hpp and homcull/occluder_lod.hpp.
#include "truth/lod_containment.hpp"
#include "truth/lod_mesh_parts.hpp"
#include "truth/lod_simplify.hpp"
#include "truth/lod_triangle_mesh.hpp"

#include <embree3/rtcore.h>
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

using detail::lod::angle_weighted_normals;
using detail::lod::contained;
using detail::lod::Part;
using detail::lod::shrink;
using detail::lod::simplify;
using detail::lod::split_into_parts;
using detail::lod::triangle_cross;
using detail::lod::TriangleMesh;
using detail::lod::TriangleScene;
using detail::lod::weld;

// ---- The Embree device -------------------------------------------------------------------------

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

struct DeviceDeleter {
    void operator()(RTCDeviceTy* device) const { rtcReleaseDevice(device); }
};

// ---- Steps 2 to 4 per part -------------------------------------------------------------------

// "Far larger" than the rounding: the margin is at least this many times the rounding.
constexpr double kMarginOverRounding = 16.0;

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
    lods.built_for_object.assign(scene.objects.size(), 0);
    for (std::uint32_t id : objects) lods.built_for_object[id] = 1;
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
