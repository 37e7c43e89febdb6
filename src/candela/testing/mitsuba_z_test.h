#pragma once
// Mitsuba 3's render-regression protocol (src/render/tests/test_renders.py in Mitsuba 3), used to
// judge candela's renders of Mitsuba's test scenes against Mitsuba's references:
//  - render with spp = floor(2,000,000 / pixel count);
//  - for every pixel and channel, z = |mean - ref| sqrt(spp / max(var, 1e-4)), where var is the
//    reference's per-sample variance, and p = 2 (1 - Phi(z)) (two-sided);
//  - with the Sidak-corrected level alpha = 1 - 0.99^(1 / pixel count), the scene passes when at least
//    99.75% of the pixel-channels have p > alpha.
#include <cmath>
#include <cstdint>

#include "candela/film/image.h"

namespace candela::testing {

inline int mitsuba_test_spp(int width, int height) { return int(2000000 / (int64_t(width) * height)); }

struct MitsubaZTestResult {
  double passing_fraction = 0;  // of the pixel-channels with p > alpha
  double alpha = 0;
  int pixel_channels = 0;
  bool passed() const { return passing_fraction >= 0.9975; }
};

// `image`, `reference` and `variance` must have the same size.
inline MitsubaZTestResult mitsuba_z_test(const Image& image, const Image& reference, const Image& variance, int spp) {
  MitsubaZTestResult r;
  const double pixels = double(image.width) * image.height;
  r.alpha = 1 - std::pow(0.99, 1 / pixels);
  int passing = 0;
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    double var = std::max(double(variance.rgb[i]), 1e-4);
    double z = std::abs(double(image.rgb[i]) - reference.rgb[i]) * std::sqrt(spp / var);
    // 2 (1 - Phi(z)) = erfc(z / sqrt 2); a NaN pixel fails (the comparison is false).
    double p = std::erfc(z / std::sqrt(2.0));
    if (p > r.alpha) ++passing;
  }
  r.pixel_channels = int(image.rgb.size());
  r.passing_fraction = r.pixel_channels > 0 ? double(passing) / r.pixel_channels : 0;
  return r;
}

// The shared references' variance images are negative in 3-40% of their pixel-channels
// (docs/conformance.md), which the protocol floors at 1e-4. This is `variance` with each negative
// value replaced by the same pixel-channel of `substitute` (|var| itself, or an independent estimate
// of the per-sample variance): the diagnostic variants of the protocol.
inline Image replace_negative_variance(const Image& variance, const Image& substitute) {
  Image out = variance;
  for (size_t i = 0; i < out.rgb.size(); ++i)
    if (out.rgb[i] < 0) out.rgb[i] = substitute.rgb[i];
  return out;
}

}  // namespace candela::testing
