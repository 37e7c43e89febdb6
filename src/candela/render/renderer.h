#pragma once
// The render loop: the image is cut into tiles, the samples into passes; each pass renders every
// tile in parallel with oneTBB. Every pixel sample draws its random numbers as a function of
// (pixel, sample index, seed) and each pixel accumulates its samples in sample order, so the image
// is bitwise identical for any thread count.
//
// Adaptive sampling (Häkkinen 2002, sec. 4.3): all pixels first get one batch of F samples (F a
// power of two, so stratification holds within the batch); after each batch, pixels whose relative
// standard error still exceeds the threshold get another batch, up to the maximum spp.
#include <cstdint>
#include <string>

#include "candela/film/film.h"
#include "candela/integrators/path_integrator.h"
#include "candela/scene/scene.h"

namespace candela {

struct RenderOptions {
  int threads = 0;       // 0 = all cores
  bool progress = true;  // draw a progress bar when stderr is a terminal
};

struct RenderStats {
  double seconds = 0;
  uint64_t samples = 0;
  uint64_t non_finite_samples = 0;  // NaN/inf radiance values, dropped (counted as black)
  RayCounts rays;
};

// Names accepted by RenderSettings::integrator.
bool is_known_integrator(const std::string& name);

// The relative error adaptive sampling compares with its threshold: the largest over the channels
// of standard error / sqrt(mean^2 + 0.01), the per-pixel form of relMSE with epsilon 0.01.
float relative_error(const PixelSums& pixel);

// Renders into `film` (sized to the camera's resolution): settings.spp samples per pixel, or
// adaptively when settings.adaptive_threshold > 0.
RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
