#pragma once
// --integrator auto: the integrator chosen by measurement on the scene at hand. Every integrator
// that can render the scene as asked renders a short pilot; each pilot's error comes from the render
// itself (film/error_estimate.h), and with the 1/time law (the error of a Monte Carlo mean falls as
// the work spent) it predicts what that integrator reaches in the budget: a time limit, an error
// target, or the time the path tracer needs for the spp. The best one renders the rest of the budget,
// continuing its pilot where it can (path, bdpt) and starting afresh where it cannot (mlt, whose
// set-up, the bootstrap and normalisation, then counts twice and is priced in).
//
// The pilots aim at 10% of the budget together: with a time limit T each of n gets 0.1 T / n;
// with an error target or spp, each gets kPilotSeconds (a time limit cuts a render's last pass to what
// fits, but a pilot's first pass and MLT's set-up are not cut, so it can take a little longer). MLT's pilot bootstraps with a hundredth of the paths (its set-up would
// otherwise take more than the slice on deep scenes) and renders its depth-0 pass at 16 spp; its full
// set-up time is extrapolated part by part. Path and bdpt pilots render every k-th tile: their error
// is scaled to the whole image's (but for bdpt's splats, which already cover it).
#include <string>
#include <vector>

#include "candela/film/error_estimate.h"
#include "candela/integrators/integrator.h"

namespace candela {

inline constexpr double kPilotSeconds = 1.0;
inline constexpr int kPilotTileStride = 8;  // path and bdpt pilots render every 8th tile (at least 16 tiles)

struct PilotRun {
  const IntegratorEntry* integrator = nullptr;
  double seconds = 0, setup_seconds = 0;
  double full_setup_seconds = 0;  // the set-up the real render would take (mlt's pilot bootstraps less)
  double image_share = 1;         // the share of the image's tiles the pilot rendered
  ErrorEstimate error;
  double predicted = 0;  // relMSE at the budget (time limit, spp), or seconds to the target
};

struct AutoChoice {
  const IntegratorEntry* integrator = nullptr;
  std::vector<PilotRun> pilots;
  double pilot_seconds = 0;     // all pilots together
  double budget_seconds = 0;    // the whole budget when it is a time (0 with an error target)
  bool continues_pilot = false;  // the film holds the winner's pilot, which the render continues
  // "path: relMSE 0.012 in 2.0 s, predicts 0.00041; bdpt: ...; chose bdpt (pilots 6.1 s)".
  std::string summary() const;
};

// The integrators that read every selective setting `settings` sets (integrator.h), and render
// participating media when the scene has them: the registry entry "auto"'s candidates.
std::vector<const IntegratorEntry*> auto_candidates(const RenderSettings& settings, bool has_media);

// The registry entry "auto"'s choice: runs the pilots (settings.integrator is ignored;
// settings.sampler.replicas must be on) under `options` (its time limit or target error is the
// budget; the film must be empty) and chooses.
// Without either, the budget is the path tracer's time for `budget_spp` samples per pixel.
// Leaves the winner's pilot in `film` when the winner continues it, an empty film otherwise.
AutoChoice choose_integrator(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options,
                             int budget_spp);

}  // namespace candela
