#pragma once
// Triangle meshes from files: .obj through tinyobjloader, .ply through Assimp, Mitsuba's .serialized
// through zlib; any of them gzipped ("mesh.ply.gz", as pbrt-v4 reads) is decompressed first (io/gzip.h).
#include <filesystem>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/description/scene_desc.h"

namespace candela {

// Loads every triangle of the file into one mesh (polygons are triangulated; per-vertex normals and
// uvs kept when present). `referenced_from` is where the scene named the file, for messages.
// A .serialized file holds several meshes: `shape_index` picks one (Mitsuba's parameter; 0 for
// other formats). Throws SceneError naming both places for a missing, unreadable, malformed or
// empty file.
TriangleMesh load_mesh_file(const std::filesystem::path& file, const SourceLocation& referenced_from,
                            int shape_index = 0);

// A material of an OBJ file's MTL library, as written there (the meaning of each is in
// io/obj_scene_reader.cpp, which turns them into candela materials).
struct ObjMaterial {
  std::string name;
  RGB diffuse{0.0f}, specular{0.0f}, emission{0.0f}, transmission_filter{1.0f};  // Kd, Ks, Ke, Tf
  float shininess = 1, ior = 1, dissolve = 1;                                  // Ns, Ni, d (1 - Tr)
  int illum = 0;
  std::string diffuse_map;  // map_Kd, relative to the working directory; empty = none
};

class Warnings;  // io/warnings.h

// An OBJ file with the materials of its `mtllib` libraries (looked up beside the OBJ file): one mesh
// per material that faces use; `material` indexes `materials`, -1 for faces without one. A missing
// or unreadable library is a warning appended to `warnings` (its materials become the default), a
// malformed OBJ an error.
struct ObjModel {
  struct Part {
    int material = -1;
    TriangleMesh mesh;
  };
  std::vector<Part> parts;
  std::vector<ObjMaterial> materials;
};
ObjModel load_obj_model(const std::filesystem::path& file, const SourceLocation& referenced_from, Warnings& warnings);

}  // namespace candela
