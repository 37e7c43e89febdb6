// The Beckmann distribution (Mitsuba 3's definitions) on its own and in every microfacet BSDF:
// normalisation, Smith masking against quadrature and known values, visible-normal sampling and
// BSDF sampling against their pdfs (chi-square, several roughnesses and incident angles up to
// near-grazing), reciprocity and energy. (Sample weights: bsdf_contract_test.cpp.)
#include <gtest/gtest.h>

#include <functional>
#include <tuple>

#include "candela/materials/bsdf.h"
#include "candela/math/frame.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/bsdf_chi_square.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using namespace testing;  // the shared BSDF test helpers: directions, albedo, chi-square

using testing::kChiSquareAlpha;

ConductorBsdf beckmann_conductor(float ax, float ay) {
  return {RGB(0.2f, 0.9f, 1.1f), RGB(3.9f, 2.4f, 2.1f), RGB(1.0f), Beckmann(ax, ay)};
}
ConductorBsdf white_conductor(float alpha) {
  return {RGB(1.0f), conductor_k_from_reflectance(RGB(1 - 1e-4f)), RGB(1.0f), Beckmann(alpha, alpha)};
}
DielectricBsdf beckmann_glass(float ax, float ay, float eta = 1.5f) { return {eta, RGB(1.0f), RGB(1.0f), Beckmann(ax, ay)}; }
CoatedDiffuseBsdf beckmann_plastic(float alpha, RGB base = RGB(0.5f)) {
  return {base, RGB(1.0f), 1.5f, Beckmann(alpha, alpha), false};
}

// ---------------------------------------------------------------- the distribution

TEST(Beckmann, IsNormalized) {
  // integral D(wm) cos(theta_m) dwm = 1, and the visible normals' density (with the exact Lambda)
  // integrates to 1, for several roughnesses and incident angles up to near-grazing.
  for (auto [ax, ay] : {std::pair{0.05f, 0.05f}, {0.3f, 0.3f}, {0.8f, 0.8f}, {0.1f, 0.5f}}) {
    Beckmann d(ax, ay);
    for (float theta : {0.0f, 50.0f, 85.0f, 89.0f}) {
      Vec3 w = direction(theta, 20);
      NormalIntegrals integrals = normal_integrals(d, w, 3000, 240);
      EXPECT_NEAR(integrals.projected, 1.0, 2e-3) << ax << " x " << ay;
      EXPECT_NEAR(integrals.visible, 1.0, 3e-3) << ax << " x " << ay << " theta " << theta;
    }
  }
}

TEST(Beckmann, MaskingMatchesKnownValuesAndQuadrature) {
  // a = 1 / (alpha tan theta): exact Lambda(1) = (erf(1) - 1) / 2 + exp(-1) / (2 sqrt(pi)) = 0.025127;
  // Mitsuba's rational G1(1) = 5.716 / 5.853.
  Beckmann d(1.0f);
  Vec3 w = normalize(Vec3(1, 0, 1));  // tan theta = 1
  EXPECT_NEAR(d.Lambda(w), 0.0251273, 1e-5);
  EXPECT_NEAR(d.G1(w), 5.716 / 5.853, 1e-5);
  EXPECT_FLOAT_EQ(d.G1(Vec3(0, 0, 1)), 1.0f);
  EXPECT_FLOAT_EQ(Beckmann(0.2f).G1(direction(30)), 1.0f);  // a = 8.66 >= 1.6: no masking
  // The rational approximation is within 0.35% of the exact masking 1 / (1 + Lambda) everywhere.
  for (float alpha : {0.05f, 0.3f, 1.0f})
    for (float theta = 1; theta < 90; theta += 0.5f) {
      Beckmann b(alpha);
      EXPECT_NEAR(b.G1(direction(theta)) / b.visible_G1(direction(theta)), 1.0, 3.6e-3) << alpha << " " << theta;
    }
  // The exact masking against quadrature: G1(w) integral D(m) max(0, w . m) dm = cos theta_w.
  for (auto [ax, ay, theta] : {std::tuple{0.3f, 0.3f, 70.0f}, {0.5f, 0.2f, 80.0f}, {0.8f, 0.8f, 60.0f}}) {
    Beckmann b(ax, ay);
    Vec3 v = direction(theta, 40);
    const int nu = 3000, nphi = 240;
    double integral = 0;
    for (int i = 0; i < nu; ++i) {
      double u = (i + 0.5) / nu, th = kPi / 2 * u * u, dth = kPi * u / nu;
      for (int j = 0; j < nphi; ++j) {
        double phi = 2 * kPi * (j + 0.5) / nphi;
        Vec3 wm(float(std::sin(th) * std::cos(phi)), float(std::sin(th) * std::sin(phi)), float(std::cos(th)));
        integral += b.D(wm) * std::max(0.0f, dot(v, wm)) * std::sin(th) * dth * 2 * kPi / nphi;
      }
    }
    EXPECT_NEAR(b.visible_G1(v) * integral / v.z, 1.0, 2e-3) << ax << " " << ay << " " << theta;
  }
  // erfinv inverts erf.
  for (double x : {-0.999999, -0.9, -0.3, 0.0, 0.2, 0.7, 0.99, 0.9999999}) EXPECT_NEAR(std::erf(erfinv(x)), x, 1e-13);
}

TEST(Beckmann, VisibleNormalSamplingMatchesPdf) {
  // Near-grazing incidence puts the visibility cut-off (w . wm = 0) through the pole, where the
  // harness's thin cells need a finer integration (as much for GGX's exact sampler).
  for (auto [ax, ay, theta, zoom, resolution] :
       {std::tuple{0.05f, 0.05f, 0.0f, 12.0f, 32}, {0.05f, 0.05f, 60.0f, 6.0f, 32}, {0.3f, 0.3f, 45.0f, 2.0f, 32},
        {0.3f, 0.3f, 88.0f, 1.0f, 64}, {0.8f, 0.8f, 80.0f, 1.0f, 32}, {0.1f, 0.5f, 45.0f, 4.0f, 32},
        {0.5f, 0.1f, 87.0f, 2.0f, 32}}) {
    Beckmann d(ax, ay);
    Vec3 w = direction(theta);
    auto sample = [&](Vec2 u) { return d.sample_visible_normal(w, u); };
    auto pdf = [&](const Vec3& wm) { return wm.z > 0 && dot(w, wm) > 0 ? d.pdf(w, wm) : 0.0f; };
    EXPECT_GT(zoomed_chi_square(sample, pdf, {Vec3(0, 0, 1), zoom, 0, resolution}), kChiSquareAlpha)
        << ax << " x " << ay << " theta " << theta;
  }
  // Sampled normals are unit, in the upper hemisphere and visible, also for directions below the surface.
  Beckmann d(0.4f, 0.2f);
  Rng rng(1, 2);
  for (int i = 0; i < 20000; ++i) {
    Vec3 w = i % 2 ? below(direction(50)) : direction(89.5f);
    Vec3 wm = d.sample_visible_normal(w, {rng.next_float(), rng.next_float()});
    ASSERT_NEAR(length(wm), 1, 1e-5f);
    EXPECT_GT(wm.z, 0);
    EXPECT_GT(dot(w.z > 0 ? w : -w, wm), -1e-5f);
  }
}

TEST(Beckmann, MicrofacetChoosesTheDistribution) {
  Microfacet g = TrowbridgeReitz(0.3f), b = Beckmann(0.3f);
  EXPECT_FALSE(g.is_beckmann());
  EXPECT_TRUE(b.is_beckmann());
  Vec3 wm = direction(20);
  EXPECT_FLOAT_EQ(b.D(wm), Beckmann(0.3f).D(wm));
  EXPECT_FLOAT_EQ(g.D(wm), TrowbridgeReitz(0.3f).D(wm));
  EXPECT_NE(b.D(wm), g.D(wm));
  EXPECT_TRUE(Microfacet(Beckmann(5e-4f)).effectively_smooth());
}

// ---------------------------------------------------------------- in the BSDFs

TEST(Beckmann, ConductorSamplingMatchesPdf) {
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(beckmann_conductor(0.05f, 0.05f), direction(0), {up, 6, 0, 12}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(beckmann_conductor(0.05f, 0.05f), direction(80), {up, 1, 0, 24}), kChiSquareAlpha);
  for (float theta : {0.0f, 45.0f, 88.0f})
    EXPECT_GT(bsdf_chi_square(beckmann_conductor(0.3f, 0.3f), direction(theta), {up, theta == 0 ? 2.0f : 1.0f, 0, 16}),
              kChiSquareAlpha)
        << theta;
  for (float theta : {45.0f, 88.0f})
    EXPECT_GT(bsdf_chi_square(beckmann_conductor(0.7f, 0.7f), direction(theta), {up, 1, 0, 12}), kChiSquareAlpha)
        << theta;
  EXPECT_GT(bsdf_chi_square(beckmann_conductor(0.1f, 0.4f), direction(60), {up, 1, 0, 24}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(beckmann_conductor(0.3f, 0.3f), below(direction(45)), {-up, 1, 0, 16}), kChiSquareAlpha);
}

TEST(Beckmann, DielectricSamplingMatchesPdf) {
  for (const RoughGlassCase& c : rough_glass_from_outside())
    EXPECT_GT(bsdf_chi_square(beckmann_glass(c.alpha_x, c.alpha_y), direction(c.theta), c.binning), kChiSquareAlpha)
        << c.alpha_x << " x " << c.alpha_y << " theta " << c.theta;
  const Vec3 up(0, 0, 1);
  EXPECT_GT(bsdf_chi_square(beckmann_glass(0.2f, 0.2f), below(direction(30)), {up, 1, -1, 16}), kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(beckmann_glass(0.2f, 0.2f), below(direction(60)), {up, 1, -1, 16}), kChiSquareAlpha);
}

TEST(Beckmann, CoatedDiffuseSamplingMatchesPdf) {
  const Vec3 up(0, 0, 1);
  for (float alpha : {0.05f, 0.3f})
    for (float theta : {0.0f, 45.0f, 85.0f})
      EXPECT_GT(bsdf_chi_square(beckmann_plastic(alpha), direction(theta), {up, 1, 0, 16}), kChiSquareAlpha)
          << alpha << " " << theta;
}

TEST(Beckmann, Reciprocity) {
  ConductorBsdf c = beckmann_conductor(0.3f, 0.15f);
  CoatedDiffuseBsdf p = beckmann_plastic(0.2f);
  DielectricBsdf g = beckmann_glass(0.3f, 0.2f);
  Rng rng(5, 6);
  for (int i = 0; i < 4000; ++i) {
    Vec3 a = random_direction(rng), b = random_direction(rng);
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(c.eval(a, b)[ch], c.eval(b, a)[ch], 1e-4f * (1 + c.eval(a, b)[ch]));
      EXPECT_NEAR(p.eval(a, b)[ch], p.eval(b, a)[ch], 1e-4f * (1 + p.eval(a, b)[ch]));
    }
    // Transmission with radiance scaling: f(a, b) / n_a^2 == f(b, a) / n_b^2.
    float n_a = a.z > 0 ? 1 : 1.5f, n_b = b.z > 0 ? 1 : 1.5f;
    float x = g.eval(a, b).g / (n_a * n_a), y = g.eval(b, a).g / (n_b * n_b);
    EXPECT_NEAR(x, y, 1e-3f * (x + y) + 1e-5f);
  }
}

TEST(Beckmann, EnergyConservation) {
  // A perfect conductor, lossless glass and a white-based plastic scatter at most everything (up to
  // the 0.35% the rational masking may add where it exceeds the exact masking).
  for (float alpha : {0.05f, 0.3f, 0.8f})
    for (Vec3 wo : {direction(0), direction(45), direction(80), direction(88)}) {
      for (const Bsdf& b : {Bsdf(white_conductor(alpha)), Bsdf(beckmann_glass(alpha, alpha)),
                            Bsdf(beckmann_plastic(alpha, RGB(1.0f)))}) {
        Estimate a = albedo(b, wo);
        EXPECT_LE(a.mean, 1.0035 + 3 * a.standard_error) << alpha << " " << wo.z << " " << b.index();
        EXPECT_GE(a.mean, 0.2) << alpha << " " << wo.z << " " << b.index();  // single scattering loses some
      }
      Estimate inside = albedo(beckmann_glass(alpha, alpha), below(wo));
      EXPECT_LE(inside.mean, 1.0035 + 3 * inside.standard_error) << alpha << " " << wo.z;
    }
}

}  // namespace
}  // namespace candela
