#pragma once
// The CIE 1931 2-degree colour matching functions and the CIE standard illuminant D65, tabulated
// every 5 nm over the visible range [kLambdaMin, kLambdaMax] and interpolated linearly between, and
// the conversion from CIE XYZ to linear sRGB. Shared by spectral rendering (wavelengths.h), the
// RGB-to-spectrum fit (rgb_to_spectrum.h) and the scene readers' spectral parameters.
#include "candela/math/color.h"

namespace candela::cie {

inline constexpr float kLambdaMin = 360, kLambdaMax = 830;

struct Xyz {
  double x = 0, y = 0, z = 0;
};

// The three matching functions at lambda (nm); zero outside the visible range.
Xyz matching(double lambda);
// Integral of y-bar over the visible range (nm): the luminance of a unit constant spectrum.
double y_integral();
// D65 scaled to luminance 1: the integral of d65 * y-bar equals y_integral().
double d65(double lambda);

// Linear sRGB (Rec. 709 primaries, D65 white) from CIE XYZ.
RGB xyz_to_linear_srgb(double x, double y, double z);
inline RGB xyz_to_linear_srgb(const Xyz& c) { return xyz_to_linear_srgb(c.x, c.y, c.z); }
// Its inverse.
Xyz linear_srgb_to_xyz(double r, double g, double b);

}  // namespace candela::cie
