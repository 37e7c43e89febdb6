#pragma once
// Hair and fur (pbrt-v4's HairBxDF): the scattering of a rough dielectric cylinder with an absorbing
// interior, after d'Eon et al. ("An Energy-Conserving Hair Reflectance Model", 2011) and Chiang et
// al. ("A Practical and Controllable Hair and Fur Model for Production Path Tracing", 2016).
//
// The local frame is the shading frame of a fibre: x along the fibre (the hit's dp/du, the curve's
// tangent), z the shading normal, y = z x x. A direction w has the longitudinal angle theta with
// sin(theta) = w.x and the azimuth phi = atan2(w.z, w.y) about the fibre. Light leaving towards wo
// hit the fibre's cross-section at the offset h in [-1, 1] (the material reads h = -1 + 2 v from the
// hit's uv, pbrt-v4's convention for curves); gamma_o = asin(h).
//
// Light leaves after p internal paths: R (p = 0, reflected at the surface), TT (p = 1, through the
// fibre), TRT (p = 2) and everything after (p = 3, a single term). Each is
//   M_p(theta_o, theta_i) A_p(theta_o, h) N_p(phi; h)
// with
//   M_p  the longitudinal scattering of d'Eon et al.: the theta marginal of a von Mises-Fisher
//        lobe of variance v_p around the mirror direction -theta_o (tilted by the cuticle's scales:
//        -2 alpha for R, alpha for TT, 4 alpha for TRT), normalised in closed form with I0, the
//        modified Bessel function of the first kind, which is evaluated through its logarithm so
//        that narrow lobes (v_p down to about 1e-5) neither overflow nor lose precision;
//        v_0 = (0.726 beta_m + 0.812 beta_m^2 + 3.7 beta_m^20)^2, v_1 = v_0 / 4, v_2 = v_3 = 4 v_0;
//   A_p  the attenuation: Fresnel at cos(theta_o) cos(gamma_o) for index eta, and the transmittance
//        T = exp(-sigma_a 2 cos(gamma_t) / cos(theta_t)) of one crossing of the refracted path
//        (sigma_a per unit of the fibre's radius); A_0 = F, A_1 = (1 - F)^2 T, A_2 = A_1 T F,
//        A_3 = A_2 F T / (1 - T F) (the rest of the geometric series);
//   N_p  the azimuthal scattering: a logistic of scale s = sqrt(pi / 8) (0.265 beta_n + 1.194 beta_n^2
//        + 5.372 beta_n^22), trimmed to [-pi, pi], around the smooth cylinder's exit azimuth
//        Phi(p) = 2 p gamma_t - 2 gamma_o + p pi; N_3 = 1 / (2 pi).
// As pbrt-v4's HairBxDF, eval() is that sum divided by |cos| of wi to the shading normal, so that the
// integrator's cosine cancels: f |cos| is the fibre's scattering function. With sigma_a = 0 the
// A_p sum to 1 and each M_p and N_p is normalised, so f |cos| integrates to exactly 1 over the
// sphere for every wo and h (the white furnace).
//
// sample() chooses p with probability A_p / sum A_p (their means over the lanes that carry values:
// three colour channels, or a spectral sample's four wavelengths), samples M_p's von Mises-Fisher
// lobe and N_p's logistic exactly, and reports the density of the whole mixture (pdf()), which is
// therefore also what a light sample is weighted with. Light scatters to both sides of the shading
// normal (the fibre is seen from all around): the non-delta part "transmits" in the sense of the
// BSDF contract. Not reciprocal (A_p and gamma_t depend on wo only), as pbrt-v4's is not: paths that
// carry importance evaluate it with the directions swapped (BsdfFlags::NonReciprocal), where pbrt-v4
// uses f(wo, wi) for both.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "candela/materials/bsdf_sample.h"
#include "candela/materials/specular.h"

namespace candela {

namespace hair_detail {

inline constexpr int kPMax = 3;
inline constexpr double kTwoPi = 6.283185307179586;

// log I0(x), I0 the modified Bessel function of the first kind of order 0: the power series below
// 15, the asymptotic expansion e^x / sqrt(2 pi x) (1 + 1/(8x) + 9/(2 (8x)^2) + ...) above (its
// relative error there is below 1e-6).
inline double log_i0(double x) {
  x = std::abs(x);
  if (x <= 15) {
    const double q = x * x / 4;
    double term = 1, sum = 1;
    for (int k = 1; k < 200 && term > 1e-17 * sum; ++k) {
      term *= q / (double(k) * k);
      sum += term;
    }
    return std::log(sum);
  }
  const double y = 1 / (8 * x);
  return x - 0.5 * std::log(kTwoPi * x) +
         std::log(1 + y * (1 + y * (9.0 / 2 + y * (225.0 / 6 + y * (11025.0 / 24)))));
}

// d'Eon et al.'s longitudinal scattering: the density over theta_i (with respect to
// cos(theta_i) dtheta_i) of the lobe of variance v around -theta_o,
//   M = exp(-sin_i sin_o / v) I0(cos_i cos_o / v) / (2 v sinh(1 / v)),
// in logarithms throughout: log(2 v sinh(1/v)) = 1/v + rest, rest = log v + log(1 - exp(-2/v))
// (small where 1/v is large, so that it keeps its precision in a float).
inline float longitudinal_log_norm_rest(double v) { return float(std::log(v) + std::log1p(-std::exp(-2 / v))); }
inline double longitudinal(float cos_i, float cos_o, float sin_i, float sin_o, float v, float rest) {
  const double a = double(cos_i) * cos_o / v, b = double(sin_i) * sin_o / v;
  return std::exp(log_i0(a) - b - 1 / double(v) - rest);
}

// The logistic distribution of scale s, its CDF, and the logistic trimmed to [-pi, pi].
inline double logistic(double x, double s) {
  const double e = std::exp(-std::abs(x) / s);
  return e / (s * (1 + e) * (1 + e));
}
inline double logistic_cdf(double x, double s) { return 1 / (1 + std::exp(-x / s)); }
inline double trimmed_logistic(double x, double s) {
  return logistic(x, s) / (logistic_cdf(kPi, s) - logistic_cdf(-kPi, s));
}
// The inverse of the trimmed logistic's CDF at u.
inline double sample_trimmed_logistic(double u, double s) {
  const double lo = logistic_cdf(-kPi, s), k = logistic_cdf(kPi, s) - lo;
  const double y = u * k + lo;
  const double x = -s * std::log(1 / y - 1);
  return std::clamp(x, -double(kPi), double(kPi));
}

// The smooth cylinder's exit azimuth of path p.
inline double exit_azimuth(int p, double gamma_o, double gamma_t) { return 2 * p * gamma_t - 2 * gamma_o + p * kPi; }

// The azimuthal scattering of path p < kPMax at the azimuth difference phi.
inline double azimuthal(double phi, int p, double s, double gamma_o, double gamma_t) {
  const double dphi = std::remainder(phi - exit_azimuth(p, gamma_o, gamma_t), kTwoPi);  // in [-pi, pi]
  return trimmed_logistic(dphi, s);
}

}  // namespace hair_detail

// pbrt-v4's SigmaAFromConcentration: the absorption of eumelanin and pheomelanin concentrations
// (linear RGB, per unit of the fibre's radius).
inline RGB hair_sigma_a_from_concentration(float eumelanin, float pheomelanin) {
  return RGB(0.419f, 0.697f, 1.37f) * eumelanin + RGB(0.187f, 0.4f, 1.05f) * pheomelanin;
}

// pbrt-v4's SigmaAFromReflectance (Chiang et al.'s fit): the absorption that gives a fibre of
// azimuthal roughness beta_n roughly the colour c (in [0, 1]; 0 absorbs everything), per lane.
inline float hair_sigma_a_from_reflectance(float c, float beta_n) {
  const float b = beta_n;
  const float d = 5.969f - 0.215f * b + 2.532f * b * b - 10.73f * b * b * b + 5.574f * b * b * b * b +
                  0.245f * b * b * b * b * b;
  return sqr(std::log(c) / d);
}
inline RGB hair_sigma_a_from_reflectance(const RGB& c, float beta_n) {
  return c.map([&](float x) { return hair_sigma_a_from_reflectance(std::clamp(x, 0.0f, 1.0f), beta_n); });
}

struct HairBsdf {
  static constexpr BsdfFlags flags =
      BsdfFlags::Reflection | BsdfFlags::Transmission | BsdfFlags::NonDelta | BsdfFlags::NonReciprocal;
  static constexpr int kPMax = hair_detail::kPMax;

  // The absorption coefficient inside the fibre (per unit of its radius), per lane. Where the
  // material gives a colour instead (pbrt-v4's "reflectance"), `color` holds it and sigma_a is made
  // from it per lane, after the colour has become a spectrum in a spectral render (spectral_bsdf.h).
  RGB sigma_a{0.0f};
  RGB color{0.0f};
  bool sigma_a_from_color = false;
  // The lanes whose mean chooses the path to sample: 3 (colour channels), 4 in a spectral render.
  uint8_t lanes = 3;

  HairBsdf() : HairBsdf(0, 1.55f, RGB(0.0f), 0.3f, 0.3f, 2) {}
  // h in [-1, 1], eta > 0, beta_m and beta_n in [0.01, 1] (pbrt-v4 clamps them from below there),
  // alpha the cuticle scales' tilt in degrees.
  HairBsdf(float h_, float eta_, const RGB& sigma_a_, float beta_m_, float beta_n_, float alpha_degrees)
      : sigma_a(sigma_a_),
        h(std::clamp(h_, -1.0f, 1.0f)),
        gamma_o(std::asin(h)),
        eta(eta_),
        beta_m(std::clamp(beta_m_, 0.01f, 1.0f)),
        beta_n(std::clamp(beta_n_, 0.01f, 1.0f)) {
    const float vm = 0.726f * beta_m + 0.812f * beta_m * beta_m + 3.7f * std::pow(beta_m, 20.0f);
    v[0] = vm * vm;
    v[1] = 0.25f * v[0];
    v[2] = 4 * v[0];
    v[3] = v[2];
    for (int p = 0; p <= kPMax; ++p) log_norm_rest[p] = hair_detail::longitudinal_log_norm_rest(v[p]);
    s = 0.626657069f * (0.265f * beta_n + 1.194f * beta_n * beta_n + 5.372f * std::pow(beta_n, 22.0f));
    // sin and cos of alpha, 2 alpha and 4 alpha.
    sin_2k_alpha[0] = std::sin(radians(alpha_degrees));
    cos_2k_alpha[0] = safe_sqrt(1 - sqr(sin_2k_alpha[0]));
    for (int i = 1; i < 3; ++i) {
      sin_2k_alpha[i] = 2 * cos_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
      cos_2k_alpha[i] = sqr(cos_2k_alpha[i - 1]) - sqr(sin_2k_alpha[i - 1]);
    }
  }

  float offset() const { return h; }
  float ior() const { return eta; }
  float longitudinal_roughness() const { return beta_m; }

  // sigma_a from `color` (a reflectance-given fibre), once the colour is in its final lanes.
  void resolve_color() {
    if (sigma_a_from_color) sigma_a = hair_sigma_a_from_reflectance(color, beta_n);
  }

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    RGB f(0.0f);
    evaluate(wo, wi, &f, nullptr);
    return f;
  }

  float pdf(const Vec3& wo, const Vec3& wi) const {
    float p = 0;
    evaluate(wo, wi, nullptr, &p);
    return p;
  }

  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    using namespace hair_detail;
    if (wo.z == 0) return std::nullopt;
    const float sin_o = std::clamp(wo.x, -1.0f, 1.0f), cos_o = safe_sqrt(1 - sin_o * sin_o);
    const float phi_o = std::atan2(wo.z, wo.y);
    const Geometry g = geometry(sin_o, cos_o);
    std::array<float, kPMax + 1> choice = path_probabilities(g);
    // The path, by u_lobe; u_lobe rescaled to [0, 1) within its share samples the azimuth.
    int p = 0;
    float x = u_lobe;
    while (p < kPMax && x >= choice[size_t(p)]) {
      x -= choice[size_t(p)];
      ++p;
    }
    if (!(choice[size_t(p)] > 0)) return std::nullopt;
    const float u_phi = std::clamp(x / choice[size_t(p)], 0.0f, 0x1.fffffep-1f);
    float sin_po, cos_po;
    tilted(p, sin_o, cos_o, sin_po, cos_po);
    // M_p: a direction of the von Mises-Fisher lobe of variance v_p around (-theta'_o), of which
    // only theta is kept: 1 - cos of its angle to the lobe's axis is -v log(u + (1 - u) e^(-2/v)).
    const double vp = v[p];
    const double one_minus_cos =
        std::clamp(-vp * std::log(std::max(double(u.x) + (1 - double(u.x)) * std::exp(-2 / vp), 1e-300)), 0.0, 2.0);
    const double cos_lobe = 1 - one_minus_cos, sin_lobe = std::sqrt(one_minus_cos * (2 - one_minus_cos));
    const double sin_i =
        std::clamp(-cos_lobe * sin_po + sin_lobe * std::cos(kTwoPi * u.y) * cos_po, -1.0, 1.0);
    const double cos_i = std::sqrt(std::max(0.0, 1 - sin_i * sin_i));
    // N_p: the azimuth.
    const double dphi =
        p < kPMax ? exit_azimuth(p, g.gamma_o, g.gamma_t) + sample_trimmed_logistic(u_phi, s) : kTwoPi * u_phi;
    const double phi_i = phi_o + dphi;
    const Vec3 wi(float(sin_i), float(cos_i * std::cos(phi_i)), float(cos_i * std::sin(phi_i)));
    if (wi.z == 0) return std::nullopt;
    RGB f(0.0f);
    float density = 0;
    evaluate(wo, wi, &f, &density);
    if (!(density > 0)) return std::nullopt;
    return BsdfSample{wi, f * (std::abs(wi.z) / density), density, false, 1};
  }

  bool has_non_delta() const { return true; }
  bool has_non_delta_transmission() const { return true; }
  float non_delta_probability(const Vec3& /*wo*/) const { return 1; }

 private:
  float h = 0, gamma_o = 0, eta = 1.55f, beta_m = 0.3f, beta_n = 0.3f;
  float v[kPMax + 1] = {};
  float log_norm_rest[kPMax + 1] = {};  // of each M_p (hair_detail::longitudinal)
  float s = 0;
  float sin_2k_alpha[3] = {}, cos_2k_alpha[3] = {};

  // What the refracted path depends on, for one wo.
  struct Geometry {
    float cos_o;
    double gamma_o, gamma_t;
    RGB T;  // transmittance of one crossing
  };
  Geometry geometry(float sin_o, float cos_o) const {
    const float sin_t = sin_o / eta, cos_t = safe_sqrt(1 - sin_t * sin_t);
    // The refracted path in the cross-section: Bravais' index of the fibre seen at theta_o.
    const float etap = safe_sqrt(eta * eta - sin_o * sin_o) / cos_o;
    const float sin_gt = std::clamp(h / etap, -1.0f, 1.0f), cos_gt = safe_sqrt(1 - sin_gt * sin_gt);
    const float length = 2 * cos_gt / cos_t;
    RGB T = sigma_a.map([&](float sa) { return std::exp(-sa * length); });
    return {cos_o, double(gamma_o), double(std::asin(sin_gt)), T};
  }

  // A_p for p = 0 .. kPMax.
  std::array<RGB, kPMax + 1> attenuation(const Geometry& g) const {
    std::array<RGB, kPMax + 1> a;
    const float cos_gamma_o = safe_sqrt(1 - h * h);
    const float F = fresnel_dielectric(g.cos_o * cos_gamma_o, eta);
    a[0] = RGB(F);
    a[1] = g.T * sqr(1 - F);
    for (int p = 2; p < kPMax; ++p) a[size_t(p)] = a[size_t(p - 1)] * g.T * F;
    a[kPMax] = RGB::from_lanes([&](int i) {
      const float tf = g.T[i] * F;
      return 1 - tf > 0 ? a[kPMax - 1][i] * tf / (1 - tf) : 0.0f;
    });
    return a;
  }

  // The probability of sampling each path: A_p's lane mean over the sum.
  std::array<float, kPMax + 1> path_probabilities(const Geometry& g) const {
    const std::array<RGB, kPMax + 1> a = attenuation(g);
    std::array<float, kPMax + 1> q;
    float sum = 0;
    for (int p = 0; p <= kPMax; ++p) sum += q[size_t(p)] = a[size_t(p)].lane_average(lanes);
    for (float& x : q) x = sum > 0 ? x / sum : 0;
    return q;
  }

  // theta_o turned by path p's cuticle tilt (-2 alpha, alpha, 4 alpha; none for the rest), with
  // cos kept non-negative.
  void tilted(int p, float sin_o, float cos_o, float& sin_po, float& cos_po) const {
    switch (p) {
      case 0:
        sin_po = sin_o * cos_2k_alpha[1] - cos_o * sin_2k_alpha[1];
        cos_po = cos_o * cos_2k_alpha[1] + sin_o * sin_2k_alpha[1];
        break;
      case 1:
        sin_po = sin_o * cos_2k_alpha[0] + cos_o * sin_2k_alpha[0];
        cos_po = cos_o * cos_2k_alpha[0] - sin_o * sin_2k_alpha[0];
        break;
      case 2:
        sin_po = sin_o * cos_2k_alpha[2] + cos_o * sin_2k_alpha[2];
        cos_po = cos_o * cos_2k_alpha[2] - sin_o * sin_2k_alpha[2];
        break;
      default:
        sin_po = sin_o;
        cos_po = cos_o;
    }
    cos_po = std::abs(cos_po);
  }

  // f(wo, wi) and the sampling density of wi, either of them (null: not wanted).
  void evaluate(const Vec3& wo, const Vec3& wi, RGB* f, float* density) const {
    using namespace hair_detail;
    if (f) *f = RGB(0.0f);
    if (density) *density = 0;
    if (wo.z == 0) return;
    const float sin_o = std::clamp(wo.x, -1.0f, 1.0f), cos_o = safe_sqrt(1 - sin_o * sin_o);
    const float sin_i = std::clamp(wi.x, -1.0f, 1.0f), cos_i = safe_sqrt(1 - sin_i * sin_i);
    const double phi = double(std::atan2(wi.z, wi.y)) - double(std::atan2(wo.z, wo.y));
    const Geometry g = geometry(sin_o, cos_o);
    const std::array<RGB, kPMax + 1> a = attenuation(g);
    float sum_a = 0;
    for (const RGB& x : a) sum_a += x.lane_average(lanes);
    RGB fsum(0.0f);
    double psum = 0;
    for (int p = 0; p < kPMax; ++p) {
      float sin_po, cos_po;
      tilted(p, sin_o, cos_o, sin_po, cos_po);
      const double mn = longitudinal(cos_i, cos_po, sin_i, sin_po, v[p], log_norm_rest[p]) *
                        azimuthal(phi, p, s, g.gamma_o, g.gamma_t);
      fsum += a[size_t(p)] * float(mn);
      psum += mn * a[size_t(p)].lane_average(lanes);
    }
    const double m_rest = longitudinal(cos_i, cos_o, sin_i, sin_o, v[kPMax], log_norm_rest[kPMax]) / kTwoPi;
    fsum += a[kPMax] * float(m_rest);
    psum += m_rest * a[kPMax].lane_average(lanes);
    if (f) *f = std::abs(wi.z) > 0 ? fsum / std::abs(wi.z) : fsum;
    if (density && sum_a > 0) *density = float(psum / sum_a);
  }
};

}  // namespace candela
