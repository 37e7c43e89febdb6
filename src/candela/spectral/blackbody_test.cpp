// Planck's law, shared by the pbrt-v4 and Mitsuba readers: each recipe gives, bit for bit, what its
// reader computed before the two copies were merged.
#include "candela/spectral/blackbody.h"

#include <gtest/gtest.h>

#include <cmath>

#include "candela/io/named_spectra.h"

namespace candela {
namespace {

// The two readers' former formulas, as they were written.
double old_pbrt(double nm, float kelvin) {
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  double l = nm * 1e-9;
  return (2 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * kelvin)) - 1));
}

double old_mitsuba(double nm, double kelvin) {
  constexpr double c = 2.99792458e8, h = 6.62607004e-34, k = 1.38064852e-23;
  const double l = nm * 1e-9;
  return 1e-9 * 2 * h * c * c / (std::pow(l, 5) * std::expm1(h * c / (l * k * kelvin)));
}

TEST(Blackbody, RecipesMatchTheReadersFormerFormulasBitForBit) {
  for (float kelvin : {500.0f, 1900.0f, 2700.0f, 3000.5f, 5500.0f, 6504.0f, 12000.0f, 40000.0f, 1e6f})
    for (double nm = 300; nm <= 900; nm += 0.5) {
      EXPECT_EQ(planck(nm, kelvin, kPbrtPlanck), old_pbrt(nm, kelvin)) << nm << " nm, " << kelvin << " K";
      EXPECT_EQ(planck(nm, double(kelvin), kMitsubaPlanck), old_mitsuba(nm, double(kelvin)))
          << nm << " nm, " << kelvin << " K";
    }
}

// The peak-normalised blackbody (what pbrt-v4's temperature grids emit): its table agrees with the
// integral, its colour is that of the luminance-normalised blackbody the pbrt reader gives lights
// (written separately), and its luminance follows the peak normalisation: about 0.5-1 near 6,000 K,
// vanishingly small at 800 K, nothing at 0 K.
TEST(Blackbody, PeakNormalisedRgbAgreesWithItsIntegralAndTheLightsColour) {
  for (float kelvin : {100.5f, 450.0f, 800.0f, 1234.5f, 1900.0f, 3000.0f, 5777.0f, 6504.0f, 12000.0f, 40000.0f, 99000.0f,
                       150000.0f}) {
    const RGB table = blackbody_peak_normalised_rgb(kelvin);
    const RGB exact = blackbody_peak_normalised_rgb_integrated(kelvin);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(table[c], exact[c], 1e-4 * exact.max_component() + 1e-30) << kelvin << " K, channel " << c;
    const float luminance = exact.luminance();
    if (kelvin >= 450) ASSERT_GT(luminance, 0) << kelvin;  // below, less than a float holds
    if (kelvin >= 800) {
      const RGB light = pbrt_spectra::blackbody_rgb(kelvin);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(exact[c] / luminance, light[c], 2e-3 * light.max_component()) << kelvin;
    }
  }
  EXPECT_GT(blackbody_peak_normalised_rgb(5777).luminance(), 0.5f);
  EXPECT_LT(blackbody_peak_normalised_rgb(5777).luminance(), 1.0f);
  EXPECT_LT(blackbody_peak_normalised_rgb(800).luminance(), 1e-5f);
  EXPECT_EQ(blackbody_peak_normalised_rgb_integrated(99).max_component(), 0);  // below the table: 0 either way
  EXPECT_EQ(blackbody_peak_normalised_rgb(99).max_component(), 0);
  EXPECT_EQ(blackbody_peak_normalised_rgb(0).max_component(), 0);
  EXPECT_EQ(blackbody_peak_normalised_rgb(-10).max_component(), 0);
}

}  // namespace
}  // namespace candela
