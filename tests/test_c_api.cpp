// The C interface (homcull.h) from C++: results instead of exceptions, per-context instruction
// sets, camera conventions, memory from the engine only (no allocation after a reserve), and
// out-of-memory at every allocation. The C99 engine host (tests/c_host) drives it on the castle.
#include <homcull/homcull.h>

#include <homcull/frustum.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/scene.hpp>

#include <gtest/gtest.h>
#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

// An engine's allocator: counts, and fails the allocation number `fail_at` (1-based; 0: never).
struct EngineMemory {
    std::size_t calls = 0, live = 0, fail_at = 0;
    static void* allocate(void* user, std::size_t size, std::size_t alignment) {
        auto& m = *static_cast<EngineMemory*>(user);
        if (++m.calls == m.fail_at) return nullptr;
        void* p = std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
        if (p) ++m.live;
        return p;
    }
    static void deallocate(void* user, void* p, std::size_t) {
        --static_cast<EngineMemory*>(user)->live;
        std::free(p);
    }
    homcull_allocator allocator() { return {allocate, deallocate, this}; }
};

struct ErrorLog {
    std::vector<std::string> messages;
    static void on_error(void* user, homcull_result, const char* message) { static_cast<ErrorLog*>(user)->messages.push_back(message); }
};

homcull_context* make_context(EngineMemory* memory = nullptr, homcull_isa isa = HOMCULL_ISA_BEST, ErrorLog* log = nullptr) {
    homcull_context_desc desc{};
    if (memory) desc.allocator = memory->allocator();
    desc.isa = isa;
    if (log) desc.on_error = ErrorLog::on_error, desc.error_user = log;
    homcull_context* context = nullptr;
    EXPECT_EQ(homcull_context_create(&desc, &context), HOMCULL_OK) << homcull_last_error();
    return context;
}

// A mesh of packed x, y, z positions and 16- or 32-bit indices, 3 per triangle.
template <typename Index>
homcull_mesh_desc indexed_mesh_desc(const std::vector<float>& positions, const std::vector<Index>& indices) {
    homcull_mesh_desc d{};
    d.positions = positions.data();
    d.position_stride = 12;
    d.vertex_count = positions.size() / 3;
    d.indices = indices.data();
    d.index_size = sizeof(Index);
    d.triangle_count = indices.size() / 3;
    return d;
}

// A small world with answers known by construction, seen from the origin looking down -z
// (right-handed, y up): a wall of 2 x 2 quads at z = -10 over x in [-20, 5] and y in [-20, 20]
// (CCW towards the camera), covering the view but for a strip on the right, and boxes.
struct Scene {
    std::vector<float> positions;
    std::vector<std::uint16_t> indices;
    std::vector<homcull_box> boxes;
    std::vector<homcull_visibility> expected;  // with a far plane at 100
    Scene() {
        // Its inner vertex is off the screen's centre: a vertex on a sample centre leaves that
        // sample unclaimed (docs/occlusion-buffer.md, rule 2), which would open a hole there.
        const float xs[3] = {-20.0f, -7.5f, 5.0f}, ys[3] = {-20.0f, 1.3f, 20.0f};
        for (int y = 0; y <= 2; ++y)
            for (int x = 0; x <= 2; ++x) positions.insert(positions.end(), {xs[x], ys[y], -10.0f});
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) {
                const auto a = std::uint16_t(3 * y + x), b = std::uint16_t(a + 1), c = std::uint16_t(a + 3), d = std::uint16_t(a + 4);
                indices.insert(indices.end(), {a, b, d, a, d, c});
            }
        add({-1, -1, -30}, {1, 1, -28}, HOMCULL_OCCLUDED);     // behind the wall
        add({-3, 2, -15}, {-1, 4, -11}, HOMCULL_OCCLUDED);     // just behind it
        add({-1, -1, -8}, {1, 1, -6}, HOMCULL_VISIBLE);        // in front of it
        add({-1, -1, -0.5f}, {1, 1, 0.5f}, HOMCULL_VISIBLE);   // across the near plane
        add({-1, -1, 5}, {1, 1, 7}, HOMCULL_VIEW_CULLED);      // behind the camera
        add({200, -1, -30}, {202, 1, -28}, HOMCULL_VIEW_CULLED);  // far off to the side
        add({-1, -1, -300}, {1, 1, -290}, HOMCULL_VIEW_CULLED);  // beyond the far plane (hidden by the wall too)
        add({30, -1, -30}, {32, 1, -28}, HOMCULL_VISIBLE);     // right of the wall
    }
    void add(glm::vec3 lo, glm::vec3 hi, homcull_visibility v) {
        boxes.push_back({{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}});
        expected.push_back(v);
    }
    homcull_mesh_desc mesh_desc() const { return indexed_mesh_desc(positions, indices); }
};

constexpr double kNear = 0.1, kFar = 100.0, kFovY = glm::radians(60.0), kAspect = 16.0 / 9.0;

void store(const glm::dmat4& m, homcull_matrix_layout layout, double out[16]) {
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[layout == HOMCULL_ROW_MAJOR ? 4 * r + c : 4 * c + r] = m[c][r];
}

// The scene's camera as engines of different conventions would give it.
enum class Engine { opengl, d3d_reversed_lh, d3d_reversed_infinite_lh, vulkan_y_down, opengl_ortho, d3d_reversed_ortho_lh, vulkan_ortho_y_down };
// The orthographic engines' window: 80 x 45 world units, so that the scene's boxes land where
// the perspective views put them (in view, beside it, behind the wall) and the answers match.
constexpr double kOrthoHalfWidth = 40.0, kOrthoHalfHeight = 22.5;
homcull_view engine_view(Engine e) {
    homcull_view v{};
    v.front_face = HOMCULL_FRONT_CCW;
    v.cull = HOMCULL_CULL_BACK;
    const glm::dmat4 rh_view = glm::lookAtRH(glm::dvec3(0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
    // The left-handed engine keeps the world with z mirrored (as it imported it): world_to_clip
    // takes the scene's positions through that mirror, then its own view (looking down its +z).
    const glm::dmat4 mirror_z = glm::scale(glm::dmat4(1.0), glm::dvec3(1, 1, -1));
    const glm::dmat4 lh_view = glm::lookAtLH(glm::dvec3(0), glm::dvec3(0, 0, 1), glm::dvec3(0, 1, 0)) * mirror_z;
    glm::dmat4 m(1.0);
    switch (e) {
        case Engine::opengl:
            m = glm::perspectiveRH_NO(kFovY, kAspect, kNear, kFar) * rh_view;
            v.layout = HOMCULL_COLUMN_MAJOR, v.depth_range = HOMCULL_DEPTH_MINUS_ONE_TO_ONE;
            break;
        case Engine::d3d_reversed_lh: {
            // Reversed depth: z' = w - z of the [0, 1] projection (near at 1, far at 0).
            glm::dmat4 r(1.0);  // row 2 = (0, 0, -1, 1)
            r[2] = glm::dvec4(0, 0, -1, 0);
            r[3] = glm::dvec4(0, 0, 1, 1);
            m = r * glm::perspectiveLH_ZO(kFovY, kAspect, kNear, kFar) * lh_view;
            v.layout = HOMCULL_ROW_MAJOR, v.depth_range = HOMCULL_DEPTH_ZERO_TO_ONE, v.flags = HOMCULL_VIEW_REVERSED_Z;
            break;
        }
        case Engine::d3d_reversed_infinite_lh: {
            // Infinite reversed: clip z = near, w = view depth.
            const double f = 1.0 / std::tan(kFovY / 2);
            glm::dmat4 p(0.0);
            p[0][0] = f / kAspect, p[1][1] = f, p[3][2] = kNear, p[2][3] = 1.0;
            m = p * lh_view;
            v.layout = HOMCULL_ROW_MAJOR, v.depth_range = HOMCULL_DEPTH_ZERO_TO_ONE, v.flags = HOMCULL_VIEW_REVERSED_Z | HOMCULL_VIEW_INFINITE_FAR;
            break;
        }
        case Engine::vulkan_y_down: {
            glm::dmat4 flip(1.0);
            flip[1][1] = -1.0;
            m = flip * glm::perspectiveRH_ZO(kFovY, kAspect, kNear, kFar) * rh_view;
            v.layout = HOMCULL_COLUMN_MAJOR, v.depth_range = HOMCULL_DEPTH_ZERO_TO_ONE, v.flags = HOMCULL_VIEW_Y_DOWN;
            break;
        }
        case Engine::opengl_ortho:
            m = glm::orthoRH_NO(-kOrthoHalfWidth, kOrthoHalfWidth, -kOrthoHalfHeight, kOrthoHalfHeight, kNear, kFar) * rh_view;
            v.layout = HOMCULL_COLUMN_MAJOR, v.depth_range = HOMCULL_DEPTH_MINUS_ONE_TO_ONE;
            break;
        case Engine::d3d_reversed_ortho_lh: {
            glm::dmat4 r(1.0);  // z' = w - z: near at 1, far at 0
            r[2] = glm::dvec4(0, 0, -1, 0);
            r[3] = glm::dvec4(0, 0, 1, 1);
            m = r * glm::orthoLH_ZO(-kOrthoHalfWidth, kOrthoHalfWidth, -kOrthoHalfHeight, kOrthoHalfHeight, kNear, kFar) * lh_view;
            m = 2.0 * m;  // a w of 2 everywhere: still orthographic
            v.layout = HOMCULL_ROW_MAJOR, v.depth_range = HOMCULL_DEPTH_ZERO_TO_ONE, v.flags = HOMCULL_VIEW_REVERSED_Z;
            break;
        }
        case Engine::vulkan_ortho_y_down: {
            glm::dmat4 flip(1.0);
            flip[1][1] = -1.0;
            m = flip * glm::orthoRH_ZO(-kOrthoHalfWidth, kOrthoHalfWidth, -kOrthoHalfHeight, kOrthoHalfHeight, kNear, kFar) * rh_view;
            v.layout = HOMCULL_COLUMN_MAJOR, v.depth_range = HOMCULL_DEPTH_ZERO_TO_ONE, v.flags = HOMCULL_VIEW_Y_DOWN;
            break;
        }
    }
    store(m, v.layout, v.world_to_clip);
    return v;
}

struct Culler {
    homcull_context* context = nullptr;
    homcull_mesh* mesh = nullptr;
    homcull_buffer* buffer = nullptr;
    explicit Culler(const Scene& scene, homcull_context* c, int width = 320, int height = 180, std::uint32_t buffer_flags = 0) : context(c) {
        const homcull_mesh_desc md = scene.mesh_desc();
        EXPECT_EQ(homcull_mesh_create(context, &md, &mesh), HOMCULL_OK) << homcull_last_error();
        homcull_buffer_desc bd{width, height, 1, float(kNear), buffer_flags, 0};
        EXPECT_EQ(homcull_buffer_create(context, &bd, &buffer), HOMCULL_OK) << homcull_last_error();
    }
    ~Culler() {
        homcull_buffer_destroy(buffer);
        homcull_mesh_destroy(mesh);
        homcull_context_destroy(context);
    }
    std::vector<homcull_visibility> frame(const Scene& scene, const homcull_view& view) {
        std::vector<homcull_visibility> answers(scene.boxes.size(), 99);
        EXPECT_EQ(homcull_buffer_begin_frame(buffer, &view), HOMCULL_OK) << homcull_last_error();
        EXPECT_EQ(homcull_buffer_draw_mesh(buffer, mesh, nullptr, 1), HOMCULL_OK) << homcull_last_error();
        EXPECT_EQ(homcull_buffer_test_boxes(buffer, scene.boxes.data(), scene.boxes.size(), nullptr, answers.data()), HOMCULL_OK)
            << homcull_last_error();
        return answers;
    }
};

TEST(CApi, VersionNamesAndInstructionSets) {
    EXPECT_EQ(homcull_version(), std::uint32_t(HOMCULL_VERSION));
    EXPECT_STREQ(homcull_result_name(HOMCULL_ERROR_OUT_OF_MEMORY), "HOMCULL_ERROR_OUT_OF_MEMORY");
    EXPECT_STREQ(homcull_result_name(12345), "HOMCULL_ERROR_UNKNOWN");
    const std::uint32_t isas = homcull_supported_isas();
    EXPECT_TRUE(isas & (1u << HOMCULL_ISA_BEST));
    EXPECT_TRUE(isas & (1u << HOMCULL_ISA_SCALAR));
    EXPECT_STREQ(homcull_isa_name(HOMCULL_ISA_AVX2), "avx2");
    EXPECT_STREQ(homcull_isa_name(-1), "unknown");
    // The names agree with the C++ list of what this machine runs.
    for (const std::string& name : homcull::available_isas()) {
        bool found = false;
        for (homcull_isa i = 1; i < HOMCULL_ISA_COUNT; ++i) found |= name == homcull_isa_name(i) && (isas & (1u << i));
        EXPECT_TRUE(found || name == "sve2_128" || name == "sve_256") << name;
    }
}

TEST(CApi, ErrorsAreResultsWithMessages) {
    ErrorLog log;
    homcull_context* context = make_context(nullptr, HOMCULL_ISA_BEST, &log);
    homcull_buffer* buffer = nullptr;
    homcull_buffer_desc bad{0, 10, 1, 0.1f, 0, 0};
    EXPECT_EQ(homcull_buffer_create(context, &bad, &buffer), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(buffer, nullptr);
    EXPECT_NE(std::string(homcull_last_error()).find("got 0x10 pixels"), std::string::npos) << homcull_last_error();
    ASSERT_EQ(log.messages.size(), 1u);
    EXPECT_EQ(log.messages[0], homcull_last_error());
    bad = {64, 36, 3, 0.1f, 0, 0};
    EXPECT_EQ(homcull_buffer_create(context, &bad, &buffer), HOMCULL_ERROR_INVALID_ARGUMENT);
    bad = {64, 36, 1, std::nanf(""), 0, 0};
    EXPECT_EQ(homcull_buffer_create(context, &bad, &buffer), HOMCULL_ERROR_INVALID_ARGUMENT);

    const homcull_buffer_desc good{64, 36, 1, 0.1f, 0, 0};
    ASSERT_EQ(homcull_buffer_create(context, &good, &buffer), HOMCULL_OK);
    // Queries before a frame: an error, and every answer visible.
    Scene scene;
    std::vector<homcull_visibility> answers(scene.boxes.size(), HOMCULL_OCCLUDED);
    EXPECT_EQ(homcull_buffer_test_boxes(buffer, scene.boxes.data(), answers.size(), nullptr, answers.data()), HOMCULL_ERROR_INVALID_OPERATION);
    for (homcull_visibility v : answers) EXPECT_EQ(v, HOMCULL_VISIBLE);
    // A mesh index out of range; an orthographic camera; a matrix with a NaN.
    homcull_mesh_desc md = scene.mesh_desc();
    std::vector<std::uint16_t> indices = scene.indices;
    indices[4] = 9;
    md.indices = indices.data();
    homcull_mesh* mesh = nullptr;
    EXPECT_EQ(homcull_mesh_create(context, &md, &mesh), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::string(homcull_last_error()).find("index 9 of triangle 1"), std::string::npos) << homcull_last_error();
    homcull_view ortho = engine_view(Engine::opengl_ortho);
    ortho.flags = HOMCULL_VIEW_INFINITE_FAR;  // an orthographic projection has a far plane
    EXPECT_EQ(homcull_buffer_begin_frame(buffer, &ortho), HOMCULL_ERROR_INVALID_ARGUMENT);
    ortho = engine_view(Engine::opengl_ortho);
    ortho.world_to_clip[15] = -1.0;  // w must be positive
    EXPECT_EQ(homcull_buffer_begin_frame(buffer, &ortho), HOMCULL_ERROR_INVALID_ARGUMENT);
    homcull_view nan_view = engine_view(Engine::opengl);
    nan_view.world_to_clip[5] = std::nan("");
    EXPECT_EQ(homcull_buffer_begin_frame(buffer, &nan_view), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(homcull_buffer_draw_mesh(buffer, nullptr, nullptr, 1), HOMCULL_ERROR_INVALID_OPERATION);  // no frame began
    homcull_buffer_destroy(buffer);
    homcull_context_destroy(context);

    homcull_context_desc desc{};
    desc.isa = 77;
    homcull_context* none = nullptr;
    EXPECT_EQ(homcull_context_create(&desc, &none), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(none, nullptr);
    EXPECT_EQ(homcull_context_create(nullptr, &none), HOMCULL_ERROR_INVALID_ARGUMENT);
}

// The same camera in four engines' conventions gives the answers known by construction.
TEST(CApi, EngineConventionsGiveTheSameAnswers) {
    const Scene scene;
    for (Engine e : {Engine::opengl, Engine::d3d_reversed_lh, Engine::d3d_reversed_infinite_lh, Engine::vulkan_y_down, Engine::opengl_ortho,
                     Engine::d3d_reversed_ortho_lh, Engine::vulkan_ortho_y_down}) {
        Culler culler(scene, make_context());
        const std::vector<homcull_visibility> answers = culler.frame(scene, engine_view(e));
        for (std::size_t k = 0; k < answers.size(); ++k) {
            homcull_visibility expected = scene.expected[k];
            if (e == Engine::d3d_reversed_infinite_lh && k == 6) expected = HOMCULL_OCCLUDED;  // no far plane: the wall hides it
            EXPECT_EQ(answers[k], expected) << "engine " << int(e) << ", box " << k;
        }
    }
}

// Orthographic frames, one after another with perspective ones on the same buffer (each
// switch reconfigures it, allocating nothing after a reserve): the boxes' answers, rectangles
// given their nearest clip z, and occludee triangles.
TEST(CApi, OrthographicFramesBetweenPerspectiveOnes) {
    const Scene scene;
    EngineMemory memory;
    {
        Culler culler(scene, make_context(&memory));
        const homcull_reserve_desc reserve{320, 180, 8, 0, 0, 0, 0, 0};
        ASSERT_EQ(homcull_buffer_reserve(culler.buffer, &reserve), HOMCULL_OK);
        const std::size_t before = memory.calls;
        for (Engine e : {Engine::opengl_ortho, Engine::opengl, Engine::vulkan_ortho_y_down, Engine::d3d_reversed_lh, Engine::d3d_reversed_ortho_lh}) {
            EXPECT_EQ(culler.frame(scene, engine_view(e)), scene.expected) << "engine " << int(e);
            const bool ortho = e == Engine::opengl_ortho || e == Engine::vulkan_ortho_y_down || e == Engine::d3d_reversed_ortho_lh;
            if (!ortho) continue;
            // The wall's middle, given the clip z of points behind and before it (z = -10 and
            // the near plane at 0.1, far at 100, in the view's depth range).
            const auto clip_z = [&](double distance) {
                const double t = (distance - kNear) / (kFar - kNear);  // 0 at near, 1 at far
                return float(e == Engine::opengl_ortho ? 2.0 * t - 1.0 : e == Engine::d3d_reversed_ortho_lh ? 1.0 - t : t);
            };
            const homcull_rect rects[3] = {{-0.1f, -0.1f, 0.1f, 0.1f, clip_z(12.0)}, {-0.1f, -0.1f, 0.1f, 0.1f, clip_z(8.0)},
                                           {-0.1f, -0.1f, 0.1f, 0.1f, clip_z(250.0)}};
            homcull_visibility answers[3];
            ASSERT_EQ(homcull_buffer_test_rects(culler.buffer, rects, 3, answers), HOMCULL_OK);
            EXPECT_EQ(answers[0], HOMCULL_OCCLUDED) << "engine " << int(e);
            EXPECT_EQ(answers[1], HOMCULL_VISIBLE) << "engine " << int(e);
            EXPECT_EQ(answers[2], HOMCULL_VISIBLE) << "engine " << int(e);  // beyond twice the far distance: not answered
            // Occludee triangles: a square behind the wall's middle, and the same before it.
            const float behind[12] = {-1, -1, -12, 1, -1, -12, 1, 1, -12, -1, 1, -12}, in_front[12] = {-1, -1, -8, 1, -1, -8, 1, 1, -8, -1, 1, -8};
            const std::uint16_t square[6] = {0, 1, 2, 0, 2, 3};
            for (const float* positions : {behind, in_front}) {
                const homcull_triangles triangles{positions, 12, 4, square, 2, 0, 2};
                homcull_visibility v = 99;
                ASSERT_EQ(homcull_buffer_test_triangles(culler.buffer, &triangles, nullptr, &v), HOMCULL_OK) << homcull_last_error();
                EXPECT_EQ(v, positions == behind ? HOMCULL_OCCLUDED : HOMCULL_VISIBLE) << "engine " << int(e);
            }
        }
        EXPECT_EQ(memory.calls, before);
    }
    EXPECT_EQ(memory.live, 0u);
}

// Back faces are named by the engine's winding: the wall faces the camera counter-clockwise.
TEST(CApi, FrontFaceWindingDecidesWhatIsCulled) {
    const Scene scene;
    for (Engine e : {Engine::opengl, Engine::d3d_reversed_lh, Engine::vulkan_y_down, Engine::d3d_reversed_ortho_lh, Engine::vulkan_ortho_y_down})
        for (homcull_winding front : {HOMCULL_FRONT_CCW, HOMCULL_FRONT_CW})
            for (homcull_cull cull : {HOMCULL_CULL_BACK, HOMCULL_CULL_FRONT, HOMCULL_CULL_NONE}) {
                Culler culler(scene, make_context());
                homcull_view view = engine_view(e);
                view.front_face = front;
                view.cull = cull;
                const bool wall_is_front = front == HOMCULL_FRONT_CCW;
                const bool wall_drawn = cull == HOMCULL_CULL_NONE || (cull == HOMCULL_CULL_BACK) == wall_is_front;
                EXPECT_EQ(culler.frame(scene, view)[0], wall_drawn ? HOMCULL_OCCLUDED : HOMCULL_VISIBLE)
                    << "engine " << int(e) << ", front " << front << ", cull " << cull;
            }
}

// Each context runs its own instruction set, leaving the process-wide choice alone, and all give
// the same answers.
// A cube of half-size 1 around the origin, 12 triangles whose (b - a) x (c - a) points out.
struct Cube {
    std::vector<float> positions;
    std::vector<std::uint16_t> indices;
    Cube() {
        for (int i = 0; i < 8; ++i) positions.insert(positions.end(), {i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f});
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                // The face's corners in order around it: the two other axes' bits.
                const int u = 1 << ((axis + 1) % 3), v = 1 << ((axis + 2) % 3), base = side << axis;
                const std::uint16_t q[4] = {std::uint16_t(base), std::uint16_t(base | u), std::uint16_t(base | u | v), std::uint16_t(base | v)};
                for (const auto& t : {std::array<std::uint16_t, 3>{q[0], q[1], q[2]}, std::array<std::uint16_t, 3>{q[0], q[2], q[3]}}) {
                    const glm::vec3 a = corner(t[0]), n = glm::cross(corner(t[1]) - a, corner(t[2]) - a);
                    const bool out = glm::dot(n, a) > 0.0f;  // the centre is the origin
                    indices.insert(indices.end(), {t[0], out ? t[1] : t[2], out ? t[2] : t[1]});
                }
            }
    }
    glm::vec3 corner(int i) const { return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]}; }
    homcull_triangles triangles() const { return {positions.data(), 12, positions.size() / 3, indices.data(), 2, 0, indices.size() / 3}; }
    // Whether triangle t faces a point p (in the cube's space).
    bool faces(std::size_t t, glm::vec3 p) const {
        const glm::vec3 a = corner(indices[3 * t]);
        return glm::dot(glm::cross(corner(indices[3 * t + 1]) - a, corner(indices[3 * t + 2]) - a), p - a) > 0.0f;
    }
};

// homcull_buffer_test_triangles_ex: the deciding triangle as next frame's start (the same
// answer from any start, fewer samples counted), closed solids (the same answers, the triangles
// seen from behind passed over), and its errors, which answer visible.
TEST(CApi, TriangleTestsStartWhereAskedAndPassOverAClosedSolidsBackFaces) {
    const Scene scene;
    const Cube cube;
    const homcull_triangles triangles = cube.triangles();
    ErrorLog log;
    Culler culler(scene, make_context(nullptr, HOMCULL_ISA_BEST, &log));
    homcull_triangle_test_result result;
    EXPECT_EQ(homcull_buffer_test_triangles_ex(culler.buffer, &triangles, nullptr, nullptr, &result), HOMCULL_ERROR_INVALID_OPERATION);
    EXPECT_EQ(result.visibility, HOMCULL_VISIBLE);
    ASSERT_EQ(culler.frame(scene, engine_view(Engine::opengl)), scene.expected);

    // The cube moved by a column-major model matrix; the eye (the world's origin) in its space.
    const auto model = [](glm::vec3 at) {
        std::array<float, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, at.x, at.y, at.z, 1};
        return m;
    };
    const auto test = [&](const std::array<float, 16>& m, const homcull_triangle_test_desc* desc) {
        homcull_triangle_test_result r;
        r.visibility = 99;
        EXPECT_EQ(homcull_buffer_test_triangles_ex(culler.buffer, &triangles, m.data(), desc, &r), HOMCULL_OK) << homcull_last_error();
        return r;
    };
    const glm::vec3 behind(-2, 2, -15), in_front(-2, 2, -7);
    for (const glm::vec3 at : {behind, in_front}) {
        const std::array<float, 16> m = model(at);
        const glm::vec3 eye = -at;
        homcull_visibility plain = 99;
        ASSERT_EQ(homcull_buffer_test_triangles(culler.buffer, &triangles, m.data(), &plain), HOMCULL_OK);
        EXPECT_EQ(plain, at == behind ? HOMCULL_OCCLUDED : HOMCULL_VISIBLE);
        // A tolerance of one sample counts every triangle's samples: with none, the triangles of
        // the hidden cube are passed over by their bounding rectangles, uncounted.
        homcull_triangle_test_desc counted{};
        counted.tolerated_samples = 1;
        const homcull_triangle_test_result from_start = test(m, &counted);
        EXPECT_EQ(from_start.visibility, plain);
        EXPECT_GT(from_start.samples, 0u);
        if (at == behind) {
            EXPECT_EQ(test(m, nullptr).samples, 0u);
        }

        homcull_triangle_test_desc closed = counted;
        closed.flags = HOMCULL_TRIANGLES_CLOSED_SOLID;
        closed.orientation = 1;
        closed.eye[0] = eye.x, closed.eye[1] = eye.y, closed.eye[2] = eye.z;
        const homcull_triangle_test_result solid = test(m, &closed);
        EXPECT_EQ(solid.visibility, plain);
        if (at == behind) {
            EXPECT_EQ(from_start.deciding_triangle, 0u);
            EXPECT_LT(solid.samples, from_start.samples);  // every triangle counted, but those facing away
            EXPECT_GT(solid.samples, 0u);
            continue;
        }
        EXPECT_TRUE(cube.faces(solid.deciding_triangle, eye)) << solid.deciding_triangle;
        // Next frame, from the deciding triangle: found at once, with no more samples counted.
        homcull_triangle_test_desc next{};
        next.first_triangle = from_start.deciding_triangle;
        const homcull_triangle_test_result again = test(m, &next);
        EXPECT_EQ(again.visibility, HOMCULL_VISIBLE);
        EXPECT_EQ(again.deciding_triangle, from_start.deciding_triangle);
        EXPECT_LE(again.samples, from_start.samples);
        // Each start gives the same answer, decided by the start itself where it faces the eye
        // (the cube is in front of everything); one past the last starts from the first.
        for (std::size_t first = 0; first < cube.indices.size() / 3; ++first) {
            next.first_triangle = first;
            const homcull_triangle_test_result r = test(m, &next);
            EXPECT_EQ(r.visibility, HOMCULL_VISIBLE) << first;
            if (cube.faces(first, eye)) {
                EXPECT_EQ(r.deciding_triangle, first);
            }
        }
        next.first_triangle = cube.indices.size() / 3 + 5;
        EXPECT_EQ(test(m, &next).deciding_triangle, from_start.deciding_triangle);
        // A tolerance of all the samples the cube may cover hides it (approximate culling).
        next.first_triangle = 0;
        next.tolerated_samples = ~std::uint64_t(0);
        EXPECT_EQ(test(m, &next).visibility, HOMCULL_OCCLUDED);
    }

    // Errors answer visible, with a message.
    const std::array<float, 16> m = model(behind);
    homcull_triangle_test_desc bad{};
    bad.flags = HOMCULL_TRIANGLES_CLOSED_SOLID;
    bad.orientation = 0;
    const auto refused = [&](const homcull_triangle_test_desc& d, const char* says) {
        homcull_triangle_test_result r;
        r.visibility = 99;
        EXPECT_EQ(homcull_buffer_test_triangles_ex(culler.buffer, &triangles, m.data(), &d, &r), HOMCULL_ERROR_INVALID_ARGUMENT);
        EXPECT_EQ(r.visibility, HOMCULL_VISIBLE);
        EXPECT_NE(std::string(homcull_last_error()).find(says), std::string::npos) << homcull_last_error();
    };
    refused(bad, "orientation must be +1 or -1");
    bad.orientation = -1;
    bad.eye[1] = std::nan("");
    refused(bad, "eye must be finite");
    bad.flags = 2;
    refused(bad, "unknown flags");
    EXPECT_EQ(homcull_buffer_test_triangles_ex(culler.buffer, &triangles, m.data(), nullptr, nullptr), HOMCULL_ERROR_INVALID_ARGUMENT);
    const homcull_view ortho = engine_view(Engine::opengl_ortho);
    ASSERT_EQ(homcull_buffer_begin_frame(culler.buffer, &ortho), HOMCULL_OK);
    bad = homcull_triangle_test_desc{};
    bad.flags = HOMCULL_TRIANGLES_CLOSED_SOLID;
    bad.orientation = 1;
    refused(bad, "closed solids need a perspective view");
    EXPECT_EQ(log.messages.size(), 6u);
}

// A box crossing the near plane has no screen rectangle; beside the view (a wall along the
// eye, reaching behind it) it is view-culled, on every instruction set, in front of the eye
// visible; the same for a reversed-depth left-handed engine and orthographic ones (whose
// window, 80 x 45, is wider than the perspective view at these depths).
TEST(CApi, BoxesCrossingTheNearPlaneBesideTheViewAreViewCulled) {
    const Scene scene;
    const homcull_box boxes[3] = {{{50, -1, -20}, {51, 3, 20}}, {{-5, 25, -20}, {5, 26, 20}}, {{-1, -1, -0.5f}, {1, 1, 0.5f}}};
    const homcull_visibility expected[3] = {HOMCULL_VIEW_CULLED, HOMCULL_VIEW_CULLED, HOMCULL_VISIBLE};
    for (homcull_isa isa = 0; isa < HOMCULL_ISA_COUNT; ++isa) {
        if (!(homcull_supported_isas() & (1u << isa))) continue;
        for (const Engine e : {Engine::opengl, Engine::d3d_reversed_lh, Engine::opengl_ortho, Engine::d3d_reversed_ortho_lh}) {
            Culler culler(scene, make_context(nullptr, isa));
            culler.frame(scene, engine_view(e));
            homcull_visibility answers[3] = {99, 99, 99};
            ASSERT_EQ(homcull_buffer_test_boxes(culler.buffer, boxes, 3, nullptr, answers), HOMCULL_OK);
            for (int k = 0; k < 3; ++k) {
                EXPECT_EQ(answers[k], expected[k]) << homcull_isa_name(isa) << ", box " << k;
            }
        }
    }
}

// Boxes beside the view volume's edges of a turned camera (yawed and pitched, so that the
// volume's edges lie across the world's axes), with nothing drawn: exactly the boxes that
// homcull::intersects() finds apart from the camera's frustum are hidden (view-culled, or
// occluded where their screen rectangle holds no sample), the others not view-culled, given as
// world boxes and as model boxes under a translation, perspective and orthographic; among them
// boxes outside no single side, which the screen rectangle and the plane tests kept.
TEST(CApi, BoxesBesideACornerOfTheViewAreViewCulled) {
    const Scene scene;
    homcull::Camera camera;
    camera.eye = {0, 0, 0};
    camera.target = {1.0, 0.35, -0.8};
    camera.fov_y_degrees = glm::degrees(kFovY);
    camera.near_plane = kNear;
    camera.far_plane = kFar;
    const glm::dmat4 view_from_world = homcull::view_matrix(camera);
    for (const bool orthographic : {false, true}) {
        homcull::Camera c = camera;
        if (orthographic) c.ortho_height = 2.0 * kOrthoHalfHeight;
        const glm::dmat4 projection = orthographic ? glm::orthoRH_NO(-kOrthoHalfWidth, kOrthoHalfWidth, -kOrthoHalfHeight, kOrthoHalfHeight, kNear, kFar)
                                                   : glm::perspectiveRH_NO(kFovY, kAspect, kNear, kFar);
        homcull_view view{};
        view.front_face = HOMCULL_FRONT_CCW, view.cull = HOMCULL_CULL_BACK;
        view.layout = HOMCULL_COLUMN_MAJOR, view.depth_range = HOMCULL_DEPTH_MINUS_ONE_TO_ONE;
        const glm::dmat4 clip_from_world = projection * view_from_world;
        for (int k = 0; k < 16; ++k) view.world_to_clip[k] = glm::value_ptr(clip_from_world)[k];
        const homcull::Frustum frustum = homcull::make_frustum(c, kAspect);
        // Boxes around the volume's four side edges (within a few units of them, on either
        // side), their corners on a grid of quarter units.
        std::vector<homcull_box> world, model;
        const glm::vec3 shift(-3.0f, 5.0f, 7.0f);  // model = world - shift, exact in float here
        std::uint64_t seed = 12345;
        const auto uniform = [&](double lo, double hi) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            return lo + (hi - lo) * double(seed >> 11) * 0x1.0p-53;
        };
        const auto quarter = [](double v) { return float(std::round(4.0 * v) / 4.0); };
        for (int k = 0; k < 4000; ++k) {
            const int edge = k % 4;
            const glm::dvec3 along = frustum.corners[std::size_t(edge)] +
                                     uniform(0.05, 0.6) * (frustum.corners[std::size_t(edge) + 4] - frustum.corners[std::size_t(edge)]);
            const glm::vec3 lo(quarter(along.x + uniform(-6, 3)), quarter(along.y + uniform(-6, 3)), quarter(along.z + uniform(-6, 3)));
            const glm::vec3 size(quarter(uniform(0.25, 3)), quarter(uniform(0.25, 3)), quarter(uniform(0.25, 3)));
            world.push_back({{lo.x, lo.y, lo.z}, {lo.x + size.x, lo.y + size.y, lo.z + size.z}});
            model.push_back({{lo.x - shift.x, lo.y - shift.y, lo.z - shift.z}, {lo.x + size.x - shift.x, lo.y + size.y - shift.y, lo.z + size.z - shift.z}});
        }
        const glm::mat4 model_matrix = glm::translate(glm::mat4(1.0f), shift);
        Culler culler(scene, make_context());
        ASSERT_EQ(homcull_buffer_begin_frame(culler.buffer, &view), HOMCULL_OK) << homcull_last_error();
        std::vector<homcull_visibility> world_answers(world.size(), 99), model_answers(model.size(), 99);
        ASSERT_EQ(homcull_buffer_test_boxes(culler.buffer, world.data(), world.size(), nullptr, world_answers.data()), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_test_boxes(culler.buffer, model.data(), model.size(), glm::value_ptr(model_matrix), model_answers.data()),
                  HOMCULL_OK);
        std::size_t apart = 0, beside_a_corner = 0;
        for (std::size_t k = 0; k < world.size(); ++k) {
            const homcull::Aabb box{{world[k].min[0], world[k].min[1], world[k].min[2]}, {world[k].max[0], world[k].max[1], world[k].max[2]}};
            const bool meets = homcull::intersects(frustum, box);
            // Nothing is drawn: a box in view is visible (or occluded when its screen rectangle
            // holds no sample centre, as some beside the view are: hidden either way).
            if (meets) {
                EXPECT_NE(world_answers[k], HOMCULL_VIEW_CULLED) << orthographic << ", box " << k;
            } else {
                EXPECT_NE(world_answers[k], HOMCULL_VISIBLE) << orthographic << ", box " << k;
            }
            EXPECT_EQ(model_answers[k], world_answers[k]) << orthographic << ", box " << k;
            apart += !meets;
            beside_a_corner += world_answers[k] == HOMCULL_VIEW_CULLED && homcull::may_meet(frustum, box);
        }
        EXPECT_GT(apart, world.size() / 4) << orthographic;
        EXPECT_GE(beside_a_corner, 3u) << orthographic << ": no box beside a corner of the view, where only the exact test culls";
    }
}

TEST(CApi, InstructionSetsArePerContext) {
    const Scene scene;
    const std::string process_wide = homcull::selected_isa();
    std::vector<homcull_visibility> first;
    for (homcull_isa isa = 0; isa < HOMCULL_ISA_COUNT; ++isa) {
        if (!(homcull_supported_isas() & (1u << isa))) continue;
        Culler culler(scene, make_context(nullptr, isa));
        if (isa != HOMCULL_ISA_BEST) {
            EXPECT_EQ(homcull_context_isa(culler.context), isa);
        }
        const auto answers = culler.frame(scene, engine_view(Engine::opengl));
        if (first.empty()) first = answers;
        EXPECT_EQ(answers, first) << homcull_isa_name(isa);
        EXPECT_EQ(homcull::selected_isa(), process_wide);
    }
}

// A resolution change keeps the buffer's memory within what it held or reserved; after a
// reserve, frames allocate nothing; everything is given back.
TEST(CApi, NoAllocationAfterReserve) {
    const Scene scene;
    EngineMemory memory;
    {
        Culler culler(scene, make_context(&memory), 320, 180);
        const homcull_reserve_desc reserve{1280, 720, 64, 64, 4, 256, 0, 0};
        ASSERT_EQ(homcull_buffer_reserve(culler.buffer, &reserve), HOMCULL_OK) << homcull_last_error();
        const std::size_t before = memory.calls;
        for (int k = 0; k < 6; ++k) {
            const int width = k % 2 ? 1280 : 333, height = k % 2 ? 720 : 97;
            ASSERT_EQ(homcull_buffer_set_resolution(culler.buffer, width, height), HOMCULL_OK);
            ASSERT_EQ(homcull_buffer_set_near(culler.buffer, k % 3 ? 0.1f : 0.05f), HOMCULL_OK);
            const auto answers = culler.frame(scene, engine_view(Engine::opengl));
            EXPECT_EQ(answers, scene.expected) << width << "x" << height;
            homcull_frame_stats stats{};
            ASSERT_EQ(homcull_buffer_frame_stats(culler.buffer, &stats), HOMCULL_OK);
            EXPECT_EQ(stats.allocations, 0u);
            EXPECT_EQ(stats.draw_calls, 1u);
            EXPECT_GT(stats.triangles_drawn, 0u);
        }
        EXPECT_EQ(memory.calls, before);
        EXPECT_GT(homcull_context_allocated_bytes(culler.context), 0u);
        EXPECT_GT(homcull_buffer_allocated_bytes(culler.buffer), 0u);
    }
    EXPECT_EQ(memory.live, 0u);
}

// Task lists (the pull model): a frame drawn as one gives the answers of draws on the calling
// thread, allocating nothing after a reserve; calls out of order are errors that change nothing;
// a list whose tasks did not all run says so and leaves the buffer usable and conservative.
TEST(CApi, TaskListsAnswerAsDrawsDoAndRefuseCallsOutOfOrder) {
    const Scene scene;
    EngineMemory memory;
    {
        Culler culler(scene, make_context(&memory));
        homcull_buffer* b = culler.buffer;
        const homcull_reserve_desc reserve{320, 180, 8, 0, 3, 24, 0, 0};
        ASSERT_EQ(homcull_buffer_reserve(b, &reserve), HOMCULL_OK) << homcull_last_error();
        const homcull_view view = engine_view(Engine::opengl);
        std::size_t tasks = 99;
        EXPECT_EQ(homcull_buffer_begin_tasks(b), HOMCULL_ERROR_INVALID_OPERATION);  // no frame yet
        ASSERT_EQ(homcull_buffer_begin_frame(b, &view), HOMCULL_OK);
        EXPECT_EQ(homcull_buffer_close_tasks(b, &tasks), HOMCULL_ERROR_INVALID_OPERATION);
        EXPECT_EQ(tasks, 0u);
        EXPECT_EQ(homcull_buffer_run_task(b, 0), HOMCULL_ERROR_INVALID_OPERATION);
        EXPECT_EQ(homcull_buffer_finish_tasks(b), HOMCULL_ERROR_INVALID_OPERATION);

        const float shifted[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 40, 0, 0, 1};  // off the screen
        const float matrices[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -20, 1};
        homcull_frame_stats drawn{};  // the same draws without a list
        ASSERT_EQ(homcull_buffer_begin_frame(b, &view), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, shifted, 1), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, matrices, 2), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_frame_stats(b, &drawn), HOMCULL_OK);
        const std::size_t before = memory.calls;
        for (int frame = 0; frame < 3; ++frame) {
            ASSERT_EQ(homcull_buffer_begin_frame(b, &view), HOMCULL_OK);
            ASSERT_EQ(homcull_buffer_begin_tasks(b), HOMCULL_OK) << homcull_last_error();
            // While it records: draws of meshes only; no queries, frames or settings.
            EXPECT_EQ(homcull_buffer_begin_tasks(b), HOMCULL_ERROR_INVALID_OPERATION);
            ASSERT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, shifted, 1), HOMCULL_OK) << homcull_last_error();
            ASSERT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, matrices, 2), HOMCULL_OK) << homcull_last_error();
            const homcull_triangles triangles{scene.positions.data(), 12, scene.positions.size() / 3, scene.indices.data(), 2, 0, 8};
            EXPECT_EQ(homcull_buffer_draw_triangles(b, &triangles, nullptr), HOMCULL_ERROR_INVALID_OPERATION);
            std::vector<homcull_visibility> refused(scene.boxes.size(), 99);
            EXPECT_EQ(homcull_buffer_test_boxes(b, scene.boxes.data(), scene.boxes.size(), nullptr, refused.data()),
                      HOMCULL_ERROR_INVALID_OPERATION);
            EXPECT_EQ(refused, std::vector<homcull_visibility>(scene.boxes.size(), HOMCULL_VISIBLE));
            EXPECT_EQ(homcull_buffer_begin_frame(b, &view), HOMCULL_ERROR_INVALID_OPERATION);
            EXPECT_EQ(homcull_buffer_set_resolution(b, 100, 100), HOMCULL_ERROR_INVALID_OPERATION);
            EXPECT_EQ(homcull_buffer_run_task(b, 0), HOMCULL_ERROR_INVALID_OPERATION);  // not closed
            ASSERT_EQ(homcull_buffer_close_tasks(b, &tasks), HOMCULL_OK) << homcull_last_error();
            ASSERT_GE(tasks, 1u);
            EXPECT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, nullptr, 1), HOMCULL_ERROR_INVALID_OPERATION);  // closed
            EXPECT_EQ(homcull_buffer_run_task(b, tasks), HOMCULL_ERROR_INVALID_ARGUMENT);
            for (std::size_t i = tasks; i-- > 0;) ASSERT_EQ(homcull_buffer_run_task(b, i), HOMCULL_OK);
            ASSERT_EQ(homcull_buffer_finish_tasks(b), HOMCULL_OK) << homcull_last_error();
            std::vector<homcull_visibility> answers(scene.boxes.size(), 99);
            ASSERT_EQ(homcull_buffer_test_boxes(b, scene.boxes.data(), scene.boxes.size(), nullptr, answers.data()), HOMCULL_OK);
            EXPECT_EQ(answers, scene.expected) << "frame " << frame;
            homcull_frame_stats stats{};
            ASSERT_EQ(homcull_buffer_frame_stats(b, &stats), HOMCULL_OK);
            EXPECT_EQ(stats.draw_calls, 2u);
            EXPECT_EQ(stats.triangles_in, drawn.triangles_in);
            EXPECT_EQ(stats.triangles_drawn, drawn.triangles_drawn);
            EXPECT_EQ(stats.clusters_hidden, drawn.clusters_hidden);
            EXPECT_EQ(stats.allocations, 0u);
        }
        EXPECT_EQ(memory.calls, before);

        // A list whose tasks did not all run: an error; the buffer answers, conservatively.
        ASSERT_EQ(homcull_buffer_begin_frame(b, &view), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_begin_tasks(b), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, nullptr, 1), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_close_tasks(b, &tasks), HOMCULL_OK);
        EXPECT_EQ(homcull_buffer_finish_tasks(b), HOMCULL_ERROR_INVALID_OPERATION);
        EXPECT_NE(std::string(homcull_last_error()).find("did not run"), std::string::npos) << homcull_last_error();
        std::vector<homcull_visibility> answers(scene.boxes.size(), 99);
        ASSERT_EQ(homcull_buffer_test_boxes(b, scene.boxes.data(), scene.boxes.size(), nullptr, answers.data()), HOMCULL_OK);
        for (std::size_t k = 0; k < answers.size(); ++k)
            if (scene.expected[k] == HOMCULL_VISIBLE) {
                EXPECT_EQ(answers[k], HOMCULL_VISIBLE) << "box " << k;
            }
        // And one never closed: nothing was drawn.
        ASSERT_EQ(homcull_buffer_begin_tasks(b), HOMCULL_OK);
        ASSERT_EQ(homcull_buffer_draw_mesh(b, culler.mesh, nullptr, 1), HOMCULL_OK);
        EXPECT_EQ(homcull_buffer_finish_tasks(b), HOMCULL_ERROR_INVALID_OPERATION);
        EXPECT_EQ(culler.frame(scene, view), scene.expected);
    }
    EXPECT_EQ(memory.live, 0u);
}

// Whichever allocation fails, every call returns OK or HOMCULL_ERROR_OUT_OF_MEMORY, nothing
// leaks, and no answer hides what is visible.
TEST(CApi, OutOfMemoryAtEveryAllocation) {
    const Scene scene;
    EngineMemory counting;
    {
        Culler culler(scene, make_context(&counting));
        culler.frame(scene, engine_view(Engine::opengl));
    }
    const std::size_t total = counting.calls;
    ASSERT_GT(total, 10u);
    std::size_t failures_seen = 0;
    for (std::size_t k = 1; k <= total + 1; ++k) {
        EngineMemory memory;
        memory.fail_at = k;
        homcull_context_desc desc{};
        desc.allocator = memory.allocator();
        homcull_context* context = nullptr;
        const homcull_result made = homcull_context_create(&desc, &context);
        if (made != HOMCULL_OK) {
            EXPECT_EQ(made, HOMCULL_ERROR_OUT_OF_MEMORY);
            EXPECT_EQ(memory.live, 0u);
            ++failures_seen;
            continue;
        }
        const homcull_mesh_desc md = scene.mesh_desc();
        homcull_mesh* mesh = nullptr;
        homcull_result r = homcull_mesh_create(context, &md, &mesh);
        EXPECT_TRUE(r == HOMCULL_OK || r == HOMCULL_ERROR_OUT_OF_MEMORY) << homcull_result_name(r);
        failures_seen += r != HOMCULL_OK;
        homcull_buffer_desc bd{320, 180, 1, float(kNear), 0, 0};
        homcull_buffer* buffer = nullptr;
        r = homcull_buffer_create(context, &bd, &buffer);
        EXPECT_TRUE(r == HOMCULL_OK || r == HOMCULL_ERROR_OUT_OF_MEMORY) << homcull_result_name(r);
        failures_seen += r != HOMCULL_OK;
        if (buffer) {
            const homcull_view view = engine_view(Engine::opengl);
            EXPECT_EQ(homcull_buffer_begin_frame(buffer, &view), HOMCULL_OK);
            if (mesh) {
                r = homcull_buffer_draw_mesh(buffer, mesh, nullptr, 1);
                EXPECT_TRUE(r == HOMCULL_OK || r == HOMCULL_ERROR_OUT_OF_MEMORY) << homcull_result_name(r);
                failures_seen += r != HOMCULL_OK;
            }
            std::vector<homcull_visibility> answers(scene.boxes.size());
            EXPECT_EQ(homcull_buffer_test_boxes(buffer, scene.boxes.data(), answers.size(), nullptr, answers.data()), HOMCULL_OK);
            for (std::size_t b = 0; b < answers.size(); ++b) {
                if (scene.expected[b] == HOMCULL_VISIBLE) {
                    EXPECT_EQ(answers[b], HOMCULL_VISIBLE) << "failing allocation " << k << ", box " << b;
                }
            }
        }
        homcull_buffer_destroy(buffer);
        homcull_mesh_destroy(mesh);
        homcull_context_destroy(context);
        EXPECT_EQ(memory.live, 0u) << "failing allocation " << k;
    }
    EXPECT_EQ(failures_seen, total);  // every allocation failed once, and was reported
}

// A unit square in the z = 0 plane split into n x n cells of two triangles: 2 n^2 triangles per
// unit of surface.
struct GridMesh {
    std::vector<float> positions;
    std::vector<std::uint32_t> indices;
    explicit GridMesh(int n, bool flat = false) {
        for (int y = 0; y <= n; ++y)
            for (int x = 0; x <= n; ++x) positions.insert(positions.end(), {float(x) / float(n), flat ? 0.0f : float(y) / float(n), 0.0f});
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const auto a = std::uint32_t((n + 1) * y + x), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
                indices.insert(indices.end(), {a, b, d, a, d, c});
            }
    }
    homcull_mesh* make(homcull_context* context) const {
        const homcull_mesh_desc d = indexed_mesh_desc(positions, indices);
        homcull_mesh* mesh = nullptr;
        EXPECT_EQ(homcull_mesh_create(context, &d, &mesh), HOMCULL_OK) << homcull_last_error();
        return mesh;
    }
};

// Zhang's complexity filter over meshes and model matrices: candidates denser than factor times
// the median (triangles per unit of world surface) and those without surface are dropped; a
// matrix's scale counts; factor 0 keeps all; bad arguments and a failed allocation are errors
// that leave every candidate kept.
TEST(CApi, ComplexityFilterDropsDenseAndFlatCandidates) {
    EngineMemory memory;
    ErrorLog log;
    homcull_context* context = make_context(&memory, HOMCULL_ISA_BEST, &log);
    homcull_mesh* coarse = GridMesh(1).make(context);   // 2 triangles per unit
    homcull_mesh* fine = GridMesh(40).make(context);    // 3,200
    homcull_mesh* flat = GridMesh(2, true).make(context);  // no surface
    const homcull_mesh* meshes[7] = {coarse, coarse, coarse, coarse, fine, fine, flat};
    // Column-major: the identity, and a uniform scale by 40 for the second fine one (its
    // surface 1,600 times larger: 2 triangles per unit again).
    std::vector<float> matrices(16 * 7, 0.0f);
    for (int k = 0; k < 7; ++k)
        for (int i = 0; i < 4; ++i) matrices[std::size_t(16 * k + 5 * i)] = k == 5 && i < 3 ? 40.0f : 1.0f;
    std::uint8_t keep[7];
    ASSERT_EQ(homcull_filter_by_complexity(context, meshes, matrices.data(), HOMCULL_COLUMN_MAJOR, 7, 256.0, keep), HOMCULL_OK)
        << homcull_last_error();
    EXPECT_EQ(std::vector<std::uint8_t>(keep, keep + 7), (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 1, 0}));
    {  // the scene culler's filter over the same objects keeps the same ones
        homcull::Scene scene;
        for (const GridMesh& g : {GridMesh(1), GridMesh(40), GridMesh(2, true)}) {
            homcull::Mesh m;
            for (std::size_t i = 0; i < g.positions.size(); i += 3) m.positions.emplace_back(g.positions[i], g.positions[i + 1], g.positions[i + 2]);
            m.indices = g.indices;
            scene.meshes.push_back(m);
        }
        const std::uint32_t mesh_of[7] = {0, 0, 0, 0, 1, 1, 2};
        for (int k = 0; k < 7; ++k) {
            homcull::Object o;
            o.mesh = mesh_of[k];
            o.world = glm::make_mat4(matrices.data() + 16 * k);
            scene.objects.push_back(o);
        }
        scene.finalize();
        const std::vector<std::uint32_t> kept = homcull::filter_by_complexity(scene, {0, 1, 2, 3, 4, 5, 6}, 256.0);
        EXPECT_EQ(kept, (std::vector<std::uint32_t>{0, 1, 2, 3, 5}));
    }
    // Without matrices both fine meshes are dense; with a factor above 1,600 they stay.
    ASSERT_EQ(homcull_filter_by_complexity(context, meshes, nullptr, HOMCULL_ROW_MAJOR, 7, 256.0, keep), HOMCULL_OK);
    EXPECT_EQ(std::vector<std::uint8_t>(keep, keep + 7), (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 0, 0}));
    ASSERT_EQ(homcull_filter_by_complexity(context, meshes, nullptr, HOMCULL_ROW_MAJOR, 7, 2000.0, keep), HOMCULL_OK);
    EXPECT_EQ(std::vector<std::uint8_t>(keep, keep + 7), (std::vector<std::uint8_t>{1, 1, 1, 1, 1, 1, 0}));
    ASSERT_EQ(homcull_filter_by_complexity(context, meshes, nullptr, HOMCULL_COLUMN_MAJOR, 7, 0.0, keep), HOMCULL_OK);
    EXPECT_EQ(std::vector<std::uint8_t>(keep, keep + 7), std::vector<std::uint8_t>(7, 1));

    const auto all_kept_after = [&](homcull_result expected, const homcull_mesh* const* m, const float* matrix, homcull_matrix_layout layout,
                                    double factor) {
        std::fill(keep, keep + 7, std::uint8_t(0));
        EXPECT_EQ(homcull_filter_by_complexity(context, m, matrix, layout, 7, factor, keep), expected);
        EXPECT_EQ(std::vector<std::uint8_t>(keep, keep + 7), std::vector<std::uint8_t>(7, 1));
    };
    all_kept_after(HOMCULL_ERROR_INVALID_ARGUMENT, meshes, nullptr, HOMCULL_COLUMN_MAJOR, std::nan(""));
    all_kept_after(HOMCULL_ERROR_INVALID_ARGUMENT, meshes, nullptr, 7, 256.0);
    all_kept_after(HOMCULL_ERROR_INVALID_ARGUMENT, nullptr, nullptr, HOMCULL_COLUMN_MAJOR, 256.0);
    const homcull_mesh* with_null[7] = {coarse, coarse, nullptr, coarse, fine, fine, flat};
    all_kept_after(HOMCULL_ERROR_INVALID_ARGUMENT, with_null, nullptr, HOMCULL_COLUMN_MAJOR, 256.0);
    matrices[16 * 3 + 2] = INFINITY;
    all_kept_after(HOMCULL_ERROR_INVALID_ARGUMENT, meshes, matrices.data(), HOMCULL_COLUMN_MAJOR, 256.0);
    matrices[16 * 3 + 2] = 0.0f;
    memory.fail_at = memory.calls + 1;  // the densities' allocation
    all_kept_after(HOMCULL_ERROR_OUT_OF_MEMORY, meshes, matrices.data(), HOMCULL_COLUMN_MAJOR, 256.0);
    memory.fail_at = 0;
    EXPECT_EQ(homcull_filter_by_complexity(context, meshes, nullptr, HOMCULL_COLUMN_MAJOR, 0, 256.0, nullptr), HOMCULL_OK);
    EXPECT_EQ(homcull_filter_by_complexity(context, meshes, nullptr, HOMCULL_COLUMN_MAJOR, 7, 256.0, nullptr), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(log.messages.size(), 7u);  // one per error above
    homcull_mesh_destroy(coarse);
    homcull_mesh_destroy(fine);
    homcull_mesh_destroy(flat);
    homcull_context_destroy(context);
    EXPECT_EQ(memory.live, 0u);
}

// An answer with the samples it counted (0 for a box).
struct CountedAnswer {
    homcull_visibility visibility;
    std::uint64_t samples, visible_samples;
    bool operator==(const CountedAnswer& o) const { return visibility == o.visibility && samples == o.samples && visible_samples == o.visible_samples; }
    friend std::ostream& operator<<(std::ostream& out, const CountedAnswer& a) {
        return out << int(a.visibility) << " (" << a.visible_samples << " of " << a.samples << " samples)";
    }
};

// A reserve or a resolution change that runs out of memory part way leaves the buffer as it
// was: its next frames answer, and count samples, as a buffer's that never failed, the
// per-sample depth computed where queries read it included (it is kept in arrays the failed
// call may have moved before it failed).
TEST(CApi, ReserveOrResolutionChangeThatRunsOutOfMemoryLeavesTheBufferAsItWas) {
    const Scene scene;
    const Cube cube;
    const homcull_triangles triangles = cube.triangles();
    const auto view_from = [](glm::dvec3 eye) {
        homcull_view v = engine_view(Engine::opengl);
        store(glm::perspectiveRH_NO(kFovY, kAspect, kNear, kFar) * glm::lookAtRH(eye, eye + glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0)),
              v.layout, v.world_to_clip);
        return v;
    };
    // Cubes behind the wall, just behind it and in front of it, some across its edge.
    std::vector<std::array<float, 16>> models;
    for (const float z : {-7.0f, -11.5f, -13.0f, -25.0f})
        for (const float x : {-4.0f, 0.0f, 4.5f, 6.0f}) models.push_back({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, 1.0f, z, 1});
    const auto frame = [&](Culler& c, const homcull_view& view) {
        std::vector<CountedAnswer> answers;
        const std::vector<homcull_visibility> boxes = c.frame(scene, view);
        for (const homcull_visibility v : boxes) answers.push_back({v, 0, 0});
        for (const auto& m : models) {
            homcull_triangle_test_result r{};
            EXPECT_EQ(homcull_buffer_test_triangles_ex(c.buffer, &triangles, m.data(), nullptr, &r), HOMCULL_OK) << homcull_last_error();
            answers.push_back({r.visibility, r.samples, r.visible_samples});
        }
        return answers;
    };
    const homcull_view near_view = view_from({0, 0, 0}), far_view = view_from({0.3, -0.2, 6});
    const homcull_reserve_desc reserve{1280, 720, 64, 64, 4, 256, 0, 0};
    for (const bool resolution_change : {false, true}) {
        std::size_t failures = 0;
        for (std::size_t k = 1;; ++k) {
            EngineMemory memory;
            Culler failing(scene, make_context(&memory), 320, 180, HOMCULL_BUFFER_SAMPLE_DEPTH);
            Culler reference(scene, make_context(), 320, 180, HOMCULL_BUFFER_SAMPLE_DEPTH);
            ASSERT_EQ(frame(failing, near_view), frame(reference, near_view));  // the per-sample depth read, so written
            memory.fail_at = memory.calls + k;
            const homcull_result r = resolution_change ? homcull_buffer_set_resolution(failing.buffer, 1280, 720)
                                                       : homcull_buffer_reserve(failing.buffer, &reserve);
            memory.fail_at = 0;  // the frames below allocate where the call did not
            if (r == HOMCULL_OK) {
                ASSERT_EQ(resolution_change ? homcull_buffer_set_resolution(reference.buffer, 1280, 720) : homcull_buffer_reserve(reference.buffer, &reserve),
                          HOMCULL_OK);
            } else {
                ASSERT_EQ(r, HOMCULL_ERROR_OUT_OF_MEMORY) << homcull_result_name(r);
                ++failures;
            }
            // Then frames from farther back, where last frame's per-sample depth would hide what is
            // in front of the wall, and from the first place again.
            EXPECT_EQ(frame(failing, far_view), frame(reference, far_view)) << "allocation " << k << " of the call failing";
            EXPECT_EQ(frame(failing, near_view), frame(reference, near_view)) << "allocation " << k << " of the call failing";
            if (r == HOMCULL_OK) break;
        }
        EXPECT_GT(failures, 3u) << (resolution_change ? "set_resolution" : "reserve") << " allocates its arrays one by one";
    }
}

}  // namespace

// The header-only C++ layer (homcull.hpp): handles own their objects, spans carry the arrays.
#include <homcull/homcull.hpp>

namespace {

// The sorter: a cube mesh placed three times along -z, seen from the origin: nearest first;
// from behind, the reverse; errors are results; an object with a NaN matrix is left out.
TEST(CApi, SorterOrdersObjectsAndReportsErrors) {
    homcull_context* context = make_context();
    std::vector<float> cube;
    for (int k = 0; k < 8; ++k) cube.insert(cube.end(), {(k & 1) ? 1.f : -1.f, (k & 2) ? 1.f : -1.f, (k & 4) ? 1.f : -1.f});
    const std::uint32_t faces[36] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    homcull_mesh_desc md{};
    md.positions = cube.data();
    md.position_stride = 3 * sizeof(float);
    md.vertex_count = 8;
    md.indices = faces;
    md.index_size = 4;
    md.triangle_count = 12;
    homcull_mesh* mesh = nullptr;
    ASSERT_EQ(homcull_mesh_create(context, &md, &mesh), HOMCULL_OK) << homcull_last_error();
    const homcull_mesh* meshes[3] = {mesh, mesh, mesh};
    homcull_sorter_desc sd{meshes, 3};
    homcull_sorter* sorter = nullptr;
    ASSERT_EQ(homcull_sorter_create(context, &sd, &sorter), HOMCULL_OK) << homcull_last_error();
    // Row-major translations to z = -20, -5 and -10.
    float matrices[48] = {};
    const float z[3] = {-20, -5, -10};
    for (int i = 0; i < 3; ++i) {
        for (int d = 0; d < 4; ++d) matrices[16 * i + 5 * d] = 1.0f;
        matrices[16 * i + 11] = z[i];
    }
    homcull_sort_frame frame{};
    frame.model_matrices = matrices;
    frame.layout = HOMCULL_ROW_MAJOR;
    homcull_sort_result result{};
    ASSERT_EQ(homcull_sorter_sort(sorter, &frame, &result), HOMCULL_OK) << homcull_last_error();
    ASSERT_EQ(result.order_count, 3u);
    EXPECT_EQ(std::vector<std::uint32_t>(result.order, result.order + 3), (std::vector<std::uint32_t>{1, 2, 0}));
    ASSERT_EQ(result.layer_count, 3u);
    EXPECT_EQ(result.cycles, 0u);
    EXPECT_EQ(result.pair_count, 0u);  // the nearest-first start already holds: nothing tested true
    frame.eye[2] = -40.0f;
    ASSERT_EQ(homcull_sorter_sort(sorter, &frame, &result), HOMCULL_OK);
    EXPECT_EQ(std::vector<std::uint32_t>(result.order, result.order + 3), (std::vector<std::uint32_t>{0, 2, 1}));
    EXPECT_GT(result.pair_count, 0u);  // last frame's order no longer held

    matrices[3] = NAN;  // object 0 leaves
    ASSERT_EQ(homcull_sorter_sort(sorter, &frame, &result), HOMCULL_OK);
    EXPECT_EQ(result.order_count, 2u);
    frame.layout = 7;
    EXPECT_EQ(homcull_sorter_sort(sorter, &frame, &result), HOMCULL_ERROR_INVALID_ARGUMENT);
    frame.layout = HOMCULL_ROW_MAJOR;
    frame.plane_count = 17;
    EXPECT_EQ(homcull_sorter_sort(sorter, &frame, &result), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(homcull_sorter_sort(sorter, nullptr, &result), HOMCULL_ERROR_INVALID_ARGUMENT);
    const homcull_mesh* none[1] = {nullptr};
    homcull_sorter_desc bad{none, 1};
    homcull_sorter* refused = nullptr;
    EXPECT_EQ(homcull_sorter_create(context, &bad, &refused), HOMCULL_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(refused, nullptr);
    homcull_sorter_destroy(sorter);
    homcull_mesh_destroy(mesh);
    homcull_context_destroy(context);
}

TEST(CApi, CppLayerOwnsItsHandles) {
    const Scene scene;
    EngineMemory memory;
    {
        homcull_context_desc desc{};
        desc.allocator = memory.allocator();
        homcull::api::Context context;
        ASSERT_EQ(homcull::api::Context::create(desc, context), HOMCULL_OK);
        homcull::api::Mesh mesh;
        ASSERT_EQ(homcull::api::Mesh::create(context, scene.mesh_desc(), mesh), HOMCULL_OK);
        EXPECT_EQ(mesh.triangle_count(), 8u);
        homcull::api::Buffer buffer;
        ASSERT_EQ(homcull::api::Buffer::create(context, homcull_buffer_desc{320, 180, 1, float(kNear), 0, 0}, buffer), HOMCULL_OK);
        ASSERT_EQ(buffer.begin_frame(engine_view(Engine::opengl)), HOMCULL_OK);
        const float identity[2][16] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
        ASSERT_EQ(buffer.draw(mesh, homcull::api::Span<const float>(&identity[0][0], 32)), HOMCULL_OK);  // two instances
        std::vector<homcull_visibility> answers(scene.boxes.size());
        ASSERT_EQ(buffer.test(scene.boxes, answers), HOMCULL_OK);
        EXPECT_EQ(answers, scene.expected);
        std::vector<homcull_visibility> too_short(1);
        EXPECT_EQ(buffer.test(scene.boxes, too_short), HOMCULL_ERROR_INVALID_ARGUMENT);
        EXPECT_EQ(buffer.frame_stats().draw_calls, 1u);
        homcull::api::Buffer moved = std::move(buffer);
        EXPECT_FALSE(buffer);
        EXPECT_TRUE(moved);
        EXPECT_GT(memory.live, 0u);
    }
    EXPECT_EQ(memory.live, 0u);  // destroyed in reverse order, all given back
}

}  // namespace

// The engine's job system: the same answers and statistics as the calling thread, for
// registered meshes and for triangles, frame after frame, and after a reserve nothing allocated
// from the first frame on.
#include "support.hpp"

#include <homcull/world_triangles.hpp>

namespace {

TEST(CApi, JobSystemGivesTheAnswersOfTheCallingThread) {
    const homcull::test::CityStreet street;
    const homcull::WorldTriangles& occluders = street.occluders;
    homcull_mesh_desc md{};
    md.positions = occluders.positions.data();
    md.position_stride = 12;
    md.vertex_count = occluders.positions.size() / 3;
    md.indices = occluders.indices.data();
    md.index_size = 4;
    md.triangle_count = occluders.triangle_count();
    homcull_triangles triangles{md.positions, 12, md.vertex_count, md.indices, 4, 0, md.triangle_count};
    std::vector<homcull_box> boxes;
    for (const homcull::Object& o : street.city.objects)
        boxes.push_back({{o.world_bounds.min.x, o.world_bounds.min.y, o.world_bounds.min.z}, {o.world_bounds.max.x, o.world_bounds.max.y, o.world_bounds.max.z}});
    const homcull::ParallelFor threads = homcull::test::parallel_jobs();
    std::vector<homcull_visibility> answers[2];
    homcull_frame_stats stats[2][3];
    for (int threaded = 0; threaded < 2; ++threaded) {
        homcull_context* context = make_context();
        homcull_mesh* mesh = nullptr;
        ASSERT_EQ(homcull_mesh_create(context, &md, &mesh), HOMCULL_OK);
        homcull_buffer* buffer = nullptr;
        const homcull_buffer_desc bd{480, 270, 2, float(street.camera.near_plane), 0, 0};
        ASSERT_EQ(homcull_buffer_create(context, &bd, &buffer), HOMCULL_OK);
        if (threaded) {
            const homcull_job_system jobs{threads.run, threads.user, 2, 0};
            ASSERT_EQ(homcull_buffer_set_job_system(buffer, &jobs), HOMCULL_OK);
        }
        const homcull_reserve_desc reserve{480, 270, md.triangle_count, md.vertex_count, 1, md.triangle_count, 2, 0};
        ASSERT_EQ(homcull_buffer_reserve(buffer, &reserve), HOMCULL_OK) << homcull_last_error();
        for (int frame = 0; frame < 3; ++frame) {
            homcull::Camera camera = street.camera;
            camera.eye.z += 4.0 * frame;
            const glm::dmat4 clip = homcull::projection_matrix(camera, 480.0 / 270.0) * homcull::view_matrix(camera);
            homcull_view view{};
            store(clip, HOMCULL_COLUMN_MAJOR, view.world_to_clip);
            view.cull = HOMCULL_CULL_NONE;
            ASSERT_EQ(homcull_buffer_begin_frame(buffer, &view), HOMCULL_OK);
            if (frame == 1) {
                ASSERT_EQ(homcull_buffer_draw_triangles(buffer, &triangles, nullptr), HOMCULL_OK);
            } else {
                ASSERT_EQ(homcull_buffer_draw_mesh(buffer, mesh, nullptr, 1), HOMCULL_OK);
            }
            std::vector<homcull_visibility> a(boxes.size());
            ASSERT_EQ(homcull_buffer_test_boxes(buffer, boxes.data(), boxes.size(), nullptr, a.data()), HOMCULL_OK);
            answers[threaded].insert(answers[threaded].end(), a.begin(), a.end());
            ASSERT_EQ(homcull_buffer_frame_stats(buffer, &stats[threaded][frame]), HOMCULL_OK);
            EXPECT_EQ(stats[threaded][frame].allocations, 0u) << "threaded " << threaded << ", frame " << frame;
        }
        homcull_buffer_destroy(buffer);
        homcull_mesh_destroy(mesh);
        homcull_context_destroy(context);
    }
    EXPECT_EQ(answers[0], answers[1]);
    for (int frame = 0; frame < 3; ++frame) {
        EXPECT_EQ(stats[0][frame].triangles_drawn, stats[1][frame].triangles_drawn) << frame;
        EXPECT_EQ(stats[0][frame].clusters_hidden, stats[1][frame].clusters_hidden) << frame;
    }
    std::size_t occluded = 0;
    for (homcull_visibility v : answers[0]) occluded += v == HOMCULL_OCCLUDED;
    EXPECT_GT(occluded, 10u);
}

}  // namespace
