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
        else if constexpr (std::is_same_v<T, PrincipledMaterial>)
          return is_constant(m.base_color) && is_constant(m.roughness) && is_constant(m.metallic) &&
                 is_constant(m.specular) && is_constant(m.specular_tint) && is_constant(m.anisotropic) &&
                 is_constant(m.sheen) && is_constant(m.sheen_tint) && is_constant(m.clearcoat) &&
                 is_constant(m.clearcoat_gloss) && is_constant(m.spec_trans) && is_constant(m.diff_trans) &&
                 is_constant(m.flatness);
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
        } else if constexpr (std::is_same_v<T, PrincipledMaterial>) {
          // Mitsuba's principled / principledthin; the inputs clamped to their documented ranges.
          auto unit = [&](const FloatInput& f) { return std::clamp(tex.eval(f, ctx), 0.0f, 1.0f); };
          PrincipledParams p;
          p.base_color = albedo(m.base_color);
          p.roughness = unit(m.roughness);
          p.anisotropic = unit(m.anisotropic);
          p.metallic = unit(m.metallic);
          p.spec_tint = unit(m.specular_tint);
          p.spec_trans = unit(m.spec_trans);
          p.sheen = unit(m.sheen);
          p.sheen_tint = unit(m.sheen_tint);
          p.clearcoat = unit(m.clearcoat);
          p.clearcoat_gloss = unit(m.clearcoat_gloss);
          p.flatness = unit(m.flatness);
          p.diff_trans = std::clamp(tex.eval(m.diff_trans, ctx), 0.0f, 2.0f);
          if (m.thin) {
            p.eta = m.eta;
            return PrincipledThinBsdf(p);
          }
          // As Mitsuba: where spec_trans is given (a texture or non-zero), eta 1 becomes 1.001 and
          // specular 0 becomes 1e-3, so that the transmission has an interface.
          bool has_trans = !m.spec_trans.is_constant() || m.spec_trans.value != 0;
          if (m.eta_given) {
            p.eta = has_trans && m.eta == 1 ? 1.001f : m.eta;
          } else {
            float specular = unit(m.specular);
            p.eta = principled_eta_from_specular(has_trans && specular == 0 ? 1e-3f : specular);
          }
          return PrincipledBsdf(p);
        } else {
          return BlackBsdf{};  // black, and interfaces (never shaded: the integrator passes through)
        }
      },
      desc);
}

}  // namespace candela
