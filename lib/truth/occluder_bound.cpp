// The occluders' bound (homcull/truth/occluder_bound.hpp): one ray per pixel centre that stops
// at the first occluder hit, recording the other objects met before it; in parallel over rows
// (oneTBB).
#include "truth/embree_scene.hpp"

#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/truth/occluder_bound.hpp>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <string>

namespace homcull {
namespace {

struct Hit {
    float t;
    std::uint32_t object;
};

// The context the filter sees. An occluder's hit is accepted, so that Embree shortens the ray
// to it and shows only nearer hits after it; any other object's is recorded and rejected, so
// that traversal goes on past it (Embree 3 sets the ray's tfar to the hit's distance before
// calling the filter).
struct StopAtOccluders {
    RTCIntersectContext context;  // first, so that the filter can cast back
    const std::uint8_t* is_occluder;
    std::vector<Hit>* passed;
};

void stop_at_occluders(const RTCFilterFunctionNArguments* args) {
    auto* c = reinterpret_cast<StopAtOccluders*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const std::uint32_t object = RTCHitN_geomID(args->hit, args->N, i);
        if (c->is_occluder[object]) continue;
        c->passed->push_back({RTCRayN_tfar(args->ray, args->N, i), object});
        args->valid[i] = 0;
    }
}

}  // namespace

OccluderBound occluder_bound(const RayScene& rays, const Scene& scene, const Camera& camera, Resolution display,
                             const std::vector<std::uint32_t>& occluders) {
    validate_camera(camera);
    validate_resolution(display);
    if (camera.ortho_height > 0.0) throw Error("occluder bound: orthographic cameras are not supported (rays start at the eye)");
    const std::size_t objects = scene.objects.size();
    if (rays.object_count() != objects) throw Error("occluder bound: the ray scene was built from another scene");
    std::vector<std::uint8_t> is_occluder(objects, 0);
    for (std::uint32_t id : occluders) {
        if (id >= objects) throw Error("occluder bound: occluder id " + std::to_string(id) + " is out of range (" + std::to_string(objects) + " objects)");
        is_occluder[id] = 1;
    }
    const auto start = std::chrono::steady_clock::now();
    const PixelCentreRays pixel_rays(rays, camera, display);

    struct Local {
        std::vector<std::uint8_t> seen;
        std::uint64_t hits = 0;
    };
    tbb::combinable<Local> locals;
    tbb::parallel_for(tbb::blocked_range<int>(0, display.height, 4), [&](const tbb::blocked_range<int>& rows) {
        Local& local = locals.local();
        if (local.seen.empty()) local.seen.assign(objects, 0);
        std::vector<Hit> passed;
        StopAtOccluders context;
        rtcInitIntersectContext(&context.context);
        context.context.filter = stop_at_occluders;
        context.is_occluder = is_occluder.data();
        context.passed = &passed;
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < display.width; ++x) {
                RTCRayHit rh = pixel_rays.at(x, y);
                passed.clear();
                rtcIntersect1(pixel_rays.scene, &context.context, &rh);
                // The first occluder hit is seen; so is every other object met no farther than it
                // (a tie with an occluder's surface counts as seen: it decides nothing either way).
                if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) local.seen[rh.hit.geomID] = 1;
                for (const Hit& h : passed)
                    if (h.t <= rh.ray.tfar) {
                        local.seen[h.object] = 1;
                        ++local.hits;
                    }
            }
    });

    OccluderBound bound;
    bound.rays = std::uint64_t(display.width) * std::uint64_t(display.height);
    bound.hideable.assign(objects, 1);
    locals.combine_each([&](const Local& l) {
        bound.hits += l.hits;
        for (std::size_t id = 0; id < l.seen.size(); ++id)
            if (l.seen[id]) bound.hideable[id] = 0;
    });
    bound.trace_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bound;
}

OccluderBoundTally& OccluderBoundTally::operator+=(const OccluderBoundTally& o) {
    hidden += o.hidden;
    hideable += o.hideable;
    missed_hideable += o.missed_hideable;
    missed_not_hideable += o.missed_not_hideable;
    return *this;
}

OccluderBoundTally tally_bound(const TruthResult& truth, const OccluderBound& bound, const std::vector<OccludeeAnswer>& answers) {
    if (truth.objects.size() != bound.hideable.size() || answers.size() != bound.hideable.size())
        throw Error("occluder bound: the truth, the bound and the answers are not of one scene");
    OccluderBoundTally t;
    for (std::size_t id = 0; id < answers.size(); ++id) {
        if (!hidden_outright(truth.objects[id])) continue;
        ++t.hidden;
        t.hideable += bound.hideable[id];
        if (answers[id].visibility == Visibility::visible) ++(bound.hideable[id] ? t.missed_hideable : t.missed_not_hideable);
    }
    return t;
}

}  // namespace homcull
