#pragma once
// Lambertian reflection, two-sided: f = R / pi on the side of wo, importance-sampled by cos(theta).
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/sampling/warp.h"

namespace candela {

struct DiffuseBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::NonDelta;
  RGB reflectance{0.5f};

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    return same_hemisphere(wo, wi) ? reflectance * kInvPi : RGB(0.0f);
  }
  float pdf(const Vec3& wo, const Vec3& wi) const {
    return same_hemisphere(wo, wi) ? abs_cos_theta(wi) * kInvPi : 0.0f;
  }
  std::optional<BsdfSample> sample(const Vec3& wo, float /*u_lobe*/, Vec2 u) const {
    Vec3 wi = square_to_cosine_hemisphere(u);
    if (wo.z < 0) wi.z = -wi.z;
    float p = abs_cos_theta(wi) * kInvPi;
    if (p <= 0) return std::nullopt;
    return BsdfSample{wi, reflectance, p, false, 1};
  }
  bool has_non_delta() const { return true; }
  bool has_non_delta_transmission() const { return false; }
  float non_delta_probability(const Vec3& /*wo*/) const { return 1; }
};

}  // namespace candela
