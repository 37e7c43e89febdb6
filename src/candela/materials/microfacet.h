#pragma once
// Microfacet theory for the rough BSDFs (pbrt-v4 sec. 9.6): the anisotropic Trowbridge-Reitz (GGX)
// distribution of microfacet normals with the height-correlated Smith masking-shadowing function and
// Heitz's visible-normal sampling, the anisotropic Beckmann distribution as Mitsuba 3 defines it, the
// `Microfacet` choice between the two that the BSDFs hold, plus the Fresnel equations of conductors and the hemispherical
// average of dielectric Fresnel reflectance that the coated BSDFs need.
//
// All directions are in the local shading frame (macro-normal = +z); microfacet normals wm are in the
// upper hemisphere. alpha_x / alpha_y are the roughness along the frame's x (surface u) and y axes.
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include "candela/materials/bsdf_sample.h"
#include "candela/math/color.h"
#include "candela/math/vec.h"

namespace candela {

// Spherical-coordinate helpers of a unit direction in the local frame.
inline float cos2_theta(const Vec3& w) { return w.z * w.z; }
inline float sin2_theta(const Vec3& w) { return std::max(0.0f, 1 - cos2_theta(w)); }
inline float tan2_theta(const Vec3& w) { return sin2_theta(w) / cos2_theta(w); }
inline float cos_phi(const Vec3& w) {
  float sin_theta = std::sqrt(sin2_theta(w));
  return sin_theta == 0 ? 1.0f : std::clamp(w.x / sin_theta, -1.0f, 1.0f);
}
inline float sin_phi(const Vec3& w) {
  float sin_theta = std::sqrt(sin2_theta(w));
  return sin_theta == 0 ? 0.0f : std::clamp(w.y / sin_theta, -1.0f, 1.0f);
}

// Mirror reflection of w about the (unit) microfacet normal n: -w + 2 (w.n) n.
inline Vec3 reflect_about(const Vec3& w, const Vec3& n) { return -w + n * (2 * dot(w, n)); }

// Refraction of w (pointing away from the surface) through a facet with normal n, where eta is
// n_below / n_above relative to n. Works from either side of n; returns false on total internal
// reflection. etap receives the relative IOR actually crossed (eta, or 1/eta leaving "below").
inline bool refract_about(const Vec3& w, Vec3 n, float eta, Vec3& wt, float& etap) {
  float cos_i = dot(n, w);
  if (cos_i < 0) {  // w is on the far side of n: swap the media
    eta = 1 / eta;
    cos_i = -cos_i;
    n = -n;
  }
  float sin2_i = std::max(0.0f, 1 - cos_i * cos_i);
  float sin2_t = sin2_i / (eta * eta);
  if (sin2_t >= 1) return false;
  float cos_t = safe_sqrt(1 - sin2_t);
  wt = -w / eta + n * (cos_i / eta - cos_t);
  etap = eta;
  return true;
}

// How masking and shadowing combine: pbrt-v4's height-correlated form or Mitsuba's product of the two.
// What both distributions share, given their own D(wm) and Smith Lambda(w):
// Smith's masking from Lambda, 1 / (1 + Lambda(w)).
template <class Distribution>
float smith_G1(const Distribution& d, const Vec3& w) {
  return 1 / (1 + d.Lambda(w));
}
// The density of normals visible from w: D_w(wm) = G1(w) / |cos theta_w| D(wm) |w . wm|.
template <class Distribution>
float visible_normal_density(const Distribution& d, const Vec3& w, const Vec3& wm) {
  float cos_w = abs_cos_theta(w);
  if (cos_w == 0) return 0;
  return smith_G1(d, w) / cos_w * d.D(wm) * abs_dot(w, wm);
}
// w stretched into the configuration where the distribution is the isotropic alpha = 1 one, and
// turned into the upper hemisphere (visible-normal sampling of a w below the surface uses -w).
inline Vec3 stretched_to_unit_roughness(const Vec3& w, float alpha_x, float alpha_y) {
  Vec3 wh = normalize(Vec3(alpha_x * w.x, alpha_y * w.y, w.z));
  if (wh.z < 0) wh = -wh;
  return wh;
}

enum class MaskingShadowing { HeightCorrelated, Separable };

// The anisotropic Trowbridge-Reitz (GGX) microfacet distribution.
struct TrowbridgeReitz {
  float alpha_x = 0, alpha_y = 0;
  MaskingShadowing masking = MaskingShadowing::HeightCorrelated;

  TrowbridgeReitz() = default;
  TrowbridgeReitz(float ax, float ay, MaskingShadowing m = MaskingShadowing::HeightCorrelated)
      : alpha_x(ax), alpha_y(ay), masking(m) {
    // A rough surface must be a little rough along both axes: D divides by each alpha (pbrt-v4).
    if (!effectively_smooth()) {
      alpha_x = std::max(alpha_x, 1e-4f);
      alpha_y = std::max(alpha_y, 1e-4f);
    }
  }
  explicit TrowbridgeReitz(float alpha) : TrowbridgeReitz(alpha, alpha) {}

  // pbrt-v4's mapping from the user-facing "roughness" to alpha.
  static float roughness_to_alpha(float r) { return std::sqrt(r); }

  // Below this roughness the lobes are narrower than anything float sampling resolves: treat the
  // surface as a perfect (delta) interface, as pbrt-v4 does.
  bool effectively_smooth() const { return std::max(alpha_x, alpha_y) < 1e-3f; }

  // Distribution of microfacet normals D(wm), normalised so that the projected area is 1:
  // integral of D(wm) cos(theta_m) dwm = 1.
  float D(const Vec3& wm) const {
    float tan2 = tan2_theta(wm);
    if (std::isinf(tan2) || std::isnan(tan2)) return 0;
    float cos4 = sqr(cos2_theta(wm));
    if (cos4 < 1e-16f) return 0;
    float e = tan2 * (sqr(cos_phi(wm) / alpha_x) + sqr(sin_phi(wm) / alpha_y));
    return 1 / (kPi * alpha_x * alpha_y * cos4 * sqr(1 + e));
  }

  // Smith's auxiliary function: the masked microfacet area per visible area, for direction w.
  float Lambda(const Vec3& w) const {
    float tan2 = tan2_theta(w);
    if (std::isinf(tan2) || std::isnan(tan2)) return 0;
    // The roughness seen in w's azimuth.
    float alpha2 = sqr(cos_phi(w) * alpha_x) + sqr(sin_phi(w) * alpha_y);
    return (std::sqrt(1 + alpha2 * tan2) - 1) / 2;
  }

  // Masking: the fraction of microfacets visible from w.
  float G1(const Vec3& w) const { return smith_G1(*this, w); }

  // Masking-shadowing: the fraction of microfacets visible from both wo and wi.
  float G(const Vec3& wo, const Vec3& wi) const {
    if (masking == MaskingShadowing::Separable) return G1(wo) * G1(wi);
    return 1 / (1 + Lambda(wo) + Lambda(wi));
  }

  // Distribution of normals visible from w: D_w(wm) = G1(w) / |cos theta_w| D(wm) |w . wm|.
  float D(const Vec3& w, const Vec3& wm) const { return visible_normal_density(*this, w, wm); }

  // Density of sample_visible_normal(w, .) at wm.
  float pdf(const Vec3& w, const Vec3& wm) const { return D(w, wm); }

  // Samples a microfacet normal from D_w (Heitz 2018, "Sampling the GGX Distribution of Visible
  // Normals", in pbrt-v4's formulation). A w below the surface samples the normals visible from -w,
  // so the returned normal always lies in the upper hemisphere.
  Vec3 sample_visible_normal(const Vec3& w, Vec2 u) const {
    Vec3 wh = stretched_to_unit_roughness(w, alpha_x, alpha_y);
    // An orthonormal basis around wh (any one at normal incidence).
    Vec3 t1 = wh.z < 0.99999f ? normalize(cross(Vec3(0, 0, 1), wh)) : Vec3(1, 0, 0);
    Vec3 t2 = cross(wh, t1);
    // A uniform point on the unit disk, warped to the projection of the visible hemisphere: its
    // lower half is squeezed towards the projected horizon.
    float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
    Vec2 p(r * std::cos(phi), r * std::sin(phi));
    float h = safe_sqrt(1 - sqr(p.x));
    p.y = lerp((1 + wh.z) / 2, h, p.y);
    // Lift the point onto the hemisphere around wh, and unstretch the normal found there.
    float pz = safe_sqrt(1 - sqr(p.x) - sqr(p.y));
    Vec3 nh = t1 * p.x + t2 * p.y + wh * pz;
    return normalize(Vec3(alpha_x * nh.x, alpha_y * nh.y, std::max(1e-6f, nh.z)));
  }
};

// The inverse error function, in double: Giles' (2010) single-precision approximation refined by
// two Newton steps on erf, so it is accurate to double precision except within ~1e-15 of +-1.
inline double erfinv(double x) {
  if (!(x > -1)) return -std::numeric_limits<double>::infinity();
  if (!(x < 1)) return std::numeric_limits<double>::infinity();
  double w = -std::log((1 - x) * (1 + x)), p;
  if (w < 5) {
    w -= 2.5;
    p = 2.81022636e-08;
    p = 3.43273939e-07 + p * w;
    p = -3.5233877e-06 + p * w;
    p = -4.39150654e-06 + p * w;
    p = 0.00021858087 + p * w;
    p = -0.00125372503 + p * w;
    p = -0.00417768164 + p * w;
    p = 0.246640727 + p * w;
    p = 1.50140941 + p * w;
  } else {
    w = std::sqrt(w) - 3;
    p = -0.000200214257;
    p = 0.000100950558 + p * w;
    p = 0.00134934322 + p * w;
    p = -0.00367342844 + p * w;
    p = 0.00573950773 + p * w;
    p = -0.0076224613 + p * w;
    p = 0.00943887047 + p * w;
    p = 1.00167406 + p * w;
    p = 2.83297682 + p * w;
  }
  double y = p * x;
  constexpr double two_over_sqrt_pi = 1.1283791670955126;
  for (int i = 0; i < 2; ++i) {
    double d = two_over_sqrt_pi * std::exp(-y * y);
    if (!(d > 0)) break;
    y -= (std::erf(y) - x) / d;
  }
  return y;
}

// The anisotropic Beckmann distribution (Gaussian random slopes of RMS alpha_x, alpha_y), with
// Mitsuba 3's definitions: D as usual, Smith's masking G1 by Mitsuba's rational approximation of the
// exact erf form (relative error below 0.35%), and the *separable* masking-shadowing G1(wo) G1(wi).
// Visible normals are sampled exactly (Jakob 2014: the slope along the incident plane by a safeguarded
// Newton iteration on its CDF in the erf domain), so pdf() is the exact density of visible normals,
// D(wm) |w . wm| / (cos theta_w (1 + Lambda(w))) with the exact Lambda; visible_G1(w) = 1 / (1 + Lambda)
// is that normalisation. (The sampled weight f cos / pdf therefore carries G1_rational / G1_exact,
// within 0.35% of 1, where Mitsuba's carries 1; Mitsuba's own pdf uses the rational G1.)
struct Beckmann {
  float alpha_x = 0, alpha_y = 0;

  Beckmann() = default;
  Beckmann(float ax, float ay) : alpha_x(ax), alpha_y(ay) {
    if (!effectively_smooth()) {
      alpha_x = std::max(alpha_x, 1e-4f);
      alpha_y = std::max(alpha_y, 1e-4f);
    }
  }
  explicit Beckmann(float alpha) : Beckmann(alpha, alpha) {}

  bool effectively_smooth() const { return std::max(alpha_x, alpha_y) < 1e-3f; }

  float D(const Vec3& wm) const {
    float cos2 = cos2_theta(wm);
    if (!(cos2 > 0)) return 0;
    float e = (sqr(wm.x / alpha_x) + sqr(wm.y / alpha_y)) / cos2;
    float d = std::exp(-e) / (kPi * alpha_x * alpha_y * cos2 * cos2);
    return d * wm.z > 1e-20f ? d : 0.0f;
  }

  // 1 / (alpha tan theta) for w, alpha being the roughness in w's azimuth; infinite at normal incidence.
  double inv_slope(const Vec3& w) const {
    double xy = sqr(alpha_x * w.x) + sqr(alpha_y * w.y);
    if (xy == 0) return std::numeric_limits<double>::infinity();
    return std::abs(double(w.z)) / std::sqrt(xy);
  }

  // Smith's exact Lambda for Gaussian slopes: (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)).
  float Lambda(const Vec3& w) const {
    double a = inv_slope(w);
    if (std::isinf(a)) return 0;
    if (a == 0) return std::numeric_limits<float>::infinity();
    constexpr double inv_sqrt_pi = 0.5641895835477563;
    return float(std::max(0.0, -0.5 * std::erfc(a) + std::exp(-a * a) * inv_sqrt_pi / (2 * a)));
  }

  // Masking as Mitsuba computes it (its rational approximation).
  float G1(const Vec3& w) const {
    double a = inv_slope(w);
    if (a >= 1.6) return 1;
    float af = float(a);
    return (3.535f * af + 2.181f * af * af) / (1 + 2.276f * af + 2.577f * af * af);
  }
  float G(const Vec3& wo, const Vec3& wi) const { return G1(wo) * G1(wi); }

  // The exact normalisation of the visible-normal density.
  float visible_G1(const Vec3& w) const { return smith_G1(*this, w); }
  float D(const Vec3& w, const Vec3& wm) const { return visible_normal_density(*this, w, wm); }
  float pdf(const Vec3& w, const Vec3& wm) const { return D(w, wm); }

  Vec3 sample_visible_normal(const Vec3& w, Vec2 u) const {
    // Stretch to the alpha = 1 configuration; there, rotate w's azimuth onto +x.
    Vec3 wh = stretched_to_unit_roughness(w, alpha_x, alpha_y);
    float sin_t = std::sqrt(sin2_theta(wh));
    float cos_p = cos_phi(wh), sin_p = sin_phi(wh);
    double sx, sy;
    sample_unit_slopes(wh.z, sin_t, u, sx, sy);
    // Rotate back and unstretch the slopes; the normal of slope (x, y) is (-x, -y, 1).
    double mx = (cos_p * sx - sin_p * sy) * alpha_x, my = (sin_p * sx + cos_p * sy) * alpha_y;
    Vec3 m(float(-mx), float(-my), 1.0f);
    return normalize(m);
  }

  // Slopes of a visible normal for alpha = 1 and an incident direction (sin_t, 0, cos_t): the slope y
  // is Gaussian (variance 1/2), independent of x; x < cot(theta) has the density proportional to
  // exp(-x^2) (1 - x tan(theta)), whose CDF in the domain e = erf(x) is
  // (1 + e + tan(theta) exp(-x^2) / sqrt(pi)) / (1 + erf(cot) + tan(theta) exp(-cot^2) / sqrt(pi)).
  static void sample_unit_slopes(float cos_t, float sin_t, Vec2 u, double& sx, double& sy) {
    constexpr double inv_sqrt_pi = 0.5641895835477563;
    double u1 = std::clamp(double(u.x), 1e-9, 1 - 1e-9), u2 = std::clamp(double(u.y), 1e-9, 1 - 1e-9);
    sy = erfinv(2 * u2 - 1);
    if (sin_t <= 1e-7f * cos_t) {  // normal incidence: both slopes Gaussian
      sx = erfinv(2 * u1 - 1);
      return;
    }
    double tan_t = double(sin_t) / std::max(double(cos_t), 1e-12), cot_t = 1 / tan_t;
    double hi = std::erf(cot_t), lo = -1;
    double target = u1 * (1 + hi + inv_sqrt_pi * tan_t * std::exp(-cot_t * cot_t));
    // Start from the grazing-incidence solution, e = hi - (hi + 1) erf(sqrt(-log u1)).
    double e = hi - (hi + 1) * std::erf(std::sqrt(-std::log(u1)));
    for (int i = 0; i < 24; ++i) {
      double x = erfinv(e);
      double value = 1 + e + inv_sqrt_pi * tan_t * std::exp(-x * x) - target;
      if (std::abs(value) < 1e-12 * target) break;
      if (value > 0) hi = e;
      else lo = e;
      double derivative = 1 - x * tan_t;
      double next = derivative > 0 ? e - value / derivative : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      e = next;
    }
    sx = erfinv(std::clamp(e, -1 + 1e-15, 1 - 1e-15));
  }
};

// The microfacet distribution of a rough BSDF: Trowbridge-Reitz (GGX) or Beckmann, dispatched by a
// two-way branch (no virtual calls). Implicitly made from either distribution.
class Microfacet {
 public:
  Microfacet() = default;
  Microfacet(const TrowbridgeReitz& d) : ggx_(d) {}  // NOLINT: implicit on purpose
  Microfacet(const Beckmann& d) : ggx_(d.alpha_x, d.alpha_y), beckmann_(true) {  // NOLINT
    ggx_.alpha_x = d.alpha_x;  // keep the alphas exactly (no GGX clamping differences)
    ggx_.alpha_y = d.alpha_y;
  }

  bool is_beckmann() const { return beckmann_; }
  float alpha_x() const { return ggx_.alpha_x; }
  float alpha_y() const { return ggx_.alpha_y; }
  bool effectively_smooth() const { return ggx_.effectively_smooth(); }

  float D(const Vec3& wm) const { return beckmann_ ? beck().D(wm) : ggx_.D(wm); }
  float G1(const Vec3& w) const { return beckmann_ ? beck().G1(w) : ggx_.G1(w); }
  float G(const Vec3& wo, const Vec3& wi) const { return beckmann_ ? beck().G(wo, wi) : ggx_.G(wo, wi); }
  // The normalisation of the visible-normal density (equal to G1 for GGX).
  float visible_G1(const Vec3& w) const { return beckmann_ ? beck().visible_G1(w) : ggx_.G1(w); }
  float D(const Vec3& w, const Vec3& wm) const { return beckmann_ ? beck().D(w, wm) : ggx_.D(w, wm); }
  float pdf(const Vec3& w, const Vec3& wm) const { return beckmann_ ? beck().pdf(w, wm) : ggx_.pdf(w, wm); }
  Vec3 sample_visible_normal(const Vec3& w, Vec2 u) const {
    return beckmann_ ? beck().sample_visible_normal(w, u) : ggx_.sample_visible_normal(w, u);
  }

 private:
  Beckmann beck() const {
    Beckmann b;
    b.alpha_x = ggx_.alpha_x;
    b.alpha_y = ggx_.alpha_y;
    return b;
  }
  TrowbridgeReitz ggx_;  // holds the alphas of either distribution
  bool beckmann_ = false;
};

// Fresnel reflectance of a conductor with complex relative index of refraction eta + i k, for
// unpolarised light: what pbrt-v4's FrComplex computes with complex arithmetic (Snell's law and
// the Fresnel equations with eta + i k), here in the equivalent real form (pbrt-v3's FrConductor;
// derivation in Born & Wolf): with a^2 + b^2 = |(eta + i k)^2 - sin^2(theta_i)|,
//   R_s = ((a^2 + b^2) + cos^2 - 2 a cos) / ((a^2 + b^2) + cos^2 + 2 a cos),
//   R_p = R_s ((a^2 + b^2) cos^2 + sin^4 - 2 a cos sin^2) / ((a^2 + b^2) cos^2 + sin^4 + 2 a cos sin^2).
// It avoids complex division, which is several times slower. The test checks it against the complex form.
inline float fresnel_complex(float cos_i, std::complex<float> eta_c) {
  float eta = eta_c.real(), k = eta_c.imag();
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  float cos2 = cos_i * cos_i, sin2 = 1 - cos2;
  float t0 = eta * eta - k * k - sin2;
  float a2_plus_b2 = std::sqrt(t0 * t0 + 4 * eta * eta * k * k);
  float a = safe_sqrt(0.5f * (a2_plus_b2 + t0));
  float t1 = a2_plus_b2 + cos2, t2 = 2 * cos_i * a;
  float r_s = (t1 - t2) / (t1 + t2);
  float t3 = cos2 * a2_plus_b2 + sin2 * sin2, t4 = t2 * sin2;
  float r_p = t3 + t4 > 0 ? r_s * (t3 - t4) / (t3 + t4) : r_s;
  return (r_s + r_p) / 2;
}

// Per lane.
inline RGB fresnel_complex(float cos_i, const RGB& eta, const RGB& k) {
  return RGB::from_lanes([&](int c) { return fresnel_complex(cos_i, std::complex<float>(eta[c], k[c])); });
}

// pbrt-v4's "artist" conductor parametrisation: with eta = 1, the absorption coefficient
// k = 2 sqrt(r) / sqrt(1 - r) gives normal-incidence reflectance exactly r. r is clamped below 1,
// where k would be infinite.
inline RGB conductor_k_from_reflectance(const RGB& r) {
  return r.map([](float v) {
    float rc = std::clamp(v, 0.0f, 0.9999f);
    return 2 * std::sqrt(rc) / std::sqrt(1 - rc);
  });
}

// The cosine-weighted hemispherical average of the dielectric Fresnel reflectance,
// 2 * integral_0^1 F(mu, eta) mu dmu, for light arriving from the outside (eta = n_inside / n_outside):
// the fraction of diffuse light the interface reflects. For eta > 1 the integral has a closed form
// (Stern 1964; see d'Eon, "A Hitchhiker's Guide to Multiple Scattering"); for eta < 1 the
// hemispherical transmittances on the two sides are related by T(eta) = eta^2 T(1 / eta)
// (reciprocity with the n^2 radiance scaling). Evaluated in double: the closed form cancels badly
// near eta = 1.
inline float fresnel_diffuse_reflectance(float eta) {
  if (!(eta > 0)) return 0;
  if (std::abs(eta - 1) < 1e-4f) return 0;  // index-matched: below 2.5e-4 either way
  if (eta < 1) return float(1 - double(eta) * eta * (1 - fresnel_diffuse_reflectance(1 / eta)));
  double n = eta, n2 = n * n, n4 = n2 * n2;
  double f = 0.5 + (n - 1) * (3 * n + 1) / (6 * (n + 1) * (n + 1))
             + n2 * (n2 - 1) * (n2 - 1) / ((n2 + 1) * (n2 + 1) * (n2 + 1)) * std::log((n - 1) / (n + 1)) -
             2 * n2 * n * (n2 + 2 * n - 1) / ((n2 + 1) * (n4 - 1)) +
             8 * n4 * (n4 + 1) / ((n2 + 1) * (n4 - 1) * (n4 - 1)) * std::log(n);
  return float(std::clamp(f, 0.0, 1.0));
}

}  // namespace candela
