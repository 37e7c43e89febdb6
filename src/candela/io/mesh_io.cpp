#include "candela/io/mesh_io.h"

// The readers of each format are in io/mesh/: obj.cpp (tinyobjloader), ply.cpp (Assimp, after its
// own checks), serialized.cpp (Mitsuba's format, through zlib); mesh_common.cpp holds what they share.
// A gzipped file of any of them (pbrt-v4's "mesh.ply.gz") is decompressed first (io/gzip.h).
#include <algorithm>
#include <cctype>
#include <new>
#include <string>

#include "candela/io/gzip.h"
#include "candela/io/mesh/mesh_common.h"

namespace candela {
namespace {

enum class MeshFormat { Obj, Ply, MitsubaSerialized };

std::string lowercase_extension(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// The format of "mesh.ply.gz" is that of "mesh.ply" (load_mesh_file decompresses it).
MeshFormat mesh_format_of(std::filesystem::path file) {
  if (lowercase_extension(file) == ".gz") file = file.stem();
  const std::string extension = lowercase_extension(file);
  if (extension == ".obj") return MeshFormat::Obj;
  if (extension == ".ply") return MeshFormat::Ply;
  if (extension == ".serialized") return MeshFormat::MitsubaSerialized;
  if (extension.empty()) fail_file_content("the file name has no extension; supported mesh formats are .obj, .ply and .serialized");
  fail_file_content("unsupported mesh format '{}'; supported mesh formats are .obj, .ply and .serialized", file.extension().string());
}

}  // namespace

TriangleMesh load_mesh_file(const std::filesystem::path& file, const SourceLocation& referenced_from,
                            int shape_index) {
  return mesh::with_mesh_file_errors(file, referenced_from, [&] {
    const MeshFormat format = mesh_format_of(file);
    if (shape_index != 0 && format != MeshFormat::MitsubaSerialized)
      fail_file_content("a shape index ({}) is only meaningful for a .serialized file", shape_index);
    const std::string bytes = gunzip_if_gzip(mesh::read_whole_file(file));
    TriangleMesh loaded = format == MeshFormat::Obj   ? mesh::load_obj(bytes)
                          : format == MeshFormat::Ply ? mesh::load_ply(bytes)
                                                      : mesh::load_serialized(bytes, shape_index);
    mesh::validate_mesh(loaded);
    return loaded;
  });
}

}  // namespace candela
