// Bad input gets a clear error that names the file and the problem, never a crash.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/generate.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/object_hierarchy.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/scene_culler.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace homcull {
namespace {

// The message of the homcull::Error that loading `path` throws.
std::string load_error(const std::string& path) {
    try {
        load_scene(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "(loaded without error)";
}

#define EXPECT_MENTIONS(message, fragment) \
    EXPECT_NE((message).find(fragment), std::string::npos) << "message: " << (message)

TEST(MalformedInput, MissingFilesAndFolders) {
    const std::string dir = test::temp_dir("Missing");
    for (const char* name : {"/none.glb", "/none.gltf", "/none.obj", "/none.ply"}) {
        const std::string message = load_error(dir + name);
        EXPECT_MENTIONS(message, dir + name);
        EXPECT_MENTIONS(message, "no such file");
    }
    EXPECT_MENTIONS(load_error(dir), "no such file");  // a folder is not a scene
}

TEST(MalformedInput, UnsupportedExtension) {
    const std::string path = test::temp_dir("Unsupported") + "/scene.xyz";
    test::write_text(path, "hello");
    EXPECT_MENTIONS(load_error(path), "unsupported scene format '.xyz'");
}

TEST(MalformedInput, BrokenGlbFiles) {
    const std::string dir = test::temp_dir("BrokenGlb");
    test::write_text(dir + "/empty.glb", "");
    test::write_text(dir + "/text.glb", "this is not a glb");
    test::write_text(dir + "/json.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [");
    for (const char* name : {"/empty.glb", "/text.glb", "/json.gltf"}) {
        const std::string message = load_error(dir + name);
        EXPECT_MENTIONS(message, dir + name);
        EXPECT_MENTIONS(message, "not a readable glTF file");
    }
    // A real GLB cut short at every few hundred bytes.
    save_glb(generate_scene("city:blocks=1"), dir + "/whole.glb");
    std::ifstream in(dir + "/whole.glb", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (std::size_t cut : {std::size_t(12), std::size_t(20), std::size_t(200), bytes.size() / 2, bytes.size() - 1}) {
        test::write_text(dir + "/cut.glb", bytes.substr(0, cut));
        EXPECT_MENTIONS(load_error(dir + "/cut.glb"), dir + "/cut.glb");
    }
}

// A one-triangle glTF whose pieces the tests below break one at a time.
// Positions (0,0,0) (1,0,0) (0,1,0) as little-endian floats; indices as base64 of uint16s.
std::string triangle_gltf(const std::string& indices_data, int index_count, int position_count = 3,
                          const std::string& position_type = "VEC3") {
    return R"({"asset":{"version":"2.0"},"nodes":[{"name":"t","mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(position_count) +
           R"(,"type":")" + position_type + R"(","min":[0,0,0],"max":[1,1,0]},
                   {"bufferView":1,"componentType":5123,"count":)" + std::to_string(index_count) + R"(,"type":"SCALAR"}],
      "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":1,"byteOffset":0,"byteLength":6}],
      "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"},
                 {"byteLength":6,"uri":"data:application/octet-stream;base64,)" + indices_data + R"("}]})";
}

TEST(MalformedInput, GltfIndexAndAccessorErrors) {
    const std::string dir = test::temp_dir("GltfErrors");
    test::write_text(dir + "/ok.gltf", triangle_gltf("AAABAAIA", 3));  // indices 0 1 2
    EXPECT_EQ(load_scene(dir + "/ok.gltf").instanced_triangle_count(), 1u);

    test::write_text(dir + "/index.gltf", triangle_gltf("AAABAAkA", 3));  // 0 1 9
    const std::string index_message = load_error(dir + "/index.gltf");
    EXPECT_MENTIONS(index_message, dir + "/index.gltf");
    EXPECT_MENTIONS(index_message, "index 9 out of range");

    test::write_text(dir + "/short.gltf", triangle_gltf("AAABAAIA", 3, 30));  // 30 positions in 36 bytes
    EXPECT_MENTIONS(load_error(dir + "/short.gltf"), "past the end");

    test::write_text(dir + "/count.gltf", triangle_gltf("AAABAAIA", 2));  // 2 indices: not triangles
    EXPECT_MENTIONS(load_error(dir + "/count.gltf"), dir + "/count.gltf");

    test::write_text(dir + "/type.gltf", triangle_gltf("AAABAAIA", 3, 3, "VEC2"));
    EXPECT_MENTIONS(load_error(dir + "/type.gltf"), dir + "/type.gltf");
}

TEST(MalformedInput, NonFiniteVerticesDropTheirTrianglesOnly) {
    Scene scene = generate_scene("city:blocks=1,cars=0");
    scene.meshes[1].positions[0].x = std::numeric_limits<float>::quiet_NaN();  // a box corner
    scene.meshes[1].positions[7].y = std::numeric_limits<float>::infinity();
    const std::string path = test::temp_dir("NonFinite") + "/nan.glb";
    save_glb(scene, path);
    const Scene loaded = load_scene(path);
    // Corner 0 is used by 6 of the box's triangles and corner 7 by the other 6: none is
    // left, and the boxes become empty objects (ids unchanged). One bad corner keeps 6.
    EXPECT_EQ(loaded.meshes[1].triangle_count(), 0u);
    Scene one_bad = generate_scene("city:blocks=1,cars=0");
    one_bad.meshes[1].positions[0].x = std::numeric_limits<float>::quiet_NaN();
    save_glb(one_bad, path);
    EXPECT_EQ(load_scene(path).meshes[1].triangle_count(), 6u);
    for (const Object& o : loaded.objects)
        EXPECT_TRUE(o.world_bounds.empty() || (std::isfinite(o.world_bounds.min.x) && std::isfinite(o.world_bounds.max.y)))
            << o.name;
}

// Objects whose transform puts them beyond float's range have world boxes with infinite bounds
// (transform_point rounds to float). The hierarchy's binning converted such a centre to int, an
// undefined conversion: SceneCuller's constructor crashed. Now they go to an end bin, every
// object is in the hierarchy once, and a cull answers every object.
TEST(MalformedInput, ObjectsBeyondFloatRange) {
    Scene scene = generate_scene("city:blocks=2,cars=0");
    const std::size_t finite_objects = scene.objects.size();
    Object stretched = scene.objects[1], moved = scene.objects[2];
    stretched.world = glm::scale(glm::dmat4(1.0), glm::dvec3(1e39, 1.0, 1.0)) * stretched.world;  // max x = +inf
    moved.world = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -1e39)) * moved.world;    // both z bounds -inf
    scene.objects.push_back(stretched);
    scene.objects.push_back(moved);
    scene.finalize();
    ASSERT_FALSE(std::isfinite(scene.objects[finite_objects].world_bounds.max.x));
    ASSERT_FALSE(std::isfinite(scene.objects[finite_objects + 1].world_bounds.min.z));

    const ObjectHierarchy h = ObjectHierarchy::build(scene, 2);
    std::vector<int> seen(scene.objects.size(), 0);
    for (std::uint32_t id : h.object_ids) ++seen[id];
    for (std::size_t id = 0; id < scene.objects.size(); ++id)
        EXPECT_EQ(seen[id], scene.objects[id].world_bounds.empty() ? 0 : 1) << "object " << id;

    SceneCullerConfig config;
    config.display = {160, 90};
    SceneCuller culler(scene, occluder_candidates(scene, OccluderFilter::role), config);
    Camera camera;
    camera.eye = {-30.0, 2.0, -30.0};
    camera.target = {0.0, 2.0, 0.0};
    std::vector<OccludeeAnswer> answers;
    culler.cull(camera, answers);
    ASSERT_EQ(answers.size(), scene.objects.size());
}

// Names are bytes in OBJ files, UTF-8 in glTF and JSON: invalid bytes become U+FFFD at load, so
// that the scene can be saved and printed (fuzz_scene_import found the exception that escaped).
TEST(MalformedInput, NamesThatAreNotUtf8AreMadeValid) {
    const std::string dir = test::temp_dir("NotUtf8");
    test::write_text(dir + "/names.obj", "o bad\x8a\xe3name\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const Scene scene = load_scene(dir + "/names.obj");
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_EQ(scene.objects[0].name, "bad\xEF\xBF\xBD\xEF\xBF\xBDname");
    save_glb(scene, dir + "/names.glb");
    EXPECT_EQ(load_scene(dir + "/names.glb").objects[0].name, scene.objects[0].name);
}

TEST(MalformedInput, BrokenObjFiles) {
    const std::string dir = test::temp_dir("BrokenObj");
    test::write_text(dir + "/garbage.obj", "\x01\x02\x03 not an obj\n");
    EXPECT_MENTIONS(load_error(dir + "/garbage.obj"), dir + "/garbage.obj");
    test::write_text(dir + "/index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    EXPECT_MENTIONS(load_error(dir + "/index.obj"), dir + "/index.obj");
}

TEST(MalformedInput, CameraPathFiles) {
    auto error_of = [](const std::string& text) {
        try {
            parse_camera_path(text, "path.json");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    EXPECT_MENTIONS(error_of("{"), "path.json: not valid JSON");
    EXPECT_MENTIONS(error_of("{\"frames\": 3}"), "expected {\"frames\"");
    EXPECT_MENTIONS(error_of("{\"frames\": []}"), "no frames");
    EXPECT_MENTIONS(error_of("{\"frames\": [{\"eye\":[0,0,0]}]}"), "frame 0: missing \"target\"");
    EXPECT_MENTIONS(error_of("{\"frames\": [{\"eye\":[0,0,0],\"target\":[0,0,-1]},{\"eye\":[1,1,1],\"target\":[1,1,1]}]}"),
                    "frame 1: camera: eye and target are the same point");
    EXPECT_MENTIONS(error_of("{\"frames\": [{\"eye\":[0,0],\"target\":[0,0,-1]}]}"), "three numbers");
    EXPECT_MENTIONS(error_of("{\"frames\": [{\"eye\":[0,0,0],\"target\":[0,0,-1],\"near\":\"x\"}]}"), "\"near\" must be a number");
    const CameraPath ok = parse_camera_path("{\"frames\": [{\"eye\":[0,0,0],\"target\":[0,0,-1]}]}", "p");
    EXPECT_EQ(ok.frames[0].fov_y_degrees, 60.0);
    EXPECT_EQ(ok.frames[0].far_plane, 10000.0);
    try {
        read_camera_path("/nonexistent/path.json");
        ADD_FAILURE();
    } catch (const Error& e) {
        EXPECT_MENTIONS(std::string(e.what()), "/nonexistent/path.json");
    }
    // A round trip through the file format keeps every number.
    CameraPath path;
    path.frames.push_back(ok.frames[0]);
    path.frames[0].eye = {0.1, 1.0 / 3.0, -7e5};
    EXPECT_EQ(parse_camera_path(camera_path_to_json(path), "p").frames[0].eye, path.frames[0].eye);
}

// Engine-side input to the occlusion buffer: missing arrays and counts that would overflow.
TEST(MalformedInput, OccluderArraysAndCounts) {
    std::uint8_t flags[2] = {};
    std::uint32_t apexes[6] = {};
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    EXPECT_THROW(compute_shared_edges(nullptr, 12, 3, nullptr, 1, flags, apexes), Error);
    EXPECT_THROW(compute_shared_edges(positions, 8, 3, nullptr, 1, flags, apexes), Error);
    EXPECT_THROW(compute_shared_edges(positions, 12, 3, nullptr, 1, nullptr, apexes), Error);
    EXPECT_THROW(compute_shared_edges(positions, 12, 3, nullptr, 1, flags, nullptr), Error);
    EXPECT_NO_THROW(compute_shared_edges(nullptr, 12, 0, nullptr, 0, nullptr, nullptr));  // nothing to do
    compute_shared_edges(positions, 12, 3, nullptr, 1, flags, apexes);
    EXPECT_EQ(flags[0], 0u);
    EXPECT_EQ(apexes[0], kNoApex);

    BufferConfig c;
    c.width = c.height = 8;
    OcclusionBuffer buffer(c);
    TriangleInput in = test::clip_space_input(std::vector<float>(positions, positions + 9));
    in.position_components = 3;
    in.position_stride = 12;
    in.clip_space = false;
    in.vertex_count = 3;
    in.triangle_count = std::numeric_limits<std::size_t>::max() / 3 + 1;  // 3 * count wraps around to 2
    EXPECT_THROW(buffer.render(in), Error);
    // Without indices, vertex numbers must fit 32 bits: a clear error, not a wrapped index
    // (nothing is read before the check).
    in.triangle_count = std::size_t(1) << 31;
    in.vertex_count = 3 * in.triangle_count;
    EXPECT_THROW(buffer.render(in), Error);
    EXPECT_THROW(buffer.test_triangles(in), Error);  // the same check for occludees
}

}  // namespace
}  // namespace homcull
