// The wrappers resolved into a SurfaceBsdf (one-sided, mask, blend) and the MaterialTable that
// builds them: one-sidedness, the mask's null part, blends' eval / pdf / sample consistency
// (chi-square), the BSDF contract's lobe order, and energy (nothing gains energy).
#include "candela/materials/surface_bsdf.h"

#include <gtest/gtest.h>

#include "candela/base/error.h"
#include "candela/materials/material.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::below;
using testing::direction;

using testing::kChiSquareAlpha;

double chi_square(const SurfaceBsdf& b, const Vec3& wo) {
  Rng lobe_rng(42, 43);
  auto sample = [&](Vec2 u) {
    auto s = b.sample(wo, lobe_rng.next_float(), u);
    return s && !s->is_delta ? s->wi : Vec3(0.0f);
  };
  return testing::spherical_chi_square_p_value(sample, [&](const Vec3& wi) { return b.pdf(wo, wi); },
                                               testing::kChiSquareSamples, 17, -1, 20, 40, 16);
}

// Every non-delta sample's weight is f cos / pdf and its pdf is pdf(wo, wi).
int check_weights(const SurfaceBsdf& b, const Vec3& wo, int n = 20000) {
  Rng rng(11, 12);
  int checked = 0;
  for (int i = 0; i < n; ++i) {
    auto s = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
    if (!s || s->is_delta) continue;
    float p = b.pdf(wo, s->wi);
    RGB expected = b.eval(wo, s->wi) * (std::abs(s->wi.z) / p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s->weight[c], expected[c], 2e-3f * (1 + expected[c]));
    EXPECT_NEAR(s->pdf, p, 2e-3f * p);
    ++checked;
  }
  return checked;
}

// Directional albedo: the mean sample weight (green), the null part included.
double albedo(const SurfaceBsdf& b, const Vec3& wo, int n = 200000) {
  Rng rng(3, 4);
  return testing::sample_mean(n, [&] {
           auto s = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
           return s ? double(s->weight.g) * s->eta * s->eta : 0.0;
         }).mean;
}

ConductorBsdf rough_conductor(float alpha, bool beckmann = false) {
  ConductorBsdf c;
  c.distribution = beckmann ? Microfacet(Beckmann(alpha)) : Microfacet(TrowbridgeReitz(alpha));
  return c;
}

SurfaceBsdf resolve(const std::vector<MaterialDesc>& descs, const std::vector<TextureDesc>& textures = {}) {
  static TextureSet set;  // the table keeps a pointer to it
  set = TextureSet(textures);
  MaterialTable table(descs, set);
  return table.bsdf(uint32_t(descs.size() - 1), TextureEvalContext{});
}

TEST(SurfaceBsdf, PlainMaterialIsItsBsdf) {
  SurfaceBsdf b = resolve({DiffuseMaterial{RGB(0.6f)}});
  EXPECT_TRUE(b.is_plain());
  EXPECT_FLOAT_EQ(b.eval(direction(20), direction(50)).g, 0.6f * kInvPi);
  EXPECT_FLOAT_EQ(b.eval(below(direction(20)), below(direction(50))).g, 0.6f * kInvPi);  // two-sided
}

TEST(SurfaceBsdf, OneSidedIsBlackFromTheBack) {
  SurfaceBsdf b = resolve({DiffuseMaterial{RGB(0.6f)}, OneSidedMaterial{0}});
  ASSERT_EQ(b.count, 1);
  EXPECT_TRUE(b.components[0].one_sided);
  Rng rng(1, 1);
  for (int i = 0; i < 2000; ++i) {
    Vec3 wo = below(direction(80 * rng.next_float(), 360 * rng.next_float()));
    Vec3 wi = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    EXPECT_EQ(b.eval(wo, wi), RGB(0.0f));
    EXPECT_EQ(b.pdf(wo, wi), 0.0f);
    EXPECT_FALSE(b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()}));
    // The front side towards a light behind the surface: black too.
    EXPECT_EQ(b.eval(direction(30), below(direction(40))), RGB(0.0f));
  }
  EXPECT_FLOAT_EQ(b.eval(direction(20), direction(50)).g, 0.6f * kInvPi);
  EXPECT_GT(chi_square(b, direction(40)), kChiSquareAlpha);
  // One-sided conductors (Mitsuba's roughconductor without "twosided").
  ConductorMaterial rough;
  rough.roughness.u = rough.roughness.v = 0.3f;
  SurfaceBsdf c = resolve({rough, OneSidedMaterial{0}});
  EXPECT_GT(c.eval(direction(30), direction(30, 210)).g, 0);
  EXPECT_EQ(c.eval(below(direction(30)), below(direction(30, 210))), RGB(0.0f));
}

TEST(SurfaceBsdf, MaskIsOpacityTimesTheMaterialPlusAStraightPassage) {
  MaskMaterial mask{.opacity = 0.3f, .material = 0};
  SurfaceBsdf b = resolve({DiffuseMaterial{RGB(0.8f)}, mask});
  EXPECT_NEAR(b.null_weight, 0.7f, 1e-6f);
  Vec3 wo = direction(35);
  EXPECT_NEAR(b.eval(wo, direction(60)).g, 0.3f * 0.8f * kInvPi, 1e-6f);
  EXPECT_NEAR(b.pdf(wo, direction(60)), 0.3f * direction(60).z * kInvPi, 1e-6f);
  EXPECT_NEAR(b.non_delta_probability(wo), 0.3f, 1e-6f);
  Rng rng(2, 2);
  int passed = 0, scattered = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    float u = rng.next_float();
    auto s = b.sample(wo, u, {rng.next_float(), rng.next_float()});
    ASSERT_TRUE(s);
    EXPECT_EQ(s->is_delta, u >= 0.3f);  // the contract: non-delta exactly below non_delta_probability
    if (s->is_delta) {
      ++passed;
      EXPECT_EQ(s->wi, -wo);
      EXPECT_EQ(s->weight, RGB(1.0f));
      EXPECT_NEAR(s->pdf, 0.7f, 1e-6f);
    } else {
      ++scattered;
      EXPECT_NEAR(s->weight.g, 0.8f, 1e-5f);
    }
  }
  EXPECT_NEAR(double(passed) / n, 0.7, 0.005);
  EXPECT_GT(check_weights(b, wo), 5000);
  EXPECT_GT(chi_square(b, wo), kChiSquareAlpha);
  // Opacity 0 and 1.
  mask.opacity = 0.0f;
  SurfaceBsdf none = resolve({DiffuseMaterial{RGB(0.8f)}, mask});
  EXPECT_EQ(none.count, 0);
  EXPECT_FALSE(none.has_non_delta());
  EXPECT_FALSE(none.is_black());
  mask.opacity = 1.0f;
  EXPECT_EQ(resolve({DiffuseMaterial{RGB(0.8f)}, mask}).null_weight, 0.0f);
}

TEST(SurfaceBsdf, BlendMixesEvalPdfAndSampling) {
  // (1 - w) diffuse + w rough conductor, and the conductor Beckmann.
  for (bool beckmann : {false, true}) {
    BlendMaterial blend{.weight = 0.35f, .material0 = 0, .material1 = 1};
    ConductorMaterial metal;
    metal.roughness.u = metal.roughness.v = 0.2f;
    metal.roughness.distribution = beckmann ? MicrofacetDistribution::Beckmann : MicrofacetDistribution::GGX;
    SurfaceBsdf b = resolve({DiffuseMaterial{RGB(0.7f)}, metal, blend});
    ASSERT_EQ(b.count, 2);
    ConductorBsdf c = rough_conductor(0.2f, beckmann);
    for (Vec3 wo : {direction(0), direction(45), direction(80), below(direction(30))}) {
      Vec3 wi = wo.z > 0 ? direction(40, 200) : below(direction(40, 200));
      RGB f = RGB(0.7f * kInvPi) * 0.65f + c.eval(wo, wi) * 0.35f;
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(b.eval(wo, wi)[ch], f[ch], 1e-5f * (1 + f[ch]));
      EXPECT_NEAR(b.pdf(wo, wi), 0.65f * std::abs(wi.z) * kInvPi + 0.35f * c.pdf(wo, wi), 1e-5f);
      EXPECT_GT(check_weights(b, wo), 15000) << wo.z;
      EXPECT_GT(chi_square(b, wo), kChiSquareAlpha) << beckmann << " " << wo.z;
    }
  }
}

TEST(SurfaceBsdf, BlendWithDeltaLobesKeepsTheContract) {
  // A smooth plastic (delta coat + diffuse) blended with a mirror and masked: non-delta parts come
  // first in u_lobe, then the delta parts, then the passage.
  MaskMaterial mask{.opacity = 0.8f, .material = 2};
  BlendMaterial blend{.weight = 0.4f, .material0 = 0, .material1 = 1};
  SurfaceBsdf b = resolve({CoatedDiffuseMaterial{}, MirrorMaterial{RGB(0.9f)}, blend, mask});
  ASSERT_EQ(b.count, 2);
  Rng rng(6, 7);
  for (Vec3 wo : {direction(10), direction(70)}) {
    float nd = b.non_delta_probability(wo);
    EXPECT_GT(nd, 0);
    EXPECT_LT(nd, 0.8f * 0.6f);
    for (int i = 0; i < 20000; ++i) {
      float u = rng.next_float();
      auto s = b.sample(wo, u, {rng.next_float(), rng.next_float()});
      if (!s) continue;
      EXPECT_EQ(!s->is_delta, u < nd) << u << " " << nd;
      if (s->is_delta && s->wi == -wo) {
        EXPECT_GE(u, 0.8f - 1e-6f);
      }
    }
    EXPECT_GT(check_weights(b, wo), 3000);
  }
}

TEST(SurfaceBsdf, NestedWrappersFlatten) {
  // mask(blend(one-sided diffuse, blend(conductor, dielectric))): three components and a passage.
  MaskMaterial mask{.opacity = 0.5f, .material = 5};
  BlendMaterial inner{.weight = 0.5f, .material0 = 1, .material1 = 2};
  BlendMaterial outer{.weight = 0.5f, .material0 = 3, .material1 = 4};
  SurfaceBsdf b = resolve({DiffuseMaterial{}, ConductorMaterial{}, DielectricMaterial{}, OneSidedMaterial{0}, inner,
                           outer, mask});
  ASSERT_EQ(b.count, 3);
  EXPECT_TRUE(b.components[0].one_sided);
  EXPECT_NEAR(b.components[0].weight, 0.25f, 1e-6f);
  EXPECT_NEAR(b.components[1].weight, 0.125f, 1e-6f);
  EXPECT_NEAR(b.components[2].weight, 0.125f, 1e-6f);
  EXPECT_NEAR(b.null_weight, 0.5f, 1e-6f);
}

TEST(SurfaceBsdf, MaterialTableRejectsWhatCannotBeResolved) {
  TextureSet textures;
  BlendMaterial self{.material0 = 0, .material1 = 0};
  EXPECT_THROW(MaterialTable({self}, textures), SceneError);  // wraps itself
  // Five components.
  std::vector<MaterialDesc> many = {DiffuseMaterial{}};
  BlendMaterial b{.material0 = 0, .material1 = 0};
  many.push_back(b);  // 2
  b.material0 = 1;
  b.material1 = 1;
  many.push_back(b);  // 4
  EXPECT_NO_THROW(MaterialTable(many, textures));
  b.material0 = 2;
  b.material1 = 0;
  many.push_back(b);  // 5
  EXPECT_THROW(MaterialTable(many, textures), SceneError);
}

TEST(SurfaceBsdf, AdjointOfABlendWeighsEachComponent) {
  BlendMaterial blend{.weight = 0.5f, .material0 = 0, .material1 = 1};
  DielectricMaterial glass;
  glass.roughness.u = glass.roughness.v = 0.3f;
  SurfaceBsdf b = resolve({DiffuseTransmissionMaterial{}, glass, blend});
  Vec3 wo = direction(30), wi = below(direction(20, 200));
  Bsdf dt = DiffuseTransmissionBsdf{RGB(0.25f), RGB(0.25f)};
  Bsdf g = DielectricBsdf{1.5f, RGB(1.0f), RGB(1.0f), TrowbridgeReitz(0.3f)};
  RGB expected = bsdf_eval(dt, wo, wi) * 0.5f + bsdf_eval(g, wo, wi) * (0.5f * bsdf_adjoint_scale(g, wo, wi));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.eval_adjoint(wo, wi)[c], expected[c], 1e-5f);
}

TEST(SurfaceBsdf, NoMaterialGainsEnergy) {
  // White furnace of the BSDFs themselves: with white inputs every wrapper's directional albedo
  // (the passage counted as transmitted energy) stays at most 1.
  MaskMaterial mask{.opacity = 0.4f, .material = 0};
  BlendMaterial blend{.weight = 0.5f, .material0 = 0, .material1 = 1};
  ConductorMaterial white;
  white.reflectance = ColorInput(RGB(0.9999f));
  white.roughness.u = white.roughness.v = 0.3f;
  white.roughness.distribution = MicrofacetDistribution::Beckmann;
  std::vector<std::vector<MaterialDesc>> cases = {
      {DiffuseMaterial{RGB(1.0f)}, white, mask},
      {DiffuseMaterial{RGB(1.0f)}, white, blend},
      {DiffuseMaterial{RGB(1.0f)}, OneSidedMaterial{0}},
      {white, OneSidedMaterial{0}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SurfaceBsdf b = resolve(cases[i]);
    for (Vec3 wo : {direction(0), direction(60), direction(88), below(direction(45))}) {
      double a = albedo(b, wo);
      EXPECT_LE(a, 1.0 + 0.005) << i << " " << wo.z;
    }
  }
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

// Mitsuba 3.7's two additions to normal and bump maps (scene/description.h, PerturbedNormalOptions),
// checked against their definitions on a normal map that tilts the normal 40 degrees towards +x.
TEST(PerturbedNormal, FlipAndTerminatorShadowingAsMitsuba) {
  const float tilt = radians(40);
  const Vec3 tilted(std::sin(tilt), 0, std::cos(tilt));
  const RGB encoded((tilted.x + 1) / 2, (tilted.y + 1) / 2, (tilted.z + 1) / 2);
  static TextureSet set;  // the table keeps a pointer to it
  set = TextureSet({ScaleTexture{ColorInput(encoded), FloatInput(1.0f)}});
  const std::vector<MaterialDesc> descs = {DiffuseMaterial{RGB(0.5f)},
                                           NormalMapMaterial{0, 0, {false, false}},
                                           NormalMapMaterial{0, 0, {true, false}},
                                           NormalMapMaterial{0, 0, {true, true}}};
  MaterialTable table(descs, set);
  SurfaceHit hit;
  hit.ng = hit.ns = Normal3(0, 0, 1);
  hit.dpdu = Vec3(1, 0, 0);
  hit.dpdv = Vec3(0, 1, 0);
  const Vec3 above(0, 0, 1);
  const Vec3 grazing(-std::sin(radians(70)), 0, std::cos(radians(70)));  // below the tilted normal
  ASSERT_LT(dot(grazing, tilted), 0);
  auto normal = [&](uint32_t m, const Vec3& wo) { return table.shading(m, TextureEvalContext{}, hit, wo).frame.n; };
  // Without the flip the tilt stands; with it, the normal is mirrored about the original one only
  // where wo is below the tilted normal.
  EXPECT_NEAR(length(normal(1, grazing) - tilted), 0, 1e-4f);
  EXPECT_NEAR(length(normal(2, above) - tilted), 0, 1e-4f);
  EXPECT_NEAR(length(normal(2, grazing) - Vec3(-tilted.x, 0, tilted.z)), 0, 1e-4f);

  // The terminator term scales f (not the pdf) by G = 2 / (1 + sqrt(1 + a^2 tan^2 theta_i)),
  // a^2 = min(tan^2(tilt) / 8, 1), theta_i the light direction's angle to the original normal.
  const float alpha2 = std::min(0.125f * sqr(std::tan(tilt)), 1.0f);
  for (float theta : {10.0f, 45.0f, 60.0f, 80.0f}) {
    const Vec3 wi_world(0, std::sin(radians(theta)), std::cos(radians(theta)));
    Shading flip = table.shading(2, TextureEvalContext{}, hit, above);
    Shading shadowed = table.shading(3, TextureEvalContext{}, hit, above);
    Vec3 wo = flip.frame.to_local(above), wi = flip.frame.to_local(wi_world);
    const float expected = 2 / (1 + std::sqrt(1 + alpha2 * sqr(std::tan(radians(theta)))));
    EXPECT_NEAR(shadowed.bsdf.eval(wo, wi).g / flip.bsdf.eval(wo, wi).g, expected, 1e-4f) << theta;
    EXPECT_FLOAT_EQ(shadowed.bsdf.pdf(wo, wi), flip.bsdf.pdf(wo, wi));
  }
  // Sampling carries the same factor in its weight.
  Shading flip = table.shading(2, TextureEvalContext{}, hit, above);
  Shading shadowed = table.shading(3, TextureEvalContext{}, hit, above);
  Vec3 wo = flip.frame.to_local(above);
  Rng rng(3, 9);
  for (int i = 0; i < 200; ++i) {
    float u = rng.next_float();
    Vec2 u2{rng.next_float(), rng.next_float()};
    auto a = flip.bsdf.sample(wo, u, u2), b = shadowed.bsdf.sample(wo, u, u2);
    ASSERT_EQ(bool(a), bool(b));
    if (!a) continue;
    float cos_original = dot(b->wi, shadowed.bsdf.original_normal);
    float tan2 = (1 - sqr(cos_original)) / sqr(cos_original);
    EXPECT_NEAR(b->weight.g / a->weight.g, 2 / (1 + std::sqrt(1 + alpha2 * tan2)), 1e-4f);
  }
}

}  // namespace
}  // namespace candela
