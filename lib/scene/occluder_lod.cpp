// The use-time side of occluder LOD: status names and the near-plane condition.
#include <cmath>
#include <homcull/occluder_lod.hpp>

namespace homcull {

const char* lod_status_name(LodStatus status) {
    switch (status) {
        case LodStatus::not_requested:
            return "not_requested";
        case LodStatus::built:
            return "built";
        case LodStatus::empty:
            return "empty";
        case LodStatus::invalid_geometry:
            return "invalid_geometry";
        case LodStatus::degenerate_triangle:
            return "degenerate_triangle";
        case LodStatus::not_closed:
            return "not_closed";
        case LodStatus::too_small:
            return "too_small";
        case LodStatus::not_reduced:
            return "not_reduced";
        case LodStatus::not_contained:
            return "not_contained";
        case LodStatus::bad_transform:
            return "bad_transform";
    }
    return "unknown";
}

bool lod_usable(const Aabb& world_box, const Camera& camera) {
    if (world_box.empty()) return false;
    const glm::dmat4 view = view_matrix(camera);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p{(corner & 1) ? world_box.max.x : world_box.min.x,
                           (corner & 2) ? world_box.max.y : world_box.min.y,
                           (corner & 4) ? world_box.max.z : world_box.min.z};
        // The camera looks down -z: view depth is -z. Written so that NaN fails.
        const double depth = -(view * glm::dvec4(p, 1.0)).z;
        if (!(depth > camera.near_plane) || !std::isfinite(depth)) return false;
    }
    return true;
}

}  // namespace homcull
