#include "candela/denoise/denoised_render.h"

#include <algorithm>
#include <chrono>

#include "candela/base/error.h"
#include "candela/film/film.h"

namespace candela {

AovSelection with_denoise_features(AovSelection selection) {
  // pbrt-v4's gbuffer film keeps its own layers alone.
  if (selection.naming == AovNaming::PbrtGbuffer)
    throw UsageError("--denoise cannot be combined with pbrt-v4's gbuffer AOVs (--aov gbuffer, or the scene's "
                     "aovs): that film keeps its own layers alone, and the denoiser reads candela's halves layer; "
                     "ask for candela's layers instead (--aov all, or a list such as albedo,normal,position)");
  for (Aov feature : kDenoiseFeatures)
    if (std::find(selection.layers.begin(), selection.layers.end(), feature) == selection.layers.end())
      selection.layers.push_back(feature);
  return selection;
}

namespace {
double denoised_render_seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

DenoisedRender denoise_render(const DenoiseInput& input) {
  const auto start = std::chrono::steady_clock::now();
  DenoisedRender denoised;
  denoised.result = denoise(input);
  denoised.seconds = denoised_render_seconds_since(start);
  return denoised;
}

DenoisedRender denoise_render(const Film& film, const AovFilm& aovs, DenoiseInput* input) {
  const auto start = std::chrono::steady_clock::now();
  DenoiseInput gathered = denoise_input(film, aovs);
  DenoisedRender denoised = denoise_render(gathered);
  denoised.seconds = denoised_render_seconds_since(start);
  if (input) *input = std::move(gathered);
  return denoised;
}

}  // namespace candela
