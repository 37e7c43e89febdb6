#pragma once
// Dielectric interfaces (glass, water), smooth or rough (pbrt-v4's DielectricBxDF).
//
// Smooth: reflects with the Fresnel probability F, else refracts (Snell); both are delta lobes.
// Radiance is scaled by 1 / eta^2 on refraction (it compresses into the smaller solid angle in the
// denser medium).
//
// Rough: the microfacet model of Walter et al. 2007 with the Trowbridge-Reitz distribution. A pair
// (wo, wi) is explained by the generalised half vector wm = normalize(eta' wi + wo) (eta' = 1 for
// reflection, else the relative IOR crossed), and
//   f_r = D(wm) G(wo, wi) F(wo . wm) / (4 |cos_o cos_i|)
//   f_t = D(wm) G(wo, wi) (1 - F) |wi . wm| |wo . wm| / (|cos_o cos_i| (wi . wm + wo . wm / eta')^2) / eta'^2.
// sample() draws a visible normal from wo and then reflects (probability F) or refracts about it;
// the pdfs are the visible-normal density times the Jacobians dwm/dwi of reflection,
// 1 / (4 |wo . wm|), and of refraction, |wi . wm| / (wi . wm + wo . wm / eta')^2.
//
// `ior` is n_inside / n_outside with "inside" below the normal (z < 0). `reflectance` and
// `transmittance` tint the two lobes (Mitsuba's specular_reflectance / specular_transmittance;
// 1 = physical); they do not change the sampling probabilities.
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/materials/microfacet.h"
#include "candela/materials/specular.h"

namespace candela {

struct DielectricBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Transmission | BsdfFlags::Delta |
                                     BsdfFlags::NonDelta | BsdfFlags::Refraction;
  float eta = 1.5f;
  RGB reflectance{1.0f};
  RGB transmittance{1.0f};
  Microfacet distribution;  // GGX or Beckmann
  // A thin sheet (Mitsuba's thindielectric): smooth, reflects with the probability of the sheet's
  // two faces and their internal reflections, else lets light through without bending it.
  bool thin = false;

  // An index-matched interface does not refract, whatever its roughness.
  bool is_smooth() const { return thin || eta == 1 || distribution.effectively_smooth(); }

  // The fraction a thin sheet lets straight through at incidence cos_theta: 1 - R', with
  // R' = R + T^2 R / (1 - R^2) summing the light reflected back and forth inside it.
  RGB thin_transmission(float cos_theta) const { return transmittance * (1 - thin_reflectance(cos_theta)); }

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    HalfVector h;
    if (is_smooth() || !half_vector(wo, wi, h)) return RGB(0.0f);
    const Microfacet& d = distribution;
    float F = fresnel_dielectric(dot(wo, h.wm), eta);
    if (h.reflect) return reflectance * (d.D(h.wm) * d.G(wo, wi) * F / std::abs(4 * wi.z * wo.z));
    float denom = sqr(dot(wi, h.wm) + dot(wo, h.wm) / h.etap) * wi.z * wo.z;
    float ft = d.D(h.wm) * (1 - F) * d.G(wo, wi) * std::abs(dot(wi, h.wm) * dot(wo, h.wm) / denom);
    return transmittance * (ft / sqr(h.etap));  // radiance scaling of camera paths
  }

  float pdf(const Vec3& wo, const Vec3& wi) const {
    HalfVector h;
    if (is_smooth() || !half_vector(wo, wi, h)) return 0;
    float R = fresnel_dielectric(dot(wo, h.wm), eta), T = 1 - R;
    if (h.reflect) return distribution.pdf(wo, h.wm) / (4 * abs_dot(wo, h.wm)) * R;
    float dwm_dwi = abs_dot(wi, h.wm) / sqr(dot(wi, h.wm) + dot(wo, h.wm) / h.etap);
    return distribution.pdf(wo, h.wm) * dwm_dwi * T;
  }

  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    if (thin) {
      float r = thin_reflectance(wo.z);
      if (u_lobe < r) return BsdfSample{reflect_local(wo), reflectance, r, true, 1};
      return BsdfSample{-wo, transmittance, 1 - r, true, 1, true};
    }
    if (is_smooth()) return sample_smooth(wo, u_lobe);
    if (wo.z == 0) return std::nullopt;
    const Microfacet& d = distribution;
    // Sample a microfacet normal visible from wo; then reflection or refraction about it, chosen
    // with the Fresnel probabilities of that facet.
    Vec3 wm = d.sample_visible_normal(wo, u);
    float R = fresnel_dielectric(dot(wo, wm), eta), T = 1 - R;
    if (u_lobe < R) {
      Vec3 wi = reflect_about(wo, wm);
      if (!same_hemisphere(wo, wi)) return std::nullopt;
      float p = d.pdf(wo, wm) / (4 * abs_dot(wo, wm)) * R;
      if (!(p > 0)) return std::nullopt;
      RGB f = reflectance * (d.D(wm) * d.G(wo, wi) * R / std::abs(4 * wi.z * wo.z));
      return BsdfSample{wi, f * (std::abs(wi.z) / p), p, false, 1};
    }
    Vec3 wi;
    float etap;
    if (!refract_about(wo, wm, eta, wi, etap) || same_hemisphere(wo, wi) || wi.z == 0) return std::nullopt;
    float denom = sqr(dot(wi, wm) + dot(wo, wm) / etap);
    float p = d.pdf(wo, wm) * abs_dot(wi, wm) / denom * T;
    if (!(p > 0)) return std::nullopt;
    float ft = d.D(wm) * T * d.G(wo, wi) * std::abs(dot(wi, wm) * dot(wo, wm) / (wi.z * wo.z * denom)) / sqr(etap);
    return BsdfSample{wi, transmittance * (ft * std::abs(wi.z) / p), p, false, etap};
  }

  bool has_non_delta() const { return !is_smooth(); }
  bool has_non_delta_transmission() const { return !is_smooth(); }
  float non_delta_probability(const Vec3& /*wo*/) const { return is_smooth() ? 0.0f : 1.0f; }

 private:
  float thin_reflectance(float cos_theta) const {
    float r = fresnel_dielectric(std::abs(cos_theta), eta);
    return r < 1 ? r + (1 - r) * (1 - r) * r / (1 - r * r) : 1.0f;
  }

  struct HalfVector {
    Vec3 wm;
    float etap = 1;
    bool reflect = true;
  };

  // The generalised half vector of (wo, wi), facing +z; false when no microfacet can explain the
  // pair (grazing directions, or a facet seen from its back by either direction).
  bool half_vector(const Vec3& wo, const Vec3& wi, HalfVector& h) const {
    float cos_o = wo.z, cos_i = wi.z;
    if (cos_o == 0 || cos_i == 0) return false;
    h.reflect = cos_o * cos_i > 0;
    h.etap = h.reflect ? 1.0f : (cos_o > 0 ? eta : 1 / eta);
    Vec3 wm = wi * h.etap + wo;
    if (length_squared(wm) == 0) return false;
    wm = face_forward(normalize(wm), Vec3(0, 0, 1));
    // Both directions must see the facet from the side they are on.
    if (dot(wm, wi) * cos_i < 0 || dot(wm, wo) * cos_o < 0) return false;
    h.wm = wm;
    return true;
  }

  // The perfectly smooth interface (identical to the former GlassBsdf).
  std::optional<BsdfSample> sample_smooth(const Vec3& wo, float u_lobe) const {
    float f = fresnel_dielectric(wo.z, eta);
    if (u_lobe < f) return BsdfSample{reflect_local(wo), reflectance, f, true, 1};
    Vec3 wt;
    float eta_rel;
    if (!refract_local(wo, eta, wt, eta_rel)) return BsdfSample{reflect_local(wo), reflectance, 1, true, 1};
    return BsdfSample{wt, transmittance / (eta_rel * eta_rel), 1 - f, true, eta_rel};
  }
};

}  // namespace candela
