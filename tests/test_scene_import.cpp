// Import: glTF node order, hierarchy, shared meshes, extras, primitive modes; OBJ groups; PLY;
// the objects' world bounds.
#include "support.hpp"

#include <homcull/io/scene_io.hpp>
#include <homcull/scene.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace homcull {
namespace {

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const unsigned v = unsigned(bytes[i]) << 16 | (i + 1 < bytes.size() ? unsigned(bytes[i + 1]) << 8 : 0u) |
                           (i + 2 < bytes.size() ? bytes[i + 2] : 0u);
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

void append_floats(std::vector<unsigned char>& buffer, std::initializer_list<float> values) {
    for (float v : values) {
        unsigned char b[4];
        std::memcpy(b, &v, 4);
        buffer.insert(buffer.end(), b, b + 4);
    }
}

// A glTF with a node hierarchy, TRS transforms, a mesh used twice, extras, and triangle
// strips, fans and lines in one mesh.
std::string hierarchy_gltf() {
    std::vector<unsigned char> buffer;
    append_floats(buffer, {0, 0, 0, 1, 0, 0, 0, 1, 0});                  // 0: triangle, 36 bytes
    buffer.insert(buffer.end(), {0, 0, 1, 0, 2, 0, 0, 0});               // 36: uint16 0 1 2 + pad
    append_floats(buffer, {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});         // 44: strip of 4
    append_floats(buffer, {0, 0, 5, 1, 0, 5, 1, 1, 5, 0, 1, 5, -1, 1, 5});  // 92: fan of 5
    append_floats(buffer, {0, 0, 9, 1, 0, 9});                           // 152: line
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,2,3]}],
  "nodes":[
    {"name":"group","translation":[10,0,0],"children":[1]},
    {"name":"child","mesh":0,"scale":[2,2,2],"extras":{"set":"walls","role":"occluder","weight":3}},
    {"name":"sibling","mesh":0,"rotation":[0,0.7071067811865476,0,0.7071067811865476]},
    {"name":"modes","mesh":1}],
  "meshes":[
    {"name":"tri","primitives":[{"attributes":{"POSITION":0},"indices":1}]},
    {"name":"modes","primitives":[{"attributes":{"POSITION":2},"mode":5},{"attributes":{"POSITION":3},"mode":6},
                                 {"attributes":{"POSITION":4},"mode":1}]}],
  "accessors":[
    {"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
    {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"},
    {"bufferView":2,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
    {"bufferView":3,"componentType":5126,"count":5,"type":"VEC3","min":[-1,0,5],"max":[1,1,5]},
    {"bufferView":4,"componentType":5126,"count":2,"type":"VEC3","min":[0,0,9],"max":[1,0,9]}],
  "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6},
                 {"buffer":0,"byteOffset":44,"byteLength":48},{"buffer":0,"byteOffset":92,"byteLength":60},
                 {"buffer":0,"byteOffset":152,"byteLength":24}],
  "buffers":[{"byteLength":176,"uri":"data:application/octet-stream;base64,)" + base64(buffer) + R"("}]})";
}

TEST(SceneImport, GltfNodeOrderHierarchySharingAndExtras) {
    const std::string path = test::temp_dir("GltfHierarchy") + "/scene.gltf";
    test::write_text(path, hierarchy_gltf());
    const Scene scene = load_scene(path);
    ASSERT_EQ(scene.objects.size(), 3u);  // the mesh-bearing nodes 1, 2, 3 in array order
    EXPECT_EQ(scene.objects[0].name, "child");
    EXPECT_EQ(scene.objects[1].name, "sibling");
    EXPECT_EQ(scene.objects[2].name, "modes");
    EXPECT_EQ(scene.meshes.size(), 2u);
    EXPECT_EQ(scene.objects[0].mesh, scene.objects[1].mesh);  // shared, not copied

    // child: scaled by 2, then moved by its parent's translation (10, 0, 0).
    EXPECT_EQ(scene.objects[0].world_bounds.min, glm::vec3(10, 0, 0));
    EXPECT_EQ(scene.objects[0].world_bounds.max, glm::vec3(12, 2, 0));
    // sibling: a quarter turn about +y takes +x to -z.
    EXPECT_NEAR(scene.objects[1].world_bounds.min.z, -1.0f, 1e-6f);
    EXPECT_NEAR(scene.objects[1].world_bounds.max.x, 0.0f, 1e-6f);

    // Extras with keys sorted (tinygltf keeps them in a map); non-string values as JSON text.
    const std::vector<std::pair<std::string, std::string>> extras = {{"role", "occluder"}, {"set", "walls"}, {"weight", "3"}};
    EXPECT_EQ(scene.objects[0].extras, extras);
    EXPECT_TRUE(scene.objects[1].extras.empty());

    // Strip of 4 -> 2 triangles, fan of 5 -> 3, the line is skipped. Winding stays CCW (+z).
    const Mesh& modes = scene.meshes[scene.objects[2].mesh];
    ASSERT_EQ(modes.triangle_count(), 5u);
    for (std::size_t t = 0; t < 5; ++t) {
        const glm::vec3 a = modes.positions[modes.indices[3 * t]], b = modes.positions[modes.indices[3 * t + 1]],
                        c = modes.positions[modes.indices[3 * t + 2]];
        EXPECT_GT(glm::cross(b - a, c - a).z, 0.0f) << "triangle " << t;
    }
}

TEST(SceneImport, ObjHasOneObjectPerGroup) {
    const std::string path = test::temp_dir("ObjGroups") + "/groups.obj";
    test::write_text(path,
                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                     "f 1 2 3\n"
                     "o first\nf 2 4 3\n"
                     "g grp\nf 1 2 4\nf 1 4 3\n"
                     "o empty\n"
                     "g a\nf 1 2 3\n"
                     "g b\nf 2 4 3\n");
    const Scene scene = load_scene(path);
    std::vector<std::string> names;
    std::vector<std::size_t> triangles;
    for (const Object& o : scene.objects) {
        names.push_back(o.name);
        triangles.push_back(scene.triangle_count(o));
    }
    EXPECT_EQ(names, (std::vector<std::string>{"defaultobject", "first", "grp", "a", "b"}));
    EXPECT_EQ(triangles, (std::vector<std::size_t>{1, 1, 2, 1, 1}));
}

TEST(SceneImport, ObjWithoutGroupsIsOneObjectAndPolygonsAreTriangulated) {
    const std::string path = test::temp_dir("ObjWhole") + "/quad.obj";
    test::write_text(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    const Scene scene = load_scene(path);
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_EQ(scene.triangle_count(scene.objects[0]), 2u);
}

TEST(SceneImport, PlyThroughAssimp) {
    const std::string path = test::temp_dir("Ply") + "/mesh.ply";
    test::write_text(path,
                     "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
    const Scene scene = load_scene(path);
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_EQ(scene.triangle_count(scene.objects[0]), 2u);
    EXPECT_EQ(scene.objects[0].world_bounds.max, glm::vec3(1, 1, 0));
}

}  // namespace
}  // namespace homcull

namespace homcull {
namespace {

// Scene::finalize bounds an object from each vertex its indices name, once: the same floats as
// extending the box at every index in turn, signed zeros and NaN included (glm::min and max keep
// the first of equal values and never take a NaN, so repeats and the order of first naming are
// all that could matter).
TEST(SceneBounds, FromEachVertexOnceAreTheBoundsFromEveryIndex) {
    std::mt19937 random(11);
    const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, std::nanf(""), 3.0f, -2.5f};
    for (int round = 0; round < 400; ++round) {
        Scene scene;
        Mesh mesh;
        const int vertices = 1 + int(random() % 12);
        for (int v = 0; v < vertices; ++v)
            mesh.positions.emplace_back(values[random() % 8], values[random() % 8], values[random() % 8]);
        const int triangles = 1 + int(random() % 10);
        for (int i = 0; i < 3 * triangles; ++i) mesh.indices.push_back(std::uint32_t(random() % std::uint32_t(vertices)));
        scene.meshes.push_back(mesh);
        for (int o = 0; o < 3; ++o) {
            Object object;
            object.mesh = 0;
            // Scales of either sign and zero (which makes -0 and +0 of the same vertex), and shifts.
            for (int c = 0; c < 3; ++c) {
                object.world[c][c] = double(values[random() % 8]);
                if (object.world[c][c] != object.world[c][c]) object.world[c][c] = 0.0;
                object.world[3][c] = double(values[random() % 8]);  // NaN: the whole object is not finite
            }
            scene.objects.push_back(object);
        }
        scene.finalize();
        for (const Object& object : scene.objects) {
            Aabb expected;
            for (const std::uint32_t index : mesh.indices) expected.extend(transform_point(object.world, mesh.positions[index]));
            ASSERT_EQ(std::memcmp(&expected.min, &object.world_bounds.min, sizeof(glm::vec3)), 0) << "round " << round;
            ASSERT_EQ(std::memcmp(&expected.max, &object.world_bounds.max, sizeof(glm::vec3)), 0) << "round " << round;
        }
    }
}

}  // namespace
}  // namespace homcull
