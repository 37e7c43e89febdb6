#pragma once
// Smooth spectra for RGB colours (Jakob and Hanika, "A Low-Dimensional Function Space for Efficient
// Spectral Upsampling", 2019), as pbrt-v4 turns its RGB parameters into spectra:
//   s(lambda) = S(c0 t^2 + c1 t + c2),  t = (lambda - 360) / (830 - 360),  S(x) = 1/2 + x / (2 sqrt(1 + x^2))
// a sigmoid of a quadratic, bounded by [0, 1] like every reflectance, whose colour under D65 is the
// given linear sRGB colour. The coefficients come from a table over the RGB cube fitted at build time
// (rgb_to_spectrum_table.h), and are interpolated trilinearly from it.
#include <array>

#include "candela/math/color.h"

namespace candela {

struct SigmoidPolynomial {
  float c0 = 0, c1 = 0, c2 = 0;
  float operator()(float lambda) const;
};

// The spectrum whose reflected D65 light has linear sRGB colour `rgb` (each component clamped to
// [0, 1]). Grey is exact: the constant spectrum of that value.
SigmoidPolynomial rgb_to_sigmoid(const RGB& rgb);

}  // namespace candela
