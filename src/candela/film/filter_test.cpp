#include "candela/film/filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using Function2D = std::function<double(double, double)>;

FilterDesc make_desc(FilterType type, Vec2 radius) {
  FilterDesc desc;
  desc.type = type;
  desc.radius = radius;
  return desc;
}

FilterDesc gaussian_desc(Vec2 radius, float sigma) {
  FilterDesc desc = make_desc(FilterType::Gaussian, radius);
  desc.gaussian_sigma = sigma;
  return desc;
}

FilterDesc mitchell_desc(Vec2 radius, float b, float c) {
  FilterDesc desc = make_desc(FilterType::Mitchell, radius);
  desc.mitchell_b = b;
  desc.mitchell_c = c;
  return desc;
}

double normal_density(double x, double sigma) {
  return std::exp(-x * x / (2 * sigma * sigma)) / (sigma * std::sqrt(2 * std::numbers::pi));
}

// Midpoint rule on an n x n grid over [x0, x1] x [y0, y1].
double integrate(const Function2D& f, double x0, double x1, double y0, double y1, int n) {
  double dx = (x1 - x0) / n, dy = (y1 - y0) / n, sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) sum += f(x0 + (i + 0.5) * dx, y0 + (j + 0.5) * dy);
  return sum * dx * dy;
}

// Over the filter's support; n is a multiple of 4 so that grid lines fall on the kinks of the tent
// (x = 0) and of Mitchell's kernel (x = +-r/2) and the midpoint rule stays accurate there.
double integrate_over_support(const Filter& filter, const Function2D& f, int n = 800) {
  Vec2 r = filter.radius();
  return integrate(f, -r.x, r.x, -r.y, r.y, n);
}

Vec2 next_u(Rng& rng) {
  float ux = rng.next_float();
  return {ux, rng.next_float()};
}

// Radii whose 32-cells-per-unit-radius tables split evenly into the chi-square test's 16 bins.
struct FilterCase {
  std::string name;
  FilterDesc desc;
};

// Names the case in gtest's messages instead of dumping its bytes.
void PrintTo(const FilterCase& c, std::ostream* os) { *os << c.name; }

std::vector<FilterCase> filter_cases() {
  return {
      {"Box", make_desc(FilterType::Box, {0.5f, 1.0f})},
      {"Tent", make_desc(FilterType::Tent, {2.0f, 1.5f})},
      {"Gaussian", gaussian_desc({1.5f, 1.0f}, 0.5f)},
      {"Mitchell", mitchell_desc({2.0f, 1.5f}, 1.0f / 3, 1.0f / 3)},
      {"CatmullRom", mitchell_desc({2.0f, 2.0f}, 0.0f, 0.5f)},  // Mitchell's deepest common negative lobes
      {"Sinc", make_desc(FilterType::LanczosSinc, {4.0f, 2.0f})},  // tau 3: several sign changes
  };
}

class FilterProperties : public ::testing::TestWithParam<FilterCase> {
 protected:
  Filter filter{GetParam().desc};
  Function2D f() const {
    return [this](double x, double y) { return double(filter.evaluate({float(x), float(y)})); };
  }
};

TEST_P(FilterProperties, IntegralMatchesNumericalIntegration) {
  double numerical = integrate_over_support(filter, f());
  EXPECT_NEAR(filter.integral(), numerical, 1e-4 * std::abs(numerical));
}

TEST_P(FilterProperties, SamplesLieWithinTheRadiusWithFiniteWeights) {
  Rng rng(1, 7);
  Vec2 r = filter.radius();
  for (int i = 0; i < 20000; ++i) {
    Filter::Sample s = filter.sample(next_u(rng));
    ASSERT_LE(std::abs(s.offset.x), r.x);
    ASSERT_LE(std::abs(s.offset.y), r.y);
    ASSERT_TRUE(std::isfinite(s.weight));
  }
}

TEST_P(FilterProperties, WeightHasTheSignOfTheFilter) {
  Rng rng(2, 7);
  for (int i = 0; i < 20000; ++i) {
    Filter::Sample s = filter.sample(next_u(rng));
    float f_value = filter.evaluate(s.offset);
    if (f_value > 0) {
      ASSERT_GT(s.weight, 0);
    } else if (f_value < 0) {
      ASSERT_LT(s.weight, 0);
    }
  }
}

TEST_P(FilterProperties, OffsetsAreDistributedAsAbsoluteFilter) {
  constexpr int kBins = 16, kSamples = 100000;
  Vec2 r = filter.radius();
  auto bin_of = [&](float x, float radius) {
    return std::clamp(int((x + radius) / (2 * radius) * kBins), 0, kBins - 1);
  };
  std::vector<double> observed(kBins * kBins, 0.0);
  Rng rng(3, 7);
  for (int i = 0; i < kSamples; ++i) {
    Vec2 p = filter.sample(next_u(rng)).offset;
    observed[size_t(bin_of(p.y, r.y) * kBins + bin_of(p.x, r.x))] += 1;
  }

  Function2D abs_f = [this](double x, double y) { return std::abs(filter.evaluate({float(x), float(y)})); };
  std::vector<double> expected(kBins * kBins);
  double bin_w = 2.0 * r.x / kBins, bin_h = 2.0 * r.y / kBins, total = 0;
  for (int j = 0; j < kBins; ++j)
    for (int i = 0; i < kBins; ++i) {
      double x0 = -r.x + i * bin_w, y0 = -r.y + j * bin_h;
      total += expected[size_t(j * kBins + i)] = integrate(abs_f, x0, x0 + bin_w, y0, y0 + bin_h, 12);
    }
  for (double& e : expected) e *= kSamples / total;

  EXPECT_GT(testing::chi_square_p_value(observed, expected), 1e-3);
}

// Filter importance sampling is unbiased: E[w g(offset)] = integral of f g, negative lobes included.
TEST_P(FilterProperties, WeightedMeanEstimatesTheFilteredIntegral) {
  constexpr int kSamples = 200000;
  const std::vector<std::pair<std::string, Function2D>> test_functions = {
      {"1", [](double, double) { return 1.0; }},
      {"1 + x + y^2", [](double x, double y) { return 1 + x + y * y; }},
  };
  for (const auto& [name, g] : test_functions) {
    Rng rng(4, 7);
    double sum = 0, sum_sq = 0;
    for (int i = 0; i < kSamples; ++i) {
      Filter::Sample s = filter.sample(next_u(rng));
      double value = s.weight * g(s.offset.x, s.offset.y);
      sum += value;
      sum_sq += value * value;
    }
    double mean = sum / kSamples;
    double standard_error = std::sqrt(std::max(0.0, sum_sq / kSamples - mean * mean) / (kSamples - 1));
    double expected = integrate_over_support(filter, [&](double x, double y) { return f()(x, y) * g(x, y); });
    // The floor covers exact samplers with g = 1, whose estimate has no variance at all.
    EXPECT_NEAR(mean, expected, 4 * standard_error + 1e-5 * std::abs(expected)) << "g = " << name;
  }
}

INSTANTIATE_TEST_SUITE_P(FilterTypes, FilterProperties, ::testing::ValuesIn(filter_cases()),
                         [](const ::testing::TestParamInfo<FilterCase>& info) { return info.param.name; });

TEST(FilterEvaluate, BoxIsOneInsideItsRadius) {
  Filter box(make_desc(FilterType::Box, {0.5f, 1.0f}));
  EXPECT_EQ(box.evaluate({0, 0}), 1.0f);
  EXPECT_EQ(box.evaluate({0.49f, -0.99f}), 1.0f);
  EXPECT_EQ(box.evaluate({0.51f, 0}), 0.0f);
  EXPECT_EQ(box.evaluate({0, -1.01f}), 0.0f);
  EXPECT_FLOAT_EQ(box.integral(), 2.0f);
}

TEST(FilterEvaluate, TentIsAProductOfTriangles) {
  Filter tent(make_desc(FilterType::Tent, {2.0f, 1.5f}));
  EXPECT_FLOAT_EQ(tent.evaluate({0, 0}), 3.0f);
  EXPECT_FLOAT_EQ(tent.evaluate({0.5f, -1.0f}), 1.5f * 0.5f);
  EXPECT_EQ(tent.evaluate({2.5f, 0}), 0.0f);
  EXPECT_EQ(tent.evaluate({0, 1.5f}), 0.0f);
  EXPECT_FLOAT_EQ(tent.integral(), 4.0f * 2.25f);
}

TEST(FilterEvaluate, GaussianIsTheNormalDensityShiftedToVanishAtTheRadius) {
  Filter gaussian(gaussian_desc({1.5f, 1.0f}, 0.5f));
  auto axis = [](double x, double r) { return normal_density(x, 0.5) - normal_density(r, 0.5); };
  EXPECT_NEAR(gaussian.evaluate({0.3f, -0.2f}), axis(0.3, 1.5) * axis(-0.2, 1.0), 1e-6);
  EXPECT_NEAR(gaussian.evaluate({0, 0}), axis(0, 1.5) * axis(0, 1.0), 1e-6);
  EXPECT_EQ(gaussian.evaluate({1.5f, 0}), 0.0f);
  EXPECT_EQ(gaussian.evaluate({0, 1.2f}), 0.0f);
  double expected_integral = (std::erf(1.5 / (0.5 * std::sqrt(2.0))) - 3 * normal_density(1.5, 0.5)) *
                             (std::erf(1.0 / (0.5 * std::sqrt(2.0))) - 2 * normal_density(1.0, 0.5));
  EXPECT_NEAR(gaussian.integral(), expected_integral, 1e-6);
}

// With B = C = 1/3 the cubic is 8/9 at 0, B/6 = 1/18 at 1, -5/144 at 1.5 and 0 from 2 on; the radius
// stretches [-2, 2] to [-r, r].
TEST(FilterEvaluate, MitchellIsTheStretchedNetravaliCubic) {
  Filter mitchell(mitchell_desc({2.0f, 1.5f}, 1.0f / 3, 1.0f / 3));
  const float at_0 = 8.0f / 9, at_1 = 1.0f / 18, at_1_5 = -5.0f / 144;
  EXPECT_NEAR(mitchell.evaluate({0, 0}), at_0 * at_0, 1e-6);
  EXPECT_NEAR(mitchell.evaluate({1.0f, 0}), at_1 * at_0, 1e-6);
  EXPECT_NEAR(mitchell.evaluate({-1.5f, 0}), at_1_5 * at_0, 1e-6);
  EXPECT_NEAR(mitchell.evaluate({1.0f, -0.75f}), at_1 * at_1, 1e-6);
  EXPECT_NEAR(mitchell.evaluate({0, 1.125f}), at_0 * at_1_5, 1e-6);
  EXPECT_NEAR(mitchell.evaluate({0, 1.5f}), 0.0f, 1e-6);  // the cubic's float rounding at 2
  EXPECT_EQ(mitchell.evaluate({2.5f, 0}), 0.0f);
  EXPECT_FLOAT_EQ(mitchell.integral(), 2.0f * 1.5f / 4);
}

// pbrt-v4's Lanczos windowed sinc: sinc(x) sinc(x / tau), zero at the integers and cut at the radius.
TEST(FilterEvaluate, SincIsTheLanczosWindowedSinc) {
  FilterDesc desc = make_desc(FilterType::LanczosSinc, {4.0f, 4.0f});
  desc.sinc_tau = 3;
  Filter sinc(desc);
  auto s = [](double x) { return x == 0 ? 1.0 : std::sin(std::numbers::pi * x) / (std::numbers::pi * x); };
  EXPECT_NEAR(sinc.evaluate({0, 0}), 1.0f, 1e-6);
  EXPECT_NEAR(sinc.evaluate({1.0f, 0}), 0.0f, 1e-6);
  EXPECT_NEAR(sinc.evaluate({0.5f, 0}), s(0.5) * s(0.5 / 3), 1e-6);
  EXPECT_NEAR(sinc.evaluate({1.5f, -0.25f}), s(1.5) * s(0.5) * s(-0.25) * s(-0.25 / 3), 1e-6);
  EXPECT_LT(sinc.evaluate({1.5f, 0}), 0.0f);  // the first negative lobe
  EXPECT_EQ(sinc.evaluate({4.5f, 0}), 0.0f);
}

TEST(FilterSample, BoxAndTentAreSampledExactlyWithWeightTheIntegral) {
  for (FilterType type : {FilterType::Box, FilterType::Tent}) {
    Filter filter(make_desc(type, {1.5f, 0.75f}));
    Rng rng(5, 7);
    for (int i = 0; i < 1000; ++i) ASSERT_FLOAT_EQ(filter.sample(next_u(rng)).weight, filter.integral());
  }
}

TEST(FilterSample, MitchellNegativeLobesGiveNegativeWeights) {
  Filter mitchell(mitchell_desc({2.0f, 2.0f}, 1.0f / 3, 1.0f / 3));
  Rng rng(6, 7);
  int negative = 0;
  for (int i = 0; i < 10000; ++i) negative += mitchell.sample(next_u(rng)).weight < 0;
  EXPECT_GT(negative, 0);
}

TEST(FilterSample, ExtremeUniformNumbersStayWithinTheRadius) {
  const float below_one = 0x1.fffffep-1f;
  for (const FilterCase& c : filter_cases()) {
    Filter filter(c.desc);
    for (Vec2 u : {Vec2{0, 0}, Vec2{below_one, below_one}, Vec2{0, below_one}}) {
      Filter::Sample s = filter.sample(u);
      EXPECT_LE(std::abs(s.offset.x), filter.radius().x) << c.name;
      EXPECT_LE(std::abs(s.offset.y), filter.radius().y) << c.name;
      EXPECT_TRUE(std::isfinite(s.weight)) << c.name;
    }
  }
}

TEST(FilterConstruction, RejectsBadParameters) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (Vec2 radius : {Vec2{0, 1}, Vec2{1, -1}, Vec2{nan, 1}, Vec2{1, inf}})
    for (FilterType type :
         {FilterType::Box, FilterType::Tent, FilterType::Gaussian, FilterType::Mitchell, FilterType::LanczosSinc})
      EXPECT_THROW(Filter(make_desc(type, radius)), InternalError);
  for (float tau : {0.0f, -1.0f, nan, inf}) {
    FilterDesc desc = make_desc(FilterType::LanczosSinc, {4, 4});
    desc.sinc_tau = tau;
    EXPECT_THROW(Filter{desc}, InternalError);
  }
  for (float sigma : {0.0f, -0.5f, nan, inf}) EXPECT_THROW(Filter(gaussian_desc({1, 1}, sigma)), InternalError);
  EXPECT_THROW(Filter(mitchell_desc({2, 2}, nan, 0.5f)), InternalError);
  EXPECT_THROW(Filter(mitchell_desc({2, 2}, 0.5f, inf)), InternalError);
  EXPECT_THROW(Filter(make_desc(static_cast<FilterType>(42), {1, 1})), InternalError);
}

TEST(FilterConstruction, IgnoresParametersOfOtherFilterTypes) {
  FilterDesc box = make_desc(FilterType::Box, {0.5f, 0.5f});
  box.gaussian_sigma = 0;
  box.mitchell_b = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NO_THROW(Filter{box});
}

}  // namespace
}  // namespace candela
