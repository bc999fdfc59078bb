#pragma once
// Small scenes built in code, with answers known by construction, and paths for test files.
#include <homcull/camera.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/world_triangles.hpp>
#include <homcull/scene.hpp>

#include "inputs.hpp"  // random_clip_triangles, clip_space_input, random_screen_rects, run_backwards, CityStreet

#include <string>
#include <vector>

#include <homcull/isa.hpp>

#include <string>

namespace homcull {
class RayScene;
}

namespace homcull::test {

// Appends an object holding `mesh` (a mesh of its own), and finalizes the scene.
std::uint32_t add_object_with_own_mesh(Scene& scene, Mesh mesh);
// Appends an object holding a quad (two CCW triangles a, b, c, d) with its own mesh.
std::uint32_t add_quad(Scene& scene, const std::string& name, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d);
// Appends an axis-aligned box object (12 triangles, CCW outward).
std::uint32_t add_box(Scene& scene, const std::string& name, glm::vec3 lo, glm::vec3 hi);
// Two interlocked objects, across the view of camera_down_minus_z: object `first` is a near quad
// (z = -2) left of x = split and a far one (z = -6) right of it, the next object one quad between
// them (z = -4): rays on the left meet the first then the second, on the right the second then
// the first. Returns the first's id.
std::uint32_t add_interlocked_pair(Scene& scene, float split = 0.0f);
// A camera at the origin looking down -z with the given vertical field of view.
Camera camera_down_minus_z(double fov_y_degrees = 90.0, double near_plane = 0.1, double far_plane = 1000.0);

// A buffer configuration: width x height pixels of samples x samples, clipped at near_w.
BufferConfig buffer_config(int width, int height, int samples, float near_w, bool sample_depth = false);


// The tests' job system with real threads: oneTBB's (homcull::tbb), or in a ThreadSanitizer
// build (HOMCULL_TSAN) threads_jobs(), since TSan reports the internals of the uninstrumented
// libtbb as races.
// A mesh's occluder clusters (build_occluder_clusters) from gathered world triangles, with their
// shared edges.
OccluderClusters cluster_world(const WorldTriangles& w, const ClusterLimits& limits = {});

ParallelFor parallel_jobs();

// An instruction set selected (select_isa: the default of buffers made without naming one)
// while the object lives, and the one selected before it again when it goes, also when a failed
// ASSERT leaves the test early, so that no later test runs on the wrong one; nested, an inner
// one gives the outer one's back. A buffer keeps the instruction set it was made with, so tests
// that run on every instruction set make one per iteration, and their buffers inside it:
//     for (const std::string& isa : available_isas()) { const test::ScopedIsa selected(isa); ... }
class ScopedIsa {
public:
    explicit ScopedIsa(const std::string& name) : previous_(selected_isa()) { select_isa(name); }
    ~ScopedIsa() { select_isa(previous_); }
    ScopedIsa(const ScopedIsa&) = delete;
    ScopedIsa& operator=(const ScopedIsa&) = delete;

private:
    std::string previous_;
};
// A plain job system: each run starts `threads` - 1 std::threads that take task numbers from
// an atomic counter with the calling thread, and joins them.
ParallelFor thread_jobs(std::size_t threads = 2);
// A "job system" (ParallelFor::run, user = a std::mt19937_64) that runs the tasks in a
// shuffled order on the calling thread.
void run_shuffled(void* user, std::size_t count, void (*task)(void*, std::size_t), void* data);
// The same subtiles, and the same read-back depth (which includes the per-sample depth when
// the buffers keep one).
bool same_subtiles(const OcclusionBuffer& a, const OcclusionBuffer& b);
// The same pyramids of the rectangle tests (built band by band with a job system).
bool same_pyramid(const OcclusionBuffer& a, const OcclusionBuffer& b);
// The pyramid as read_pyramid documents it, computed from the subtiles' d0.
std::vector<float> pyramid_by_definition(const OcclusionBuffer& b);

// Wherever the buffer claims an occluder (read_depth finite), a ray through the sample's
// centre must hit something at or before the claimed depth (the ray parameter is the view
// depth; 10^-5 absorbs Embree's float rounding). Adds a failure naming `what` and the sample at
// the first that does not; returns the number of claimed samples.
// Embree's first-hit object id at every pixel centre of `display` (kNoObject: nothing).
std::vector<std::uint32_t> embree_first_hits(const RayScene& rays, const Scene& scene, const Camera& camera, Resolution display);
long expect_claims_behind_embree_hits(const RayScene& rays, const Camera& camera, const OcclusionBuffer& buffer, const std::string& what);

// A fresh, empty folder for one test's files.
std::string temp_dir(const std::string& test_name);
// The shared scenes folder: $HOMCULL_SHARED_SCENES_DIR, else the one CMake was given.
std::string shared_scenes_dir();
// <shared scenes folder>/<file>, or "" when it is missing.
std::string shared_scene(const std::string& file);
// DESIGN.md's castle view C0 (the first view of data/views/castle.json).
Camera castle_view_c0();
void write_text(const std::string& path, const std::string& text);

}  // namespace homcull::test
