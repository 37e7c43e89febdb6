#pragma once
// pbrt-v4's spectral values as candela's RGB: its built-in named spectra ("metal-Cu-eta",
// "glass-BK7", "stdillum-D65", ...), blackbody emitters, and spectra written inline as
// (wavelength, value) pairs. The tables and the conversions are documented in docs/pbrt-format.md
// ("Spectra").
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "candela/math/color.h"

namespace candela {

// A conductor's complex index of refraction eta + i k, as RGB.
struct ComplexIor {
  RGB eta, k;
};

// An entry of a table of named conductors (pbrt-v4's metals, Mitsuba's conductor presets).
struct NamedComplexIor {
  std::string_view name;
  ComplexIor ior;
};

// The metals candela's JSON format names in a conductor's "metal" (docs/scene-format.md): "Au" is
// pbrt-v4's "metal-Au-eta" and "metal-Au-k", and Tungsten's metals that pbrt-v4 lacks (Be, Cr, ...).
std::optional<ComplexIor> named_metal(std::string_view name);
std::vector<std::string> named_metal_names();  // sorted

}  // namespace candela

namespace candela::pbrt_spectra {

// What a spectrum describes decides how it becomes RGB.
enum class Role {
  Reflectance,  // an albedo in [0, 1]: weighted so that a constant spectrum keeps its value
  Unbounded,    // an optical constant (a conductor's eta or k)
  Illuminant    // emission: normalised to luminance 1, as pbrt-v4 normalises every light spectrum
};

// A built-in named spectrum. `kind` says which family it belongs to.
enum class NamedKind { Metal, Glass, Illuminant };
struct NamedSpectrum {
  NamedKind kind;
  RGB rgb;          // metals: eta or k per channel; illuminants: luminance 1; glasses: the IOR in all three
  float ior_550nm;  // glasses: the refractive index at 550 nm; others: rgb.g
};
std::optional<NamedSpectrum> find_named(std::string_view name);

// Every name find_named() knows, for messages.
const std::vector<std::string_view>& named_spectrum_names();

// A blackbody emitter at `kelvin`, as linear sRGB with luminance 1 (pbrt-v4 normalises a light's
// spectrum to one nit before "scale" and "power" apply).
RGB blackbody_rgb(float kelvin);

// A spectrum written as (wavelength in nm, value) pairs, increasing in wavelength.
RGB sampled_spectrum_rgb(std::span<const double> pairs, Role role);
// Its value at `lambda` nm (linear interpolation, constant beyond the ends).
float sampled_spectrum_at(std::span<const double> pairs, float lambda);

}  // namespace candela::pbrt_spectra

// Mitsuba 3's spectral values as its RGB variants (scalar_rgb) see them (docs/mitsuba-format.md).
namespace candela::mitsuba_spectra {

// Mitsuba's spectrum_list_to_srgb: the piecewise-linear spectrum (zero outside its first and last
// wavelength) integrated against the CIE 1931 curves at 1000 points over 360..830 nm, turned into
// linear sRGB, and clamped to [0, 1] (bounded) or at 0. The values are used as given: Mitsuba's XML
// parser first multiplies inline spectra by kCieYNormalization.
RGB spectrum_list_to_srgb(std::span<const double> wavelengths, std::span<const double> values, bool bounded);
inline constexpr double kCieYNormalization = 1.0 / 106.7502593994140625;

// Mitsuba's named indices of refraction (src/render/ior.h: "bk7", "air", "diamond", ...), by
// lower-case name.
std::optional<float> named_ior(std::string_view name);
const std::vector<std::string_view>& named_ior_names();

// A conductor preset ("material" of conductor / roughconductor): eta and k as Mitsuba's RGB mode
// converts the measured spectra (resources/data/ior/NAME.{eta,k}.spd through spectrum_list_to_srgb).
using Conductor = ComplexIor;
std::optional<Conductor> named_conductor(std::string_view name);
const std::vector<std::string_view>& named_conductor_names();

}  // namespace candela::mitsuba_spectra
