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

// A scattering vertex of a camera path, as PathIntegrator::radiance shows it to a PathVertexVisitor:
// after its direct light has been estimated, before the next direction is drawn.
struct PathVertexView {
  const SurfaceHit& hit;
  const Shading& shading;  // the BSDF (at the path's wavelengths) and its shading frame
  Vec3 wo;                 // unit, towards the previous vertex
  RGB beta;                // the path's throughput up to this vertex
  int depth;               // 1 at the first scattering vertex
};

// Sees every scattering vertex of a path (stochastic progressive photon mapping stores its visible
// points this way, sppm.h). visit() returning true makes the vertex the path's last scattering one:
// its direction is still drawn and the emission found along it added, as at the maximum depth.
class PathVertexVisitor {
 public:
  virtual bool visit(const PathVertexView& vertex) = 0;

 protected:
  ~PathVertexVisitor() = default;
};

class PathIntegrator {
 public:
  PathIntegrator(const Scene& scene, const RenderSettings& settings);

  // Radiance arriving along the camera ray: RGB, or with wavelengths (a spectral render) the values
  // at those wavelengths (spectral/wavelengths.h). With a visitor, each scattering vertex is shown
  // to it (PathVertexVisitor).
  template <typename Sampler>
  RGB radiance(Ray ray, Sampler& sampler, RayCounts& counts, const Wavelengths* wl = nullptr,
               PathVertexVisitor* visitor = nullptr) const;

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
