// homcull.h: visibility sorting. A sorter holds a VisibilitySorter (lib/sort) made in its own
// account, so that its hulls, its scratch and its answers come from the engine's allocator.
#include "capi/c_objects.hpp"
#include "capi/view_conventions.hpp"

#include <homcull/visibility_sort.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

using namespace homcull;

struct homcull_sorter {
    homcull::capi::Account account;
    std::optional<homcull::VisibilitySorter> sorter;  // made in the account's scope
    // The frame's model matrices and planes, read; assigned in the account's scope (made
    // here, before it, they would hold no hooks).
    homcull::detail::Vector<glm::mat4> transforms;
    homcull::detail::Vector<glm::vec4> planes;
    explicit homcull_sorter(homcull_context* context) : account(context) {}
};

extern "C" {

homcull_result homcull_sorter_create(homcull_context* context, const homcull_sorter_desc* desc, homcull_sorter** out) {
    if (!out) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_create: out is null");
    *out = nullptr;
    if (!context || !desc) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_create: context or desc is null");
    if (desc->object_count > 0 && !desc->object_meshes)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_create: object_meshes is null");
    for (std::size_t i = 0; i < desc->object_count; ++i)
        if (!desc->object_meshes[i])
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_create: object %zu has no mesh", i);
    homcull_sorter* sorter = nullptr;
    const homcull_result result = capi::guarded(context, "homcull_sorter_create", [&]() -> homcull_result {
        sorter = capi::place<homcull_sorter>(context);
        const detail::MemoryScope scope(&sorter->account.hooks);
        // One shape per distinct mesh: the hull of the vertices its clusters hold (those its
        // triangles use); a mesh without triangles is a point at its origin.
        const std::size_t n = desc->object_count;
        detail::Vector<const homcull_mesh*> meshes(desc->object_meshes, desc->object_meshes + n);
        std::sort(meshes.begin(), meshes.end());
        meshes.erase(std::unique(meshes.begin(), meshes.end()), meshes.end());
        detail::Vector<detail::Vector<glm::vec3>> hulls;
        detail::Vector<HullPoints> views;
        hulls.reserve(meshes.size());
        for (const homcull_mesh* mesh : meshes) {
            const detail::Vector<float>& xyz = mesh->clusters.positions;
            detail::Vector<glm::vec3> points;
            for (std::size_t k = 0; k + 2 < xyz.size(); k += 3) points.emplace_back(xyz[k], xyz[k + 1], xyz[k + 2]);
            if (points.empty()) points.emplace_back(0.0f);
            hulls.push_back(convex_hull_points(points.data(), points.size(), kSortHullPoints));
            views.push_back({hulls.back().data(), hulls.back().size()});
        }
        detail::Vector<std::uint32_t> shapes(n);
        for (std::size_t i = 0; i < n; ++i)
            shapes[i] = std::uint32_t(std::lower_bound(meshes.begin(), meshes.end(), desc->object_meshes[i]) - meshes.begin());
        sorter->sorter.emplace(views.data(), views.size(), shapes.data(), shapes.size());
        sorter->transforms = detail::Vector<glm::mat4>(n);  // the allocator propagates
        sorter->planes = detail::Vector<glm::vec4>(16);
        sorter->planes.clear();
        return HOMCULL_OK;
    });
    if (result != HOMCULL_OK) {
        if (sorter) capi::unplace(sorter);
        return result;
    }
    *out = sorter;
    return HOMCULL_OK;
}

void homcull_sorter_destroy(homcull_sorter* sorter) {
    if (sorter) capi::unplace(sorter);
}

homcull_result homcull_sorter_sort(homcull_sorter* sorter, const homcull_sort_frame* frame, homcull_sort_result* out) {
    if (!sorter || !frame || !out) return capi::report(sorter ? sorter->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT,
                                                       "homcull_sorter_sort: sorter, frame or out is null");
    homcull_context* context = sorter->account.context;
    *out = homcull_sort_result{};
    const std::size_t n = sorter->transforms.size();
    if (n > 0 && !frame->model_matrices)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_sort: model_matrices is null");
    if (frame->layout != HOMCULL_COLUMN_MAJOR && frame->layout != HOMCULL_ROW_MAJOR)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_sort: unknown matrix layout %d", int(frame->layout));
    if (frame->plane_count > 16)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_sort: %u planes, at most 16", unsigned(frame->plane_count));
    if (frame->plane_count > 0 && !frame->planes)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_sorter_sort: planes is null");
    return capi::guarded(sorter->account, "homcull_sorter_sort", [&]() -> homcull_result {
        for (std::size_t i = 0; i < n; ++i) sorter->transforms[i] = glm::mat4(capi::read_matrix(frame->model_matrices + 16 * i, frame->layout));
        sorter->planes.clear();
        for (std::uint32_t k = 0; k < frame->plane_count; ++k) {
            const float* p = frame->planes + 4 * k;
            sorter->planes.emplace_back(p[0], p[1], p[2], p[3]);
        }
        SortFrame f;
        f.transforms = sorter->transforms.data();
        f.eye = glm::vec3(frame->eye[0], frame->eye[1], frame->eye[2]);
        f.planes = sorter->planes.data();
        f.plane_count = sorter->planes.size();
        f.incremental = frame->from_scratch == 0;
        const VisibilitySort& sort = sorter->sorter->sort(f);
        out->order = sort.order.data();
        out->order_count = sort.order.size();
        static_assert(sizeof(SortLayer) == sizeof(homcull_sort_layer) && sizeof(OcclusionPair) == sizeof(homcull_occlusion_pair),
                      "the C structs mirror the C++ ones");
        out->layers = reinterpret_cast<const homcull_sort_layer*>(sort.layers.data());
        out->layer_count = sort.layers.size();
        out->pairs = reinterpret_cast<const homcull_occlusion_pair*>(sort.pairs.data());
        out->pair_count = sort.pairs.size();
        out->cycles = sort.stats.cycles;
        out->objects_in_cycles = sort.stats.objects_in_cycles;
        return HOMCULL_OK;
    });
}

}  // extern "C"
