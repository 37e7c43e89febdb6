#pragma once
// Statistical tools for tests: Pearson's chi-square test of observed counts against expected
// counts (cells with small expectation pooled, as Mitsuba's chi2 test does), and a spherical
// version that bins sampled directions over (cos theta, phi) and integrates the pdf per cell; and
// Monte Carlo means with their standard errors.
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "candela/math/vec.h"

namespace candela::testing {

// Significance of each chi-square test of a sampling routine: 1% for the whole family of about 40
// such tests in the suite, Sidak-corrected (1 - 0.99^(1/40)), as Mitsuba and pbrt do.
inline constexpr double kChiSquareAlpha = 2.51e-4;
// Samples per chi-square test of a direction-sampling routine.
inline constexpr int kChiSquareSamples = 1000000;

// p-value of the chi-square statistic; cells with expected count < 5 are pooled together.
double chi_square_p_value(const std::vector<double>& observed, const std::vector<double>& expected);

// Draws `samples` directions from `sample(u)` (u uniform on [0,1)^2, seeded by `seed`), bins them
// on a grid uniform in cos(theta) over [z_min, 1] and in phi (directions with z < z_min share one
// extra cell, so narrow lobes can be resolved), and compares with the pdf integrated numerically per cell
// (midpoint rule on integration_resolution^2 points: raise it for pdfs with sharp edges).
double spherical_chi_square_p_value(const std::function<Vec3(Vec2)>& sample,
                                    const std::function<float(const Vec3&)>& pdf, int samples, uint64_t seed,
                                    float z_min = -1, int theta_bins = 20, int phi_bins = 40,
                                    int integration_resolution = 12);

// A Monte Carlo estimate: the mean of the samples and its standard error.
struct Estimate {
  double mean = 0, standard_error = 0;
};

// The mean of n values of sample() (called n times, in order) and its standard error.
template <typename F>
Estimate sample_mean(int n, F&& sample) {
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    double v = sample();
    sum += v;
    sum2 += v * v;
  }
  double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

// Regularised upper incomplete gamma Q(a, x): the chi-square survival function is Q(k/2, x/2).
double gamma_q(double a, double x);

}  // namespace candela::testing
