// The microfacet BSDFs (rough conductor, rough dielectric, coated diffuse) and diffuse transmission:
// the Trowbridge-Reitz distribution on its own (normalisation, visible-normal sampling), sample()
// against pdf() by chi-square tests (sample weights: bsdf_contract_test.cpp), reciprocity, energy
// conservation, and the smooth limits.
#include <gtest/gtest.h>

#include <complex>
#include <functional>
#include <tuple>

#include "candela/materials/bsdf.h"
#include "candela/math/frame.h"
#include "candela/sampling/rng.h"
#include "candela/testing/bsdf_chi_square.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using namespace testing;  // the shared BSDF test helpers: directions, albedo, chi-square

using testing::kChiSquareAlpha;

// The former GlassBsdf, verbatim: the reference for the smooth DielectricBsdf.
struct LegacyGlass {
  float ior = 1.5f;
  RGB reflectance{1.0f};
  RGB transmittance{1.0f};
  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2) const {
    float f = fresnel_dielectric(wo.z, ior);
    if (u_lobe < f) return BsdfSample{reflect_local(wo), reflectance, f, true, 1};
    Vec3 wt;
    float eta_rel;
    if (!refract_local(wo, ior, wt, eta_rel)) return BsdfSample{reflect_local(wo), reflectance, 1, true, 1};
    return BsdfSample{wt, transmittance / (eta_rel * eta_rel), 1 - f, true, eta_rel};
  }
};

// ---------------------------------------------------------------- the distribution

TEST(Microfacet, TrowbridgeReitzIsNormalized) {
  // integral D(wm) cos(theta_m) dwm = 1 and, for visible normals, integral D_w(wm) dwm = 1.
  for (auto [ax, ay] : {std::pair{0.1f, 0.1f}, {0.3f, 0.3f}, {0.8f, 0.8f}, {0.1f, 0.4f}}) {
    TrowbridgeReitz d(ax, ay);
    Vec3 w = direction(70, 20);
    NormalIntegrals integrals = normal_integrals(d, w, 2000, 200);
    EXPECT_NEAR(integrals.projected, 1.0, 2e-3) << ax << " x " << ay;
    EXPECT_NEAR(integrals.visible, 1.0, 2e-3) << ax << " x " << ay;
  }
}

TEST(Microfacet, VisibleNormalSamplingMatchesPdf) {
  for (auto [ax, ay, theta, zoom] : {std::tuple{0.3f, 0.3f, 80.0f, 1.0f}, {0.1f, 0.5f, 45.0f, 4.0f}}) {
    TrowbridgeReitz d(ax, ay);
    Vec3 w = direction(theta);
    auto sample = [&](Vec2 u) { return d.sample_visible_normal(w, u); };
    auto pdf = [&](const Vec3& wm) { return wm.z > 0 && dot(w, wm) > 0 ? d.pdf(w, wm) : 0.0f; };
    EXPECT_GT(zoomed_chi_square(sample, pdf, {Vec3(0, 0, 1), zoom, 0, 32}), kChiSquareAlpha)
        << ax << " x " << ay << " theta " << theta;
  }
  // A direction below the surface samples the normals visible from -w, in the upper hemisphere.
  TrowbridgeReitz d(0.3f, 0.3f);
  Rng rng(1, 2);
  for (int i = 0; i < 1000; ++i) {
    Vec3 wm = d.sample_visible_normal(below(direction(50)), {rng.next_float(), rng.next_float()});
    EXPECT_GT(wm.z, 0);
    EXPECT_LT(dot(below(direction(50)), wm), 1e-6f);
  }
}

TEST(Microfacet, SmoothThresholdAndRoughnessMapping) {
  EXPECT_TRUE(TrowbridgeReitz(0, 0).effectively_smooth());
  EXPECT_TRUE(TrowbridgeReitz(9e-4f, 5e-4f).effectively_smooth());
  EXPECT_FALSE(TrowbridgeReitz(9e-4f, 2e-3f).effectively_smooth());
  EXPECT_FLOAT_EQ(TrowbridgeReitz::roughness_to_alpha(0.25f), 0.5f);
  // Rough along one axis only: the other is clamped so that D stays finite.
  TrowbridgeReitz one_axis(0, 0.3f);
  EXPECT_TRUE(std::isfinite(one_axis.D(normalize(Vec3(0.1f, 0.2f, 1)))));
  // Masking of the normal direction is complete visibility; G <= G1 <= 1.
  TrowbridgeReitz d(0.4f, 0.2f);
  EXPECT_FLOAT_EQ(d.G1(Vec3(0, 0, 1)), 1.0f);
  Vec3 a = direction(60), b = direction(75, 200);
  EXPECT_LE(d.G(a, b), std::min(d.G1(a), d.G1(b)));
}

// pbrt-v4's FrComplex, with std::complex: the reference for the real-valued form.
float fresnel_complex_reference(float cos_i, std::complex<double> eta) {
  using C = std::complex<double>;
  double c = std::clamp(double(cos_i), 0.0, 1.0);
  C sin2_t = (1 - c * c) / (eta * eta);
  C cos_t = std::sqrt(C(1) - sin2_t);
  C r_parl = (eta * c - cos_t) / (eta * c + cos_t);
  C r_perp = (c - eta * cos_t) / (c + eta * cos_t);
  return float((std::norm(r_parl) + std::norm(r_perp)) / 2);
}

TEST(Microfacet, FresnelComplexKnownValues) {
  // The real-valued form equals the complex Fresnel equations (metals, dielectrics both ways).
  for (auto [n, k] : {std::pair{0.2f, 3.0f}, {1.1f, 2.1f}, {1.0f, 200.0f}, {1.5f, 0.0f}, {0.67f, 0.0f}, {2.5f, 0.5f}})
    for (float c : {0.0f, 0.01f, 0.2f, 0.5f, 0.74f, 0.9f, 1.0f})
      EXPECT_NEAR(fresnel_complex(c, std::complex<float>(n, k)), fresnel_complex_reference(c, {n, k}), 2e-5f)
          << n << " + " << k << "i, cos " << c;
  // Normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2). Gold at ~600 nm (n 0.2, k 3.0),
  // copper (pbrt's RGB defaults).
  auto normal = [](float n, float k) { return (sqr(n - 1) + k * k) / (sqr(n + 1) + k * k); };
  EXPECT_NEAR(fresnel_complex(1, std::complex<float>(0.2f, 3.0f)), normal(0.2f, 3.0f), 1e-5f);
  RGB eta(0.200438f, 0.924033f, 1.102212f), k(3.912949f, 2.452848f, 2.142188f);
  RGB f = fresnel_complex(1, eta, k);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], normal(eta[c], k[c]), 1e-5f);
  // Grazing incidence reflects everything; k = 0 is the dielectric Fresnel.
  EXPECT_NEAR(fresnel_complex(0, std::complex<float>(0.2f, 3.0f)), 1.0f, 1e-5f);
  for (float c : {1.0f, 0.7f, 0.3f, 0.05f})
    EXPECT_NEAR(fresnel_complex(c, std::complex<float>(1.5f, 0)), fresnel_dielectric(c, 1.5f), 1e-5f);
  // Artist mode: eta = 1 and k from the reflectance reproduce it at normal incidence.
  RGB r(0.9f, 0.5f, 0.1f);
  RGB fr = fresnel_complex(1, RGB(1.0f), conductor_k_from_reflectance(r));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fr[c], r[c], 1e-5f);
  EXPECT_TRUE(std::isfinite(conductor_k_from_reflectance(RGB(1.0f)).g));
}

TEST(Microfacet, DiffuseFresnelReflectanceMatchesQuadrature) {
  for (float eta : {1.0f / 2.5f, 1.0f / 1.5f, 1.0f / 1.1f, 1.01f, 1.1f, 1.33f, 1.5f, 2.5f}) {
    const int n = 200000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      double mu = (i + 0.5) / n;
      sum += fresnel_dielectric(float(mu), eta) * mu;
    }
    EXPECT_NEAR(fresnel_diffuse_reflectance(eta), 2 * sum / n, 2e-4) << eta;
  }
}

// ---------------------------------------------------------------- rough conductor

ConductorBsdf copper(float ax, float ay) {
  return {RGB(0.200438f, 0.924033f, 1.102212f), RGB(3.912949f, 2.452848f, 2.142188f), RGB(1.0f),
          TrowbridgeReitz(ax, ay)};
}

TEST(Conductor, SamplingMatchesPdf) {
  // Everything is binned over the upper hemisphere (z_min = 0); narrow lobes at normal incidence
  // magnified, those near the horizon integrated more finely.
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(copper(0.05f, 0.05f), direction(0), {up, 6, 0, 12}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(copper(0.05f, 0.05f), direction(80), {up, 1, 0, 24}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(copper(0.2f, 0.2f), direction(0), {up, 2, 0, 12}), kChiSquareAlpha);
  for (float theta : {45.0f, 88.0f})
    EXPECT_GT(bsdf_chi_square(copper(0.2f, 0.2f), direction(theta), {up, 1, 0, 16}), kChiSquareAlpha) << theta;
  for (float theta : {45.0f, 88.0f})
    EXPECT_GT(bsdf_chi_square(copper(0.6f, 0.6f), direction(theta), {up, 1, 0, 12}), kChiSquareAlpha) << theta;
  for (float theta : {45.0f, 80.0f})
    EXPECT_GT(bsdf_chi_square(copper(0.1f, 0.4f), direction(theta), {up, 1, 0, 24}), kChiSquareAlpha) << theta;
  // From below (two-sided): binned over the lower hemisphere.
  EXPECT_GT(bsdf_chi_square(copper(0.2f, 0.2f), below(direction(45)), {-up, 1, 0, 16}), kChiSquareAlpha);
}

TEST(Conductor, Reciprocity) {
  ConductorBsdf b = copper(0.3f, 0.15f);
  Rng rng(5, 6);
  for (int i = 0; i < 2000; ++i) {
    Vec3 a = random_direction(rng), c = random_direction(rng);
    RGB f1 = b.eval(a, c), f2 = b.eval(c, a);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(f1[ch], f2[ch], 1e-4f * (1 + f1[ch]));
    EXPECT_EQ(same_hemisphere(a, c), b.pdf(a, c) > 0);
  }
}

// Directional albedo of a rough conductor by quadrature over wi, independent of the sampling code:
// integral D(wm) F G(wo, wi) / (4 cos_o) dwi (the cos_i of f cos_i cancels).
double conductor_albedo_quadrature(const ConductorBsdf& b, const Vec3& wo) {
  const int nu = 800, nphi = 400;
  double sum = 0;
  for (int i = 0; i < nu; ++i) {
    double theta = kPi / 2 * (i + 0.5) / nu;
    for (int j = 0; j < nphi; ++j) {
      double phi = 2 * kPi * (j + 0.5) / nphi;
      Vec3 wi(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
      Vec3 wm = normalize(wo + wi);
      double F = fresnel_complex(dot(wo, wm), b.eta, b.k).g;
      sum += b.distribution.D(wm) * F * b.distribution.G(wo, wi) / (4 * wo.z) * std::sin(theta);
    }
  }
  return sum * (kPi / 2 / nu) * (2 * kPi / nphi);
}

TEST(Conductor, EnergyConservation) {
  // A perfect reflector (normal-incidence reflectance 1 - 1e-4) loses only what single scattering
  // misses; its albedo is below 1 and matches the quadrature of the model. The loss is large at
  // high roughness: at normal incidence, the visible normals tilted beyond 45 degrees (a fraction
  // 1 - 1 / (1 + alpha^2), 26% at alpha 0.6 and 4% at alpha 0.2) reflect below the horizon.
  for (float alpha : {0.2f, 0.6f}) {
    ConductorBsdf b{RGB(1.0f), conductor_k_from_reflectance(RGB(1 - 1e-4f)), RGB(1.0f), TrowbridgeReitz(alpha, alpha)};
    for (float theta : {0.0f, 45.0f, 80.0f, 88.0f}) {
      Estimate a = albedo(b, direction(theta));
      double expected = conductor_albedo_quadrature(b, direction(theta));
      EXPECT_LE(a.mean, 1.0 + 3 * a.standard_error) << alpha << " " << theta;
      EXPECT_NEAR(a.mean, expected, 4 * a.standard_error + 2e-3) << alpha << " " << theta;
      if (alpha == 0.2f && theta <= 45) {
        EXPECT_GE(a.mean, 0.9) << theta;
      }
    }
  }
  // Anisotropic, from below.
  ConductorBsdf b{RGB(1.0f), conductor_k_from_reflectance(RGB(1 - 1e-4f)), RGB(1.0f), TrowbridgeReitz(0.1f, 0.4f)};
  Estimate a = albedo(b, below(direction(60)));
  EXPECT_LE(a.mean, 1.0 + 3 * a.standard_error);
  EXPECT_GE(a.mean, 0.8);
}

TEST(Conductor, SmoothLimitIsFresnelMirror) {
  ConductorBsdf b = copper(0, 0);
  b.tint = RGB(0.9f, 0.8f, 0.7f);
  for (Vec3 wo : {direction(0), direction(50), direction(85), below(direction(30))}) {
    auto s = b.sample(wo, 0.3f, {0.2f, 0.7f});
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->is_delta);
    EXPECT_EQ(s->wi, reflect_local(wo));
    RGB F = fresnel_complex(std::abs(wo.z), b.eta, b.k) * b.tint;
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(s->weight[c], F[c]);
    EXPECT_EQ(b.eval(wo, reflect_local(wo)), RGB(0.0f));
    EXPECT_EQ(b.pdf(wo, reflect_local(wo)), 0.0f);
    EXPECT_EQ(b.non_delta_probability(wo), 0.0f);
    EXPECT_FALSE(b.has_non_delta());
  }
}

// ---------------------------------------------------------------- rough dielectric

DielectricBsdf glass(float ax, float ay, float eta = 1.5f) { return {eta, RGB(1.0f), RGB(1.0f), TrowbridgeReitz(ax, ay)}; }

TEST(Dielectric, RoughSamplingMatchesPdfFromOutside) {
  // At normal incidence both lobes (reflection around +z, refraction around -z) sit at the poles
  // that the zoom magnifies: a very narrow pair needs a strong zoom.
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(glass(0.05f, 0.05f), direction(0), {up, 30, -1, 16}), kChiSquareAlpha);
  for (const RoughGlassCase& c : rough_glass_from_outside())
    EXPECT_GT(bsdf_chi_square(glass(c.alpha_x, c.alpha_y), direction(c.theta), c.binning), kChiSquareAlpha)
        << c.alpha_x << " x " << c.alpha_y << " theta " << c.theta;
}

TEST(Dielectric, RoughSamplingMatchesPdfFromInside) {
  // wo inside the glass (z < 0): refraction out below the critical angle (41.8 degrees), mostly
  // total internal reflection beyond it.
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(glass(0.2f, 0.2f), below(direction(30)), {up, 1, -1, 16}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(glass(0.2f, 0.2f), below(direction(60)), {up, 1, -1, 16}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(glass(0.6f, 0.6f), below(direction(0)), {up, 2, -1, 16}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(glass(0.05f, 0.05f), below(direction(60)), {up, 1, -1, 32}), kChiSquareAlpha);
  // eta < 1 from outside is the same interface seen from the other medium.
  EXPECT_GT(bsdf_chi_square(glass(0.3f, 0.3f, 1 / 1.5f), direction(20)), kChiSquareAlpha);
}

TEST(Dielectric, SamplesReportTheRelativeIor) {
  // BsdfSample::eta is the relative IOR crossed (the contract, bsdf_contract_test.cpp, checks the weights).
  DielectricBsdf b = glass(0.3f, 0.3f);
  Rng rng(3, 3);
  for (int i = 0; i < 2000; ++i) {
    for (Vec3 wo : {direction(30), below(direction(30))}) {
      auto s = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
      if (!s) continue;
      float expected = same_hemisphere(wo, s->wi) ? 1.0f : (wo.z > 0 ? 1.5f : 1 / 1.5f);
      EXPECT_FLOAT_EQ(s->eta, expected);
    }
  }
}

TEST(Dielectric, GeneralizedReciprocity) {
  // Reflection: f(wo, wi) == f(wi, wo). Transmission with radiance scaling:
  // f(wo, wi) / n_o^2 == f(wi, wo) / n_i^2, n the index on each direction's side.
  for (float eta : {1.5f, 1 / 1.33f}) {
    DielectricBsdf b = glass(0.3f, 0.2f, eta);
    Rng rng(8, 9);
    int nonzero = 0;
    for (int i = 0; i < 4000; ++i) {
      Vec3 wo = random_direction(rng), wi = random_direction(rng);
      float n_o = wo.z > 0 ? 1 : eta, n_i = wi.z > 0 ? 1 : eta;
      float a = b.eval(wo, wi).g / (n_o * n_o), c = b.eval(wi, wo).g / (n_i * n_i);
      // (Pairs where wo or wi grazes its microfacet have f ~ 1e-6 and Fresnel terms that float
      // rounding perturbs; an absolute tolerance far below typical values of f covers them.)
      EXPECT_NEAR(a, c, 1e-3f * (a + c) + 1e-5f) << wo.z << " " << wi.z;
      if (a > 0 && !same_hemisphere(wo, wi)) ++nonzero;
    }
    EXPECT_GT(nonzero, 200);
  }
}

TEST(Dielectric, EnergyConservation) {
  // Reflection plus transmission (with the 1 / eta^2 radiance scaling undone) never exceeds 1,
  // and a smooth-ish interface scatters nearly everything.
  for (float alpha : {0.05f, 0.2f, 0.6f})
    for (Vec3 wo : {direction(0), direction(45), direction(80), direction(88), below(direction(30)),
                    below(direction(60))}) {
      Estimate a = albedo(glass(alpha, alpha), wo);
      EXPECT_LE(a.mean, 1.0 + 3 * a.standard_error) << alpha << " " << wo.z;
      if (alpha == 0.05f && std::abs(wo.z) > 0.7f) {
        EXPECT_GE(a.mean, 0.97) << wo.z;
      }
    }
}

TEST(Dielectric, SmoothLimitIsTheFormerGlass) {
  for (float eta : {1.5f, 1.0f / 1.33f, 2.4f}) {
    LegacyGlass old{eta, RGB(0.9f, 0.8f, 0.7f), RGB(0.5f, 0.6f, 0.7f)};
    DielectricBsdf now{eta, RGB(0.9f, 0.8f, 0.7f), RGB(0.5f, 0.6f, 0.7f), {}};
    EXPECT_FALSE(now.has_non_delta());
    EXPECT_FALSE(now.has_non_delta_transmission());
    Rng rng(4, 4);
    for (int i = 0; i < 20000; ++i) {
      Vec3 wo = random_direction(rng);
      float u_lobe = rng.next_float();
      Vec2 u(rng.next_float(), rng.next_float());
      auto a = old.sample(wo, u_lobe, u), b = now.sample(wo, u_lobe, u);
      ASSERT_EQ(bool(a), bool(b));
      if (!a) continue;
      EXPECT_EQ(a->wi, b->wi);
      EXPECT_EQ(a->weight, b->weight);
      EXPECT_EQ(a->pdf, b->pdf);
      EXPECT_EQ(a->is_delta, b->is_delta);
      EXPECT_EQ(a->eta, b->eta);
      EXPECT_EQ(now.non_delta_probability(wo), 0.0f);
    }
  }
}

// ---------------------------------------------------------------- coated diffuse

CoatedDiffuseBsdf plastic(float alpha, RGB base = RGB(0.6f, 0.4f, 0.2f), bool nonlinear = false) {
  return {base, RGB(1.0f), 1.5f, TrowbridgeReitz(alpha, alpha), nonlinear};
}

TEST(CoatedDiffuse, SamplingMatchesPdf) {
  // Rough coat: glossy and diffuse lobes mixed, binned over the upper hemisphere.
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(plastic(0.05f), direction(45), {up, 1, 0, 32}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(plastic(0.2f), direction(0), {up, 2, 0, 12}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(plastic(0.2f), direction(80), {up, 1, 0, 16}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(plastic(0.6f, RGB(0.9f), true), direction(88), {up, 1, 0, 12}), kChiSquareAlpha);
  // Smooth coat: the non-delta (diffuse) part only.
  EXPECT_GT(bsdf_chi_square(plastic(0), direction(0), {up, 1, 0, 12}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(plastic(0), below(direction(60))), kChiSquareAlpha);
}

TEST(CoatedDiffuse, Reciprocity) {
  for (float alpha : {0.0f, 0.3f}) {
    CoatedDiffuseBsdf b = plastic(alpha, RGB(0.8f, 0.5f, 0.2f), true);
    Rng rng(6, 7);
    for (int i = 0; i < 2000; ++i) {
      Vec3 a = random_direction(rng), c = random_direction(rng);
      RGB f1 = b.eval(a, c), f2 = b.eval(c, a);
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(f1[ch], f2[ch], 1e-4f * (1 + f1[ch]));
    }
  }
}

TEST(CoatedDiffuse, EnergyConservation) {
  // A white base under a smooth coat reflects everything: F(wo) at the coat and 1 - F(wo) through
  // the internal bounces (the linear model is exact there; nonlinear equal for R = 1).
  for (bool nonlinear : {false, true})
    for (float theta : {0.0f, 45.0f, 80.0f}) {
      Estimate a = albedo(plastic(0, RGB(1.0f), nonlinear), direction(theta));
      EXPECT_NEAR(a.mean, 1.0, 3 * a.standard_error + 1e-3) << theta;
    }
  // Nothing gains energy, rough or smooth, for any base up to white.
  for (float alpha : {0.0f, 0.05f, 0.2f, 0.6f})
    for (float theta : {0.0f, 45.0f, 80.0f, 88.0f})
      for (bool nonlinear : {false, true}) {
        Estimate a = albedo(plastic(alpha, RGB(1.0f), nonlinear), direction(theta));
        EXPECT_LE(a.mean, 1.0 + 3 * a.standard_error) << alpha << " " << theta;
      }
  // The nonlinear model darkens a coloured base (saturation shift), the linear one keeps
  // albedo = F + (1 - F) R for the smooth coat.
  Vec3 wo = direction(30);
  float F = fresnel_dielectric(wo.z, 1.5f);
  Estimate linear = albedo(plastic(0, RGB(0.5f), false), wo), nonlinear = albedo(plastic(0, RGB(0.5f), true), wo);
  EXPECT_NEAR(linear.mean, F + (1 - F) * 0.5, 3 * linear.standard_error + 1e-3);
  EXPECT_LT(nonlinear.mean, linear.mean);
}

TEST(CoatedDiffuse, LobeSelectionFollowsNonDeltaProbability) {
  // Smooth coat: sample() takes the diffuse lobe exactly when u_lobe < non_delta_probability(wo),
  // which follows Mitsuba's weighting (1 - F)(1 - s) : F s, s = mean(specular) / (mean(specular) + mean(R)).
  CoatedDiffuseBsdf b = plastic(0, RGB(0.3f));
  for (Vec3 wo : {direction(10), direction(70), below(direction(85))}) {
    float p = b.non_delta_probability(wo);
    float F = fresnel_dielectric(std::abs(wo.z), 1.5f), s = 1 / 1.3f;
    EXPECT_NEAR(p, (1 - F) * (1 - s) / ((1 - F) * (1 - s) + F * s), 1e-6f);
    for (float u_lobe : {0.0f, p * 0.999f, p * 1.001f, 0.999f}) {
      auto sample = b.sample(wo, u_lobe, {0.3f, 0.6f});
      ASSERT_TRUE(sample);
      EXPECT_EQ(sample->is_delta, u_lobe >= p);
      EXPECT_TRUE(same_hemisphere(wo, sample->wi));
    }
  }
  // Rough coat: every lobe is non-delta.
  EXPECT_EQ(plastic(0.2f).non_delta_probability(direction(70)), 1.0f);
}

TEST(CoatedDiffuse, TabulatedCoatSamplesItsPdfAndWeights) {
  // Mitsuba's roughplastic: the rough coat's tables replace the Fresnel factors in the diffuse
  // lobe and in the lobe selection; sampling must still match the pdf (and the weights eval cos / pdf:
  // bsdf_contract_test.cpp).
  static const RoughCoatTable ggx_table = make_rough_coat_table(TrowbridgeReitz(0.3f, 0.3f), 1.5f);
  static const RoughCoatTable beckmann_table = make_rough_coat_table(Beckmann(0.05f, 0.05f), 1.49f);
  CoatedDiffuseBsdf rough = plastic(0.3f, RGB(0.7f, 0.5f, 0.3f));
  rough.coat_table = &ggx_table;
  CoatedDiffuseBsdf shiny{RGB(0.5f), RGB(1.0f), 1.49f, Beckmann(0.05f, 0.05f), false, &beckmann_table};
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(rough, direction(0), {up, 2, 0, 12}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(rough, direction(80), {up, 1, 0, 16}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(shiny, direction(45), {up, 1, 0, 32}), kChiSquareAlpha);
  // The diffuse lobe is the table's: R t(wo) t(wi) / (pi eta^2 (1 - Ri)), here far from the
  // highlight so that the glossy lobe is negligible.
  CoatedDiffuseBsdf diffuse_only = shiny;
  Vec3 wo = direction(30, 0), wi = direction(50, 90);
  float expected = 0.5f * beckmann_table.transmittance_at(wo.z) * beckmann_table.transmittance_at(wi.z) /
                   (kPi * 1.49f * 1.49f * (1 - beckmann_table.internal_reflectance));
  EXPECT_NEAR(diffuse_only.eval(wo, wi).g, expected, 1e-5f * expected);
  // A white base loses energy under the rough coat and never gains any.
  CoatedDiffuseBsdf white = rough;
  white.reflectance = RGB(1.0f);
  for (float theta : {0.0f, 45.0f, 85.0f}) {
    Estimate a = albedo(white, direction(theta));
    EXPECT_LE(a.mean, 1.0 + 3 * a.standard_error) << theta;
  }
}

// ---------------------------------------------------------------- diffuse transmission

TEST(DiffuseTransmission, SamplingMatchesPdf) {
  DiffuseTransmissionBsdf b{RGB(0.2f, 0.5f, 0.3f), RGB(0.6f, 0.3f, 0.1f)};
  EXPECT_GT(bsdf_chi_square(b, direction(30)), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(b, below(direction(70))), kChiSquareAlpha);
}

TEST(DiffuseTransmission, ReciprocityAndEnergy) {
  DiffuseTransmissionBsdf b{RGB(0.2f, 0.5f, 0.3f), RGB(0.6f, 0.3f, 0.1f)};
  EXPECT_TRUE(b.has_non_delta_transmission());
  // f is symmetric, and the albedo is R + T exactly in expectation.
  Rng rng(2, 3);
  for (int i = 0; i < 200; ++i) {
    Vec3 a = random_direction(rng), c = random_direction(rng);
    EXPECT_EQ(b.eval(a, c), b.eval(c, a));
  }
  Estimate a = albedo(b, direction(20));
  EXPECT_NEAR(a.mean, 0.5 + 0.3, 3 * a.standard_error + 1e-4);
  // Black on both lobes: absorbed.
  DiffuseTransmissionBsdf black{RGB(0.0f), RGB(0.0f)};
  EXPECT_FALSE(black.sample(direction(20), 0.5f, {0.5f, 0.5f}));
  EXPECT_EQ(black.pdf(direction(20), direction(40)), 0.0f);
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

// GGX with Mitsuba's separable masking-shadowing (MicrofacetDistribution::GGXSeparable): G is the
// product of the two G1, never above the height-correlated form; a conductor on it keeps the BSDF
// contract (sampling follows its pdf, weights are f cos / pdf, reciprocity) and its albedo matches
// the quadrature of the model.
TEST(Microfacet, SeparableMaskingShadowingIsTheProductOfTheMaskings) {
  const TrowbridgeReitz correlated(0.4f, 0.1f), separable(0.4f, 0.1f, MaskingShadowing::Separable);
  Rng rng(8, 2);
  for (int i = 0; i < 2000; ++i) {
    Vec3 wo = random_direction(rng), wi = random_direction(rng);
    if (wo.z <= 0 || wi.z <= 0) continue;
    float g1g1 = correlated.G1(wo) * correlated.G1(wi);
    EXPECT_NEAR(separable.G(wo, wi), g1g1, 1e-6f);
    EXPECT_LE(separable.G(wo, wi), correlated.G(wo, wi) + 1e-6f);
    EXPECT_FLOAT_EQ(separable.D(normalize(wo + wi)), correlated.D(normalize(wo + wi)));
  }
  ConductorBsdf b = copper(0.3f, 0.15f);
  b.distribution = TrowbridgeReitz(0.3f, 0.15f, MaskingShadowing::Separable);
  const Vec3 up(0, 0, 1);
  for (float theta : {30.0f, 80.0f}) {
    EXPECT_GT(bsdf_chi_square(b, direction(theta), {up, 1, 0, 16}), kChiSquareAlpha) << theta;
  }
  for (int i = 0; i < 500; ++i) {
    Vec3 a = random_direction(rng), c = random_direction(rng);
    RGB f1 = b.eval(a, c), f2 = b.eval(c, a);
    EXPECT_NEAR(f1.g, f2.g, 1e-4f * (1 + f1.g));
  }
  ConductorBsdf white{RGB(1.0f), conductor_k_from_reflectance(RGB(1 - 1e-4f)), RGB(1.0f),
                      TrowbridgeReitz(0.6f, 0.6f, MaskingShadowing::Separable)};
  for (float theta : {0.0f, 60.0f}) {
    EXPECT_NEAR(albedo(white, direction(theta), 200000, Rng(4, uint64_t(theta))).mean,
                conductor_albedo_quadrature(white, direction(theta)), 0.005)
        << theta;
  }
}

}  // namespace
}  // namespace candela
