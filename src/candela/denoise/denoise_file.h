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

// The denoiser's input from `file`'s Halves layer. Throws FileContentError
// naming the file and the missing channels (and how to write them) where it lacks one.
DenoiseInput read_denoise_input(const std::filesystem::path& file);

}  // namespace candela
