#pragma once
// The volumetric path tracer (integrator "volpath"): path tracing of scenes with participating media,
// after the null-scattering path integral of Miller, Georgiev and Jarosz (2019) as pbrt-v4's
// VolPathIntegrator implements it.
//   - Distances in a medium are sampled by delta tracking against the majorant (media/medium.h: a
//     coarse grid of local maxima in heterogeneous media, traversed by DDA): at each tentative
//     collision the path is absorbed, scatters or continues (a null collision) with probabilities
//     sigma_a, sigma_s and sigma_n over the majorant.
//   - Chromatic media: one colour channel (or wavelength), the hero, chosen uniformly per path,
//     drives every sampling decision; the others are carried as ratios of path densities (r_u for the
//     unidirectional strategy, r_l for light sampling), and each contribution is divided by their
//     average over the channels: the one-sample balance heuristic over channels (spectral MIS), which
//     has no colour bias and does not blow up where one channel's coefficient is small. The same
//     average weighs light sampling against the unidirectional strategy (the balance heuristic).
//   - Next-event estimation at surfaces and in media, its shadow rays carrying transmittance by ratio
//     tracking (in media of constant extinction: the exact transmittance, ratio tracking's expectation)
//     through every medium and pass-through surface (interfaces, masks, thin sheets) they cross,
//     combined by MIS with the phase function or BSDF sampled continuation.
//   - Equiangular sampling in homogeneous media (Kulla and Fajardo 2012, as Cycles does; --equiangular,
//     on by default): on every ray segment through a medium of constant density (not a subsurface one)
//     where the path may still scatter, with probability 1/2 (one-sample MIS, as Cycles), a light and
//     a point y on it are chosen first (the light by the light sampler at the segment's midpoint, y as
//     that light samples it: lights whose point does not depend on where they are seen from, i.e.
//     point, spot, projector and goniometric lights and the area-sampled triangles, rectangles, disks,
//     cylinders and partial spheres), then a distance t along the segment with density proportional
//     to 1 / (h^2 + (t - t_closest)^2), and the light from y scattered at t is estimated (one shadow
//     ray). That scattering point serves direct light only. Otherwise (probability 1/2) those lights
//     are sampled from the point distance sampling chooses on the segment, as before; other lights
//     always are. The two are combined by the one-sample balance heuristic over both strategies and
//     all channels (averaged over the channels as the spectral MIS above does), nested inside the
//     existing MIS of light against phase-function sampling: a path's light-sampling share
//     avg(a) / avg(a + b) (a, b: the light and phase strategies' densities) is estimated with the
//     weight over the density 1 / avg(a / 2 + e / 2) (e: equiangular sampling's density), so the
//     phase-sampled hits keep their weights and the estimator stays unbiased. Paths whose
//     distance-sampled walk met a null collision (none in constant density but for rounding) and
//     lights that equiangular sampling cannot choose (spheres, lights at infinity) weigh e = 0; a
//     scene without a light it can choose skips it. Heterogeneous media keep distance sampling alone.
//   - Media emit (source term sigma_a Le) where their emission is non-zero; light emitted on a
//     segment after k scattering events is a path of depth k, counted while k <= max_depth.
//   - Russian roulette on the throughput over the unidirectional density.
//   - A subsurface medium (MediumDesc::subsurface, pbrt-v4's "subsurface" material) is random-walked
//     like any other, but the path's whole excursion inside counts as the one bounce that entered it,
//     as pbrt-v4's BSSRDF does: its scattering events and the surfaces met from inside do not count
//     towards max_depth.
// Surfaces that let light pass straight on (interfaces; a mask's absent part; a thin sheet's
// transmission) do not count as bounces, as in Mitsuba 3's volpath. Without media the result
// equals the path tracer's (same estimator for surfaces, one shadow ray per vertex).
#include "candela/geometry/ray.h"
#include "candela/math/color.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

class VolPathIntegrator {
 public:
  VolPathIntegrator(const Scene& scene, const RenderSettings& settings);

  template <typename Sampler>
  RGB radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl = nullptr) const;

  // The transmittance between two points (no surface blocks in between but pass-through ones),
  // estimated by ratio tracking with the given hero channel; starting in medium `medium`. Exposed
  // for tests, which compare it with quadrature.
  RGB transmittance(const Point3& from, const Point3& to, int medium, int hero, uint64_t seed, float time,
                    const Wavelengths* wl = nullptr) const;

 private:
  struct ScatterPoint;   // where next-event estimation starts: a surface hit or a point in a medium
  struct MediumSegment;  // a ray segment through a medium of constant density, for equiangular sampling
  template <typename Sampler>
  RGB sample_direct(const ScatterPoint& at, Sampler& sampler, const RGB& beta, const RGB& r_u, int hero,
                    RayCounts& counts) const;
  // The light of point u of light `li` (chosen with probability pmf at `at`) arriving at `at` and
  // scattered by it, MIS-weighted (beta, r_p: the path's throughput and channel densities there).
  RGB light_contribution(const ScatterPoint& at, size_t li, float pmf, Vec2 u, uint64_t seed, const RGB& beta,
                         const RGB& r_p, int hero, RayCounts& counts) const;
  // Equiangular sampling's estimate of direct light scattered from `segment` (beta, r_u: the path's
  // throughput and channel densities at its start).
  template <typename Sampler>
  RGB sample_equiangular_direct(const MediumSegment& segment, Sampler& sampler, const RGB& beta, const RGB& r_u,
                                int hero, RayCounts& counts) const;
  // Ratio tracking from `origin` along unit `dir` over [0, t_max) through media and pass-through
  // surfaces; multiplies r_u and r_l by the path densities of the strategies (pbrt-v4's SampleLd).
  RGB trace_transmittance(Point3 origin, const Vec3& dir, float t_max, int medium, int hero, uint64_t seed, float time,
                          const Wavelengths* wl, RGB& r_u, RGB& r_l, RayCounts& counts) const;

  const Scene& scene_;
  int max_depth_;
  int rr_start_depth_;
  bool hide_emitters_;
  bool equiangular_;
};

// Integrator "volpath".
RenderStats render_volpath(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

}  // namespace candela
