// BSDF sampling routines against their pdfs (chi-square), and energy conservation / reciprocity
// where they hold. (Sample weights against eval / pdf: the contract, bsdf_contract_test.cpp.)
#include "candela/materials/bsdf.h"

#include <gtest/gtest.h>

#include "candela/sampling/rng.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::albedo;
using testing::direction;

using testing::kChiSquareSamples;

// Chi-square of the directions sample() returns against pdf(); non-delta samples only.
double bsdf_sampling_p_value(const Bsdf& bsdf, const Vec3& wo, float z_min = -1) {
  Rng lobe_rng(42, 43);
  auto sample = [&](Vec2 u) {
    auto s = bsdf_sample(bsdf, wo, lobe_rng.next_float(), u);
    return s && !s->is_delta ? s->wi : Vec3(0.0f);
  };
  auto pdf = [&](const Vec3& wi) { return bsdf_pdf(bsdf, wo, wi); };
  return testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 17, z_min);
}

TEST(Bsdf, DiffuseSamplingMatchesPdf) {
  Bsdf b = DiffuseBsdf{RGB(0.5f)};
  EXPECT_GT(bsdf_sampling_p_value(b, direction(30)), testing::kChiSquareAlpha);
  EXPECT_GT(bsdf_sampling_p_value(b, -direction(40)), testing::kChiSquareAlpha);  // two-sided: from below
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
      EXPECT_GT(bsdf_sampling_p_value(p, direction(theta)), testing::kChiSquareAlpha)
          << "n " << exponent << " theta " << theta;
    }
  }
}

TEST(Bsdf, NarrowPhongLobeSamplingMatchesPdf) {
  PhongBsdf p;
  p.exponent = 300;
  p.d = 0;
  p.s = 1;
  // The lobe around the mirror direction of normal incidence is narrow: bin finely near the pole.
  EXPECT_GT(bsdf_sampling_p_value(p, direction(0), 0.9f), testing::kChiSquareAlpha);
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
    EXPECT_LE(albedo(p, direction(theta), 200000, Rng(3, uint64_t(theta))).mean, 1.0 + 0.01) << theta;
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

// Light paths carry importance and use the adjoint BSDF f*(wo, wi) = f(wi, wo). For a rough dielectric
// f(wo, wi) of a transmitted pair carries 1 / eta'^2, eta' the relative IOR crossed from wo's side
// (eta' = eta when wo is above, 1 / eta below), while the rest of it, B, satisfies B(wi, wo) = B(wo, wi) /
// eta'^2; so f(wi, wo) = eta'^2 f(wo, wi): bsdf_adjoint_scale must be eta'^2 for transmitted pairs and 1 for
// reflected ones, and every other BSDF here is reciprocal (scale 1).
TEST(BsdfAdjoint, ScaleTurnsEvalIntoTheAdjointForTransmittedPairs) {
  struct Case {
    Bsdf bsdf;
    const char* name;
  };
  CoatedDiffuseBsdf coated;
  coated.reflectance = RGB(0.6f, 0.4f, 0.2f);
  coated.distribution = TrowbridgeReitz(0.2f, 0.35f);
  ConductorBsdf conductor;
  conductor.distribution = TrowbridgeReitz(0.25f, 0.4f);
  PhongBsdf phong;
  phong.d = 0.4f;
  phong.s = 0.4f;
  phong.t = 0.2f;
  phong.exponent = 12;
  std::vector<Case> cases = {
      {DielectricBsdf{1.5f, RGB(1.0f), RGB(0.9f, 0.8f, 0.7f), TrowbridgeReitz(0.3f)}, "rough dielectric 1.5"},
      {DielectricBsdf{1 / 1.5f, RGB(1.0f), RGB(0.9f, 0.8f, 0.7f), TrowbridgeReitz(0.3f)}, "rough dielectric 1/1.5"},
      {DielectricBsdf{1.33f, RGB(1.0f), RGB(1.0f), TrowbridgeReitz(0.1f, 0.4f)}, "anisotropic rough dielectric"},
      {DiffuseBsdf{RGB(0.7f)}, "diffuse"},
      {DiffuseTransmissionBsdf{RGB(0.3f), RGB(0.6f)}, "diffuse transmission"},
      {coated, "rough coated diffuse"},
      {conductor, "rough conductor"},
      {phong, "phong"},
  };
  for (const Case& c : cases) {
    const auto* dielectric = std::get_if<DielectricBsdf>(&c.bsdf);
    Rng rng(11, 12);
    int transmitted = 0, reflected = 0;
    for (int i = 0; i < 40000; ++i) {
      Vec3 wo = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
      Vec3 wi = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
      if (std::abs(wo.z) < 1e-3f || std::abs(wi.z) < 1e-3f) continue;
      if (dielectric && !same_hemisphere(wo, wi)) {
        // Ill-conditioned in float: near-grazing directions, or a facet (the generalised half vector)
        // seen at grazing incidence by either direction, where 1 - F cancels (relative errors of 1e-2 and
        // more between the two orders); elsewhere the two agree to ~1e-4.
        float etap = wo.z > 0 ? dielectric->eta : 1 / dielectric->eta;
        Vec3 wm = normalize(wi * etap + wo);
        if (std::min(std::abs(wo.z), std::abs(wi.z)) < 0.02f ||
            std::min(std::abs(dot(wm, wo)), std::abs(dot(wm, wi))) < 0.05f)
          continue;
      }
      float scale = bsdf_adjoint_scale(c.bsdf, wo, wi);
      RGB f = bsdf_eval(c.bsdf, wo, wi), f_rev = bsdf_eval(c.bsdf, wi, wo);
      if (same_hemisphere(wo, wi)) {
        ASSERT_EQ(scale, 1) << c.name;
        ++reflected;
      } else {
        float etap = dielectric ? (wo.z > 0 ? dielectric->eta : 1 / dielectric->eta) : 1.0f;
        ASSERT_NEAR(scale, etap * etap, 1e-6f * etap * etap) << c.name;
        // The scale of the reverse pair undoes it.
        ASSERT_NEAR(scale * bsdf_adjoint_scale(c.bsdf, wi, wo), 1, 1e-5f) << c.name;
        if (f.max_component() > 0 || f_rev.max_component() > 0) ++transmitted;
      }
      RGB adjoint = f * scale;
      for (int k = 0; k < 3; ++k)
        ASSERT_NEAR(adjoint[k], f_rev[k], 1e-3f * std::max(adjoint[k], f_rev[k]) + 1e-7f)
            << c.name << " channel " << k << " wo " << wo.x << " " << wo.y << " " << wo.z << " wi " << wi.x << " "
            << wi.y << " " << wi.z << " scale " << scale;
    }
    EXPECT_GT(reflected, 10000) << c.name;
    // Transmitted pairs with a non-zero value (most random pairs have no microfacet explaining them).
    if (dielectric || std::holds_alternative<DiffuseTransmissionBsdf>(c.bsdf)) {
      EXPECT_GT(transmitted, 2000) << c.name;
    }
  }
}

TEST(BsdfAdjoint, SampledRefractionsAreUncompressedForImportance) {
  // Delta refractions (smooth dielectric, Phong's t lobe) and sampled rough refractions report eta', and
  // the importance-mode weight is the radiance-mode weight times eta'^2 (the integrator applies that);
  // for the dielectric that factor is also bsdf_adjoint_scale of the sampled pair.
  PhongBsdf phong;
  phong.d = 0;
  phong.s = 0;
  phong.t = 1;
  phong.transmission = RGB(0.9f, 0.8f, 0.7f);
  phong.ior = 1.5f;
  struct Case {
    Bsdf bsdf;
    const char* name;
  };
  std::vector<Case> cases = {
      {DielectricBsdf{1.5f, RGB(1.0f), RGB(0.9f, 0.8f, 0.7f), {}}, "smooth dielectric 1.5"},
      {DielectricBsdf{1 / 1.5f, RGB(1.0f), RGB(0.9f, 0.8f, 0.7f), {}}, "smooth dielectric 1/1.5"},
      {DielectricBsdf{1.5f, RGB(1.0f), RGB(0.9f, 0.8f, 0.7f), TrowbridgeReitz(0.3f)}, "rough dielectric 1.5"},
      {DielectricBsdf{1 / 1.5f, RGB(1.0f), RGB(0.9f, 0.8f, 0.7f), TrowbridgeReitz(0.3f)}, "rough dielectric 1/1.5"},
      {phong, "phong transmission"},
  };
  for (const Case& c : cases) {
    const auto* dielectric = std::get_if<DielectricBsdf>(&c.bsdf);
    const float ior = dielectric ? dielectric->eta : phong.ior;
    Rng rng(13, 14);
    int refracted = 0;
    for (int i = 0; i < 20000; ++i) {
      Vec3 wo = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
      if (std::abs(wo.z) < 1e-3f) continue;
      auto s = bsdf_sample(c.bsdf, wo, rng.next_float(), {rng.next_float(), rng.next_float()});
      if (!s) continue;
      if (same_hemisphere(wo, s->wi)) {
        ASSERT_EQ(s->eta, 1) << c.name;
        ASSERT_EQ(bsdf_adjoint_scale(c.bsdf, wo, s->wi), 1) << c.name;
        continue;
      }
      ++refracted;
      float etap = wo.z > 0 ? ior : 1 / ior;
      ASSERT_NEAR(s->eta, etap, 1e-6f * etap) << c.name;
      if (dielectric) {
        ASSERT_NEAR(bsdf_adjoint_scale(c.bsdf, wo, s->wi), etap * etap, 1e-5f * etap * etap) << c.name;
      }
      if (s->is_delta) {
        // Delta refraction: the radiance weight is T / eta'^2, the importance weight T.
        RGB t = dielectric ? dielectric->transmittance : phong.transmission;
        RGB importance_weight = s->weight * (s->eta * s->eta);
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(importance_weight[k], t[k], 1e-5f) << c.name;
      } else {
        // Rough: the importance weight is f(wi, wo) |cos_i| / pdf(wo, wi).
        RGB expected = bsdf_eval(c.bsdf, s->wi, wo) * (std::abs(s->wi.z) / s->pdf);
        RGB importance_weight = s->weight * (s->eta * s->eta);
        for (int k = 0; k < 3; ++k)
          ASSERT_NEAR(importance_weight[k], expected[k], 2e-3f * expected[k] + 1e-6f) << c.name;
      }
    }
    EXPECT_GT(refracted, 2000) << c.name;
  }
}

}  // namespace
}  // namespace candela
