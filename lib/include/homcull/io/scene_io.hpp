#pragma once
// Reading and writing scenes. Every failure throws homcull::Error with a message that names
// the file and the problem (missing, unreadable, malformed, unsupported).
#include <homcull/scene.hpp>

#include <string>

namespace homcull {

// A file path, or "gen:NAME[:options]" for a generated scene (see generate.hpp).
// .glb and .gltf go through load_gltf; every other extension through assimp.
Scene load_scene(const std::string& path_or_spec);

// glTF 2.0 (binary or JSON). One object per node that has a mesh, in the order of the file's
// `nodes` array (DESIGN.md object ids), placed by the node's world transform; a glTF mesh used
// by several nodes becomes one shared Mesh; node extras become Object::extras. Triangle lists,
// strips and fans are read, points and lines skipped; triangles that use a non-finite vertex
// are dropped with a warning on stderr.
Scene load_gltf(const std::string& path);

// Any format assimp reads (OBJ, PLY, IFC, FBX, ...). One object per node that has meshes,
// depth-first in the node tree: for OBJ that is one object per `o`/`g` group, or the whole
// file when it has none.
Scene load_with_assimp(const std::string& path);

// Writes the scene as a binary glTF that load_gltf reads back to the same scene (meshes
// shared, object order, transforms and extras kept).
void save_glb(const Scene& scene, const std::string& path);

}  // namespace homcull
