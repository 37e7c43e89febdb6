#pragma once
// Mitsuba 3's render-regression protocol (src/render/tests/test_renders.py in Mitsuba 3), used to
// judge candela's renders of Mitsuba's test scenes against Mitsuba's references:
//  - render with spp = floor(2,000,000 / pixel count);
//  - the image, the reference and the reference's per-sample variance are converted from linear sRGB
//    to CIE XYZ (the variance was computed in XYZ by Mitsuba's `moment` integrator and written out as
//    RGB by the same linear map, which is why the RGB file holds negative "variances": the test
//    undoes it);
//  - for every pixel and XYZ channel, z = |mean - ref| sqrt(spp / max(var, 1e-4)) and
//    p = 2 (1 - Phi(z)) (two-sided);
//  - with the Sidak-corrected level alpha = 1 - 0.99^(1 / pixel count), the scene passes when at least
//    99.75% of the pixel-channels have p > alpha.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "candela/film/image.h"

namespace candela::testing {

// Linear sRGB to CIE XYZ, the matrix of Mitsuba's Bitmap conversions (Rec. 709 primaries, D65).
inline RGB srgb_to_xyz(const RGB& c) {
  return {0.412453f * c.r + 0.357580f * c.g + 0.180423f * c.b, 0.212671f * c.r + 0.715160f * c.g + 0.072169f * c.b,
          0.019334f * c.r + 0.119193f * c.g + 0.950227f * c.b};
}

inline Image srgb_to_xyz(const Image& image) {
  Image xyz = image;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) xyz.set(x, y, srgb_to_xyz(image.at(x, y)));
  return xyz;
}

inline int mitsuba_test_spp(int width, int height) { return int(2000000 / (int64_t(width) * height)); }

struct MitsubaZTestResult {
  double passing_fraction = 0;  // of the pixel-channels (X, Y, Z) with p > alpha
  double alpha = 0;
  int pixel_channels = 0;
  bool passed() const { return passing_fraction >= 0.9975; }
};

// `image`, `reference` and `variance` (linear sRGB, as the reference files are) must have the same size.
inline MitsubaZTestResult mitsuba_z_test(const Image& rgb_image, const Image& rgb_reference, const Image& rgb_variance,
                                         int spp) {
  const Image image = srgb_to_xyz(rgb_image), reference = srgb_to_xyz(rgb_reference),
              variance = srgb_to_xyz(rgb_variance);
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

// A check beyond Mitsuba's protocol, which a bias of a few percent passes (docs/conformance.md): the
// whole image's mean against the reference's, per XYZ channel. The pixels' errors are independent,
// each with the variance of an spp-sample mean plus that of the reference's own
// `reference_spp`-sample mean (both from the reference's per-sample variance).
struct ImageMeanAgreement {
  RGB z;                    // the difference of the image means in standard errors, per X, Y, Z
  RGB relative_difference;  // the same difference over the reference's mean
  // Within `z_bound` standard errors, or within `relative_bound` of the reference: the references
  // carry a systematic offset of about 0.1% in X and Z (a white constant emitter seen directly reads
  // (1.00108, 0.99971, 0.99970) in them), which a large constant region turns into many standard
  // errors.
  bool agrees(float z_bound = 5, float relative_bound = 0.002f) const {
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(z[c]) < z_bound || std::abs(relative_difference[c]) < relative_bound)) return false;
    return true;
  }
};

inline ImageMeanAgreement image_mean_agreement(const Image& rgb_image, const Image& rgb_reference,
                                               const Image& rgb_variance, int spp, int reference_spp = 32000) {
  const Image image = srgb_to_xyz(rgb_image), reference = srgb_to_xyz(rgb_reference),
              variance = srgb_to_xyz(rgb_variance);
  double difference[3] = {0, 0, 0}, sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    difference[i % 3] += double(image.rgb[i]) - reference.rgb[i];
    sum[i % 3] += reference.rgb[i];
    var[i % 3] += std::max(double(variance.rgb[i]), 0.0) * (1.0 / spp + 1.0 / reference_spp);
  }
  auto z = [&](int c) { return float(difference[c] / std::sqrt(std::max(var[c], 1e-30))); };
  auto relative = [&](int c) { return float(difference[c] / std::max(std::abs(sum[c]), 1e-30)); };
  return {RGB(z(0), z(1), z(2)), RGB(relative(0), relative(1), relative(2))};
}

}  // namespace candela::testing
