// Piecewise-constant 1D and 2D distributions: samples follow the reported pdf (chi-square on a grid
// finer than the cells, so uniformity within cells is tested too), the pdf integrates to one, and
// cells of zero weight are never sampled.
#include "candela/sampling/distribution2d.h"

#include <gtest/gtest.h>

#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::kChiSquareSamples;

TEST(PiecewiseConstant1D, PiecewiseConstantSamplesItsPdf) {
  const std::vector<float> weights = {0.5f, 0.0f, 3.0f, 1.0f, 0.0f, 0.25f, 2.0f};
  PiecewiseConstant1D dist(weights);
  EXPECT_NEAR(dist.integral(), 6.75 / 7, 1e-6);
  // Bins three times finer than the cells.
  const int bins = 3 * int(weights.size());
  std::vector<double> observed(bins, 0), expected(bins, 0);
  Rng rng(3, 5);
  for (int i = 0; i < kChiSquareSamples; ++i) {
    float pdf;
    size_t cell;
    float x = dist.sample(rng.next_float(), &pdf, &cell);
    ASSERT_GE(x, 0);
    ASSERT_LT(x, 1);
    ASSERT_EQ(dist.cell(x), cell);
    ASSERT_EQ(dist.pdf(x), pdf);
    ASSERT_GT(weights[cell], 0);
    observed[std::min(bins - 1, int(x * bins))] += 1;
  }
  double total = 0;
  for (int b = 0; b < bins; ++b) {
    expected[b] = double(kChiSquareSamples) * dist.pdf((b + 0.5f) / bins) / bins;
    total += dist.pdf((b + 0.5f) / bins) / bins;
  }
  EXPECT_NEAR(total, 1.0, 1e-6);
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(PiecewiseConstant1D, AllZeroWeightsAreUniform) {
  PiecewiseConstant1D dist(std::vector<float>{0, 0, 0, 0});
  for (float x : {0.1f, 0.4f, 0.6f, 0.99f}) EXPECT_FLOAT_EQ(dist.pdf(x), 1.0f);
  EXPECT_NEAR(dist.sample(0.3f), 0.3f, 1e-6f);
}

// A small random function with some empty cells and an empty row.
struct RandomGrid {
  int nu = 7, nv = 5;
  std::vector<float> weights;
  RandomGrid() {
    Rng rng(17, 4);
    for (int v = 0; v < nv; ++v)
      for (int u = 0; u < nu; ++u) {
        float w = rng.next_float();
        weights.push_back(v == 2 ? 0.0f : (w < 0.2f ? 0.0f : w * w * 10));
      }
  }
};

TEST(Distribution2D, SamplesFollowThePdf) {
  RandomGrid g;
  Distribution2D dist(g.weights, g.nu, g.nv);
  // Bins 3x finer than the cells in each direction.
  const int bu = 3 * g.nu, bv = 3 * g.nv;
  std::vector<double> observed(size_t(bu * bv), 0), expected(observed.size(), 0);
  Rng rng(9, 2);
  for (int i = 0; i < kChiSquareSamples; ++i) {
    Distribution2DSample s = dist.sample({rng.next_float(), rng.next_float()});
    ASSERT_GE(s.point.x, 0);
    ASSERT_LT(s.point.x, 1);
    ASSERT_GE(s.point.y, 0);
    ASSERT_LT(s.point.y, 1);
    ASSERT_GT(s.pdf, 0);
    ASSERT_EQ(dist.pdf(s.point), s.pdf);  // exactly the density the sample was drawn with
    int cu = int(s.point.x * g.nu), cv = int(s.point.y * g.nv);
    ASSERT_GT(g.weights[size_t(cv * g.nu + cu)], 0);  // never from an empty cell
    observed[size_t(std::min(bv - 1, int(s.point.y * bv)) * bu + std::min(bu - 1, int(s.point.x * bu)))] += 1;
  }
  for (int v = 0; v < bv; ++v)
    for (int u = 0; u < bu; ++u)
      expected[size_t(v * bu + u)] =
          double(kChiSquareSamples) * dist.pdf({(u + 0.5f) / bu, (v + 0.5f) / bv}) / (bu * bv);
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(Distribution2D, PdfIntegratesToOneAndIsProportionalToTheWeights) {
  RandomGrid g;
  Distribution2D dist(g.weights, g.nu, g.nv);
  double integral = 0, weight_sum = 0;
  for (float w : g.weights) weight_sum += w;
  for (int v = 0; v < g.nv; ++v)
    for (int u = 0; u < g.nu; ++u) {
      float pdf = dist.pdf({(u + 0.5f) / g.nu, (v + 0.5f) / g.nv});
      integral += pdf / (g.nu * g.nv);
      // The weights normalised to integrate to one: w / mean(w).
      EXPECT_NEAR(pdf, g.weights[size_t(v * g.nu + u)] / (weight_sum / (g.nu * g.nv)), 1e-5);
    }
  EXPECT_NEAR(integral, 1.0, 1e-5);
}

}  // namespace
}  // namespace candela
