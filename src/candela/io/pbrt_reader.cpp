// The pbrt-v4 reader's entry points; the reader is in io/pbrt/ (scene_parser.h describes its parts).
#include "candela/io/pbrt_reader.h"

#include <cstdio>
#include <map>
#include <utility>

#include "candela/base/error.h"
#include "candela/io/pbrt/scene_parser.h"

namespace candela {

namespace {

// Reads with `read`, printing the warnings whether it succeeds or throws.
template <typename Read>
SceneDesc read_printing_warnings(Read read) {
  std::vector<std::string> warnings;
  try {
    SceneDesc scene = read(warnings);
    print_pbrt_warnings(warnings);
    return scene;
  } catch (const SceneError&) {
    print_pbrt_warnings(warnings);
    throw;
  }
}

}  // namespace

SceneDesc read_pbrt_scene(const std::filesystem::path& file, std::vector<std::string>& warnings) {
  return pbrt::SceneParser(warnings).parse(file);
}

SceneDesc read_pbrt_scene(const std::filesystem::path& file) {
  return read_printing_warnings([&](std::vector<std::string>& warnings) { return read_pbrt_scene(file, warnings); });
}

SceneDesc read_pbrt_string(std::string_view text, const std::string& name_for_messages,
                           const std::filesystem::path& base_dir, std::vector<std::string>& warnings) {
  return pbrt::SceneParser(warnings).parse(std::string(text), name_for_messages, base_dir);
}

SceneDesc read_pbrt_string(std::string_view text, const std::string& name_for_messages,
                           const std::filesystem::path& base_dir) {
  return read_printing_warnings([&](std::vector<std::string>& warnings) {
    return read_pbrt_string(text, name_for_messages, base_dir, warnings);
  });
}

void print_pbrt_warnings(const std::vector<std::string>& warnings, int per_kind) {
  std::map<std::string, int> seen;
  for (const std::string& warning : warnings) {
    size_t text = warning.find(": warning: ");
    std::string kind = text == std::string::npos ? warning : warning.substr(text);
    if (++seen[kind] <= per_kind) std::fprintf(stderr, "%s\n", warning.c_str());
  }
  for (const auto& [kind, count] : seen)
    if (count > per_kind)
      std::fprintf(stderr, "(%d more warnings like \"%s\")\n", count - per_kind, kind.substr(11).c_str());
}

}  // namespace candela
