#pragma once
// Mitsuba 3 XML scenes (the subset in docs/mitsuba-format.md) read into a SceneDesc.
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "candela/description/scene_desc.h"
#include "candela/io/warnings.h"

namespace candela {

struct MitsubaReadOptions {
  // Values for the scene's $parameters; they take precedence over the scene's <default> tags (as
  // Mitsuba's "-D name=value"), e.g. {"spp", "64"}.
  std::map<std::string, std::string> parameters;
};

// Reads a Mitsuba 3 scene file. Each warning is appended to `warnings` as one line,
// "file:line: warning: ...". Throws SceneError ("file:line: what is wrong") for the first error.
SceneDesc read_mitsuba_scene(const std::filesystem::path& file, Warnings& warnings,
                             const MitsubaReadOptions& options = {});

// The same for XML text; `file_name` is used in messages and relative paths are resolved against
// `base_dir` (as if the text were a file there).
SceneDesc read_mitsuba_scene_text(std::string_view xml, const std::string& file_name,
                                  const std::filesystem::path& base_dir, Warnings& warnings,
                                  const MitsubaReadOptions& options = {});

// read_mitsuba_scene printing its warnings to stderr (Warnings::print; also those before an error).
SceneDesc read_mitsuba_scene(const std::filesystem::path& file, const MitsubaReadOptions& options = {});

}  // namespace candela
