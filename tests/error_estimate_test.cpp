// The image's error estimated from its own two independent halves (film/error_estimate.h), against
// the true relMSE of the same image (eps 0.01) with respect to a long render; and --target-error.
// A small version of bench/error_estimate_accuracy.py, which measures it on the Bitterli scenes
// against pbrt-v4's references (docs/error-estimates.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "candela/film/error_estimate.h"
#include "candela/integrators/integrator.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

// The built-in Cornell box (zsobol) at 48 x 48.
SceneDesc cornell_box(int spp, uint64_t seed, const std::string& integrator = "path") {
  SceneDesc desc = read_json_scene(builtin_scene_json(), "<built-in cornell-box.json>", ".");
  desc.film.width = desc.film.height = 48;
  desc.settings.spp = spp;
  desc.settings.seed = seed;
  desc.settings.integrator = integrator;
  desc.settings.sampler.replicas = true;
  return desc;
}

const Image& reference() {
  static const Image image = [] {
    SceneDesc desc = cornell_box(4096, 1000);
    desc.settings.sampler.replicas = false;
    return testing::render_description(desc).mean_image();
  }();
  return image;
}

struct Outcome {
  double estimate = 0, truth = 0;
  bool covered = false;
};

Outcome measure(const SceneDesc& desc) {
  Scene scene(desc);
  Film film(desc.film.width, desc.film.height);
  RenderOptions options;
  options.progress = false;
  RenderStats stats = render(scene, desc.settings, film, options);
  ErrorEstimate e = estimate_error(film, stats.splat_scale_relative_error);
  EXPECT_TRUE(e.valid) << e.why_not;
  Outcome o{e.relmse, testing::rel_mse(film.mean_image(), reference())};
  o.covered = e.low <= o.truth && o.truth <= e.high;
  return o;
}

// Every integrator, two budgets, three seeds: the estimate within a factor 1.5 of the truth, and the
// truth inside the 95% interval in most runs. (The reference's own error, 1/256 of the 16-spp
// error, is negligible.)
TEST(ErrorEstimate, AgreesWithTheTrueErrorUnderEveryIntegrator) {
  struct Case {
    const char* integrator;
    SamplerType sampler;
    int spp;
  };
  const Case cases[] = {{"path", SamplerType::ZSobol, 16},      {"path", SamplerType::ZSobol, 64},
                        {"path", SamplerType::Independent, 16}, {"path", SamplerType::Stratified, 32},
                        {"bdpt", SamplerType::ZSobol, 16},      {"mlt", SamplerType::ZSobol, 64}};
  int runs = 0, covered = 0;
  for (const Case& c : cases)
    for (uint64_t seed : {1, 2, 3}) {
      SceneDesc desc = cornell_box(c.spp, seed, c.integrator);
      desc.settings.sampler.type = c.sampler;
      if (std::string(c.integrator) == "mlt") desc.settings.mlt.chains = 64;
      Outcome o = measure(desc);
      std::printf("%s, sampler %d, %d spp, seed %d: estimate %.5f, truth %.5f\n", c.integrator, int(c.sampler), c.spp,
                  int(seed), o.estimate, o.truth);
      EXPECT_LT(o.estimate, 1.5 * o.truth) << c.integrator << " " << c.spp << " seed " << seed;
      EXPECT_GT(o.estimate, o.truth / 1.5) << c.integrator << " " << c.spp << " seed " << seed;
      ++runs;
      covered += o.covered;
    }
  EXPECT_GE(covered, runs * 8 / 10) << covered << " of " << runs << " intervals hold the truth";
}

TEST(ErrorEstimate, NeedsTwoIndependentHalves) {
  // One ZSobol net has no independent halves: no estimate, and it says why.
  SceneDesc desc = cornell_box(16, 1);
  desc.settings.sampler.replicas = false;
  ErrorEstimate e = estimate_error(testing::render_description(desc));
  EXPECT_FALSE(e.valid);
  EXPECT_NE(e.why_not.find("only one of the two independent halves"), std::string::npos) << e.why_not;
  // Independent samples always have them.
  desc.settings.sampler.type = SamplerType::Independent;
  EXPECT_TRUE(estimate_error(testing::render_description(desc)).valid);
}

TEST(ErrorEstimate, ReplicasAreTheSameImageForAnyThreadCount) {
  SceneDesc desc = cornell_box(24, 5);
  EXPECT_EQ(testing::render_description(desc, 1).mean_image().rgb, testing::render_description(desc, 2).mean_image().rgb);
}

// --target-error: stops once the estimate is at the target, and the true error is then within
// 1.5x of it, with fewer samples than the cap; the path tracer and BDPT.
TEST(ErrorEstimate, TargetErrorStopsNearTheTarget) {
  for (const char* integrator : {"path", "bdpt"}) {
    SceneDesc desc = cornell_box(4096, 7, integrator);
    Scene scene(desc);
    Film film(desc.film.width, desc.film.height);
    RenderOptions options;
    options.progress = false;
    options.target_error = 0.004;
    RenderStats stats = render(scene, desc.settings, film, options);
    const double truth = testing::rel_mse(film.mean_image(), reference());
    std::printf("%s: target 0.004 reached at %llu spp, true relMSE %.5f\n", integrator,
                (unsigned long long)film.max_samples(), truth);
    EXPECT_TRUE(stats.reached_target) << integrator;
    EXPECT_LT(film.max_samples(), 4096u) << integrator;
    EXPECT_LE(truth, 1.5 * 0.004) << integrator;
    EXPECT_LE(estimate_error(film).relmse, 0.004) << integrator;
  }
}

}  // namespace
}  // namespace candela
