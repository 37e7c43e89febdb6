// The light tracer (integrators/light_path.h) against the path tracer and analytic answers: where the
// camera sees only diffuse surfaces it converges to the same image (a point light in a closed diffuse
// sphere; a diffuse sphere lit by the sky, whose light paths start on the scene's disk), what the
// camera sees through a delta surface and the sky seen directly are black, and the render is the
// same for every thread count (splats are fixed-point sums).
#include "candela/integrators/light_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using LightPathRegion = std::function<bool(int, int)>;

// The mean of `region` over renders of `d` with `integrator` and seeds 1..n, and its standard error
// from the spread of the per-seed means (a light path splats onto neighbouring pixels, so the spread
// of pixels would understate it).
testing::MeanEstimate light_path_seed_mean(SceneDesc d, const std::string& integrator, const LightPathRegion& region,
                                           int seeds = 6) {
  d.settings.integrator = integrator;
  std::vector<double> means;
  for (int seed = 1; seed <= seeds; ++seed) {
    d.settings.seed = uint64_t(seed);
    means.push_back(testing::region_mean(testing::render_description(d).mean_image(), -1, region).mean);
  }
  return testing::mean_of_estimates(means);
}

// Pixels well inside the silhouette of sphere_under_sky's sphere seen with a 20-degree view (it
// subtends 14.5 degrees: the whole image).
bool light_path_inside_sphere(int x, int y) {
  float sx = 2 * (x + 0.5f) / 16 - 1, sy = 2 * (y + 0.5f) / 16 - 1;
  return sx * sx + sy * sy < 0.5f;
}

// With a 60-degree view the sphere's silhouette has radius tan(14.5) / tan(30) = 0.45 of the half
// image: pixels well inside it, and pixels of the sky well outside it.
bool light_path_inside_small_sphere(int x, int y) {
  float sx = 2 * (x + 0.5f) / 16 - 1, sy = 2 * (y + 0.5f) / 16 - 1;
  return sx * sx + sy * sy < 0.09f;
}

bool light_path_sky_around_small_sphere(int x, int y) {
  float sx = 2 * (x + 0.5f) / 16 - 1, sy = 2 * (y + 0.5f) / 16 - 1;
  return sx * sx + sy * sy > 0.36f;
}

TEST(LightPath, ConvergesToThePathTracersImageOfAClosedDiffuseSphereQuadrantByQuadrant) {
  // A point light at the centre of a closed diffuse sphere: every pixel is I / (pi r^2) (rho + ... +
  // rho^depth), and the path tracer agrees region by region.
  const float rho = 0.5f, I = 3.0f, r = 2.0f;
  const int depth = 3;
  SceneDesc d = testing::closed_diffuse_sphere(rho, depth);
  d.lights = {PointLight{{0, 0, 0}, RGB(I)}};
  d.settings.spp = 8;
  const double expected = I / (kPi * r * r) * rho * (1 - std::pow(rho, depth)) / (1 - rho);
  for (int quadrant = 0; quadrant < 4; ++quadrant) {
    SCOPED_TRACE(quadrant);
    const LightPathRegion region = [quadrant](int x, int y) { return (x >= 8) + 2 * (y >= 8) == quadrant; };
    const testing::MeanEstimate light = light_path_seed_mean(d, "light_path", region);
    const testing::MeanEstimate path = light_path_seed_mean(d, "path", region);
    EXPECT_GT(light.mean, 0.5 * expected);
    EXPECT_NEAR(light.mean, path.mean, 5 * std::hypot(light.standard_error, path.standard_error));
    EXPECT_NEAR(light.mean, expected, 5 * light.standard_error + 1e-3 * expected);
  }
}

TEST(LightPath, RendersADiffuseSphereLitByTheSkyButNotTheSkyItself) {
  // One bounce off a convex diffuse sphere under a uniform sky of 2: albedo x 2 = 1.4. The light paths
  // start on the disk facing their direction; the sky seen directly cannot be joined to the lens.
  SceneDesc d = testing::sphere_under_sky(DiffuseMaterial{RGB(0.7f)}, RGB(2.0f), 16, 60, 64, 5);
  const testing::MeanEstimate inside = light_path_seed_mean(d, "light_path", light_path_inside_small_sphere);
  EXPECT_NEAR(inside.mean, 1.4, 5 * inside.standard_error + 2e-3);
  EXPECT_EQ(light_path_seed_mean(d, "light_path", light_path_sky_around_small_sphere, 2).mean, 0.0);
  EXPECT_NEAR(light_path_seed_mean(d, "path", light_path_sky_around_small_sphere, 2).mean, 2.0, 1e-3);
}

TEST(LightPath, IsBlackWhereTheCameraSeesADeltaSurface) {
  // A mirror sphere under the sky: the path tracer sees the sky in it, the light tracer nothing.
  SceneDesc d = testing::sphere_under_sky(MirrorMaterial{RGB(0.8f)}, RGB(2.0f), 16, 20, 8, 5);
  EXPECT_EQ(light_path_seed_mean(d, "light_path", light_path_inside_sphere, 2).mean, 0.0);
  EXPECT_GT(light_path_seed_mean(d, "path", light_path_inside_sphere, 2).mean, 1.0);
}

TEST(LightPath, RendersTheSameImageForEveryThreadCount) {
  SceneDesc d = testing::closed_diffuse_sphere(0.6f, 4);
  d.lights = {PointLight{{0.3f, 0, 0}, RGB(2.0f)}};
  d.settings.integrator = "light_path";
  d.settings.spp = 4;
  const Image one = testing::render_description(d, 1).mean_image();
  const Image two = testing::render_description(d, 2).mean_image();
  ASSERT_EQ(one.rgb.size(), two.rgb.size());
  EXPECT_EQ(one.rgb, two.rgb);
}

}  // namespace
}  // namespace candela
