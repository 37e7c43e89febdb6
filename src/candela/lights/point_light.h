#pragma once
// Isotropic point light of intensity I (W/sr): irradiance falls off as I cos / d^2.
#include "candela/lights/light_sample.h"

namespace candela {

struct PointLightSource {
  Point3 position;
  RGB intensity;

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    Vec3 d = position - ctx.p;
    float dist2 = length_squared(d);
    float dist = std::sqrt(dist2);
    return {intensity / dist2, d / dist, dist, 1, position, Normal3(0.0f), true};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }
  float power() const { return 4 * kPi * intensity.luminance(); }
};

}  // namespace candela
