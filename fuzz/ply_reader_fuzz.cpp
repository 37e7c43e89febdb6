// libFuzzer target: load_mesh_file on a .ply file.
#include <cstdint>

#include "candela/base/error.h"
#include "candela/io/mesh_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = candela_fuzz::write_input(data, size, "input.ply");
  try {
    (void)candela::load_mesh_file(file, candela::SourceLocation{"fuzz", 1, 1, {}});
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
