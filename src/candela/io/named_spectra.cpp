// pbrt-v4's named spectra and spectral parameters converted to RGB (see named_spectra.h).
#include "candela/io/named_spectra.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "candela/spectral/blackbody.h"
#include "candela/spectral/cie.h"

namespace candela::pbrt_spectra {
namespace {

// ---------------------------------------------------------------- colour matching

using cie::Xyz;

// Integrates f against the CIE 1931 matching functions (spectral/cie.h) over pbrt's visible range,
// 360 to 830 nm, in 1 nm steps.
template <typename F>
Xyz integrate(F f) {
  Xyz sum;
  for (int nm = 360; nm <= 830; ++nm) {
    double v = f(double(nm));
    Xyz m = cie::matching(nm);
    sum.x += v * m.x;
    sum.y += v * m.y;
    sum.z += v * m.z;
  }
  return sum;
}

RGB to_rgb(const Xyz& xyz) { return cie::xyz_to_linear_srgb(xyz); }

// A colour of chromaticity (x, y) and luminance 1.
RGB chromaticity_rgb(double x, double y) {
  return cie::xyz_to_linear_srgb(x / y, 1.0, (1 - x - y) / y);
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
  Xyz xyz = integrate([&](double nm) { return planck(nm, kelvin, kPbrtPlanck); });
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

// ---------------------------------------------------------------- named conductors

namespace candela {
namespace {

std::optional<ComplexIor> find_complex_ior(std::span<const NamedComplexIor> table, std::string_view name) {
  for (const NamedComplexIor& entry : table)
    if (entry.name == name) return entry.ior;
  return std::nullopt;
}

std::vector<std::string_view> complex_ior_names(std::span<const NamedComplexIor> table) {
  std::vector<std::string_view> names;
  for (const NamedComplexIor& entry : table) names.push_back(entry.name);
  return names;
}

// Metals that pbrt-v4's named spectra (named_spectra.h: Ag, Al, Au, Cu, CuZn, ...) lack, from the
// same source as those: the published RGB values of Tungsten's ComplexIorData.hpp (also Mitsuba's
// conductor presets). Na, Ni and V are that table's "_palik" entries, the only ones it has for them.
constexpr NamedComplexIor kMoreMetals[] = {
    {"Be", {{4.1850592788f, 3.1850604423f, 2.7840913457f}, {3.8354398268f, 3.0101260162f, 2.8690088743f}}},
    {"Cr", {{4.3696828663f, 2.9167024892f, 1.6547005413f}, {5.2064337956f, 4.2313645277f, 3.7549467933f}}},
    {"Hg", {{2.3989314904f, 1.4400254917f, 0.9095512090f}, {6.3276269444f, 4.3719414152f, 3.4217899270f}}},
    {"Ir", {{3.0864098394f, 2.0821938440f, 1.6178866805f}, {5.5921510077f, 4.0671757150f, 3.2672611269f}}},
    {"K", {{0.0640493070f, 0.0464100621f, 0.0381842017f}, {2.1042155920f, 1.3489364357f, 0.9132113889f}}},
    {"Li", {{0.2657871942f, 0.1956102432f, 0.2209198538f}, {3.5401743407f, 2.3111306542f, 1.6685930000f}}},
    {"Mo", {{4.4837010280f, 3.5254578255f, 2.7760769438f}, {4.1111307988f, 3.4208716252f, 3.1506031404f}}},
    {"Na", {{0.0602665320f, 0.0561412435f, 0.0619909494f}, {3.1792906496f, 2.1124800781f, 1.5790940266f}}},
    {"Nb", {{3.4201353595f, 2.7901921379f, 2.3955856658f}, {3.4413817900f, 2.7376437930f, 2.5799132708f}}},
    {"Ni", {{2.3672753521f, 1.6633583302f, 1.4670554172f}, {4.4988329911f, 3.0501643957f, 2.3454274399f}}},
    {"Rh", {{2.5857954933f, 1.8601866068f, 1.5544279524f}, {6.7822927110f, 4.7029501026f, 3.9760892461f}}},
    {"Ta", {{2.0625846607f, 2.3930915569f, 2.6280684948f}, {2.4080467973f, 1.7413705864f, 1.9470377016f}}},
    {"TiN", {{1.6484691607f, 1.1504482522f, 1.3797795097f}, {3.3684596226f, 1.9434888540f, 1.1020123347f}}},
    {"V", {{4.2775126218f, 3.5131538236f, 2.7611257461f}, {3.4911844504f, 2.8893580874f, 3.1116965117f}}},
    {"W", {{4.3707029924f, 3.3002972445f, 2.9982666528f}, {3.5006778591f, 2.6048652781f, 2.2731930614f}}},
};

}  // namespace

std::optional<ComplexIor> named_metal(std::string_view name) {
  std::string prefix = fmt::format("metal-{}-", name);
  auto eta = pbrt_spectra::find_named(prefix + "eta"), k = pbrt_spectra::find_named(prefix + "k");
  if (eta && k && eta->kind == pbrt_spectra::NamedKind::Metal) return ComplexIor{eta->rgb, k->rgb};
  return find_complex_ior(kMoreMetals, name);
}

std::vector<std::string> named_metal_names() {
  std::vector<std::string> names;
  for (std::string_view spectrum : pbrt_spectra::named_spectrum_names())
    if (spectrum.starts_with("metal-") && spectrum.ends_with("-eta"))
      names.emplace_back(spectrum.substr(6, spectrum.size() - 6 - 4));
  for (std::string_view metal : complex_ior_names(kMoreMetals)) names.emplace_back(metal);
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace candela

// ---------------------------------------------------------------- Mitsuba 3

namespace candela::mitsuba_spectra {
namespace {

// Mitsuba interpolates the CIE's 5 nm tables linearly, as cie::matching does.
constexpr double kCieMin = cie::kLambdaMin, kCieMax = cie::kLambdaMax;

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
    cie::Xyz c = cie::matching(w);
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

// Computed with spectrum_list_to_srgb above (after the kCieYNormalization Mitsuba applies) from
// Mitsuba's measured spectra, data/ior/*.spd (luxpop.com); Ag agrees with Mitsuba 3's own output to
// 1e-6. "none" is Mitsuba's perfect mirror (eta 0, k 1: Fresnel reflectance 1 at every angle).
const NamedComplexIor kConductors[] = {
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

std::optional<Conductor> named_conductor(std::string_view name) { return find_complex_ior(kConductors, name); }

const std::vector<std::string_view>& named_conductor_names() {
  static const std::vector<std::string_view> names = complex_ior_names(kConductors);
  return names;
}

}  // namespace candela::mitsuba_spectra
