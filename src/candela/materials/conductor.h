#pragma once
// Metals (pbrt-v4's ConductorBxDF): Fresnel reflection with a complex index of refraction eta + i k
// per RGB channel. A smooth surface is a delta mirror weighted by the Fresnel reflectance; a rough
// one is the Torrance-Sparrow microfacet BRDF
//   f(wo, wi) = D(wm) F(wo . wm) G(wo, wi) / (4 cos(theta_o) cos(theta_i)),   wm = normalize(wo + wi),
// importance-sampled through the distribution of visible normals, which gives the weight
// f cos(theta_i) / pdf = F G(wo, wi) / G1(wo) (G1: the visible-normal normalisation). D is GGX or
// Beckmann (microfacet.h). Single scattering only: the energy that would
// scatter between microfacets several times is lost (noticeable at high roughness).
// Two-sided: a wo below the surface is handled by mirroring the problem to the upper side.
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/materials/microfacet.h"
#include "candela/materials/specular.h"

namespace candela {

struct ConductorBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Delta | BsdfFlags::NonDelta;
  // Complex index of refraction eta + i k relative to the outside medium; copper by default (as
  // ConductorMaterial). pbrt-v4's artist mode: eta = 1, k = conductor_k_from_reflectance(r).
  RGB eta{0.200438f, 0.924033f, 1.102212f}, k{3.912949f, 2.452848f, 2.142188f};
  RGB tint{1.0f};          // multiplies the reflection (Mitsuba's specular_reflectance); 1 = physical
  Microfacet distribution;  // GGX or Beckmann

  RGB eval(Vec3 wo, Vec3 wi) const {
    if (distribution.effectively_smooth() || !same_hemisphere(wo, wi)) return RGB(0.0f);
    if (wo.z < 0) {
      wo.z = -wo.z;
      wi.z = -wi.z;
    }
    // The half vector is the microfacet normal that reflects wo into wi.
    Vec3 wm = wo + wi;
    if (length_squared(wm) == 0) return RGB(0.0f);
    wm = normalize(wm);
    RGB F = fresnel_complex(dot(wo, wm), eta, k);
    float s = distribution.D(wm) * distribution.G(wo, wi) / (4 * wo.z * wi.z);
    return tint * F * s;
  }

  float pdf(Vec3 wo, Vec3 wi) const {
    if (distribution.effectively_smooth() || !same_hemisphere(wo, wi)) return 0;
    if (wo.z < 0) {
      wo.z = -wo.z;
      wi.z = -wi.z;
    }
    Vec3 wm = wo + wi;
    if (length_squared(wm) == 0) return 0;
    wm = normalize(wm);
    // Visible-normal density times the Jacobian of reflection, dwm / dwi = 1 / (4 |wo . wm|).
    return distribution.pdf(wo, wm) / (4 * abs_dot(wo, wm));
  }

  std::optional<BsdfSample> sample(Vec3 wo, float /*u_lobe*/, Vec2 u) const {
    if (wo.z == 0) return std::nullopt;
    if (distribution.effectively_smooth()) {
      // Perfect mirror: the delta lobe carries the Fresnel reflectance.
      Vec3 wi = reflect_local(wo);
      return BsdfSample{wi, tint * fresnel_complex(std::abs(wo.z), eta, k), 1, true, 1};
    }
    bool flipped = wo.z < 0;
    if (flipped) wo.z = -wo.z;
    // Sample a visible microfacet normal and reflect about it.
    Vec3 wm = distribution.sample_visible_normal(wo, u);
    Vec3 wi = reflect_about(wo, wm);
    if (wi.z <= 0) return std::nullopt;  // reflected below the surface: masked, the path ends
    float p = distribution.pdf(wo, wm) / (4 * abs_dot(wo, wm));
    if (!(p > 0)) return std::nullopt;
    RGB F = fresnel_complex(dot(wo, wm), eta, k);
    RGB weight = tint * F * (distribution.G(wo, wi) / distribution.visible_G1(wo));
    if (flipped) wi.z = -wi.z;
    return BsdfSample{wi, weight, p, false, 1};
  }

  bool has_non_delta() const { return !distribution.effectively_smooth(); }
  bool has_non_delta_transmission() const { return false; }
  float non_delta_probability(const Vec3& /*wo*/) const { return has_non_delta() ? 1.0f : 0.0f; }
};

}  // namespace candela
