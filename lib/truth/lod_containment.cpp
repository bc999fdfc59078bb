// Step 4 of the occluder LOD build: the containment check with Embree. A triangle mesh as a
// robust Embree scene that answers segment queries and counts every triangle a ray crosses
// (a filter that records and rejects each hit); on top of it, the check that no edge of S
// meets O, no edge of O meets S, and every vertex of S has odd parity in three directions.
#include "truth/lod_containment.hpp"

#include <algorithm>
#include <limits>

namespace homcull::detail::lod {
namespace {

// The context a filter function sees, extended with the triangles it was shown.
struct HitCollector {
    RTCIntersectContext context;  // first, so that the filter can cast back
    std::vector<unsigned> triangles;
};

// Records each hit and rejects it, so that traversal goes on to every triangle on the ray.
// A triangle could be shown twice (Embree does not promise otherwise), hence the unique().
void collect_and_reject(const RTCFilterFunctionNArguments* args) {
    auto* collector = reinterpret_cast<HitCollector*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        collector->triangles.push_back(RTCHitN_primID(args->hit, args->N, i));
        args->valid[i] = 0;
    }
}

RTCRay make_ray(const glm::vec3& origin, const glm::vec3& direction, float t_far) {
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

}  // namespace

TriangleScene::TriangleScene(RTCDevice device, const std::vector<glm::vec3>& positions,
                             const std::vector<std::uint32_t>& indices)
    : scene_(rtcNewScene(device)) {
    if (!scene_) return;
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geometry) return;
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), positions.size()));
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

TriangleScene::~TriangleScene() {
    if (scene_) rtcReleaseScene(scene_);
}

bool TriangleScene::segment_hits(const glm::vec3& a, const glm::vec3& b) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = make_ray(a, b - a, 1.0f);
    rtcOccluded1(scene_, &context, &ray);
    return ray.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
}

std::size_t TriangleScene::crossings(const glm::vec3& origin, const glm::vec3& direction) const {
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

bool contained(const TriangleMesh& o, const TriangleScene& o_scene, const TriangleMesh& s, RTCDevice device) {
    for (const glm::vec3& p : s.positions)
        if (!inside_by_parity(p, o_scene)) return false;  // the cheapest way to fail first
    const TriangleScene s_scene(device, s.positions, s.indices);
    return s_scene.ok() && no_edge_meets(s, o_scene) && no_edge_meets(o, s_scene);
}

}  // namespace homcull::detail::lod
