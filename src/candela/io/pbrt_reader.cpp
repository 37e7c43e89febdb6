// The pbrt-v4 reader's entry points; the reader is in io/pbrt/ (scene_parser.h describes its parts).
#include "candela/io/pbrt_reader.h"

#include "candela/io/pbrt/scene_parser.h"

namespace candela {

SceneDesc read_pbrt_scene(const std::filesystem::path& file, Warnings& warnings) {
  return pbrt::SceneParser(warnings).parse(file);
}

SceneDesc read_pbrt_scene(const std::filesystem::path& file) {
  return read_printing_warnings([&](Warnings& warnings) { return read_pbrt_scene(file, warnings); });
}

SceneDesc read_pbrt_string(std::string_view text, const std::string& name_for_messages,
                           const std::filesystem::path& base_dir, Warnings& warnings) {
  return pbrt::SceneParser(warnings).parse(std::string(text), name_for_messages, base_dir);
}

SceneDesc read_pbrt_string(std::string_view text, const std::string& name_for_messages,
                           const std::filesystem::path& base_dir) {
  return read_printing_warnings([&](Warnings& warnings) {
    return read_pbrt_string(text, name_for_messages, base_dir, warnings);
  });
}

}  // namespace candela
