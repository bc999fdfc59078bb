// glTF 2.0 import through tinygltf (Debian's libtinygltf). We use it rather than assimp's
// glTF importer because object ids are defined by the order of the file's `nodes` array and
// by node extras (the castle's `role`), both of which assimp's node tree does not keep.
#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>

#include <nlohmann/json.hpp>
#include "io/tinygltf_config.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace homcull {
namespace {

// Images are irrelevant to occlusion; accept them without decoding.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*) {
    return true;
}

class GltfReader {
public:
    GltfReader(const tinygltf::Model& model, std::string path) : model_(model), path_(std::move(path)) {}

    Scene read() {
        Scene scene;
        scene.source = path_;
        mesh_index_.assign(model_.meshes.size(), -1);
        const std::vector<glm::dmat4> world = world_transforms();
        for (std::size_t n = 0; n < model_.nodes.size(); ++n) {
            const tinygltf::Node& node = model_.nodes[n];
            if (node.mesh < 0) continue;
            if (std::size_t(node.mesh) >= model_.meshes.size())
                fail("node " + std::to_string(n) + " names mesh " + std::to_string(node.mesh) +
                     " but the file has " + std::to_string(model_.meshes.size()));
            int& shared = mesh_index_[node.mesh];
            if (shared < 0) {
                shared = int(scene.meshes.size());
                scene.meshes.push_back(read_mesh(node.mesh));
            }
            Object object;
            object.name = node.name.empty() ? "node" + std::to_string(n) : node.name;
            object.mesh = std::uint32_t(shared);
            object.world = world[n];
            object.extras = read_extras(node.extras_json_string, n);
            scene.objects.push_back(std::move(object));
        }
        if (dropped_triangles_ > 0)
            std::fprintf(stderr, "homcull: warning: %s: dropped %zu triangles with non-finite vertices\n",
                         path_.c_str(), dropped_triangles_);
        if (skipped_primitives_ > 0)
            std::fprintf(stderr, "homcull: warning: %s: skipped %zu point or line primitives\n",
                         path_.c_str(), skipped_primitives_);
        scene.finalize();
        return scene;
    }

private:
    [[noreturn]] void fail(const std::string& what) const { throw Error(path_ + ": " + what); }

    glm::dmat4 local_transform(const tinygltf::Node& node, std::size_t n) const {
        glm::dmat4 m(1.0);
        if (!node.matrix.empty()) {
            if (node.matrix.size() != 16) fail("node " + std::to_string(n) + " has a matrix of " + std::to_string(node.matrix.size()) + " numbers");
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[std::size_t(4 * c + r)];  // column-major, as glm
            return m;
        }
        glm::dmat4 t(1.0), r(1.0), s(1.0);
        if (node.translation.size() == 3) t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
        if (node.rotation.size() == 4) {
            const double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2], w = node.rotation[3];
            r = glm::dmat4(1.0 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0.0,
                           2 * (x * y - z * w), 1.0 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0.0,
                           2 * (x * z + y * w), 2 * (y * z - x * w), 1.0 - 2 * (x * x + y * y), 0.0,
                           0.0, 0.0, 0.0, 1.0);
        }
        if (node.scale.size() == 3) {
            s[0][0] = node.scale[0];
            s[1][1] = node.scale[1];
            s[2][2] = node.scale[2];
        }
        return t * r * s;
    }

    // World transform of every node: parent world * local, over the node forest.
    std::vector<glm::dmat4> world_transforms() const {
        const std::size_t count = model_.nodes.size();
        std::vector<int> parent(count, -1);
        for (std::size_t n = 0; n < count; ++n)
            for (int child : model_.nodes[n].children) {
                if (child < 0 || std::size_t(child) >= count)
                    fail("node " + std::to_string(n) + " has child " + std::to_string(child) + " out of range");
                if (parent[std::size_t(child)] >= 0)
                    fail("node " + std::to_string(child) + " has two parents");
                parent[std::size_t(child)] = int(n);
            }
        std::vector<glm::dmat4> world(count);
        std::vector<char> state(count, 0);  // 0 not done, 1 in progress, 2 done
        for (std::size_t n = 0; n < count; ++n) {
            // Walk up to the first finished ancestor, then come back down.
            std::vector<std::size_t> chain;
            for (int k = int(n); k >= 0 && state[std::size_t(k)] != 2; k = parent[std::size_t(k)]) {
                if (state[std::size_t(k)] == 1) fail("the node hierarchy has a cycle through node " + std::to_string(k));
                state[std::size_t(k)] = 1;
                chain.push_back(std::size_t(k));
            }
            for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
                const int p = parent[*it];
                const glm::dmat4 local = local_transform(model_.nodes[*it], *it);
                world[*it] = p >= 0 ? world[std::size_t(p)] * local : local;
                state[*it] = 2;
            }
        }
        return world;
    }

    // Checked view of an accessor's bytes: element i starts at data + i * stride.
    struct View {
        const unsigned char* data;
        std::size_t stride;
        std::size_t count;
    };

    View accessor_view(int index, const std::string& what) const {
        if (index < 0 || std::size_t(index) >= model_.accessors.size())
            fail(what + ": accessor " + std::to_string(index) + " out of range");
        const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
        if (a.sparse.isSparse) fail(what + ": sparse accessors are not supported");
        if (a.bufferView < 0 || std::size_t(a.bufferView) >= model_.bufferViews.size())
            fail(what + ": accessor " + std::to_string(index) + " has no valid bufferView");
        const tinygltf::BufferView& v = model_.bufferViews[std::size_t(a.bufferView)];
        if (v.buffer < 0 || std::size_t(v.buffer) >= model_.buffers.size())
            fail(what + ": bufferView " + std::to_string(a.bufferView) + " has no valid buffer");
        const auto& bytes = model_.buffers[std::size_t(v.buffer)].data;
        const int stride = a.ByteStride(v);
        const int element = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType)) *
                            tinygltf::GetNumComponentsInType(std::uint32_t(a.type));
        if (stride <= 0 || element <= 0) fail(what + ": accessor " + std::to_string(index) + " has an invalid layout");
        const std::size_t begin = v.byteOffset + a.byteOffset;
        const std::size_t needed = a.count == 0 ? 0 : (a.count - 1) * std::size_t(stride) + std::size_t(element);
        if (a.byteOffset + needed > v.byteLength || v.byteOffset + v.byteLength > bytes.size())
            fail(what + ": accessor " + std::to_string(index) + " reaches past the end of its buffer");
        return {bytes.data() + begin, std::size_t(stride), a.count};
    }

    Mesh read_mesh(int mesh_index) {
        const tinygltf::Mesh& gm = model_.meshes[std::size_t(mesh_index)];
        Mesh mesh;
        mesh.name = gm.name.empty() ? "mesh" + std::to_string(mesh_index) : gm.name;
        std::vector<char> finite;
        for (std::size_t p = 0; p < gm.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = gm.primitives[p];
            const std::string what = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(p);
            if (prim.mode >= 0 && prim.mode <= 3) { ++skipped_primitives_; continue; }
            if (prim.mode > 6) fail(what + ": unknown primitive mode " + std::to_string(prim.mode));
            auto pos = prim.attributes.find("POSITION");
            if (pos == prim.attributes.end()) fail(what + " has no POSITION attribute");
            const View pv = accessor_view(pos->second, what + " POSITION");
            const tinygltf::Accessor& pa = model_.accessors[std::size_t(pos->second)];
            if (pa.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || pa.type != TINYGLTF_TYPE_VEC3)
                fail(what + ": POSITION must be float VEC3 (quantized positions are not supported)");
            const std::uint32_t base = std::uint32_t(mesh.positions.size());
            for (std::size_t i = 0; i < pv.count; ++i) {
                float xyz[3];
                std::memcpy(xyz, pv.data + i * pv.stride, sizeof xyz);
                mesh.positions.emplace_back(xyz[0], xyz[1], xyz[2]);
                finite.push_back(std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2]));
            }

            std::vector<std::uint32_t> order;  // vertex order before assembling triangles
            if (prim.indices >= 0) {
                const View iv = accessor_view(prim.indices, what + " indices");
                const tinygltf::Accessor& ia = model_.accessors[std::size_t(prim.indices)];
                if (ia.type != TINYGLTF_TYPE_SCALAR) fail(what + ": indices must be SCALAR");
                order.resize(iv.count);
                for (std::size_t i = 0; i < iv.count; ++i) {
                    const unsigned char* e = iv.data + i * iv.stride;
                    switch (ia.componentType) {
                        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: order[i] = *e; break;
                        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t v; std::memcpy(&v, e, 2); order[i] = v; break; }
                        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t v; std::memcpy(&v, e, 4); order[i] = v; break; }
                        default: fail(what + ": indices must be unsigned byte, short or int");
                    }
                    if (order[i] >= pv.count)
                        fail(what + ": index " + std::to_string(order[i]) + " out of range (" +
                             std::to_string(pv.count) + " vertices)");
                }
            } else {
                order.resize(pv.count);
                for (std::size_t i = 0; i < pv.count; ++i) order[i] = std::uint32_t(i);
            }

            auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
                if (!finite[base + a] || !finite[base + b] || !finite[base + c]) { ++dropped_triangles_; return; }
                mesh.indices.insert(mesh.indices.end(), {base + a, base + b, base + c});
            };
            if (prim.mode == TINYGLTF_MODE_TRIANGLES || prim.mode < 0) {
                if (order.size() % 3 != 0) fail(what + ": triangle list with " + std::to_string(order.size()) + " indices");
                for (std::size_t i = 0; i + 2 < order.size(); i += 3) emit(order[i], order[i + 1], order[i + 2]);
            } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                for (std::size_t i = 0; i + 2 < order.size(); ++i)  // every other triangle flipped to keep CCW
                    (i % 2 == 0) ? emit(order[i], order[i + 1], order[i + 2]) : emit(order[i + 1], order[i], order[i + 2]);
            } else {  // TINYGLTF_MODE_TRIANGLE_FAN
                for (std::size_t i = 1; i + 1 < order.size(); ++i) emit(order[0], order[i], order[i + 1]);
            }
        }
        return mesh;
    }

    std::vector<std::pair<std::string, std::string>> read_extras(const std::string& json_text, std::size_t n) const {
        std::vector<std::pair<std::string, std::string>> extras;
        if (json_text.empty()) return extras;
        nlohmann::ordered_json j = nlohmann::ordered_json::parse(json_text, nullptr, false);
        if (j.is_discarded()) fail("node " + std::to_string(n) + " has unreadable extras");
        if (!j.is_object()) return extras;
        for (auto it = j.begin(); it != j.end(); ++it)
            extras.emplace_back(it.key(), it->is_string() ? it->get<std::string>() : it->dump());
        return extras;
    }

    const tinygltf::Model& model_;
    std::string path_;
    std::vector<int> mesh_index_;
    std::size_t dropped_triangles_ = 0;
    std::size_t skipped_primitives_ = 0;
};

bool starts_with_glb_magic(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    char magic[4] = {};
    const bool glb = std::fread(magic, 1, 4, f) == 4 && std::memcmp(magic, "glTF", 4) == 0;
    std::fclose(f);
    return glb;
}

}  // namespace

Scene load_gltf(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": no such file");
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image, nullptr);
    loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        ok = starts_with_glb_magic(path) ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    } catch (const std::exception& e) {  // tinygltf's JSON parser can throw on some inputs
        throw Error(path + ": not a readable glTF file (" + e.what() + ")");
    }
    if (!ok) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        throw Error(path + ": not a readable glTF file" + (err.empty() ? std::string() : ": " + err));
    }
    return GltfReader(model, path).read();
}

}  // namespace homcull
