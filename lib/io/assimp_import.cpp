// Every format assimp reads (OBJ, PLY, IFC, FBX, 3DS, ...). glTF goes through load_gltf
// instead (see gltf_import.cpp for why).
#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <vector>

namespace homcull {
namespace {

glm::dmat4 to_glm(const aiMatrix4x4& m) {  // assimp is row-major, glm column-major
    glm::dmat4 g;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) g[c][r] = m[r][c];
    return g;
}

class AssimpReader {
public:
    AssimpReader(const aiScene& ai, std::string path) : ai_(ai), path_(std::move(path)) { scene_.source = path_; }

    Scene read() {
        visit(*ai_.mRootNode, glm::dmat4(1.0));
        if (dropped_triangles_ > 0)
            std::fprintf(stderr, "homcull: warning: %s: dropped %zu triangles with non-finite vertices\n",
                         path_.c_str(), dropped_triangles_);
        scene_.finalize();
        return std::move(scene_);
    }

private:
    // Depth-first, parents before children: the order assimp's node tree has the groups in.
    void visit(const aiNode& node, const glm::dmat4& parent) {
        const glm::dmat4 world = parent * to_glm(node.mTransformation);
        if (node.mNumMeshes > 0) {
            Object object;
            object.name = node.mName.length > 0 ? node.mName.C_Str() : "object" + std::to_string(scene_.objects.size());
            object.mesh = shared_mesh(std::vector<unsigned>(node.mMeshes, node.mMeshes + node.mNumMeshes), object.name);
            object.world = world;
            scene_.objects.push_back(std::move(object));
        }
        for (unsigned c = 0; c < node.mNumChildren; ++c) visit(*node.mChildren[c], world);
    }

    // A node's meshes merged into one Mesh, stored once for every node with the same list.
    std::uint32_t shared_mesh(const std::vector<unsigned>& ai_meshes, const std::string& name) {
        auto found = mesh_of_.find(ai_meshes);
        if (found != mesh_of_.end()) return found->second;
        Mesh mesh;
        mesh.name = ai_meshes.size() == 1 && ai_.mMeshes[ai_meshes[0]]->mName.length > 0
                        ? ai_.mMeshes[ai_meshes[0]]->mName.C_Str() : name;
        for (unsigned m : ai_meshes) {
            if (m >= ai_.mNumMeshes) throw Error(path_ + ": a node names mesh " + std::to_string(m) + " out of range");
            const aiMesh& am = *ai_.mMeshes[m];
            const std::uint32_t base = std::uint32_t(mesh.positions.size());
            std::vector<char> finite(am.mNumVertices);
            for (unsigned v = 0; v < am.mNumVertices; ++v) {
                const aiVector3D& p = am.mVertices[v];
                mesh.positions.emplace_back(p.x, p.y, p.z);
                finite[v] = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
            }
            for (unsigned f = 0; f < am.mNumFaces; ++f) {
                const aiFace& face = am.mFaces[f];
                if (face.mNumIndices != 3) continue;  // points and lines (after triangulation)
                bool ok = true;
                for (int k = 0; k < 3; ++k) {
                    if (face.mIndices[k] >= am.mNumVertices)
                        throw Error(path_ + ": mesh '" + mesh.name + "' uses vertex " + std::to_string(face.mIndices[k]) +
                                    " but has " + std::to_string(am.mNumVertices));
                    ok = ok && finite[face.mIndices[k]];
                }
                if (!ok) { ++dropped_triangles_; continue; }
                for (int k = 0; k < 3; ++k) mesh.indices.push_back(base + face.mIndices[k]);
            }
        }
        scene_.meshes.push_back(std::move(mesh));
        const auto index = std::uint32_t(scene_.meshes.size() - 1);
        mesh_of_.emplace(ai_meshes, index);
        return index;
    }

    const aiScene& ai_;
    std::string path_;
    Scene scene_;
    std::map<std::vector<unsigned>, std::uint32_t> mesh_of_;
    std::size_t dropped_triangles_ = 0;
};

}  // namespace

Scene load_with_assimp(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": no such file");
    Assimp::Importer importer;
    const std::string extension = std::filesystem::path(path).extension().string();
    if (!importer.IsExtensionSupported(extension))
        throw Error(path + ": unsupported scene format '" + extension + "' (glTF/GLB, OBJ, PLY, IFC, FBX and the other formats assimp reads)");
    // Triangulate polygons, weld the vertices OBJ stores per corner, and keep the node tree
    // as it is (no aiProcess_PreTransformVertices: that would copy every instanced mesh).
    const aiScene* ai = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                    aiProcess_SortByPType | aiProcess_ValidateDataStructure);
    if (!ai || !ai->mRootNode || (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
        throw Error(path + ": not a readable scene: " + importer.GetErrorString());
    return AssimpReader(*ai, path).read();
}

}  // namespace homcull
