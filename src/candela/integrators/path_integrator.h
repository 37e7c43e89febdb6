#pragma once
// The path tracer (Häkkinen 2002, sec. 4.1; pbrt-v4's PathIntegrator): one path per camera sample,
// never split. At every vertex with a non-delta BSDF, direct light is estimated with shadow rays
// (sec. 4.5) and combined with the BSDF-sampled continuation by multiple importance sampling (power
// heuristic, optional). The continuation direction is chosen by BSDF importance sampling, or, as in
// the paper's sec. 4.7, cosine-weighted or uniformly over the hemisphere and weighted by the BSDF.
// Russian roulette on the throughput ends paths after a few bounces.
//
// The integrator is a template over the sampler type: the render loop dispatches once per tile.
#include <cstdint>

#include "candela/geometry/ray.h"
#include "candela/math/color.h"
#include "candela/render/render_loop.h"
#include "candela/scene/scene.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

class PathIntegrator {
 public:
  PathIntegrator(const Scene& scene, const RenderSettings& settings);

  // Radiance arriving along the camera ray: RGB, or with wavelengths (a spectral render) the values
  // at those wavelengths (spectral/wavelengths.h).
  template <typename Sampler>
  RGB radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl = nullptr) const;

 private:
  struct Vertex;  // what direct lighting needs to know about the current path vertex

  template <typename Sampler>
  RGB direct_light(const Vertex& v, Sampler& sampler, RayCounts& counts) const;
  RGB shadow_ray_estimate(const Vertex& v, size_t light, const Vec2& u, float expected_rays,
                          RayCounts& counts) const;
  // Expected number of shadow rays that light `li` receives at a vertex: the light-sampling
  // strategy's sample count for MIS (Veach's multi-sample model).
  float expected_shadow_rays(size_t li, const LightSampleContext& ctx) const;
  // Weight of a light found by BSDF sampling (hit or escaped to the sky), against light sampling.
  float emitter_mis_weight(size_t li, float bsdf_pdf, float light_pdf_li, const LightSampleContext& prev) const;

  template <typename Sampler>
  std::optional<BsdfSample> sample_direction(const SurfaceBsdf& bsdf, const Vec3& wo, Sampler& sampler) const;
  float direction_pdf(const SurfaceBsdf& bsdf, const Vec3& wo, const Vec3& wi) const;

  const Scene& scene_;
  int max_depth_;
  int rr_start_depth_;
  DirectionSampling direction_sampling_;
  bool mis_;
  bool hide_emitters_;
  int shadow_rays_;
};

// Integrator "path": renders `film` with the path tracer through the shared tile loop.
RenderStats render_path(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options);

inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (std::isinf(a)) return 1;
  return a + b > 0 ? a / (a + b) : 0;
}

}  // namespace candela
