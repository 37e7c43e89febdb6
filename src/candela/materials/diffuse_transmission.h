#pragma once
// Lambertian reflection and Lambertian transmission (pbrt-v4's DiffuseTransmissionBxDF): leaves,
// paper, lamp shades. f = R / pi for wi on wo's side, T / pi on the other side; each lobe is
// cosine-sampled and chosen with probability proportional to its largest channel.
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/sampling/warp.h"

namespace candela {

struct DiffuseTransmissionBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Transmission | BsdfFlags::NonDelta;
  RGB reflectance{0.25f};
  RGB transmittance{0.25f};

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    if (wo.z == 0 || wi.z == 0) return RGB(0.0f);
    return (same_hemisphere(wo, wi) ? reflectance : transmittance) * kInvPi;
  }

  float pdf(const Vec3& wo, const Vec3& wi) const {
    float pr = reflectance.max_component(), pt = transmittance.max_component();
    if (!(pr + pt > 0) || wo.z == 0 || wi.z == 0) return 0;
    float lobe = same_hemisphere(wo, wi) ? pr : pt;
    return lobe / (pr + pt) * abs_cos_theta(wi) * kInvPi;
  }

  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    float pr = reflectance.max_component(), pt = transmittance.max_component();
    if (!(pr + pt > 0) || wo.z == 0) return std::nullopt;
    Vec3 wi = square_to_cosine_hemisphere(u);
    bool reflect = u_lobe < pr / (pr + pt);
    // Reflection stays on wo's side; transmission goes to the other one.
    if ((wo.z < 0) == reflect) wi.z = -wi.z;
    float p = (reflect ? pr : pt) / (pr + pt) * abs_cos_theta(wi) * kInvPi;
    if (!(p > 0)) return std::nullopt;
    RGB weight = (reflect ? reflectance : transmittance) * ((pr + pt) / (reflect ? pr : pt));
    return BsdfSample{wi, weight, p, false, 1};
  }

  bool has_non_delta() const { return reflectance.max_component() + transmittance.max_component() > 0; }
  bool has_non_delta_transmission() const { return transmittance.max_component() > 0; }
  float non_delta_probability(const Vec3& /*wo*/) const { return 1; }
};

}  // namespace candela
