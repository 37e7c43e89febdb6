// Reader for glTF 2.0 files (.gltf with its buffers and images, or one .glb), through Debian's shared
// tinygltf library (docs/gltf-format.md has what is supported and how it maps).
//
// tinygltf parses the JSON and loads the buffers; this file walks the default scene's node tree and
// turns meshes, materials, cameras and KHR_lights_punctual lights into a SceneDesc. Images are not
// decoded by tinygltf (a loader callback keeps the encoded bytes): candela's TextureSet reads them
// with OpenImageIO from files, so images embedded in the file, and images derived from the file's
// ones where candela has no texture operation for what glTF asks (one channel of a texture, an
// alpha mask, a colour factor times a texture, a scaled normal map), are written once to a cache
// directory. Errors name the file and the element by JSON pointer (file: at /meshes/2/primitives/0:
// ...); what candela approximates or ignores is a warning in the same form.
//
// The reader's parts are in io/gltf/ (reader.h names them).
#include "candela/io/gltf_reader.h"

#include "candela/io/gltf/reader.h"

namespace candela {

SceneDesc read_gltf_scene(const std::filesystem::path& file, Warnings& warnings,
                          const GltfOptions& options) {
  SceneDesc scene = gltf::GltfReader(file, warnings, options).read();
  scene.source_file = file.string();
  return scene;
}

SceneDesc read_gltf_scene(const std::filesystem::path& file) {
  return read_printing_warnings([&](Warnings& warnings) { return read_gltf_scene(file, warnings); });
}

}  // namespace candela

