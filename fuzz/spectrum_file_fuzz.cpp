// libFuzzer target: spectrum files (io/spectrum_file.h: pbrt-v4's "spectrum" parameters that name a
// file, Mitsuba's <spectrum filename>). parse_spectrum_file must return increasing, finite pairs or
// throw SceneError, the documented answer to a malformed file.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "candela/base/error.h"
#include "candela/io/spectrum_file.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const std::vector<double> pairs =
        candela::parse_spectrum_file(std::string_view(reinterpret_cast<const char*>(data), size), "input.spd");
    if (pairs.empty() || pairs.size() % 2 != 0) std::abort();
    for (size_t i = 0; i < pairs.size(); ++i)
      if (!std::isfinite(pairs[i]) || (i % 2 == 0 && i >= 2 && !(pairs[i] > pairs[i - 2]))) std::abort();
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
