// Light sampling: the directions sample_li produces follow pdf_li (chi-square), and radiance/pdf is
// consistent for area lights; spot and distant lights deliver what pbrt-v4's do.
#include "candela/lights/light.h"

#include <gtest/gtest.h>

#include "candela/base/error.h"

#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::kChiSquareSamples;

// Directions from `ctx` as seen in a frame whose +z points along `axis`, so narrow cones are binned finely.
template <typename SampleFn, typename PdfFn>
double light_chi_square(SampleFn sample_world, PdfFn pdf_world, const Vec3& axis, float z_min, int resolution = 12) {
  Frame frame(normalize(axis));
  auto sample = [&](Vec2 u) {
    Vec3 w = sample_world(u);
    return length_squared(w) > 0 ? frame.to_local(w) : w;
  };
  auto pdf = [&](const Vec3& local) { return pdf_world(frame.to_world(local)); };
  return testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 23, z_min, 20, 40, resolution);
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

TEST(Lights, SpotLightFallsOffBetweenItsCones) {
  SpotLight desc;
  desc.position = {1, 2, 3};
  desc.direction = {0, -2, 0};  // need not be unit
  desc.intensity = RGB(4.0f, 2.0f, 1.0f);
  desc.cone_angle = 30;
  desc.cone_delta = 10;
  SpotLightSource spot = make_spot_light(desc);
  EXPECT_NEAR(spot.cos_falloff_start, std::cos(radians(20)), 1e-6f);
  EXPECT_NEAR(spot.cos_falloff_end, std::cos(radians(30)), 1e-6f);
  // A receiver at distance 2 from the light, at `degrees` from the axis.
  auto received = [&](float degrees) {
    Vec3 w(std::sin(radians(degrees)), -std::cos(radians(degrees)), 0);  // from the light
    LightSampleContext ctx{desc.position + w * 2.0f, Normal3(0.0f)};
    LightSample s = spot.sample_li(ctx, {0.5f, 0.5f});
    if (s.pdf > 0) {
      EXPECT_TRUE(s.is_delta);
      EXPECT_FLOAT_EQ(s.pdf, 1);
      EXPECT_NEAR(s.distance, 2, 1e-5f);
      EXPECT_NEAR(length(s.wi + w), 0, 1e-5f);
    }
    return s.pdf > 0 ? s.radiance : RGB(0.0f);
  };
  // Full intensity / d^2 on the axis and inside the inner cone.
  for (float deg : {0.0f, 10.0f, 19.9f}) EXPECT_NEAR(received(deg).r, 1.0f, 1e-4f) << deg;
  // pbrt-v4's smoothstep in cos(theta) between the cones: 1/2 where cos is half-way.
  float mid = std::acos(0.5f * (std::cos(radians(20)) + std::cos(radians(30)))) * 180 / kPi;
  EXPECT_NEAR(received(mid).r, 0.5f, 1e-3f);
  EXPECT_NEAR(received(mid).g, 0.25f, 1e-3f);
  float at25 = received(25).r, t = (std::cos(radians(25)) - spot.cos_falloff_end) /
                                   (spot.cos_falloff_start - spot.cos_falloff_end);
  EXPECT_NEAR(at25, t * t * (3 - 2 * t), 1e-4f);
  // Nothing at or outside the outer cone, nor behind.
  for (float deg : {30.0f, 31.0f, 90.0f, 180.0f}) EXPECT_NEAR(received(deg).r, 0.0f, 1e-6f) << deg;
  EXPECT_EQ(spot.pdf_li({}, {0, 1, 0}, {}, {}), 0);
  // A sharp cone (cone_delta 0) is a step.
  desc.cone_delta = 0;
  SpotLightSource sharp = make_spot_light(desc);
  EXPECT_EQ(sharp.falloff(normalize(Vec3(std::tan(radians(29.9f)), -1, 0))), 1.0f);
  EXPECT_EQ(sharp.falloff(normalize(Vec3(std::tan(radians(30.1f)), -1, 0))), 0.0f);
  desc.direction = Vec3(0.0f);
  EXPECT_THROW(make_spot_light(desc), SceneError);
}

TEST(Lights, SpotLightPowerIsItsIntensityIntegratedOverTheSphere) {
  SpotLight desc;
  desc.direction = {1, 1, 0};
  desc.intensity = RGB(2.0f);
  desc.cone_angle = 50;
  desc.cone_delta = 20;
  SpotLightSource spot = make_spot_light(desc);
  // Midpoint rule in cos(theta) about the axis (the falloff depends on nothing else).
  double sum = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    float c = -1 + 2 * (i + 0.5f) / n;
    sum += SpotLightSource::smoothstep(c, spot.cos_falloff_end, spot.cos_falloff_start);
  }
  double integral = sum * 2.0 / n * 2 * kPi * desc.intensity.luminance();
  EXPECT_NEAR(spot.power(), integral, 1e-4 * integral);
  // pbrt-v4's closed form.
  EXPECT_NEAR(spot.power(), 2.0f * 2 * kPi * (1 - 0.5f * (std::cos(radians(30)) + std::cos(radians(50)))), 1e-4f);
}

TEST(Lights, DistantLightArrivesFromOneDirection) {
  DistantLightSource sun = make_distant_light(DistantLight{{0, -3, 0}, RGB(3.0f, 2.0f, 1.0f)}, 5.0f);
  LightSampleContext ctx{{1, 2, 3}, {0, 1, 0}};
  LightSample s = sun.sample_li(ctx, {0.3f, 0.7f});
  EXPECT_NEAR(length(s.wi - Vec3(0, 1, 0)), 0, 1e-6f);
  EXPECT_TRUE(std::isinf(s.distance));
  EXPECT_TRUE(s.is_delta);
  EXPECT_EQ(s.pdf, 1);
  EXPECT_EQ(s.radiance, RGB(3.0f, 2.0f, 1.0f));
  EXPECT_EQ(sun.pdf_li(ctx, s.wi, {}, {}), 0);
  EXPECT_NEAR(sun.power(), kPi * 25 * RGB(3.0f, 2.0f, 1.0f).luminance(), 1e-3f);
  // Importance is the irradiance E cos.
  LightSampleContext tilted{{0, 0, 0}, normalize(Vec3(1, 1, 0))};
  EXPECT_NEAR(sun.importance(tilted), RGB(3.0f, 2.0f, 1.0f).luminance() * std::sqrt(0.5f), 1e-5f);
  EXPECT_THROW(make_distant_light(DistantLight{Vec3(0.0f), RGB(1.0f)}, 1), SceneError);
}

TEST(Lights, SpotAndDistantLightsAreDeltaLights) {
  EXPECT_TRUE(light_is_delta(Light(PointLightSource{})));
  EXPECT_TRUE(light_is_delta(Light(SpotLightSource{})));
  EXPECT_TRUE(light_is_delta(Light(DistantLightSource{})));
  EXPECT_FALSE(light_is_delta(Light(SkyLightSource{})));
  Image img(2, 1);
  img.set(0, 0, RGB(1.0f));
  EXPECT_FALSE(light_is_delta(Light(EnvironmentLight(img, EnvironmentMapping::Equirectangular, RGB(1.0f), {}, 1))));
}

}  // namespace
}  // namespace candela
