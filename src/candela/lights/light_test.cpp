// Light sampling: the directions sample_li produces follow pdf_li (chi-square), and radiance/pdf is
// consistent for area lights.
#include "candela/lights/light.h"

#include <gtest/gtest.h>

#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

constexpr int kSamples = testing::kChiSquareSamples;

// Directions from `ctx` as seen in a frame whose +z points along `axis`, so narrow cones are binned finely.
template <typename SampleFn, typename PdfFn>
double light_chi_square(SampleFn sample_world, PdfFn pdf_world, const Vec3& axis, float z_min, int resolution = 12) {
  Frame frame(normalize(axis));
  auto sample = [&](Vec2 u) {
    Vec3 w = sample_world(u);
    return length_squared(w) > 0 ? frame.to_local(w) : w;
  };
  auto pdf = [&](const Vec3& local) { return pdf_world(frame.to_world(local)); };
  return testing::spherical_chi_square_p_value(sample, pdf, kSamples, 23, z_min, 20, 40, resolution);
}

// The directions a light's sample_li produces from ctx (zero when it returns no sample).
template <typename LightType>
auto sampled_directions(const LightType& light, const LightSampleContext& ctx) {
  return [&light, ctx](Vec2 u) {
    LightSample s = light.sample_li(ctx, u);
    return s.pdf > 0 ? s.wi : Vec3(0.0f);
  };
}

// Nearest hit of the ray (o, w) with a sphere, or nothing.
std::optional<Point3> hit_sphere(const Point3& o, const Vec3& w, const Point3& c, float r) {
  Vec3 f = o - c;
  float b = dot(f, w), cc = dot(f, f) - r * r, disc = b * b - cc;
  if (disc < 0) return std::nullopt;
  float t = -b - std::sqrt(disc);
  if (t <= 0) t = -b + std::sqrt(disc);
  if (t <= 0) return std::nullopt;
  return o + w * t;
}

TEST(Lights, SphereLightFromOutsideSamplesTheCone) {
  SphereLight light{{0, 0, 5}, 1.5f, RGB(1.0f), false, false};
  LightSampleContext ctx{{0.3f, -0.2f, 0}, Normal3(0.0f)};
  auto sample = sampled_directions(light, ctx);
  auto pdf = [&](const Vec3& w) {
    auto p = hit_sphere(ctx.p, w, light.center, light.radius);
    return p ? light.pdf_li(ctx, w, *p, normalize(*p - light.center)) : 0.0f;
  };
  float cos_max = light.cone_cos_max(ctx.p);
  EXPECT_GT(light_chi_square(sample, pdf, light.center - ctx.p, cos_max - 0.01f), testing::kChiSquareAlpha);
}

TEST(Lights, SphereLightFromInsideSamplesByArea) {
  SphereLight light{{0, 0, 0}, 2, RGB(1.0f), true, false};
  LightSampleContext ctx{{0.5f, 0.3f, -0.4f}, Normal3(0.0f)};
  auto sample = sampled_directions(light, ctx);
  auto pdf = [&](const Vec3& w) {
    auto p = hit_sphere(ctx.p, w, light.center, light.radius);
    return p ? light.pdf_li(ctx, w, *p, normalize(*p - light.center)) : 0.0f;
  };
  EXPECT_GT(light_chi_square(sample, pdf, {0, 0, 1}, -1), testing::kChiSquareAlpha);
}

TEST(Lights, TriangleLightSamplesByArea) {
  TriangleLight light{{-1, 2, -1}, {1, 2, -1}, {0, 2, 1.5f}, {0, -1, 0}, 0, RGB(2.0f), false};
  light.area = length(cross(light.p1 - light.p0, light.p2 - light.p0)) / 2;
  LightSampleContext ctx{{0.2f, 0, 0.1f}, {0, 1, 0}};
  auto sample = sampled_directions(light, ctx);
  auto pdf = [&](const Vec3& w) {
    // Where the direction meets the plane y = 2, if inside the triangle.
    if (w.y <= 0) return 0.0f;
    Point3 p = ctx.p + w * ((2 - ctx.p.y) / w.y);
    Vec3 e0 = light.p1 - light.p0, e1 = light.p2 - light.p0, d = p - light.p0;
    float d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(d, e0), d21 = dot(d, e1);
    float den = d00 * d11 - d01 * d01, v = (d11 * d20 - d01 * d21) / den, t = (d00 * d21 - d01 * d20) / den;
    if (v < 0 || t < 0 || v + t > 1) return 0.0f;
    return light.pdf_li(ctx, w, p, light.n);
  };
  // The triangle's edges cut through cells: integrate its pdf finely.
  EXPECT_GT(light_chi_square(sample, pdf, {0, 1, 0}, 0.5f, 64), testing::kChiSquareAlpha);
  // One-sided: nothing from behind.
  LightSampleContext above{{0, 3, 0}, {0, -1, 0}};
  EXPECT_EQ(light.sample_li(above, {0.3f, 0.3f}).pdf, 0);
}

TEST(Lights, SkySamplesCosineAboutTheNormalOrUniformly) {
  SkyLightSource sky{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}, 1};
  for (Normal3 n : {Normal3(0, 0, 1), Normal3(0.0f)}) {
    LightSampleContext ctx{{0, 0, 0}, n};
    auto sample = [&](Vec2 u) { return sky.sample_li(ctx, u).wi; };
    auto pdf = [&](const Vec3& w) { return sky.pdf_li(ctx, w, {}, {}); };
    EXPECT_GT(light_chi_square(sample, pdf, {0, 0, 1}, -1), testing::kChiSquareAlpha);
  }
}

TEST(Lights, SkyGradientAndPower) {
  SkyLightSource sky{RGB(2.0f), RGB(1.0f), RGB(0.5f), {0, 1, 0}, 1};
  EXPECT_FLOAT_EQ(sky.radiance({0, 1, 0}).g, 2.0f);
  EXPECT_FLOAT_EQ(sky.radiance({1, 0, 0}).g, 1.0f);
  EXPECT_FLOAT_EQ(sky.radiance({0, -1, 0}).g, 0.5f);
  // Integral over the sphere by Monte Carlo matches the closed form used for power().
  Rng rng(1, 1);
  double sum = 0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) sum += sky.radiance(square_to_uniform_sphere({rng.next_float(), rng.next_float()})).g;
  double integral = sum / n * 4 * kPi;
  EXPECT_NEAR(sky.power(), kPi * integral, 0.01 * sky.power());
}

TEST(Lights, RectangleLightSamplesByAreaAndStratifies) {
  RectangleLight light{{-1, 2, -1}, {2, 0, 0}, {0, 0, 1.5f}, {0, -1, 0}, 3.0f, RGB(2.0f), false};
  LightSampleContext ctx{{0.3f, 0, 0.2f}, {0, 1, 0}};
  auto sample = sampled_directions(light, ctx);
  auto pdf = [&](const Vec3& w) {
    if (w.y <= 0) return 0.0f;
    Point3 p = ctx.p + w * ((2 - ctx.p.y) / w.y);
    if (p.x < -1 || p.x > 1 || p.z < -1 || p.z > 0.5f) return 0.0f;
    return light.pdf_li(ctx, w, p, light.n);
  };
  EXPECT_GT(light_chi_square(sample, pdf, {0, 1, 0}, 0.3f, 64), testing::kChiSquareAlpha);
  // The 2D sample maps straight onto the parallelogram: strata of u are strata of the light.
  LightSample s = light.sample_li(ctx, {0.25f, 0.5f});
  EXPECT_NEAR(s.p_light.x, -0.5f, 1e-5f);
  EXPECT_NEAR(s.p_light.z, -0.25f, 1e-5f);
}

}  // namespace
}  // namespace candela
