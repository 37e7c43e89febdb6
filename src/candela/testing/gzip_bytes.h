#pragma once
// Gzipped data for the tests of the readers that take gzipped files (io/gzip.h).
#include <zlib.h>

#include <stdexcept>
#include <string>
#include <string_view>

#include "candela/base/error.h"

namespace candela::testing {

// `data` as one gzip member, as `gzip` writes it.
inline std::string gzip_bytes(std::string_view data) {
  z_stream stream{};
  if (deflateInit2(&stream, Z_BEST_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw InternalError("deflateInit2 failed");
  std::string out(deflateBound(&stream, uLong(data.size())), '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  stream.avail_in = uInt(data.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = uInt(out.size());
  const int status = deflate(&stream, Z_FINISH);
  out.resize(out.size() - stream.avail_out);
  deflateEnd(&stream);
  if (status != Z_STREAM_END) throw InternalError("deflate failed");
  return out;
}

// A gzip bomb: about 1 MB that inflates to `mebibytes` MiB of zeros, one 1 MiB member repeated (gzip
// reads concatenated members one after another).
inline std::string gzip_bomb(int mebibytes) {
  const std::string member = gzip_bytes(std::string(size_t(1) << 20, '\0'));
  std::string bomb;
  for (int k = 0; k < mebibytes; ++k) bomb += member;
  return bomb;
}

}  // namespace candela::testing
