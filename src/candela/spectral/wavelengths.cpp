#include "candela/spectral/wavelengths.h"

#include <cmath>

#include "candela/spectral/cie.h"
#include "candela/spectral/rgb_to_spectrum.h"

namespace candela {

float visible_wavelength_pdf(float lambda) {
  if (lambda < cie::kLambdaMin || lambda > cie::kLambdaMax) return 0;
  float c = std::cosh(0.0072f * (lambda - 538));
  return 0.0039398042f / (c * c);
}

Wavelengths sample_visible_wavelengths(float u) {
  Wavelengths wl;
  for (int i = 0; i < Wavelengths::kCount; ++i) {
    float ui = u + float(i) / Wavelengths::kCount;
    if (ui >= 1) ui -= 1;
    // Inverse of the density's CDF over [360, 830] nm.
    wl.lambda[i] = 538 - 138.888889f * std::atanh(0.85691062f - 1.82750197f * ui);
    wl.lambda[i] = std::clamp(wl.lambda[i], cie::kLambdaMin, cie::kLambdaMax);
    wl.pdf[i] = visible_wavelength_pdf(wl.lambda[i]);
  }
  return wl;
}

RGB wavelengths_to_rgb(const RGB& values, const Wavelengths& wl) {
  cie::Xyz xyz;
  for (int i = 0; i < Wavelengths::kCount; ++i) {
    if (values[i] == 0 || wl.pdf[i] <= 0) continue;
    cie::Xyz m = cie::matching(wl.lambda[i]);
    double w = double(values[i]) / wl.pdf[i];
    xyz.x += m.x * w;
    xyz.y += m.y * w;
    xyz.z += m.z * w;
  }
  double norm = 1.0 / (Wavelengths::kCount * cie::y_integral());
  return cie::xyz_to_linear_srgb(xyz.x * norm, xyz.y * norm, xyz.z * norm);
}

namespace {

RGB sigmoid_at(const SigmoidPolynomial& s, const Wavelengths& wl) {
  return {s(wl.lambda[0]), s(wl.lambda[1]), s(wl.lambda[2]), s(wl.lambda[3])};
}

}  // namespace

RGB unbounded_at(const RGB& rgb, const Wavelengths& wl) {
  if (rgb.r == rgb.g && rgb.g == rgb.b) return rgb;
  float scale = 2 * rgb.max_component();
  if (scale <= 0) return RGB(0.0f);
  return sigmoid_at(rgb_to_sigmoid(rgb / scale), wl) * scale;
}

RGB reflectance_at(const RGB& rgb, const Wavelengths& wl) {
  if (rgb.r == rgb.g && rgb.g == rgb.b) return rgb;
  if (rgb.max_component() > 1) return unbounded_at(rgb, wl);
  return sigmoid_at(rgb_to_sigmoid(rgb), wl);
}

RGB illuminant_at(const RGB& rgb, const Wavelengths& wl) {
  RGB s = unbounded_at(rgb, wl);
  return s * RGB(float(cie::d65(wl.lambda[0])), float(cie::d65(wl.lambda[1])), float(cie::d65(wl.lambda[2])),
                 float(cie::d65(wl.lambda[3])));
}

}  // namespace candela
