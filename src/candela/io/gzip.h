#pragma once
// Gzipped input files (pbrt-v4 reads "x.pbrt.gz" includes and "x.ply.gz" meshes): recognised by
// gzip's magic bytes, not by the name, and decompressed whole with a bound on the result, so that a
// small file that inflates to terabytes (a "gzip bomb") is refused instead of filling the memory.
#include <cstdint>
#include <string>
#include <string_view>

namespace candela {

// The most bytes a gzipped file may decompress to. A plain file's size is known before it is read
// (and checked against the memory, scene/resource_limits.h); a gzipped one's only while inflating.
// Text scenes and meshes this large are rare; gunzipping the file lifts the limit.
inline constexpr uint64_t kMaxGunzippedBytes = uint64_t(1) << 30;

// True when `bytes` start with gzip's magic bytes 1f 8b.
bool is_gzip(std::string_view bytes);

// The decompressed contents of a gzip file, its members one after another (as `gzip` writes a
// concatenation). Throws FileContentError (base/error.h) when the data is damaged or cut short, or
// when it inflates to more than `max_bytes`, which is never allocated:
//   "gzip: it decompresses to more than 1.0 GiB, the limit for a gzipped file (a gzip bomb?); gunzip it
//    to read it without this limit"
std::string gunzip(std::string_view bytes, uint64_t max_bytes = kMaxGunzippedBytes);

// `bytes` decompressed if they are gzip, else as they are.
std::string gunzip_if_gzip(std::string bytes);

}  // namespace candela
