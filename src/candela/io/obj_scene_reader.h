#pragma once
// An OBJ or PLY file as a whole scene: its geometry with the materials of its MTL library, emitters from
// Ke, and (OBJ has no cameras) a camera that frames the model. docs/obj-format.md has the mapping.
#include <filesystem>

#include "candela/description/scene_desc.h"
#include "candela/io/warnings.h"

namespace candela {

// Throws SceneError naming the file for a missing or malformed OBJ. Warnings (a missing MTL file,
// material parameters that cannot be represented) are appended to `warnings`, one line each.
SceneDesc read_obj_scene(const std::filesystem::path& file, Warnings& warnings);

// The same, printing the warnings to stderr (Warnings::print), as the other readers do.
SceneDesc read_obj_scene(const std::filesystem::path& file);

// A PLY mesh (or any mesh file load_mesh_file reads) as a whole scene: one grey diffuse shape,
// framed and lit as an OBJ model without emitters is.
SceneDesc read_mesh_scene(const std::filesystem::path& file);

}  // namespace candela
