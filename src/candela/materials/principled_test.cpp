// Mitsuba's principled and principledthin BSDFs: eval against values of Mitsuba's formulas, sampling
// against pdf (chi-square), energy where the model conserves it, reciprocity. (Sample weights:
// bsdf_contract_test.cpp.)
#include "candela/materials/principled.h"

#include <gtest/gtest.h>

#include <type_traits>

#include <string>
#include <vector>

#include "candela/materials/material.h"
#include "candela/sampling/rng.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/principled_cases.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::direction;
using testing::random_direction;

// Chi-square of sample() against pdf(). The harness bins uniformly in cos theta around its pole,
// which cannot resolve the narrow lobes that sit at the pole for near-normal incidence (the first
// row of cells spans 25 degrees): there the directions are binned in a frame whose pole is the
// surface's x axis instead (a rotation, so densities are unchanged).
template <typename B>
double chi_square(const B& bsdf, const Vec3& wo, int resolution = 32) {
  Rng lobe_rng(42, 43);
  bool tilt = std::abs(wo.z) > 0.7f;
  auto sample = [&](Vec2 u) {
    auto s = bsdf.sample(wo, lobe_rng.next_float(), u);
    if (!s) return Vec3(0.0f);
    return tilt ? Vec3(s->wi.y, s->wi.z, s->wi.x) : s->wi;
  };
  auto pdf = [&](const Vec3& w) { return bsdf.pdf(wo, tilt ? Vec3(w.z, w.x, w.y) : w); };
  return testing::spherical_chi_square_p_value(sample, pdf, testing::kChiSquareSamples, 17, -1, 20, 40, resolution);
}

// ---------------------------------------------------------------- Mitsuba's definition

// f(wo, wi) at fixed directions, computed in double precision by a separate transcription of Mitsuba
// 3's principled.cpp / principledthin.cpp / principledhelpers.h (Mitsuba's value divided by the
// cosine of the light direction). A change of any lobe's formula or weight shows up here.
struct EvalCase {
  const char* name;
  bool thin;
  PrincipledParams params;
  Vec3 wo, wi;
  RGB expected;
};

std::vector<EvalCase> eval_cases() {
  // Every lobe of principled at once (no transmission).
  PrincipledParams all{.base_color = RGB(0.8f, 0.4f, 0.2f), .roughness = 0.4f, .anisotropic = 0.5f, .metallic = 0.3f,
                       .spec_tint = 0.4f, .sheen = 0.6f, .sheen_tint = 0.5f, .clearcoat = 0.7f, .clearcoat_gloss = 0.6f,
                       .flatness = 0.3f, .eta = 1.5f};
  // With specular transmission.
  PrincipledParams glass{.base_color = RGB(0.3f, 0.6f, 0.8f), .roughness = 0.3f, .anisotropic = 0.2f,
                         .spec_trans = 0.7f, .sheen = 0.4f, .clearcoat = 0.5f, .clearcoat_gloss = 0.2f, .eta = 1.3f};
  // glTF's metallic-roughness: specular 0.5 (eta 1.5), the rest off.
  PrincipledParams gltf{.base_color = RGB(0.9f, 0.6f, 0.3f), .roughness = 0.5f, .eta = 1.5f};
  PrincipledParams metal = gltf;
  metal.roughness = 0.25f;
  metal.metallic = 1;
  PrincipledParams thin{.base_color = RGB(0.7f, 0.1f, 0.1f), .roughness = 0.5f, .anisotropic = 0.4f, .spec_tint = 0.3f,
                        .spec_trans = 0.6f, .sheen = 0.5f, .sheen_tint = 0.3f, .flatness = 0.4f, .eta = 1.33f,
                        .diff_trans = 0.8f};
  return {
      {"all lobes", false, all, direction(30, 20), direction(50, 200), {0.655422927f, 0.349932783f, 0.197187711f}},
      {"all lobes near mirror", false, all, direction(40, 10), direction(38, 185),
       {1.44095692f, 0.814754324f, 0.501653024f}},
      {"all lobes grazing", false, all, direction(80, 0), direction(60, 170), {0.657528985f, 0.421239798f, 0.303095205f}},
      {"glass reflection", false, glass, direction(35, 40), direction(30, 230),
       {0.168829054f, 0.197476456f, 0.216574725f}},
      {"glass transmission", false, glass, direction(35, 40), -direction(20, 30),
       {0.117619632f, 0.166339279f, 0.192072055f}},
      {"glass back reflection", false, glass, -direction(30, 60), -direction(40, 250),
       {0.0390095455f, 0.0390095455f, 0.0390095455f}},
      {"glass back transmission", false, glass, -direction(30, 60), direction(45, 70),
       {0.570850252f, 0.807304169f, 0.932194559f}},
      {"glTF dielectric", false, gltf, direction(45, 0), direction(45, 180), {0.410565459f, 0.315072493f, 0.219579527f}},
      {"glTF metal", false, metal, direction(60, 0), direction(55, 175), {8.94740118f, 6.03410579f, 3.12081039f}},
      {"thin reflection", true, thin, direction(30, 20), direction(35, 190), {0.0788719832f, 0.0231794527f, 0.0231794527f}},
      {"thin transmission", true, thin, direction(30, 20), -direction(35, 10), {2.43109143f, 0.347298775f, 0.347298775f}},
      {"thin from the back", true, thin, -direction(30, 20), direction(35, 10), {2.43109143f, 0.347298775f, 0.347298775f}},
  };
}

TEST(PrincipledEval, MatchesMitsubasFormulas) {
  for (const EvalCase& c : eval_cases()) {
    RGB f = c.thin ? PrincipledThinBsdf(c.params).eval(c.wo, c.wi) : PrincipledBsdf(c.params).eval(c.wo, c.wi);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], c.expected[k], 2e-4f * c.expected[k]) << c.name << " channel " << k;
  }
}

TEST(PrincipledEval, SpecularMapsToEtaAsMitsubaDoes) {
  // specular = R0 / 0.08: 0.5 is eta 1.5, the glTF default.
  EXPECT_NEAR(principled_eta_from_specular(0.5f), 1.5f, 1e-6f);
  for (float s : {0.1f, 0.4f, 0.7f, 1.0f})
    EXPECT_NEAR(principled_detail::schlick_r0(principled_eta_from_specular(s)), 0.08f * s, 1e-6f) << s;
}

TEST(PrincipledEval, MetalReflectsBaseColorAtNormalIncidence) {
  // metallic = 1: Schlick's Fresnel with R0 = base_color, so at wo = wi = n the colour is exactly base_color
  // times the grey microfacet factor D G / 4.
  PrincipledParams p{.base_color = RGB(0.9f, 0.5f, 0.2f), .roughness = 0.3f, .metallic = 1};
  RGB f = PrincipledBsdf(p).eval(Vec3(0, 0, 1), Vec3(0, 0, 1));
  float dg = principled_distribution(0.3f, 0).D(Vec3(0, 0, 1)) / 4;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], p.base_color[k] * dg, 1e-5f * dg);
}

TEST(PrincipledEval, OpaqueSurfaceIsBlackFromBehind) {
  PrincipledParams p{.sheen = 1, .clearcoat = 1};
  PrincipledBsdf b(p);
  EXPECT_TRUE(b.eval(-direction(30), -direction(40, 200)).is_black());
  EXPECT_EQ(b.pdf(-direction(30), -direction(40, 200)), 0);
  EXPECT_FALSE(b.sample(-direction(30), 0.5f, {0.3f, 0.6f}));
  EXPECT_FALSE(b.has_non_delta_transmission());
}

// ---------------------------------------------------------------- sampling

TEST(PrincipledSampling, MatchesPdf) {
  for (const testing::PrincipledCase& c : testing::principled_sampling_cases()) {
    PrincipledBsdf b(c.params);
    std::vector<Vec3> wos = {direction(0), direction(35), direction(70), direction(87)};
    if (b.has_non_delta_transmission()) {
      wos.push_back(-direction(25));
      wos.push_back(-direction(60));  // beyond the critical angle for most facets
    }
    for (const Vec3& wo : wos)
      EXPECT_GT(chi_square(b, wo), testing::kChiSquareAlpha)
          << c.name << " wo.z " << wo.z;
  }
}

TEST(PrincipledThinSampling, MatchesPdf) {
  PrincipledParams p{.base_color = RGB(0.7f, 0.3f, 0.2f), .roughness = 0.5f, .anisotropic = 0.5f, .spec_trans = 0.5f,
                     .sheen = 0.5f, .eta = 1.33f, .diff_trans = 0.6f};
  PrincipledParams specular = p;
  specular.spec_trans = 1;
  specular.eta = 1.8f;
  PrincipledParams diffuse = p;
  diffuse.spec_trans = 0;
  diffuse.diff_trans = 1.4f;
  for (const PrincipledParams& params : {p, specular, diffuse}) {
    PrincipledThinBsdf b(params);
    for (const Vec3& wo : {direction(0), direction(40), direction(86), -direction(30), -direction(75)})
      EXPECT_GT(chi_square(b, wo), testing::kChiSquareAlpha)
          << "spec_trans " << params.spec_trans << " wo.z " << wo.z;
  }
}

TEST(PrincipledSampling, RefractionsReportTheRelativeIor) {
  PrincipledParams p{.roughness = 0.3f, .spec_trans = 1, .eta = 1.5f};
  PrincipledBsdf b(p);
  Rng rng(5, 5);
  int refracted = 0;
  for (int i = 0; i < 4000; ++i) {
    Vec3 wo = i % 2 ? direction(30) : -direction(30);
    auto s = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
    if (!s) continue;
    if (same_hemisphere(wo, s->wi)) {
      EXPECT_EQ(s->eta, 1);
    } else {
      EXPECT_NEAR(s->eta, wo.z > 0 ? 1.5f : 1 / 1.5f, 1e-6f);
      ++refracted;
    }
  }
  EXPECT_GT(refracted, 2000);
  PrincipledParams t = p;
  t.diff_trans = 1;
  auto s = PrincipledThinBsdf(t).sample(direction(30), 0.9f, {0.3f, 0.3f});
  ASSERT_TRUE(s);
  EXPECT_EQ(s->eta, 1);  // a thin sheet does not bend light
}

// ---------------------------------------------------------------- energy, reciprocity

template <typename B>
double albedo(const B& b, const Vec3& wo, int n = 200000) {
  Rng rng(3, uint64_t(1000 * wo.z + 7));
  return testing::sample_mean(n, [&] {
           auto s = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
           return s ? double(s->weight.max_component()) : 0.0;
         }).mean;
}

TEST(PrincipledEnergy, AlbedoAtMostOneWhereTheModelConservesEnergy) {
  // Single-scattering microfacet lobes with Fresnel weights that sum to at most 1: the metal (Schlick
  // of a white base), the dielectric with full specular transmission (entering: radiance scaled by 1 / eta^2),
  // and the thin sheet's specular pair. Uncorrelated lobes (below) are not covered.
  PrincipledParams metal{.base_color = RGB(1.0f), .metallic = 1};
  PrincipledParams glass{.base_color = RGB(1.0f), .spec_trans = 1, .eta = 1.5f};
  PrincipledParams thin = glass;
  thin.eta = 1.33f;
  PrincipledParams thin_diffuse{.base_color = RGB(1.0f), .roughness = 0, .diff_trans = 1};
  for (float roughness : {0.2f, 0.5f, 0.9f}) {
    metal.roughness = glass.roughness = thin.roughness = roughness;
    for (float theta : {0.0f, 30.0f, 60.0f, 80.0f}) {
      EXPECT_LE(albedo(PrincipledBsdf(metal), direction(theta)), 1.005) << "metal " << roughness << " " << theta;
      EXPECT_LE(albedo(PrincipledBsdf(glass), direction(theta)), 1.005) << "glass " << roughness << " " << theta;
      EXPECT_LE(albedo(PrincipledThinBsdf(thin), direction(theta)), 1.005) << "thin " << roughness << " " << theta;
    }
  }
  // Burley's smooth diffuse (roughness 0: no retro-reflection) is below 1 everywhere.
  for (float theta : {0.0f, 45.0f, 85.0f})
    EXPECT_LE(albedo(PrincipledThinBsdf(thin_diffuse), direction(theta)), 1.0) << theta;
}

TEST(PrincipledEnergy, MitsubasModelIsNotEnergyConservingElsewhere) {
  // Documents where Mitsuba's principled (like Burley's) creates energy, so that a "fix" would be a
  // deviation from Mitsuba: the retro-reflection of a rough white diffuse base at grazing angles, and
  // the sheen and specular lobes added on top of an undiminished diffuse lobe.
  PrincipledParams rough{.base_color = RGB(1.0f), .roughness = 1};
  rough.eta = 1.0001f;  // no specular lobe at all
  EXPECT_GT(albedo(PrincipledBsdf(rough), direction(80)), 1.05);
  PrincipledParams sheen = rough;
  sheen.roughness = 0.5f;
  sheen.sheen = 1;
  sheen.eta = 1.5f;
  EXPECT_GT(albedo(PrincipledBsdf(sheen), direction(75)), 1.05);
  // glTF's metallic-roughness case with a white base: the diffuse lobe keeps its full weight under the
  // specular reflection (albedo ~1.03 at normal incidence, ~1.23 at 80 degrees for roughness 0.2).
  PrincipledParams gltf{.base_color = RGB(1.0f), .roughness = 0.2f, .eta = 1.5f};
  EXPECT_GT(albedo(PrincipledBsdf(gltf), direction(80)), 1.1);
}

// Mitsuba's thin transmission keeps a facet wh = normalize(v + (l.x, l.y, |l.z|)) only where the
// transmitted direction l sees its back (l . wh < 0; v, l mirrored to the viewer's side), a condition
// on l that is not symmetric in the pair: where it holds one way only, the specular transmission is
// there in one direction and not in the other. Elsewhere the thin sheet is reciprocal.
bool thin_transmission_masks_agree(const Vec3& a, const Vec3& c) {
  auto visible = [](const Vec3& wo, const Vec3& wi) {
    float s = wo.z > 0 ? 1.0f : -1.0f;
    Vec3 v = wo * s, l = wi * s;
    Vec3 wh = normalize(v + Vec3(l.x, l.y, std::abs(l.z)));
    return dot(l, wh) < 0;
  };
  return visible(a, c) == visible(c, a);
}

TEST(PrincipledReciprocity, ReflectionAndThinTransmissionAreReciprocal) {
  PrincipledParams p{.base_color = RGB(0.8f, 0.5f, 0.3f), .roughness = 0.45f, .anisotropic = 0.6f, .metallic = 0.3f,
                     .spec_tint = 0.5f, .spec_trans = 0.4f, .sheen = 0.7f, .sheen_tint = 0.4f, .clearcoat = 0.8f,
                     .clearcoat_gloss = 0.5f, .flatness = 0.5f, .diff_trans = 0.7f};
  PrincipledBsdf b(p);
  PrincipledThinBsdf t(p);
  Rng rng(4, 4);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3 a = random_direction(rng), c = random_direction(rng);
    if (std::abs(a.z) < 1e-2f || std::abs(c.z) < 1e-2f) continue;
    if (same_hemisphere(a, c) || thin_transmission_masks_agree(a, c)) {
      RGB t_ac = t.eval(a, c), t_ca = t.eval(c, a);
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(t_ac[k], t_ca[k], 1e-3f * (1e-3f + t_ac[k])) << "thin";
    }
    if (!same_hemisphere(a, c)) continue;
    RGB f_ac = b.eval(a, c), f_ca = b.eval(c, a);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(f_ac[k], f_ca[k], 1e-3f * (1e-3f + f_ac[k])) << "principled";
    ++checked;
  }
  EXPECT_GT(checked, 8000);
}

TEST(PrincipledReciprocity, TransmissionCarriesTheRadianceScaling) {
  // The refracted part follows Walter et al. for radiance: f(wi, wo) = eta'^2 f(wo, wi), eta' the
  // relative IOR crossed from wo's side (what bsdf_adjoint_scale turns into the adjoint).
  PrincipledParams p{.base_color = RGB(0.6f, 0.7f, 0.9f), .roughness = 0.5f, .spec_trans = 0.9f, .eta = 1.4f};
  PrincipledBsdf b(p);
  Rng rng(6, 6);
  int checked = 0;
  for (int i = 0; i < 40000; ++i) {
    Vec3 wo = random_direction(rng), wi = random_direction(rng);
    if (same_hemisphere(wo, wi) || std::min(std::abs(wo.z), std::abs(wi.z)) < 0.05f) continue;
    float etap = wo.z > 0 ? p.eta : 1 / p.eta;
    Vec3 wm = normalize(wo + wi * etap);
    if (std::min(std::abs(dot(wm, wo)), std::abs(dot(wm, wi))) < 0.05f) continue;  // ill-conditioned 1 - F
    RGB f = b.eval(wo, wi) * (etap * etap), f_rev = b.eval(wi, wo);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(f[k], f_rev[k], 2e-3f * std::max(f[k], f_rev[k]) + 1e-7f);
    if (f.max_component() > 0) ++checked;
  }
  EXPECT_GT(checked, 2000);
}

// ---------------------------------------------------------------- the material

// MaterialTable::bsdf gives a Bsdf, or a SurfaceBsdf (a mixture) where wrappers are supported.
template <typename T>
const Bsdf& as_bsdf(const T& b) {
  if constexpr (std::is_same_v<T, Bsdf>) return b;
  else return b.components[0].bsdf;
}

TEST(PrincipledMaterialTable, BuildsBothModelsFromTexturedInputs) {
  TextureSet textures({CheckerboardTexture{ColorInput(RGB(0.7f)), ColorInput(RGB(0.1f)), {}}});
  PrincipledMaterial opaque;
  opaque.base_color = RGB(0.2f, 0.8f, 0.1f);
  opaque.roughness = 0.15f;
  opaque.metallic.texture = 0;
  opaque.specular = 0.7f;
  opaque.clearcoat = 0.9f;
  opaque.sheen = 0.2f;
  PrincipledMaterial thin;
  thin.thin = true;
  thin.eta = 1.33f;
  thin.eta_given = true;
  thin.spec_trans = 0.2f;
  thin.diff_trans.texture = 0;
  PrincipledMaterial glass;  // specular 0 with transmission: Mitsuba uses 1e-3
  glass.spec_trans = 1;
  glass.specular = 0;
  PrincipledMaterial glass_eta;  // eta 1 with transmission: Mitsuba uses 1.001
  glass_eta.spec_trans.texture = 0;
  glass_eta.eta = 1;
  glass_eta.eta_given = true;
  MaterialTable table({opaque, thin, glass, glass_eta}, textures);
  TextureEvalContext on_tex1, on_tex2;
  on_tex1.uv = Vec2(0.25f, 0.25f);
  on_tex2.uv = Vec2(1.25f, 0.25f);

  for (const auto& [ctx, metallic] : {std::pair{on_tex1, 0.7f}, std::pair{on_tex2, 0.1f}}) {
    auto built = table.bsdf(0, ctx);
    const auto* b = std::get_if<PrincipledBsdf>(&as_bsdf(built));
    ASSERT_TRUE(b);
    EXPECT_NEAR(b->metallic, metallic, 1e-6f);
    PrincipledParams p{.base_color = opaque.base_color.value, .roughness = 0.15f, .metallic = metallic, .sheen = 0.2f,
                       .clearcoat = 0.9f, .eta = principled_eta_from_specular(0.7f)};
    RGB expected = PrincipledBsdf(p).eval(direction(30), direction(45, 200)), f = b->eval(direction(30), direction(45, 200));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], expected[k], 1e-6f * (1 + expected[k]));
  }
  auto built_thin = table.bsdf(1, on_tex2);
  const auto* t = std::get_if<PrincipledThinBsdf>(&as_bsdf(built_thin));
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->diff_trans, 0.05f, 1e-6f);  // Mitsuba's diff_trans / 2
  EXPECT_NEAR(t->eta, 1.33f, 1e-6f);
  auto built_glass = table.bsdf(2, on_tex1);
  const auto* g = std::get_if<PrincipledBsdf>(&as_bsdf(built_glass));
  ASSERT_TRUE(g);
  EXPECT_NEAR(g->eta, principled_eta_from_specular(1e-3f), 1e-6f);
  EXPECT_TRUE(g->has_non_delta_transmission());
  auto built_glass_eta = table.bsdf(3, on_tex1);
  const auto* ge = std::get_if<PrincipledBsdf>(&as_bsdf(built_glass_eta));
  ASSERT_TRUE(ge);
  EXPECT_FLOAT_EQ(ge->eta, 1.001f);
  EXPECT_FLOAT_EQ(bsdf_adjoint_scale(as_bsdf(built_glass_eta), direction(30), -direction(20)), 1.001f * 1.001f);
}

}  // namespace
}  // namespace candela
