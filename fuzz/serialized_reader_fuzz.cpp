// libFuzzer target: load_mesh_file on Mitsuba .serialized files (their first and second mesh).
// The first input byte picks what the rest is: bit 0 set, a whole file (container, offset table
// and zlib streams fuzzed as they are); clear, one mesh's decompressed stream, which the harness
// compresses and wraps in a file of version 3 or 4 (bit 1), so that the fuzzer reaches the mesh
// parsing behind zlib.
#include <zlib.h>

#include <cstdint>
#include <string>

#include "candela/base/error.h"
#include "candela/io/mesh_io.h"
#include "fuzz_common.h"

namespace {

std::string wrapped(const uint8_t* raw, size_t size, uint16_t version) {
  uLongf packed_size = compressBound(uLong(size));
  std::string packed(packed_size, '\0');
  if (compress(reinterpret_cast<Bytef*>(packed.data()), &packed_size, raw, uLong(size)) != Z_OK) return {};
  std::string file = {'\x1c', '\x04', char(version), '\0'};
  file.append(packed.data(), packed_size);
  file.append(version == 3 ? 4 : 8, '\0');  // the one mesh starts at offset 0
  file.append({'\x01', '\0', '\0', '\0'});  // one mesh
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const bool whole_file = data[0] & 1;
  const std::string bytes = whole_file ? std::string(reinterpret_cast<const char*>(data + 1), size - 1)
                                       : wrapped(data + 1, size - 1, data[0] & 2 ? 4 : 3);
  const auto file =
      candela_fuzz::write_input(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "input.serialized");
  for (int shape_index : {0, 1}) {
    try {
      (void)candela::load_mesh_file(file, candela::SourceLocation{"fuzz", 1, 1, {}}, shape_index);
    } catch (const candela::SceneError& e) {
      candela_fuzz::rejected(e);
    }
  }
  return 0;
}
