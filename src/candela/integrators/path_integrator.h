#pragma once
// The path tracer (Häkkinen 2002, sec. 4.1; pbrt-v4's PathIntegrator): one path per camera sample,
// never split; next-event estimation at every vertex with a non-delta BSDF, combined with BSDF
// sampling by multiple importance sampling (power heuristic); Russian roulette on the throughput
// after a few bounces.
#include <cstdint>

#include "candela/geometry/ray.h"
#include "candela/math/color.h"
#include "candela/sampling/sampler.h"
#include "candela/scene/scene.h"

namespace candela {

struct RayCounts {
  uint64_t camera = 0, bounce = 0, shadow = 0;
  uint64_t total() const { return camera + bounce + shadow; }
  RayCounts& operator+=(const RayCounts& o) {
    camera += o.camera;
    bounce += o.bounce;
    shadow += o.shadow;
    return *this;
  }
};

class PathIntegrator {
 public:
  PathIntegrator(const Scene& scene, const RenderSettings& settings)
      : scene_(scene), max_depth_(settings.max_depth), rr_start_depth_(settings.rr_start_depth) {}

  // Radiance arriving along the camera ray.
  RGB radiance(Ray ray, IndependentSampler& sampler, RayCounts& counts) const;

 private:
  RGB sample_direct(const SurfaceHit& hit, const Bsdf& bsdf, const Frame& frame, const Vec3& wo_local,
                    const LightSampleContext& ctx, float time, IndependentSampler& sampler, RayCounts& counts) const;

  const Scene& scene_;
  int max_depth_;
  int rr_start_depth_;
};

inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (std::isinf(a)) return 1;
  return a + b > 0 ? a / (a + b) : 0;
}

}  // namespace candela
