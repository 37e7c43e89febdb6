// Furnace tests: scenes with analytic answers. Each asserts the rendered mean within 4 standard
// errors estimated from the render itself (plus a tiny floor for zero-variance estimators).
#include <gtest/gtest.h>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using testing::look_at_camera;
using testing::region_mean;
using testing::render_description;

void expect_within_standard_errors(const testing::MeanEstimate& e, double expected, const char* what) {
  double tolerance = 4 * e.standard_error + 1e-5 * std::max(1.0, std::abs(expected));
  EXPECT_NEAR(e.mean, expected, tolerance) << what << ": standard error " << e.standard_error << " over "
                                           << e.pixels << " pixels";
}

// A sphere of radius 1 at the origin seen from z = -4; pixels whose centres look well inside the
// silhouette (the sphere subtends asin(1/4) = 14.5 degrees; the fov is 40 degrees).
SceneDesc sphere_under_sky(const MaterialDesc& material, const RGB& sky) {
  SceneDesc d;
  d.film = {32, 32, ""};
  d.camera = look_at_camera({0, 0, -4}, {0, 0, 0}, 40);
  d.settings.spp = 16;
  d.settings.max_depth = 200;
  d.materials = {material};
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, 0}, 1};
  s.material = 0;
  d.shapes = {s};
  d.lights = {SkyLight{sky, sky, sky, {0, 1, 0}}};
  return d;
}

bool inside_silhouette(int x, int y) {
  // Pixel centre direction angle from the axis < 10 degrees (silhouette at 14.48).
  float sx = (2 * (x + 0.5f) / 32 - 1) * std::tan(radians(20)), sy = (2 * (y + 0.5f) / 32 - 1) * std::tan(radians(20));
  return std::sqrt(sx * sx + sy * sy) < std::tan(radians(10));
}
bool outside_silhouette(int x, int y) {
  float sx = (2 * (x + 0.5f) / 32 - 1) * std::tan(radians(20)), sy = (2 * (y + 0.5f) / 32 - 1) * std::tan(radians(20));
  return std::sqrt(sx * sx + sy * sy) > std::tan(radians(17));
}

TEST(Furnace, DiffuseSphereUnderUniformSkyIsAlbedoTimesSky) {
  const float albedo = 0.7f;
  const RGB sky(0.5f, 1.0f, 2.0f);
  Image img = render_description(sphere_under_sky(DiffuseMaterial{RGB(albedo)}, sky)).mean_image();
  for (int c = 0; c < 3; ++c) {
    expect_within_standard_errors(region_mean(img, c, inside_silhouette), albedo * sky[c], "sphere");
    expect_within_standard_errors(region_mean(img, c, outside_silhouette), sky[c], "background");
  }
}

TEST(Furnace, PhongMaterialDiffuseLobeUnderUniformSky) {
  // With s = t = 0 the paper's material is Lambertian with albedo d * diffuse.
  PhongMaterial m;
  m.diffuse = RGB(0.8f);
  m.d = 0.5f;
  m.s = 0;
  m.t = 0;
  Image img = render_description(sphere_under_sky(m, RGB(1.0f))).mean_image();
  expect_within_standard_errors(region_mean(img, -1, inside_silhouette), 0.4, "phong d=0.5");
}

TEST(Furnace, LosslessGlassSphereIsInvisibleInWhiteFurnace) {
  // Fresnel reflection + refraction conserve energy, and the 1/eta^2 radiance scaling on the way in
  // cancels on the way out: every pixel sees exactly the sky.
  Image img = render_description(sphere_under_sky(DielectricMaterial{1.5f, RGB(1.0f), RGB(1.0f)}, RGB(1.0f))).mean_image();
  expect_within_standard_errors(region_mean(img, -1, inside_silhouette), 1.0, "glass");
}

TEST(Furnace, PaperTransmissionLobeIsLosslessInWhiteFurnace) {
  // The paper's material with t = 1 and white transmission: refraction only, no loss.
  PhongMaterial m;
  m.d = 0;
  m.s = 0;
  m.t = 1;
  m.transmission = RGB(1.0f);
  m.ior = 1.33f;
  Image img = render_description(sphere_under_sky(m, RGB(1.0f))).mean_image();
  expect_within_standard_errors(region_mean(img, -1, inside_silhouette), 1.0, "phong t=1");
}

TEST(Furnace, WhiteMaterialsConserveEnergy) {
  // A white, lossless object in a white furnace is invisible: diffuse with albedo 1, the paper's
  // material with d = 1 or t = 1, a white mirror, clear glass. The normalised Phong lobe loses the
  // part of the lobe below the surface, so a white d + s = 1 mixture may only be darker.
  PhongMaterial diffuse_phong;
  diffuse_phong.diffuse = RGB(1.0f);
  diffuse_phong.d = 1;
  diffuse_phong.s = diffuse_phong.t = 0;
  for (const MaterialDesc& m : std::vector<MaterialDesc>{DiffuseMaterial{RGB(1.0f)}, diffuse_phong,
                                                         MirrorMaterial{RGB(1.0f)}, DielectricMaterial{1.33f, RGB(1.0f), RGB(1.0f)}})
    expect_within_standard_errors(region_mean(render_description(sphere_under_sky(m, RGB(1.0f))).mean_image(), -1,
                                              inside_silhouette),
                                  1.0, "white material");
  PhongMaterial glossy;
  glossy.diffuse = glossy.specular = RGB(1.0f);
  glossy.exponent = 10;
  glossy.d = glossy.s = 0.5f;
  glossy.t = 0;
  auto e = region_mean(render_description(sphere_under_sky(glossy, RGB(1.0f))).mean_image(), -1, inside_silhouette);
  EXPECT_LE(e.mean, 1.0 + 4 * e.standard_error);
  EXPECT_GT(e.mean, 0.8);
}

TEST(Furnace, MirrorSphereReflectsItsReflectance) {
  Image img = render_description(sphere_under_sky(MirrorMaterial{RGB(0.25f, 0.5f, 0.75f)}, RGB(2.0f))).mean_image();
  for (int c = 0; c < 3; ++c)
    expect_within_standard_errors(region_mean(img, c, inside_silhouette), 2.0 * (0.25 * (c + 1)), "mirror");
}

// A closed diffuse sphere seen from its centre.
SceneDesc closed_sphere(float albedo, int spp) {
  SceneDesc d = testing::closed_diffuse_sphere(albedo, 10000);
  d.settings.spp = spp;
  return d;
}

TEST(Furnace, EmissiveClosedSphereSeesEmissionOverOneMinusAlbedo) {
  // L = Le + rho L  =>  L = Le / (1 - rho), summed over all path lengths (Russian roulette on).
  const float albedo = 0.8f, Le = 0.5f;
  for (bool two_sided : {true, false}) {
    SceneDesc d = closed_sphere(albedo, 64);
    d.shapes[0].emission = AreaEmission{RGB(Le), two_sided};
    d.shapes[0].reverse_orientation = !two_sided;  // one-sided: make the emitting side face inwards
    Image img = render_description(d).mean_image();
    expect_within_standard_errors(region_mean(img, -1), Le / (1 - albedo), two_sided ? "two-sided" : "inward");
  }
}

TEST(Furnace, PointLightInsideDiffuseSphere) {
  // Direct irradiance I / r^2 everywhere; each bounce multiplies radiance by rho:
  // L = rho I / (pi r^2 (1 - rho)).
  const float albedo = 0.6f, I = 3.0f, r = 2.0f;
  SceneDesc d = closed_sphere(albedo, 64);
  d.lights = {PointLight{{0, 0, 0}, RGB(I)}};
  Image img = render_description(d).mean_image();
  expect_within_standard_errors(region_mean(img, -1), albedo * I / (kPi * r * r * (1 - albedo)), "point light");
}

TEST(Furnace, MaxDepthOneGivesDirectLightOnly) {
  // With one bounce, only emission + single scattering remain: Le + rho Le.
  const float albedo = 0.5f, Le = 1.0f;
  SceneDesc d = closed_sphere(albedo, 64);
  d.shapes[0].emission = AreaEmission{RGB(Le), true};
  d.settings.max_depth = 1;
  Image img = render_description(d).mean_image();
  expect_within_standard_errors(region_mean(img, -1), Le * (1 + albedo), "max depth 1");
}

}  // namespace
}  // namespace candela
