#pragma once
// A finished render denoised, as `candela render --denoise` and the Python module's
// render(denoise=True) and denoise() do it: the AOV layer the render must collect for it (the
// halves layer: each half's colour and features), and the denoiser (denoiser.h) run on it, timed. What it adds to the
// image file (the metadata, the layer Noisy, the closing line) is denoise_file.h's.
#include "candela/denoise/denoiser.h"
#include "candela/film/aov_film.h"

namespace candela {

// The AOV layers the denoiser reads (denoise_input).
inline constexpr Aov kDenoiseFeatures[] = {Aov::Halves};

// `selection` with the denoiser's layers added where it lacks them (after its own layers; its
// space kept: the features' linear fit does not depend on it). Throws UsageError for pbrt-v4's
// gbuffer naming, whose film keeps its own layers alone.
AovSelection with_denoise_features(AovSelection selection);

struct DenoisedRender {
  DenoiseResult result;
  double seconds = 0;  // gathering the input and denoising it
};

// Denoises a finished film with its AOV film, which must hold kDenoiseFeatures (InternalError
// otherwise, from denoise_input). `input`, when given, receives the denoiser's input.
DenoisedRender denoise_render(const Film& film, const AovFilm& aovs, DenoiseInput* input = nullptr);
// Denoises an input given directly (the Python module's denoise()), timed the same way.
DenoisedRender denoise_render(const DenoiseInput& input);

}  // namespace candela
