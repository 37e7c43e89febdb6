#pragma once
// Stochastic progressive photon mapping (integrator "sppm"; Hachisuka & Jensen 2009, as pbrt-v4's
// SPPMIntegrator). RenderSettings::spp is the number of iterations; each iteration:
//
//   1. Camera pass: one camera path per pixel (sample `iteration` of the pixel's sampler), traced by
//      the path tracer (path_integrator.h) through delta and glossy surfaces, adding the emission it
//      meets and next-event estimates of direct light (MIS weighted) to the pixel's Ld. At the first
//      surface with a diffuse lobe (or a glossy one at the maximum depth) it leaves a visible point
//      (position, BSDF, direction to the camera, throughput) and ends one bounce later, once the
//      emission found along its BSDF-sampled direction (the other half of direct light's MIS) is in.
//   2. The visible points go into a hash grid of cells as large as the largest search radius.
//   3. Photon pass: photons_per_iteration light subpaths (bdpt.h's: a light chosen by power, lights at
//      infinity from the scene's bounding disk, BSDF sampling with Russian roulette, adjoint BSDFs),
//      each of at most max_depth surface hits. From its second hit on (the first is direct light,
//      which the camera pass estimates), every hit adds beta_photon f(wo_vp, wi) beta_vp to Phi and 1
//      to M of each visible point within that point's radius.
//   4. Each pixel with M > 0 is updated progressively (alpha = 2/3): N' = N + alpha M,
//      r' = r sqrt(N' / (N + M)), tau' = (tau + Phi) r'^2 / r^2.
//
// The pixel's value after I iterations of P photons: Ld / I + tau / (I P pi r^2). It is consistent,
// not unbiased: the density estimate blurs light over the radius, which shrinks as photons arrive.
//
// As in pbrt-v4: all pixels and photons of an iteration share its wavelengths (a spectral render);
// the camera path takes one sample per pixel per iteration and the pixel filter weighs it (a box filter
// not at all); participating media are not rendered (the traits refuse such scenes); the pixel sensor
// applies to every contribution. Beyond pbrt-v4: --clamp limits each iteration's camera-path light (Ld's
// sample), not the photons'; a time limit stops between iterations; a live view sees every iteration.
// Memory: every pixel keeps its visible point's BSDF and shading frame, about 650 bytes (1.4 GB at 1080p).
//
// Determinism: every camera path draws its numbers from (pixel, iteration, seed) and every photon from
// (photon index, iteration, seed); the photons' contributions to Phi are summed in fixed point with
// integer atomics (SplatImage, in units of the scene's light power) and M is an integer count, so the
// sums do not depend on the order threads add in: the image is the same for any thread count. The
// grid's lists are built in any order, which changes only the order of those exact sums.
#include <cstdint>

#include "candela/film/film.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"

namespace candela {

// What an SPPM render reports besides RenderStats (its RenderStats::details).
struct SppmStats {
  int iterations = 0;               // completed
  uint64_t photons = 0;             // traced, over all iterations
  double min_radius = 0, max_radius = 0;  // the pixels' search radii at the end (world units)
};

// The SppmStats of a render by render_sppm, or null for another integrator's.
inline const SppmStats* sppm_stats(const RenderStats& stats) { return std::any_cast<SppmStats>(&stats.details); }

// The photons an iteration traces: settings.sppm.photons_per_iteration, or one per pixel.
uint64_t sppm_photons_per_iteration(const RenderSettings& settings, int width, int height);

// Integrator "sppm": renders settings.spp iterations into `film`, whose every pixel ends with the
// SPPM estimate as its mean (its sample count is the number of iterations).
RenderStats render_sppm(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
