#include "candela/denoise/denoise_file.h"

#include <fmt/format.h>

#include <algorithm>

#include "candela/base/error.h"

namespace candela {

FloatChannels noisy_layer(const Image& raw) {
  return {{"Noisy.R", "Noisy.G", "Noisy.B"}, raw.rgb};
}

FloatChannels append_channels(const FloatChannels& channels, const FloatChannels& more) {
  if (channels.names.empty()) return more;
  if (more.names.empty()) return channels;
  const size_t a = channels.names.size(), b = more.names.size(), pixels = channels.values.size() / a;
  if (more.values.size() != pixels * b)
    throw InternalError("append_channels: the two sets of channels have different pixel counts");
  FloatChannels result;
  result.names = channels.names;
  result.names.insert(result.names.end(), more.names.begin(), more.names.end());
  result.values.resize(pixels * (a + b));
  for (size_t i = 0; i < pixels; ++i) {
    std::copy_n(&channels.values[i * a], a, &result.values[i * (a + b)]);
    std::copy_n(&more.values[i * b], b, &result.values[i * (a + b) + a]);
  }
  return result;
}

void add_denoise_metadata(std::map<std::string, std::string>& metadata, const DenoiseResult& result, double seconds) {
  metadata["candela:denoised"] = "true";
  metadata["candela:denoise_seconds"] = fmt::format("{:.3f}", seconds);
  if (result.error.valid) {
    metadata["candela:denoised_relmse_estimate"] = fmt::format("{:.6g}", result.error.relmse);
    metadata["candela:denoised_relmse_interval95"] = fmt::format("{:.6g} {:.6g}", result.error.low, result.error.high);
  }
}

std::string describe_denoised(const DenoiseResult& result, double seconds) {
  return fmt::format("denoised: {} in {:.2f} s", describe(result.error), seconds);
}

namespace {
// The channels `names` (a layer's, in this order) of `found` (read from `file`), one float each per pixel.
std::vector<float> layer_channels(const FloatChannels& found, const std::filesystem::path& file,
                                  const std::string& layer, const std::vector<std::string>& names, size_t pixels) {
  std::vector<float> values(pixels * names.size());
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string wanted = layer + "." + names[k];
    const auto it = std::find(found.names.begin(), found.names.end(), wanted);
    if (it == found.names.end())
      throw FileContentError(fmt::format(
          "{}: has no channel {}: candela denoise reads an .exr written with --aov halves",
          file.string(), wanted));
    const size_t from = size_t(it - found.names.begin()), stride = found.names.size();
    for (size_t i = 0; i < pixels; ++i) values[i * names.size() + k] = found.values[i * stride + from];
  }
  return values;
}
}  // namespace

DenoiseFile read_denoise_file(const std::filesystem::path& file) {
  const FloatChannels all = read_float_channels(file, "");
  const size_t pixels = size_t(all.width) * size_t(all.height);
  const std::vector<float> halves = layer_channels(
      all, file, "Halves",
      {"A.R", "A.G", "A.B", "B.R", "B.G", "B.B", "ShareA", "A.Albedo.R", "A.Albedo.G", "A.Albedo.B", "A.Normal.X",
       "A.Normal.Y", "A.Normal.Z", "A.Depth.Z", "B.Albedo.R", "B.Albedo.G", "B.Albedo.B", "B.Normal.X", "B.Normal.Y",
       "B.Normal.Z", "B.Depth.Z"},
      pixels);
  DenoiseFile result;
  DenoiseInput& in = result.input;
  in = denoise_input(all.width, all.height, halves);
  for (size_t i = 0; i < pixels; ++i)
    if (!(in.share_a[i] > 0 && in.share_a[i] < 1))
      throw FileContentError(fmt::format("{}: pixel ({}, {}) has Halves.ShareA {}, outside (0, 1)", file.string(),
                                         i % size_t(in.width), i / size_t(in.width), in.share_a[i]));
  // The layers kept: all but the colour and an earlier Noisy layer.
  std::vector<size_t> kept;
  for (size_t k = 0; k < all.names.size(); ++k) {
    const std::string& name = all.names[k];
    if (name == "R" || name == "G" || name == "B" || name == "A" || name.rfind("Noisy.", 0) == 0) continue;
    kept.push_back(k);
    result.layers.names.push_back(name);
  }
  result.layers.width = all.width, result.layers.height = all.height;
  result.layers.values.resize(pixels * kept.size());
  for (size_t i = 0; i < pixels; ++i)
    for (size_t k = 0; k < kept.size(); ++k)
      result.layers.values[i * kept.size() + k] = all.values[i * all.names.size() + kept[k]];
  return result;
}

}  // namespace candela
