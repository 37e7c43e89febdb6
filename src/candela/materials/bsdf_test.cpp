// BSDF sampling routines against their pdfs (chi-square), sample weights against eval/pdf, and
// energy conservation / reciprocity where they hold.
#include "candela/materials/bsdf.h"

#include <gtest/gtest.h>

#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

constexpr int kSamples = testing::kChiSquareSamples;

Vec3 direction(float theta_degrees, float phi_degrees = 30) {
  float t = radians(theta_degrees), p = radians(phi_degrees);
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// Chi-square of the directions sample() returns against pdf(); non-delta samples only.
double bsdf_chi_square(const Bsdf& bsdf, const Vec3& wo, float z_min = -1) {
  Rng lobe_rng(42, 43);
  auto sample = [&](Vec2 u) {
    auto s = bsdf_sample(bsdf, wo, lobe_rng.next_float(), u);
    return s && !s->is_delta ? s->wi : Vec3(0.0f);
  };
  auto pdf = [&](const Vec3& wi) { return bsdf_pdf(bsdf, wo, wi); };
  return testing::spherical_chi_square_p_value(sample, pdf, kSamples, 17, z_min);
}

TEST(Bsdf, DiffuseSamplingMatchesPdf) {
  Bsdf b = DiffuseBsdf{RGB(0.5f)};
  EXPECT_GT(bsdf_chi_square(b, direction(30)), testing::kChiSquareAlpha);
  EXPECT_GT(bsdf_chi_square(b, -direction(40)), testing::kChiSquareAlpha);  // two-sided: from below
}

TEST(Bsdf, PhongMixtureSamplingMatchesPdf) {
  for (float exponent : {2.0f, 20.0f}) {
    for (float theta : {0.0f, 45.0f, 80.0f}) {
      PhongBsdf p;
      p.diffuse = RGB(0.7f);
      p.specular = RGB(0.9f);
      p.exponent = exponent;
      p.d = 0.4f;
      p.s = 0.5f;
      p.t = 0.0f;
      EXPECT_GT(bsdf_chi_square(p, direction(theta)), testing::kChiSquareAlpha) << "n " << exponent << " theta " << theta;
    }
  }
}

TEST(Bsdf, NarrowPhongLobeSamplingMatchesPdf) {
  PhongBsdf p;
  p.exponent = 300;
  p.d = 0;
  p.s = 1;
  // The lobe around the mirror direction of normal incidence is narrow: bin finely near the pole.
  EXPECT_GT(bsdf_chi_square(p, direction(0), 0.9f), testing::kChiSquareAlpha);
}

TEST(Bsdf, SampleWeightIsEvalCosOverPdf) {
  PhongBsdf p;
  p.diffuse = RGB(0.6f, 0.5f, 0.4f);
  p.specular = RGB(0.9f);
  p.exponent = 15;
  p.d = 0.5f;
  p.s = 0.3f;
  p.t = 0.1f;
  Rng rng(1, 1);
  Vec3 wo = direction(35);
  int checked = 0;
  for (int i = 0; i < 10000; ++i) {
    auto s = p.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
    if (!s || s->is_delta) continue;
    RGB expected = p.eval(wo, s->wi) * (std::abs(s->wi.z) / p.pdf(wo, s->wi));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s->weight[c], expected[c], 1e-4f * (1 + expected[c]));
    EXPECT_NEAR(s->pdf, p.pdf(wo, s->wi), 1e-4f * s->pdf);
    ++checked;
  }
  EXPECT_GT(checked, 7000);
}

TEST(Bsdf, PhongModeProbabilitiesFollowDST) {
  // The fraction of paths continuing as diffuse / specular / transmitted is d / s / t (paper, 4.6),
  // minus specular samples that fall below the surface.
  PhongBsdf p;
  p.exponent = 1000;  // nothing falls below the surface at normal incidence
  p.d = 0.2f;
  p.s = 0.3f;
  p.t = 0.4f;
  Rng rng(2, 2);
  int diffuse = 0, specular = 0, transmitted = 0, absorbed = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    auto s = p.sample(direction(0), rng.next_float(), {rng.next_float(), rng.next_float()});
    if (!s) ++absorbed;
    else if (s->is_delta) ++transmitted;
    else if (s->wi.z > 0.99f) ++specular;
    else ++diffuse;
  }
  std::vector<double> observed = {double(diffuse), double(specular), double(transmitted), double(absorbed)};
  // A cosine-distributed diffuse sample lands within 8 degrees of the normal with probability 1 - 0.99^2.
  double near_pole = 1 - 0.99 * 0.99;
  std::vector<double> expected = {n * 0.2 * (1 - near_pole), n * (0.3 + 0.2 * near_pole), n * 0.4, n * 0.1};
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(Bsdf, EnergyConservationAndReciprocity) {
  // Albedo E[weight] <= 1 for white lobes with d + s <= 1, and f(wo, wi) == f(wi, wo).
  PhongBsdf p;
  p.diffuse = RGB(1.0f);
  p.specular = RGB(1.0f);
  p.exponent = 10;
  p.d = 0.5f;
  p.s = 0.5f;
  for (float theta : {0.0f, 30.0f, 60.0f, 85.0f}) {
    Rng rng(3, uint64_t(theta));
    double sum = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      auto s = p.sample(direction(theta), rng.next_float(), {rng.next_float(), rng.next_float()});
      if (s) sum += s->weight.g;
    }
    EXPECT_LE(sum / n, 1.0 + 0.01) << theta;
  }
  Rng rng(4, 4);
  for (int i = 0; i < 1000; ++i) {
    Vec3 a = square_to_cosine_hemisphere({rng.next_float(), rng.next_float()});
    Vec3 b = square_to_cosine_hemisphere({rng.next_float(), rng.next_float()});
    EXPECT_NEAR(p.eval(a, b).g, p.eval(b, a).g, 1e-4f * (1 + p.eval(a, b).g));
  }
}

TEST(Bsdf, GlassChoosesReflectionWithFresnelProbability) {
  DielectricBsdf g{1.5f, RGB(1.0f), RGB(1.0f), {}};
  for (float theta : {0.0f, 45.0f, 75.0f}) {
    Vec3 wo = direction(theta);
    float F = fresnel_dielectric(wo.z, 1.5f);
    Rng rng(5, uint64_t(theta));
    int reflected = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      auto s = g.sample(wo, rng.next_float(), {0, 0});
      ASSERT_TRUE(s);
      ASSERT_TRUE(s->is_delta);
      if (s->wi.z > 0) {
        ++reflected;
        EXPECT_NEAR(s->wi.z, wo.z, 1e-5f);
      } else {
        // Snell's law: sin(theta_t) = sin(theta_i) / 1.5, radiance scaled by 1 / eta^2.
        EXPECT_NEAR(std::sqrt(1 - s->wi.z * s->wi.z), std::sin(radians(theta)) / 1.5f, 1e-4f);
        EXPECT_NEAR(s->weight.g, 1 / (1.5f * 1.5f), 1e-5f);
      }
    }
    double se = std::sqrt(F * (1 - F) / n);
    EXPECT_NEAR(double(reflected) / n, F, 5 * se + 1e-4) << theta;
  }
  // Normal incidence: ((eta - 1) / (eta + 1))^2 = 0.04; beyond the critical angle inside: total reflection.
  EXPECT_NEAR(fresnel_dielectric(1, 1.5f), 0.04f, 1e-6f);
  EXPECT_FLOAT_EQ(fresnel_dielectric(-std::cos(radians(60)), 1.5f), 1.0f);
}

}  // namespace
}  // namespace candela
