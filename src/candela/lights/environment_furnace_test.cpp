// Furnace tests for environment maps, rendered end to end from a scene description with the map
// read from an EXR file. A convex diffuse sphere alone under distant light reflects
// L = albedo / pi * E(n) with E(n) the irradiance the map gives a plane facing n (the sphere never
// sees itself), so:
//   - under a constant map L, every point is albedo * L and the background is L;
//   - under a map of radiance L only in the upper hemisphere around +y, E(n) = pi L (1 + n_y) / 2
//     (the sky-view factor of a plane tilted from the zenith).
// Each check asserts a mean within 4 standard errors estimated from the render itself.
#include <gtest/gtest.h>

#include <string>

#include "candela/sampling/warp.h"
#include "candela/testing/render_helpers.h"
#include "candela/testing/temp_image_file.h"

namespace candela {
namespace {

using testing::look_at_camera;
using testing::TempImageFile;
using testing::region_mean;
using testing::render_description;

constexpr int kSize = 32;  // film width and height
constexpr float kAlbedo = 0.8f;

// A unit sphere at the origin seen from z = -4 (it subtends asin(1/4) = 14.5 degrees; the fov is 40).
SceneDesc sphere_under_environment(const EnvironmentMap& map, int spp) {
  SceneDesc d;
  d.film = {kSize, kSize, ""};
  d.camera = look_at_camera({0, 0, -4}, {0, 0, 0}, 40);
  d.settings.spp = spp;
  d.settings.max_depth = 8;  // the sphere is convex: rays leaving it escape
  d.materials = {DiffuseMaterial{RGB(kAlbedo)}};
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, 0}, 1};
  s.material = 0;
  d.shapes = {s};
  d.lights = {map};
  return d;
}

// The film position (x, y) in pixels as a camera-space direction (+y up, row 0 at the top).
Vec3 camera_direction(float x, float y) {
  float t = std::tan(radians(20));
  return normalize(Vec3((2 * x / kSize - 1) * t, (1 - 2 * y / kSize) * t, 1));
}
float angle_from_axis(int x, int y) {
  Vec3 d = camera_direction(x + 0.5f, y + 0.5f);
  return std::acos(d.z) * 180 / kPi;
}
// Pixel centres looking well inside the silhouette (< 10 degrees off the axis) or well outside it.
bool inside_silhouette(int x, int y) { return angle_from_axis(x, y) < 10; }
bool outside_silhouette(int x, int y) { return angle_from_axis(x, y) > 17; }

// The mean over pixel (x, y) of the sphere's normal's y component (the camera's +y is world +y and
// its axis world +z; the sign of x does not matter here): a midpoint rule on a sub-pixel grid.
double mean_normal_y(int x, int y) {
  const int n = 8;
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      Vec3 d = camera_direction(x + (i + 0.5f) / n, y + (j + 0.5f) / n);
      // Nearest hit of (0, 0, -4) + t d with the unit sphere.
      double b = -4.0 * d.z, c = 16.0 - 1.0;
      double t = -b - std::sqrt(b * b - c);
      sum += t * d.y;  // the hit point's y is the normal's y
    }
  return sum / (n * n);
}

void expect_within_standard_errors(const testing::MeanEstimate& e, double expected, const std::string& what) {
  double tolerance = 4 * e.standard_error + 1e-5 * std::max(1.0, std::abs(expected));
  EXPECT_NEAR(e.mean, expected, tolerance) << what << ": standard error " << e.standard_error << " over "
                                           << e.pixels << " pixels";
}

TEST(EnvironmentFurnace, DiffuseSphereUnderConstantMapIsAlbedoTimesRadiance) {
  const RGB L(0.5f, 1.0f, 2.0f);
  struct Case {
    EnvironmentMapping mapping;
    int width, height;
    Transform to_world;
  };
  for (const Case& c : {Case{EnvironmentMapping::Equirectangular, 16, 8, Transform()},
                        Case{EnvironmentMapping::EqualAreaOctahedral, 8, 8,
                             Transform::rotate(30, normalize(Vec3(1, 1, 0)))}}) {
    Image img(c.width, c.height);
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) img.set(x, y, L);
    TempImageFile file(img, c.mapping == EnvironmentMapping::Equirectangular ? "constant-latlong" : "constant-octa");
    Image out = render_description(sphere_under_environment({file.path(), c.mapping, RGB(1.0f), c.to_world}, 32))
                    .mean_image();
    for (int ch = 0; ch < 3; ++ch) {
      std::string what = c.mapping == EnvironmentMapping::Equirectangular ? "equirectangular" : "octahedral";
      what += " channel " + std::to_string(ch);
      expect_within_standard_errors(region_mean(out, ch, inside_silhouette), kAlbedo * L[ch], what + " sphere");
      expect_within_standard_errors(region_mean(out, ch, outside_silhouette), L[ch], what + " background");
    }
  }
}

// Renders the sphere under `map` (radiance L above the world's horizon, nothing below) and compares
// every pixel inside the silhouette with albedo L (1 + mean n_y) / 2: over the upper and the lower
// half of the sphere separately, so a map upside down or ignored cannot pass.
void expect_sky_view_factor(const EnvironmentMap& map, const RGB& L, const std::string& what) {
  Image out = render_description(sphere_under_environment(map, 64)).mean_image();
  Image diff(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      if (!inside_silhouette(x, y)) continue;
      double factor = kAlbedo * (1 + mean_normal_y(x, y)) / 2;
      RGB r = out.at(x, y);
      diff.set(x, y, RGB(float(r.r - L.r * factor), float(r.g - L.g * factor), float(r.b - L.b * factor)));
    }
  auto upper = [](int x, int y) { return inside_silhouette(x, y) && y < kSize / 2; };
  auto lower = [](int x, int y) { return inside_silhouette(x, y) && y >= kSize / 2; };
  for (int ch = 0; ch < 3; ++ch) {
    std::string channel = ", channel " + std::to_string(ch);
    expect_within_standard_errors(region_mean(diff, ch, upper), 0.0, what + " upper half" + channel);
    expect_within_standard_errors(region_mean(diff, ch, lower), 0.0, what + " lower half" + channel);
  }
  // The top of the sphere faces the bright sky, the bottom the dark ground.
  EXPECT_GT(region_mean(out, -1, upper).mean, 1.5 * region_mean(out, -1, lower).mean) << what;
}

TEST(EnvironmentFurnace, UpperHemisphereEquirectangularMapGivesTheSkyViewFactor) {
  // Rows above the middle are theta < pi/2 (+y up). Bilinear interpolation blurs the horizon over
  // one row either side, symmetrically, which changes the irradiance only to second order.
  const RGB L(1.0f, 0.8f, 0.6f);
  const int w = 256, h = 128;
  Image img(w, h);
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w; ++x) img.set(x, y, L);
  TempImageFile file(img, "upper-latlong");
  expect_sky_view_factor({file.path(), EnvironmentMapping::Equirectangular, RGB(1.0f), Transform()}, L,
                         "equirectangular");
}

TEST(EnvironmentFurnace, UpperHemisphereOctahedralMapRotatedToYUpGivesTheSkyViewFactor) {
  // The equal-area square's +z hemisphere (the inner diamond), turned to +y by the map's to_world.
  // Pixels on the diamond's edge get the fraction of their area inside it.
  const RGB L(0.6f, 0.9f, 1.2f);
  const int n = 128, sub = 8;
  Image img(n, n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      int inside = 0;
      for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i)
          inside += equal_area_square_to_sphere({(x + (i + 0.5f) / sub) / n, (y + (j + 0.5f) / sub) / n}).z > 0;
      img.set(x, y, L * (float(inside) / (sub * sub)));
    }
  TempImageFile file(img, "upper-octa");
  Transform z_to_y = Transform::rotate(-90, {1, 0, 0});
  expect_sky_view_factor({file.path(), EnvironmentMapping::EqualAreaOctahedral, RGB(1.0f), z_to_y}, L,
                         "octahedral");
}

}  // namespace
}  // namespace candela
