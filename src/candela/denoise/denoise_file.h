#pragma once
// What denoising adds to an image file, and `candela denoise`'s input: an OpenEXR file written with
// `--aov halves` (film/aov_film.h) holds everything the denoiser reads.
#include <filesystem>
#include <map>
#include <string>

#include "candela/denoise/denoiser.h"
#include "candela/film/image_io.h"

namespace candela {

// The raw image as the EXR layer "Noisy" (Noisy.R, Noisy.G, Noisy.B), kept beside the denoised RGB.
FloatChannels noisy_layer(const Image& raw);
// `channels` followed by `more` (the same number of pixels).
FloatChannels append_channels(const FloatChannels& channels, const FloatChannels& more);

// The image metadata a denoised image carries: candela:denoised, candela:denoised_relmse_estimate,
// candela:denoised_relmse_interval95 and candela:denoise_seconds.
void add_denoise_metadata(std::map<std::string, std::string>& metadata, const DenoiseResult& result, double seconds);

// "denoised: relMSE 0.0012 (95% interval ..., eps 0.01) in 0.41 s": the closing line's report.
std::string describe_denoised(const DenoiseResult& result, double seconds);

// An .exr written with --aov halves, read once: the denoiser's input (its Halves layer) and the layers
// a denoised file keeps (every channel but the colour R, G, B, A and an earlier Noisy layer).
struct DenoiseFile {
  DenoiseInput input;
  FloatChannels layers;
};
// Throws FileContentError naming the file and the missing channel (and how to write it) where it lacks one.
DenoiseFile read_denoise_file(const std::filesystem::path& file);

}  // namespace candela
