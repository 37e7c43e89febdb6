// libFuzzer target: the pbrt-v4 scene reader. The input becomes a .pbrt file in an otherwise empty
// directory (so an Include of a relative name finds nothing, or the input itself).
#include <cstdint>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/pbrt_reader.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = candela_fuzz::write_input(data, size, "input.pbrt");
  candela::Warnings warnings;
  try {
    (void)candela::read_pbrt_scene(file, warnings);
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
