// libFuzzer target: gzipped input (io/gzip.h: pbrt includes and imports, .pbrt.gz scenes, .ply.gz
// meshes), as gzip_input.h makes it from the input: the data as it is, or text the target compresses
// into one to four members and then cuts short or damages. gunzip must either return the text (exactly,
// when the data is undamaged) or throw FileContentError, the documented answer to damaged data; the
// limit is 4 KiB here (the production limit is 1 GiB), so that the bomb check is reached by inputs of a
// few KB.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "candela/base/error.h"
#include "candela/io/gzip.h"
#include "fuzz_common.h"
#include "gzip_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const candela_fuzz::GzipInput input =
      candela_fuzz::gzip_input_of(std::string_view(reinterpret_cast<const char*>(data), size));
  constexpr uint64_t kLimit = 4096;
  try {
    const std::string text = candela::gunzip(input.bytes, kLimit);
    if (text.size() > kLimit) std::abort();  // past the limit it was given
    if (input.expected && text != *input.expected) std::abort();  // undamaged data read back wrong
  } catch (const candela::FileContentError& e) {
    if (input.expected && input.expected->size() <= kLimit) std::abort();  // undamaged data refused
    candela_fuzz::rejected(e);
  }
  // gunzip_if_gzip: the data as it is unless it starts with gzip's magic bytes.
  try {
    (void)candela::gunzip_if_gzip(input.bytes);
  } catch (const candela::FileContentError& e) {
    candela_fuzz::rejected(e);
  }
  return 0;
}
