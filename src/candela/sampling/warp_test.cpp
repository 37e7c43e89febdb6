// Warps: samples land in their domain, pdfs integrate to one, and the sample histograms match the
// pdfs (chi-square over a grid in (cos theta, phi) or (x, y)).
#include "candela/sampling/warp.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>

#include "candela/sampling/distribution1d.h"
#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::kChiSquareSamples;

// Monte Carlo integral of pdf over the sphere with uniform directions: must be 1 within 5 sigma.
void expect_pdf_integrates_to_one(const std::function<float(const Vec3&)>& pdf) {
  Rng rng(7, 11);
  double sum = 0, sum_sq = 0;
  for (int i = 0; i < kChiSquareSamples; ++i) {
    Vec3 w = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    double v = pdf(w) / uniform_sphere_pdf();
    sum += v;
    sum_sq += v * v;
  }
  double mean = sum / kChiSquareSamples;
  double se = std::sqrt((sum_sq / kChiSquareSamples - mean * mean) / kChiSquareSamples);
  EXPECT_NEAR(mean, 1.0, 5 * se + 1e-3);
}

TEST(Warp, UniformSphere) {
  Rng rng(1, 2);
  for (int i = 0; i < 10000; ++i) EXPECT_NEAR(length(square_to_uniform_sphere({rng.next_float(), rng.next_float()})), 1, 1e-5);
  auto sample = [](Vec2 u) { return square_to_uniform_sphere(u); };
  auto pdf = [](const Vec3&) { return uniform_sphere_pdf(); };
  EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 3), testing::kChiSquareAlpha);
}

TEST(Warp, UniformHemisphere) {
  Rng rng(1, 3);
  for (int i = 0; i < 10000; ++i) EXPECT_GE(square_to_uniform_hemisphere({rng.next_float(), rng.next_float()}).z, 0);
  expect_pdf_integrates_to_one([](const Vec3& w) { return uniform_hemisphere_pdf(w); });
  auto sample = [](Vec2 u) { return square_to_uniform_hemisphere(u); };
  auto pdf = [](const Vec3& w) { return uniform_hemisphere_pdf(w); };
  EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 4), testing::kChiSquareAlpha);
}

TEST(Warp, CosineHemisphere) {
  Rng rng(1, 4);
  for (int i = 0; i < 10000; ++i) {
    Vec3 w = square_to_cosine_hemisphere({rng.next_float(), rng.next_float()});
    EXPECT_GE(w.z, 0);
    EXPECT_NEAR(length(w), 1, 1e-5);
  }
  expect_pdf_integrates_to_one([](const Vec3& w) { return cosine_hemisphere_pdf(w); });
  auto sample = [](Vec2 u) { return square_to_cosine_hemisphere(u); };
  auto pdf = [](const Vec3& w) { return cosine_hemisphere_pdf(w); };
  EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 5), testing::kChiSquareAlpha);
}

TEST(Warp, UniformCone) {
  for (float cos_max : {0.2f, 0.9f, 0.999f}) {
    Rng rng(1, 5);
    for (int i = 0; i < 10000; ++i)
      EXPECT_GE(square_to_uniform_cone({rng.next_float(), rng.next_float()}, cos_max).z, cos_max - 1e-6f);
    expect_pdf_integrates_to_one([&](const Vec3& w) { return w.z >= cos_max ? uniform_cone_pdf(cos_max) : 0.0f; });
    auto sample = [&](Vec2 u) { return square_to_uniform_cone(u, cos_max); };
    auto pdf = [&](const Vec3& w) { return w.z >= cos_max ? uniform_cone_pdf(cos_max) : 0.0f; };
    EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 6, cos_max), testing::kChiSquareAlpha)
        << "cos_max " << cos_max;
  }
}

TEST(Warp, PhongLobe) {
  for (float n : {1.0f, 10.0f, 200.0f}) {
    expect_pdf_integrates_to_one([&](const Vec3& w) { return phong_lobe_pdf(w.z, n); });
    auto sample = [&](Vec2 u) { return square_to_phong_lobe(u, n); };
    auto pdf = [&](const Vec3& w) { return phong_lobe_pdf(w.z, n); };
    float z_min = n > 50 ? 0.9f : -1.0f;  // resolve the narrow lobe
    EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 7, z_min), testing::kChiSquareAlpha)
        << "exponent " << n;
  }
}

TEST(Warp, ConcentricDiskIsUniform) {
  // Samples land in the unit disk, and each quadrant ring holds its share of the area.
  Rng rng(3, 4);
  int counts[4][4] = {};
  for (int i = 0; i < kChiSquareSamples; ++i) {
    Vec2 p = square_to_concentric_disk({rng.next_float(), rng.next_float()});
    float r2 = p.x * p.x + p.y * p.y;
    ASSERT_LE(r2, 1 + 1e-5f);
    int ring = std::min(3, int(r2 * 4));  // equal-area rings
    int quadrant = (p.x >= 0 ? 0 : 1) + (p.y >= 0 ? 0 : 2);
    ++counts[ring][quadrant];
  }
  std::vector<double> observed, expected;
  for (auto& ring : counts)
    for (int c : ring) {
      observed.push_back(c);
      expected.push_back(kChiSquareSamples / 16.0);
    }
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
  EXPECT_FLOAT_EQ(concentric_disk_pdf({0.5f, 0.5f}), kInvPi);
}

TEST(Warp, ConcentricDiskMatchesShirleyChiuExactly) {
  // The polynomial sine and cosine agree with libm (in double) to float precision over the whole
  // quarter-pi range, and so the mapping is Shirley and Chiu's, point by point.
  for (int i = 0; i <= 10000; ++i) {
    double a = (kPi / 4) * (2.0 * i / 10000 - 1);
    Vec2 cs = cos_sin_quarter_pi(float(a));
    EXPECT_NEAR(cs.x, std::cos(a), 1.2e-7) << a;
    EXPECT_NEAR(cs.y, std::sin(a), 1.2e-7) << a;
  }
  Rng rng(5, 6);
  for (int i = 0; i < 10000; ++i) {
    Vec2 u{rng.next_float(), rng.next_float()};
    double ox = 2.0 * u.x - 1, oy = 2.0 * u.y - 1, r, theta;
    if (std::abs(ox) > std::abs(oy)) {
      r = ox;
      theta = (kPi / 4) * (oy / ox);
    } else {
      r = oy;
      theta = kPi / 2 - (kPi / 4) * (ox / oy);
    }
    Vec2 p = square_to_concentric_disk(u);
    EXPECT_NEAR(p.x, r * std::cos(theta), 3e-7);
    EXPECT_NEAR(p.y, r * std::sin(theta), 3e-7);
  }
}

TEST(Warp, UniformTriangle) {
  // Barycentrics are valid and uniform: split the triangle into 4 congruent sub-triangles.
  Rng rng(5, 6);
  std::vector<double> observed(4, 0), expected(4, kChiSquareSamples / 4.0);
  for (int i = 0; i < kChiSquareSamples; ++i) {
    Vec2 b = square_to_uniform_triangle({rng.next_float(), rng.next_float()});
    float b2 = 1 - b.x - b.y;
    ASSERT_GE(b.x, 0);
    ASSERT_GE(b.y, 0);
    ASSERT_GE(b2, -1e-6f);
    int region = b.x > 0.5f ? 0 : b.y > 0.5f ? 1 : b2 > 0.5f ? 2 : 3;
    observed[region] += 1;
  }
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(Distribution1D, SamplesProportionally) {
  std::vector<float> w = {1, 0, 3, 6};
  Distribution1D d(w);
  EXPECT_FLOAT_EQ(d.pmf(0), 0.1f);
  EXPECT_FLOAT_EQ(d.pmf(1), 0.0f);
  Rng rng(9, 9);
  std::vector<double> observed(4, 0),
      expected = {0.1 * kChiSquareSamples, 0, 0.3 * kChiSquareSamples, 0.6 * kChiSquareSamples};
  for (int i = 0; i < kChiSquareSamples; ++i) observed[d.sample(rng.next_float())] += 1;
  EXPECT_EQ(observed[1], 0);
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(Warp, EquiangularSamplingMatchesItsPdf) {
  // Distances binned over [t0, t1) (an infinite t1: up to delta + 40 h, then one tail cell), against the
  // pdf's integral per cell, the closed form (atan((t - delta) / h) - theta_a) / (theta_b - theta_a):
  // the foot of the point inside, before and beyond the interval, and a half-line.
  struct Case {
    float delta, h, t0, t1;
  };
  const float inf = std::numeric_limits<float>::infinity();
  uint64_t seed = 20;
  for (const Case& c : {Case{3, 0.5f, 1, 7}, Case{-2, 1.5f, 0, 4}, Case{9, 0.2f, 0, 4}, Case{2, 0.3f, 0.5f, inf}}) {
    const EquiangularSegment s = equiangular_segment(c.delta, c.h, c.t0, c.t1);
    ASSERT_TRUE(s.valid());
    const double a = std::atan2(double(c.t0) - c.delta, double(c.h));
    const double b = std::isinf(c.t1) ? kPi / 2 : std::atan2(double(c.t1) - c.delta, double(c.h));
    auto cdf = [&](double t) { return (std::atan2(t - c.delta, double(c.h)) - a) / (b - a); };
    const double end = std::isinf(c.t1) ? c.delta + 40 * c.h : c.t1;
    const int bins = 60;
    std::vector<double> observed(bins + 1, 0), expected(bins + 1, 0);
    for (int i = 0; i < bins; ++i)
      expected[i] = kChiSquareSamples * (cdf(c.t0 + (end - c.t0) * (i + 1) / bins) - cdf(c.t0 + (end - c.t0) * i / bins));
    expected[bins] = kChiSquareSamples * (1 - cdf(end));
    Rng rng(seed++, 3);
    double inv_sum = 0, inv_sum2 = 0;
    for (int i = 0; i < kChiSquareSamples; ++i) {
      const float t = sample_equiangular(s, rng.next_float(), c.t0, c.t1);
      ASSERT_GE(t, c.t0);
      ASSERT_LT(t, c.t1);
      const double x = (t - c.t0) / (end - c.t0);
      observed[x >= 1 ? bins : std::min(bins - 1, int(x * bins))] += 1;
      // The pdf against the closed form's derivative.
      const double exact = double(c.h) / ((b - a) * (double(c.h) * c.h + (double(t) - c.delta) * (double(t) - c.delta)));
      ASSERT_NEAR(equiangular_pdf(s, t), exact, 1e-4 * exact) << t;
      inv_sum += 1 / exact;
      inv_sum2 += 1 / (exact * exact);
    }
    EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha)
        << "delta " << c.delta << " h " << c.h << " [" << c.t0 << ", " << c.t1 << ")";
    // The mean of 1 / pdf estimates the interval's length (finite intervals), within 5 standard errors.
    if (std::isfinite(c.t1)) {
      const double mean = inv_sum / kChiSquareSamples;
      const double se = std::sqrt(std::max(0.0, inv_sum2 / kChiSquareSamples - mean * mean) / kChiSquareSamples);
      EXPECT_NEAR(mean, c.t1 - c.t0, 5 * se + 1e-6);
    }
  }
  // No sample where the point lies on the line or the interval is empty.
  EXPECT_FALSE(equiangular_segment(1, 0, 0, 2).valid());
  EXPECT_FALSE(equiangular_segment(1, 1, 2, 2).valid());
  EXPECT_EQ(equiangular_pdf(equiangular_segment(1, 0, 0, 2), 1), 0);
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

TEST(Warp, ChiSquareRejectsAMismatchedPdf) {
  // The test must be able to fail: uniform hemisphere samples judged against the cosine pdf.
  auto sample = [](Vec2 u) { return square_to_uniform_hemisphere(u); };
  auto pdf = [](const Vec3& w) { return cosine_hemisphere_pdf(w); };
  EXPECT_LT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 8), 1e-6);
}

}  // namespace
}  // namespace candela
