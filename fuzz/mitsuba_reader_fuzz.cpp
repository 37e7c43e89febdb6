// libFuzzer target: the Mitsuba 3 XML scene reader (read_mitsuba_scene_text). The text is read in
// memory as if it were a file in the scratch directory (fuzz_common.h), so relative file names in it
// (meshes, <include>, <path>) resolve there.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mitsuba_reader.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  candela::Warnings warnings;
  try {
    (void)candela::read_mitsuba_scene_text(text, "fuzz.xml", candela_fuzz::scratch_dir(), warnings);
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
