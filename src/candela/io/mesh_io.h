#pragma once
// Triangle meshes from files: .obj through tinyobjloader, .ply through Assimp.
#include <filesystem>

#include "candela/io/error.h"
#include "candela/scene/description.h"

namespace candela {

// Loads every triangle of the file into one mesh (polygons are triangulated; per-vertex normals and
// uvs kept when present). `referenced_from` is where the scene named the file, for messages.
// Throws SceneError naming both places for a missing, unreadable, malformed or empty file.
TriangleMesh load_mesh_file(const std::filesystem::path& file, const SourceLocation& referenced_from);

}  // namespace candela
