// "No heap allocation per frame once the buffer is set up": after a buffer's first frame, its
// renders (every kind of input, with and without a job system) and its queries allocate
// nothing. Counted by replacing the global operator new for this test binary: it forwards to
// malloc and counts while a test asks it to.
#include "support.hpp"

#include <homcull/generate.hpp>
#include <homcull/homcull.h>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occluder_lod.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/scene_sort.hpp>
#include <homcull/visibility_sort.hpp>
#include <homcull/world_triangles.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <vector>

namespace {

// Only the counting thread's allocations count (a full run of the binary may have other
// threads, a job system's say, allocating at the same time).
thread_local bool counting = false;
std::atomic<std::size_t> allocations{0}, allocated_bytes{0};

void* counted_allocation(std::size_t size, std::size_t alignment) {
    if (counting) {
        allocations.fetch_add(1, std::memory_order_relaxed);
        allocated_bytes.fetch_add(size, std::memory_order_relaxed);
    }
    if (size == 0) size = 1;
    void* p = alignment <= alignof(std::max_align_t) ? std::malloc(size) : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
    if (!p) throw std::bad_alloc();
    return p;
}

}  // namespace

void* operator new(std::size_t size) { return counted_allocation(size, 0); }
void* operator new[](std::size_t size) { return counted_allocation(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) { return counted_allocation(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return counted_allocation(size, std::size_t(a)); }
// The nothrow forms too: the library's are not replaced with the others, so std::stable_sort's
// buffer (nothrow new) would otherwise come from the library's allocator and be freed here
// (AddressSanitizer reports that mismatch).
static void* nothrow_allocation(std::size_t size, std::size_t alignment) noexcept {
    try {
        return counted_allocation(size, alignment);
    } catch (const std::bad_alloc&) {
        return nullptr;
    }
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return nothrow_allocation(size, 0); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return nothrow_allocation(size, 0); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept { return nothrow_allocation(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept { return nothrow_allocation(size, std::size_t(a)); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace homcull {
namespace {

// The allocations the calling thread makes in `work`, and their bytes (freed or not).
struct Allocated {
    std::size_t count = 0, bytes = 0;
};
template <typename Work>
Allocated allocated_in(Work&& work) {
    allocations.store(0);
    allocated_bytes.store(0);
    counting = true;
    work();
    counting = false;
    return {allocations.load(), allocated_bytes.load()};
}
template <typename Frame>
std::size_t allocations_of(Frame&& frame) {
    return allocated_in(frame).count;
}

TEST(FrameAllocations, NoneAfterTheFirstFrame) {
    const std::vector<float> soup_xyzw = test::random_clip_triangles(5, 4000, 0.3f);
    const TriangleInput soup = test::clip_space_input(soup_xyzw);
    const test::CityStreet street;
    const Scene& city = street.city;
    const WorldTriangles& occluders = street.occluders;
    const OccluderClusters clusters = test::cluster_world(occluders);
    const std::array<float, 16> clip = street.clip(320.0 / 180.0);
    const TriangleInput city_input = occluders.input(clip);
    const ClusteredInput clustered{&clusters, clip, Backface::none};

    // Queries: rectangles, boxes (the scene's objects) and one object's triangles.
    const std::vector<ScreenRect> rects = test::random_screen_rects(3, 200);
    std::vector<Aabb> boxes;
    for (const Object& o : city.objects) boxes.push_back(o.world_bounds);
    const WorldTriangles occludee = gather_world_triangles(city, {std::uint32_t(city.objects.size() - 1)});
    const TriangleInput occludee_input = occludee.input(clip);
    std::vector<Visibility> answers(std::max(rects.size(), boxes.size()));

    const ParallelFor serial{}, job_system{&test::run_backwards, nullptr, 2};
    for (const bool sample_depth : {false, true})
        for (const ParallelFor* parallel : {&serial, &job_system}) {
            const std::string what = std::string(sample_depth ? "per-sample depth, " : "") + (parallel->run ? "job system" : "serial");
            OcclusionBuffer buffer(test::buffer_config(320, 180, 1, float(street.camera.near_plane), sample_depth));
            const auto frames = [&] {
                buffer.render_frame(soup, *parallel);
                buffer.render_frame(city_input, *parallel);
                buffer.render_frame(clustered, *parallel);
                buffer.render(city_input, *parallel);  // a second input into the same frame
            };
            const auto queries = [&] {
                for (const ScreenRect& r : rects) (void)buffer.test_rect(r.ndc_min_x, r.ndc_min_y, r.ndc_max_x, r.ndc_max_y, r.w_min);
                buffer.test_rects(rects.data(), rects.size(), answers.data());
                for (const Aabb& b : boxes) (void)buffer.test_aabb(&b.min.x, &b.max.x, clip);
                buffer.test_aabbs(boxes.data(), boxes.size(), clip, answers.data());
                (void)buffer.test_triangles(occludee_input);
            };
            frames();  // the first frame may allocate (draw order, scratch sized to the input)
            queries();
            EXPECT_EQ(allocations_of(frames), 0u) << what;
            EXPECT_EQ(allocations_of(queries), 0u) << what;
            EXPECT_GT(buffer.stats().rasterized, 0u) << what;  // the frames drew something
        }
}

// check(config, job system, what) for a 320x180 culler of every strategy, drawing clusters or
// triangles, on one thread and through a job system.
template <typename Check>
void for_each_frame_setup(Check&& check) {
    const ParallelFor serial{}, job_system{&test::run_backwards, nullptr, 2};
    for (const CullStrategy strategy : {CullStrategy::temporal, CullStrategy::one_pass, CullStrategy::progressive})
        for (const bool clusters : {true, false})
            for (const ParallelFor* parallel : {&serial, &job_system}) {
                SceneCullerConfig config;
                config.display = {320, 180};
                config.occluder_clusters = clusters;
                config.strategy = strategy;
                check(config, *parallel,
                      std::string(parallel->run ? "job system" : "serial") + (clusters ? ", clusters" : ", triangles") + ", strategy " +
                          std::to_string(int(strategy)));
            }
}

// SceneCuller frames allocate nothing, from the first on (the culler reserves its worst frame
// when it is made), on one thread and with a job system, drawing clusters or triangles, and a
// new near plane is no exception: the buffer and the maps take it in place (they were rebuilt,
// about 15 MB at 720p). Only the caller's answers vector may grow, on its first frame. The
// answers with the new near plane are a fresh culler's.
TEST(FrameAllocations, SceneCullerFramesNoneFromTheFirstNearPlaneChangesIncluded) {
    const test::CityStreet street;
    const std::vector<std::uint32_t> candidates = occluder_candidates(street.city, OccluderFilter::role);
    Camera other = street.camera, farther = street.camera;
    other.eye += glm::dvec3(4.0, 0.5, 10.0);
    farther.near_plane = 0.35;
    for_each_frame_setup([&](const SceneCullerConfig& config, const ParallelFor& parallel, const std::string& what) {
        SceneCuller culler(street.city, candidates, config);
        std::vector<OccludeeAnswer> answers(street.city.objects.size());
        EXPECT_EQ(allocations_of([&] {
                      culler.cull(street.camera, answers, parallel);
                      culler.cull(farther, answers, parallel);
                      culler.cull(other, answers, parallel);
                      culler.cull(farther, answers, parallel);
                      culler.cull(street.camera, answers, parallel);
                  }),
                  0u)
            << what;
        culler.cull(farther, answers, parallel);
        SceneCuller fresh(street.city, candidates, config);
        std::vector<OccludeeAnswer> fresh_answers;
        fresh.cull(farther, fresh_answers, parallel);
        ASSERT_EQ(answers.size(), fresh_answers.size()) << what;
        std::size_t occluded = 0;
        for (std::size_t id = 0; id < answers.size(); ++id) {
            EXPECT_EQ(answers[id].visibility, fresh_answers[id].visibility) << what << ", object " << id;
            occluded += answers[id].visibility == Visibility::occluded;
        }
        EXPECT_GT(occluded, 10u) << what;  // the frames culled something
    });
}

// A culler told that no job system will come (SceneCullerConfig::job_system false) reserves
// less when it is made (not the room of the draws a job system runs: with clusters, the task
// list's set-up pool), still allocates nothing in a frame on its own thread, and, given a job
// system anyway, answers as a culler that reserved for one.
TEST(FrameAllocations, SceneCullerWithoutAJobSystemReservesLessAndAnswersTheSame) {
    const test::CityStreet street;
    const std::vector<std::uint32_t> candidates = occluder_candidates(street.city, OccluderFilter::role);
    Camera other = street.camera;
    other.eye += glm::dvec3(4.0, 0.5, 10.0);
    const ParallelFor serial{}, job_system{&test::run_backwards, nullptr, 2};
    for (const bool clusters : {true, false}) {
        const std::string what = clusters ? "clusters" : "triangles";
        SceneCullerConfig reserving;
        reserving.display = {320, 180};
        reserving.occluder_clusters = clusters;
        SceneCullerConfig light = reserving;
        light.job_system = false;
        const std::size_t reserving_bytes = allocated_in([&] { const SceneCuller c(street.city, candidates, reserving); }).bytes;
        const std::size_t light_bytes = allocated_in([&] { const SceneCuller c(street.city, candidates, light); }).bytes;
        EXPECT_LT(light_bytes, reserving_bytes) << what;
        SceneCuller with_room(street.city, candidates, reserving), without_room(street.city, candidates, light);
        std::vector<OccludeeAnswer> answers(street.city.objects.size()), light_answers(street.city.objects.size());
        EXPECT_EQ(allocations_of([&] {
                      without_room.cull(street.camera, light_answers, serial);
                      without_room.cull(other, light_answers, serial);
                  }),
                  0u)
            << what;
        std::size_t occluded = 0;
        for (const Camera& camera : {street.camera, other, street.camera}) {
            with_room.cull(camera, answers, job_system);
            without_room.cull(camera, light_answers, job_system);
            for (std::size_t id = 0; id < answers.size(); ++id) {
                EXPECT_EQ(answers[id].visibility, light_answers[id].visibility) << what << ", object " << id;
                occluded += answers[id].visibility == Visibility::occluded;
            }
        }
        EXPECT_GT(occluded, 10u) << what;  // the frames culled something
    }
}

// Occluders drawn with their LODs (SceneCullerConfig::lods) allocate nothing in a frame either,
// every strategy, clusters or triangles, on one thread and with a job system. Each LOD here is
// its mesh itself (the path is the same; what makes a real LOD is homcull::truth's build).
TEST(FrameAllocations, SceneCullerFramesWithLodsNone) {
    const test::CityStreet street;
    const std::vector<std::uint32_t> candidates = occluder_candidates(street.city, OccluderFilter::role);
    OccluderLods lods;
    lods.lod_of_mesh.assign(street.city.meshes.size(), -1);
    lods.status_of_mesh.assign(street.city.meshes.size(), LodStatus::not_requested);
    lods.built_for_object.assign(street.city.objects.size(), 0);
    for (const std::uint32_t id : candidates) {
        const std::uint32_t mesh = street.city.objects[id].mesh;
        lods.built_for_object[id] = 1;
        if (lods.lod_of_mesh[mesh] >= 0) continue;
        lods.lod_of_mesh[mesh] = std::int32_t(lods.lods.size());
        lods.status_of_mesh[mesh] = LodStatus::built;
        lods.lods.push_back(OccluderLod{street.city.meshes[mesh], mesh, 0, 1, 0.0f});
    }
    Camera other = street.camera;
    other.eye += glm::dvec3(4.0, 0.5, 10.0);
    for_each_frame_setup([&](SceneCullerConfig config, const ParallelFor& parallel, const std::string& what) {
        config.lods = &lods;
        SceneCuller culler(street.city, candidates, config);
        std::vector<OccludeeAnswer> answers(street.city.objects.size());
        std::size_t drawn_with_lod = 0;
        EXPECT_EQ(allocations_of([&] {
                      for (const Camera& camera : {street.camera, other, street.camera}) {
                          culler.cull(camera, answers, parallel);
                          drawn_with_lod += culler.work().occluder_lods;
                      }
                  }),
                  0u)
            << what;
        EXPECT_GT(drawn_with_lod, 0u) << what;  // the frames drew LODs
    });
}

// After OcclusionBuffer::reserve, not even the first frame allocates: every resolution within
// the reserve, every kind of input, on one thread and through job systems of two and three
// threads. The inputs include a clip-space soup (drawn in parts of rows), an indexed one of many
// waves of chunks and one whose chunks clip into more triangles than their room.
TEST(FrameAllocations, NoneFromTheFirstFrameAfterAReserve) {
    const std::vector<float> soup_xyzw = test::random_clip_triangles(5, 4000, 0.3f);
    const TriangleInput soup = test::clip_space_input(soup_xyzw);
    const std::vector<float> many_xyzw = test::random_clip_triangles(6, 70000, 0.05f);
    std::vector<std::uint32_t> many_indices(many_xyzw.size() / 4);
    for (std::size_t k = 0; k < many_indices.size(); ++k) many_indices[k] = std::uint32_t(k);
    TriangleInput many = test::clip_space_input(many_xyzw);
    many.clip_space = false;  // indexed: through the identity matrix
    many.indices = many_indices.data();
    std::vector<float> crossing_xyzw = test::random_clip_triangles(7, 5000, 0.2f, 0.8f);
    for (std::size_t v = 0; v < crossing_xyzw.size(); v += 12) {  // each triangle's first vertex behind the near plane
        for (int c = 0; c < 4; ++c) crossing_xyzw[v + std::size_t(c)] *= 0.02f / crossing_xyzw[v + 3];  // w 0.02, the near plane 0.1
    }
    TriangleInput crossing = test::clip_space_input(crossing_xyzw);
    crossing.clip_space = false;
    crossing.indices = many_indices.data();
    const test::CityStreet street;
    const WorldTriangles& occluders = street.occluders;
    const OccluderClusters clusters = test::cluster_world(occluders);
    const std::array<float, 16> clip = street.clip(320.0 / 180.0);
    const TriangleInput city_input = occluders.input(clip);
    const ClusteredInput clustered{&clusters, clip, Backface::none};

    BufferReserve reserve;
    reserve.max_width = 640, reserve.max_height = 360;
    reserve.max_triangles = many.triangle_count;
    reserve.max_vertices = many.vertex_count;
    reserve.max_clusters = reserve.max_task_list_clusters = clusters.clusters.size();
    reserve.max_task_list_triangles = occluders.triangle_count();
    reserve.max_task_list_draws = 1;
    for (const OccluderCluster& c : clusters.clusters)
        reserve.max_cluster_vertices = std::max<std::size_t>(reserve.max_cluster_vertices, c.vertex_count);
    reserve.max_threads = 3;
    const ParallelFor serial{}, two{&test::run_backwards, nullptr, 2}, three{&test::run_backwards, nullptr, 3};
    for (const bool sample_depth : {false, true}) {
        OcclusionBuffer buffer(test::buffer_config(320, 180, 1, float(street.camera.near_plane), sample_depth));
        buffer.reserve(reserve);
        for (const ParallelFor* parallel : {&three, &serial, &two})
            for (const std::array<int, 2> size : {std::array<int, 2>{640, 360}, {333, 97}, {320, 180}}) {
                const std::string what = std::string(sample_depth ? "per-sample depth, " : "") + std::to_string(parallel->threads) +
                                         " threads, " + std::to_string(size[0]) + "x" + std::to_string(size[1]);
                const std::size_t allocated = allocations_of([&] {
                    BufferConfig config = buffer.config();
                    config.width = size[0], config.height = size[1];
                    buffer.configure(config);
                    buffer.render_frame(many, *parallel);
                    buffer.render_frame(crossing, *parallel);
                    buffer.render_frame(soup, *parallel);
                    buffer.render_frame(city_input, *parallel);
                    buffer.render(clustered, *parallel);
                });
                EXPECT_EQ(allocated, 0u) << what;
                EXPECT_GT(buffer.stats().rasterized, 0u) << what;
            }
    }
}

// The C interface takes every byte from the engine's allocator: with a context holding one,
// making meshes and buffers, frames, draws (registered meshes and triangles), queries, a
// resolution change and destroying it all never call the global operator new; and what the
// engine gave is all given back.
// An engine's allocator that counts its calls and the blocks still live.
struct EngineAllocator {
    std::size_t calls = 0, live = 0;
    homcull_context_desc context_desc() {
        homcull_context_desc desc{};
        desc.allocator.allocate = [](void* user, std::size_t size, std::size_t alignment) -> void* {
            auto& e = *static_cast<EngineAllocator*>(user);
            ++e.calls, ++e.live;
            return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
        };
        desc.allocator.deallocate = [](void* user, void* p, std::size_t) {
            --static_cast<EngineAllocator*>(user)->live;
            std::free(p);
        };
        desc.allocator.user = this;
        return desc;
    }
};

TEST(FrameAllocations, CInterfaceTakesEveryByteFromTheEngine) {
    const test::CityStreet street;
    const WorldTriangles& occluders = street.occluders;
    EngineAllocator engine;
    const homcull_context_desc desc = engine.context_desc();
    const glm::dmat4 clip = projection_matrix(street.camera, 320.0 / 180.0) * view_matrix(street.camera);
    homcull_view view{};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) view.world_to_clip[4 * c + r] = clip[c][r];
    view.layout = HOMCULL_COLUMN_MAJOR;
    view.cull = HOMCULL_CULL_NONE;
    std::vector<homcull_box> boxes;
    for (const Object& o : street.city.objects)
        boxes.push_back({{o.world_bounds.min.x, o.world_bounds.min.y, o.world_bounds.min.z}, {o.world_bounds.max.x, o.world_bounds.max.y, o.world_bounds.max.z}});
    std::vector<homcull_visibility> answers(boxes.size());
    std::size_t occluded = 0;
    const std::size_t global = allocations_of([&] {
        homcull_context* context = nullptr;
        ASSERT_EQ(homcull_context_create(&desc, &context), HOMCULL_OK);
        homcull_mesh_desc md{};
        md.positions = occluders.positions.data();
        md.position_stride = 3 * sizeof(float);
        md.vertex_count = occluders.positions.size() / 3;
        md.indices = occluders.indices.data();
        md.index_size = 4;
        md.triangle_count = occluders.triangle_count();
        homcull_mesh* mesh = nullptr;
        ASSERT_EQ(homcull_mesh_create(context, &md, &mesh), HOMCULL_OK);
        homcull_buffer* buffer = nullptr;
        const homcull_buffer_desc bd{320, 180, 2, float(street.camera.near_plane), HOMCULL_BUFFER_SAMPLE_DEPTH, 0};
        ASSERT_EQ(homcull_buffer_create(context, &bd, &buffer), HOMCULL_OK);
        homcull_triangles triangles{};
        triangles.positions = md.positions;
        triangles.position_stride = md.position_stride;
        triangles.vertex_count = md.vertex_count;
        triangles.indices = md.indices;
        triangles.index_size = 4;
        triangles.triangle_count = md.triangle_count;
        for (int frame = 0; frame < 3; ++frame) {
            if (frame == 2) {
                ASSERT_EQ(homcull_buffer_set_resolution(buffer, 640, 360), HOMCULL_OK);
            }
            ASSERT_EQ(homcull_buffer_begin_frame(buffer, &view), HOMCULL_OK);
            ASSERT_EQ(homcull_buffer_draw_mesh(buffer, mesh, nullptr, 1), HOMCULL_OK);
            ASSERT_EQ(homcull_buffer_draw_triangles(buffer, &triangles, nullptr), HOMCULL_OK);
            ASSERT_EQ(homcull_buffer_test_boxes(buffer, boxes.data(), boxes.size(), nullptr, answers.data()), HOMCULL_OK);
            homcull_visibility v;
            ASSERT_EQ(homcull_buffer_test_triangles(buffer, &triangles, nullptr, &v), HOMCULL_OK);
        }
        for (homcull_visibility a : answers) occluded += a == HOMCULL_OCCLUDED;
        homcull_buffer_destroy(buffer);
        homcull_mesh_destroy(mesh);
        homcull_context_destroy(context);
    });
    EXPECT_EQ(global, 0u);
    EXPECT_GT(engine.calls, 20u);
    EXPECT_EQ(engine.live, 0u);
    EXPECT_GT(occluded, 0u);  // the street hides something
}

// A visibility sorter allocates nothing per frame once it has seen its frames: tumbling
// toothpicks (cycles come and go), incremental and from scratch, with and without planes.
TEST(FrameAllocations, VisibilitySortNoneAfterWarmUp) {
    ToothpickOptions options;
    options.count = 200;
    const Scene scene = generate_toothpicks(options, 0);
    VisibilitySorter sorter = make_visibility_sorter(scene);
    std::vector<std::vector<glm::mat4>> frames(8, std::vector<glm::mat4>(scene.objects.size()));
    for (std::size_t f = 0; f < frames.size(); ++f)
        for (int i = 0; i < options.count; ++i) frames[f][std::size_t(i)] = glm::mat4(toothpick_transform(options, i, int(f)));
    const glm::vec4 planes[2] = {{0, 0, -1, 30}, {0.3f, 0, -1, 40}};
    std::size_t sorted = 0;
    const auto run = [&] {
        for (const bool incremental : {true, false})
            for (const std::size_t plane_count : {std::size_t(0), std::size_t(2)})
                for (const auto& transforms : frames) {
                    SortFrame frame;
                    frame.transforms = transforms.data();
                    frame.eye = {0.0f, 4.0f, 24.0f};
                    frame.planes = planes;
                    frame.plane_count = plane_count;
                    frame.incremental = incremental;
                    sorted += sorter.sort(frame).stats.sorted;
                }
    };
    run();  // warm-up: the sorter's scratch grows to the busiest frame (twice: the second
    run();  // starts from the first's last order, and may visit in another order)
    EXPECT_EQ(allocations_of(run), 0u);
    EXPECT_GT(sorted, 0u);
}

// The C interface's sorter: every byte from the engine's allocator, from creation (the hulls)
// to the last sort, and its answers those of the C++ sorter over the same hulls.
TEST(FrameAllocations, CInterfaceSorterTakesEveryByteFromTheEngine) {
    ToothpickOptions options;
    options.count = 150;
    const Scene scene = generate_toothpicks(options, 0);
    const Mesh& mesh = scene.meshes[0];
    EngineAllocator engine;
    const homcull_context_desc desc = engine.context_desc();
    std::vector<std::vector<float>> matrices(4, std::vector<float>(16 * scene.objects.size()));
    for (std::size_t f = 0; f < matrices.size(); ++f)
        for (int i = 0; i < options.count; ++i) {
            const glm::mat4 m(toothpick_transform(options, i, int(f)));
            for (int k = 0; k < 16; ++k) matrices[f][16 * std::size_t(i) + std::size_t(k)] = m[k / 4][k % 4];
        }
    // The test's own containers are made before counting starts.
    std::vector<std::vector<std::uint32_t>> orders(matrices.size(), std::vector<std::uint32_t>(scene.objects.size() + 1));
    std::vector<const homcull_mesh*> object_meshes(scene.objects.size());
    const std::size_t global = allocations_of([&] {
        homcull_context* context = nullptr;
        ASSERT_EQ(homcull_context_create(&desc, &context), HOMCULL_OK);
        homcull_mesh_desc md{};
        md.positions = &mesh.positions[0].x;
        md.position_stride = 3 * sizeof(float);
        md.vertex_count = mesh.positions.size();
        md.indices = mesh.indices.data();
        md.index_size = 4;
        md.triangle_count = mesh.triangle_count();
        homcull_mesh* m = nullptr;
        ASSERT_EQ(homcull_mesh_create(context, &md, &m), HOMCULL_OK);
        std::fill(object_meshes.begin(), object_meshes.end(), m);
        homcull_sorter_desc sd{object_meshes.data(), object_meshes.size()};
        homcull_sorter* sorter = nullptr;
        ASSERT_EQ(homcull_sorter_create(context, &sd, &sorter), HOMCULL_OK) << homcull_last_error();
        for (int round = 0; round < 2; ++round)
            for (std::size_t f = 0; f < matrices.size(); ++f) {
                homcull_sort_frame frame{};
                frame.model_matrices = matrices[f].data();
                frame.layout = HOMCULL_COLUMN_MAJOR;
                frame.eye[1] = 3.0f, frame.eye[2] = 22.0f;
                homcull_sort_result result{};
                ASSERT_EQ(homcull_sorter_sort(sorter, &frame, &result), HOMCULL_OK) << homcull_last_error();
                ASSERT_LE(result.order_count, scene.objects.size());
                if (round == 1) {  // the order, then a count past its end
                    std::copy(result.order, result.order + result.order_count, orders[f].begin());
                    orders[f].back() = std::uint32_t(result.order_count);
                }
            }
        homcull_sorter_destroy(sorter);
        homcull_mesh_destroy(m);
        homcull_context_destroy(context);
    });
    EXPECT_EQ(global, 0u);
    EXPECT_EQ(engine.live, 0u);
    for (auto& order : orders) order.resize(order.back());

    // The C++ sorter, over the hull of the same vertices, gives the same orders.
    const auto hull = convex_hull_points(mesh.positions.data(), mesh.positions.size(), kSortHullPoints);
    const HullPoints shape{hull.data(), hull.size()};
    const std::vector<std::uint32_t> shapes(scene.objects.size(), 0);
    VisibilitySorter sorter(&shape, 1, shapes.data(), shapes.size());
    for (int round = 0; round < 2; ++round)
        for (std::size_t f = 0; f < matrices.size(); ++f) {
            std::vector<glm::mat4> transforms(scene.objects.size());
            for (std::size_t i = 0; i < transforms.size(); ++i)
                for (int k = 0; k < 16; ++k) transforms[i][k / 4][k % 4] = matrices[f][16 * i + std::size_t(k)];
            SortFrame frame;
            frame.transforms = transforms.data();
            frame.eye = {0.0f, 3.0f, 22.0f};
            const VisibilitySort& sort = sorter.sort(frame);
            if (round == 1) {
                EXPECT_EQ(std::vector<std::uint32_t>(sort.order.begin(), sort.order.end()), orders[f]) << "frame " << f;
            }
        }
}

}  // namespace
}  // namespace homcull
