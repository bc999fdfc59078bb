// What drawing occluders object by object costs against one merged call, through the C
// interface (homcull.h) on one thread: the castle's occluders (role "occluder") in views C0-C4
// of data/views/castle.json at 1280x720.
//   per object: each occluder object's registered mesh drawn with its own model matrix, one
//               homcull_buffer_draw_mesh call each, nearest object first (as an engine's scene
//               traversal draws them);
//   merged:     every occluder's world triangles registered as one mesh, one call;
//   task list:  the per-object draws recorded in a task list (homcull_buffer_begin_tasks), its
//               tasks then run in order on the calling thread: what the pull model costs on
//               one thread.
// A frame is homcull_buffer_begin_frame and the draws. Rounds alternate the three (the order
// rotated every round); the medians and their ratios are printed per view.
//
//   draw_calls_bench SCENE.glb VIEWS.json [--rounds N] [--width W --height H]
#include <homcull/homcull.hpp>

#include <homcull/camera.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/scene.hpp>

#include <glm/ext/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

using namespace homcull;

namespace {

void check(homcull_result r, const char* what) {
    if (r != HOMCULL_OK) {
        std::fprintf(stderr, "draw_calls_bench: %s: %s\n", what, homcull_last_error());
        std::exit(1);
    }
}

api::Mesh register_mesh(const api::Context& context, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices) {
    homcull_mesh_desc d{};
    d.positions = &positions[0].x;
    d.position_stride = sizeof(glm::vec3);
    d.vertex_count = positions.size();
    d.indices = indices.data();
    d.index_size = 4;
    d.triangle_count = indices.size() / 3;
    api::Mesh mesh;
    check(api::Mesh::create(context, d, mesh), "homcull_mesh_create");
    return mesh;
}

struct Draw {
    const api::Mesh* mesh;
    std::array<float, 16> model;  // column-major, anchored world
    double distance2;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: draw_calls_bench SCENE.glb VIEWS.json [--rounds N] [--width W --height H]\n");
        return 1;
    }
    int rounds = 21, width = 1280, height = 720;
    for (int i = 3; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--rounds")) rounds = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--width")) width = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--height")) height = std::atoi(argv[i + 1]);
    }
    const Scene scene = load_scene(argv[1]);
    const CameraPath views = read_camera_path(argv[2]);
    const glm::dvec3 anchor = scene_anchor(scene);
    const std::vector<std::uint32_t> occluders = occluder_candidates(scene, OccluderFilter::role);

    api::Context context;
    check(api::Context::create(homcull_context_desc{}, context), "homcull_context_create");
    // Per object: one registered mesh per scene mesh. Merged: every occluder's anchored world
    // triangles (transform_point_from, as the culler and the truth round them) in one mesh.
    std::map<std::uint32_t, api::Mesh> meshes;
    std::vector<Draw> draws;
    std::vector<glm::vec3> world;
    std::vector<std::uint32_t> world_indices;
    std::size_t triangles = 0;
    for (std::uint32_t id : occluders) {
        const Object& o = scene.objects[id];
        const Mesh& m = scene.meshes[o.mesh];
        if (m.triangle_count() == 0) continue;
        if (!meshes.count(o.mesh)) meshes[o.mesh] = register_mesh(context, m.positions, m.indices);
        const glm::dmat4 model = glm::translate(glm::dmat4(1.0), -anchor) * o.world;
        Draw d{&meshes[o.mesh], {}, 0.0};
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) d.model[std::size_t(4 * c + r)] = float(model[c][r]);
        draws.push_back(d);
        const std::uint32_t base = std::uint32_t(world.size());
        for (const glm::vec3& p : m.positions) world.push_back(transform_point_from(o.world, p, anchor));
        for (std::uint32_t i : m.indices) world_indices.push_back(base + i);
        triangles += m.triangle_count();
    }
    const api::Mesh merged = register_mesh(context, world, world_indices);

    api::Buffer buffer;
    check(api::Buffer::create(context, homcull_buffer_desc{width, height, 1, 1.0f, 0, 0}, buffer), "homcull_buffer_create");
    check(buffer.reserve(homcull_reserve_desc{width, height, triangles, 0, draws.size(), triangles, 0, 0}), "homcull_buffer_reserve");

    std::printf("%zu occluder objects (%zu triangles), %dx%d, %d rounds, instruction set %s\n", draws.size(), triangles, width, height, rounds,
                homcull_isa_name(context.isa()));
    std::printf("| view | per object (ms) | merged (ms) | task list (ms) | per object / merged | task list / per object | calls | drawn per object "
                "| drawn merged |\n|---|---|---|---|---|---|---|---|---|\n");
    double sum_objects = 0.0, sum_merged = 0.0, sum_list = 0.0;
    for (std::size_t v = 0; v < views.frames.size(); ++v) {
        Camera camera = views.frames[v];
        check(buffer.set_near(float(camera.near_plane)), "homcull_buffer_set_near");
        camera.eye -= anchor, camera.target -= anchor;
        const glm::dmat4 clip = projection_matrix(camera, double(width) / height) * view_matrix(camera);
        homcull_view view{};
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) view.world_to_clip[4 * c + r] = clip[c][r];
        view.layout = HOMCULL_COLUMN_MAJOR;
        view.cull = HOMCULL_CULL_BACK;
        for (Draw& d : draws) {
            const glm::dvec3 centre(d.model[12], d.model[13], d.model[14]);
            const glm::dvec3 to = centre - camera.eye;
            d.distance2 = glm::dot(to, to);
        }
        std::sort(draws.begin(), draws.end(), [](const Draw& a, const Draw& b) { return a.distance2 < b.distance2; });
        homcull_frame_stats objects_stats{}, merged_stats{};
        const auto per_object = [&] {
            check(buffer.begin_frame(view), "homcull_buffer_begin_frame");
            for (const Draw& d : draws) check(buffer.draw(*d.mesh, d.model), "homcull_buffer_draw_mesh");
            objects_stats = buffer.frame_stats();
        };
        const auto one_call = [&] {
            check(buffer.begin_frame(view), "homcull_buffer_begin_frame");
            check(buffer.draw(merged), "homcull_buffer_draw_mesh");
            merged_stats = buffer.frame_stats();
        };
        homcull_frame_stats list_stats{};
        const auto task_list = [&] {
            check(buffer.begin_frame(view), "homcull_buffer_begin_frame");
            check(buffer.begin_tasks(), "homcull_buffer_begin_tasks");
            for (const Draw& d : draws) check(buffer.draw(*d.mesh, d.model), "homcull_buffer_draw_mesh");
            std::size_t tasks = 0;
            check(buffer.close_tasks(tasks), "homcull_buffer_close_tasks");
            for (std::size_t i = 0; i < tasks; ++i) check(buffer.run_task(i), "homcull_buffer_run_task");
            check(buffer.finish_tasks(), "homcull_buffer_finish_tasks");
            list_stats = buffer.frame_stats();
        };
        const auto time = [](auto&& frame) {
            const auto t0 = std::chrono::steady_clock::now();
            frame();
            return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        };
        per_object(), one_call(), task_list();  // warm
        std::vector<double> a, b, c;
        for (int r = 0; r < rounds; ++r)
            for (int k = 0; k < 3; ++k) {
                const int which = (r + k) % 3;
                if (which == 0) a.push_back(time(per_object));
                else if (which == 1) b.push_back(time(one_call));
                else c.push_back(time(task_list));
            }
        const double ma = median(a), mb = median(b), mc = median(c);
        sum_objects += ma, sum_merged += mb, sum_list += mc;
        std::printf("| C%zu | %.3f | %.3f | %.3f | %.2f | %.2f | %llu | %llu | %llu |\n", v, ma, mb, mc, ma / mb, mc / ma,
                    (unsigned long long)objects_stats.draw_calls, (unsigned long long)objects_stats.triangles_drawn,
                    (unsigned long long)merged_stats.triangles_drawn);
        if (objects_stats.allocations || merged_stats.allocations || list_stats.allocations)
            std::printf("  (frames allocated after the reserve: a bug)\n");
        if (list_stats.triangles_drawn != objects_stats.triangles_drawn) std::printf("  (the task list drew other triangles: a bug)\n");
    }
    std::printf("| all | %.3f | %.3f | %.3f | %.2f | %.2f | | | |\n", sum_objects, sum_merged, sum_list, sum_objects / sum_merged,
                sum_list / sum_objects);
    return 0;
}
