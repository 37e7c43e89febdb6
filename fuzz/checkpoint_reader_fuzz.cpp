// libFuzzer target: render checkpoints (parse_checkpoint, in memory), as checkpoint_input.h makes
// them from the input. FileContentError naming the file is the documented answer to a bad
// checkpoint (render/checkpoint.h); any other exception is a finding.
#include <cstdint>
#include <string>
#include <string_view>

#include "candela/base/error.h"
#include "candela/render/checkpoint.h"
#include "checkpoint_input.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = candela_fuzz::checkpoint_bytes_of(std::string_view(reinterpret_cast<const char*>(data), size));
  try {
    (void)candela::parse_checkpoint(bytes, "fuzz.ckpt");
  } catch (const candela::FileContentError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
