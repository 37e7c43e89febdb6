#pragma once
// The pbrt-v4 reader's entry point with its warnings (docs/pbrt-format.md). read_pbrt_scene(file)
// in scene_reader.h reads the same way and prints the warnings to stderr.
#include <filesystem>
#include <string>
#include <vector>

#include "candela/scene/description.h"

namespace candela {

// Reads a pbrt-v4 scene. Each warning is appended to `warnings` as one line,
// "file:line:column: warning: what was replaced or ignored". Throws SceneError for the first error.
SceneDesc read_pbrt_scene(const std::filesystem::path& file, std::vector<std::string>& warnings);

// Prints warnings to stderr, at most `per_kind` of each kind (the same text at different places),
// followed by a count of the ones left out.
void print_pbrt_warnings(const std::vector<std::string>& warnings, int per_kind = 3);

}  // namespace candela
