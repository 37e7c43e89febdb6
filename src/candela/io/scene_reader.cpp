// read_scene_file: picks the reader by the file's extension.
#include "candela/io/scene_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include "candela/base/error.h"
#include "candela/io/gltf_reader.h"
#include "candela/io/mitsuba_reader.h"
#include "candela/io/obj_scene_reader.h"
#include "candela/io/pbrt_reader.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

SourceLocation location_of_file(const fs::path& file) { return {file.string(), 0, 0, {}}; }

std::string lowercase_extension(const fs::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return extension;
}

void check_is_readable_file(const fs::path& file) {
  SourceLocation where = location_of_file(file);
  std::error_code error;
  fs::file_status status = fs::status(file, error);
  if (!fs::exists(status)) throw_scene_error(where, "scene file not found");
  if (fs::is_directory(status)) throw_scene_error(where, "is a directory, not a scene file");
}

std::string read_text_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_scene_error(location_of_file(file), "cannot open scene file: {}", std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw_scene_error(location_of_file(file), "cannot read scene file");
  return std::move(text).str();
}

}  // namespace

SceneDesc read_scene_file(const std::filesystem::path& file, const SceneReadOptions& options) {
  if (!options.warnings)  // the readers' warnings printed to stderr, also those before an error
    return read_printing_warnings([&](Warnings& warnings) {
      return read_scene_file(file, SceneReadOptions{options.parameters, &warnings});
    });
  Warnings& warnings = *options.warnings;
  check_is_readable_file(file);
  std::string extension = lowercase_extension(file);
  // As pbrt-v4, a gzipped pbrt scene or PLY mesh ("scene.pbrt.gz"): their readers decompress it (io/gzip.h).
  const std::string inner = lowercase_extension(file.stem());
  if (extension == ".gz" && (inner == ".pbrt" || inner == ".ply")) extension = inner;
  if (!options.parameters.empty() && extension != ".xml")
    throw_scene_error(location_of_file(file), "${} is a Mitsuba scene parameter, and this is not a Mitsuba .xml file",
                      options.parameters.begin()->first);
  SceneDesc scene;
  // A file system error in a reader (a file it looks for in a directory it may not search) names the
  // path; it reaches the user as a SceneError at the scene file, not as a bare library exception.
  try {
    if (extension == ".json")
      scene = read_json_scene(read_text_file(file), file.string(), file.parent_path());
    else if (extension == ".pbrt")
      scene = read_pbrt_scene(file, warnings);
    else if (extension == ".obj")
      scene = read_obj_scene(file, warnings);
    else if (extension == ".ply")
      scene = read_mesh_scene(file);
    else if (extension == ".gltf" || extension == ".glb")
      scene = read_gltf_scene(file, warnings);
    else if (extension == ".xml")
      scene = read_mitsuba_scene(file, warnings, MitsubaReadOptions{options.parameters});
    else
      throw_scene_error(location_of_file(file),
                        "unsupported scene file extension {}; supported: .json, .pbrt, .xml (Mitsuba 3), .gltf, .glb, "
                        ".obj, .ply, and .pbrt.gz and .ply.gz gzipped",
                        extension.empty() ? std::string("(none)") : "\"" + extension + "\"");
  } catch (const std::filesystem::filesystem_error& e) {
    throw_scene_error(location_of_file(file), "{}", e.what());
  }
  scene.source_file = file.string();
  return scene;
}

}  // namespace candela
