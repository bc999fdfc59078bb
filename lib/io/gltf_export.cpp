// Binary glTF export through tinygltf, so that generated scenes can be saved, looked at in
// any glTF viewer, and fed to other culling tools.
#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/io/write_file.hpp>

#include "io/tinygltf_config.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

namespace homcull {
namespace {

// Appends raw bytes to the single buffer and returns the new bufferView's index.
int add_buffer_view(tinygltf::Model& model, const void* data, std::size_t bytes, int target) {
    auto& buffer = model.buffers[0].data;
    while (buffer.size() % 4 != 0) buffer.push_back(0);  // glTF requires aligned accessors
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* begin = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), begin, begin + bytes);
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size() - 1);
}

}  // namespace

void save_glb(const Scene& scene, const std::string& path) {
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "homcull";
    model.buffers.resize(1);

    for (const Mesh& mesh : scene.meshes) {
        if (mesh.indices.empty() || mesh.positions.empty())
            throw Error(path + ": cannot write mesh '" + mesh.name + "': glTF does not allow empty meshes");
        tinygltf::Accessor positions;
        positions.bufferView = add_buffer_view(model, mesh.positions.data(),
                                               mesh.positions.size() * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
        positions.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        positions.type = TINYGLTF_TYPE_VEC3;
        positions.count = mesh.positions.size();
        Aabb box;
        for (const auto& p : mesh.positions)  // glTF min/max must be numbers: skip NaN/Inf
            if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) box.extend(p);
        if (box.empty()) box.extend(glm::vec3(0.0f));
        positions.minValues = {box.min.x, box.min.y, box.min.z};
        positions.maxValues = {box.max.x, box.max.y, box.max.z};
        model.accessors.push_back(positions);

        tinygltf::Accessor indices;
        indices.bufferView = add_buffer_view(model, mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t),
                                             TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        indices.type = TINYGLTF_TYPE_SCALAR;
        indices.count = mesh.indices.size();
        model.accessors.push_back(indices);

        tinygltf::Primitive primitive;
        primitive.attributes["POSITION"] = int(model.accessors.size() - 2);
        primitive.indices = int(model.accessors.size() - 1);
        primitive.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Mesh gm;
        gm.name = mesh.name;
        gm.primitives.push_back(primitive);
        model.meshes.push_back(gm);
    }

    tinygltf::Scene root;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const Object& object = scene.objects[i];
        tinygltf::Node node;
        node.name = object.name;
        node.mesh = int(object.mesh);
        if (object.world != glm::dmat4(1.0))
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) node.matrix.push_back(object.world[c][r]);
        if (!object.extras.empty()) {
            tinygltf::Value::Object extras;
            for (const auto& [key, value] : object.extras) extras[key] = tinygltf::Value(value);
            node.extras = tinygltf::Value(extras);
        }
        model.nodes.push_back(node);
        root.nodes.push_back(int(i));
    }
    model.scenes.push_back(root);
    model.defaultScene = 0;

    // Serialized in memory, then written by write_file, which reports what tinygltf's own file
    // writing does not (a folder as the path, a missing folder, a full disk).
    tinygltf::TinyGLTF writer;
    std::ostringstream glb;
    try {
        if (!writer.WriteGltfSceneToStream(&model, glb, /*prettyPrint=*/false, /*writeBinary=*/true))
            throw Error(path + ": could not serialize the scene as glTF");
    } catch (const std::exception& e) {  // nlohmann::json's, for text JSON cannot hold
        throw Error(path + ": could not serialize the scene as glTF: " + e.what());
    }
    write_file(path, glb.str(), "the scene");
}

}  // namespace homcull
