// pbrt-v4's spherical cameras (CameraDesc's Projection::Equirectangular and ::EqualArea): the
// analytic directions of the equirectangular image, the equal-area square's uniform coverage of the
// sphere (chi-square), cropped films, no light-path connections (bidirectional path tracing still
// agrees with the path tracer; the light tracer refuses), and the readers and the writer.
#include <gtest/gtest.h>

#include <cmath>

#include "candela/base/error.h"
#include "candela/camera/camera.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/sampling/rng.h"
#include "candela/testing/pbrt_reader_helpers.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

// Qualified, not a using-directive: the unity build shares this anonymous namespace with other tests.
namespace spherical_pbrt = candela::testing::pbrt_reader;

CameraDesc spherical_desc(Projection projection, const Transform& world_from_camera = Transform()) {
  CameraDesc d;
  d.projection = projection;
  d.world_from_camera = world_from_camera;
  return d;
}

TEST(SphericalCamera, EquirectangularDirectionsAreAnalytic) {
  const int w = 64, h = 32;
  // A camera turned about y by 90 degrees: its +z (the view) is the world's +x.
  const Transform turn = Transform::rotate(90, {0, 1, 0});
  const Camera cam(spherical_desc(Projection::Equirectangular, turn), w, h);
  EXPECT_TRUE(cam.is_spherical());
  EXPECT_TRUE(cam.is_delta_direction());
  EXPECT_FALSE(cam.has_lens());
  Rng rng(3, 4);
  for (int i = 0; i < 500; ++i) {
    const Vec2 film{rng.next_float() * w, rng.next_float() * h};
    const Ray ray = cam.generate_ray(film, {rng.next_float(), rng.next_float()}, 0.5f);
    const float theta = kPi * film.y / h, phi = 2 * kPi * film.x / w;
    const Vec3 expected = turn.vector(
        Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)));
    EXPECT_NEAR(ray.direction.x, expected.x, 1e-5f);
    EXPECT_NEAR(ray.direction.y, expected.y, 1e-5f);
    EXPECT_NEAR(ray.direction.z, expected.z, 1e-5f);
    EXPECT_NEAR(ray.origin.x, 0, 1e-6f);
  }
  // The top row looks up; a quarter of the way across the middle row looks along the view.
  EXPECT_NEAR(cam.generate_ray({10, 0}, {0.5f, 0.5f}, 0).direction.y, 1, 1e-6f);
  EXPECT_NEAR(dot(cam.generate_ray({w / 4.0f, h / 2.0f}, {0.5f, 0.5f}, 0).direction, cam.forward()), 1, 1e-6f);
}

// Equal areas of the image are equal solid angles: uniform film positions give uniform directions.
// Chi-square of the up component (uniform in [-1, 1] on the sphere) and of the azimuth, 20 bins each.
TEST(SphericalCamera, EqualAreaImageCoversTheSphereUniformly) {
  const int w = 50, h = 50, n = 200000, bins = 20;
  const Camera cam(spherical_desc(Projection::EqualArea), w, h);
  std::vector<int> up(bins, 0), azimuth(bins, 0);
  Rng rng(5, 6);
  for (int i = 0; i < n; ++i) {
    const Vec3 d = cam.generate_ray({rng.next_float() * w, rng.next_float() * h}, {0.5f, 0.5f}, 0).direction;
    ASSERT_NEAR(length(d), 1, 1e-5f);
    up[std::min(bins - 1, int((d.y + 1) / 2 * bins))]++;
    azimuth[std::min(bins - 1, int((std::atan2(d.z, d.x) + kPi) / (2 * kPi) * bins))]++;
  }
  auto chi_square = [&](const std::vector<int>& counts) {
    const double expected = double(n) / bins;
    double chi2 = 0;
    for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
    return chi2;
  };
  // 19 degrees of freedom: 43.8 is the 0.1% tail.
  EXPECT_LT(chi_square(up), 43.8);
  EXPECT_LT(chi_square(azimuth), 43.8);
  // The square's centre looks up (pbrt-v4 swaps the square's z to y); film beyond the edges wraps.
  EXPECT_NEAR(cam.generate_ray({25, 25}, {0.5f, 0.5f}, 0).direction.y, 1, 1e-5f);
  const Vec3 beyond = cam.generate_ray({-1, 10}, {0.5f, 0.5f}, 0).direction;
  const Vec3 mirrored = cam.generate_ray({1, 40}, {0.5f, 0.5f}, 0).direction;
  EXPECT_NEAR(length(beyond - mirrored), 0, 1e-4f);
}

// A film cropped to part of the image sees what the full image's pixels there see.
TEST(SphericalCamera, ScreenWindowIsThePartOfTheFullImage) {
  for (Projection p : {Projection::Equirectangular, Projection::EqualArea}) {
    const Camera full(spherical_desc(p), 40, 20);
    CameraDesc cropped_desc = spherical_desc(p);
    cropped_desc.screen_window = std::array<float, 4>{0.25f, 0.5f, 0.5f, 1.0f};  // pixels 10..19 x 10..19
    const Camera cropped(cropped_desc, 10, 10);
    for (Vec2 film : {Vec2(0.5f, 0.5f), Vec2(3.2f, 7.9f), Vec2(9.5f, 0.1f)}) {
      const Vec3 a = cropped.generate_ray(film, {0.5f, 0.5f}, 0).direction;
      const Vec3 b = full.generate_ray(film + Vec2(10, 10), {0.5f, 0.5f}, 0).direction;
      EXPECT_NEAR(length(a - b), 0, 1e-5f);
    }
  }
}

TEST(SphericalCamera, IsNeverJoinedToLightPaths) {
  const Camera cam(spherical_desc(Projection::EqualArea), 16, 16);
  Vec2 raster;
  EXPECT_EQ(cam.importance(Point3(0.0f), {0, 0, 1}, &raster), 0);
  EXPECT_EQ(cam.pdf_importance(Point3(0.0f), {0, 0, 1}).dir, 0);
  EXPECT_FALSE(cam.sample_lens({1, 2, 3}, {0.3f, 0.6f}).has_value());
}

// A floor under a sky, seen all around: bidirectional path tracing, without its light-tracing
// strategies, converges to the path tracer's image; the light tracer, which has only those, refuses.
TEST(SphericalCamera, BidirectionalAgreesWithThePathTracerAndTheLightTracerRefuses) {
  SceneDesc desc;
  desc.camera = spherical_desc(Projection::Equirectangular, Transform::translate({0, 1, 0}));
  desc.film.width = 32;
  desc.film.height = 16;
  desc.settings.spp = 64;
  desc.settings.max_depth = 4;
  desc.materials = {DiffuseMaterial{RGB(0.6f, 0.5f, 0.4f)}};
  desc.shapes = {ShapeDesc{.geometry = RectangleShape{{-4, 0, 4}, {8, 0, 0}, {0, 0, -8}}, .material = 0}};
  desc.lights = {SkyLight{RGB(0.8f, 0.9f, 1.0f), RGB(0.6f), RGB(0.2f), {0, 1, 0}}};
  auto mean_of = [&](const std::string& integrator) {
    SceneDesc d = desc;
    d.settings.integrator = integrator;
    return testing::region_mean(testing::render_description(d, 2).mean_image(), -1);
  };
  const testing::MeanEstimate path = mean_of("path"), bdpt = mean_of("bdpt");
  EXPECT_NEAR(path.mean, bdpt.mean, 4 * std::hypot(path.standard_error, bdpt.standard_error) + 1e-4);
  SceneDesc light_path = desc;
  light_path.settings.integrator = "light_path";
  EXPECT_THROW(testing::render_description(light_path, 1), UsageError);
}

TEST(SphericalCamera, PbrtReaderReadsItsMappingsAndIgnoresTheLens) {
  const SceneDesc plain = spherical_pbrt::read_lines({"Camera \"spherical\"", "WorldBegin"});
  EXPECT_EQ(plain.camera.projection, Projection::EqualArea);  // pbrt-v4's default mapping
  const spherical_pbrt::Warned equirect = spherical_pbrt::read_warned(
      {"Camera \"spherical\" \"string mapping\" \"equirectangular\" \"float lensradius\" 0.5 "
       "\"float screenwindow\" [-1 1 -1 1]",
       "WorldBegin"});
  EXPECT_EQ(equirect.scene.camera.projection, Projection::Equirectangular);
  EXPECT_EQ(equirect.scene.camera.lens_radius, 0);
  EXPECT_FALSE(equirect.scene.camera.screen_window.has_value());
  ASSERT_EQ(equirect.warnings.size(), 2u);
  EXPECT_NE(equirect.warnings[0].find("does not apply to a spherical camera"), std::string::npos);
  spherical_pbrt::expect_error({"Camera \"spherical\" \"string mapping\" \"cube\"", "WorldBegin"}, 1, "\"string mapping\"",
               "unknown \"mapping\" \"cube\"");
  spherical_pbrt::expect_error({"Camera \"spherical\" \"float fov\" 40", "WorldBegin"}, 1, "\"float fov\"", "");
  // A cropped film's window is its part of the full image's (u, v).
  const SceneDesc cropped = spherical_pbrt::read_lines({"Camera \"spherical\"",
                                        "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 20 "
                                        "\"integer pixelbounds\" [10 20 10 20]",
                                        "WorldBegin"});
  ASSERT_TRUE(cropped.camera.screen_window.has_value());
  EXPECT_EQ(*cropped.camera.screen_window, (std::array<float, 4>{0.25f, 0.5f, 0.5f, 1.0f}));
  EXPECT_EQ(cropped.film.width, 10);
}

TEST(SphericalCamera, JsonRoundTripsAndRefusesProjectiveKeys) {
  SceneDesc desc;
  desc.camera = spherical_desc(Projection::EqualArea, Transform::translate({1, 2, 3}));
  desc.camera.screen_window = std::array<float, 4>{0, 0.5f, 0, 1};
  const std::string json = scene_to_json(desc);
  EXPECT_EQ(json.find("\"fov\""), std::string::npos);
  const SceneDesc back = read_json_scene(json, "round-trip.json", ".");
  EXPECT_EQ(back.camera.projection, Projection::EqualArea);
  EXPECT_EQ(back.camera.screen_window, desc.camera.screen_window);
  const SceneDesc again = read_json_scene(scene_to_json(back), "round-trip.json", ".");
  EXPECT_EQ(again.camera.projection, back.camera.projection);
  EXPECT_EQ(again.camera.screen_window, back.camera.screen_window);
  EXPECT_THROW(read_json_scene(R"({"camera": {"projection": "equirectangular", "fov": 60}})", "bad.json", "."),
               SceneError);
  EXPECT_THROW(read_json_scene(R"({"camera": {"projection": "equal_area", "lens_radius": 0.1}})", "bad.json", "."),
               SceneError);
}

}  // namespace
}  // namespace candela
