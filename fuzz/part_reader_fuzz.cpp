// libFuzzer target: `candela merge` on one part file (merge_parts, which reads it with read_part),
// the file made from the input as part_input.h says: an EXR as it is, or a part described as text
// and written by candela's own writer. OpenImageIO (Debian's, with OpenEXR, not instrumented) reads
// the image; the target's point is candela's checks around it: the EXR header walk before it, the
// candela:* attributes, the exact channels and their sizes after it. FileContentError naming the
// file is the documented answer to a bad part (render/film_part.h); any other exception is a finding.
#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <string_view>

#include "candela/base/error.h"
#include "candela/render/film_part.h"
#include "fuzz_common.h"
#include "part_input.h"

// OpenEXR's thread pool off: the parts read here are a few pixels, and waiting on the pool's threads
// (futex) took most of each input's time on a busy machine.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  OIIO::attribute("exr_threads", -1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = candela_fuzz::scratch_dir() / "input.exr";
  if (!candela_fuzz::write_part_input(std::string_view(reinterpret_cast<const char*>(data), size), file)) return 0;
  try {
    (void)candela::merge_parts({file});
  } catch (const candela::FileContentError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
