// libFuzzer target: Mitsuba's .vol grids, read as a medium's grid (read_grid_file) and as an SDF grid
// shape (read_sdf_grid_file, which also checks the values: finite, a surface somewhere).
#include <cstdint>

#include "candela/base/error.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/io/grid_files.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = candela_fuzz::write_input(data, size, "input.vol");
  const candela::SourceLocation where{"fuzz", 1, 1, {}};
  try {
    (void)candela::read_grid_file(file, "density", where);
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  try {
    (void)candela::read_sdf_grid_file(file, where, candela::SdfNormals::Smooth);
  } catch (const candela::SceneError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
