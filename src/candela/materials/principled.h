#pragma once
// Mitsuba 3's `principled` and `principledthin` BSDFs (after Burley's Disney BRDF, 2012, and its BSDF
// extension, 2015), following Mitsuba's definitions term by term so that renders agree with Mitsuba's.
//
// Conventions here: wo points to the viewer, wi to the light (Mitsuba calls them si.wi and wo), and
// eval() is f without the cosine (Mitsuba's eval returns f |cos theta_wi|). lerp(a, b, t) below is
// Mitsuba's a + t (b - a); F_w(c) = clamp(1 - c, 0, 1)^5 is the Schlick weight. wh is the half vector
// of the pair, turned to +z: normalize(wo + wi) for reflection, normalize(wo + eta_path wi) for
// refraction, with eta_path = eta seen from the front (wo.z > 0), 1 / eta from the back.
//
// principled (PrincipledBsdf). Lobe weights: w_diffuse = (1 - metallic)(1 - spec_trans),
// w_trans = (1 - metallic) spec_trans. D and G are anisotropic GGX with Mitsuba's *separable* Smith
// masking G1(wo, wh) G1(wi, wh) (not the height-correlated form of the other candela BSDFs);
// alpha_x = max(0.001, r^2 / aspect), alpha_y = max(0.001, r^2 aspect), aspect = sqrt(1 - 0.9 anisotropic).
//   specular reflection   F_p D G / (4 |cos_o cos_i|), where on the front side
//                           F_p = (1 - metallic)(1 - spec_tint) F_diel(wo.wh)
//                               + metallic Schlick(base_color) + (1 - metallic) spec_tint Schlick(tint R0(eta))
//                         and on the back side F_p = w_trans F_diel (no tint, no metal).
//                         Schlick(R0) = R0 + (1 - R0) F_w(c), with c = |wo.wh| where the light enters the
//                         denser side (eta_it > 1) and the refracted cosine otherwise; tint = base / luminance.
//   specular transmission sqrt(base_color) w_trans (1 - F_diel) D G |wo.wh wi.wh| /
//                           (|cos_o cos_i| (wo.wh + eta_path wi.wh)^2)            (radiance; Walter et al.)
//   clearcoat (front)     0.25 clearcoat Schlick_0.04 D_GTR1(wh) G1_0.25(wo) G1_0.25(wi), GTR1 alpha =
//                         lerp(0.1, 0.001, clearcoat_gloss), G1 of GGX with alpha 0.25. Exactly as Mitsuba:
//                         *without* the 1 / (4 cos_o cos_i) of a microfacet BRDF (Mitsuba's value carries
//                         only the cosine), so this lobe is much weaker than Burley's away from grazing.
//   diffuse (front)       w_diffuse base / pi lerp((1 - F_w(o)/2)(1 - F_w(i)/2) + f_retro, f_ss, flatness), with
//                         Rr = 2 roughness (wh.wi)^2, f_retro = Rr (F_o + F_i + F_o F_i (Rr - 1)) and
//                         f_ss = 1.25 (Fss (1 / (|cos_o| + |cos_i|) - 0.5) + 0.5),
//                         Fss = lerp(1, Rr / 2, F_o) lerp(1, Rr / 2, F_i)  (F_o, F_i: Schlick weights of the cosines)
//   sheen (front, only where w_diffuse > 0)  sheen (1 - metallic) F_w(|wh.wi|) lerp(1, tint, sheen_tint)
// The back side (wo.z < 0) has only the specular reflection and transmission, so it is black when
// w_trans = 0 (Mitsuba's principled is one-sided for opaque settings without a "twosided" wrapper).
// Sampling (Mitsuba's probabilities): a visible GGX normal m is drawn first; with F = F_diel(wo.m),
// on the front side the lobes diffuse : clearcoat : transmission : reflection are chosen in proportion
// to w_diffuse : clearcoat / 4 : w_trans (1 - F) : 1 - w_trans (1 - F) (the total does not depend on
// F); on the back side transmission : reflection = 1 - F : F. Diffuse samples the cosine, clearcoat the
// GTR1 normals (D cos); pdf() is the mixture density of all of them, and the weight is eval cos / pdf.
// Energy: not conserving in general (as Burley's model): the diffuse lobe is not reduced by the
// specular reflection, and its retro-reflection exceeds 1 at grazing angles for rough surfaces
// (white base, eta 1.5: albedo ~1.03-1.05 at normal incidence, 1.16-1.27 at 80 degrees; a white
// rough diffuse alone 1.28 at 80 degrees). Metals, full specular transmission and the thin sheet's
// specular pair stay below 1 (single scattering).
// The glTF metallic-roughness case (specular 0.5, i.e. eta = 1.5; the rest 0) evaluates only the
// diffuse and specular reflection terms, with no tint or clearcoat work.
//
// principledthin (PrincipledThinBsdf): a two-sided sheet with no refraction (eta only sets the Fresnel
// term); everything is evaluated mirrored to the side of wo. With dt = diff_trans / 2 (Mitsuba's
// diff_trans runs over [0, 2]) and wh = normalize(wo + (wi.x, wi.y, |wi.z|)):
//   specular reflection   spec_trans lerp(F_diel, Schlick(tint R0(eta)), spec_tint) D G / (4 |cos_o cos_i|)
//   specular transmission spec_trans base (1 - F_diel) D' G' / (4 |cos_o cos_i|), wi mirrored through the
//                         sheet; D', G' use roughness (0.65 eta - 0.35) roughness (Burley 2015, fig. 15)
//   diffuse reflection    (1 - spec_trans)(1 - dt) base / pi (Burley's diffuse, retro, fake subsurface as
//                         above) + sheen (1 - spec_trans)(1 - dt) F_w(|wh.wi|) lerp(1, tint, sheen_tint)
//   diffuse transmission  (1 - spec_trans) dt base / pi
// Note that the thin sheet's specular reflection is scaled by spec_trans (none when spec_trans = 0),
// as in Mitsuba. Lobe probabilities: spec_trans / 2, spec_trans / 2, (1 - spec_trans)(1 - dt),
// (1 - spec_trans) dt.
#include <algorithm>
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/materials/microfacet.h"
#include "candela/materials/specular.h"
#include "candela/sampling/warp.h"

namespace candela {

// The inputs of both models, as Mitsuba names them, evaluated at a hit.
struct PrincipledParams {
  RGB base_color{0.5f};
  float roughness = 0.5f;
  float anisotropic = 0;
  float metallic = 0;     // principled only
  float spec_tint = 0;
  float spec_trans = 0;
  float sheen = 0;
  float sheen_tint = 0;
  float clearcoat = 0;        // principled only
  float clearcoat_gloss = 0;  // principled only
  float flatness = 0;
  float eta = 1.5f;  // n_inside / n_outside (see principled_eta_from_specular)
  float diff_trans = 0;  // principledthin only, in [0, 2]
};

namespace principled_detail {

inline float lerp_to(float a, float b, float t) { return a + t * (b - a); }
inline RGB lerp_to(const RGB& a, const RGB& b, float t) { return a + (b - a) * t; }

// Scales lobe weights to sum to 1, the sum taken left to right in the order given.
template <class... Weights>
void scale_to_unit_sum(Weights&... w) {
  float inv_total = 1 / (... + w);
  ((w *= inv_total), ...);
}

inline float schlick_weight(float c) {
  float m = std::clamp(1 - c, 0.0f, 1.0f);
  return sqr(sqr(m)) * m;
}

// Mitsuba's luminance of a linear sRGB colour.
inline float luminance(const RGB& c) { return 0.212671f * c.r + 0.715160f * c.g + 0.072169f * c.b; }

// base_color normalised by its luminance (white where black): the tint of spec_tint and sheen_tint.
inline RGB tint_color(const RGB& base) {
  float lum = luminance(base);
  return lum > 0 ? base / lum : RGB(1.0f);
}

inline float schlick_r0(float eta) { return sqr((eta - 1) / (eta + 1)); }

// The Schlick weight Mitsuba's principled uses for a microfacet cosine cos_i (negative: the incident
// direction is on the inside): that of cos_i itself when the light goes into the denser side, else
// that of the refracted direction (0 under total internal reflection, so the weight is 1).
inline float fresnel_schlick_weight(float cos_i, float eta) {
  float eta_it = cos_i >= 0 ? eta : 1 / eta;
  if (eta_it > 1) return schlick_weight(std::abs(cos_i));
  float cos_t = safe_sqrt(1 - (1 - cos_i * cos_i) / sqr(eta_it));
  return schlick_weight(cos_t);
}
inline float fresnel_schlick(float r0, float cos_i, float eta) {
  return lerp_to(fresnel_schlick_weight(cos_i, eta), 1.0f, r0);
}
inline RGB fresnel_schlick(const RGB& r0, float cos_i, float eta) {
  float w = fresnel_schlick_weight(cos_i, eta);
  return r0.map([w](float c) { return lerp_to(w, 1.0f, c); });
}

// Smith masking with Mitsuba's orientation rule: zero where v sees the back of the facet m.
inline float smith_g1(const TrowbridgeReitz& d, const Vec3& v, const Vec3& m) {
  if (dot(v, m) * v.z <= 0) return 0;
  return d.G1(v);
}

// Burley's GTR1 ("Berry") distribution of the clearcoat, sampled by D cos (not by visible normals).
struct Gtr1 {
  float alpha = 0.1f;
  float D(const Vec3& m) const {
    float a2 = sqr(alpha);
    float d = (a2 - 1) / (kPi * std::log(a2) * (1 + (a2 - 1) * sqr(m.z)));
    return d * m.z > 1e-20f ? d : 0.0f;
  }
  float pdf(const Vec3& m) const { return m.z < 0 ? 0.0f : m.z * D(m); }
  Vec3 sample(Vec2 u) const {
    float a2 = sqr(alpha);
    float cos2 = (1 - std::pow(a2, 1 - u.y)) / (1 - a2);
    float sin_t = safe_sqrt(1 - cos2), cos_t = safe_sqrt(cos2);
    float phi = 2 * kPi * u.x;
    return {std::cos(phi) * sin_t, std::sin(phi) * sin_t, cos_t};
  }
};

// The fixed GGX masking of Mitsuba's clearcoat lobe.
inline TrowbridgeReitz clearcoat_masking() { return TrowbridgeReitz(0.25f, 0.25f); }

// Burley's diffuse with retro-reflection, blended towards the fake subsurface term by flatness:
// the factor that multiplies base / pi. c_o, c_i: |cos| of the two directions, cos_d = wh . wi.
inline float burley_diffuse(float c_o, float c_i, float cos_d, float roughness, float flatness) {
  float f_o = schlick_weight(c_o), f_i = schlick_weight(c_i);
  float f_diff = (1 - 0.5f * f_o) * (1 - 0.5f * f_i);
  float rr = 2 * roughness * sqr(cos_d);
  float f_retro = rr * (f_o + f_i + f_o * f_i * (rr - 1));
  float value = f_diff + f_retro;
  if (flatness > 0) {
    float fss90 = rr / 2;
    float fss = lerp_to(1.0f, fss90, f_o) * lerp_to(1.0f, fss90, f_i);
    float f_ss = 1.25f * (fss * (1 / (c_o + c_i) - 0.5f) + 0.5f);
    value = lerp_to(value, f_ss, flatness);
  }
  return value;
}

inline RGB sheen_color(const RGB& base, float sheen_tint) {
  return sheen_tint > 0 ? lerp_to(RGB(1.0f), tint_color(base), sheen_tint) : RGB(1.0f);
}

}  // namespace principled_detail

// Mitsuba's alphas from roughness and anisotropic (Disney course notes).
inline TrowbridgeReitz principled_distribution(float roughness, float anisotropic) {
  float r2 = sqr(roughness);
  float aspect = std::sqrt(std::max(0.0f, 1 - 0.9f * anisotropic));
  return TrowbridgeReitz(std::max(0.001f, r2 / aspect), std::max(0.001f, r2 * aspect));
}

// Mitsuba's "specular" parameter as a relative IOR: specular = 0.08 R0(eta) (0.5 <-> eta = 1.5).
inline float principled_eta_from_specular(float specular) {
  return 2 / (1 - std::sqrt(0.08f * specular)) - 1;
}

struct PrincipledBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Transmission | BsdfFlags::NonDelta |
                                     BsdfFlags::Refraction;
  RGB base_color{0.5f};
  float roughness = 0.5f;
  TrowbridgeReitz distribution = principled_distribution(0.5f, 0);
  float metallic = 0, spec_tint = 0, spec_trans = 0;
  float sheen = 0, sheen_tint = 0;
  float clearcoat = 0;
  principled_detail::Gtr1 clearcoat_distribution;
  float flatness = 0;
  float eta = 1.5f;

  PrincipledBsdf() = default;
  explicit PrincipledBsdf(const PrincipledParams& p)
      : base_color(p.base_color),
        roughness(p.roughness),
        distribution(principled_distribution(p.roughness, p.anisotropic)),
        metallic(p.metallic),
        spec_tint(p.spec_tint),
        spec_trans(p.spec_trans),
        sheen(p.sheen),
        sheen_tint(p.sheen_tint),
        clearcoat(p.clearcoat),
        clearcoat_distribution{principled_detail::lerp_to(0.1f, 0.001f, p.clearcoat_gloss)},
        flatness(p.flatness),
        eta(p.eta) {}

  float diffuse_weight() const { return (1 - metallic) * (1 - spec_trans); }
  float transmission_weight() const { return (1 - metallic) * spec_trans; }

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    using namespace principled_detail;
    Pair q;
    if (!setup(wo, wi, q)) return RGB(0.0f);
    float abs_cos_o = std::abs(wo.z), abs_cos_i = std::abs(wi.z);
    RGB f(0.0f);
    if (q.reflect) {
      if (q.compatible && q.F > 0) {
        float dg = distribution.D(q.wh) * smith_g1(distribution, wo, q.wh) * smith_g1(distribution, wi, q.wh) /
                   (4 * abs_cos_o * abs_cos_i);
        if (dg > 0) f += specular_fresnel(q) * dg;
      }
      if (!q.front) return f;
      if (clearcoat > 0 && q.compatible) {
        const TrowbridgeReitz m = clearcoat_masking();
        float fcc = fresnel_schlick(0.04f, q.cos_oh, eta);
        f += RGB(0.25f * clearcoat * fcc * clearcoat_distribution.D(q.wh) * smith_g1(m, wo, q.wh) *
                 smith_g1(m, wi, q.wh));
      }
      float w_diffuse = diffuse_weight();
      if (w_diffuse > 0) {
        float cos_d = dot(q.wh, wi);
        f += base_color * (w_diffuse * kInvPi * burley_diffuse(abs_cos_o, abs_cos_i, cos_d, roughness, flatness));
        if (sheen > 0)
          f += sheen_color(base_color, sheen_tint) * (sheen * (1 - metallic) * schlick_weight(std::abs(cos_d)));
      }
      return f;
    }
    float w_trans = transmission_weight();
    if (w_trans > 0 && q.compatible && q.F < 1) {
      float cos_ih = dot(wi, q.wh);
      float t = w_trans * (1 - q.F) * distribution.D(q.wh) * smith_g1(distribution, wo, q.wh) *
                smith_g1(distribution, wi, q.wh) * std::abs(q.cos_oh * cos_ih) /
                (abs_cos_o * abs_cos_i * sqr(q.cos_oh + q.eta_path * cos_ih));
      RGB tint = base_color.map([](float c) { return std::sqrt(c); });
      f = tint * t;
    }
    return f;
  }

  float pdf(const Vec3& wo, const Vec3& wi) const {
    Pair q;
    if (!setup(wo, wi, q)) return 0;
    return pdf(wo, wi, q);
  }

  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    if (wo.z == 0) return std::nullopt;
    bool front = wo.z > 0;
    if (!front && !(transmission_weight() > 0)) return std::nullopt;
    float s = front ? 1.0f : -1.0f;
    Vec3 m = distribution.sample_visible_normal(wo, u);
    Lobes p = lobes(front, fresnel_dielectric(dot(wo, m), eta));
    Vec3 wi;
    float etap = 1;
    if (u_lobe < p.diffuse) {
      wi = square_to_cosine_hemisphere(u);
      if (!(wi.z > 0)) return std::nullopt;
    } else if (u_lobe < p.diffuse + p.clearcoat) {
      Vec3 mc = clearcoat_distribution.sample(u);
      wi = reflect_about(wo, mc);
      if (!(wi.z > 0) || dot(wo, mc) <= 0 || dot(wi, mc) <= 0) return std::nullopt;
    } else if (u_lobe < p.diffuse + p.clearcoat + p.transmission) {
      if (!refract_about(wo, m, eta, wi, etap)) return std::nullopt;
      if (!(wi.z * wo.z < 0) || dot(wo, m) * s <= 0 || dot(wi, m) * s >= 0) return std::nullopt;
    } else {
      wi = reflect_about(wo, m);
      if (!(wi.z * wo.z > 0) || dot(wo, m) * s <= 0 || dot(wi, m) * s <= 0) return std::nullopt;
    }
    float density = pdf(wo, wi);
    if (!(density > 0)) return std::nullopt;
    RGB weight = eval(wo, wi) * (std::abs(wi.z) / density);
    return BsdfSample{wi, weight, density, false, wi.z * wo.z < 0 ? etap : 1.0f};
  }

  bool has_non_delta() const { return true; }
  bool has_non_delta_transmission() const { return transmission_weight() > 0; }
  float non_delta_probability(const Vec3& /*wo*/) const { return 1; }

 private:
  // What eval and pdf share about a pair (wo, wi).
  struct Pair {
    Vec3 wh;
    float cos_oh = 0, F = 0, eta_path = 1;
    bool front = true, reflect = true, compatible = false;
  };
  struct Lobes {
    float diffuse = 0, clearcoat = 0, transmission = 0, reflection = 0;
  };

  bool setup(const Vec3& wo, const Vec3& wi, Pair& q) const {
    if (wo.z == 0 || wi.z == 0) return false;
    q.front = wo.z > 0;
    if (!q.front && !(transmission_weight() > 0)) return false;  // the back of an opaque surface
    q.reflect = wo.z * wi.z > 0;
    q.eta_path = q.front ? eta : 1 / eta;
    Vec3 h = q.reflect ? wo + wi : wo + wi * q.eta_path;
    if (length_squared(h) == 0) return false;
    q.wh = normalize(h);
    if (q.wh.z < 0) q.wh = -q.wh;
    q.cos_oh = dot(wo, q.wh);
    float s = q.front ? 1.0f : -1.0f, cos_ih = dot(wi, q.wh);
    q.compatible = q.cos_oh * s > 0 && (q.reflect ? cos_ih * s > 0 : cos_ih * s < 0);
    q.F = fresnel_dielectric(q.cos_oh, eta);
    return true;
  }

  // Mitsuba's lobe-selection probabilities for a microfacet whose dielectric Fresnel is F.
  Lobes lobes(bool front, float F) const {
    Lobes p;
    if (front) {
      float w_trans = transmission_weight();
      p.diffuse = diffuse_weight();
      p.clearcoat = 0.25f * clearcoat;
      p.transmission = w_trans * (1 - F);
      p.reflection = 1 - w_trans * (1 - F);
    } else {
      p.transmission = 1 - F;
      p.reflection = F;
    }
    principled_detail::scale_to_unit_sum(p.diffuse, p.clearcoat, p.transmission, p.reflection);
    return p;
  }

  float pdf(const Vec3& wo, const Vec3& wi, const Pair& q) const {
    Lobes p = lobes(q.front, q.F);
    float cos_ih = dot(wi, q.wh);
    float result = 0;
    if (q.reflect) {
      if (q.compatible) {
        float dwh_dwi = 1 / (4 * std::abs(cos_ih));
        result += p.reflection * distribution.pdf(wo, q.wh) * dwh_dwi;
        if (p.clearcoat > 0) result += p.clearcoat * clearcoat_distribution.pdf(q.wh) * dwh_dwi;
      }
      result += p.diffuse * std::abs(wi.z) * kInvPi;
    } else if (q.compatible && p.transmission > 0) {
      float dwh_dwi = sqr(q.eta_path) * std::abs(cos_ih) / sqr(q.cos_oh + q.eta_path * cos_ih);
      result += p.transmission * distribution.pdf(wo, q.wh) * dwh_dwi;
    }
    return result;
  }

  // Mitsuba's principled Fresnel: the dielectric's, blended with Schlick's of the metal (base_color)
  // and of the tinted dielectric on the front side; the plain dielectric's, weighted, on the back.
  RGB specular_fresnel(const Pair& q) const {
    using namespace principled_detail;
    if (!q.front) return RGB(transmission_weight() * q.F);
    RGB f((1 - metallic) * (1 - spec_tint) * q.F);
    if (metallic > 0) f += fresnel_schlick(base_color, q.cos_oh, eta) * metallic;
    if (spec_tint > 0) {
      float eta_it = q.cos_oh >= 0 ? eta : 1 / eta;
      f += fresnel_schlick(tint_color(base_color) * schlick_r0(eta_it), q.cos_oh, eta) * ((1 - metallic) * spec_tint);
    }
    return f;
  }
};

struct PrincipledThinBsdf {
  // its transmission does not bend
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Transmission | BsdfFlags::NonDelta;
  RGB base_color{0.5f};
  float roughness = 0.5f;
  TrowbridgeReitz distribution = principled_distribution(0.5f, 0);
  TrowbridgeReitz transmission_distribution = principled_distribution((0.65f * 1.5f - 0.35f) * 0.5f, 0);
  float spec_tint = 0, spec_trans = 0;
  float sheen = 0, sheen_tint = 0;
  float flatness = 0;
  float eta = 1.5f;
  float diff_trans = 0;  // Mitsuba's diff_trans / 2, in [0, 1]

  PrincipledThinBsdf() = default;
  explicit PrincipledThinBsdf(const PrincipledParams& p)
      : base_color(p.base_color),
        roughness(p.roughness),
        distribution(principled_distribution(p.roughness, p.anisotropic)),
        transmission_distribution(principled_distribution((0.65f * p.eta - 0.35f) * p.roughness, p.anisotropic)),
        spec_tint(p.spec_tint),
        spec_trans(p.spec_trans),
        sheen(p.sheen),
        sheen_tint(p.sheen_tint),
        flatness(p.flatness),
        eta(p.eta),
        diff_trans(p.diff_trans / 2) {}

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    using namespace principled_detail;
    Pair q;
    if (!setup(wo, wi, q)) return RGB(0.0f);
    float cos_o = q.v.z, abs_cos_i = std::abs(q.l.z);
    RGB f(0.0f);
    if (spec_trans > 0) {
      float cos_oh = dot(q.v, q.wh);
      float F = fresnel_dielectric(cos_oh, eta);
      if (q.reflect && q.compatible) {
        float dg = distribution.D(q.wh) * smith_g1(distribution, q.v, q.wh) * smith_g1(distribution, q.l, q.wh);
        RGB Ft(F);
        if (spec_tint > 0)
          Ft = lerp_to(Ft, fresnel_schlick(tint_color(base_color) * schlick_r0(eta), cos_oh, eta), spec_tint);
        f += Ft * (spec_trans * dg / (4 * cos_o * abs_cos_i));
      } else if (!q.reflect && q.compatible) {
        const TrowbridgeReitz& d = transmission_distribution;
        float dg = d.D(q.wh) * smith_g1(d, q.v, q.wh) * smith_g1(d, q.l, q.wh);
        f += base_color * (spec_trans * (1 - F) * dg / (4 * cos_o * abs_cos_i));
      }
    }
    if (spec_trans < 1) {
      if (q.reflect && diff_trans < 1) {
        float w = (1 - spec_trans) * (1 - diff_trans);
        float cos_d = dot(q.wh, q.l);
        f += base_color * (w * kInvPi * burley_diffuse(cos_o, abs_cos_i, cos_d, roughness, flatness));
        if (sheen > 0) f += sheen_color(base_color, sheen_tint) * (sheen * w * schlick_weight(std::abs(cos_d)));
      } else if (!q.reflect && diff_trans > 0) {
        f += base_color * ((1 - spec_trans) * diff_trans * kInvPi);
      }
    }
    return f;
  }

  float pdf(const Vec3& wo, const Vec3& wi) const {
    Pair q;
    if (!setup(wo, wi, q)) return 0;
    Lobes p = lobes();
    float result = 0;
    if (q.compatible && spec_trans > 0) {
      float dwh_dwi = 1 / (4 * std::abs(dot(q.l_r, q.wh)));
      const TrowbridgeReitz& d = q.reflect ? distribution : transmission_distribution;
      result += (q.reflect ? p.reflection : p.transmission) * d.pdf(q.v, q.wh) * dwh_dwi;
    }
    result += (q.reflect ? p.diffuse_reflection : p.diffuse_transmission) * std::abs(q.l.z) * kInvPi;
    return result;
  }

  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    if (wo.z == 0) return std::nullopt;
    float s = wo.z > 0 ? 1.0f : -1.0f;
    Vec3 v = wo * s, l;
    Lobes p = lobes();
    if (u_lobe < p.reflection) {
      Vec3 m = distribution.sample_visible_normal(v, u);
      l = reflect_about(v, m);
      if (!(l.z > 0) || dot(v, m) <= 0 || dot(l, m) <= 0) return std::nullopt;
    } else if (u_lobe < p.reflection + p.transmission) {
      // No bending through the sheet: the reflection about the facet, mirrored to the other side.
      Vec3 m = transmission_distribution.sample_visible_normal(v, u);
      l = reflect_about(v, m);
      l.z = -l.z;
      if (!(l.z < 0) || dot(v, m) <= 0 || dot(l, m) >= 0) return std::nullopt;
    } else if (u_lobe < p.reflection + p.transmission + p.diffuse_reflection || !(p.diffuse_transmission > 0)) {
      l = square_to_cosine_hemisphere(u);
    } else {
      l = -square_to_cosine_hemisphere(u);
    }
    Vec3 wi = l * s;
    float density = pdf(wo, wi);
    if (!(density > 0)) return std::nullopt;
    return BsdfSample{wi, eval(wo, wi) * (std::abs(wi.z) / density), density, false, 1};
  }

  bool has_non_delta() const { return true; }
  bool has_non_delta_transmission() const { return spec_trans > 0 || diff_trans > 0; }
  float non_delta_probability(const Vec3& /*wo*/) const { return 1; }

 private:
  struct Pair {
    Vec3 v, l, l_r, wh;  // wo and wi mirrored to wo's side, wi reflected up, and their half vector
    bool reflect = true, compatible = false;
  };
  struct Lobes {
    float reflection = 0, transmission = 0, diffuse_reflection = 0, diffuse_transmission = 0;
  };

  bool setup(const Vec3& wo, const Vec3& wi, Pair& q) const {
    if (wo.z == 0 || wi.z == 0) return false;
    float s = wo.z > 0 ? 1.0f : -1.0f;
    q.v = wo * s;
    q.l = wi * s;
    q.reflect = q.l.z > 0;
    q.l_r = Vec3(q.l.x, q.l.y, std::abs(q.l.z));
    q.wh = normalize(q.v + q.l_r);
    float cos_lh = dot(q.l, q.wh);
    q.compatible = dot(q.v, q.wh) > 0 && (q.reflect ? cos_lh > 0 : cos_lh < 0);
    return true;
  }

  Lobes lobes() const {
    Lobes p;
    p.reflection = spec_trans / 2;
    p.transmission = spec_trans / 2;
    p.diffuse_reflection = (1 - spec_trans) * (1 - diff_trans);
    p.diffuse_transmission = (1 - spec_trans) * diff_trans;
    principled_detail::scale_to_unit_sum(p.reflection, p.transmission, p.diffuse_reflection, p.diffuse_transmission);
    return p;
  }
};

}  // namespace candela
