#pragma once
// Coated diffuse ("plastic"): a dielectric coat of relative index `eta` over a Lambertian base of
// albedo R, after Mitsuba 3's `plastic` (smooth coat) and `roughplastic` (GGX coat), which follow
// Weidlich and Wilkie's layered model.
//
// Specular lobe: the coat's own reflection. Smooth: a delta mirror carrying the Fresnel reflectance
// F(wo); rough: the Torrance-Sparrow BRDF D(wm) F(wo . wm) G(wo, wi) / (4 cos_o cos_i).
//
// Diffuse lobe: light refracts into the coat with probability 1 - F(wi), scatters at the base, and
// bounces between base and coat; the part reflected back at the coat from inside is the diffuse
// Fresnel reflectance Fdr of the inside (fresnel_diffuse_reflectance(1 / eta)). Summing the series of
// internal bounces gives
//   f_d = R (1 - F(wi)) (1 - F(wo)) / (pi eta^2 (1 - Fdr R))      (nonlinear = true)
// where 1 / eta^2 converts radiance across the interface. With nonlinear = false (the default, as in
// Mitsuba) the denominator is 1 - Fdr instead, which keeps the material's colour equal to R
// (no saturation shift from the internal bounces); both are energy-conserving for R <= 1, and for
// the smooth coat with R = 1 the total albedo is exactly 1 (since 1 - Fdr_ext = eta^2 (1 - Fdr_int)).
//
// Rough coat transmittance. Mitsuba 3's roughplastic does not use the smooth Fresnel here: for the
// (1 - F) factors it precomputes a table of 1 - (directional albedo of the rough interface), and a
// rough internal reflectance, by numerical integration whenever alpha or eta change. Here BSDFs are
// built per hit from possibly textured (and anisotropic) roughness, so a table per BSDF would cost
// far more than the shading itself. We use the smooth-interface Fresnel at the macro-normal,
// 1 - F(cos theta), and the smooth Fdr for both coats instead: exact in the smooth limit, reciprocal,
// and cheap. The price: where a slightly rough coat reflects a little more than a smooth one
// (alpha ~ 0.02-0.1, 40-60 degrees) the albedo of a perfectly white base (R = 1) exceeds 1 by up
// to ~7e-4 (measured for eta 1.33-2.5); at higher roughness or grazing angles the rough coat
// reflects less than F and the model loses energy (single scattering, like every microfacet BSDF here).
// Materials with a constant roughness can instead ask for Mitsuba's tables (`coat_table`, built
// once per material by rough_coat.h): then 1 - F(cos) becomes the tabulated rough transmittance
// and Fdr the tabulated internal reflectance, in the diffuse lobe and in the lobe selection alike.
//
// Lobe selection (Mitsuba): with s = mean(specular) / (mean(specular) + mean(R)), the specular lobe
// is sampled with probability proportional to F(wo) s and the diffuse one proportional to
// (1 - F(wo)) (1 - s). The diffuse (non-delta) lobe comes first in u_lobe, as the BSDF contract asks.
//
// Two-sided: a wo below the surface is handled by mirroring the problem to the upper side (as
// pbrt-v4's coated materials do by default); wi on the other side than wo gives zero.
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/materials/microfacet.h"
#include "candela/materials/rough_coat.h"
#include "candela/materials/specular.h"
#include "candela/sampling/warp.h"

namespace candela {

struct CoatedDiffuseBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Delta | BsdfFlags::NonDelta;
  RGB reflectance{0.5f};  // the diffuse base
  RGB specular{1.0f};     // tints the coat's reflection; 1 = physical
  float eta = 1.5f;       // n_coat / n_outside
  Microfacet distribution;  // GGX or Beckmann
  bool nonlinear = false;
  const RoughCoatTable* coat_table = nullptr;  // Mitsuba's tabulated rough coat; null: smooth Fresnel

  RGB eval(Vec3 wo, Vec3 wi) const {
    if (!same_hemisphere(wo, wi)) return RGB(0.0f);
    mirror_to_upper(wo, wi);
    RGB f = diffuse(wo, wi);
    if (!distribution.effectively_smooth()) f += glossy(wo, wi);
    return f;
  }

  float pdf(Vec3 wo, Vec3 wi) const {
    if (!same_hemisphere(wo, wi)) return 0;
    mirror_to_upper(wo, wi);
    float p_diffuse = diffuse_probability(wo);
    float p = p_diffuse * cosine_hemisphere_pdf(wi);
    if (!distribution.effectively_smooth()) p += (1 - p_diffuse) * glossy_pdf(wo, wi);
    return p;
  }

  std::optional<BsdfSample> sample(Vec3 wo, float u_lobe, Vec2 u) const {
    if (wo.z == 0) return std::nullopt;
    bool flipped = wo.z < 0;
    if (flipped) wo.z = -wo.z;
    float p_diffuse = diffuse_probability(wo);
    bool smooth = distribution.effectively_smooth();
    Vec3 wi;
    if (u_lobe < p_diffuse) {
      wi = square_to_cosine_hemisphere(u);
    } else if (smooth) {
      // The coat's mirror reflection: a delta lobe chosen with probability 1 - p_diffuse.
      float p_specular = 1 - p_diffuse;
      if (!(p_specular > 0)) return std::nullopt;
      wi = reflect_local(wo);
      RGB weight = specular * (fresnel_dielectric(wo.z, eta) / p_specular);
      if (flipped) wi.z = -wi.z;
      return BsdfSample{wi, weight, p_specular, true, 1};
    } else {
      Vec3 wm = distribution.sample_visible_normal(wo, u);
      wi = reflect_about(wo, wm);
      if (wi.z <= 0) return std::nullopt;
    }
    // Non-delta sample: the mixture pdf of all non-delta lobes, so the weight is unbiased whichever
    // lobe produced wi.
    float p = p_diffuse * cosine_hemisphere_pdf(wi);
    if (!smooth) p += (1 - p_diffuse) * glossy_pdf(wo, wi);
    if (!(p > 0)) return std::nullopt;
    RGB f = diffuse(wo, wi);
    if (!smooth) f += glossy(wo, wi);
    RGB weight = f * (wi.z / p);
    if (flipped) wi.z = -wi.z;
    return BsdfSample{wi, weight, p, false, 1};
  }

  bool has_non_delta() const { return !distribution.effectively_smooth() || reflectance.max_component() > 0; }
  bool has_non_delta_transmission() const { return false; }
  float non_delta_probability(Vec3 wo) const {
    if (!distribution.effectively_smooth()) return 1;
    wo.z = std::abs(wo.z);
    return diffuse_probability(wo);
  }

  // Probability of sampling the diffuse lobe for wo (upper hemisphere): Mitsuba's weighting of the
  // lobes by their Fresnel share and their mean albedo.
  float diffuse_probability(const Vec3& wo) const {
    float s_mean = specular.average(), d_mean = reflectance.average();
    if (!(s_mean + d_mean > 0)) return 1;
    float s = s_mean / (s_mean + d_mean);
    float t = coat_transmittance(wo.z);
    float p_specular = (1 - t) * s, p_diffuse = t * (1 - s);
    if (!(p_specular + p_diffuse > 0)) return 1;
    return p_diffuse / (p_specular + p_diffuse);
  }

 private:
  static void mirror_to_upper(Vec3& wo, Vec3& wi) {
    if (wo.z < 0) {
      wo.z = -wo.z;
      wi.z = -wi.z;
    }
  }

  // The fraction of light the coat lets through from the outside at cos theta (upper hemisphere).
  float coat_transmittance(float cos_theta) const {
    return coat_table ? coat_table->transmittance_at(cos_theta) : 1 - fresnel_dielectric(cos_theta, eta);
  }

  // The diffuse lobe for wo, wi in the upper hemisphere.
  RGB diffuse(const Vec3& wo, const Vec3& wi) const {
    // Inside the coat, looking out.
    float fdr = coat_table ? coat_table->internal_reflectance : fresnel_diffuse_reflectance(1 / eta);
    RGB R = reflectance;
    RGB denom = nonlinear ? RGB(1.0f) - R * fdr : RGB(1 - fdr);
    float t = coat_transmittance(wo.z) * coat_transmittance(wi.z);
    float s = t * kInvPi / (eta * eta);
    return RGB::from_lanes([&](int c) { return denom[c] > 0 ? R[c] * s / denom[c] : 0.0f; });
  }

  // The rough coat's reflection, wo and wi in the upper hemisphere.
  RGB glossy(const Vec3& wo, const Vec3& wi) const {
    Vec3 wm = wo + wi;
    if (length_squared(wm) == 0) return RGB(0.0f);
    wm = normalize(wm);
    float F = fresnel_dielectric(dot(wo, wm), eta);
    return specular * (distribution.D(wm) * F * distribution.G(wo, wi) / (4 * wo.z * wi.z));
  }

  float glossy_pdf(const Vec3& wo, const Vec3& wi) const {
    Vec3 wm = wo + wi;
    if (length_squared(wm) == 0) return 0;
    wm = normalize(wm);
    return distribution.pdf(wo, wm) / (4 * abs_dot(wo, wm));
  }
};

}  // namespace candela
