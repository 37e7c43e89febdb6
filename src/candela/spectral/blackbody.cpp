#include "candela/spectral/blackbody.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "candela/spectral/cie.h"

namespace candela {

double planck(double wavelength_nm, double kelvin, const PlanckRecipe& r) {
  const double l = wavelength_nm * 1e-9;
  const double x = r.h * r.c / (l * r.k * kelvin);
  // scale * 2 * h * c * c in this order: with scale 1 it is exactly 2 * h * c * c.
  return r.scale * 2 * r.h * r.c * r.c / (std::pow(l, 5) * (r.expm1 ? std::expm1(x) : std::exp(x) - 1));
}

namespace {

// The peak-normalised blackbody's CIE XYZ over the luminance of a constant 1 (1 nm steps), in double:
// at low temperatures it is far below what a float holds.
cie::Xyz peak_normalised_xyz(double kelvin) {
  // pbrt-v4's peak: Wien's displacement constant (m K) over the temperature.
  const double peak = planck(2.8977721e-3 / kelvin * 1e9, kelvin, kPbrtPlanck);
  cie::Xyz sum;
  double y_of_one = 0;
  for (int nm = int(cie::kLambdaMin); nm <= int(cie::kLambdaMax); ++nm) {
    const double v = planck(nm, kelvin, kPbrtPlanck) / peak;
    const cie::Xyz m = cie::matching(nm);
    sum.x += v * m.x, sum.y += v * m.y, sum.z += v * m.z;
    y_of_one += m.y;
  }
  return {sum.x / y_of_one, sum.y / y_of_one, sum.z / y_of_one};
}

// The table holds the colour at luminance 1 and the log of the luminance, both smooth in log T
// (the luminance itself falls like exp(-c / T), which linear interpolation would follow poorly).
constexpr double kTableMin = 100, kTableMax = 100000;
constexpr int kTableSize = 4096;

struct TableEntry {
  RGB colour;  // at luminance 1
  double log_luminance;
};

const std::vector<TableEntry>& blackbody_table() {
  static const std::vector<TableEntry> table = [] {
    std::vector<TableEntry> t(kTableSize);
    for (int i = 0; i < kTableSize; ++i) {
      const cie::Xyz c = peak_normalised_xyz(kTableMin * std::pow(kTableMax / kTableMin, double(i) / (kTableSize - 1)));
      t[size_t(i)] = {cie::xyz_to_linear_srgb(c.x / c.y, 1.0, c.z / c.y), std::log(c.y)};
    }
    return t;
  }();
  return table;
}

}  // namespace

RGB blackbody_peak_normalised_rgb_integrated(double kelvin) {
  if (!(kelvin > 0)) return RGB(0.0f);
  return cie::xyz_to_linear_srgb(peak_normalised_xyz(kelvin));
}

RGB blackbody_peak_normalised_rgb(float kelvin) {
  // Below the table the visible part of the peak-normalised spectrum is under 1e-60: 0 in a float,
  // without integrating at every lookup.
  if (!(kelvin >= kTableMin)) return RGB(0.0f);
  if (kelvin > kTableMax) return blackbody_peak_normalised_rgb_integrated(kelvin);
  const std::vector<TableEntry>& table = blackbody_table();
  const double f = std::log(kelvin / kTableMin) / std::log(kTableMax / kTableMin) * (kTableSize - 1);
  const int i = std::clamp(int(f), 0, kTableSize - 2);
  const double w = f - i;
  const TableEntry &a = table[size_t(i)], &b = table[size_t(i) + 1];
  const RGB colour = a.colour * float(1 - w) + b.colour * float(w);
  return colour * float(std::exp(a.log_luminance * (1 - w) + b.log_luminance * w));
}

}  // namespace candela
