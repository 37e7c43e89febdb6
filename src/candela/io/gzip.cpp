#include "candela/io/gzip.h"

#include <zlib.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <utility>

#include "candela/base/error.h"
#include "candela/scene/resource_limits.h"

namespace candela {
namespace {

class GzipInflater {
 public:
  GzipInflater() {
    // 16 + MAX_WBITS: a gzip header and trailer (with its CRC-32 checked) around the deflate data.
    if (inflateInit2(&stream_, 16 + MAX_WBITS) != Z_OK) fail_file_content("gzip: zlib cannot start inflating");
  }
  ~GzipInflater() { inflateEnd(&stream_); }
  GzipInflater(const GzipInflater&) = delete;
  GzipInflater& operator=(const GzipInflater&) = delete;
  z_stream& stream() { return stream_; }

 private:
  z_stream stream_{};
};

// Inflates every member of `bytes`, handing the output to `take` a chunk at a time.
void inflate_gzip(std::string_view bytes, const std::function<void(const char*, size_t)>& take) {
  GzipInflater inflater;
  z_stream& stream = inflater.stream();
  char chunk[1 << 16];
  size_t at = 0;
  while (true) {
    const size_t in_step = std::min<size_t>(bytes.size() - at, std::numeric_limits<uInt>::max());
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + at));
    stream.avail_in = uInt(in_step);
    stream.next_out = reinterpret_cast<Bytef*>(chunk);
    stream.avail_out = sizeof chunk;
    const int status = inflate(&stream, Z_NO_FLUSH);
    at += in_step - stream.avail_in;
    const size_t produced = sizeof chunk - stream.avail_out;
    take(chunk, produced);
    if (status == Z_STREAM_END) {
      // Another member may follow (gzip a b > ab.gz, or cat a.gz b.gz); anything else is not gzip.
      if (at == bytes.size()) return;
      if (!is_gzip(bytes.substr(at)))
        fail_file_content("gzip: {} bytes after the end of the compressed data are not gzip data", bytes.size() - at);
      if (inflateReset(&stream) != Z_OK) fail_file_content("gzip: zlib cannot start inflating");
    } else if (status == Z_BUF_ERROR && produced == 0) {  // no progress: the input ran out
      fail_file_content("gzip: the compressed data is cut short");
    } else if (status != Z_OK && status != Z_BUF_ERROR) {
      fail_file_content("gzip: corrupt compressed data ({})", stream.msg ? stream.msg : "inflate failed");
    }
  }
}

}  // namespace

bool is_gzip(std::string_view bytes) {
  return bytes.size() >= 2 && uint8_t(bytes[0]) == 0x1f && uint8_t(bytes[1]) == 0x8b;
}

// Twice through the data: first only counting the output, so that a bomb costs the time to inflate
// max_bytes but no memory; then into a string of exactly the right size.
std::string gunzip(std::string_view bytes, uint64_t max_bytes) {
  uint64_t size = 0;
  inflate_gzip(bytes, [&](const char*, size_t produced) {
    size += produced;
    if (size > max_bytes)
      fail_file_content("gzip: it decompresses to more than {}, the limit for a gzipped file (a gzip bomb?); gunzip "
                        "it to read it without this limit",
                        format_bytes(max_bytes));
  });
  std::string out;
  out.reserve(size_t(size));
  inflate_gzip(bytes, [&](const char* data, size_t produced) { out.append(data, produced); });
  return out;
}

std::string gunzip_if_gzip(std::string bytes) { return is_gzip(bytes) ? gunzip(bytes) : std::move(bytes); }

}  // namespace candela
