#include "truth/embree_scene.hpp"

#include <homcull/error.hpp>

#include <limits>

namespace homcull {
namespace {

void record_error(void* user, RTCError code, const char* message) {
    auto* impl = static_cast<RayScene::Impl*>(user);
    std::lock_guard<std::mutex> lock(impl->error_mutex);
    if (impl->first_error.empty())
        impl->first_error = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

void throw_if_failed(RayScene::Impl& impl, const char* what) {
    std::lock_guard<std::mutex> lock(impl.error_mutex);
    if (!impl.first_error.empty()) throw Error(std::string(what) + ": " + impl.first_error);
}

}  // namespace

RayScene::Impl::~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
}

RayScene::RayScene(const Scene& source) : RayScene(source, scene_anchor(source)) {}

RayScene::RayScene(const Scene& source, const glm::dvec3& anchor) : impl_(std::make_unique<Impl>()) {
    Impl& impl = *impl_;
    impl.device = rtcNewDevice(nullptr);
    if (!impl.device) throw Error("Embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(impl.device, record_error, &impl);
    impl.scene = rtcNewScene(impl.device);
    // Robust: no arithmetic shortcuts that could lose a hit on an edge. Context filter
    // functions: the tie check of ground_truth.cpp excludes the hit object per ray.
    rtcSetSceneFlags(impl.scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(impl.scene, RTC_BUILD_QUALITY_MEDIUM);
    impl.objects = source.objects.size();
    impl.anchor = anchor;
    if (impl.objects >= std::numeric_limits<unsigned>::max())
        throw Error(source.source + ": too many objects for Embree");

    for (std::size_t id = 0; id < source.objects.size(); ++id) {
        const Object& object = source.objects[id];
        const Mesh& mesh = source.meshes[object.mesh];
        if (mesh.triangle_count() == 0) continue;
        RTCGeometry geometry = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.positions.size()));
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangle_count()));
        if (!vertices || !indices) {
            rtcReleaseGeometry(geometry);
            throw_if_failed(impl, "Embree: cannot allocate geometry");
            throw Error("Embree: cannot allocate geometry for object " + std::to_string(id));
        }
        for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
            const glm::vec3 p = transform_point_from(object.world, mesh.positions[v], impl.anchor);
            vertices[3 * v + 0] = p.x;
            vertices[3 * v + 1] = p.y;
            vertices[3 * v + 2] = p.z;
        }
        for (std::size_t i = 0; i < mesh.indices.size(); ++i) indices[i] = mesh.indices[i];
        rtcCommitGeometry(geometry);
        rtcAttachGeometryByID(impl.scene, geometry, unsigned(id));
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(impl.scene);
    throw_if_failed(impl, ("Embree: cannot build the scene of " + source.source).c_str());
}

RayScene::~RayScene() = default;
RayScene::RayScene(RayScene&&) noexcept = default;
RayScene& RayScene::operator=(RayScene&&) noexcept = default;

std::size_t RayScene::object_count() const { return impl_->objects; }

glm::dvec3 RayScene::anchor() const { return impl_->anchor; }

RayHit RayScene::intersect(const glm::dvec3& world_origin, const glm::vec3& direction, float t_near, float t_far) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = single_ray(glm::vec3(world_origin - impl_->anchor), direction, t_near, t_far);
    rtcIntersect1(impl_->scene, &context, &rh);
    RayHit hit;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
        hit.object = rh.hit.geomID;
        hit.t = rh.ray.tfar;
        hit.normal = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    }
    return hit;
}

}  // namespace homcull
