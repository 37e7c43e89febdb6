// pbrt-v4's named spectra and spectral parameters converted to RGB (see named_spectra.h).
#include "candela/io/named_spectra.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

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

// ---------------------------------------------------------------- Mitsuba 3

namespace candela::mitsuba_spectra {
namespace {

// The CIE 1931 2-degree colour matching functions tabulated every 5 nm from 360 to 830 nm (the
// CIE's own table, which Mitsuba interpolates linearly).
constexpr int kCieSamples = 95;
constexpr double kCieMin = 360, kCieMax = 830;
constexpr float kCieX[kCieSamples] = {
    0.0001299f, 0.0002321f, 0.0004149f, 0.0007416f, 0.001368f, 0.002236f, 0.004243f, 0.00765f, 0.01431f,
    0.02319f, 0.04351f, 0.07763f, 0.13438f, 0.21477f, 0.2839f, 0.3285f, 0.34828f, 0.34806f, 0.3362f, 0.3187f,
    0.2908f, 0.2511f, 0.19536f, 0.1421f, 0.09564f, 0.05795001f, 0.03201f, 0.0147f, 0.0049f, 0.0024f, 0.0093f,
    0.0291f, 0.06327f, 0.1096f, 0.1655f, 0.2257499f, 0.2904f, 0.3597f, 0.4334499f, 0.5120501f, 0.5945f, 0.6784f,
    0.7621f, 0.8425f, 0.9163f, 0.9786f, 1.0263f, 1.0567f, 1.0622f, 1.0456f, 1.0026f, 0.9384f, 0.8544499f, 0.7514f,
    0.6424f, 0.5419f, 0.4479f, 0.3608f, 0.2835f, 0.2187f, 0.1649f, 0.1212f, 0.0874f, 0.0636f, 0.04677f, 0.0329f,
    0.0227f, 0.01584f, 0.01135916f, 0.008110916f, 0.005790346f, 0.004109457f, 0.002899327f, 0.00204919f,
    0.001439971f, 0.0009999493f, 0.0006900786f, 0.0004760213f, 0.0003323011f, 0.0002348261f, 0.0001661505f,
    0.000117413f, 8.307527e-05f, 5.870652e-05f, 4.150994e-05f, 2.935326e-05f, 2.067383e-05f, 1.455977e-05f,
    1.025398e-05f, 7.221456e-06f, 5.085868e-06f, 3.581652e-06f, 2.522525e-06f, 1.776509e-06f, 1.251141e-06f};
constexpr float kCieY[kCieSamples] = {
    3.917e-06f, 6.965e-06f, 1.239e-05f, 2.202e-05f, 3.9e-05f, 6.4e-05f, 0.00012f, 0.000217f, 0.000396f, 0.00064f,
    0.00121f, 0.00218f, 0.004f, 0.0073f, 0.0116f, 0.01684f, 0.023f, 0.0298f, 0.038f, 0.048f, 0.06f, 0.0739f,
    0.09098f, 0.1126f, 0.13902f, 0.1693f, 0.20802f, 0.2586f, 0.323f, 0.4073f, 0.503f, 0.6082f, 0.71f, 0.7932f,
    0.862f, 0.9148501f, 0.954f, 0.9803f, 0.9949501f, 1.0f, 0.995f, 0.9786f, 0.952f, 0.9154f, 0.87f, 0.8163f,
    0.757f, 0.6949f, 0.631f, 0.5668f, 0.503f, 0.4412f, 0.381f, 0.321f, 0.265f, 0.217f, 0.175f, 0.1382f, 0.107f,
    0.0816f, 0.061f, 0.04458f, 0.032f, 0.0232f, 0.017f, 0.01192f, 0.00821f, 0.005723f, 0.004102f, 0.002929f,
    0.002091f, 0.001484f, 0.001047f, 0.00074f, 0.00052f, 0.0003611f, 0.0002492f, 0.0001719f, 0.00012f, 8.48e-05f,
    6e-05f, 4.24e-05f, 3e-05f, 2.12e-05f, 1.499e-05f, 1.06e-05f, 7.4657e-06f, 5.2578e-06f, 3.7029e-06f,
    2.6078e-06f, 1.8366e-06f, 1.2934e-06f, 9.1093e-07f, 6.4153e-07f, 4.5181e-07f};
constexpr float kCieZ[kCieSamples] = {
    0.0006061f, 0.001086f, 0.001946f, 0.003486f, 0.006450001f, 0.01054999f, 0.02005001f, 0.03621f, 0.06785001f,
    0.1102f, 0.2074f, 0.3713f, 0.6456f, 1.0390501f, 1.3856f, 1.62296f, 1.74706f, 1.7826f, 1.77211f, 1.7441f,
    1.6692f, 1.5281f, 1.28764f, 1.0419f, 0.8129501f, 0.6162f, 0.46518f, 0.3533f, 0.272f, 0.2123f, 0.1582f, 0.1117f,
    0.07824999f, 0.05725001f, 0.04216f, 0.02984f, 0.0203f, 0.0134f, 0.008749999f, 0.005749999f, 0.0039f,
    0.002749999f, 0.0021f, 0.0018f, 0.001650001f, 0.0014f, 0.0011f, 0.001f, 0.0008f, 0.0006f, 0.00034f, 0.00024f,
    0.00019f, 0.0001f, 4.999999e-05f, 3e-05f, 2e-05f, 1e-05f};  // zero from 650 nm on

struct CieXyz {
  double x, y, z;
};
CieXyz cie_at(double nm) {
  double t = (nm - kCieMin) * ((kCieSamples - 1) / (kCieMax - kCieMin));
  int i0 = std::clamp(int(t), 0, kCieSamples - 2);
  double w1 = t - i0, w0 = 1 - w1;
  return {w0 * kCieX[i0] + w1 * kCieX[i0 + 1], w0 * kCieY[i0] + w1 * kCieY[i0 + 1],
          w0 * kCieZ[i0] + w1 * kCieZ[i0 + 1]};
}

}  // namespace

RGB spectrum_list_to_srgb(std::span<const double> wavelengths, std::span<const double> values, bool bounded) {
  size_t n = std::min(wavelengths.size(), values.size());
  if (n < 2) return RGB(n == 1 ? float(values[0]) : 0.0f);
  double x = 0, y = 0, z = 0;
  const int steps = 1000;
  for (int i = 0; i < steps; ++i) {
    double w = kCieMin + (i / double(steps - 1)) * (kCieMax - kCieMin);
    if (w < wavelengths[0] || w > wavelengths[n - 1]) continue;
    size_t k = 0;
    while (k + 2 < n && wavelengths[k + 1] <= w) ++k;
    double w0 = wavelengths[k], w1 = wavelengths[k + 1], v0 = values[k], v1 = values[k + 1];
    double v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
    CieXyz c = cie_at(w);
    x += c.x * v;
    y += c.y * v;
    z += c.z * v;
  }
  double dw = (kCieMax - kCieMin) / steps;
  x *= dw, y *= dw, z *= dw;
  // Mitsuba's XYZ -> linear Rec. 709 matrix.
  double r = 3.240479 * x - 1.537150 * y - 0.498535 * z;
  double g = -0.969256 * x + 1.875991 * y + 0.041556 * z;
  double b = 0.055648 * x - 0.204043 * y + 1.057311 * z;
  auto fix = [&](double c) { return float(bounded ? std::clamp(c, 0.0, 1.0) : std::max(c, 0.0)); };
  return {fix(r), fix(g), fix(b)};
}

namespace {
struct IorEntry {
  std::string_view name;
  float ior;
};
// Mitsuba's table (Hecht, Optics; 0-20 degrees Celsius, about 589 nm).
constexpr IorEntry kIors[] = {
    {"vacuum", 1.0f},          {"helium", 1.000036f},        {"hydrogen", 1.000132f},
    {"air", 1.000277f},        {"carbon dioxide", 1.00045f}, {"water", 1.3330f},
    {"acetone", 1.36f},        {"ethanol", 1.361f},          {"carbon tetrachloride", 1.461f},
    {"glycerol", 1.4729f},     {"benzene", 1.501f},          {"silicone oil", 1.52045f},
    {"bromine", 1.661f},       {"water ice", 1.31f},         {"fused quartz", 1.458f},
    {"pyrex", 1.470f},         {"acrylic glass", 1.49f},     {"polypropylene", 1.49f},
    {"bk7", 1.5046f},          {"sodium chloride", 1.544f},  {"amber", 1.55f},
    {"pet", 1.5750f},          {"diamond", 2.419f},
};

struct ConductorEntry {
  std::string_view name;
  Conductor value;
};
// Computed with spectrum_list_to_srgb above (after the kCieYNormalization Mitsuba applies) from
// Mitsuba's measured spectra, data/ior/*.spd (luxpop.com); Ag agrees with Mitsuba 3's own output to
// 1e-6. "none" is Mitsuba's perfect mirror (eta 0, k 1: Fresnel reflectance 1 at every angle).
const ConductorEntry kConductors[] = {
    {"none", {RGB(0.0f), RGB(1.0f)}},
    {"Ag", {RGB(0.155276f, 0.116728f, 0.138388f), RGB(4.828354f, 3.122222f, 2.146901f)}},
    {"Al", {RGB(1.657501f, 0.880405f, 0.521244f), RGB(9.223811f, 6.269502f, 4.837004f)}},
    {"Au", {RGB(0.143036f, 0.375307f, 1.442045f), RGB(3.982997f, 2.385556f, 1.603359f)}},
    {"Cu", {RGB(0.201006f, 0.923749f, 1.102215f), RGB(3.913262f, 2.453045f, 2.142090f)}},
    {"a-C", {RGB(2.944046f, 2.227136f, 1.968162f), RGB(0.887465f, 0.799298f, 0.815290f)}},
};
}  // namespace

std::optional<float> named_ior(std::string_view name) {
  std::string lower(name);
  for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  for (const IorEntry& e : kIors)
    if (e.name == lower) return e.ior;
  return std::nullopt;
}

const std::vector<std::string_view>& named_ior_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> n;
    for (const IorEntry& e : kIors) n.push_back(e.name);
    return n;
  }();
  return names;
}

std::optional<Conductor> named_conductor(std::string_view name) {
  for (const ConductorEntry& e : kConductors)
    if (e.name == name) return e.value;
  return std::nullopt;
}

const std::vector<std::string_view>& named_conductor_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> n;
    for (const ConductorEntry& e : kConductors) n.push_back(e.name);
    return n;
  }();
  return names;
}

}  // namespace candela::mitsuba_spectra
