// Planck's law, shared by the pbrt-v4 and Mitsuba readers: each recipe gives, bit for bit, what its
// reader computed before the two copies were merged.
#include "candela/spectral/blackbody.h"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace candela
