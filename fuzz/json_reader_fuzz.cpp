// libFuzzer target: the JSON scene reader (read_json_scene). A SceneError is the documented answer
// to bad input; anything else (another exception, a crash, a sanitizer report, a hang) is a bug.
#include <cstdint>
#include <string_view>

#include "candela/animation/pose.h"
#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    // Read, then posed as a frame would be (keyframes, skins and morph targets evaluated).
    const candela::SceneDesc desc = candela::read_json_scene(text, "fuzz.json", candela_fuzz::scratch_dir());
    if (candela::is_animated(desc)) (void)candela::pose_scene(desc, {0.25f, 0.75f});
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
