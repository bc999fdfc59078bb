// The C99 engine host (tests/c_host/engine_host.c) walks the castle through homcull.h: a
// left-handed world, reversed depth, row-major matrices, occluders drawn object by object,
// boxes queried from two threads, a resolution and a near-plane change in mid-walk. Checked
// here: zero false culls against Embree, the same answers as the C++ interface given the same
// draws, zero allocations after the reserve (the host checks), and the allocation-failure sweep.
#include "support.hpp"

#include <homcull/io/scene_io.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/walk_path.hpp>

#include "capi/view_conventions.hpp"

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>

namespace homcull {
namespace {

struct HostWalk {
    std::vector<std::uint32_t> meshes;     // scene mesh of each walk mesh
    std::vector<std::uint32_t> occluders;  // object ids
    std::vector<std::uint32_t> occluder_mesh;
    std::vector<std::array<float, 16>> models;  // column-major, right-handed, anchored
    std::vector<Aabb> boxes;                    // every object's, anchored
    std::vector<Camera> cameras;                // anchored
    std::vector<Resolution> resolutions;
};

template <typename T>
void put(std::ofstream& out, const T& v) {
    out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

// The walk file engine_host.c reads (its header comment has the format).
void write_walk(const std::string& path, const Scene& scene, const HostWalk& w) {
    std::ofstream out(path, std::ios::binary);
    out.write("HCWALK1", 8);
    put(out, std::uint32_t(1));  // samples
    put(out, std::uint32_t(w.meshes.size()));
    for (std::uint32_t m : w.meshes) {
        const Mesh& mesh = scene.meshes[m];
        put(out, std::uint32_t(mesh.positions.size()));
        put(out, std::uint32_t(mesh.triangle_count()));
        out.write(reinterpret_cast<const char*>(mesh.positions.data()), std::streamsize(mesh.positions.size() * sizeof(glm::vec3)));
        out.write(reinterpret_cast<const char*>(mesh.indices.data()), std::streamsize(mesh.indices.size() * sizeof(std::uint32_t)));
    }
    put(out, std::uint32_t(w.occluders.size()));
    for (std::size_t i = 0; i < w.occluders.size(); ++i) {
        put(out, w.occluder_mesh[i]);
        put(out, w.models[i]);
    }
    put(out, std::uint32_t(w.boxes.size()));
    for (const Aabb& b : w.boxes) {
        const float v[6] = {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z};
        put(out, v);
    }
    put(out, std::uint32_t(w.cameras.size()));
    for (std::size_t f = 0; f < w.cameras.size(); ++f) {
        const Camera& c = w.cameras[f];
        const double v[12] = {c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_degrees, c.near_plane, c.far_plane};
        put(out, v);
        put(out, std::int32_t(w.resolutions[f].width));
        put(out, std::int32_t(w.resolutions[f].height));
    }
    ASSERT_TRUE(out.good()) << path;
}

// runs x frames x boxes answers (engine_host.c's write_answers).
std::vector<std::uint8_t> read_answers(const std::string& path, std::uint32_t& runs, std::uint32_t& frames, std::uint32_t& boxes) {
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(&runs), 4);
    in.read(reinterpret_cast<char*>(&frames), 4);
    in.read(reinterpret_cast<char*>(&boxes), 4);
    std::vector<std::uint8_t> answers(std::size_t(runs) * frames * boxes);
    in.read(reinterpret_cast<char*>(answers.data()), std::streamsize(answers.size()));
    EXPECT_TRUE(in.good()) << path;
    return answers;
}

// The host's input: the occluders' meshes and placements, every object's box, the cameras. Every
// frame at `fixed` when it is given; else, a walk: 640x360, then 800x450 from the third of the
// walk on and a farther near plane (0.3) from two thirds on.
HostWalk castle_walk(const Scene& castle, const std::vector<std::uint32_t>& occluders, const CameraPath& path, Resolution fixed = {}) {
    HostWalk w;
    const glm::dvec3 anchor = scene_anchor(castle);
    std::map<std::uint32_t, std::uint32_t> walk_mesh;
    for (std::uint32_t id : occluders) {
        const Object& o = castle.objects[id];
        if (castle.meshes[o.mesh].triangle_count() == 0) continue;
        const auto [it, added] = walk_mesh.emplace(o.mesh, std::uint32_t(w.meshes.size()));
        if (added) w.meshes.push_back(o.mesh);
        w.occluders.push_back(id);
        w.occluder_mesh.push_back(it->second);
        const glm::dmat4 model = glm::translate(glm::dmat4(1.0), -anchor) * o.world;
        std::array<float, 16> m;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[std::size_t(4 * c + r)] = float(model[c][r]);
        w.models.push_back(m);
    }
    for (const Object& o : castle.objects) w.boxes.push_back(anchored_box(o.world_bounds, anchor));
    for (std::size_t f = 0; f < path.frames.size(); ++f) {
        Camera c = path.frames[f];
        // Mid-walk: a larger display from the third of the walk on, a farther near plane from
        // two thirds on.
        if (fixed.width > 0) {
            w.resolutions.push_back(fixed);
        } else {
            if (3 * f >= 2 * path.frames.size()) c.near_plane = 0.3;
            w.resolutions.push_back(3 * f >= path.frames.size() ? Resolution{800, 450} : Resolution{640, 360});
        }
        c.eye -= anchor, c.target -= anchor;
        w.cameras.push_back(c);
    }
    return w;
}

// The orthographic walk's cameras are as high as the perspective ones at this distance (world
// units: about a courtyard of the castle).
constexpr double kOrthographicDistance = 60.0;

// The cameras relative to the anchor back in the scene's world, for ground truth; orthographic:
// as engine_host --orthographic D makes its cameras.
Camera world_camera(Camera c, const Scene& scene, bool orthographic = false) {
    const glm::dvec3 anchor = scene_anchor(scene);
    if (orthographic) c.ortho_height = 2.0 * std::tan(glm::radians(c.fov_y_degrees) * 0.5) * kOrthographicDistance;
    c.eye += anchor, c.target += anchor;
    return c;
}

// The host's castle walk, perspective or orthographic: zero false culls against Embree at every
// frame's resolution, most hidden objects culled, and the same answers as the C++ interface
// given the host's cameras and draw order.
void check_castle_walk_from_c99_host(bool orthographic) {
    const std::string file = test::shared_scene("intel_castle.glb");
    if (file.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene castle = load_scene(file);
    const RayScene rays(castle);
    WalkOptions options;
    options.frames = 24;
    options.seed = 7;
    const HostWalk walk = castle_walk(castle, occluder_candidates(castle, OccluderFilter::role), walk_path(rays, castle, options));
    const std::string dir = test::temp_dir(orthographic ? "EngineHost.OrthographicCastleWalk" : "EngineHost.CastleWalk");
    write_walk(dir + "/castle.walk", castle, walk);
    const std::string command =
        std::string(HOMCULL_ENGINE_HOST) + (orthographic ? " --orthographic " + std::to_string(kOrthographicDistance) + " " : " ") + dir +
        "/castle.walk " + dir + "/answers";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    std::uint32_t runs, frames, boxes;
    const std::vector<std::uint8_t> answers = read_answers(dir + "/answers", runs, frames, boxes);
    ASSERT_EQ(runs, 1u);
    ASSERT_EQ(frames, walk.cameras.size());
    ASSERT_EQ(boxes, castle.objects.size());

    // Ground truth at each frame's resolution: no object answered hidden may be seen.
    std::size_t false_culls = 0, hidden = 0, culled_hidden = 0;
    std::vector<std::uint8_t> in_frustum(std::size_t(frames) * boxes);  // truth's exact frustum test
    for (std::uint32_t f = 0; f < frames; ++f) {
        TruthOptions truth_options;
        truth_options.resolution = walk.resolutions[f];
        const TruthResult truth = compute_ground_truth(rays, castle, world_camera(walk.cameras[f], castle, orthographic), truth_options);
        for (std::uint32_t id = 0; id < boxes; ++id) {
            const std::uint8_t a = answers[std::size_t(f) * boxes + id];
            const ObjectVisibility& t = truth.objects[id];
            in_frustum[std::size_t(f) * boxes + id] = t.in_frustum;
            if (a != 0 && t.visible_samples > 0) {
                ++false_culls;
                ADD_FAILURE() << "frame " << f << ": object " << id << " (" << castle.objects[id].name << ") answered " << int(a) << " but "
                              << t.visible_samples << " samples see it";
            }
            const bool hidden_outright = t.in_frustum && t.visible_samples == 0 && t.tie_samples == 0;
            hidden += hidden_outright;
            culled_hidden += hidden_outright && a == 1;
        }
    }
    EXPECT_EQ(false_culls, 0u);
    // An orthographic view's near plane is as wide as its view: every box that the eye's plane
    // cuts (walls and houses beside the walker) is answered visible, so it culls less.
    EXPECT_GT(culled_hidden, orthographic ? hidden / 4 : hidden / 2) << "the walk culls little: " << culled_hidden << " of " << hidden;
    std::printf("engine host %s walk: %zu of %zu objects hidden outright culled, %zu false culls\n", orthographic ? "orthographic" : "perspective",
                culled_hidden, hidden, false_culls);

    // The C++ interface, given the host's cameras and draw order (its trace), answers the same,
    // but for the boxes the C interface's exact frustum test alone finds outside the view
    // (view-culled where the buffer's rectangle test says visible): those must lie outside
    // truth's frustum.
    std::ifstream trace(dir + "/answers.trace", std::ios::binary);
    std::vector<OccluderClusters> clusters;
    for (std::uint32_t m : walk.meshes) {
        const Mesh& mesh = castle.meshes[m];
        const std::size_t t = mesh.triangle_count();
        std::vector<std::uint8_t> shared(t);
        std::vector<std::uint32_t> apexes(3 * t);
        compute_shared_edges(&mesh.positions[0].x, 12, mesh.positions.size(), mesh.indices.data(), t, shared.data(), apexes.data());
        clusters.push_back(build_occluder_clusters(&mesh.positions[0].x, 12, mesh.positions.size(), mesh.indices.data(), t, shared.data(),
                                                   apexes.data()));
    }
    std::size_t differing = 0, exact_view_culls = 0;
    for (std::uint32_t f = 0; f < frames; ++f) {
        homcull_view view{};
        trace.read(reinterpret_cast<char*>(view.world_to_clip), sizeof view.world_to_clip);
        view.layout = HOMCULL_ROW_MAJOR, view.depth_range = HOMCULL_DEPTH_ZERO_TO_ONE, view.front_face = HOMCULL_FRONT_CCW;
        view.cull = HOMCULL_CULL_BACK, view.flags = HOMCULL_VIEW_REVERSED_Z;
        capi::ViewConventions conventions;
        ASSERT_EQ(capi::read_view(nullptr, view, conventions), HOMCULL_OK);
        BufferConfig config = test::buffer_config(walk.resolutions[f].width, walk.resolutions[f].height, 1, float(walk.cameras[f].near_plane));
        config.orthographic = conventions.orthographic;
        ASSERT_EQ(conventions.orthographic, orthographic);
        OcclusionBuffer buffer(config);
        std::uint32_t draws = 0;
        trace.read(reinterpret_cast<char*>(&draws), 4);
        const glm::dmat4 mirror = glm::scale(glm::dmat4(1.0), glm::dvec3(1, 1, -1));  // the host's left-handed world
        for (std::uint32_t k = 0; k < draws; ++k) {
            std::uint32_t i = 0;
            trace.read(reinterpret_cast<char*>(&i), 4);
            glm::dmat4 model;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) model[c][r] = double(walk.models[i][std::size_t(4 * c + r)]);
            ClusteredInput in;
            in.clusters = &clusters[walk.occluder_mesh[i]];
            in.backface = conventions.backface;
            in.orthographic = conventions.orthographic;
            in.model_to_clip = capi::float_clip_from_model(conventions.clip_from_world, mirror * model);
            buffer.render(in);
        }
        ASSERT_TRUE(trace.good());
        std::vector<Aabb> mirrored;
        for (const Aabb& b : walk.boxes) mirrored.push_back({{b.min.x, b.min.y, -b.max.z}, {b.max.x, b.max.y, -b.min.z}});
        std::vector<Visibility> cxx(boxes);
        buffer.test_aabbs(mirrored.data(), boxes, capi::float_clip_from_model(conventions.clip_from_world, glm::dmat4(1.0)), cxx.data());
        for (std::uint32_t id = 0; id < boxes; ++id) {
            std::uint8_t expected = cxx[id] == Visibility::occluded ? 1 : cxx[id] == Visibility::view_culled ? 2 : 0;
            const float lo[3] = {mirrored[id].min.x, mirrored[id].min.y, mirrored[id].min.z};
            const float hi[3] = {mirrored[id].max.x, mirrored[id].max.y, mirrored[id].max.z};
            glm::dvec4 far_row;
            for (int c = 0; c < 4; ++c) far_row[c] = glm::dot(conventions.far_row, conventions.clip_from_world[c]);
            if (expected != 2 && capi::box_beyond_far(far_row, lo, hi)) expected = 2;
            const std::size_t at = std::size_t(f) * boxes + id;
            if (expected == 0 && answers[at] == 2 && !in_frustum[at]) {
                ++exact_view_culls;
                continue;
            }
            differing += answers[at] != expected;
        }
    }
    EXPECT_EQ(differing, 0u) << "answers that differ from the C++ interface's";
    std::printf("engine host %s walk: %zu boxes view-culled by the exact frustum test alone\n", orthographic ? "orthographic" : "perspective",
                exact_view_culls);
}

TEST(EngineHost, CastleWalkFromAC99Host) { check_castle_walk_from_c99_host(false); }
// The same walk with orthographic cameras (the host's engine_view, --orthographic).
TEST(EngineHost, OrthographicCastleWalkFromAC99Host) { check_castle_walk_from_c99_host(true); }

// The objects the host answers hidden that Embree sees, over every frame of every run in the
// answers file (runs x frames x boxes); `culled` counts the hidden answers, `kept_outside` the
// visible answers of objects outside truth's frustum (what the view test missed).
std::size_t false_culls(const RayScene& rays, const Scene& scene, const HostWalk& walk, const std::vector<std::uint8_t>& answers,
                        std::uint32_t runs, std::size_t& culled, std::size_t& kept_outside, bool orthographic = false) {
    const std::uint32_t frames = std::uint32_t(walk.cameras.size()), boxes = std::uint32_t(scene.objects.size());
    std::size_t wrong = 0;
    for (std::uint32_t f = 0; f < frames; ++f) {
        TruthOptions truth_options;
        truth_options.resolution = walk.resolutions[f];
        const TruthResult truth = compute_ground_truth(rays, scene, world_camera(walk.cameras[f], scene, orthographic), truth_options);
        for (std::uint32_t run = 0; run < runs; ++run)
            for (std::uint32_t id = 0; id < boxes; ++id) {
                const std::uint8_t a = answers[(std::size_t(run) * frames + f) * boxes + id];
                culled += a == 1;
                kept_outside += a == 0 && !truth.objects[id].in_frustum;
                wrong += a != 0 && truth.objects[id].visible_samples > 0;
            }
    }
    return wrong;
}

// Random views (the eye anywhere in the free space, any direction) at an odd resolution, on the
// castle, sponza and the castle moved 10^5 from the origin, perspective and orthographic: no
// false cull.
void check_random_views_from_c99_host(bool orthographic) {
    struct Case {
        const char* file;
        glm::dvec3 offset;
    };
    std::size_t scenes = 0;
    for (const Case& c : {Case{"intel_castle.glb", {0, 0, 0}}, Case{"crytek_sponza.glb", {0, 0, 0}}, Case{"intel_castle.glb", {1e5, 0, -1e5}}}) {
        const std::string file = test::shared_scene(c.file);
        if (file.empty()) continue;
        ++scenes;
        const Scene scene = translated_scene(load_scene(file), c.offset);
        const RayScene rays(scene);
        const HostWalk walk = castle_walk(scene, occluder_candidates(scene, OccluderFilter::size), random_views(rays, scene, 8, 11), {643, 359});
        // A folder of its own: the perspective and orthographic tests may run at once (ctest -j).
        const std::string dir = test::temp_dir(orthographic ? "EngineHost.RandomOrthographicViews" : "EngineHost.RandomViews");
        write_walk(dir + "/views.walk", scene, walk);
        const std::string command = std::string(HOMCULL_ENGINE_HOST) +
                                    (orthographic ? " --orthographic " + std::to_string(kOrthographicDistance) + " " : " ") + dir +
                                    "/views.walk " + dir + "/answers";
        ASSERT_EQ(std::system(command.c_str()), 0) << command;
        std::uint32_t runs, frames, boxes;
        const std::vector<std::uint8_t> answers = read_answers(dir + "/answers", runs, frames, boxes);
        ASSERT_EQ(boxes, scene.objects.size());
        std::size_t culled = 0, kept_outside = 0;
        EXPECT_EQ(false_culls(rays, scene, walk, answers, runs, culled, kept_outside, orthographic), 0u)
            << c.file << " moved by " << format_vec3(c.offset);
        // The exact frustum test leaves none outside the view for the engine to draw (the
        // buffer's own rectangle and plane tests kept 2, 6 and 2 of the perspective views').
        EXPECT_EQ(kept_outside, 0u) << c.file << " moved by " << format_vec3(c.offset);
        std::printf("engine host, %s moved by %s: 8 random %s views at 643x359, %zu objects answered hidden, %zu outside the view "
                    "answered visible\n",
                    c.file, format_vec3(c.offset).c_str(), orthographic ? "orthographic" : "perspective", culled, kept_outside);
    }
    if (scenes == 0) GTEST_SKIP() << "no shared scene in " << test::shared_scenes_dir();
}

TEST(EngineHost, RandomViewsOnSharedScenesFromAC99Host) { check_random_views_from_c99_host(false); }
TEST(EngineHost, RandomOrthographicViewsOnSharedScenesFromAC99Host) { check_random_views_from_c99_host(true); }

// For every k, the host's walk (a few frames of a part of the castle) with an allocator that
// fails on its k-th call: every call returns OK or out of memory, every block comes back (the
// host checks both; under AddressSanitizer, leaks and bad accesses fail it too), and no answer
// hides what Embree sees. Perspective and orthographic.
void check_allocation_failure_sweep(bool orthographic) {
    const std::string file = test::shared_scene("intel_castle.glb");
    if (file.empty()) GTEST_SKIP() << "intel_castle.glb is missing from " << test::shared_scenes_dir();
    const Scene castle = load_scene(file);
    const RayScene rays(castle);
    WalkOptions options;
    options.frames = 3;
    options.seed = 7;
    std::vector<std::uint32_t> occluders = occluder_candidates(castle, OccluderFilter::role);
    occluders.resize(std::min<std::size_t>(occluders.size(), 12));  // a few hundred allocations a run
    HostWalk walk = castle_walk(castle, occluders, walk_path(rays, castle, options));
    const std::string dir = test::temp_dir(orthographic ? "EngineHost.OrthographicAllocationFailureSweep" : "EngineHost.AllocationFailureSweep");
    write_walk(dir + "/castle.walk", castle, walk);
    const std::string command = std::string(HOMCULL_ENGINE_HOST) +
                                (orthographic ? " --orthographic " + std::to_string(kOrthographicDistance) : std::string()) + " --fail-sweep " +
                                dir + "/castle.walk " + dir + "/answers";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    std::uint32_t runs, frames, boxes;
    const std::vector<std::uint8_t> answers = read_answers(dir + "/answers", runs, frames, boxes);
    ASSERT_GT(runs, 50u);
    ASSERT_EQ(frames, walk.cameras.size());
    ASSERT_EQ(boxes, castle.objects.size());
    std::size_t culled = 0;
    std::size_t kept_outside = 0;
    EXPECT_EQ(false_culls(rays, castle, walk, answers, runs, culled, kept_outside, orthographic), 0u);
    EXPECT_GT(culled, 0u);  // the runs whose allocations all succeeded cull something
}

TEST(EngineHost, AllocationFailureSweep) { check_allocation_failure_sweep(false); }
TEST(EngineHost, OrthographicAllocationFailureSweep) { check_allocation_failure_sweep(true); }

}  // namespace
}  // namespace homcull
