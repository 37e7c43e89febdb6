#pragma once
// Job-array parts and their merge. `candela render SCENE --part K/N -o part-K.exr` renders every N-th
// tile from the (K-1)-th on (tile_in_part) and writes an EXR whose R, G, B show what it rendered and
// whose exact channels hold its film bit for bit (each pixel's sums and count, and the splats of its
// light paths, which land anywhere on the image), with what made them (scene hash, settings, part)
// in its metadata. `candela merge part-*.exr -o out.exr` checks that the parts belong together and
// cover the image exactly once, and puts the film back together: the same pixels, bit for bit, as
// one process rendering the whole image.
//
// Renders of the same scene and settings with different seeds are independent sample sets: merge
// adds them up (each pixel's sums and counts, the splats), so the result weighs each by its sample
// count, e.g. a 1024-spp render plus another 1024 spp with another seed make a 2048-spp image.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "candela/film/film.h"
#include "candela/render/checkpoint.h"

namespace candela {

// Whether tile number `tile` (in make_tiles order) belongs to part `index` (0-based) of `count`.
inline bool tile_in_part(size_t tile, int index, int count) { return tile % size_t(count) == size_t(index); }

struct FilmPart {
  int index = 0, count = 1;       // part index + 1 of count
  RenderFingerprint fingerprint;  // scene hash and every setting that changes the image (seed and spp too)
  // The camera's importance film area: a film with splats (bdpt) shows them times this over its
  // number of samples.
  double splat_area = 0;
  uint64_t non_finite_samples = 0;
  Film film{0, 0};
};

// Writes `part` to an .exr (atomically, like every image), R, G, B from its film, with `metadata`
// and the part's own attributes. Throws OutputError naming the file.
void write_part(const std::filesystem::path& file, const FilmPart& part, std::map<std::string, std::string> metadata);
// Throws FileContentError naming the file when it cannot be read or is not a candela part.
FilmPart read_part(const std::filesystem::path& file);

struct MergedRender {
  Film film{0, 0};
  uint64_t non_finite_samples = 0;
  RenderFingerprint fingerprint;  // the parts' (the first set's seed and spp)
  std::string description;        // "3 parts of seed 1, 1 part of seed 2"
  std::vector<std::string> seeds;
};

// Merges the parts in `files` (read with read_part): they must come from the same scene and
// settings; grouped by seed, each group must hold parts 1..N of one N exactly once. Throws
// FileContentError naming the file at fault (missing, duplicated or foreign part), UsageError for no
// files.
MergedRender merge_parts(const std::vector<std::filesystem::path>& files);

}  // namespace candela
