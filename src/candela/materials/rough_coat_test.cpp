// Tests of the quadrature rule and of the rough coat's tables (rough_coat.h).
#include "candela/materials/rough_coat.h"

#include <gtest/gtest.h>

#include <cmath>

#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

TEST(GaussLegendre, IntegratesPolynomialsUpToDegree2nMinus1Exactly) {
  for (int n : {1, 2, 5, 32, 128}) {
    QuadratureRule rule = gauss_legendre(n);
    for (int k = 0; k <= std::min(2 * n - 1, 40); ++k) {
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += rule.weights[size_t(i)] * std::pow(rule.nodes[size_t(i)], k);
      double exact = k % 2 ? 0.0 : 2.0 / (k + 1);
      EXPECT_NEAR(sum, exact, 1e-12) << "n " << n << " degree " << k;
    }
    for (int i = 1; i < n; ++i) EXPECT_LT(rule.nodes[size_t(i - 1)], rule.nodes[size_t(i)]);
  }
  // Degree 2n is no longer exact: the rule is not trivially right.
  QuadratureRule two = gauss_legendre(2);
  double sum = 0;
  for (int i = 0; i < 2; ++i) sum += two.weights[size_t(i)] * std::pow(two.nodes[size_t(i)], 4);
  EXPECT_GT(std::abs(sum - 2.0 / 5), 0.1);
}

Vec3 at_cosine(float mu) { return Vec3(std::sqrt(1 - mu * mu), 0, mu); }

// An independent estimate of the same integral: uniform random points of the visible-normal
// square instead of the quadrature's nodes.
testing::Estimate monte_carlo_albedo(const Microfacet& d, const Vec3& wi, float eta, bool transmitted, int n = 50000) {
  Rng rng(11, 5);
  return testing::sample_mean(n, [&] {
    Vec3 m = d.sample_visible_normal(wi, Vec2(rng.next_float(), rng.next_float()));
    float c = dot(wi, m), F = fresnel_dielectric(c, eta);
    double v = 0;
    if (c > 0 && !transmitted) {
      Vec3 wo = m * (2 * c) - wi;
      if (wo.z > 0) v = F * d.G1(wo);
    } else if (c > 0) {
      float sin2_t = (1 - c * c) / (eta * eta);
      if (sin2_t < 1) {
        Vec3 wo = m * (c / eta - std::sqrt(1 - sin2_t)) - wi / eta;
        if (wo.z < 0) v = (1 - F) * d.G1(wo);
      }
    }
    return v;
  });
}

TEST(RoughCoat, InterfaceAlbedoAgreesWithMonteCarlo) {
  for (bool beckmann : {false, true})
    for (float alpha : {0.05f, 0.6f})
      for (float mu : {0.1f, 0.8f})
        for (float eta : {1.5f, 1 / 1.5f})
          for (bool transmitted : {false, true}) {
            Microfacet d = beckmann ? Microfacet(Beckmann(alpha, alpha)) : Microfacet(TrowbridgeReitz(alpha, alpha));
            double q = rough_interface_albedo(d, at_cosine(mu), eta, transmitted);
            testing::Estimate e = monte_carlo_albedo(d, at_cosine(mu), eta, transmitted);
            EXPECT_NEAR(q, e.mean, 5 * e.standard_error + 2e-4)
                << (beckmann ? "beckmann" : "ggx") << " alpha " << alpha << " mu " << mu << " eta " << eta
                << (transmitted ? " transmitted" : " reflected");
          }
}

TEST(RoughCoat, NearlySmoothInterfaceIsFresnel) {
  Microfacet d = Beckmann(1e-3f, 1e-3f);
  for (float mu : {0.1f, 0.5f, 1.0f})
    for (float eta : {1.49f, 1 / 1.49f}) {
      float F = fresnel_dielectric(mu, eta);
      EXPECT_NEAR(rough_interface_albedo(d, at_cosine(mu), eta, false), F, 1e-3) << mu << " " << eta;
      EXPECT_NEAR(rough_interface_albedo(d, at_cosine(mu), eta, true), 1 - F, 1e-3) << mu << " " << eta;
    }
}

TEST(RoughCoat, ReflectedAndTransmittedNeverExceedOne) {
  for (float alpha : {0.1f, 0.5f, 1.0f})
    for (float mu : {0.02f, 0.3f, 0.7f, 1.0f}) {
      Microfacet d = TrowbridgeReitz(alpha, alpha);
      double sum = rough_interface_albedo(d, at_cosine(mu), 1.5f, false) +
                   rough_interface_albedo(d, at_cosine(mu), 1.5f, true);
      EXPECT_LE(sum, 1 + 1e-6) << alpha << " " << mu;
      // Only masking is lost: little for a smooth-ish coat away from grazing angles.
      if (alpha <= 0.1f && mu >= 0.3f) {
        EXPECT_GT(sum, 0.97) << alpha << " " << mu;
      }
    }
}

TEST(RoughCoat, TableFollowsMitsubasSixtyFourPointMean) {
  // Nearly smooth, the table is the Fresnel transmittance, and the internal reflectance is
  // Mitsuba's 2 * mean of F(mu_i, 1 / eta) mu_i over mu_i = i / 63, not the integral.
  const float eta = 1.49f / 1.000277f;
  RoughCoatTable table = make_rough_coat_table(Beckmann(1e-3f, 1e-3f), eta);
  double mean = 0;
  for (int i = 0; i < 64; ++i) {
    float mu = std::max(1e-6f, float(i) / 63);
    mean += fresnel_dielectric(mu, 1 / eta) * mu;
    if (i > 0) {
      EXPECT_NEAR(table.transmittance[size_t(i)], 1 - fresnel_dielectric(mu, eta), 1e-3) << mu;
    }
  }
  EXPECT_NEAR(table.internal_reflectance, 2 * mean / 64, 1e-3);
  EXPECT_GT(fresnel_diffuse_reflectance(1 / eta) - table.internal_reflectance, 0.008);  // the mean's known deficit
  // Linear interpolation between the nodes.
  float between = table.transmittance_at(10.5f / 63);
  EXPECT_NEAR(between, (table.transmittance[10] + table.transmittance[11]) / 2, 1e-6f);
  EXPECT_EQ(table.transmittance_at(2.0f), table.transmittance[63]);
}

}  // namespace
}  // namespace candela
