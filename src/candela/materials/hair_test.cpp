// pbrt-v4's hair BSDF (hair.h): the white furnace (sigma_a = 0 scatters all light: f |cos| integrates
// to 1 over the sphere for every wo and h), by Monte Carlo within its standard error and by
// quadrature; sampling's density against pdf() (chi-square) and its weights; absorption; the
// lobes where the smooth cylinder sends them; pbrt-v4's sigma_a from concentrations and colours; the
// spectral form; and the material that builds it (h from the hit's v). The contract's per-sample
// checks are in bsdf_contract_test.cpp.
#include "candela/materials/hair.h"

#include <gtest/gtest.h>

#include <cmath>

#include "candela/materials/material.h"
#include "candela/materials/spectral_bsdf.h"
#include "candela/materials/surface_bsdf.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/bsdf_chi_square.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

struct HairSetting {
  float h, beta_m, beta_n, alpha;
};
// Smooth to rough, on and off the fibre's axis, tilted scales or not.
const HairSetting kHairSettings[] = {
    {0.0f, 0.1f, 0.1f, 0}, {-0.9f, 0.1f, 0.9f, 2}, {0.5f, 0.3f, 0.3f, 2}, {0.99f, 0.3f, 0.8f, 5},
    {-0.4f, 0.7f, 0.1f, 2}, {0.2f, 1.0f, 1.0f, 0}, {0.7f, 0.05f, 0.5f, 10},
};
// Outgoing directions: across the fibre, oblique, nearly along it, below the shading normal.
const Vec3 kHairOutgoing[] = {normalize(Vec3(0, 0.3f, 1)), normalize(Vec3(0.5f, -0.6f, 0.4f)),
                              normalize(Vec3(-0.97f, 0.1f, 0.2f)), normalize(Vec3(0.3f, 0.4f, -0.8f))};

HairBsdf white_hair(const HairSetting& s) { return HairBsdf(s.h, 1.55f, RGB(0.0f), s.beta_m, s.beta_n, s.alpha); }

// The integral over the sphere of g(wi) by the midpoint rule on a grid uniform in sin(theta) = wi.x
// and phi (dw = d(sin theta) dphi).
template <typename G>
double hair_quadrature(G&& g, int n) {
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double x = -1 + 2 * (i + 0.5) / n, c = std::sqrt(1 - x * x);
    for (int j = 0; j < 2 * n; ++j) {
      const double phi = 2 * kPi * (j + 0.5) / (2 * n);
      sum += g(Vec3(float(x), float(c * std::cos(phi)), float(c * std::sin(phi))));
    }
  }
  return sum * (2.0 / n) * (2 * kPi / (2 * n));
}

// As pbrt-v4's Hair.WhiteFurnace: with nothing absorbed, f |cos| integrated over the sphere by
// uniform sampling is 1, for every wo, h and roughness; here within 4.5 standard errors of the
// estimate (its variance is large where lobes are narrow, so more samples there).
TEST(Hair, WhiteFurnaceIntegratesToOne) {
  Rng rng(5, 6);
  for (const HairSetting& s : kHairSettings) {
    const HairBsdf b = white_hair(s);
    const int n = s.beta_m < 0.2f || s.beta_n < 0.2f ? 400000 : 100000;
    for (const Vec3& wo : {kHairOutgoing[1], kHairOutgoing[2], kHairOutgoing[3]}) {
      testing::Estimate e = testing::sample_mean(n, [&] {
        const Vec3 wi = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
        return double(b.eval(wo, wi).g) * std::abs(wi.z) * (4 * kPi);
      });
      EXPECT_NEAR(e.mean, 1.0, 4.5 * e.standard_error)
          << "h " << s.h << " beta_m " << s.beta_m << " beta_n " << s.beta_n << " wo " << wo.x << " " << wo.y << " "
          << wo.z << ": " << e.mean << " +- " << e.standard_error;
      EXPECT_LT(e.standard_error, 0.05);  // small enough for the test to mean something
    }
  }
}

// The same integrals, and that of pdf(), by quadrature: 1 to the quadrature's accuracy.
TEST(Hair, WhiteFurnaceAndPdfByQuadrature) {
  for (const HairSetting& s : kHairSettings) {
    if (s.beta_m < 0.1f) continue;  // lobes narrower than the grid resolves
    const HairBsdf b = white_hair(s);
    for (const Vec3& wo : {kHairOutgoing[1], kHairOutgoing[3]}) {
      double f = hair_quadrature([&](const Vec3& wi) { return double(b.eval(wo, wi).g) * std::abs(wi.z); }, 300);
      double p = hair_quadrature([&](const Vec3& wi) { return double(b.pdf(wo, wi)); }, 300);
      EXPECT_NEAR(f, 1.0, 2e-3) << "h " << s.h << " beta_m " << s.beta_m << " beta_n " << s.beta_n;
      EXPECT_NEAR(p, 1.0, 2e-3) << "h " << s.h << " beta_m " << s.beta_m << " beta_n " << s.beta_n;
    }
  }
}

// As pbrt-v4's Hair.WhiteFurnaceSampled: without absorption every path's share of the light is
// the probability of sampling it, so every sample's weight is 1.
TEST(Hair, WhiteFurnaceSampleWeightsAreOne) {
  Rng rng(7, 8);
  for (const HairSetting& s : kHairSettings) {
    const HairBsdf b = white_hair(s);
    int samples = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec3 wo = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
      auto bs = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
      if (!bs) continue;
      ++samples;
      ASSERT_NEAR(bs->weight.g, 1.0f, 2e-3f) << "h " << s.h << " beta_m " << s.beta_m << " beta_n " << s.beta_n;
    }
    EXPECT_GT(samples, 19900);
  }
}

// Sampling draws directions with the density pdf() reports: each sample's pdf is pdf(wo, wi), and
// the directions pass a chi-square test against pdf() (binned about the fibre's axis, along which
// the longitudinal lobes are cones).
TEST(Hair, SamplingMatchesPdf) {
  const RGB brown = hair_sigma_a_from_concentration(1.3f, 0.2f);
  struct SamplingCase {
    HairSetting s;
    Vec3 wo;
  };
  const SamplingCase cases[] = {{{0.5f, 0.3f, 0.3f, 2}, kHairOutgoing[0]},
                                {{0.5f, 0.3f, 0.3f, 2}, kHairOutgoing[3]},
                                {{-0.9f, 0.6f, 0.8f, 5}, kHairOutgoing[1]},
                                {{0.1f, 0.2f, 0.5f, 0}, kHairOutgoing[2]}};
  testing::Binning binning;
  binning.axis = Vec3(1, 0, 0);
  binning.resolution = 16;
  Rng rng(9, 10);
  for (const auto& [s, wo] : cases) {
    const HairBsdf b(s.h, 1.55f, brown, s.beta_m, s.beta_n, s.alpha);
    for (int i = 0; i < 2000; ++i) {
      auto bs = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()});
      ASSERT_TRUE(bs.has_value());
      ASSERT_FALSE(bs->is_delta);
      ASSERT_NEAR(bs->pdf, b.pdf(wo, bs->wi), 1e-5f * bs->pdf);
    }
    double p = testing::bsdf_chi_square(Bsdf(b), wo, binning);
    EXPECT_GT(p, testing::kChiSquareAlpha)
        << "h " << s.h << " beta_m " << s.beta_m << " beta_n " << s.beta_n << " wo " << wo.x << " " << wo.y << " "
        << wo.z;
  }
}

// Absorption darkens the fibre, more the more it absorbs, and the red channel least for melanin
// (whose absorption rises towards blue); a sample's weight is eval |cos| / pdf on average.
TEST(Hair, AbsorptionDarkensAndTints) {
  Rng rng(1, 2);
  const Vec3 wo = kHairOutgoing[1];
  double previous = 1.01;
  for (float eumelanin : {0.0f, 0.3f, 1.3f, 8.0f}) {
    const HairBsdf b(0.3f, 1.55f, hair_sigma_a_from_concentration(eumelanin, 0), 0.3f, 0.3f, 2);
    RGB sum(0.0f);
    const int n = 100000;
    for (int i = 0; i < n; ++i)
      if (auto bs = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()})) sum += bs->weight;
    const RGB mean = sum / float(n);
    EXPECT_LT(mean.g, previous) << "eumelanin " << eumelanin;
    if (eumelanin > 0) {
      EXPECT_GT(mean.r, mean.g);
      EXPECT_GT(mean.g, mean.b);
    }
    previous = mean.g;
  }
  // Even the darkest fibre reflects its surface's Fresnel share (the R lobe).
  EXPECT_GT(previous, 0.02);
}

// The lobes lie where the smooth cylinder sends light: at h = 0 and across the fibre, R straight back
// towards wo (phi_i = phi_o) and TT straight through (phi_i = phi_o + pi), mirrored in theta.
TEST(Hair, LobesWhereTheSmoothCylinderSendsThem) {
  const HairBsdf b(0, 1.55f, RGB(0.0f), 0.1f, 0.1f, 0);
  const float theta = 0.3f;
  const Vec3 wo(std::sin(theta), 0, std::cos(theta));  // phi_o = pi / 2
  const Vec3 back(-std::sin(theta), 0, std::cos(theta)), through(-std::sin(theta), 0, -std::cos(theta));
  const Vec3 aside(-std::sin(theta), std::cos(theta), 0);
  EXPECT_GT(b.eval(wo, back).g, 20 * b.eval(wo, aside).g);
  EXPECT_GT(b.eval(wo, through).g, 20 * b.eval(wo, aside).g);
  // Off the mirror cone the longitudinal lobe falls off.
  const Vec3 off(std::sin(theta), 0, std::cos(theta));
  EXPECT_GT(b.eval(wo, back).g, 20 * b.eval(wo, off).g);
  // The cuticle tilt moves R's peak by -2 alpha: with alpha > 0, R peaks below the mirror angle.
  const HairBsdf tilted(0, 1.55f, RGB(0.0f), 0.1f, 0.1f, 5);
  auto r_at = [&](float t) { return tilted.eval(wo, Vec3(-std::sin(t), 0, std::cos(t))).g * std::cos(t); };
  EXPECT_GT(r_at(theta - radians(10)), r_at(theta + radians(10)));
}

// Hair is not reciprocal: paths that carry importance use the adjoint f*(wo, wi) = f(wi, wo), in
// a surface's mixture too, where a reciprocal BSDF's adjoint is eval() (times refraction's scale).
TEST(Hair, AdjointSwapsTheDirections) {
  const HairBsdf hair(0.4f, 1.55f, hair_sigma_a_from_concentration(0.8f, 0.1f), 0.3f, 0.4f, 2);
  SurfaceBsdf mixture;
  mixture.add(hair, 0.5f, false);
  mixture.add(DiffuseBsdf{RGB(0.5f)}, 0.5f, false);
  EXPECT_FALSE(mixture.is_reciprocal());
  EXPECT_FALSE(SurfaceBsdf(hair).is_reciprocal());
  EXPECT_TRUE(SurfaceBsdf(DiffuseBsdf{RGB(0.5f)}).is_reciprocal());
  Rng rng(3, 4);
  int differ = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 wo = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3 wi = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    const RGB swapped = hair.eval(wi, wo);
    EXPECT_EQ(bsdf_eval_adjoint(Bsdf(hair), wo, wi), swapped);
    EXPECT_EQ(SurfaceBsdf(hair).eval_adjoint(wo, wi), swapped);
    const RGB mixed = mixture.eval_adjoint(wo, wi), expected = swapped * 0.5f + RGB(0.25f * kInvPi) * float(same_hemisphere(wo, wi));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(mixed[k], expected[k], 1e-5f * (1 + expected[k]));
    differ += std::abs(swapped.g - hair.eval(wo, wi).g) > 1e-3f * swapped.g;
  }
  EXPECT_GT(differ, 150);  // not reciprocal, so the swap matters
}

TEST(Hair, SigmaAFromConcentrationAndColour) {
  RGB brown = hair_sigma_a_from_concentration(1.3f, 0);
  EXPECT_NEAR(brown.r, 1.3f * 0.419f, 1e-6f);
  EXPECT_NEAR(brown.g, 1.3f * 0.697f, 1e-6f);
  EXPECT_NEAR(brown.b, 1.3f * 1.37f, 1e-6f);
  RGB red = hair_sigma_a_from_concentration(0, 2);
  EXPECT_NEAR(red.r, 2 * 0.187f, 1e-6f);
  EXPECT_NEAR(red.b, 2 * 1.05f, 1e-6f);
  // Chiang et al.'s fit: white absorbs nothing, darker absorbs more, black everything.
  EXPECT_EQ(hair_sigma_a_from_reflectance(1.0f, 0.3f), 0.0f);
  EXPECT_GT(hair_sigma_a_from_reflectance(0.2f, 0.3f), hair_sigma_a_from_reflectance(0.6f, 0.3f));
  EXPECT_TRUE(std::isinf(hair_sigma_a_from_reflectance(0.0f, 0.3f)));
  // At beta_n = 0.3: (ln 0.5 / (5.969 - 0.0645 + 0.22788 - 0.28971 + 0.045149 + 0.000595))^2.
  EXPECT_NEAR(hair_sigma_a_from_reflectance(0.5f, 0.3f), 0.0138565f, 1e-6f);
  // A fibre that absorbs everything it lets in reflects only the R lobe.
  HairBsdf black(0.2f, 1.55f, RGB(0.0f), 0.3f, 0.3f, 2);
  black.color = RGB(0.0f);
  black.sigma_a_from_color = true;
  black.resolve_color();
  const Vec3 wo = kHairOutgoing[0];
  auto s = black.sample(wo, 0.99f, {0.3f, 0.6f});
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->weight.is_finite());
}

// In a spectral render sigma_a is an unbounded spectrum (a constant one stays as it is), a colour a
// reflectance spectrum turned into sigma_a per wavelength, and the path choice averages four lanes.
TEST(Hair, SpectralForm) {
  Wavelengths wl = sample_visible_wavelengths(0.37f);
  Bsdf grey = HairBsdf(0.1f, 1.55f, RGB(0.8f), 0.3f, 0.3f, 2);
  bsdf_at_wavelengths(grey, wl);
  const auto& g = std::get<HairBsdf>(grey);
  EXPECT_EQ(g.lanes, 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(g.sigma_a[i], 0.8f, 1e-5f);
  HairBsdf coloured(0.1f, 1.55f, RGB(0.0f), 0.3f, 0.5f, 2);
  coloured.color = RGB(0.5f);
  coloured.sigma_a_from_color = true;
  coloured.resolve_color();
  Bsdf c = coloured;
  bsdf_at_wavelengths(c, wl);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(std::get<HairBsdf>(c).sigma_a[i], hair_sigma_a_from_reflectance(0.5f, 0.5f), 1e-4f);
  // Melanin's sigma_a varies over the wavelengths (more absorbed towards blue).
  Bsdf brown = HairBsdf(0.1f, 1.55f, hair_sigma_a_from_concentration(1.3f, 0), 0.3f, 0.3f, 2);
  Wavelengths ends;
  ends.lambda[0] = 450;
  ends.lambda[1] = 500;
  ends.lambda[2] = 600;
  ends.lambda[3] = 650;
  for (float& p : ends.pdf) p = 1;
  bsdf_at_wavelengths(brown, ends);
  EXPECT_GT(std::get<HairBsdf>(brown).sigma_a[0], std::get<HairBsdf>(brown).sigma_a[3]);
}

// The material: h = -1 + 2 v from the hit's uv, sigma_a by precedence (sigma_a, reflectance,
// melanin, pbrt-v4's default eumelanin 1.3), the roughness clamped to at least 0.01; never built once
// for all hits.
TEST(Hair, MaterialBuildsTheBsdfAtTheHit) {
  static TextureSet textures;
  HairMaterial by_default;
  HairMaterial given;
  given.sigma_a = ColorInput(RGB(0.1f, 0.2f, 0.3f));
  given.reflectance = ColorInput(RGB(0.5f));
  HairMaterial coloured;
  coloured.reflectance = ColorInput(RGB(0.5f));
  coloured.beta_n = FloatInput(0.5f);
  HairMaterial smooth;
  smooth.beta_m = FloatInput(0.0f);
  smooth.pheomelanin = FloatInput(0.5f);
  MaterialTable table({by_default, given, coloured, smooth}, textures);
  TextureEvalContext ctx;
  ctx.uv = Vec2(0.3f, 0.75f);
  auto hair_at = [&](uint32_t m, const TextureEvalContext& c) {
    SurfaceBsdf b = table.bsdf(m, c);
    EXPECT_EQ(b.count, 1);
    return std::get<HairBsdf>(b.components[0].bsdf);
  };
  HairBsdf d = hair_at(0, ctx);
  EXPECT_NEAR(d.offset(), 0.5f, 1e-6f);
  EXPECT_NEAR(d.sigma_a.g, 1.3f * 0.697f, 1e-5f);
  EXPECT_NEAR(d.ior(), 1.55f, 1e-6f);
  EXPECT_NEAR(d.longitudinal_roughness(), 0.3f, 1e-6f);
  ctx.uv.y = 0.1f;
  EXPECT_NEAR(hair_at(0, ctx).offset(), -0.8f, 1e-6f);
  EXPECT_NEAR(hair_at(1, ctx).sigma_a.b, 0.3f, 1e-6f);
  HairBsdf c = hair_at(2, ctx);
  EXPECT_TRUE(c.sigma_a_from_color);
  EXPECT_NEAR(c.sigma_a.r, hair_sigma_a_from_reflectance(0.5f, 0.5f), 1e-6f);
  HairBsdf s = hair_at(3, ctx);
  EXPECT_NEAR(s.longitudinal_roughness(), 0.01f, 1e-7f);
  EXPECT_NEAR(s.sigma_a.r, 1.3f * 0.419f + 0.5f * 0.187f, 1e-5f);
}

}  // namespace
}  // namespace candela
