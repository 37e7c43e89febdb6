#pragma once
// How fuzz/gzip_fuzz.cpp turns an input into gzip data. Bit 0 of the first byte set: the rest is the
// data as it is. Clear: the rest is text, which the target compresses itself, so that mutations reach
// the inflating behind the header and the CRC-32 (few mutated bytes are a valid deflate stream):
//   bits 1-2 of the first byte + 1: how many gzip members the text is split into (concatenated, as
//   `cat a.gz b.gz` or `gzip a b` make them);
//   bits 3-7: how the result is damaged: 0 not at all, 1-15 that many bytes cut off its end, 16-31 one
//   byte flipped, at a place chosen from the code.
// `expected` is the text when the data is undamaged, which gunzip must then return exactly.
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

namespace candela_fuzz {

struct GzipInput {
  std::string bytes;
  std::optional<std::string> expected;  // the decompressed text, when the data is undamaged
};

// One gzip member holding `text` (zlib's deflate with a gzip wrapper: windowBits 16 + 15).
inline std::string gzip_member(std::string_view text) {
  z_stream stream{};
  if (deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    std::abort();
  std::string out(deflateBound(&stream, uLong(text.size())) + 32, '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  stream.avail_in = uInt(text.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = uInt(out.size());
  if (deflate(&stream, Z_FINISH) != Z_STREAM_END) std::abort();
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

inline GzipInput gzip_input_of(std::string_view input) {
  if (input.empty()) return {};
  const uint8_t code = uint8_t(input[0]);
  std::string_view text = input.substr(1);
  if (code & 1) return {std::string(text), std::nullopt};
  const size_t members = ((code >> 1) & 3) + 1;
  GzipInput result{"", std::string(text)};
  for (size_t i = 0; i < members; ++i) {
    const size_t begin = text.size() * i / members, end = text.size() * (i + 1) / members;
    result.bytes += gzip_member(text.substr(begin, end - begin));
  }
  const unsigned damage = code >> 3;
  if (damage > 0 && damage < 16) {
    result.bytes.resize(result.bytes.size() - std::min<size_t>(damage, result.bytes.size()));
    result.expected.reset();
  } else if (damage >= 16) {
    result.bytes[(damage * 7919u) % result.bytes.size()] ^= char(1 + (damage & 7));
    result.expected.reset();
  }
  return result;
}

}  // namespace candela_fuzz
