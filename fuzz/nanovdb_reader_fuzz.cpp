// libFuzzer target: the VDB grid files of io/grid_files.cpp, NanoVDB's .nvdb (the header-only NanoVDB
// reader, instrumented with candela's code) and OpenVDB's .vdb (Debian's libopenvdb, not
// instrumented), as grid_input.h makes them from the input. The target lists the grids
// (grid_names_in_file) and reads the first one, or "density" when none is listed, into at most
// kMaxFuzzedDenseSamples samples.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/grid_files.h"
#include "fuzz_common.h"
#include "grid_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const candela_fuzz::GridInput input = candela_fuzz::grid_input_of(
      std::string_view(reinterpret_cast<const char*>(data), size), candela_fuzz::scratch_dir());
  const auto file = candela_fuzz::write_input(reinterpret_cast<const uint8_t*>(input.bytes.data()), input.bytes.size(),
                                              input.file_name);
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
