#pragma once
// The paper's material (Häkkinen 2002, sec. 4.6-4.7): with probability d a diffuse bounce, with
// probability s a bounce in a normalised Phong lobe around the mirror direction, with probability t
// ideal refraction, else absorption. The BSDF this Russian roulette samples is
//   f = d * diffuse / pi + s * specular * (n + 2) / (2 pi) cos^n(alpha) + t * transmission * delta_refraction,
// so the sampled weight is the chosen lobe's colour and never needs scaling by d, s or t (the paper's
// remark). The two reflection lobes share one mixture pdf, which is what MIS with light sampling needs.
// Reflection is two-sided; refraction uses `ior` with the normal pointing to the outside.
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/materials/specular.h"
#include "candela/math/frame.h"
#include "candela/sampling/warp.h"

namespace candela {

struct PhongBsdf {
  // its transmission is an ideal (delta) refraction
  static constexpr BsdfFlags flags =
      BsdfFlags::Reflection | BsdfFlags::Transmission | BsdfFlags::Delta | BsdfFlags::NonDelta;
  RGB diffuse{0.5f};
  RGB specular{1.0f};
  float exponent = 32;
  RGB transmission{1.0f};
  float ior = 1.5f;
  float d = 1, s = 0, t = 0;

  // cos of the angle between wi and the mirror direction of wo.
  static float cos_alpha(const Vec3& wo, const Vec3& wi) { return dot(reflect_local(wo), wi); }

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    if (!same_hemisphere(wo, wi)) return RGB(0.0f);
    RGB f = diffuse * (d * kInvPi);
    float ca = cos_alpha(wo, wi);
    if (s > 0 && ca > 0) f += specular * (s * (exponent + 2) * kInv2Pi * std::pow(ca, exponent));
    return f;
  }
  float pdf(const Vec3& wo, const Vec3& wi) const {
    if (!same_hemisphere(wo, wi)) return 0;
    return d * abs_cos_theta(wi) * kInvPi + s * phong_lobe_pdf(cos_alpha(wo, wi), exponent);
  }
  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    // Russian roulette over the modes: diffuse, specular, transmission, absorption.
    Vec3 wi;
    if (u_lobe < d) {
      wi = square_to_cosine_hemisphere(u);
      if (wo.z < 0) wi.z = -wi.z;
    } else if (u_lobe < d + s) {
      Vec3 r = reflect_local(wo);
      Frame lobe(r);
      wi = lobe.to_world(square_to_phong_lobe(u, exponent));
      if (!same_hemisphere(wo, wi)) return std::nullopt;  // lobe dips below the surface: absorbed
    } else if (u_lobe < d + s + t) {
      Vec3 wt;
      float eta_rel;
      if (!refract_local(wo, ior, wt, eta_rel)) return BsdfSample{reflect_local(wo), transmission, t, true, 1};
      return BsdfSample{wt, transmission / (eta_rel * eta_rel), t, true, eta_rel};
    } else {
      return std::nullopt;
    }
    float p = pdf(wo, wi);
    if (p <= 0) return std::nullopt;
    return BsdfSample{wi, eval(wo, wi) * (abs_cos_theta(wi) / p), p, false, 1};
  }
  bool has_non_delta() const { return d > 0 || s > 0; }
  bool has_non_delta_transmission() const { return false; }
  float non_delta_probability(const Vec3& /*wo*/) const { return d + s; }
};

}  // namespace candela
