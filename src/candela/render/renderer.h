#pragma once
// The render loop: the image is cut into tiles, the samples into passes; each pass renders every
// tile in parallel with oneTBB. Every pixel sample draws its random numbers from its own stream
// (pixel, sample index, seed) and each pixel accumulates its samples in sample order, so the image
// is bitwise identical for any thread count.
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
  RayCounts rays;
};

// Names accepted by RenderSettings::integrator.
bool is_known_integrator(const std::string& name);

// Renders settings.spp samples per pixel into `film` (sized to the camera's resolution).
RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
