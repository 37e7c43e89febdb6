#pragma once
// Entry points of the scene readers. Each returns a complete SceneDesc (meshes loaded, includes
// resolved) or throws SceneError naming the file and place of the first problem.
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "candela/description/scene_desc.h"
#include "candela/io/warnings.h"

namespace candela {

// Chooses the reader by extension: .json (candela's format), .pbrt (pbrt-v4), .xml (Mitsuba 3),
// .gltf / .glb (glTF 2.0), .obj (with its MTL), .ply (a mesh). Throws SceneError for a missing file or an unknown
// extension.
struct SceneReadOptions {
  // A Mitsuba scene's $parameters, over its <default> tags (Mitsuba's -D name=value); the other
  // formats have none, and giving one for them is a SceneError.
  std::map<std::string, std::string> parameters;
  // Where the readers' warnings go (pbrt, Mitsuba, glTF, OBJ); null: printed to stderr (Warnings::print).
  Warnings* warnings = nullptr;
};
SceneDesc read_scene_file(const std::filesystem::path& file, const SceneReadOptions& options = {});

// The native JSON format (docs/scene-format.md). `file_name` is used in messages; relative mesh
// paths are resolved against `base_dir`.
SceneDesc read_json_scene(std::string_view text, const std::string& file_name,
                          const std::filesystem::path& base_dir);

// scenes/cornell-box.json, compiled into the program.
std::string_view builtin_scene_json();

}  // namespace candela
