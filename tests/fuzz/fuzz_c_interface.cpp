// libFuzzer target: the C interface (homcull.h) as an engine could misuse it. Arbitrary descs
// (resolutions, samples, near distances, flags, enum values), meshes (NaN/Inf/huge positions,
// 16- and 32-bit indices out of range), views (any matrix, layout, depth range, winding),
// instanced draws, triangles, boxes, rectangles, occludee triangles, resolution and near
// changes, reserves, and an allocator that fails on a chosen call. Traps on a crash, a leak (the
// allocator's live blocks), a result outside homcull_result, or a query that fails without
// answering "visible" everywhere.
#include <homcull/homcull.h>

#include "fuzz_input.hpp"

#include <cstdlib>
#include <vector>

namespace {

struct Memory {
    std::size_t calls = 0, live = 0, fail_at = 0;
};

void* allocate(void* user, std::size_t size, std::size_t alignment) {
    auto& m = *static_cast<Memory*>(user);
    if (++m.calls == m.fail_at) return nullptr;
    void* p = std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
    if (p) ++m.live;
    return p;
}

void deallocate(void* user, void* p, std::size_t) {
    --static_cast<Memory*>(user)->live;
    std::free(p);
}

void check(homcull_result r) {
    if (r < HOMCULL_OK || r > HOMCULL_ERROR_INTERNAL || r == HOMCULL_ERROR_INTERNAL) __builtin_trap();
}

// A failed query answers visible everywhere.
void check_query(homcull_result r, const homcull_visibility* v, std::size_t n) {
    check(r);
    for (std::size_t i = 0; r != HOMCULL_OK && i < n; ++i)
        if (v[i] != HOMCULL_VISIBLE) __builtin_trap();
    for (std::size_t i = 0; i < n; ++i)
        if (v[i] > HOMCULL_VIEW_CULLED) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    homcull::fuzz::Bytes in(data, size);
    Memory memory;
    memory.fail_at = in.below(400);  // 0: never
    homcull_context_desc cd{};
    cd.allocator = {allocate, deallocate, &memory};
    cd.isa = in.flag() ? HOMCULL_ISA_SCALAR : HOMCULL_ISA_BEST;
    homcull_context* context = nullptr;
    check(homcull_context_create(&cd, &context));
    if (!context) {
        if (memory.live != 0) __builtin_trap();
        return 0;
    }

    // A mesh of up to 24 vertices, 16 triangles, its positions every `stride` bytes (the array
    // always holds them: a stride below 12 is refused before anything is read).
    static constexpr std::size_t kStrides[] = {12, 16, 24, 8, 0};
    const std::size_t stride = kStrides[in.below(5)];
    const std::size_t vertices = in.below(25), triangles = in.below(17);
    std::vector<float> positions(vertices * (stride < 12 ? 12 : stride) / 4);
    for (float& p : positions) p = in.flag() ? in.take<float>() : float(int(in.below(41)) - 20);
    const bool small = in.flag();
    std::vector<std::uint16_t> i16(3 * triangles);
    std::vector<std::uint32_t> i32(3 * triangles);
    for (std::size_t i = 0; i < 3 * triangles; ++i) i16[i] = std::uint16_t(i32[i] = in.below(vertices + 2));
    homcull_mesh_desc md{};
    md.positions = positions.empty() ? nullptr : positions.data();
    md.position_stride = stride;
    md.vertex_count = vertices;
    md.indices = in.flag() ? nullptr : small ? static_cast<const void*>(i16.data()) : i32.data();
    md.index_size = small ? 2 : in.flag() ? 4 : in.below(9);
    md.triangle_count = triangles;
    homcull_mesh* mesh = nullptr;
    check(homcull_mesh_create(context, &md, &mesh));
    homcull_triangles tris{md.positions, md.position_stride, md.vertex_count, md.indices, md.index_size, 0, md.triangle_count};

    homcull_buffer_desc bd{int(in.below(300)) - 2, int(in.below(200)) - 2, int(in.below(6)), in.flag() ? in.take<float>() : 0.1f,
                           in.below(3), 0};
    homcull_buffer* buffer = nullptr;
    check(homcull_buffer_create(context, &bd, &buffer));

    for (int step = 0; buffer && step < 6 && in.left() > 0; ++step) {
        switch (in.below(7)) {
            case 0: check(homcull_buffer_set_resolution(buffer, int(in.below(400)) - 2, int(in.below(300)) - 2)); break;
            case 1: check(homcull_buffer_set_near(buffer, in.take<float>())); break;
            case 2: {
                const homcull_reserve_desc r{int(in.below(600)), int(in.below(400)), in.below(5000), in.below(5000), in.below(9), in.below(5000), std::uint32_t(in.below(5)), 0};
                check(homcull_buffer_reserve(buffer, &r));
                break;
            }
            default: break;
        }
        homcull_view view{};
        for (double& m : view.world_to_clip) m = in.flag() ? double(in.take<float>()) : double(int(in.below(5)) - 2);
        view.world_to_clip[in.flag() ? 11 : 14] = in.flag() ? -1.0 : 1.0;  // usually a perspective w
        view.layout = homcull_matrix_layout(in.below(3));
        view.depth_range = homcull_depth_range(in.below(3));
        view.front_face = homcull_winding(in.below(3));
        view.cull = homcull_cull(in.below(4));
        view.flags = in.below(9);
        check(homcull_buffer_begin_frame(buffer, &view));
        float models[2][16];
        for (auto& model : models)
            for (float& m : model) m = in.flag() ? in.take<float>() : float(int(in.below(3)) - 1);
        // Sometimes as a task list, its steps in or out of order, its tasks all, some or none run.
        const bool as_tasks = in.flag();
        if (as_tasks) check(homcull_buffer_begin_tasks(buffer));
        check(homcull_buffer_draw_mesh(buffer, mesh, in.flag() ? nullptr : &models[0][0], in.below(3)));
        check(homcull_buffer_draw_triangles(buffer, in.flag() ? &tris : nullptr, in.flag() ? nullptr : models[1]));
        if (as_tasks) {
            std::size_t tasks = 0;
            if (in.flag()) check(homcull_buffer_close_tasks(buffer, in.flag() ? &tasks : nullptr));
            const std::size_t run = in.flag() ? tasks : in.below(unsigned(tasks) + 2);
            for (std::size_t i = run; i-- > 0;) check(homcull_buffer_run_task(buffer, i));
            if (in.flag()) check(homcull_buffer_finish_tasks(buffer));  // else the list stays open into the queries and the next frame
        }
        homcull_box boxes[4];
        for (homcull_box& b : boxes)
            for (int k = 0; k < 3; ++k) b.min[k] = in.take<float>(), b.max[k] = in.flag() ? b.min[k] + float(in.below(9)) : in.take<float>();
        homcull_visibility answers[4];
        check_query(homcull_buffer_test_boxes(buffer, boxes, 4, in.flag() ? nullptr : models[0], answers), answers, 4);
        homcull_rect rects[2];
        for (homcull_rect& r : rects) r = {in.take<float>(), in.take<float>(), in.take<float>(), in.take<float>(), in.take<float>()};
        check_query(homcull_buffer_test_rects(buffer, rects, 2, answers), answers, 2);
        check_query(homcull_buffer_test_triangles(buffer, &tris, in.flag() ? nullptr : models[1], answers), answers, 1);
        homcull_triangle_test_desc test_desc{};
        test_desc.first_triangle = in.below(8);
        test_desc.tolerated_samples = in.flag() ? in.below(64) : 0;
        test_desc.flags = std::uint32_t(in.below(4));  // 2 and 3: unknown flags
        test_desc.orientation = int(in.below(4)) - 2;
        for (double& e : test_desc.eye) e = in.flag() ? double(in.take<float>()) : double(int(in.below(41)) - 20);
        homcull_triangle_test_result tested;
        const homcull_result r = homcull_buffer_test_triangles_ex(buffer, &tris, in.flag() ? nullptr : models[1], in.flag() ? nullptr : &test_desc, &tested);
        check_query(r, &tested.visibility, 1);
        if (r == HOMCULL_OK && tested.visible_samples > tested.samples) __builtin_trap();
        homcull_frame_stats stats;
        check(homcull_buffer_frame_stats(buffer, &stats));
    }
    homcull_buffer_destroy(buffer);
    homcull_mesh_destroy(mesh);
    homcull_context_destroy(context);
    if (memory.live != 0) __builtin_trap();
    return 0;
}
