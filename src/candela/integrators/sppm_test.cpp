// Stochastic progressive photon mapping (integrators/sppm.h) against the path tracer and itself: in a
// closed diffuse box lit by an area light its image converges to the path tracer's (the furnace tests,
// furnace_test.cpp, check it against analytic answers through the registry); the photons carry the
// indirect light (without them the image is darker by exactly that share); the search radius shrinks
// as photons arrive; the image is bitwise the same for every thread count; and what it cannot do is
// refused.
#include "candela/integrators/sppm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/integrators/integrator.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

// A closed grey box [-1, 1]^3 seen from inside, lit by a square area light under its ceiling that
// shines down: most of what the camera sees is lit directly and once more indirectly.
SceneDesc sppm_lit_box(int size, int spp, float albedo = 0.7f) {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 0, -0.95f}, {0, -0.1f, 1}, 70), size, size, spp, 5);
  d.materials = {DiffuseMaterial{RGB(albedo)}, DiffuseMaterial{RGB(0.0f)}};
  ShapeDesc box;
  box.geometry = BoxShape{Point3(-1.0f), Point3(1.0f)};
  box.material = 0;
  ShapeDesc light;
  light.geometry = RectangleShape{{-0.3f, 0.98f, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f}};  // normal -y: down
  light.material = 1;
  light.emission = AreaEmission{RGB(4.0f), false};
  d.shapes = {box, light};
  d.settings.integrator = "sppm";
  d.settings.sppm.radius = 0.1f;
  return d;
}

Film sppm_render(const SceneDesc& d, int threads = 0, RenderStats* stats = nullptr) {
  const Scene scene(d);
  Film film(d.film.width, d.film.height);
  RenderOptions options;
  options.threads = threads;
  options.progress = false;
  RenderStats s = render(scene, d.settings, film, options);
  if (stats) *stats = s;
  return film;
}

// The image means of renders with seeds 1..n and their standard error from the spread of the per-seed
// means (photons reach many pixels at once, so the spread of pixels would understate it).
testing::MeanEstimate sppm_seed_mean(SceneDesc d, int seeds) {
  std::vector<double> means;
  for (int seed = 1; seed <= seeds; ++seed) {
    d.settings.seed = uint64_t(seed);
    means.push_back(testing::region_mean(sppm_render(d).mean_image(), -1).mean);
  }
  return testing::mean_of_estimates(means);
}

TEST(Sppm, ConvergesToThePathTracersImageInALitBox) {
  SceneDesc d = sppm_lit_box(24, 16);
  const testing::MeanEstimate sppm = sppm_seed_mean(d, 4);
  d.settings.integrator = "path";
  d.settings.spp = 64;
  const testing::MeanEstimate path = sppm_seed_mean(d, 4);
  // Density estimation blurs the indirect light over the radius (0.1 at first, shrinking): it moves
  // light between neighbouring pixels but keeps the image's mean, except within a radius of the box's
  // edges, where the search sphere also gathers the photons of the adjoining wall. That share (the
  // edges' strip of the walls seen, about 4 r / 2 of each wall's width, times the indirect light's
  // share of the image, under a half) bounds the bias: 3% allowed beyond the noise.
  EXPECT_NEAR(sppm.mean, path.mean,
              5 * std::hypot(sppm.standard_error, path.standard_error) + 0.03 * path.mean)
      << "sppm " << sppm.mean << " +- " << sppm.standard_error << ", path " << path.mean << " +- "
      << path.standard_error;
  // The photons carry the light of depths 2 to 5: without them (max depth 1 for both, no photon has a
  // second hit) the image is darker by that share, as the path tracer's is.
  d.settings.max_depth = 1;
  const testing::MeanEstimate path_direct = sppm_seed_mean(d, 4);
  d.settings.integrator = "sppm";
  d.settings.spp = 16;
  const testing::MeanEstimate sppm_direct = sppm_seed_mean(d, 4);
  EXPECT_NEAR(sppm_direct.mean, path_direct.mean,
              5 * std::hypot(sppm_direct.standard_error, path_direct.standard_error) + 1e-3 * path_direct.mean);
  EXPECT_GT(sppm.mean - sppm_direct.mean, 0.2 * sppm_direct.mean);
}

TEST(Sppm, SearchRadiusShrinksAsPhotonsArrive) {
  SceneDesc d = sppm_lit_box(16, 8);
  RenderStats stats;
  sppm_render(d, 0, &stats);
  const SppmStats* s = sppm_stats(stats);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->iterations, 8);
  EXPECT_EQ(s->photons, 8u * 16u * 16u);  // one photon per pixel per iteration by default
  EXPECT_EQ(stats.samples, 8u * 16u * 16u);
  // Every pixel sees a lit wall and gathers photons: its radius falls below the first one, by at most
  // sqrt(2/3) per iteration.
  EXPECT_LT(s->max_radius, 0.1);
  EXPECT_GT(s->min_radius, 0.1 * std::pow(std::sqrt(2.0 / 3.0), 8) * 0.999);
  d.settings.sppm.photons_per_iteration = 100;
  sppm_render(d, 0, &stats);
  EXPECT_EQ(sppm_stats(stats)->photons, 800u);
}

TEST(Sppm, SameImageForEveryThreadCount) {
  SceneDesc d = sppm_lit_box(16, 4);
  d.settings.spectral = true;  // the iteration's wavelengths too
  const Film one = sppm_render(d, 1), two = sppm_render(d, 2);
  for (int y = 0; y < d.film.height; ++y)
    for (int x = 0; x < d.film.width; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(one.pixel(x, y).weighted[c], two.pixel(x, y).weighted[c]) << x << "," << y;
  EXPECT_EQ(one.pixel(3, 3).count, 4u);  // a sample per iteration
}

TEST(Sppm, RefusesMediaAndAnErrorTarget) {
  SceneDesc d = sppm_lit_box(8, 2);
  d.media = {MediumDesc{}};
  d.camera.medium = 0;
  EXPECT_THROW(sppm_render(d), UsageError);
  const IntegratorEntry* sppm = find_integrator("sppm");
  ASSERT_NE(sppm, nullptr);
  EXPECT_THROW(check_capabilities(*sppm, {.target_error = true}), UsageError);
  EXPECT_THROW(check_capabilities(*sppm, {.continues_film = true}), UsageError);
  EXPECT_NO_THROW(check_capabilities(*sppm, {}));
}

}  // namespace
}  // namespace candela
