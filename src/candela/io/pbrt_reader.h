#pragma once
// The pbrt-v4 reader's entry points (docs/pbrt-format.md). The reader itself is in io/pbrt/: the
// tokenizer, the parameter lists and the directive parser that builds the SceneDesc.
#include <filesystem>
#include <string>
#include <string_view>

#include "candela/description/scene_desc.h"
#include "candela/io/warnings.h"

namespace candela {

// Reads a pbrt-v4 scene. Each warning is appended to `warnings` as one line,
// "file:line:column: warning: what was replaced or ignored". Throws SceneError for the first error.
SceneDesc read_pbrt_scene(const std::filesystem::path& file, Warnings& warnings);

// The same, printing the warnings to stderr (Warnings::print).
SceneDesc read_pbrt_scene(const std::filesystem::path& file);

// Reads pbrt-v4 text that is not in a file (pbrt-v4's ParseString): `name_for_messages` stands for
// the file name in messages and warnings, and relative file names (Include, Import, meshes, images)
// are looked up in `base_dir`.
SceneDesc read_pbrt_string(std::string_view text, const std::string& name_for_messages,
                           const std::filesystem::path& base_dir, Warnings& warnings);
SceneDesc read_pbrt_string(std::string_view text, const std::string& name_for_messages,
                           const std::filesystem::path& base_dir);

}  // namespace candela
