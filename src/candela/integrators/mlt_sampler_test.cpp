// The primary-sample-space sampler: which numbers each kind of mutation moves, that a rejection
// puts everything back, and that a Metropolis chain driven by it (every kind of mutation mixed)
// samples a known target density.
#include "candela/integrators/mlt_sampler.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace candela {
namespace {

// Reads camera stream numbers 0-2 and light stream numbers 0-4, as a path of depth >= 1 does
// (strategy, film position; light choice, point on the light, direction leaving it).
struct Numbers {
  float camera[3], light[5];
};
Numbers read_numbers(MltSampler& sampler) {
  Numbers n{};
  sampler.start_stream(MltSampler::kCameraStream);
  for (float& x : n.camera) x = sampler.get_1d();
  sampler.start_stream(MltSampler::kLightStream);
  for (float& x : n.light) x = sampler.get_1d();
  return n;
}

const MltPerturbedNumbers kPerturbed{1, 3, {64, 32}};

TEST(MltSampler, EachPerturbationMovesOnlyItsPair) {
  MltSampler sampler(7, 3, 0.01f, {0.1f, 0.3f, 0.3f}, kPerturbed);
  Numbers current = read_numbers(sampler);  // the start: a large step
  int lens = 0, caustic = 0;
  for (int i = 0; i < 2000; ++i) {
    sampler.start_iteration();
    Numbers next = read_numbers(sampler);
    auto mutation = sampler.mutation();
    for (int k = 0; k < 3; ++k) {
      bool moves = mutation == MltSampler::Mutation::Large || mutation == MltSampler::Mutation::Small ||
                   (mutation == MltSampler::Mutation::Lens && k >= 1);
      if (!moves) {
        EXPECT_EQ(next.camera[k], current.camera[k]) << i << " camera " << k;
      }
    }
    for (int k = 0; k < 5; ++k) {
      bool moves = mutation == MltSampler::Mutation::Large || mutation == MltSampler::Mutation::Small ||
                   (mutation == MltSampler::Mutation::Caustic && k >= 3);
      if (!moves) {
        EXPECT_EQ(next.light[k], current.light[k]) << i << " light " << k;
      }
    }
    if (mutation == MltSampler::Mutation::Lens) {
      ++lens;
      // Within Veach's radii: 0.1 pixel to 10% of the larger side (6.4 pixels), around the torus.
      float dx = std::remainder(next.camera[1] - current.camera[1], 1.0f) * 64;
      float dy = std::remainder(next.camera[2] - current.camera[2], 1.0f) * 32;
      float r = std::hypot(dx, dy);
      EXPECT_GE(r, 0.099f);
      EXPECT_LE(r, 6.41f);
    }
    if (mutation == MltSampler::Mutation::Caustic) ++caustic;
    // Alternate: accept one proposal, reject the next, which must restore every number.
    if (i % 2 == 0) {
      sampler.accept();
      current = next;
    } else {
      sampler.reject();
      sampler.start_iteration();
      sampler.reject();  // a proposal that reads nothing changes nothing
    }
  }
  EXPECT_GT(lens, 400);
  EXPECT_GT(caustic, 400);
}

TEST(MltSampler, ChainWithEveryMutationSamplesItsTarget) {
  // Target density over the eight numbers: a product of factors on the strategy number, the film
  // pair, the light-choice number and the direction pair; the chain's averages of a few functions
  // must match their expectations under it, within 5 standard errors from batch means (the
  // chain's samples are correlated).
  auto film = [](float x, float y) { return 0.05f + x * y * y; };
  auto direction = [](float x, float y) { return 0.1f + (x - 0.3f) * (x - 0.3f) + 2 * y * (1 - y); };
  auto target = [&](const Numbers& n) {
    return (0.5f + n.camera[0]) * film(n.camera[1], n.camera[2]) * (1.5f - n.light[0]) *
           direction(n.light[3], n.light[4]);
  };
  // Expectations by the midpoint rule.
  const int grid = 400;
  double film_w = 0, film_x = 0, film_y = 0, dir_w = 0, dir_x = 0, dir_y = 0;
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      float x = (i + 0.5f) / grid, y = (j + 0.5f) / grid;
      film_w += film(x, y), film_x += film(x, y) * x, film_y += film(x, y) * y;
      dir_w += direction(x, y), dir_x += direction(x, y) * x, dir_y += direction(x, y) * y;
    }
  const double expected[5] = {film_x / film_w, film_y / film_w, dir_x / dir_w, dir_y / dir_w,
                              (7.0 / 12) / 1.0 /* E[c0] under 0.5 + c0 */};

  // Second pass: as in the renderer, where a perturbation would not move the path (here: the
  // strategy number below 0.4 for the lens move, above 0.6 for the caustic one) it becomes a small
  // step, and small steps are accepted with Hastings' ratio of their state-dependent chances.
  // (Without that ratio the strategy number's mean comes out 0.5781 against 0.5833, 5.3 standard
  // errors, and this fails.)
  for (bool state_dependent : {false, true}) {
    auto lens_moves = [&](const Numbers& n) { return !state_dependent || n.camera[0] >= 0.4f; };
    auto caustic_moves = [&](const Numbers& n) { return !state_dependent || n.camera[0] <= 0.6f; };
    // Mostly perturbations, so that small steps are five times likelier where they stand in for one.
    MltSampler sampler(11, 5, 0.05f, state_dependent ? MltMutationProbabilities{0.1f, 0.4f, 0.4f}
                                                     : MltMutationProbabilities{0.2f, 0.3f, 0.3f},
                       kPerturbed);
    Rng accept_rng(1, 2);
    Numbers current = read_numbers(sampler);
    float f_current = target(current);
    const int batches = 50, per_batch = 40000;
    std::vector<std::array<double, 5>> batch_means(batches, {0, 0, 0, 0, 0});
    for (int b = 0; b < batches; ++b)
      for (int i = 0; i < per_batch; ++i) {
        sampler.start_iteration(lens_moves(current), caustic_moves(current));
        Numbers next = read_numbers(sampler);
        float ratio = target(next) / f_current;
        if (sampler.mutation() == MltSampler::Mutation::Small)
          ratio *= sampler.small_step_probability(lens_moves(next), caustic_moves(next)) /
                   sampler.small_step_probability(lens_moves(current), caustic_moves(current));
        if (accept_rng.next_float() < std::min(1.0f, ratio)) {
          sampler.accept();
          current = next;
          f_current = target(next);
        } else {
          sampler.reject();
        }
        const double values[5] = {current.camera[1], current.camera[2], current.light[3], current.light[4],
                                  current.camera[0]};
        for (int k = 0; k < 5; ++k) batch_means[size_t(b)][size_t(k)] += values[k] / per_batch;
      }
    for (int k = 0; k < 5; ++k) {
      double mean = 0, sq = 0;
      for (const auto& m : batch_means) mean += m[size_t(k)] / batches;
      for (const auto& m : batch_means) sq += (m[size_t(k)] - mean) * (m[size_t(k)] - mean);
      double se = std::sqrt(sq / (batches - 1) / batches);
      EXPECT_NEAR(mean, expected[k], 5 * se + 1e-4)
          << "function " << k << " (se " << se << ")" << (state_dependent ? ", state-dependent perturbations" : "");
    }
  }
}

}  // namespace
}  // namespace candela
