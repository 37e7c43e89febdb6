// Emission sampling for light paths (bidirectional methods): the directions sample_le produces
// follow pdf_le's direction density (chi-square; conditional on the sampled point for area lights),
// its position density matches pdf_le and the light's geometry (1 / area on area lights, the scene
// disk for lights at infinity), and radiance |cos| / (pdf_pos pdf_dir) estimates the light's power().
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <string>

#include "candela/film/image.h"
#include "candela/lights/light.h"
#include "candela/math/transform.h"
#include "candela/sampling/rng.h"
#include "candela/testing/environment_maps.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::kChiSquareSamples;

// Chi-square of the directions sample_le(u_pos, u) produces (u_pos fixed, so the point is fixed for
// area lights) against pdf_le(p, n, w).dir at the point it returns, binned in a frame whose +z is
// `axis` (the emitter's normal or cone axis).
double emission_chi_square(const Light& light, Vec2 u_pos, const SceneSphere& scene, const Vec3& axis,
                           float z_min = -1, int resolution = 12, uint64_t seed = 71) {
  LightEmission ref = light_sample_le(light, u_pos, {0.37f, 0.61f}, scene);
  const Point3 p = ref.p;
  const Normal3 n = ref.n;
  Frame frame(normalize(axis));
  bool moved = false;
  auto sample = [&](Vec2 u) {
    LightEmission e = light_sample_le(light, u_pos, u, scene);
    if (!(e.pdf_dir > 0)) return Vec3(0.0f);
    // Area lights: the point must not depend on u_dir, or the density would not be conditional on p.
    if (!light_is_at_infinity(light) && length(e.p - p) > 1e-4f * (1 + length(p))) moved = true;
    return frame.to_local(e.w);
  };
  auto pdf = [&](const Vec3& local) { return light_pdf_le(light, p, n, frame.to_world(local), scene).dir; };
  double pv = testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, seed, z_min, 20, 40, resolution);
  EXPECT_FALSE(moved) << "sample_le's point changed with u_dir";
  return pv;
}

// Every sample's densities agree with pdf_le's for the same ray (relative tolerance).
void expect_sample_densities_match_pdf_le(const Light& light, const SceneSphere& scene, const char* what,
                                          bool check_dir = true) {
  Rng rng(9, 10);
  int valid = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec2 up{rng.next_float(), rng.next_float()}, ud{rng.next_float(), rng.next_float()};
    LightEmission e = light_sample_le(light, up, ud, scene);
    if (!(e.pdf_dir > 0)) continue;
    ++valid;
    ASSERT_NEAR(length(e.w), 1, 1e-5f) << what;
    EmissionPdf pdf = light_pdf_le(light, e.p, e.n, e.w, scene);
    ASSERT_NEAR(pdf.pos, e.pdf_pos, 1e-5f * e.pdf_pos) << what;
    if (check_dir) {
      ASSERT_NEAR(pdf.dir, e.pdf_dir, 1e-3f * e.pdf_dir) << what << " w " << e.w.x << " " << e.w.y << " " << e.w.z;
    }
  }
  EXPECT_GT(valid, 19900) << what;
}

using testing::Estimate;

// E[luminance(radiance) |cos(n, w)| / (pdf_pos pdf_dir)] (cos = 1 where n is zero) with independent
// uniform position and direction samples: the emitted power.
Estimate emitted_power(const Light& light, const SceneSphere& scene, int n = 400000, uint64_t seed = 3) {
  Rng rng(seed, 77);
  return testing::sample_mean(n, [&] {
    Vec2 up{rng.next_float(), rng.next_float()}, ud{rng.next_float(), rng.next_float()};
    LightEmission e = light_sample_le(light, up, ud, scene);
    if (!(e.pdf_dir > 0 && e.pdf_pos > 0)) return 0.0;
    double c = e.n == Normal3(0.0f) ? 1.0 : std::abs(dot(e.n, e.w));
    return double(e.radiance.luminance()) * c / (double(e.pdf_pos) * double(e.pdf_dir));
  });
}

void expect_power(const Light& light, const SceneSphere& scene, const char* what) {
  Estimate e = emitted_power(light, scene);
  double power = light_power(light);
  EXPECT_NEAR(e.mean, power, 5 * e.standard_error + 1e-4 * power)
      << what << ": estimate " << e.mean << " +- " << e.standard_error << ", power() " << power;
}

// ---------------------------------------------------------------- the lights under test

const SceneSphere kScene{{1, -2, 0.5f}, 4};

TriangleLight test_triangle(bool two_sided) {
  TriangleLight t{{-1, 2, -1}, {1, 2.5f, -1}, {0, 2, 1.5f}, {}, 0, RGB(2.0f, 1.0f, 0.5f), two_sided};
  Vec3 c = cross(t.p1 - t.p0, t.p2 - t.p0);
  t.n = normalize(c);
  t.area = length(c) / 2;
  return t;
}

RectangleLight test_rectangle(bool two_sided) {
  RectangleLight r{{-1, 2, -1}, {2, 0, 0.3f}, {0, 0.4f, 1.5f}, {}, 0, RGB(1.0f, 3.0f, 2.0f), two_sided};
  Vec3 c = cross(r.edge_u, r.edge_v);
  r.n = normalize(c);
  r.area = length(c);
  return r;
}

SpotLightSource test_spot() {
  SpotLightSource s;
  s.position = {0.5f, 1, -2};
  s.frame = Frame(normalize(Vec3(0.3f, -1, 0.2f)));
  s.intensity = RGB(4.0f, 2.0f, 1.0f);
  s.cos_falloff_start = std::cos(radians(25));
  s.cos_falloff_end = std::cos(radians(40));
  return s;
}

SkyLightSource test_sky() { return {RGB(2.0f, 2.5f, 3.0f), RGB(1.0f), RGB(0.3f, 0.2f, 0.1f), {0, 1, 0}, kScene.radius}; }

EnvironmentLight test_environment(EnvironmentMapping mapping) {
  return EnvironmentLight(testing::environment_test_map(mapping), mapping, RGB(1.2f, 1.0f, 0.7f),
                          Transform::rotate(35, normalize(Vec3(1, -2, 0.5f))), kScene.radius);
}

constexpr EnvironmentMapping kMappings[] = {EnvironmentMapping::Equirectangular,
                                            EnvironmentMapping::EqualAreaOctahedral};

// ---------------------------------------------------------------- directions (chi-square)

TEST(LightEmission, PointLightDirectionsAreUniform) {
  Light l = PointLightSource{{0.3f, 1, -2}, RGB(5.0f)};
  EXPECT_GT(emission_chi_square(l, {0.2f, 0.7f}, kScene, {0, 0, 1}), testing::kChiSquareAlpha);
  expect_sample_densities_match_pdf_le(l, kScene, "point");
}

TEST(LightEmission, SpotLightDirectionsAreUniformInTheOuterCone) {
  SpotLightSource spot = test_spot();
  Light l = spot;
  // The cone's edge cuts through the cells near it: integrate the pdf finely.
  EXPECT_GT(emission_chi_square(l, {0.2f, 0.7f}, kScene, spot.frame.n, spot.cos_falloff_end - 0.05f, 64),
            testing::kChiSquareAlpha);
  expect_sample_densities_match_pdf_le(l, kScene, "spot");
  // Nothing outside the cone.
  EXPECT_EQ(light_pdf_le(l, spot.position, Normal3(0.0f), -spot.frame.n, kScene).dir, 0);
}

// A flat area light made by make(two_sided), one- and two-sided: directions cosine-distributed
// about its normal from each sampled point, and densities matching pdf_le.
template <typename FlatLight>
void expect_cosine_about_the_normal(FlatLight (*make)(bool), std::initializer_list<Vec2> u_positions,
                                    const std::string& name) {
  for (bool two_sided : {false, true}) {
    FlatLight light = make(two_sided);
    Light l = light;
    for (Vec2 u_pos : u_positions)
      EXPECT_GT(emission_chi_square(l, u_pos, kScene, light.n), testing::kChiSquareAlpha) << "two-sided " << two_sided;
    expect_sample_densities_match_pdf_le(l, kScene, (two_sided ? "two-sided " + name : name).c_str());
  }
}

TEST(LightEmission, TriangleLightDirectionsAreCosineAboutTheNormal) {
  expect_cosine_about_the_normal(test_triangle, {Vec2{0.2f, 0.3f}, Vec2{0.8f, 0.1f}}, "triangle");
}

TEST(LightEmission, RectangleLightDirectionsAreCosineAboutTheNormal) {
  expect_cosine_about_the_normal(test_rectangle, {Vec2{0.5f, 0.5f}, Vec2{0.9f, 0.05f}}, "rectangle");
}

TEST(LightEmission, SphereLightDirectionsAreCosineAboutTheEmittingSide) {
  struct Case {
    bool two_sided, emits_inward;
    const char* name;
  };
  for (Case c : {Case{false, false, "outward"}, Case{false, true, "inward"}, Case{true, false, "two-sided"}}) {
    SphereLight s{{0.5f, -1, 2}, 1.5f, RGB(1.0f, 2.0f, 0.5f), c.two_sided, c.emits_inward};
    Light l = s;
    for (Vec2 u_pos : {Vec2{0.3f, 0.6f}, Vec2{0.85f, 0.2f}}) {
      LightEmission e = light_sample_le(l, u_pos, {0.5f, 0.5f}, kScene);
      Vec3 outward = normalize(e.p - s.center);
      EXPECT_GT(emission_chi_square(l, u_pos, kScene, outward), testing::kChiSquareAlpha) << c.name;
    }
    expect_sample_densities_match_pdf_le(l, kScene, c.name);
  }
}

TEST(LightEmission, SkyDirectionsFollowPdfLe) {
  Light l = test_sky();
  EXPECT_GT(emission_chi_square(l, {0.4f, 0.1f}, kScene, {0, 1, 0}), testing::kChiSquareAlpha);
  expect_sample_densities_match_pdf_le(l, kScene, "sky");
}

TEST(LightEmission, EnvironmentDirectionsFollowPdfLe) {
  for (EnvironmentMapping m : kMappings) {
    Light l = test_environment(m);
    // The pdf is piecewise constant over the pixels: integrate it finely per cell.
    EXPECT_GT(emission_chi_square(l, {0.4f, 0.1f}, kScene, {0, 0, 1}, -1, 64), testing::kChiSquareAlpha)
        << int(m);
    expect_sample_densities_match_pdf_le(l, kScene, "environment");
  }
}

// ---------------------------------------------------------------- positions

TEST(LightEmission, PointAndSpotLightsEmitFromTheirPosition) {
  SpotLightSource spot = test_spot();
  PointLightSource point{{0.3f, 1, -2}, RGB(5.0f)};
  Rng rng(4, 5);
  for (int i = 0; i < 1000; ++i) {
    Vec2 up{rng.next_float(), rng.next_float()}, ud{rng.next_float(), rng.next_float()};
    for (const Light& l : {Light(point), Light(spot)}) {
      LightEmission e = light_sample_le(l, up, ud, kScene);
      Point3 pos = std::holds_alternative<PointLightSource>(l) ? point.position : spot.position;
      ASSERT_EQ(e.p, pos);
      ASSERT_EQ(e.n, Normal3(0.0f));
      ASSERT_EQ(e.pdf_pos, 1);
      ASSERT_EQ(light_pdf_le(l, e.p, e.n, e.w, kScene).pos, 1);
    }
  }
}

// Barycentric coordinates of p in the triangle (a, b, c) and p's distance from its plane.
void triangle_coordinates(const Point3& p, const Point3& a, const Point3& b, const Point3& c, float& v, float& w,
                          float& plane_distance) {
  Vec3 e0 = b - a, e1 = c - a, d = p - a;
  float d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(d, e0), d21 = dot(d, e1);
  float den = d00 * d11 - d01 * d01;
  v = (d11 * d20 - d01 * d21) / den;
  w = (d00 * d21 - d01 * d20) / den;
  plane_distance = std::abs(dot(d, normalize(cross(e0, e1))));
}

TEST(LightEmission, AreaLightPointsLieOnTheLightWithDensityOneOverArea) {
  TriangleLight tri = test_triangle(false);
  RectangleLight rect = test_rectangle(true);
  SphereLight sph{{0.5f, -1, 2}, 1.5f, RGB(1.0f), false, true};
  const float sphere_area = 4 * kPi * sph.radius * sph.radius;
  Rng rng(6, 7);
  const int n = 200000;
  double rect_in_first_quarter = 0, sphere_upper = 0;
  for (int i = 0; i < n; ++i) {
    Vec2 up{rng.next_float(), rng.next_float()}, ud{rng.next_float(), rng.next_float()};
    LightEmission e = light_sample_le(Light(tri), up, ud, kScene);
    float v, w, dist;
    triangle_coordinates(e.p, tri.p0, tri.p1, tri.p2, v, w, dist);
    ASSERT_LT(dist, 1e-5f);
    ASSERT_GE(v, -1e-5f);
    ASSERT_GE(w, -1e-5f);
    ASSERT_LE(v + w, 1 + 1e-5f);
    ASSERT_NEAR(e.pdf_pos, 1 / tri.area, 1e-6f / tri.area);
    ASSERT_EQ(e.n, tri.n);
    ASSERT_GT(dot(e.n, e.w), 0);  // one-sided: emits on the side of n

    e = light_sample_le(Light(rect), up, ud, kScene);
    Vec3 d = e.p - rect.corner;
    ASSERT_LT(std::abs(dot(d, rect.n)), 1e-5f);
    // (s, t) of the point: d = s edge_u + t edge_v.
    float uu = dot(rect.edge_u, rect.edge_u), uv = dot(rect.edge_u, rect.edge_v), vv = dot(rect.edge_v, rect.edge_v);
    float du = dot(d, rect.edge_u), dv = dot(d, rect.edge_v), den = uu * vv - uv * uv;
    float s = (vv * du - uv * dv) / den, t = (uu * dv - uv * du) / den;
    ASSERT_GE(s, -1e-5f);
    ASSERT_LE(s, 1 + 1e-5f);
    ASSERT_GE(t, -1e-5f);
    ASSERT_LE(t, 1 + 1e-5f);
    if (s < 0.5f && t < 0.5f) rect_in_first_quarter += 1;
    ASSERT_NEAR(e.pdf_pos, 1 / rect.area, 1e-6f / rect.area);

    e = light_sample_le(Light(sph), up, ud, kScene);
    ASSERT_NEAR(distance(e.p, sph.center), sph.radius, 1e-5f * sph.radius);
    ASSERT_NEAR(e.pdf_pos, 1 / sphere_area, 1e-6f / sphere_area);
    Vec3 outward = normalize(e.p - sph.center);
    ASSERT_NEAR(length(e.n + outward), 0, 1e-5f);  // emits_inward: n faces the centre
    ASSERT_GT(dot(e.n, e.w), 0);
    if (e.p.z > sph.center.z) sphere_upper += 1;
  }
  // Uniform by area: a quarter of the parallelogram, half of the sphere.
  EXPECT_NEAR(rect_in_first_quarter / n, 0.25, 5 * std::sqrt(0.25 * 0.75 / n));
  EXPECT_NEAR(sphere_upper / n, 0.5, 5 * std::sqrt(0.25 / n));
}

TEST(LightEmission, LightsAtInfinityStartOnTheSceneDisk) {
  DistantLightSource distant{normalize(Vec3(0.2f, -1, 0.4f)), RGB(3.0f), kScene.radius};
  Light lights[] = {Light(test_sky()), Light(test_environment(EnvironmentMapping::Equirectangular)),
                    Light(test_environment(EnvironmentMapping::EqualAreaOctahedral)), Light(distant)};
  const float disk_pdf = 1 / (kPi * kScene.radius * kScene.radius);
  for (const Light& l : lights) {
    Rng rng(8, 9);
    const int n = 100000;
    double inner = 0;
    int valid = 0;
    for (int i = 0; i < n; ++i) {
      Vec2 up{rng.next_float(), rng.next_float()}, ud{rng.next_float(), rng.next_float()};
      LightEmission e = light_sample_le(l, up, ud, kScene);
      if (!(e.pdf_dir > 0)) continue;
      ++valid;
      ASSERT_NEAR(length(e.w), 1, 1e-5f);
      ASSERT_EQ(e.n, Normal3(0.0f));
      ASSERT_NEAR(e.pdf_pos, disk_pdf, 1e-6f * disk_pdf);
      ASSERT_NEAR(light_pdf_le(l, e.p, e.n, e.w, kScene).pos, disk_pdf, 1e-6f * disk_pdf);
      // The origin lies R behind the centre along w, within R of the line through the centre.
      Vec3 d = e.p - kScene.center;
      ASSERT_NEAR(dot(d, e.w), -kScene.radius, 1e-4f * kScene.radius);
      float off_axis2 = length_squared(d - e.w * dot(d, e.w));
      ASSERT_LE(off_axis2, kScene.radius * kScene.radius * (1 + 1e-4f));
      ASSERT_TRUE(scene_disk_covers(kScene, e.w, kScene.center));
      if (off_axis2 < 0.25f * kScene.radius * kScene.radius) inner += 1;
      if (std::holds_alternative<DistantLightSource>(l)) {
        ASSERT_NEAR(length(e.w - distant.direction), 0, 1e-6f);
      }
    }
    EXPECT_GT(valid, n - 100);
    // Uniform over the disk: a quarter of the points within half the radius.
    EXPECT_NEAR(inner / valid, 0.25, 5 * std::sqrt(0.25 * 0.75 / valid));
  }
}

// ---------------------------------------------------------------- power

TEST(LightEmission, EmittedPowerMatchesPowerForLocalLights) {
  expect_power(PointLightSource{{0.3f, 1, -2}, RGB(5.0f, 2.0f, 1.0f)}, kScene, "point");
  expect_power(test_spot(), kScene, "spot");
  SpotLightSource hard = test_spot();
  hard.cos_falloff_start = hard.cos_falloff_end;  // no falloff
  expect_power(hard, kScene, "spot without falloff");
  for (bool two_sided : {false, true}) {
    expect_power(test_triangle(two_sided), kScene, two_sided ? "two-sided triangle" : "triangle");
    expect_power(test_rectangle(two_sided), kScene, two_sided ? "two-sided rectangle" : "rectangle");
  }
  expect_power(SphereLight{{0.5f, -1, 2}, 1.5f, RGB(1.0f, 2.0f, 0.5f), false, false}, kScene, "sphere");
  expect_power(SphereLight{{0.5f, -1, 2}, 1.5f, RGB(1.0f, 2.0f, 0.5f), false, true}, kScene, "inward sphere");
  expect_power(SphereLight{{0.5f, -1, 2}, 1.5f, RGB(1.0f, 2.0f, 0.5f), true, false}, kScene, "two-sided sphere");
}

TEST(LightEmission, EmittedPowerMatchesPowerForLightsAtInfinity) {
  // power() of a light at infinity is pi R^2 times its integrated radiance (pi R^2 E for a distant light).
  expect_power(test_sky(), kScene, "sky");
  for (EnvironmentMapping m : kMappings) expect_power(test_environment(m), kScene, "environment");
  expect_power(DistantLightSource{normalize(Vec3(0.2f, -1, 0.4f)), RGB(3.0f, 1.0f, 2.0f), kScene.radius}, kScene,
               "distant");
}

}  // namespace
}  // namespace candela
