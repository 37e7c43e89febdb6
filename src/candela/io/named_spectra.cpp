// pbrt-v4's named spectra and spectral parameters converted to RGB (see named_spectra.h).
#include "candela/io/named_spectra.h"

#include <algorithm>
#include <cmath>

namespace candela::pbrt_spectra {
namespace {

// ---------------------------------------------------------------- colour matching

// The CIE 1931 2-degree colour matching functions as the multi-lobe Gaussian fit of Wyman, Sloan
// and Shirley, "Simple Analytic Approximations to the CIE XYZ Color Matching Functions" (JCGT 2013),
// accurate to about 1% of the tabulated functions: plenty for the few conversions done here.
double lobe(double lambda, double mu, double sigma_below, double sigma_above) {
  double t = (lambda - mu) / (lambda < mu ? sigma_below : sigma_above);
  return std::exp(-0.5 * t * t);
}
double cie_x(double l) {
  return 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) - 0.065 * lobe(l, 501.1, 20.4, 26.2);
}
double cie_y(double l) { return 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1); }
double cie_z(double l) { return 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8); }

struct Xyz {
  double x = 0, y = 0, z = 0;
};

// Integrates f against the matching functions over pbrt's visible range, 360 to 830 nm, in 1 nm steps.
template <typename F>
Xyz integrate(F f) {
  Xyz sum;
  for (int nm = 360; nm <= 830; ++nm) {
    double v = f(double(nm));
    sum.x += v * cie_x(nm);
    sum.y += v * cie_y(nm);
    sum.z += v * cie_z(nm);
  }
  return sum;
}

RGB to_rgb(const Xyz& xyz) {
  return xyz_to_linear_srgb(static_cast<float>(xyz.x), static_cast<float>(xyz.y), static_cast<float>(xyz.z));
}

// A colour of chromaticity (x, y) and luminance 1.
RGB chromaticity_rgb(double x, double y) {
  return xyz_to_linear_srgb(static_cast<float>(x / y), 1.0f, static_cast<float>((1 - x - y) / y));
}

// ---------------------------------------------------------------- the named spectra

struct Entry {
  std::string_view name;
  NamedSpectrum spectrum;
};

constexpr NamedSpectrum metal(float r, float g, float b) { return {NamedKind::Metal, RGB(r, g, b), g}; }
constexpr NamedSpectrum glass(float ior) { return {NamedKind::Glass, RGB(ior), ior}; }

const std::vector<Entry>& table() {
  static const std::vector<Entry> entries = [] {
    std::vector<Entry> e = {
        // Conductors: RGB eta and k as published by Tungsten (B. Bitterli), src/core/bsdfs/ComplexIorData.hpp,
        // which the Bitterli scenes' "rgb eta"/"rgb k" values come from (e.g. Cu, Al), and which
        // description.h's ConductorMaterial defaults (pbrt-v4's default copper) use too. They are the
        // CIE 1931 XYZ -> linear sRGB image of the measured spectra under an equal-energy spectrum, not
        // white-balanced (a constant eta of 1.74 for MgO becomes 2.09 1.65 1.59).
        {"metal-Ag-eta", metal(0.155265f, 0.116723f, 0.138381f)},
        {"metal-Ag-k", metal(4.828343f, 3.122246f, 2.146950f)},
        {"metal-Al-eta", metal(1.657460f, 0.880369f, 0.521229f)},
        {"metal-Al-k", metal(9.223869f, 6.269523f, 4.837001f)},
        {"metal-Au-eta", metal(0.143119f, 0.374957f, 1.442479f)},
        {"metal-Au-k", metal(3.983160f, 2.385721f, 1.603215f)},
        {"metal-Cu-eta", metal(0.200438f, 0.924033f, 1.102212f)},
        {"metal-Cu-k", metal(3.912949f, 2.452848f, 2.142188f)},
        // Brass is not in Tungsten's list: converted here the same way from pbrt-v4's CuZn table
        // (refractiveindex.info, Querry 1987), with this file's matching functions (which give
        // Tungsten's Cu and Au values to about 1%).
        {"metal-CuZn-eta", metal(0.519152f, 0.488167f, 1.040889f)},
        {"metal-CuZn-k", metal(4.302314f, 2.559099f, 1.589303f)},
        {"metal-MgO-eta", metal(2.089589f, 1.650722f, 1.594876f)},
        {"metal-MgO-k", metal(0.0f, 0.0f, 0.0f)},
        {"metal-TiO2-eta", metal(3.456620f, 2.801708f, 2.905149f)},
        {"metal-TiO2-k", metal(0.000103f, 0.0f, 0.000636f)},  // Tungsten's -0.00009 green clamped to 0
        // Glasses: pbrt-v4's tables (refractiveindex.info's Schott data) interpolated at 550 nm. pbrt-v4's
        // "glass-F5", "-F10", "-F11" are the SF5, SF10 and SF11 glasses.
        {"glass-BK7", glass(1.51854f)},
        {"glass-BAF10", glass(1.67305f)},
        {"glass-FK51A", glass(1.48780f)},
        {"glass-LASF9", glass(1.85581f)},
        {"glass-F5", glass(1.67709f)},
        {"glass-F10", glass(1.73357f)},
        {"glass-F11", glass(1.79112f)},
    };
    // Illuminants: pbrt-v4 normalises a light's spectrum to luminance 1, so only the chromaticity
    // matters; these are the CIE 1931 chromaticities of the standard illuminants (CIE 15:2004).
    // D65 is the sRGB white and so exactly 1 1 1.
    struct Illuminant {
      std::string_view name;
      double x, y;
    };
    const Illuminant illuminants[] = {
        {"stdillum-A", 0.44757, 0.40745},   {"stdillum-D50", 0.34567, 0.35850}, {"stdillum-F1", 0.31310, 0.33727},
        {"stdillum-F2", 0.37208, 0.37529},  {"stdillum-F3", 0.40910, 0.39430},  {"stdillum-F4", 0.44018, 0.40329},
        {"stdillum-F5", 0.31379, 0.34531},  {"stdillum-F6", 0.37790, 0.38835},  {"stdillum-F7", 0.31292, 0.32933},
        {"stdillum-F8", 0.34588, 0.35875},  {"stdillum-F9", 0.37417, 0.37281},  {"stdillum-F10", 0.34609, 0.35986},
        {"stdillum-F11", 0.38052, 0.37713}, {"stdillum-F12", 0.43695, 0.40441}, {"illum-acesD60", 0.32168, 0.33767},
    };
    e.push_back({"stdillum-D65", {NamedKind::Illuminant, RGB(1.0f), 1.0f}});
    for (const Illuminant& i : illuminants) {
      RGB rgb = chromaticity_rgb(i.x, i.y);
      e.push_back({i.name, {NamedKind::Illuminant, rgb, rgb.g}});
    }
    return e;
  }();
  return entries;
}

}  // namespace

RGB xyz_to_linear_srgb(float x, float y, float z) {
  return {3.2404542f * x - 1.5371385f * y - 0.4985314f * z, -0.9692660f * x + 1.8760108f * y + 0.0415560f * z,
          0.0556434f * x - 0.2040259f * y + 1.0572252f * z};
}

std::optional<NamedSpectrum> find_named(std::string_view name) {
  for (const Entry& entry : table())
    if (entry.name == name) return entry.spectrum;
  return std::nullopt;
}

const std::vector<std::string_view>& named_spectrum_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> n;
    for (const Entry& entry : table()) n.push_back(entry.name);
    return n;
  }();
  return names;
}

// pbrt-v4's BlackbodySpectrum is Planck's law normalised to a peak of 1; as a light it is then
// normalised to luminance 1, which makes the peak normalisation irrelevant.
RGB blackbody_rgb(float kelvin) {
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  Xyz xyz = integrate([&](double nm) {
    double l = nm * 1e-9;
    return (2 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * kelvin)) - 1));
  });
  return to_rgb({xyz.x / xyz.y, 1.0, xyz.z / xyz.y});
}

float sampled_spectrum_at(std::span<const double> pairs, float lambda) {
  size_t n = pairs.size() / 2;
  if (n == 0) return 0;
  if (lambda <= pairs[0]) return static_cast<float>(pairs[1]);
  for (size_t i = 0; i + 1 < n; ++i) {
    double l0 = pairs[2 * i], l1 = pairs[2 * i + 2];
    if (lambda <= l1) {
      double t = (lambda - l0) / (l1 - l0);
      return static_cast<float>(pairs[2 * i + 1] * (1 - t) + pairs[2 * i + 3] * t);
    }
  }
  return static_cast<float>(pairs[2 * n - 1]);
}

RGB sampled_spectrum_rgb(std::span<const double> pairs, Role role) {
  auto value = [&](double nm) { return double(sampled_spectrum_at(pairs, static_cast<float>(nm))); };
  Xyz xyz = integrate(value);
  switch (role) {
    case Role::Illuminant:
      if (!(xyz.y > 0)) return RGB(0.0f);
      return to_rgb({xyz.x / xyz.y, 1.0, xyz.z / xyz.y});
    case Role::Unbounded: {
      // As Tungsten's metal table: normalised by the matching functions' luminance integral only.
      Xyz one = integrate([](double) { return 1.0; });
      return to_rgb({xyz.x / one.y, xyz.y / one.y, xyz.z / one.y});
    }
    case Role::Reflectance: {
      // Divided channel by channel by the image of a constant 1, so a flat reflectance stays flat.
      RGB rgb = to_rgb(xyz), white = to_rgb(integrate([](double) { return 1.0; }));
      return {rgb.r / white.r, rgb.g / white.g, rgb.b / white.b};
    }
  }
  return RGB(0.0f);
}

}  // namespace candela::pbrt_spectra
