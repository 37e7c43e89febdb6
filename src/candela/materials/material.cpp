#include "candela/materials/material.h"

namespace candela {
namespace {

bool is_constant(const ColorInput& c) { return c.is_constant(); }
bool is_constant(const FloatInput& f) { return f.is_constant(); }
bool is_constant(const Roughness& r) { return r.u.is_constant() && r.v.is_constant(); }

// Whether every input of the material is a constant (then its BSDF is the same at every hit).
bool has_constant_inputs(const MaterialDesc& desc) {
  return std::visit(
      [](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, DiffuseMaterial>) return is_constant(m.reflectance);
        else if constexpr (std::is_same_v<T, PhongMaterial>)
          return is_constant(m.diffuse) && is_constant(m.specular) && is_constant(m.transmission);
        else if constexpr (std::is_same_v<T, MirrorMaterial>) return is_constant(m.reflectance);
        else if constexpr (std::is_same_v<T, DielectricMaterial>)
          return is_constant(m.reflectance) && is_constant(m.transmittance) && is_constant(m.roughness);
        else if constexpr (std::is_same_v<T, ConductorMaterial>)
          return is_constant(m.eta) && is_constant(m.k) && (!m.reflectance || is_constant(*m.reflectance)) &&
                 is_constant(m.specular_tint) && is_constant(m.roughness);
        else if constexpr (std::is_same_v<T, CoatedDiffuseMaterial>)
          return is_constant(m.reflectance) && is_constant(m.specular) && is_constant(m.roughness);
        else if constexpr (std::is_same_v<T, DiffuseTransmissionMaterial>)
          return is_constant(m.reflectance) && is_constant(m.transmittance);
        else return true;
      },
      desc);
}

}  // namespace

MaterialTable::MaterialTable(const std::vector<MaterialDesc>& descs, const TextureSet& textures)
    : textures_(&textures) {
  entries_.reserve(descs.size() + 1);
  for (const auto& d : descs) entries_.push_back({d, std::nullopt, std::holds_alternative<InterfaceMaterial>(d)});
  entries_.push_back({DiffuseMaterial{RGB(0.5f)}, std::nullopt, false});
  for (auto& e : entries_)
    if (has_constant_inputs(e.desc)) e.constant = build(e.desc, TextureEvalContext{});
}

Bsdf MaterialTable::build(const MaterialDesc& desc, const TextureEvalContext& ctx) const {
  const TextureSet& tex = *textures_;
  auto color = [&](const ColorInput& c) { return tex.eval(c, ctx); };
  // Clamp reflectances to [0, 1]: a texture brighter than 1 would create energy.
  auto albedo = [&](const ColorInput& c) {
    RGB v = tex.eval(c, ctx);
    return RGB(std::clamp(v.r, 0.0f, 1.0f), std::clamp(v.g, 0.0f, 1.0f), std::clamp(v.b, 0.0f, 1.0f));
  };
  auto distribution = [&](const Roughness& r) {
    float u = std::max(0.0f, tex.eval(r.u, ctx)), v = std::max(0.0f, tex.eval(r.v, ctx));
    if (r.remap) {
      u = TrowbridgeReitz::roughness_to_alpha(u);
      v = TrowbridgeReitz::roughness_to_alpha(v);
    }
    return TrowbridgeReitz(u, v);
  };
  return std::visit(
      [&](const auto& m) -> Bsdf {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, DiffuseMaterial>) {
          return DiffuseBsdf{albedo(m.reflectance)};
        } else if constexpr (std::is_same_v<T, PhongMaterial>) {
          return PhongBsdf{albedo(m.diffuse), albedo(m.specular), m.exponent, albedo(m.transmission), m.ior,
                           m.d, m.s, m.t};
        } else if constexpr (std::is_same_v<T, MirrorMaterial>) {
          return MirrorBsdf{albedo(m.reflectance)};
        } else if constexpr (std::is_same_v<T, DielectricMaterial>) {
          return DielectricBsdf{m.ior, albedo(m.reflectance), albedo(m.transmittance), distribution(m.roughness)};
        } else if constexpr (std::is_same_v<T, ConductorMaterial>) {
          RGB eta = color(m.eta), k = color(m.k);
          if (m.reflectance) {
            eta = RGB(1.0f);
            k = conductor_k_from_reflectance(albedo(*m.reflectance));
          }
          return ConductorBsdf{eta, k, albedo(m.specular_tint), distribution(m.roughness)};
        } else if constexpr (std::is_same_v<T, CoatedDiffuseMaterial>) {
          return CoatedDiffuseBsdf{albedo(m.reflectance), albedo(m.specular), m.ior, distribution(m.roughness),
                                   m.nonlinear};
        } else if constexpr (std::is_same_v<T, DiffuseTransmissionMaterial>) {
          return DiffuseTransmissionBsdf{albedo(m.reflectance), albedo(m.transmittance)};
        } else {
          return BlackBsdf{};  // black, and interfaces (never shaded: the integrator passes through)
        }
      },
      desc);
}

}  // namespace candela
