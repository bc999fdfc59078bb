// Ground-truth visibility: Embree ray packets through every sample of the display, in
// parallel over image tiles (TBB).
#include "truth/embree_scene.hpp"

#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/truth/ground_truth.hpp>

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

namespace homcull {
namespace {

constexpr int kPacket = 8;  // rtcIntersect8: 8 consecutive samples of one row
constexpr std::uint32_t kNone = RTC_INVALID_GEOMETRY_ID;
static_assert(kNone == kNoObject, "sample ids hand Embree's 'no geometry' on as kNoObject");

// The tie check of a packet: which other objects lie within each ray's tie window. The ray
// id holds the ray's lane in the packet; hits of the lane's own object do not count.
constexpr int kMaxTies = 4;  // distinct other objects recorded per sample (more are counted as a tie, not named)
struct TieContext {
    RTCIntersectContext base;  // first: Embree hands the filter a pointer to it
    std::uint32_t hit_object[kPacket];
    std::uint32_t tied[kPacket][kMaxTies];
    int tie_count[kPacket];
};

// Records every other object's hit in the window and rejects it, so that traversal goes on to
// find them all.
void record_ties(const RTCFilterFunctionNArguments* args) {
    auto* context = reinterpret_cast<TieContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        args->valid[i] = 0;
        const unsigned lane = RTCRayN_id(args->ray, args->N, i);
        const std::uint32_t object = RTCHitN_geomID(args->hit, args->N, i);
        if (lane >= unsigned(kPacket) || object == context->hit_object[lane]) continue;
        int& count = context->tie_count[lane];
        bool known = false;
        for (int k = 0; k < std::min(count, kMaxTies); ++k) known = known || context->tied[lane][k] == object;
        if (known) continue;
        if (count < kMaxTies) context->tied[lane][count] = object;
        ++count;
    }
}

}  // namespace

TruthResult compute_ground_truth(const RayScene& rays, const Scene& scene, const Camera& camera,
                                 const TruthOptions& options) {
    validate_camera(camera);
    validate_resolution(options.resolution);
    if (options.samples < 1 || options.samples > 16) throw Error("samples per pixel axis must be in [1, 16]");
    if (!(options.tie_relative_depth >= 0.0 && options.tie_relative_depth < 1.0))
        throw Error("tie relative depth must be in [0, 1)");
    // Per-sample buffers are indexed with int coordinates and cost 5 bytes a sample.
    if (double(options.resolution.width) * options.samples * double(options.resolution.height) * options.samples > double(1 << 30))
        throw Error("ground truth: resolution x samples^2 exceeds 2^30 samples; lower the resolution or the samples");
    if (rays.object_count() != scene.objects.size()) throw Error("the ray scene was built from another scene");

    const auto start = std::chrono::steady_clock::now();
    const RTCScene rtc = rays.impl().scene;
    const int S = options.samples;
    const Resolution display = options.resolution;
    const int width = display.width * S, height = display.height * S;
    const double aspect = display.aspect();
    const CameraBasis basis = camera_basis(camera);
    const float t_near = float(camera.near_plane), t_far = float(camera.far_plane);
    // The eye relative to the Embree vertices' anchor, in double, then rounded.
    const glm::vec3 eye(camera.eye - rays.anchor());
    const float origin[3] = {eye.x, eye.y, eye.z};
    const bool orthographic = camera.ortho_height > 0.0;
    const float tie_lo = float(1.0 - options.tie_relative_depth), tie_hi = float(1.0 + options.tie_relative_depth);

    // Per sample: the object seen, and whether another object lies within the tie window.
    std::vector<std::uint32_t> ids(std::size_t(width) * std::size_t(height), kNone);
    std::vector<std::uint8_t> tied(ids.size(), 0);
    std::atomic<std::uint64_t> tie_rays{0};
    // Per object: samples at which it lies in another object's tie window (summed over tiles).
    std::vector<std::atomic<std::uint64_t>> tie_samples(scene.objects.size());

    tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 8, 0, width, 64), [&](const tbb::blocked_range2d<int>& tile) {
        RTCIntersectContext primary;
        rtcInitIntersectContext(&primary);
        TieContext tie_check;
        rtcInitIntersectContext(&tie_check.base);
        tie_check.base.filter = record_ties;
        std::uint64_t local_tie_rays = 0;

        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y) {
            const double pixel_y = (y + 0.5) / S;
            for (int x0 = tile.cols().begin(); x0 < tile.cols().end(); x0 += kPacket) {
                alignas(32) int valid[kPacket];
                RTCRayHit8 rh;
                for (int k = 0; k < kPacket; ++k) {
                    const int x = x0 + k;
                    valid[k] = x < tile.cols().end() ? -1 : 0;
                    const glm::dvec2 ndc = pixel_to_ndc(display, (x + 0.5) / S, pixel_y);
                    const glm::vec3 d(ray_direction(camera, basis, aspect, ndc));
                    if (orthographic) {  // parallel rays from the eye's plane, relative to the anchor in double
                        const glm::vec3 o(ray_origin(camera, basis, aspect, ndc) - rays.anchor());
                        rh.ray.org_x[k] = o.x, rh.ray.org_y[k] = o.y, rh.ray.org_z[k] = o.z;
                    } else {
                        rh.ray.org_x[k] = origin[0];
                        rh.ray.org_y[k] = origin[1];
                        rh.ray.org_z[k] = origin[2];
                    }
                    rh.ray.dir_x[k] = d.x;
                    rh.ray.dir_y[k] = d.y;
                    rh.ray.dir_z[k] = d.z;
                    rh.ray.tnear[k] = t_near;
                    rh.ray.tfar[k] = t_far;
                    rh.ray.time[k] = 0.0f;
                    rh.ray.mask[k] = 0xFFFFFFFFu;
                    rh.ray.id[k] = 0;
                    rh.ray.flags[k] = 0;
                    rh.hit.geomID[k] = kNone;
                    rh.hit.instID[0][k] = kNone;
                }
                rtcIntersect8(valid, rtc, &primary, &rh);

                // Tie check: from just before to just after the hit, ignoring the hit object.
                alignas(32) int tie_valid[kPacket];
                RTCRay8 tie;
                bool any = false;
                for (int k = 0; k < kPacket; ++k) {
                    const bool hit = valid[k] != 0 && rh.hit.geomID[k] != kNone;
                    tie_valid[k] = hit ? -1 : 0;
                    any = any || hit;
                    tie.org_x[k] = rh.ray.org_x[k];
                    tie.org_y[k] = rh.ray.org_y[k];
                    tie.org_z[k] = rh.ray.org_z[k];
                    tie.dir_x[k] = rh.ray.dir_x[k];
                    tie.dir_y[k] = rh.ray.dir_y[k];
                    tie.dir_z[k] = rh.ray.dir_z[k];
                    tie.tnear[k] = rh.ray.tfar[k] * tie_lo;
                    tie.tfar[k] = rh.ray.tfar[k] * tie_hi;
                    tie.time[k] = 0.0f;
                    tie.mask[k] = 0xFFFFFFFFu;
                    tie.id[k] = unsigned(k);
                    tie.flags[k] = 0;
                    tie_check.hit_object[k] = hit ? rh.hit.geomID[k] : kNone;
                    tie_check.tie_count[k] = 0;
                }
                if (any) {
                    rtcOccluded8(tie_valid, rtc, &tie_check.base, &tie);
                    for (int k = 0; k < kPacket; ++k) local_tie_rays += tie_valid[k] != 0;
                }
                const std::size_t row = std::size_t(y) * std::size_t(width);
                for (int k = 0; k < kPacket && x0 + k < tile.cols().end(); ++k) {
                    ids[row + std::size_t(x0 + k)] = rh.hit.geomID[k];
                    tied[row + std::size_t(x0 + k)] = tie_valid[k] != 0 && tie_check.tie_count[k] > 0;
                    if (tie_valid[k] == 0) continue;
                    for (int n = 0; n < std::min(tie_check.tie_count[k], kMaxTies); ++n)
                        tie_samples[tie_check.tied[k][n]].fetch_add(1, std::memory_order_relaxed);
                }
            }
        }
        tie_rays += local_tie_rays;
    });

    TruthResult result;
    result.sample_width = width;
    result.sample_height = height;
    result.objects.resize(scene.objects.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
        if (ids[i] == kNone) continue;
        ObjectVisibility& v = result.objects[ids[i]];
        ++v.visible_samples;
        v.robust_samples += tied[i] == 0;
    }
    for (std::size_t id = 0; id < scene.objects.size(); ++id) result.objects[id].tie_samples = tie_samples[id].load();
    const FrustumAxes frustum = frustum_axes(make_frustum(camera, aspect));  // once, not per object
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, scene.objects.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i)
            result.objects[i].in_frustum = !separated(frustum, scene.objects[i].world_bounds);
    });
    result.rays = ids.size() + tie_rays.load();
    if (options.keep_sample_ids) result.sample_ids = std::move(ids);
    result.trace_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace homcull
