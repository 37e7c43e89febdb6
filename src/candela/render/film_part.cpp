#include "candela/render/film_part.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/film/image_io.h"
#include "candela/render/render_loop.h"

namespace candela {
namespace {

constexpr const char* kPrefix = "candela.";
// The exact channels: each 64-bit value of a pixel as two 32-bit halves, low first.
constexpr const char* kPixelFields[] = {"sum.R", "sum.G", "sum.B", "sumsq.R", "sumsq.G", "sumsq.B", "weight", "count"};
constexpr const char* kSplatFields[] = {"splat.R", "splat.G", "splat.B"};
constexpr size_t kPixelWords = 2 * std::size(kPixelFields), kSplatWords = 2 * std::size(kSplatFields);

[[noreturn]] void fail_part(const std::filesystem::path& file, const std::string& what) {
  throw FileContentError(fmt::format("{}: {}", file.string(), what));
}

void put64(uint32_t* out, uint64_t v) {
  out[0] = uint32_t(v);
  out[1] = uint32_t(v >> 32);
}
uint64_t get64(const uint32_t* in) { return uint64_t(in[0]) | (uint64_t(in[1]) << 32); }
template <typename T>
uint64_t bits(T v) {
  static_assert(sizeof(T) == 8);
  uint64_t u;
  std::memcpy(&u, &v, 8);
  return u;
}
template <typename T>
T from_bits(uint64_t u) {
  T v;
  std::memcpy(&v, &u, 8);
  return v;
}

// The exact channels' names, in the order of a pixel's words.
std::vector<std::string> channel_names(bool splats) {
  std::vector<std::string> names;
  for (const char* field : kPixelFields)
    for (const char* half : {".lo", ".hi"}) names.push_back(std::string(kPrefix) + field + half);
  if (splats)
    for (const char* field : kSplatFields)
      for (const char* half : {".lo", ".hi"}) names.push_back(std::string(kPrefix) + field + half);
  return names;
}

std::string settings_text(const RenderFingerprint& fp) {
  std::string text;
  for (const auto& [key, value] : fp.settings) text += key + "=" + value + "\n";
  return text;
}

const std::string& attribute(const std::map<std::string, std::string>& metadata, const std::filesystem::path& file,
                             const std::string& key) {
  auto it = metadata.find(key);
  if (it == metadata.end())
    fail_part(file, fmt::format("not a candela part (no {} attribute; write parts with candela render --part K/N)", key));
  return it->second;
}

// The fingerprint without the settings that merely choose a sample set: parts with different seeds
// (and sample counts) of one render merge.
RenderFingerprint without_sample_set(RenderFingerprint fp) {
  std::erase_if(fp.settings, [](const auto& kv) { return kv.first == "seed" || kv.first == "spp"; });
  return fp;
}

// The unsigned number `text` in `base`, all of it, or a FileContentError naming the file and the attribute.
uint64_t parse_u64(const std::filesystem::path& file, const std::string& attribute, const std::string& text, int base) {
  uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value, base);
  if (error != std::errc() || end != text.data() + text.size() || text.empty())
    fail_part(file, fmt::format("{} '{}' is not a {} number below 2^64", attribute, text, base == 16 ? "hexadecimal" : "decimal"));
  return value;
}

std::string setting(const RenderFingerprint& fp, const std::string& key) {
  for (const auto& [k, v] : fp.settings)
    if (k == key) return v;
  return "";
}

}  // namespace

void write_part(const std::filesystem::path& file, const FilmPart& part, std::map<std::string, std::string> metadata) {
  const Film& film = part.film;
  const size_t pixels = size_t(film.width()) * size_t(film.height());
  ExactChannels channels;
  channels.names = channel_names(film.has_splats());
  const size_t words = channels.names.size();
  channels.values.resize(pixels * words);
  for (size_t i = 0; i < pixels; ++i) {
    const PixelSums& p = film.pixels()[i];
    uint32_t* out = &channels.values[i * words];
    for (int c = 0; c < 3; ++c) put64(out + 2 * c, bits(p.weighted[c]));
    for (int c = 0; c < 3; ++c) put64(out + 6 + 2 * c, bits(p.weighted_sq[c]));
    put64(out + 12, bits(p.weight));
    put64(out + 14, p.count);
    if (film.has_splats())
      for (int c = 0; c < 3; ++c) put64(out + kPixelWords + 2 * c, uint64_t(film.splats().sums()[i * 3 + size_t(c)]));
  }
  metadata["candela:part"] = fmt::format("{}/{}", part.index + 1, part.count);
  metadata["candela:scene_hash"] = fmt::format("{:016x}", part.fingerprint.scene_hash);
  metadata["candela:settings"] = settings_text(part.fingerprint);
  metadata["candela:splat_area"] = fmt::format("{:a}", part.splat_area);
  metadata["candela:non_finite_samples"] = std::to_string(part.non_finite_samples);
  write_image(file, film.mean_image(), metadata, channels);
}

FilmPart read_part(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) fail_part(file, ec ? ec.message() : "no such file");
  // A part is a single-part image (write_part writes no other); check_exr_header walks the header
  // before OpenImageIO reads it.
  const int exr_flags = check_exr_header(file);
  if (exr_flags < 0) fail_part(file, "not an OpenEXR file");
  if (exr_flags & 0x18) fail_part(file, "not a candela part (a multi-part or deep OpenEXR file)");
  std::map<std::string, std::string> metadata = read_image_metadata(file);
  FilmPart part;
  const std::string& which = attribute(metadata, file, "candela:part");
  if (std::sscanf(which.c_str(), "%d/%d", &part.index, &part.count) != 2 || part.count < 1 || part.index < 1 ||
      part.index > part.count)
    fail_part(file, fmt::format("candela:part '{}' is not K/N with 1 <= K <= N", which));
  --part.index;
  part.fingerprint.scene_hash =
      parse_u64(file, "candela:scene_hash", attribute(metadata, file, "candela:scene_hash"), 16);
  const std::string& settings = attribute(metadata, file, "candela:settings");
  for (size_t at = 0; at < settings.size();) {
    size_t end = settings.find('\n', at), eq = settings.find('=', at);
    if (end == std::string::npos || eq == std::string::npos || eq > end) fail_part(file, "candela:settings is malformed");
    part.fingerprint.settings.emplace_back(settings.substr(at, eq - at), settings.substr(eq + 1, end - eq - 1));
    at = end + 1;
  }
  part.splat_area = std::strtod(attribute(metadata, file, "candela:splat_area").c_str(), nullptr);
  part.non_finite_samples =
      parse_u64(file, "candela:non_finite_samples", attribute(metadata, file, "candela:non_finite_samples"), 10);

  ExactChannels channels = read_exact_channels(file, kPrefix);
  const size_t words = channels.names.size();
  if (words != kPixelWords && words != kPixelWords + kSplatWords)
    fail_part(file, fmt::format("has {} {}* channels, expected {} or {}", words, kPrefix, kPixelWords, kPixelWords + kSplatWords));
  const size_t pixels = channels.values.size() / words;
  std::string resolution = setting(part.fingerprint, "resolution");
  int width = 0, height = 0;
  // Both sides positive: -2 x -2 would pass the product check as 4 pixels, and make a film of negative width.
  if (std::sscanf(resolution.c_str(), "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0 ||
      size_t(width) * size_t(height) != pixels)
    fail_part(file, fmt::format("its pixels do not match its resolution setting '{}'", resolution));
  part.film = Film(width, height);
  if (words > kPixelWords) part.film.enable_splats();
  // EXR keeps channels sorted by name: find each of ours, in the order write_part made them.
  std::vector<size_t> column;
  for (const std::string& name : channel_names(words > kPixelWords)) {
    auto it = std::find(channels.names.begin(), channels.names.end(), name);
    if (it == channels.names.end()) fail_part(file, "has no channel " + name);
    column.push_back(size_t(it - channels.names.begin()));
  }
  uint32_t in[kPixelWords + kSplatWords];
  for (size_t i = 0; i < pixels; ++i) {
    for (size_t k = 0; k < column.size(); ++k) in[k] = channels.values[i * words + column[k]];
    PixelSums& p = part.film.pixels()[i];
    for (int c = 0; c < 3; ++c) p.weighted[c] = from_bits<double>(get64(in + 2 * c));
    for (int c = 0; c < 3; ++c) p.weighted_sq[c] = from_bits<double>(get64(in + 6 + 2 * c));
    p.weight = from_bits<double>(get64(in + 12));
    p.count = get64(in + 14);
    if (words > kPixelWords)
      for (int c = 0; c < 3; ++c) part.film.splats().sums()[i * 3 + size_t(c)] = int64_t(get64(in + kPixelWords + 2 * c));
  }
  return part;
}

MergedRender merge_parts(const std::vector<std::filesystem::path>& files) {
  if (files.empty()) throw UsageError("merge: no parts given");
  std::vector<FilmPart> parts;
  for (const auto& f : files) parts.push_back(read_part(f));

  // Every part must come from the first one's scene and settings (its seed and spp aside).
  const RenderFingerprint reference = without_sample_set(parts[0].fingerprint);
  for (size_t i = 1; i < parts.size(); ++i) {
    std::string diff = without_sample_set(parts[i].fingerprint).difference(reference);
    if (!diff.empty())
      fail_part(files[i], fmt::format("does not belong with {}: {} ({} vs {})", files[0].string(), diff, files[i].string(),
                                 files[0].string()));
    if (parts[i].film.has_splats() != parts[0].film.has_splats() || parts[i].splat_area != parts[0].splat_area)
      fail_part(files[i], fmt::format("does not belong with {}: its light-path splats differ", files[0].string()));
  }
  // Sample sets by seed, in increasing order; each must hold parts 1..N of one N exactly once.
  std::vector<std::string> seeds;
  for (const FilmPart& p : parts) seeds.push_back(setting(p.fingerprint, "seed"));
  std::sort(seeds.begin(), seeds.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());

  const int width = parts[0].film.width(), height = parts[0].film.height();
  const std::vector<Tile> tiles = make_tiles(width, height);
  MergedRender merged;
  merged.film = Film(width, height);
  if (parts[0].film.has_splats()) merged.film.enable_splats();
  merged.fingerprint = parts[0].fingerprint;
  merged.seeds = seeds;
  bool first_set = true;
  for (const std::string& seed : seeds) {
    std::vector<int> of_set;  // indices into parts
    for (size_t i = 0; i < parts.size(); ++i)
      if (setting(parts[i].fingerprint, "seed") == seed) of_set.push_back(int(i));
    const FilmPart& lead = parts[size_t(of_set[0])];
    // The index into parts of each part number. A map, not a vector of lead.count entries: one file
    // claiming to be part 1 of 2147483647 must not cost 8 GB before it is found missing the others.
    std::map<int, int> holder;
    for (int i : of_set) {
      const FilmPart& p = parts[size_t(i)];
      if (p.count != lead.count)
        fail_part(files[size_t(i)], fmt::format("is part {}/{} but {} is part {}/{} of the same seed {}", p.index + 1, p.count,
                                           files[size_t(of_set[0])].string(), lead.index + 1, lead.count, seed));
      if (setting(p.fingerprint, "spp") != setting(lead.fingerprint, "spp"))
        fail_part(files[size_t(i)], fmt::format("has spp {} but {} of the same seed {} has spp {}", setting(p.fingerprint, "spp"),
                                           files[size_t(of_set[0])].string(), seed, setting(lead.fingerprint, "spp")));
      if (const auto held = holder.find(p.index); held != holder.end())
        fail_part(files[size_t(i)], fmt::format("is part {}/{} of seed {}, as {} is", p.index + 1, p.count, seed,
                                           files[size_t(held->second)].string()));
      holder[p.index] = i;
    }
    for (int k = 0; k < lead.count; ++k)  // stops at the first missing part, at most of_set.size() on
      if (!holder.contains(k))
        throw FileContentError(fmt::format("merge: part {}/{} of seed {} is missing (have {})", k + 1, lead.count,
                                           seed, files[size_t(of_set[0])].string()));
    // This sample set's film: each tile's pixels from the part that rendered it, splats summed.
    Film set(width, height);
    for (size_t t = 0; t < tiles.size(); ++t) {
      const Film& from = parts[size_t(holder.at(int(t % size_t(lead.count))))].film;
      for (int y = tiles[t].y0; y < tiles[t].y1; ++y)
        for (int x = tiles[t].x0; x < tiles[t].x1; ++x)
          set.pixels()[size_t(y) * size_t(width) + size_t(x)] = from.pixel(x, y);
    }
    for (int i : of_set) merged.non_finite_samples += parts[size_t(i)].non_finite_samples;
    if (merged.film.has_splats())
      for (int i : of_set)
        for (size_t j = 0; j < merged.film.splats().sums().size(); ++j)
          merged.film.splats().sums()[j] += parts[size_t(i)].film.splats().sums()[j];
    // Sample sets add up: every pixel's sums and counts.
    if (first_set) {
      merged.film.pixels() = set.pixels();
    } else {
      for (size_t i = 0; i < set.pixels().size(); ++i) {
        PixelSums& to = merged.film.pixels()[i];
        const PixelSums& from = set.pixels()[i];
        for (int c = 0; c < 3; ++c) {
          to.weighted[c] += from.weighted[c];
          to.weighted_sq[c] += from.weighted_sq[c];
        }
        to.weight += from.weight;
        to.count += from.count;
      }
    }
    first_set = false;
    merged.description += fmt::format("{}{} part{} of seed {}", merged.description.empty() ? "" : ", ", lead.count,
                                      lead.count == 1 ? "" : "s", seed);
  }
  // One light path per camera sample (bdpt), as render_bdpt scales its splats.
  uint64_t light_paths = merged.film.total_samples();
  if (merged.film.has_splats())
    merged.film.set_splat_scale(light_paths > 0 ? parts[0].splat_area / double(light_paths) : 0);
  return merged;
}

}  // namespace candela
