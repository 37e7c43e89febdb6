// pbrt-v4's layered BSDFs (layered.h): energy (white furnaces), the limit in which the coated
// diffuse has a closed form, the exact sampling density where it is known, determinism and seeds,
// the slab's absorption, the u_lobe contract where both interfaces are smooth, the colours at a
// spectral sample's wavelengths, and how the material table builds and seeds them. The statistical
// check of sample weights against eval() for the general case is the BSDF contract's
// (bsdf_contract_test.cpp, testing/stochastic_bsdf.h).
#include "candela/materials/layered.h"

#include <gtest/gtest.h>

#include "candela/materials/material.h"
#include "candela/materials/spectral_bsdf.h"
#include "candela/sampling/warp.h"
#include "candela/spectral/wavelengths.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/stochastic_bsdf.h"

namespace candela {
namespace {

using testing::below;
using testing::direction;
using testing::Estimate;

LayeredDiffuseBsdf coated_diffuse(float alpha, RGB reflectance, float thickness, int max_depth = 10) {
  LayeredDiffuseBsdf b;
  b.top = CoatInterface{1.5f, TrowbridgeReitz(alpha, alpha)};
  b.bottom = DiffuseBsdf{reflectance};
  b.thickness = thickness;
  b.max_depth = uint16_t(max_depth);
  return b;
}

// The directional albedo from eval(): the coat's delta reflection (smooth coats) plus the integral
// of eval |cos| by cosine sampling, every eval() with a seed of its own.
Estimate eval_albedo(LayeredDiffuseBsdf b, const Vec3& wo, int n = 200000) {
  Rng rng(21, 22);
  const double delta = b.top.is_specular() ? fresnel_dielectric(std::abs(wo.z), b.top.eta) : 0.0;
  uint32_t seed = 0;
  return testing::sample_mean(n, [&] {
    Vec3 wi = square_to_cosine_hemisphere({rng.next_float(), rng.next_float()});
    if (wo.z < 0) wi.z = -wi.z;
    b.seed = seed++;
    return delta + double(b.eval(wo, wi).g) * kPi;
  });
}

// A white coat over a white Lambertian base with nothing between them absorbs nothing: every
// sampled path leaves with weight 1 (so the estimate is exact, not merely within noise), and eval()
// integrates to 1 - F(wo) beside the coat's mirror reflection F(wo). A white scattering slab
// between them absorbs nothing either. (The walk is cut after max_depth events, here made long
// enough that what it cuts is below 1e-9.)
TEST(LayeredBsdf, WhiteFurnaceWithoutAbsorptionIsOne) {
  for (float theta : {0.0f, 45.0f, 80.0f}) {
    const Vec3 wo = direction(theta);
    LayeredDiffuseBsdf empty = coated_diffuse(0, RGB(1.0f), 0, 1000);
    Estimate sampled = testing::albedo(Bsdf(empty), wo, 100000);
    EXPECT_NEAR(sampled.mean, 1.0, 1e-5) << theta;
    Estimate evaluated = eval_albedo(empty, wo);
    EXPECT_NEAR(evaluated.mean, 1.0, 4 * evaluated.standard_error) << theta;
    EXPECT_LT(evaluated.standard_error, 2e-3);

    LayeredDiffuseBsdf scattering = coated_diffuse(0, RGB(1.0f), 1.0f, 5000);
    scattering.albedo = RGB(1.0f);
    scattering.g = 0.5f;
    Estimate slab = testing::albedo(Bsdf(scattering), wo, 100000);
    EXPECT_NEAR(slab.mean, 1.0, 1e-5) << theta;
    Estimate slab_eval = eval_albedo(scattering, wo, 100000);
    EXPECT_NEAR(slab_eval.mean, 1.0, 4 * slab_eval.standard_error + 2e-3) << theta;
  }
  // Seen from below (two-sided), the same.
  EXPECT_NEAR(testing::albedo(Bsdf(coated_diffuse(0, RGB(1.0f), 0, 1000)), below(direction(30)), 20000).mean, 1.0, 1e-5);
}

// A rough coat loses what its microfacets shadow, as every single-scattering microfacet BSDF does
// (pbrt-v4's too): from inside, where light meets the coat again and again, about 10% per meeting
// at alpha 0.3. Nothing gains energy.
TEST(LayeredBsdf, RoughCoatLosesWhatItsMicrofacetsShadow) {
  for (float alpha : {0.1f, 0.3f}) {
    Estimate a = testing::albedo(Bsdf(coated_diffuse(alpha, RGB(1.0f), 0, 1000)), direction(45), 100000);
    EXPECT_LT(a.mean, 1.0);
    EXPECT_GT(a.mean, alpha < 0.2f ? 0.9 : 0.65) << alpha;
  }
}

// The slab with albedo 0 absorbs exp(-thickness / |cos|) on each crossing: the thicker, the darker.
TEST(LayeredBsdf, AbsorbingSlabDarkensWithThickness) {
  const Vec3 wo = direction(0);
  double previous = 2;
  for (float thickness : {0.0f, 0.05f, 0.2f, 1.0f}) {
    Estimate a = testing::albedo(Bsdf(coated_diffuse(0, RGB(0.8f), thickness)), wo, 100000);
    EXPECT_LT(a.mean, previous) << thickness;
    previous = a.mean;
  }
  // Thickness 0: nothing between coat and base (pbrt-v4 clamps it to the smallest float, whose
  // transmittance is exactly 1).
  EXPECT_NEAR(testing::albedo(Bsdf(coated_diffuse(0, RGB(1.0f), 0, 1000)), wo, 10000).mean, 1.0, 1e-5);
}

// In the limit the closed form models -- a smooth coat touching a Lambertian base (thickness 0, no
// medium) -- pbrt-v4's random walk sums the same series of internal reflections as the closed form
// with Mitsuba's nonlinear denominator: f = R (1 - F(wi)) (1 - F(wo)) / (pi eta^2 (1 - Fdr R)). They
// agree within the Monte Carlo error (here about 0.5%) once the walk is long enough; pbrt-v4's
// default max_depth of 10 cuts the series after 5 bounces at the base, about (R Fdr)^5 low (1.3%
// for R = 0.7). With a rough coat they differ (by about 10% at alpha 0.3): the closed form keeps the
// smooth Fresnel factors, the walk meets the rough interface and its shadowing.
TEST(LayeredBsdf, ThinSmoothCoatAgreesWithTheClosedForm) {
  const RGB R(0.7f, 0.5f, 0.3f);
  LayeredDiffuseBsdf layered = coated_diffuse(0, R, 0, 100);
  const CoatedDiffuseBsdf closed{R, RGB(1.0f), 1.5f, TrowbridgeReitz(0, 0), /*nonlinear=*/true};
  const std::pair<float, float> pairs[] = {{0, 0}, {30, 60}, {60, 20}, {75, 75}};
  for (auto [theta_o, theta_i] : pairs) {
    const Vec3 wo = direction(theta_o, 10), wi = direction(theta_i, 200);
    const RGB expected = closed.eval(wo, wi);
    for (int c = 0; c < 3; ++c) {
      uint32_t seed = 0;
      Estimate e = testing::sample_mean(20000, [&] {
        layered.seed = seed++;
        return double(layered.eval(wo, wi)[c]);
      });
      EXPECT_NEAR(e.mean, expected[c], 4 * e.standard_error) << theta_o << " " << theta_i << " channel " << c;
      EXPECT_NEAR(e.mean / expected[c], 1.0, 0.02) << theta_o << " " << theta_i << " channel " << c;
    }
  }
  // The albedos too (sample() against the closed form's, delta reflection included).
  for (float theta : {0.0f, 45.0f, 80.0f}) {
    Estimate a = testing::albedo(Bsdf(layered), direction(theta), 200000);
    Estimate b = testing::albedo(Bsdf(closed), direction(theta), 200000);
    EXPECT_NEAR(a.mean, b.mean, 4 * std::hypot(a.standard_error, b.standard_error)) << theta;
  }
}

// Through a smooth coat over a Lambertian base (no slab) each walk leaves in a direction whose
// density is that of the base's cosine lobe refracted out, weighted by the coat's transmittance:
// (1 - F(wi)) cos(theta_i) / (pi (1 - Fdr)), Fdr the coat's diffuse reflectance from outside,
// whatever the number of internal bounces. sample()'s non-delta directions must follow it
// (chi-square). pdf() is not this density -- it is pbrt-v4's approximation for MIS -- so it is not
// the one tested.
TEST(LayeredBsdf, SampledDirectionsThroughASmoothCoatFollowTheRefractedCosine) {
  const LayeredDiffuseBsdf b = coated_diffuse(0, RGB(0.6f), 0, 100);
  const double normalisation = kPi * (1 - fresnel_diffuse_reflectance(1.5f));
  for (float theta : {10.0f, 70.0f}) {
    const Vec3 wo = direction(theta);
    Rng rng(5, 6);
    auto sample = [&](Vec2 u) {
      for (int tries = 0; tries < 1000; ++tries) {
        auto s = b.sample(wo, rng.next_float(), u);
        if (s && !s->is_delta) return s->wi;
        u = Vec2(rng.next_float(), rng.next_float());
      }
      return Vec3(0.0f);
    };
    auto density = [&](const Vec3& wi) {
      if (wi.z <= 0) return 0.0f;
      return float((1 - fresnel_dielectric(wi.z, 1.5f)) * wi.z / normalisation);
    };
    double p = testing::spherical_chi_square_p_value(sample, density, 200000, 31, 0, 10, 20, 12);
    EXPECT_GT(p, testing::kChiSquareAlpha) << theta;
  }
}

// eval() and pdf() are fixed functions of (seed, wo, wi); another seed gives another estimate.
// pdf() is positive wherever eval() is (on wo's side) and both are zero on the other side.
TEST(LayeredBsdf, EstimatesAreFixedPerSeedAndDirections) {
  LayeredDiffuseBsdf b = coated_diffuse(0.3f, RGB(0.6f), 0.1f);
  b.albedo = RGB(0.5f);
  b.seed = 7;
  const Vec3 wo = direction(40), wi = direction(25, 140);
  const RGB f = b.eval(wo, wi);
  const float p = b.pdf(wo, wi);
  EXPECT_EQ(b.eval(wo, wi), f);
  EXPECT_EQ(b.pdf(wo, wi), p);
  LayeredDiffuseBsdf other = b;
  other.seed = 8;
  EXPECT_NE(other.eval(wo, wi), f);
  // The same sample for the same numbers.
  auto s1 = b.sample(wo, 0.3f, {0.2f, 0.7f}), s2 = b.sample(wo, 0.3f, {0.2f, 0.7f});
  ASSERT_EQ(bool(s1), bool(s2));
  if (s1) {
    EXPECT_EQ(s1->wi, s2->wi);
    EXPECT_EQ(s1->weight, s2->weight);
  }
  Rng rng(3, 4);
  for (int i = 0; i < 2000; ++i) {
    Vec3 w = testing::random_direction(rng);
    b.seed = rng.next_u32();
    if (same_hemisphere(wo, w)) {
      EXPECT_GT(b.pdf(wo, w), 0.0f);
    } else {
      EXPECT_EQ(b.eval(wo, w), RGB(0.0f));
      EXPECT_EQ(b.pdf(wo, w), 0.0f);
    }
  }
}

// Both interfaces smooth and a scattering slab between: u_lobe above the coat's transmittance is
// the coat's mirror reflection (delta); below it, walks that the slab scattered are non-delta and
// walks it did not are delta (the exception to the u_lobe contract that layered.h states).
TEST(LayeredBsdf, SmoothCoatOverSmoothMetalWithAScatteringSlab) {
  LayeredConductorBsdf b;
  b.top = CoatInterface{1.5f, TrowbridgeReitz(0, 0)};
  b.bottom = ConductorBsdf{RGB(0.2f) / 1.5f, RGB(3.9f) / 1.5f, RGB(1.0f), TrowbridgeReitz(0, 0)};
  b.thickness = 0.3f;
  b.albedo = RGB(0.8f);
  const Vec3 wo = direction(30);
  const float threshold = b.non_delta_probability(wo);
  EXPECT_NEAR(threshold, 1 - fresnel_dielectric(wo.z, 1.5f), 1e-6f);
  Rng rng(9, 10);
  int delta_below = 0, non_delta_below = 0;
  for (int i = 0; i < 20000; ++i) {
    float u_lobe = rng.next_float();
    auto s = b.sample(wo, u_lobe, {rng.next_float(), rng.next_float()});
    if (!s) continue;
    if (u_lobe >= threshold) {
      EXPECT_TRUE(s->is_delta);
      EXPECT_EQ(s->wi, reflect_local(wo));
    } else {
      (s->is_delta ? delta_below : non_delta_below) += 1;
    }
  }
  EXPECT_GT(delta_below, 100);
  EXPECT_GT(non_delta_below, 100);
  // Without the slab the whole BSDF is delta: eval() and pdf() are zero.
  b.albedo = RGB(0.0f);
  EXPECT_FALSE(b.has_non_delta());
  EXPECT_EQ(b.non_delta_probability(wo), 0.0f);
  EXPECT_EQ(b.eval(wo, direction(50)), RGB(0.0f));
  EXPECT_EQ(b.pdf(wo, direction(50)), 0.0f);
  auto s = b.sample(wo, 0.1f, {0.5f, 0.5f});
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->is_delta);
}

// At a spectral sample's wavelengths the base's reflectance and the slab's albedo become
// reflectance spectra and the conductor's eta and k (relative to the coat) unbounded ones, as
// for a bare conductor.
TEST(LayeredBsdf, ColoursAtWavelengths) {
  const Wavelengths wl = sample_visible_wavelengths(0.3f);
  LayeredConductorBsdf metal;
  metal.bottom = ConductorBsdf{RGB(0.2f, 0.9f, 1.1f) / 1.5f, RGB(3.9f, 2.4f, 2.1f) / 1.5f, RGB(1.0f), TrowbridgeReitz(0.1f)};
  metal.albedo = RGB(0.2f, 0.5f, 0.8f);
  Bsdf spectral = metal;
  bsdf_at_wavelengths(spectral, wl);
  const auto& m = std::get<LayeredConductorBsdf>(spectral);
  EXPECT_EQ(m.bottom.eta, unbounded_at(metal.bottom.eta, wl));
  EXPECT_EQ(m.bottom.k, unbounded_at(metal.bottom.k, wl));
  EXPECT_EQ(m.albedo, reflectance_at(metal.albedo, wl));
  LayeredDiffuseBsdf diffuse = coated_diffuse(0.1f, RGB(0.7f, 0.2f, 0.1f), 0.01f);
  Bsdf spectral_diffuse = diffuse;
  bsdf_at_wavelengths(spectral_diffuse, wl);
  EXPECT_EQ(std::get<LayeredDiffuseBsdf>(spectral_diffuse).bottom.reflectance,
            reflectance_at(diffuse.bottom.reflectance, wl));
}

// The material table builds the coated conductor with the conductor's index relative to the coat
// (as pbrt-v4 divides it), pbrt's artist mode from a reflectance, and gives each shading point a
// seed of its own: the same for the same hit, another for another.
TEST(LayeredBsdf, MaterialTableBuildsAndSeedsPerHit) {
  LayeredConductorMaterial gold;
  gold.ior = 1.6f;
  gold.eta = RGB(0.15f, 0.37f, 1.44f);
  gold.k = RGB(3.98f, 2.39f, 1.60f);
  gold.conductor_roughness.u = gold.conductor_roughness.v = FloatInput(0.2f);
  gold.layer.thickness = FloatInput(0.05f);
  gold.layer.samples = 2;
  LayeredConductorMaterial artist;
  artist.reflectance = ColorInput(RGB(0.9f, 0.6f, 0.3f));
  LayeredDiffuseMaterial plastic;
  plastic.layer.albedo = ColorInput(RGB(0.3f));
  plastic.layer.g = FloatInput(1.0f);
  static TextureSet textures;
  MaterialTable table(std::vector<MaterialDesc>{gold, artist, plastic}, textures);
  SurfaceHit hit;
  hit.p = Point3(0.25f, 1, -2);
  hit.ng = hit.ns = Normal3(0, 0, 1);
  hit.dpdu = Vec3(1, 0, 0);
  const Vec3 wo(0, 0, 1);
  Shading a = table.shading(0, TextureEvalContext{}, hit, wo);
  const auto& built = std::get<LayeredConductorBsdf>(a.bsdf.components[0].bsdf);
  EXPECT_EQ(built.top.eta, 1.6f);
  EXPECT_EQ(built.bottom.eta, gold.eta.value / 1.6f);
  EXPECT_EQ(built.bottom.k, gold.k.value / 1.6f);
  EXPECT_FLOAT_EQ(built.bottom.distribution.alpha_x(), 0.2f);
  EXPECT_EQ(built.thickness, 0.05f);
  EXPECT_EQ(built.samples, 2);
  EXPECT_EQ(built.max_depth, 10);
  const Shading from_reflectance_shading = table.shading(1, TextureEvalContext{}, hit, wo);
  const auto& from_reflectance = std::get<LayeredConductorBsdf>(from_reflectance_shading.bsdf.components[0].bsdf);
  EXPECT_EQ(from_reflectance.bottom.eta, RGB(1.0f) / 1.5f);
  EXPECT_EQ(from_reflectance.bottom.k, conductor_k_from_reflectance(RGB(0.9f, 0.6f, 0.3f)) / 1.5f);
  const Shading diffuse_shading = table.shading(2, TextureEvalContext{}, hit, wo);
  const auto& diffuse = std::get<LayeredDiffuseBsdf>(diffuse_shading.bsdf.components[0].bsdf);
  EXPECT_EQ(diffuse.albedo, RGB(0.3f));
  EXPECT_LT(diffuse.g, 1.0f);  // kept where Henyey-Greenstein is finite
  EXPECT_GT(diffuse.g, 0.99f);

  const uint32_t seed = built.seed;
  EXPECT_EQ(std::get<LayeredConductorBsdf>(table.shading(0, TextureEvalContext{}, hit, wo).bsdf.components[0].bsdf).seed,
            seed);
  SurfaceHit elsewhere = hit;
  elsewhere.p.x += 1e-3f;
  EXPECT_NE(std::get<LayeredConductorBsdf>(table.shading(0, TextureEvalContext{}, elsewhere, wo).bsdf.components[0].bsdf).seed,
            seed);
}

}  // namespace
}  // namespace candela
