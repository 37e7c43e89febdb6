// The spectral module: the CIE tables against known integrals, the RGB-to-spectrum fit round trip,
// the wavelength sampler against its density (chi-square), and the estimator that turns a sample's
// values into RGB against the exact colour of a spectrum.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "candela/spectral/cie.h"
#include "candela/spectral/rgb_to_spectrum.h"
#include "candela/spectral/rgb_to_spectrum_table.h"
#include "candela/spectral/wavelengths.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

// The linear sRGB colour of spectrum f (reflected D65 light when `under_d65`), by 0.1 nm quadrature.
template <typename F>
RGB exact_rgb(F f, bool under_d65) {
  cie::Xyz xyz;
  const double step = 0.1;
  for (double l = cie::kLambdaMin; l <= cie::kLambdaMax; l += step) {
    cie::Xyz m = cie::matching(l);
    double v = f(l) * (under_d65 ? cie::d65(l) : 1.0) * step;
    xyz.x += m.x * v;
    xyz.y += m.y * v;
    xyz.z += m.z * v;
  }
  double n = 1 / cie::y_integral();
  return cie::xyz_to_linear_srgb(xyz.x * n, xyz.y * n, xyz.z * n);
}

TEST(Cie, TablesGiveTheStandardIntegralsAndD65IsSrgbWhite) {
  // pbrt-v4's CIE_Y_integral (1 nm sums of the same tables) is 106.856895.
  EXPECT_NEAR(cie::y_integral(), 106.856895, 0.01);
  RGB white = exact_rgb([](double) { return 1.0; }, true);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(white[c], 1.0, 2e-3) << c;
  // Luminance of D65 as normalised: exactly 1 (what makes a white light of radiance 1 render as 1).
  EXPECT_NEAR(exact_rgb([](double) { return 1.0; }, true).luminance(), 1.0, 1e-3);
}

TEST(RgbToSpectrum, GreyIsExactAndColoursRoundTrip) {
  for (float v : {0.0f, 0.05f, 0.5f, 0.9f, 1.0f}) {
    SigmoidPolynomial s = rgb_to_sigmoid(RGB(v));
    for (float l : {360.0f, 500.0f, 830.0f}) EXPECT_NEAR(s(l), v, 1e-6f);
  }
  // Colours over the cube (the corners' neighbourhood included): the fitted spectrum reflects D65
  // as the colour asked for. The fit is exact at the table's nodes; between them the trilinear
  // interpolation of the coefficients leaves an error, measured here.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0, 1);
  double worst = 0, sum = 0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    RGB rgb(uni(rng), uni(rng), uni(rng));
    if (i % 4 == 0) rgb = rgb * rgb * rgb;  // dark and saturated ones too
    SigmoidPolynomial s = rgb_to_sigmoid(rgb);
    RGB back = exact_rgb([&](double l) { return double(s(float(l))); }, true);
    for (int c = 0; c < 3; ++c) {
      double e = std::abs(back[c] - rgb[c]);
      worst = std::max(worst, e);
      sum += e;
    }
  }
  std::printf("RGB -> spectrum -> RGB: mean abs error %.5f, worst %.5f\n", sum / (3 * n), worst);
  EXPECT_LT(sum / (3 * n), 0.002);
  EXPECT_LT(worst, 0.02);
  // Every value is a reflectance.
  SigmoidPolynomial red = rgb_to_sigmoid(RGB(1, 0, 0));
  for (float l = 360; l <= 830; l += 10) {
    EXPECT_GE(red(l), 0.0f);
    EXPECT_LE(red(l), 1.0f);
  }
}

// The table the build fitted (apps/make_rgb_to_spectrum_table) is the fits' own: rows refitted here,
// one per region and a corner row, agree with it (to rounding: the generator may be compiled with
// other flags than the library).
TEST(RgbToSpectrum, TheBuiltInTableIsTheFitsTable) {
  constexpr int r = kRgbToSpectrumResolution;
  std::vector<float> refit(kRgbToSpectrumTableSize, std::nanf(""));
  const std::pair<int, int> rows[] = {{0, 0}, {1, r / 2}, {2, r - 1}, {0, 7}};
  for (auto [l, yi] : rows) {
    fit_rgb_to_spectrum_row(l, yi, refit.data());
    for (int zi = 0; zi < r; ++zi)
      for (int xi = 0; xi < r; ++xi)
        for (int c = 0; c < 3; ++c) {
          const size_t i = rgb_to_spectrum_index(l, zi, yi, xi) + size_t(c);
          ASSERT_NEAR(kRgbToSpectrumTable[i], refit[i], 1e-4f * (1 + std::abs(refit[i])))
              << "l " << l << " z " << zi << " y " << yi << " x " << xi << " c " << c;
        }
  }
}

TEST(Wavelengths, SamplerMatchesItsDensity) {
  // The density integrates to 1 over the visible range...
  double total = 0;
  for (double l = cie::kLambdaMin; l < cie::kLambdaMax; l += 0.01) total += visible_wavelength_pdf(float(l + 0.005)) * 0.01;
  EXPECT_NEAR(total, 1.0, 1e-3);
  // ...and each of the four wavelengths follows it (chi-square over 47 bins of 10 nm).
  const int bins = 47, samples = 200000;
  std::vector<double> observed(bins, 0), expected(bins, 0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0, 1);
  for (int i = 0; i < samples; ++i) {
    Wavelengths wl = sample_visible_wavelengths(uni(rng));
    int k = i % Wavelengths::kCount;
    int b = std::min(bins - 1, int((wl.lambda[k] - cie::kLambdaMin) / 10));
    observed[size_t(b)] += 1;
    EXPECT_NEAR(wl.pdf[k], visible_wavelength_pdf(wl.lambda[k]), 1e-6f);
  }
  for (int b = 0; b < bins; ++b)
    for (int j = 0; j < 100; ++j)
      expected[size_t(b)] += visible_wavelength_pdf(cie::kLambdaMin + 10 * b + 0.1f * (j + 0.5f)) * 0.1 * samples;
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(Wavelengths, OneSampleTakesOneWavelengthFromEachQuarterOfTheDensity) {
  // Stratified as pbrt-v4 does: wavelength i of u is the inverse CDF at u + i/4 (mod 1), so the four
  // fall in different quarters of the density's mass, whatever u.
  auto cdf = [](float lambda) {
    double sum = 0;
    for (double l = cie::kLambdaMin; l < lambda; l += 0.01) sum += visible_wavelength_pdf(float(l + 0.005)) * 0.01;
    return sum;
  };
  static_assert(Wavelengths::kCount == 4);
  for (float u : {0.0f, 0.1f, 0.37f, 0.74f, 0.999f}) {
    Wavelengths wl = sample_visible_wavelengths(u);
    bool quarter_taken[4] = {};
    for (int i = 0; i < Wavelengths::kCount; ++i) {
      double c = cdf(wl.lambda[i]);
      double expected = std::fmod(double(u) + i / 4.0, 1.0);
      EXPECT_NEAR(c, expected, 2e-3) << "u " << u << " wavelength " << i;
      quarter_taken[std::min(3, int(expected * 4))] = true;
    }
    for (bool taken : quarter_taken) EXPECT_TRUE(taken) << "u " << u;
  }
}

// Mean of wavelengths_to_rgb over many samples, with its standard error per channel.
template <typename F>
void expect_estimates(F values_at, const RGB& exact, const char* what) {
  const int n = 40000;
  double sum[3] = {}, sum_sq[3] = {};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(0, 1);
  for (int i = 0; i < n; ++i) {
    Wavelengths wl = sample_visible_wavelengths(uni(rng));
    RGB v = wavelengths_to_rgb(values_at(wl), wl);
    for (int c = 0; c < 3; ++c) {
      sum[c] += v[c];
      sum_sq[c] += double(v[c]) * v[c];
    }
  }
  for (int c = 0; c < 3; ++c) {
    double mean = sum[c] / n, se = std::sqrt(std::max(0.0, sum_sq[c] / n - mean * mean) / n);
    EXPECT_NEAR(mean, exact[c], 4 * se + 1e-4) << what << " channel " << c << " (standard error " << se << ")";
  }
}

TEST(Wavelengths, SpectralSamplesEstimateTheSpectrumsColour) {
  // Emission: an RGB light seen directly renders as its RGB (up to the fit's error, checked above:
  // compared here with the exact colour of the spectrum it was given).
  for (RGB light : {RGB(17, 12, 4), RGB(1, 1, 1), RGB(0.1f, 0.5f, 2.0f)}) {
    float scale = 2 * light.max_component();
    SigmoidPolynomial s = rgb_to_sigmoid(light / scale);
    RGB exact = exact_rgb([&](double l) { return scale * double(s(float(l))); }, true);
    expect_estimates([&](const Wavelengths& wl) { return illuminant_at(light, wl); }, exact, "illuminant");
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(exact[c], light[c], 0.01 * light.max_component()) << c;
  }
  // A reflectance under D65: its values times the illuminant's.
  RGB wall(0.63f, 0.065f, 0.05f);
  SigmoidPolynomial s = rgb_to_sigmoid(wall);
  RGB exact = exact_rgb([&](double l) { return double(s(float(l))); }, true);
  expect_estimates([&](const Wavelengths& wl) { return reflectance_at(wall, wl) * illuminant_at(RGB(1.0f), wl); },
                   exact, "reflected");
  // Unbounded values scale: m s(lambda) with m = 2 max.
  Wavelengths wl = sample_visible_wavelengths(0.3f);
  RGB eta(0.2f, 0.9f, 1.1f), v = unbounded_at(eta, wl);
  SigmoidPolynomial se = rgb_to_sigmoid(eta / 2.2f);
  for (int i = 0; i < Wavelengths::kCount; ++i) EXPECT_NEAR(v[i], 2.2f * se(wl.lambda[i]), 1e-5f);
  EXPECT_EQ(unbounded_at(RGB(1.5f), wl), RGB(1.5f));
}

}  // namespace
}  // namespace candela
