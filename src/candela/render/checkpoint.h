#pragma once
// Render checkpoints: the film's per-pixel sums, weights and sample counts, stored bit for bit, with
// a fingerprint of what made them (a hash of the scene file's bytes and every setting that affects
// the image), so a render can continue later and end bitwise equal to an uninterrupted one.
//
// File layout (little-endian, as the host writes it):
//   8 bytes  magic "CNDLCKPT"
//   u32      format version (3; versions 1, without splats, and 2, without the halves, are still read)
//   u64      payload size in bytes
//   u64      FNV-1a 64 hash of the payload
//   payload: u64 scene hash; u32 n; n x (u32 length, key bytes, u32 length, value bytes) settings;
//            i32 width, i32 height; u64 non-finite samples so far;
//            width x height x (7 doubles: weighted[3], weighted_sq[3], weight; u64 count;
//                              4 doubles: half_weighted[3], half_weight; u64 half_count);
//            u64 m (0 or 3 width height), m x i64 fixed-point splat sums (bidirectional light paths);
//            u64 m, m x i64: the first half's splat sums
// Written atomically: a temporary file beside the target, fsynced, renamed over it, and the
// directory fsynced, so a crash at any moment leaves the previous checkpoint intact.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/film/film.h"

namespace candela {

// FNV-1a, 64 bit.
uint64_t fnv1a64(const void* data, size_t size, uint64_t hash = 0xcbf29ce484222325ULL);

struct RenderFingerprint {
  uint64_t scene_hash = 0;                                    // fnv1a64 of the scene file's bytes
  std::vector<std::pair<std::string, std::string>> settings;  // ordered (name, value)

  // "" when they match; otherwise what differs, e.g. "scene file differs" or
  // "settings differ: spp 64 vs 128" (this fingerprint's value first).
  std::string difference(const RenderFingerprint& now) const;
};

struct Checkpoint {
  RenderFingerprint fingerprint;
  int width = 0, height = 0;
  uint64_t non_finite_samples = 0;
  std::vector<PixelSums> pixels;  // row-major, width x height
  std::vector<int64_t> splats;    // SplatImage::sums(), or empty
  std::vector<int64_t> half_splats;  // Film::half_splats()'s sums, or empty
};

// Throws OutputError naming the file when it cannot be written.
void write_checkpoint(const std::filesystem::path& file, const Checkpoint& checkpoint);
// Throws FileContentError naming the file and the problem: missing, not a checkpoint, another
// version, truncated, or corrupt (checksum mismatch).
Checkpoint read_checkpoint(const std::filesystem::path& file);
// The two steps of read_checkpoint, for a checkpoint read by one rank and sent to the others: the
// file's bytes, and the checkpoint they hold (`file` names it in errors).
std::string read_checkpoint_bytes(const std::filesystem::path& file);
Checkpoint parse_checkpoint(std::string_view bytes, const std::filesystem::path& file);

}  // namespace candela
