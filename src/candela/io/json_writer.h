#pragma once
// Writes a SceneDesc in candela's JSON format (docs/scene-format.md), so that any scene candela reads
// (pbrt-v4, Mitsuba 3, glTF, OBJ) can be converted to it: `candela convert IN OUT.json`. Reading the
// written file back gives the same description, and so the same image bit for bit: every number is
// written with enough digits to round-trip, meshes are written inline, and the order of textures,
// materials, shapes and lights is kept.
#include <filesystem>
#include <string>

#include "candela/description/scene_desc.h"

namespace candela {

// The JSON text of `scene`. File names (images, environment maps) are written as absolute paths, so
// the file can be moved. Every SceneDesc can be expressed.
std::string scene_to_json(const SceneDesc& scene);

// scene_to_json written to `file` atomically (a temporary file renamed over it): an existing file is
// never left half-written. Throws OutputError naming the file when it cannot be written.
void write_json_scene(const SceneDesc& scene, const std::filesystem::path& file);

}  // namespace candela
