#include "support.hpp"

#include <homcull/tbb_parallel_for.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <thread>

namespace homcull::test {

std::uint32_t add_object_with_own_mesh(Scene& scene, Mesh mesh) {
    Object object;
    object.name = mesh.name;
    object.mesh = std::uint32_t(scene.meshes.size());
    scene.meshes.push_back(std::move(mesh));
    scene.objects.push_back(object);
    scene.finalize();
    return std::uint32_t(scene.objects.size() - 1);
}

std::uint32_t add_quad(Scene& scene, const std::string& name, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    Mesh mesh;
    mesh.name = name;
    mesh.positions = {a, b, c, d};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    return add_object_with_own_mesh(scene, std::move(mesh));
}

std::uint32_t add_interlocked_pair(Scene& scene, float split) {
    Mesh interlocked;
    interlocked.name = "interlocked";
    const auto quad = [&](float x0, float x1, float z) {
        const auto base = std::uint32_t(interlocked.positions.size());
        interlocked.positions.insert(interlocked.positions.end(), {{x0, -50, z}, {x1, -50, z}, {x1, 50, z}, {x0, 50, z}});
        interlocked.indices.insert(interlocked.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    };
    quad(-50.0f, split, -2.0f);
    quad(split, 50.0f, -6.0f);
    const std::uint32_t first = add_object_with_own_mesh(scene, interlocked);
    add_quad(scene, "between", {-50, -50, -4}, {50, -50, -4}, {50, 50, -4}, {-50, 50, -4});
    return first;
}

std::uint32_t add_box(Scene& scene, const std::string& name, glm::vec3 lo, glm::vec3 hi) {
    Mesh mesh;
    mesh.name = name;
    for (int k = 0; k < 8; ++k)
        mesh.positions.emplace_back((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    mesh.indices = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                    2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    return add_object_with_own_mesh(scene, std::move(mesh));
}

Camera camera_down_minus_z(double fov_y_degrees, double near_plane, double far_plane) {
    Camera c;
    c.eye = {0, 0, 0};
    c.target = {0, 0, -1};
    c.up = {0, 1, 0};
    c.fov_y_degrees = fov_y_degrees;
    c.near_plane = near_plane;
    c.far_plane = far_plane;
    return c;
}

BufferConfig buffer_config(int width, int height, int samples, float near_w, bool sample_depth) {
    BufferConfig c;
    c.width = width;
    c.height = height;
    c.samples = samples;
    c.near_w = near_w;
    c.sample_depth = sample_depth;
    return c;
}

std::string temp_dir(const std::string& test_name) {
    const std::filesystem::path dir = std::filesystem::path(HOMCULL_TEST_TMP_DIR) / test_name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

std::string shared_scenes_dir() {
    const char* override_dir = std::getenv("HOMCULL_SHARED_SCENES_DIR");
    return override_dir && *override_dir ? override_dir : HOMCULL_SHARED_SCENES_DIR;
}

std::string shared_scene(const std::string& file) {
    const std::filesystem::path path = std::filesystem::path(shared_scenes_dir()) / file;
    return std::filesystem::is_regular_file(path) ? path.string() : std::string();
}

Camera castle_view_c0() {
    Camera c0;
    c0.eye = {27, 2, -47};
    c0.target = {28.4258, 2.6111, -37.1211};
    c0.fov_y_degrees = 36;
    c0.near_plane = 1;
    c0.far_plane = 5000;
    return c0;
}

void write_text(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

namespace {
void run_on_threads(void* user, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    const std::size_t threads = std::max<std::size_t>(1, reinterpret_cast<std::uintptr_t>(user));
    std::atomic<std::size_t> next{0};
    auto work = [&] {
        for (std::size_t i; (i = next.fetch_add(1, std::memory_order_relaxed)) < count;) task(data, i);
    };
    std::vector<std::thread> helpers;
    for (std::size_t t = 1; t < threads && t < count; ++t) helpers.emplace_back(work);
    work();
    for (std::thread& h : helpers) h.join();
}
}  // namespace

ParallelFor thread_jobs(std::size_t threads) {
    return ParallelFor{run_on_threads, reinterpret_cast<void*>(std::uintptr_t(threads)), threads};
}

OccluderClusters cluster_world(const WorldTriangles& w, const ClusterLimits& limits) {
    return build_occluder_clusters(w.positions.data(), 3 * sizeof(float), w.positions.size() / 3, w.indices.data(), w.triangle_count(),
                                   w.shared_edges.data(), w.edge_apexes.data(), limits);
}

ParallelFor parallel_jobs() {
#ifdef HOMCULL_TSAN
    return thread_jobs(2);
#else
    return tbb_parallel_for();
#endif
}

void run_shuffled(void* user, std::size_t count, void (*task)(void*, std::size_t), void* data) {
    std::vector<std::size_t> order(count);
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::shuffle(order.begin(), order.end(), *static_cast<std::mt19937_64*>(user));
    for (std::size_t i : order) task(data, i);
}

std::vector<float> pyramid_by_definition(const OcclusionBuffer& b) {
    int w = b.subtiles_x(), h = b.subtiles_y();
    std::vector<float> cells;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) cells.push_back(b.subtile(x, y).d0);
    std::size_t below = 0;
    while (w > 1 || h > 1) {
        const int nw = (w + 1) / 2, nh = (h + 1) / 2;
        const std::size_t here = cells.size();
        for (int y = 0; y < nh; ++y)
            for (int x = 0; x < nw; ++x) {
                float m = cells[below + std::size_t(2 * y) * std::size_t(w) + std::size_t(2 * x)];
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx)
                        if (2 * x + dx < w && 2 * y + dy < h)
                            m = std::min(m, cells[below + std::size_t(2 * y + dy) * std::size_t(w) + std::size_t(2 * x + dx)]);
                cells.push_back(m);
            }
        below = here, w = nw, h = nh;
    }
    return cells;
}

bool same_subtiles(const OcclusionBuffer& a, const OcclusionBuffer& b) {
    const auto x = a.subtiles();
    const auto y = b.subtiles();
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i)
        if (x[i].d0 != y[i].d0 || x[i].d1 != y[i].d1 || x[i].mask != y[i].mask || x[i].covered != y[i].covered) return false;
    std::vector<float> depth_a, depth_b;
    a.read_depth(depth_a);
    b.read_depth(depth_b);
    if (depth_a != depth_b) return false;
    // The per-sample depth itself, bit for bit: read_depth sees it only through a maximum with
    // the layers and a reciprocal.
    a.read_sample_depth(depth_a);
    b.read_sample_depth(depth_b);
    return depth_a.size() == depth_b.size() &&
           std::memcmp(depth_a.data(), depth_b.data(), depth_a.size() * sizeof(float)) == 0;
}

bool same_pyramid(const OcclusionBuffer& a, const OcclusionBuffer& b) {
    std::vector<float> x, y;
    a.read_pyramid(x);
    b.read_pyramid(y);
    return x == y;
}

}  // namespace homcull::test
