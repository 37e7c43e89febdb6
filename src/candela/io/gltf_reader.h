#pragma once
// The glTF 2.0 reader (.gltf and .glb, through tinygltf; docs/gltf-format.md). read_gltf_scene(file)
// in scene_reader.cpp reads the same way and prints the warnings to stderr.
#include <filesystem>
#include <string>

#include "candela/description/scene_desc.h"
#include "candela/io/warnings.h"

namespace candela {

struct GltfOptions {
  // Where images the reader has to make are written: images embedded in the file (data URIs,
  // .glb buffers) and images derived from the file's ones (a channel picked out, an alpha mask, a
  // base colour times a coloured factor, a scaled normal map). Named by a hash of their source and
  // operation, so a second read reuses them. Empty = <temp directory>/candela-gltf.
  std::filesystem::path cache_dir;
  // Film width when the file's camera has an aspect ratio (height = width / aspect), or with no camera.
  int film_width = 1024;
};

// Reads a glTF 2.0 file. Each warning is appended to `warnings` as one line,
// "file: at /json/pointer: warning: what was approximated or ignored". Throws SceneError for the
// first error (naming the file and, where there is one, the JSON pointer of the element).
SceneDesc read_gltf_scene(const std::filesystem::path& file, Warnings& warnings,
                          const GltfOptions& options = {});

// The same, printing the warnings to stderr (Warnings::print: at most three of each kind).
SceneDesc read_gltf_scene(const std::filesystem::path& file);

}  // namespace candela
