// Point lights shaped by an image: pbrt-v4's goniometric light (an equal-area image of the
// directions) and pbrt-v4's "projection" light (the projector with ProjectorRadiometry::Intensity
// and the fov on the image's shorter axis). Intensities against hand-placed texels, emission
// sampling by chi-square against pdf_le, sample weights against power(), power() against a
// numerical integral.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "candela/base/error.h"
#include "candela/lights/light.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/environment_maps.h"
#include "candela/testing/statistics.h"
#include "candela/testing/temp_image_file.h"
#include "candela/textures/texture.h"

namespace candela {
namespace {

const SceneSphere kImagePointLightSphere{{0, 0, 0}, 10};

// A 4 x 4 image whose texel (x, y) has R, G, B averaging 1 + x + 4 y.
Image goniometric_numbered_image() {
  Image img(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      float mean = 1.0f + float(x) + 4.0f * float(y);
      img.set(x, y, RGB(mean - 0.5f, mean, mean + 0.5f));
    }
  return img;
}

// Chi-square p-value of the directions light_sample_le gives against light_pdf_le, binned about `axis`.
double image_point_light_chi_square(const Light& light, const Vec3& axis, float z_min, int resolution) {
  Frame frame(normalize(axis));
  auto sample = [&](Vec2 u) {
    LightEmission e = light_sample_le(light, {0.5f, 0.5f}, u, kImagePointLightSphere);
    return e.pdf_dir > 0 ? frame.to_local(e.w) : Vec3(0.0f);
  };
  const Point3 p = light_sample_le(light, {0.5f, 0.5f}, {0.3f, 0.6f}, kImagePointLightSphere).p;
  auto pdf = [&](const Vec3& local) {
    return light_pdf_le(light, p, Normal3(0.0f), frame.to_world(local), kImagePointLightSphere).dir;
  };
  return testing::spherical_chi_square_p_value(sample, pdf, testing::kChiSquareSamples, 41, z_min, 20, 40,
                                               resolution);
}

// Every emission sample's pdf_dir is pdf_le's; returns the estimate of the power, E[lum(I) / pdf_dir].
testing::Estimate image_point_light_emitted_power(const Light& light) {
  Rng rng(5, 6);
  for (int i = 0; i < 20000; ++i) {
    LightEmission e = light_sample_le(light, {0.5f, 0.5f}, {rng.next_float(), rng.next_float()}, kImagePointLightSphere);
    if (!(e.pdf_dir > 0)) continue;
    EmissionPdf pdf = light_pdf_le(light, e.p, e.n, e.w, kImagePointLightSphere);
    EXPECT_NEAR(pdf.dir, e.pdf_dir, 2e-3f * e.pdf_dir);
    if (::testing::Test::HasFailure()) break;
  }
  Rng r2(7, 8);
  return testing::sample_mean(400000, [&] {
    LightEmission e = light_sample_le(light, {0.5f, 0.5f}, {r2.next_float(), r2.next_float()}, kImagePointLightSphere);
    if (!(e.pdf_dir > 0)) return 0.0;
    return double(e.radiance.luminance()) / double(e.pdf_dir);
  });
}

// ---------------------------------------------------------------- goniometric

TEST(GoniometricLight, IntensityIsTheNearestTexelsMeanWithTheLightsYAtTheSquaresCentre) {
  GoniometricLight desc;
  desc.to_world = Transform::translate({1, 2, 3});
  desc.intensity = RGB(2.0f, 1.0f, 0.5f);
  GoniometricLightSource light = make_goniometric_light(desc, goniometric_numbered_image());
  // Local directions and the texels they read, placed by hand on Clarberg's square (+z of the square
  // = the light's +y at the centre (0.5, 0.5); the square's +x towards u = 1, its +y, the light's +z,
  // towards v = 1).
  struct Case {
    Vec3 dir;
    int x, y;
  };
  const Case cases[] = {{{0, 1, 0}, 2, 2},        {{1, 0, 0}, 3, 2},         {{-1, 0, 0}, 0, 2},
                        {{0, 0, 1}, 2, 3},        {{0, 0, -1}, 2, 0},        {{0.1f, 1, 0.1f}, 2, 2},
                        {{-0.1f, 1, -0.1f}, 1, 1}, {{0.3f, -1, 0.2f}, 3, 3}, {{-0.3f, -1, -0.2f}, 0, 0}};
  for (const Case& c : cases) {
    const float distance = 2.5f;
    const Point3 p = Point3(1, 2, 3) + normalize(c.dir) * distance;
    LightSample ls = light.sample_li({p, Normal3(0.0f)}, {});
    const float texel = 1.0f + float(c.x) + 4.0f * float(c.y);
    const RGB expected = desc.intensity * (texel / (distance * distance));
    ASSERT_GT(ls.pdf, 0) << c.dir.x << " " << c.dir.y << " " << c.dir.z;
    EXPECT_NEAR(ls.radiance.r, expected.r, 1e-4f * expected.r) << c.dir.x << " " << c.dir.y << " " << c.dir.z;
    EXPECT_NEAR(ls.radiance.b, expected.b, 1e-4f * expected.b) << c.dir.x << " " << c.dir.y << " " << c.dir.z;
    const Vec3 towards_light = -normalize(c.dir);
    EXPECT_NEAR(ls.wi.x, towards_light.x, 1e-5f);
    EXPECT_NEAR(ls.wi.y, towards_light.y, 1e-5f);
    EXPECT_NEAR(ls.wi.z, towards_light.z, 1e-5f);
  }
}

TEST(GoniometricLight, EmissionIsImportanceSampledByTheImageAndPowerIsItsIntegral) {
  GoniometricLight desc;
  desc.to_world = Transform::translate({0.5f, -1, 2}) * Transform::rotate(40, normalize(Vec3(1, 2, -1)));
  desc.intensity = RGB(1.5f, 1.0f, 0.5f);
  Image img = testing::environment_test_map(EnvironmentMapping::EqualAreaOctahedral);
  GoniometricLightSource light = make_goniometric_light(desc, img);
  EXPECT_GT(image_point_light_chi_square(Light(light), {0, 0, 1}, -1, 64), testing::kChiSquareAlpha);
  // The pdf is exactly proportional to the intensity: every sample weighs power() (up to rounding).
  Rng rng(3, 4);
  for (int i = 0; i < 2000; ++i) {
    LightEmission e = light_sample_le(Light(light), {}, {rng.next_float(), rng.next_float()}, kImagePointLightSphere);
    ASSERT_GT(e.pdf_dir, 0);
    EXPECT_NEAR(e.radiance.luminance() / e.pdf_dir, light.power(), 1e-3f * light.power());
  }
  testing::Estimate emitted = image_point_light_emitted_power(Light(light));
  EXPECT_NEAR(emitted.mean, light.power(), 5 * emitted.standard_error + 1e-4 * light.power());
  // power() against the integral of the intensity over the sphere, on a stratified grid of directions.
  const int n = 600;
  double integral = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec3 w = square_to_uniform_sphere({(i + 0.5f) / n, (j + 0.5f) / n});
      integral += light.intensity_towards(w).luminance();
    }
  integral *= 4 * kPi / (double(n) * n);
  EXPECT_NEAR(light.power(), integral, 1e-2 * integral);
}

TEST(GoniometricLight, PowerNormalisesAndBadImagesAreErrors) {
  GoniometricLight desc;
  desc.power = 10;
  GoniometricLightSource light = make_goniometric_light(desc, goniometric_numbered_image());
  EXPECT_NEAR(light.power(), 10, 1e-4);  // unit intensity emits `power`
  desc.intensity = RGB(2.0f);
  EXPECT_NEAR(make_goniometric_light(desc, goniometric_numbered_image()).power(), 20, 2e-4);
  EXPECT_THROW(make_goniometric_light(desc, Image(4, 3)), SceneError);  // not square
  EXPECT_THROW(make_goniometric_light(desc, Image(4, 4)), SceneError);  // black: no power to meet
  desc.power = 0;
  EXPECT_EQ(make_goniometric_light(desc, Image(4, 4)).power(), 0);
}

// ---------------------------------------------------------------- pbrt-v4's projection light

// A 4 x 3 image with a black texel, and the texture set that reads it without filtering.
Image pbrt_projection_image() {
  Image img(4, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) img.set(x, y, RGB(0.5f + x, 1.0f + 0.5f * y, 2.0f));
  img.set(1, 2, RGB(0.0f));
  return img;
}
TextureSet pbrt_projection_texture(const std::string& file) {
  ImageTexture tex;
  tex.filename = file;
  tex.encoding = ColorEncoding::Linear;
  tex.filter = TextureFilter::Nearest;
  tex.wrap = TextureWrap::Clamp;
  return TextureSet(std::vector<TextureDesc>{tex});
}
ProjectorLight pbrt_projection_desc(float fov) {
  ProjectorLight desc;
  desc.to_world = Transform::translate({1, 2, 3}) * Transform::rotate(50, normalize(Vec3(1, 2, 3)));
  desc.fov_degrees = fov;
  desc.irradiance = 0;
  desc.scale = RGB(2.0f, 1.0f, 0.5f);
  desc.radiometry = ProjectorRadiometry::Intensity;
  desc.fov_axis = ProjectorFovAxis::Smaller;
  return desc;
}

TEST(PbrtProjectorLight, IntensityIsScaleTimesTheTexelWithTheFovOnTheShorterAxis) {
  Image img = pbrt_projection_image();
  testing::TempImageFile file(img, "pbrt_projection");
  TextureSet textures = pbrt_projection_texture(file.path());
  ProjectorLight desc = pbrt_projection_desc(60);
  ProjectorLightSource p = make_projector_light(desc, &textures);
  // 4 x 3: the fov spans y, the shorter axis; x is wider by the aspect ratio.
  const float tan_y = std::tan(radians(30)), tan_x = tan_y * 4 / 3;
  EXPECT_NEAR(p.tan_y, tan_y, 1e-6f);
  EXPECT_NEAR(p.tan_x, tan_x, 1e-6f);
  Rng rng(7, 8);
  int inside_count = 0;
  for (int i = 0; i < 2000; ++i) {
    float depth = 0.5f + 2 * rng.next_float();
    float x = (2 * rng.next_float() - 1) * 1.2f * tan_x * depth, y = (2 * rng.next_float() - 1) * 1.2f * tan_y * depth;
    Point3 q = desc.to_world.point({x, y, depth});
    LightSample ls = p.sample_li({q, Normal3(0.0f)}, {});
    float u = 0.5f - 0.5f * x / (depth * tan_x), v = 0.5f - 0.5f * y / (depth * tan_y);
    if (!(u >= 0 && u <= 1 && v >= 0 && v <= 1)) {
      EXPECT_FALSE(ls.pdf > 0 && !ls.radiance.is_black()) << "outside the frustum at uv " << u << " " << v;
      continue;
    }
    // pbrt-v4: I = scale x texel, no 1 / cos^3; radiance arriving = I / distance^2.
    RGB texel = img.at(std::min(3, int(u * 4)), std::min(2, int((1 - v) * 3)));
    float dist2 = x * x + y * y + depth * depth;
    RGB expected = texel * desc.scale / dist2;
    if (expected.is_black()) {
      EXPECT_TRUE(!(ls.pdf > 0) || ls.radiance.is_black());
      continue;
    }
    ++inside_count;
    ASSERT_GT(ls.pdf, 0);
    EXPECT_NEAR(ls.radiance.r, expected.r, 1e-4f * expected.r) << u << " " << v;
    EXPECT_NEAR(ls.radiance.g, expected.g, 1e-4f * expected.g) << u << " " << v;
  }
  EXPECT_GT(inside_count, 800);
  // A portrait image: the fov spans x.
  Image portrait(3, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 3; ++x) portrait.set(x, y, RGB(1.0f));
  testing::TempImageFile portrait_file(portrait, "pbrt_projection_portrait");
  TextureSet portrait_textures = pbrt_projection_texture(portrait_file.path());
  ProjectorLightSource tall = make_projector_light(desc, &portrait_textures);
  EXPECT_NEAR(tall.tan_x, tan_y, 1e-6f);
  EXPECT_NEAR(tall.tan_y, tan_y * 4 / 3, 1e-6f);
}

TEST(PbrtProjectorLight, EmissionIsImportanceSampledAndPowerIsTheIntegralOfTheIntensity) {
  Image img = pbrt_projection_image();
  testing::TempImageFile file(img, "pbrt_projection_emission");
  TextureSet textures = pbrt_projection_texture(file.path());
  ProjectorLight desc = pbrt_projection_desc(70);
  ProjectorLightSource p = make_projector_light(desc, &textures);
  const Vec3 axis = normalize(desc.to_world.vector({0, 0, 1}));
  const float z_min = 1 / std::sqrt(1 + p.tan_x * p.tan_x + p.tan_y * p.tan_y);
  EXPECT_GT(image_point_light_chi_square(Light(p), axis, z_min - 0.02f, 48), testing::kChiSquareAlpha);
  testing::Estimate emitted = image_point_light_emitted_power(Light(p));
  EXPECT_NEAR(emitted.mean, p.power(), 5 * emitted.standard_error + 1e-4 * p.power());
  // power() against the integral of I over the frustum: I dw = I cos^3 dA on the unit-distance plane,
  // midpoint rule on a grid much finer than the texels.
  const int n = 800;
  double integral = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float x = (2 * (i + 0.5f) / n - 1) * p.tan_x, y = (2 * (j + 0.5f) / n - 1) * p.tan_y;
      const Vec3 d = normalize(Vec3(x, y, 1));
      const Point3 q = desc.to_world.point(Vec3(x, y, 1));
      LightSample ls = p.sample_li({q, Normal3(0.0f)}, {});
      const double dist2 = double(x) * x + double(y) * y + 1;
      if (ls.pdf > 0) integral += double(ls.radiance.luminance()) * dist2 * double(d.z) * d.z * d.z;
    }
  integral *= 4.0 * p.tan_x * p.tan_y / (double(n) * n);
  EXPECT_NEAR(p.power(), integral, 5e-3 * integral);
  // pbrt-v4's "power": the emission times power / (the power with scale 1 as pbrt-v4 reckons it:
  // each texel's luminance times cos^3 at its centre, over the image plane's area); scale multiplies.
  double pbrt_unit_power = 0;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) {
      const float px = (2 * (x + 0.5f) / 4 - 1) * p.tan_x, py = (2 * (y + 0.5f) / 3 - 1) * p.tan_y;
      const double c = 1 / std::sqrt(1.0 + px * px + py * py);
      pbrt_unit_power += double(img.at(x, y).luminance()) * c * c * c;
    }
  pbrt_unit_power *= 4.0 * p.tan_x * p.tan_y / 12;
  ProjectorLight normalised = desc;
  normalised.power = 7;
  EXPECT_NEAR(make_projector_light(normalised, &textures).power(), p.power() * 7 / pbrt_unit_power,
              1e-4 * p.power() * 7 / pbrt_unit_power);
  normalised.scale = desc.scale = RGB(1.0f);
  const float unit = make_projector_light(desc, &textures).power();
  EXPECT_NEAR(make_projector_light(normalised, &textures).power(), unit * 7 / pbrt_unit_power,
              1e-4 * unit * 7 / pbrt_unit_power);
}

}  // namespace
}  // namespace candela
