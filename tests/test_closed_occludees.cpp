// Closed occludees (scene/closed_occludees.hpp, buffer/seen_solid.hpp): which objects are closed
// solids, when the eye certainly sees a triangle from behind, and that the scene culler passes
// over those triangles only for a solid seen from outside, never hiding what Embree sees.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/scene_culler.hpp>
#include <homcull/truth/ray_scene.hpp>
#include <homcull/world_triangles.hpp>

#include "buffer/seen_solid.hpp"
#include "scene/closed_occludees.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace homcull {
namespace {

constexpr std::size_t kNotGathered = ~std::size_t(0);

// A regular octahedron, counter-clockwise seen from outside.
Mesh octahedron(glm::vec3 centre, float radius) {
    Mesh mesh;
    mesh.name = "octahedron";
    const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& a : axes) mesh.positions.push_back(centre + radius * a);
    mesh.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    return mesh;
}

OcclusionBuffer::ClosedSolid solid(glm::dvec3 eye, int orientation) { return {{eye.x, eye.y, eye.z}, orientation}; }

std::vector<std::int8_t> orientations(const Scene& scene) {
    std::vector<float> positions;
    std::vector<std::size_t> first(scene.objects.size());
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        first[id] = positions.size() / 3;
        append_world_positions(scene, scene.objects[id], positions);
    }
    return detail::closed_occludee_orientations(scene, positions, first, kNotGathered);
}

TEST(ClosedOccludees, OrientationsOfClosedOpenFlatMirroredAndSplitMeshes) {
    Scene scene;
    const std::uint32_t box = test::add_box(scene, "box", {0, 0, 0}, {1, 2, 3});
    const std::uint32_t closed = test::add_object_with_own_mesh(scene, octahedron({5, 0, 0}, 1));
    Mesh inside_out = octahedron({10, 0, 0}, 1);
    for (std::size_t t = 0; t < inside_out.indices.size(); t += 3) std::swap(inside_out.indices[t + 1], inside_out.indices[t + 2]);
    const std::uint32_t inverted = test::add_object_with_own_mesh(scene, inside_out);
    Mesh open = octahedron({15, 0, 0}, 1);
    open.indices.resize(open.indices.size() - 3);  // one face missing
    const std::uint32_t open_id = test::add_object_with_own_mesh(scene, open);
    // Two sides of one quad, back to back: every edge shared, no volume.
    Mesh sheet;
    sheet.positions = {{20, 0, 0}, {21, 0, 0}, {21, 1, 0}, {20, 1, 0}};
    sheet.indices = {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2};
    const std::uint32_t flat = test::add_object_with_own_mesh(scene, sheet);
    // An outward piece and an inside-out piece in one mesh: no single sign.
    Mesh mixed = octahedron({25, 0, 0}, 1);
    const Mesh other = octahedron({28, 0, 0}, 1);
    for (const glm::vec3& p : other.positions) mixed.positions.push_back(p);
    for (std::size_t t = 0; t < other.indices.size(); t += 3)
        mixed.indices.insert(mixed.indices.end(), {other.indices[t] + 6, other.indices[t + 2] + 6, other.indices[t + 1] + 6});
    const std::uint32_t two_signs = test::add_object_with_own_mesh(scene, mixed);
    // A small inside-out piece touching an outward one at a vertex only: two pieces, two signs
    // (joined through the vertex, their volumes would sum to a positive one).
    Mesh touching = octahedron({40, 0, 0}, 1);
    const Mesh small = octahedron({41.5f, 0, 0}, 0.5f);  // its vertex (41, 0, 0) is the other's
    for (const glm::vec3& p : small.positions) touching.positions.push_back(p);
    for (std::size_t t = 0; t < small.indices.size(); t += 3)
        touching.indices.insert(touching.indices.end(), {small.indices[t] + 6, small.indices[t + 2] + 6, small.indices[t + 1] + 6});
    const std::uint32_t at_a_vertex = test::add_object_with_own_mesh(scene, touching);
    // Each face with its own four vertices (split normals): closed by position.
    Mesh split;
    const Mesh whole = octahedron({35, 0, 0}, 2);
    for (std::size_t i = 0; i < whole.indices.size(); ++i) {
        split.positions.push_back(whole.positions[whole.indices[i]]);
        split.indices.push_back(std::uint32_t(i));
    }
    const std::uint32_t seams = test::add_object_with_own_mesh(scene, split);
    // The box's mesh again, mirrored by its world transform: fronts facing in.
    Object mirrored = scene.objects[box];
    mirrored.world = glm::scale(glm::dmat4(1.0), glm::dvec3(-1.0, 1.0, 1.0));
    scene.objects.push_back(mirrored);
    const std::uint32_t mirror = std::uint32_t(scene.objects.size() - 1);
    scene.finalize();

    const std::vector<std::int8_t> o = orientations(scene);
    EXPECT_EQ(o[box], 1);
    EXPECT_EQ(o[closed], 1);
    EXPECT_EQ(o[inverted], -1);
    EXPECT_EQ(o[open_id], 0);
    EXPECT_EQ(o[flat], 0);
    EXPECT_EQ(o[two_signs], 0);
    EXPECT_EQ(o[at_a_vertex], 0);
    EXPECT_EQ(o[seams], 1);
    EXPECT_EQ(o[mirror], -1);
}

TEST(ClosedOccludees, BackFacesOnlyWhenCertain) {
    const glm::dvec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);  // counter-clockwise seen from +z
    EXPECT_TRUE(detail::certainly_faces_away(a, b, c, solid({0.2, 0.2, -1.0}, 1)));
    EXPECT_FALSE(detail::certainly_faces_away(a, b, c, solid({0.2, 0.2, 1.0}, 1)));
    EXPECT_FALSE(detail::certainly_faces_away(a, b, c, solid({0.2, 0.2, -1.0}, -1)));
    EXPECT_TRUE(detail::certainly_faces_away(a, b, c, solid({0.2, 0.2, 1.0}, -1)));
    EXPECT_FALSE(detail::certainly_faces_away(a, b, c, solid({5.0, 7.0, 0.0}, 1)));  // in its plane
    // A tilted triangle (normal (-1, 0, 1)) and an eye far along its plane: the terms of the
    // product are 1e6, so an offset of 1e-9 is within their rounding bound, 1e-3 is not.
    const glm::dvec3 tilted(1, 0, 1);
    EXPECT_FALSE(detail::certainly_faces_away(a, tilted, c, solid({1e6, 0.0, 1e6}, 1)));
    EXPECT_FALSE(detail::certainly_faces_away(a, tilted, c, solid({1e6, 0.0, 1e6 - 1e-9}, 1)));
    EXPECT_TRUE(detail::certainly_faces_away(a, tilted, c, solid({1e6, 0.0, 1e6 - 1e-3}, 1)));
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(detail::certainly_faces_away(a, b, c, solid({nan, 0.0, -1.0}, 1)));
    EXPECT_FALSE(detail::certainly_faces_away(a, b, glm::dvec3(nan, 1.0, 0.0), solid({0.2, 0.2, -1.0}, 1)));
    // Far from the origin (large coordinates, a small triangle): still decided by the sign.
    const glm::dvec3 far(1e6, -2e6, 3e5);
    EXPECT_TRUE(detail::certainly_faces_away(far + a, far + b, far + c, solid(far + glm::dvec3(0.2, 0.2, -1.0), 1)));
    EXPECT_FALSE(detail::certainly_faces_away(far + a, far + b, far + c, solid(far + glm::dvec3(0.2, 0.2, 1.0), 1)));
}

// ClosedSolid's argument needs rays from one eye and point positions: an orthographic, clip-space
// or 4-component input, an orientation other than +1 or -1, or a non-finite eye is an error,
// not a quietly wrong answer.
TEST(ClosedOccludees, AClosedSolidOutsideItsArgumentIsAnError) {
    const OcclusionBuffer buffer(test::buffer_config(64, 48, 1, 0.5f, false));
    const Mesh solid_mesh = octahedron({0, 0, -5}, 1);
    TriangleInput in;
    in.positions = &solid_mesh.positions[0].x;
    in.vertex_count = solid_mesh.positions.size();
    in.indices = solid_mesh.indices.data();
    in.triangle_count = solid_mesh.triangle_count();
    in.model_to_clip = clip_from_world(test::camera_down_minus_z(90.0), 64.0 / 48.0);
    const OcclusionBuffer::ClosedSolid good = solid({0, 0, 0}, 1);
    EXPECT_EQ(buffer.test_triangles(in, 0, 0, good).visibility, buffer.test_triangles(in).visibility);
    EXPECT_THROW(buffer.test_triangles(in, 0, 0, solid({0, 0, 0}, 0)), Error);
    EXPECT_THROW(buffer.test_triangles(in, 0, 0, solid({0, 0, 0}, 2)), Error);
    EXPECT_THROW(buffer.test_triangles(in, 0, 0, solid({std::numeric_limits<double>::quiet_NaN(), 0, 0}, 1)), Error);
    EXPECT_THROW(buffer.test_triangles(in, 0, 0, solid({0, 0, std::numeric_limits<double>::infinity()}, 1)), Error);
    TriangleInput clip = in;
    clip.clip_space = true;
    EXPECT_THROW(buffer.test_triangles(clip, 0, 0, good), Error);
    std::vector<float> xyzw;
    for (const glm::vec3& p : solid_mesh.positions) xyzw.insert(xyzw.end(), {p.x, p.y, p.z, 1.0f});
    TriangleInput four = in;
    four.positions = xyzw.data();
    four.position_components = 4;
    four.position_stride = 4 * sizeof(float);
    EXPECT_THROW(buffer.test_triangles(four, 0, 0, good), Error);
    TriangleInput ortho = in;
    ortho.orthographic = true;
    EXPECT_THROW(buffer.test_triangles(ortho, 0, 0, good), Error);
}

// A closed octahedron behind a wall, placed so that the wall hides it but not its box (and not
// every part's box): its parts are tested as a solid seen from outside, and it is hidden. A
// closed room around the eye is seen from inside, from behind every face: it is never taken as
// a solid, and stays visible, as Embree sees it. Both against Embree at every sample.
TEST(ClosedOccludees, SolidsOnlyFromOutsideAndNeverHidingWhatIsSeen) {
    Scene scene;
    const std::uint32_t wall = test::add_box(scene, "wall", {-5, -5, -20}, {5, 5, -10});
    const std::uint32_t behind = test::add_object_with_own_mesh(scene, octahedron({11.2f, 0.0f, -30.0f}, 3.0f));
    const std::uint32_t room = test::add_box(scene, "room around the eye", {-60, -60, -100}, {60, 60, 40});
    scene.finalize();
    const Camera camera = test::camera_down_minus_z(90.0);
    const Resolution display{160, 120};
    SceneCullerConfig config;
    config.display = display;
    SceneCuller culler(scene, {wall}, config);
    std::vector<OccludeeAnswer> answers;
    culler.cull(camera, answers);
    EXPECT_EQ(answers[behind].visibility, Visibility::occluded);
    EXPECT_EQ(answers[room].visibility, Visibility::visible);
    EXPECT_GT(culler.work().solid_parts_tested, 0u);

    const RayScene rays(scene);
    const auto seen_by_embree = [&](const Camera& c) {
        std::vector<std::uint8_t> visible(scene.objects.size(), 0);
        for (const std::uint32_t id : test::embree_first_hits(rays, scene, c, display))
            if (id < visible.size()) visible[id] = 1;
        return visible;
    };
    const std::vector<std::uint8_t> visible = seen_by_embree(camera);
    EXPECT_TRUE(visible[room]);
    EXPECT_FALSE(visible[behind]);
    for (std::size_t id = 0; id < answers.size(); ++id) {
        if (visible[id]) {
            EXPECT_EQ(answers[id].visibility, Visibility::visible) << id;
        }
    }

    // The eye inside the octahedron, looking back at the wall: it sees the octahedron's faces
    // from behind, and so does Embree; the wall, wholly beyond the near plane, is a solid seen
    // from outside.
    Camera inside = camera;
    inside.eye = {11.2, 0.0, -30.0};
    inside.target = {0.0, 0.0, 0.0};
    culler.cull(inside, answers);
    const std::vector<std::uint8_t> visible_inside = seen_by_embree(inside);
    EXPECT_TRUE(visible_inside[behind]);
    EXPECT_EQ(answers[behind].visibility, Visibility::visible);
    for (std::size_t id = 0; id < answers.size(); ++id) {
        if (visible_inside[id]) {
            EXPECT_EQ(answers[id].visibility, Visibility::visible) << id;
        }
    }
}

}  // namespace
}  // namespace homcull
