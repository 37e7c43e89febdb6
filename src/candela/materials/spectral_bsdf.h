#pragma once
// A BSDF's RGB parameters turned into their values at a spectral sample's wavelengths
// (spectral/wavelengths.h), as pbrt-v4 reads RGB material parameters: colours as reflectance
// spectra, a conductor's eta and k as unbounded ones. Weights, roughness and indices of refraction
// are scalars and stay as they are; a hair fibre's absorption is an unbounded spectrum.
#include "candela/materials/surface_bsdf.h"
#include "candela/spectral/wavelengths.h"

namespace candela {

inline void bsdf_at_wavelengths(Bsdf& bsdf, const Wavelengths& wl) {
  auto reflectance = [&](RGB& c) { c = reflectance_at(c, wl); };
  // A conductor's optical constants as unbounded spectra (also the base of a coated conductor).
  auto conductor = [&](ConductorBsdf& b) {
    b.eta = unbounded_at(b.eta, wl);
    b.k = unbounded_at(b.k, wl);
    reflectance(b.tint);
  };
  std::visit(
      [&](auto& b) {
        using T = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<T, DiffuseBsdf> || std::is_same_v<T, MirrorBsdf>) {
          reflectance(b.reflectance);
        } else if constexpr (std::is_same_v<T, PhongBsdf>) {
          reflectance(b.diffuse);
          reflectance(b.specular);
          reflectance(b.transmission);
        } else if constexpr (std::is_same_v<T, DielectricBsdf> || std::is_same_v<T, DiffuseTransmissionBsdf>) {
          reflectance(b.reflectance);
          reflectance(b.transmittance);
        } else if constexpr (std::is_same_v<T, ConductorBsdf>) {
          conductor(b);
        } else if constexpr (std::is_same_v<T, LayeredDiffuseBsdf>) {
          reflectance(b.bottom.reflectance);
          reflectance(b.albedo);
        } else if constexpr (std::is_same_v<T, LayeredConductorBsdf>) {
          conductor(b.bottom);  // eta and k relative to the coat: a scale, which unbounded spectra keep
          reflectance(b.albedo);
        } else if constexpr (std::is_same_v<T, CoatedDiffuseBsdf>) {
          reflectance(b.reflectance);
          reflectance(b.specular);
        } else if constexpr (std::is_same_v<T, PrincipledBsdf> || std::is_same_v<T, PrincipledThinBsdf>) {
          reflectance(b.base_color);
        } else if constexpr (std::is_same_v<T, HairBsdf>) {
          // As pbrt-v4's HairMaterial: sigma_a (given, or from melanin concentrations) is an
          // unbounded spectrum; a colour is a reflectance spectrum, turned into sigma_a per wavelength.
          b.lanes = Wavelengths::kCount;
          if (b.sigma_a_from_color) {
            reflectance(b.color);
            b.resolve_color();
          } else {
            b.sigma_a = unbounded_at(b.sigma_a, wl);
          }
        } else {
          static_assert(std::is_same_v<T, BlackBsdf>, "a BSDF with colours must say how they become spectra");
        }
      },
      bsdf);
}

// Every component of a surface's mixture; wl null (an RGB render) leaves it as it is.
inline void bsdf_at_wavelengths(SurfaceBsdf& bsdf, const Wavelengths* wl) {
  if (!wl) return;
  for (int k = 0; k < bsdf.count; ++k) bsdf_at_wavelengths(bsdf.components[size_t(k)].bsdf, *wl);
}

}  // namespace candela
