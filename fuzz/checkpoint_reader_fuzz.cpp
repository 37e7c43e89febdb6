// libFuzzer target: render checkpoints (parse_checkpoint, in memory), as checkpoint_input.h makes
// them from the input. std::runtime_error naming the file is the documented answer to a bad
// checkpoint (render/checkpoint.h).
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "candela/render/checkpoint.h"
#include "checkpoint_input.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = candela_fuzz::checkpoint_bytes_of(std::string_view(reinterpret_cast<const char*>(data), size));
  try {
    (void)candela::parse_checkpoint(bytes, "fuzz.ckpt");
  } catch (const std::runtime_error& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
