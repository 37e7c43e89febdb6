// libFuzzer target: the glTF 2.0 reader (read_gltf_scene, tinygltf behind it). An input that starts
// with the binary container's magic "glTF" is written to input.glb, any other to input.gltf (JSON),
// since the reader picks the parser by the extension. Images the reader writes (embedded or derived
// ones) go to a cache directory in the scratch directory, emptied after each input so that it does
// not grow over a long run.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "candela/animation/pose.h"
#include "candela/base/error.h"
#include "candela/io/gltf_reader.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool binary = std::string_view(reinterpret_cast<const char*>(data), size).starts_with("glTF");
  const auto file = candela_fuzz::write_input(data, size, binary ? "input.glb" : "input.gltf");
  candela::GltfOptions options;
  options.cache_dir = candela_fuzz::scratch_dir() / "gltf-cache";
  options.film_width = 64;
  candela::Warnings warnings;
  try {
    // Read, then posed as a frame would be (keyframes, skins and morph targets evaluated).
    const candela::SceneDesc desc = candela::read_gltf_scene(file, warnings, options);
    if (candela::is_animated(desc)) (void)candela::pose_scene(desc, {0.25f, 0.75f});
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  std::error_code ec;
  std::filesystem::remove_all(options.cache_dir, ec);
  return 0;
}
