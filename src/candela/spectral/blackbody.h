#pragma once
// Planck's law: the spectral radiance of a black body. pbrt-v4 and Mitsuba 3 evaluate it with
// different constants (CODATA 2010 and 2014), units and expressions; candela reproduces each bit
// for bit for the scenes of that format, so the formula takes the difference as a recipe.
#include "candela/math/color.h"

namespace candela {

struct PlanckRecipe {
  double c, h, k;  // the speed of light, Planck's and Boltzmann's constants (SI units)
  double scale;    // 1: W m^-2 sr^-1 per metre of wavelength; 1e-9: per nanometre
  bool expm1;      // the denominator's e^x - 1 as std::expm1(x) rather than std::exp(x) - 1
};

// pbrt-v4's BlackbodySpectrum (before its normalisation), per metre of wavelength.
inline constexpr PlanckRecipe kPbrtPlanck{299792458.0, 6.62606957e-34, 1.3806488e-23, 1.0, false};
// Mitsuba 3's blackbody, per nanometre.
inline constexpr PlanckRecipe kMitsubaPlanck{2.99792458e8, 6.62607004e-34, 1.38064852e-23, 1e-9, true};

// The radiance at `wavelength_nm` of a black body at `kelvin`:
// scale * 2 h c^2 / (l^5 (e^(h c / (l k T)) - 1)), l the wavelength in metres.
double planck(double wavelength_nm, double kelvin, const PlanckRecipe& recipe);

// pbrt-v4's BlackbodySpectrum, Planck's law over its value at the peak (Wien's displacement law), as
// linear sRGB: its CIE XYZ over the luminance of a constant spectrum of 1 (as a film records it).
// What the temperature grids of pbrt-v4's media emit, times their "Lescale". Interpolated in a table
// over 100 K to 100,000 K (log-spaced; within 1e-4 of the integral), computed above it; 0 below it
// (where the visible part is too small for a float).
RGB blackbody_peak_normalised_rgb(float kelvin);
// The same by direct integration (1 nm steps): the table's reference.
RGB blackbody_peak_normalised_rgb_integrated(double kelvin);

}  // namespace candela
