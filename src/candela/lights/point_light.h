#pragma once
// Isotropic point light of intensity I (W/sr): irradiance falls off as I cos / d^2.
#include "candela/lights/light_sample.h"

namespace candela {

struct PointLightSource {
  static constexpr LightFlags flags = LightFlags::DeltaPosition;
  Point3 position;
  RGB intensity;

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    Vec3 d = position - ctx.p;
    float dist2 = length_squared(d);
    float dist = std::sqrt(dist2);
    return {intensity / dist2, d / dist, dist, 1, position, Normal3(0.0f), true};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }
  // Emission: uniformly in all directions.
  LightEmission sample_le(Vec2, Vec2 u_dir, const SceneSphere&) const {
    return {intensity, position, square_to_uniform_sphere(u_dir), Normal3(0.0f), 1, uniform_sphere_pdf()};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3&, const SceneSphere&) const {
    return {1, uniform_sphere_pdf()};
  }
  float power() const { return 4 * kPi * intensity.luminance(); }
  // Estimated irradiance at ctx: I cos / d^2 (for spending shadow rays where lights matter).
  float importance(const LightSampleContext& ctx) const {
    Vec3 d = position - ctx.p;
    float d2 = length_squared(d);
    float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, d) / std::sqrt(d2));
    return intensity.luminance() * cos_p / std::max(d2, 1e-12f);
  }
};

}  // namespace candela
