// homcull_filter_by_complexity: Zhang's complexity filter over an engine's occluder candidates,
// each a homcull_mesh under a model matrix (the scene culler's filter_by_complexity takes a
// Scene's objects; both apply common/complexity_rule.hpp).
#include <homcull/homcull.h>

#include "capi/c_objects.hpp"
#include "capi/view_conventions.hpp"
#include "common/complexity_rule.hpp"
#include "common/float_mode.hpp"

#include <glm/vec4.hpp>

#include <cmath>

namespace homcull {
namespace {

// The surface of a mesh's triangles under a model matrix, in double (its clusters hold every
// triangle once, with its own vertices). Not finite when a transformed coordinate is not.
double world_area(const homcull_mesh& mesh, const glm::dmat4& model) {
    const OccluderClusters& c = mesh.clusters;
    double area = 0.0;
    for (const OccluderCluster& cluster : c.clusters) {
        const auto vertex = [&](std::uint16_t local) {
            const float* p = c.positions.data() + 3 * (std::size_t(cluster.first_vertex) + local);
            return glm::dvec3(model * glm::dvec4(double(p[0]), double(p[1]), double(p[2]), 1.0));
        };
        for (std::uint32_t t = cluster.first_triangle; t < cluster.first_triangle + cluster.triangle_count; ++t) {
            const glm::dvec3 a = vertex(c.indices[3 * std::size_t(t)]), b = vertex(c.indices[3 * std::size_t(t) + 1]),
                             d = vertex(c.indices[3 * std::size_t(t) + 2]);
            area += detail::triangle_area(a, b, d);
        }
    }
    return area;
}

}  // namespace
}  // namespace homcull

using namespace homcull;

extern "C" {

homcull_result homcull_filter_by_complexity(homcull_context* context, const homcull_mesh* const* meshes, const float* model_matrices,
                                            homcull_matrix_layout layout, size_t count, double factor, uint8_t* keep) {
    const char* const fn = "homcull_filter_by_complexity";
    if (count > 0 && !keep) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: keep is null", fn);
    for (size_t k = 0; k < count; ++k) keep[k] = 1;  // what an error leaves: every candidate
    if (!context) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: context is null", fn);
    if (count > 0 && !meshes) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: meshes is null", fn);
    if (layout != HOMCULL_COLUMN_MAJOR && layout != HOMCULL_ROW_MAJOR)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: layout %d is neither HOMCULL_COLUMN_MAJOR nor HOMCULL_ROW_MAJOR", fn,
                            int(layout));
    if (std::isnan(factor)) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: factor is not a number", fn);
    for (size_t k = 0; k < count; ++k) {
        if (!meshes[k]) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: mesh %zu is null", fn, k);
        if (model_matrices && !capi::finite_matrix(model_matrices + 16 * k))
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: model matrix %zu has a number that is not finite", fn, k);
    }
    if (!(factor > 0.0) || count == 0) return HOMCULL_OK;
    return capi::guarded(context->own, fn, [&]() -> homcull_result {
        const detail::StandardFloatMode mode;  // float_mode.hpp
        detail::Vector<double> densities(count), sorted(count);
        for (size_t k = 0; k < count; ++k) {
            const glm::dmat4 model = model_matrices ? capi::read_matrix(model_matrices + 16 * k, layout) : glm::dmat4(1.0);
            densities[k] = sorted[k] = detail::triangle_density(meshes[k]->triangle_count, world_area(*meshes[k], model));
        }
        const double limit = detail::complexity_limit(sorted.data(), count, factor);
        for (size_t k = 0; k < count; ++k) keep[k] = detail::within_complexity(densities[k], limit) ? 1 : 0;
        return HOMCULL_OK;
    });
}

}  // extern "C"
