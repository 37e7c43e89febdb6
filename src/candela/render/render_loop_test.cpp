// The render loop's control: stopping (cancel flag, time limit), continuing a partly rendered film
// bit for bit, single-pixel renders, clamping, and NaN/inf samples kept off the film.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

SceneDesc small_scene(int spp) {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 2, -6}, {0, 0.5f, 0}, 40), 24, 18, spp, 4);
  d.settings.sampler.type = SamplerType::Stratified;
  d.materials = {DiffuseMaterial{RGB(0.7f)}};
  ShapeDesc floor{.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}}, .material = 0};
  ShapeDesc sphere{.geometry = SphereShape{{0, 1, 0}, 1}, .material = 0};
  d.shapes = {floor, sphere};
  d.lights = {PointLight{{-3, 3, -2}, RGB(20.0f)}, SkyLight{RGB(0.3f), RGB(0.3f), RGB(0.3f), {0, 1, 0}}};
  return d;
}

RenderOptions quiet_options() {
  RenderOptions o;
  o.progress = false;
  o.threads = 2;
  return o;
}

bool same_sums(const Film& a, const Film& b) {
  return a.pixels().size() == b.pixels().size() &&
         std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(PixelSums)) == 0;
}

TEST(RenderControl, StoppedAndContinuedFilmIsBitwiseTheUninterruptedOne) {
  SceneDesc d = small_scene(48);  // three passes of 16 samples per pixel
  Scene scene(d);
  Film full(d.film.width, d.film.height);
  render(scene, d.settings, full, quiet_options());

  Film part(d.film.width, d.film.height);
  std::atomic<bool> stop{false};
  RenderOptions o = quiet_options();
  o.cancel = &stop;
  int passes = 0;
  o.after_pass = [&](const Film&, uint64_t) {
    if (++passes == 2) stop = true;
  };
  RenderStats s = render(scene, d.settings, part, o);
  EXPECT_TRUE(s.cancelled);
  EXPECT_EQ(part.min_samples(), 32u);
  EXPECT_EQ(part.max_samples(), 32u);
  EXPECT_FALSE(same_sums(part, full));

  // A film whose pixels stopped at different counts (as a cancel between tiles leaves it) continues too.
  for (int x = 0; x < 5; ++x) {
    PixelSums& p = part.pixels()[size_t(x)];
    p = full.pixel(x, 0);  // "finished" pixels of the same render
  }
  RenderStats rest = render(scene, d.settings, part, quiet_options());
  EXPECT_FALSE(rest.cancelled);
  EXPECT_TRUE(same_sums(part, full));
}

// A time limit stops the render with every pixel at the same count: after whole passes with a
// set-based sampler (its sets are not cut), with others after a last pass cut to what fits.
TEST(RenderControl, TimeLimitStopsWithEveryPixelAtTheSameCount) {
  for (SamplerType type : {SamplerType::Stratified, SamplerType::Independent, SamplerType::ZSobol}) {
    SceneDesc d = small_scene(1 << 20);
    d.settings.sampler.type = type;
    Scene scene(d);
    Film film(d.film.width, d.film.height);
    RenderOptions o = quiet_options();
    o.time_limit_seconds = 0.05;
    RenderStats s = render(scene, d.settings, film, o);
    EXPECT_TRUE(s.time_limited);
    EXPECT_GT(film.min_samples(), 0u);
    EXPECT_EQ(film.min_samples(), film.max_samples());
    if (type == SamplerType::Stratified) EXPECT_EQ(film.min_samples() % 16, 0u);
    EXPECT_LT(film.min_samples(), uint64_t(1 << 20));
  }
}

TEST(RenderControl, SinglePixelMatchesTheFullRender) {
  SceneDesc d = small_scene(16);
  Scene scene(d);
  Film full(d.film.width, d.film.height), one(d.film.width, d.film.height);
  render(scene, d.settings, full, quiet_options());
  RenderOptions o = quiet_options();
  o.only_x = 13;
  o.only_y = 9;
  RenderStats s = render(scene, d.settings, one, o);
  EXPECT_EQ(s.samples, 16u);
  EXPECT_EQ(std::memcmp(&one.pixel(13, 9), &full.pixel(13, 9), sizeof(PixelSums)), 0);
  EXPECT_EQ(one.pixel(0, 0).count, 0u);
}

TEST(RenderControl, ClampBoundsEverySample) {
  SceneDesc d = small_scene(8);
  d.lights = {PointLight{{-3, 3, -2}, RGB(2000.0f)}};
  Scene scene(d);
  Film plain(d.film.width, d.film.height), clamped(d.film.width, d.film.height);
  render(scene, d.settings, plain, quiet_options());
  RenderOptions o = quiet_options();
  o.clamp = 0.25f;
  render(scene, d.settings, clamped, o);
  float plain_max = 0;
  for (float v : plain.mean_image().rgb) plain_max = std::max(plain_max, v);
  EXPECT_GT(plain_max, 1.0f);
  for (float v : clamped.mean_image().rgb) EXPECT_LE(v, 0.25f * (1 + 1e-5f));
}

// An emitter with NaN radiance in view: its samples are counted and dropped, never reach the film,
// and the first few are reported with pixel and sample index, in a thread-independent order.
TEST(RenderControl, NanSamplesAreDroppedCountedAndReported) {
  SceneDesc d = small_scene(8);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  ShapeDesc bad{.geometry = SphereShape{{0, 1.0f, -1.2f}, 0.3f}, .material = 0,
                .emission = AreaEmission{RGB(nan, 1.0f, 1.0f), true}};
  d.shapes.push_back(bad);
  d.lights = {SkyLight{RGB(0.3f), RGB(0.3f), RGB(0.3f), {0, 1, 0}}};
  Scene scene(d);
  Film film(d.film.width, d.film.height);
  RenderStats s = render(scene, d.settings, film, quiet_options());
  EXPECT_GT(s.non_finite_samples, 0u);
  ASSERT_EQ(s.first_non_finite.size(), std::min<size_t>(5, s.non_finite_samples));
  for (size_t i = 1; i < s.first_non_finite.size(); ++i) {
    const auto &a = s.first_non_finite[i - 1], &b = s.first_non_finite[i];
    EXPECT_TRUE(std::tie(a.sample, a.y, a.x) < std::tie(b.sample, b.y, b.x));
  }
  for (const PixelSums& p : film.pixels()) {
    EXPECT_EQ(p.count, 8u);
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(p.weighted[c]));
      EXPECT_TRUE(std::isfinite(p.weighted_sq[c]));
    }
  }
  for (float v : film.mean_image().rgb) EXPECT_TRUE(std::isfinite(v));

  // The same report with one thread, and the single-pixel render reproduces a reported sample.
  RenderOptions one = quiet_options();
  one.threads = 1;
  Film film1(d.film.width, d.film.height);
  RenderStats s1 = render(scene, d.settings, film1, one);
  EXPECT_EQ(s1.non_finite_samples, s.non_finite_samples);
  ASSERT_EQ(s1.first_non_finite.size(), s.first_non_finite.size());
  for (size_t i = 0; i < s.first_non_finite.size(); ++i) {
    EXPECT_EQ(s1.first_non_finite[i].x, s.first_non_finite[i].x);
    EXPECT_EQ(s1.first_non_finite[i].y, s.first_non_finite[i].y);
    EXPECT_EQ(s1.first_non_finite[i].sample, s.first_non_finite[i].sample);
  }
  RenderOptions pixel = quiet_options();
  pixel.only_x = s.first_non_finite[0].x;
  pixel.only_y = s.first_non_finite[0].y;
  pixel.max_reported_non_finite = 1000;
  Film film2(d.film.width, d.film.height);
  RenderStats s2 = render(scene, d.settings, film2, pixel);
  ASSERT_FALSE(s2.first_non_finite.empty());
  EXPECT_EQ(s2.first_non_finite[0].sample, s.first_non_finite[0].sample);
}

}  // namespace
}  // namespace candela
