// homcull.h: meshes registered once. The copy, the shared edges and the clusters are made in
// the mesh's account, so that all of it comes from the engine's allocator.
#include "capi/c_objects.hpp"

#include "common/float_mode.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace homcull;

namespace {

// The indices as 32-bit numbers, checked against the vertex count; false (with the result
// reported) at the first out of range.
homcull_result read_indices(const homcull_context* context, const homcull_mesh_desc& d, detail::Vector<std::uint32_t>& out) {
    out.resize(3 * d.triangle_count);
    for (std::size_t i = 0; i < out.size(); ++i) {
        std::uint32_t v;
        if (!d.indices) v = std::uint32_t(i);
        else if (d.index_size == 2) v = static_cast<const std::uint16_t*>(d.indices)[i];
        else v = static_cast<const std::uint32_t*>(d.indices)[i];
        if (v >= d.vertex_count)
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT,
                                "homcull_mesh_create: index %u of triangle %zu is not below vertex_count %zu", unsigned(v), i / 3,
                                d.vertex_count);
        out[i] = v;
    }
    return HOMCULL_OK;
}

}  // namespace

extern "C" {

homcull_result homcull_mesh_create(homcull_context* context, const homcull_mesh_desc* desc, homcull_mesh** out) {
    if (!out) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_mesh_create: out is null");
    *out = nullptr;
    if (!context || !desc) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_mesh_create: context or desc is null");
    const homcull_mesh_desc& d = *desc;
    if (d.triangle_count > 0 && !d.positions)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_mesh_create: positions is null");
    if (d.position_stride < 3 * sizeof(float))
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_mesh_create: position_stride %zu is below one position (12 bytes)",
                            d.position_stride);
    if (d.indices && d.index_size != 2 && d.index_size != 4)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_mesh_create: index_size must be 2 or 4, got %u", unsigned(d.index_size));
    if (!d.indices && d.triangle_count > d.vertex_count / 3)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT,
                            "homcull_mesh_create: %zu triangles without indices need %zu vertices, vertex_count is %zu", d.triangle_count,
                            3 * d.triangle_count, d.vertex_count);
    // compute_shared_edges numbers triangles' edges in 32 bits.
    if (d.triangle_count >= (std::size_t(1) << 32) / 3 || d.vertex_count >= (std::size_t(1) << 32))
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_mesh_create: a mesh has fewer than 2^32 / 3 triangles and 2^32 vertices");

    homcull_mesh* mesh = nullptr;
    const homcull_result result = capi::guarded(context, "homcull_mesh_create", [&]() -> homcull_result {
        mesh = capi::place<homcull_mesh>(context);
        const detail::MemoryScope scope(&mesh->account.hooks);
        const detail::StandardFloatMode mode;
        detail::Vector<std::uint32_t> indices;
        const homcull_result r = read_indices(context, d, indices);
        if (r != HOMCULL_OK) return r;
        detail::Vector<std::uint8_t> shared(d.triangle_count);
        detail::Vector<std::uint32_t> apexes(3 * d.triangle_count);
        if (d.triangle_count > 0) {
            compute_shared_edges(d.positions, d.position_stride, d.vertex_count, indices.data(), d.triangle_count, shared.data(), apexes.data());
            mesh->clusters = build_occluder_clusters(d.positions, d.position_stride, d.vertex_count, indices.data(), d.triangle_count,
                                                     shared.data(), apexes.data());
        }
        mesh->triangle_count = d.triangle_count;
        mesh->bounded = d.triangle_count > 0;
        for (int k = 0; k < 3; ++k) mesh->bounds_min[k] = INFINITY, mesh->bounds_max[k] = -INFINITY;
        for (const std::uint32_t v : indices) {
            const float* p = reinterpret_cast<const float*>(reinterpret_cast<const unsigned char*>(d.positions) + std::size_t(v) * d.position_stride);
            for (int k = 0; k < 3; ++k) {
                mesh->bounded = mesh->bounded && std::isfinite(p[k]);
                mesh->bounds_min[k] = std::min(mesh->bounds_min[k], p[k]);
                mesh->bounds_max[k] = std::max(mesh->bounds_max[k], p[k]);
            }
        }
        return HOMCULL_OK;
    });
    if (result != HOMCULL_OK) {
        if (mesh) capi::unplace(mesh);
        return result;
    }
    *out = mesh;
    return HOMCULL_OK;
}

void homcull_mesh_destroy(homcull_mesh* mesh) {
    if (mesh) capi::unplace(mesh);
}

size_t homcull_mesh_triangle_count(const homcull_mesh* mesh) { return mesh ? mesh->triangle_count : 0; }

}  // extern "C"
