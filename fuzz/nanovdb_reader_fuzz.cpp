// libFuzzer target: NanoVDB's .nvdb grid files (io/grid_files.cpp, which reads them itself and uses
// the header-only NanoVDB library, instrumented with it, for the grids' layout and lookups), as
// grid_input.h makes them from the input. The target lists the grids (grid_names_in_file) and reads
// the first one, or "density" when none is listed, into at most kMaxFuzzedDenseSamples samples.
// OpenVDB's .vdb files are not fuzzed (docs/reliability.md says why).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/grid_files.h"
#include "fuzz_common.h"
#include "grid_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = candela_fuzz::nanovdb_file_of(std::string_view(reinterpret_cast<const char*>(data), size),
                                                          candela_fuzz::scratch_dir());
  const auto file =
      candela_fuzz::write_input(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "input.nvdb");
  const candela::SourceLocation where{"fuzz", 1, 1, {}};
  std::vector<std::string> names;
  try {
    names = candela::grid_names_in_file(file, where);
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  try {
    (void)candela::read_grid_file(file, names.empty() ? "density" : names.front(), where,
                                  candela_fuzz::kMaxFuzzedDenseSamples);
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
