// The native JSON scene format (docs/scene-format.md) read into a SceneDesc.
//
// Every value is read through CheckedObject, which checks types and ranges as it reads and, once an
// object is done, rejects any key nobody asked for: a misspelt optional key would otherwise be
// silently ignored. Errors name the value by JSON pointer and, found again in the source text, by line.
//
// The reader is in io/json/: source_position (JSON pointers, their places in the text, the
// ErrorReporter), checked_object (typed reads, CheckedObject) and reader.h's JsonSceneReader, whose
// sections are read in reader.cpp, settings.cpp, textures.cpp, materials.cpp, shapes.cpp and
// lights.cpp.
#include "candela/io/json/reader.h"
#include "candela/io/scene_reader.h"

namespace candela {

SceneDesc read_json_scene(std::string_view text, const std::string& file_name, const std::filesystem::path& base_dir) {
  return json::JsonSceneReader(text, file_name, base_dir).read();
}

}  // namespace candela
