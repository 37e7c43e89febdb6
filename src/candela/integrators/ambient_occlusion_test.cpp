// Ambient occlusion against its analytic values: an open floor is exactly the illuminant's white
// (1 per cosine-weighted sample), a floor beside an infinite wall and the wall are half open, the
// inside of a sphere of radius R with occluders counted within D is 1 - (D / 2R)^2 open (the chord
// in a direction at theta to the inward normal is 2R cos theta, and cos^2 theta is uniform under
// cosine weighting), and nothing escaping adds anything. Cosine and uniform directions converge to
// the same values; the render is the same for every thread count; the JSON format keeps the settings.
#include "candela/integrators/ambient_occlusion.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>

#include "candela/base/error.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

constexpr int kAoTestSize = 16;

// `d` rendered with ambient occlusion, cosine-weighted or uniform directions, occluders within
// `max_distance`.
SceneDesc with_ambient_occlusion(SceneDesc d, bool cosine, float max_distance) {
  d.settings.integrator = "ambient_occlusion";
  d.settings.ambient_occlusion.cosine_sampling = cosine;
  d.settings.ambient_occlusion.max_distance = max_distance;
  return d;
}

// A diffuse floor (y = 0) under a bright sky, which ambient occlusion ignores, seen from above.
SceneDesc ao_open_floor_scene(int spp) {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 3, 0}, {0, 0, 0}, 40), kAoTestSize, kAoTestSize,
                                     spp, 5);
  d.materials = {DiffuseMaterial{RGB(0.5f)}};
  d.shapes = {ShapeDesc{.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}}, .material = 0}};
  d.lights = {SkyLight{RGB(4.0f), RGB(4.0f), RGB(4.0f), {0, 1, 0}}};
  return d;
}

// The floor (y = 0) and an infinite wall (x = 0) seen from the +x side: every point seen has half of
// its hemisphere blocked by the other plane.
SceneDesc ao_floor_and_wall_scene(int spp) {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({3, 2, 0.5f}, {0.5f, 0.3f, 0}, 50), kAoTestSize,
                                     kAoTestSize, spp, 5);
  d.materials = {DiffuseMaterial{RGB(0.5f)}};
  d.shapes = {ShapeDesc{.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}}, .material = 0},
              ShapeDesc{.geometry = PlaneShape{{0, 0, 0}, {1, 0, 0}}, .material = 0}};
  return d;
}

// Every pixel's mean of every channel, with the standard error from the spread over pixels.
testing::MeanEstimate ao_image_mean(const SceneDesc& d, int threads = 0) {
  return testing::region_mean(testing::render_description(d, threads).mean_image(), -1);
}

void expect_ao_mean(const SceneDesc& d, double expected, const char* what) {
  const testing::MeanEstimate m = ao_image_mean(d);
  // The renders are sized so that a bias of a few percent would show.
  EXPECT_LT(m.standard_error, 0.012) << what;
  EXPECT_NEAR(m.mean, expected, 4 * m.standard_error + 1e-6) << what << ": standard error " << m.standard_error;
}

TEST(AmbientOcclusion, AnOpenFloorIsExactlyWhiteAndTheSkyIsBlack) {
  const float kInf = std::numeric_limits<float>::infinity();
  // Cosine-weighted directions: every sample that sees the floor is exactly 1 (cos / (pi cos / pi)).
  const Image floor = testing::render_description(with_ambient_occlusion(ao_open_floor_scene(4), true, kInf))
                          .mean_image();
  for (int y = 0; y < floor.height; ++y)
    for (int x = 0; x < floor.width; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(floor.at(x, y)[c], 1.0f, 1e-5f) << x << "," << y;
  // Uniform directions: 2 cos theta per sample, 1 on average.
  expect_ao_mean(with_ambient_occlusion(ao_open_floor_scene(64), false, kInf), 1.0, "uniform, open floor");
  // Looking up, every camera ray escapes: black, though the sky is bright.
  SceneDesc up = with_ambient_occlusion(ao_open_floor_scene(4), true, kInf);
  up.camera = testing::look_at_camera({0, 3, 0}, {0.2f, 10, 0.1f}, 40);
  const testing::MeanEstimate sky = ao_image_mean(up);
  EXPECT_EQ(sky.mean, 0.0);
}

// A spectral render multiplies by D65 normalised to luminance 1, which is white: the open floor
// converges to RGB 1 in every channel (the wavelengths' noise averages out).
TEST(AmbientOcclusion, TheSpectralIlluminantIsWhite) {
  SceneDesc d = with_ambient_occlusion(ao_open_floor_scene(64), true, std::numeric_limits<float>::infinity());
  d.settings.spectral = true;
  const Image img = testing::render_description(d).mean_image();
  for (int c = 0; c < 3; ++c) {
    const testing::MeanEstimate m = testing::region_mean(img, c);
    EXPECT_LT(m.standard_error, 0.02) << "channel " << c;
    // (Plus the few tenths of a percent between tabulated D65 and sRGB's white point.)
    EXPECT_NEAR(m.mean, 1.0, 4 * m.standard_error + 0.005) << "channel " << c;
  }
}

TEST(AmbientOcclusion, AFloorBesideAnInfiniteWallIsHalfOpenWithEitherSampling) {
  const float kInf = std::numeric_limits<float>::infinity();
  expect_ao_mean(with_ambient_occlusion(ao_floor_and_wall_scene(32), true, kInf), 0.5, "cosine");
  expect_ao_mean(with_ambient_occlusion(ao_floor_and_wall_scene(64), false, kInf), 0.5, "uniform");
}

// Inside a sphere of radius 2 everything is occluded; occluders counted only within D leave
// 1 - (D / 4)^2 open.
TEST(AmbientOcclusion, MaxDistanceCutsOccludersBeyondIt) {
  const SceneDesc inside = testing::closed_diffuse_sphere(0.5f, 5);
  SceneDesc all = with_ambient_occlusion(inside, true, std::numeric_limits<float>::infinity());
  all.settings.spp = 4;
  EXPECT_EQ(ao_image_mean(all).mean, 0.0);
  for (bool cosine : {true, false}) {
    for (float distance : {1.0f, 2.0f, 3.0f}) {
      SceneDesc d = with_ambient_occlusion(inside, cosine, distance);
      d.settings.spp = cosine ? 32 : 64;
      const double open = 1 - (distance / 4.0) * (distance / 4.0);
      expect_ao_mean(d, open, cosine ? "cosine" : "uniform");
    }
  }
}

// The camera ray passes an interface (no surface) to the floor below, but the floor's occlusion
// rays are stopped by it, as pbrt-v4's are: black, unless the interface is beyond max_distance.
TEST(AmbientOcclusion, InterfacesArePassedByCameraRaysAndOccludeWithinTheDistance) {
  SceneDesc d = ao_open_floor_scene(4);
  d.materials.push_back(InterfaceMaterial{});
  d.shapes.push_back(ShapeDesc{.geometry = PlaneShape{{0, 1, 0}, {0, 1, 0}}, .material = 1});
  EXPECT_EQ(ao_image_mean(with_ambient_occlusion(d, true, std::numeric_limits<float>::infinity())).mean, 0.0);
  const testing::MeanEstimate below = ao_image_mean(with_ambient_occlusion(d, true, 0.9f));
  EXPECT_NEAR(below.mean, 1.0, 1e-5);
}

// A mask of opacity 1/4 above the floor (pbrt-v4's alpha): a camera ray stops on it a quarter of the
// time, where it is open (1), and otherwise passes to the floor, whose occlusion rays it stops (0).
TEST(AmbientOcclusion, AMasksAbsentPartIsPassedWithItsProbability) {
  SceneDesc d = ao_open_floor_scene(16);
  d.materials.push_back(MaskMaterial{.opacity = FloatInput{0.25f}, .material = 0});
  d.shapes.push_back(ShapeDesc{.geometry = PlaneShape{{0, 1, 0}, {0, 1, 0}}, .material = 1});
  expect_ao_mean(with_ambient_occlusion(d, true, std::numeric_limits<float>::infinity()), 0.25, "mask");
}

TEST(AmbientOcclusion, TheImageIsTheSameForEveryThreadCount) {
  const SceneDesc d = with_ambient_occlusion(ao_floor_and_wall_scene(8), false, 2.0f);
  const Image one = testing::render_description(d, 1).mean_image();
  const Image two = testing::render_description(d, 2).mean_image();
  ASSERT_EQ(one.rgb.size(), two.rgb.size());
  for (size_t i = 0; i < one.rgb.size(); ++i) ASSERT_EQ(one.rgb[i], two.rgb[i]) << "value " << i;
}

// The JSON format writes the settings in the "ambient_occlusion" object and reads them back; an
// integrator that does not read them refuses them.
TEST(AmbientOcclusion, TheJsonFormatKeepsItsSettings) {
  SceneDesc d = with_ambient_occlusion(ao_floor_and_wall_scene(8), false, 2.5f);
  const std::string json = scene_to_json(d);
  const nlohmann::json parsed = nlohmann::json::parse(json);
  EXPECT_EQ(parsed["render"]["integrator"], "ambient_occlusion");
  EXPECT_EQ(parsed["render"]["ambient_occlusion"]["max_distance"], 2.5);
  EXPECT_EQ(parsed["render"]["ambient_occlusion"]["sampling"], "uniform");
  const SceneDesc back = read_json_scene(json, "ao.json", ".");
  EXPECT_EQ(back.settings.integrator, "ambient_occlusion");
  EXPECT_EQ(back.settings.ambient_occlusion, d.settings.ambient_occlusion);
  // The default distance (infinite) is no key at all.
  d.settings.ambient_occlusion.max_distance = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(nlohmann::json::parse(scene_to_json(d))["render"]["ambient_occlusion"].contains("max_distance"));
  nlohmann::json refused = parsed;
  refused["render"]["integrator"] = "path";
  try {
    read_json_scene(refused.dump(), "ao.json", ".");
    ADD_FAILURE() << "the path integrator accepted ambient_occlusion's settings";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("the path integrator does not read ambient_occlusion"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace candela
