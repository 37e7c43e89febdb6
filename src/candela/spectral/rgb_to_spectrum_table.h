#pragma once
// The table behind rgb_to_sigmoid() (rgb_to_spectrum.h): for each RGB colour on a grid over the cube, the
// coefficients of the sigmoid-polynomial spectrum that reflects D65 as that colour, found by
// Gauss-Newton fits in CIELAB. The fits take about a second on 2 cores, so they run at build time (as
// pbrt-v4's rgb2spec_opt does): apps/make_rgb_to_spectrum_table/main.cpp writes the table into
// the library as kRgbToSpectrumTable; the tests refit rows of it.
//
// Layout, as pbrt-v4's: for the largest component l (3 regions), its value z on a grid that is denser
// near 0 and 1 (z_k = smoothstep(smoothstep(k / (res - 1)))), and the other two as fractions x, y of it
// on a uniform grid; three coefficients per node, [l][zi][yi][xi][c].
#include <cstddef>

namespace candela {

// The table's resolution along each axis (pbrt-v4 uses 64).
inline constexpr int kRgbToSpectrumResolution = 32;
inline constexpr size_t kRgbToSpectrumTableSize =
    size_t(3) * kRgbToSpectrumResolution * kRgbToSpectrumResolution * kRgbToSpectrumResolution * 3;

// The table the build wrote (generated/rgb_to_spectrum_table_data.cpp).
extern const float kRgbToSpectrumTable[kRgbToSpectrumTableSize];

inline size_t rgb_to_spectrum_index(int l, int zi, int yi, int xi) {
  constexpr size_t r = kRgbToSpectrumResolution;
  return (((size_t(l) * r + size_t(zi)) * r + size_t(yi)) * r + size_t(xi)) * 3;
}

// The grid's z values (brightness of the largest component).
constexpr float rgb_to_spectrum_z_node(int k) {
  const double t = double(k) / (kRgbToSpectrumResolution - 1);
  const double s = t * t * (3 - 2 * t);
  return float(s * s * (3 - 2 * s));
}

// Fits the nodes of one row (l, yi), every zi and xi, into `table` at their indices.
void fit_rgb_to_spectrum_row(int l, int yi, float* table);

}  // namespace candela
