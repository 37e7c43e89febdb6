#pragma once
// Spectral rendering with the RGB transport type: in a spectral render each camera sample draws
// four wavelengths, as pbrt-v4 does, and every RGB the path carries (throughput, radiance, BSDF
// values) holds the values at those four wavelengths in its four lanes instead of red, green, blue.
// RGB scene parameters become spectra as pbrt-v4 makes them (rgb_to_spectrum.h): reflectances as
// bounded sigmoid spectra, unbounded values (eta, k) as a scale times one, emission as one times the
// D65 illuminant; the sample's value reaches the film as linear sRGB through the CIE matching
// functions.
#include "candela/math/color.h"

namespace candela {

struct Wavelengths {
  static constexpr int kCount = RGB::kLanes;  // one per lane of the RGB that carries the values
  float lambda[kCount] = {};                  // nm
  float pdf[kCount] = {};                     // density of each, per nm
};

// Four wavelengths stratified over [360, 830] nm by one uniform number (u + i/4 mod 1), each
// importance-sampled from pbrt-v4's visible-wavelength density, proportional to
// 1 / cosh^2(0.0072 (lambda - 538)).
Wavelengths sample_visible_wavelengths(float u);
float visible_wavelength_pdf(float lambda);

// Linear sRGB of the sample whose values at wl are `values`: the Monte Carlo estimate of the
// spectrum's XYZ, (1/4) sum_i values_i xyz-bar(lambda_i) / pdf_i / integral(y-bar), turned into sRGB.
RGB wavelengths_to_rgb(const RGB& values, const Wavelengths& wl);

// The values at wl of the spectra pbrt-v4 makes from RGB parameters:
//   reflectance   a sigmoid spectrum (values above 1 are taken as unbounded)
//   unbounded     m s(lambda), s the sigmoid spectrum of rgb / m, m = 2 max(rgb)  (eta, k, scales)
//   illuminant    the unbounded spectrum times D65 (normalised to luminance 1): emitted radiance
// Grey reflectances and unbounded values are constant spectra, so they come back unchanged.
RGB reflectance_at(const RGB& rgb, const Wavelengths& wl);
RGB unbounded_at(const RGB& rgb, const Wavelengths& wl);
RGB illuminant_at(const RGB& rgb, const Wavelengths& wl);

// The lanes of an RGB that carry values: the wavelengths of a spectral render, the three colour
// channels of an RGB render (wl null), whose fourth lane only mirrors green.
inline int transport_lanes(const Wavelengths* wl) { return wl ? Wavelengths::kCount : 3; }

// The same for a render that may be RGB (wl null): then the colour is returned as it is.
inline RGB illuminant_at(const RGB& rgb, const Wavelengths* wl) { return wl ? illuminant_at(rgb, *wl) : rgb; }
inline RGB wavelengths_to_rgb(const RGB& values, const Wavelengths* wl) {
  return wl ? wavelengths_to_rgb(values, *wl) : values;
}

// A sample's wavelengths in a render that may be RGB: when spectral, drawn into `storage` with the
// sampler's next number and returned; null otherwise (an RGB render consumes no number for them).
template <typename Sampler>
const Wavelengths* sample_wavelengths_if(bool spectral, Sampler& sampler, Wavelengths& storage) {
  if (!spectral) return nullptr;
  storage = sample_visible_wavelengths(sampler.get_1d());
  return &storage;
}

}  // namespace candela
