#include "candela/materials/material.h"

#include <bit>

#include "candela/base/error.h"
#include "candela/base/overloaded.h"
#include "candela/sampling/rng.h"

namespace candela {
namespace {

bool is_constant(const Roughness& r) { return r.u.is_constant() && r.v.is_constant(); }

// Whether every input of the material is a constant (then its BSDF is the same at every hit):
// its colours, numbers and roughness, as its schema lists them (description/materials.h). The
// materials a wrapper wraps are checked by the caller.
bool has_constant_inputs(const MaterialDesc& desc) {
  const TypeSchema& schema = schema_of(desc);
  const void* object = std::visit([](const auto& m) -> const void* { return &m; }, desc);
  for (const Field& f : schema.fields) {
    switch (f.kind) {
      case FieldKind::Color:
        if (!field_value<ColorInput>(f, object).is_constant()) return false;
        break;
      case FieldKind::OptionalColor:
        if (const auto& c = field_value<std::optional<ColorInput>>(f, object); c && !c->is_constant()) return false;
        break;
      case FieldKind::Float:
        if (!field_value<FloatInput>(f, object).is_constant()) return false;
        break;
      case FieldKind::Roughness:
        if (!is_constant(field_value<Roughness>(f, object))) return false;
        break;
      // Constant by nature; and maps only tilt the frame.
      case FieldKind::Number:
      case FieldKind::NumberIfGiven:
      case FieldKind::Flag:
      case FieldKind::Material:
      case FieldKind::MaterialPair:
      case FieldKind::Texture:
      case FieldKind::Rgb:
      case FieldKind::Point:
      case FieldKind::Direction:
      case FieldKind::Vector:
      case FieldKind::Transform:
      case FieldKind::Enum:
      case FieldKind::File:
      // Not in materials' schemas.
      case FieldKind::Text:
      case FieldKind::UvMapping:
      case FieldKind::Integer:
      case FieldKind::ScalarVolume:
      case FieldKind::ColorVolume:
      case FieldKind::OptionalScalarVolume: break;
    }
  }
  return true;
}

// The materials a wrapper wraps, in its schema's order (none for other materials).
std::vector<int> nested_materials(const MaterialDesc& desc) {
  const TypeSchema& schema = schema_of(desc);
  const void* object = std::visit([](const auto& m) -> const void* { return &m; }, desc);
  std::vector<int> nested;
  for (const Field& f : schema.fields) {
    if (f.kind == FieldKind::Material) nested.push_back(field_value<int>(f, object));
    if (f.kind == FieldKind::MaterialPair) {
      nested.push_back(field_value<int>(f, object));
      nested.push_back(field_second<int>(f, object));
    }
  }
  return nested;
}

// The microfacet distribution a roughness input gives at a hit.
Microfacet microfacet(const Roughness& r, const TextureSet& tex, const TextureEvalContext& ctx) {
  float u = std::max(0.0f, tex.eval(r.u, ctx)), v = std::max(0.0f, tex.eval(r.v, ctx));
  if (r.remap) {
    u = TrowbridgeReitz::roughness_to_alpha(u);
    v = TrowbridgeReitz::roughness_to_alpha(v);
  }
  switch (r.distribution) {
    case MicrofacetDistribution::Beckmann: return Beckmann(u, v);
    case MicrofacetDistribution::GGXSeparable: return TrowbridgeReitz(u, v, MaskingShadowing::Separable);
    case MicrofacetDistribution::GGX: break;
  }
  return TrowbridgeReitz(u, v);
}

}  // namespace

MaterialTable::MaterialTable(const std::vector<MaterialDesc>& descs, const TextureSet& textures,
                             const EntryPlace& place_of)
    : textures_(&textures) {
  auto name = [&](size_t i) { return place_of ? fmt::format("{}: material {}", place_of(i), i) : fmt::format("material {}", i); };
  entries_.reserve(descs.size() + 1);
  for (const auto& d : descs) {
    const auto* dielectric = std::get_if<DielectricMaterial>(&d);
    bool interface = std::holds_alternative<InterfaceMaterial>(d);
    bool passes = interface || std::holds_alternative<MaskMaterial>(d) || (dielectric && dielectric->thin);
    entries_.push_back({d, std::nullopt, interface, passes, {}});
    entries_.back().stochastic =
        std::holds_alternative<LayeredDiffuseMaterial>(d) || std::holds_alternative<LayeredConductorMaterial>(d);
  }
  entries_.push_back({DiffuseMaterial{RGB(0.5f)}, std::nullopt, false, false, {}});
  // Wrappers refer to materials before them, so one pass in order sees every nested material done.
  std::vector<int> leaves(entries_.size(), 1);
  std::vector<bool> constant(entries_.size(), true);
  for (size_t i = 0; i < entries_.size(); ++i) {
    Entry& e = entries_[i];
    // A hair's BSDF depends on where across the fibre the hit lies (its v), whatever its inputs.
    constant[i] = has_constant_inputs(e.desc) && !std::holds_alternative<HairMaterial>(e.desc);
    if (const auto* coated = std::get_if<CoatedDiffuseMaterial>(&e.desc); coated && coated->tabulated_coat) {
      if (!is_constant(coated->roughness))
        throw SceneError(fmt::format("{}: a tabulated coat needs a constant roughness", name(i)));
      e.coat_table = std::make_shared<const RoughCoatTable>(
          make_rough_coat_table(microfacet(coated->roughness, textures, TextureEvalContext{}), coated->ior));
    }
    std::vector<int> nested = nested_materials(e.desc);
    if (nested.empty()) continue;
    int count = 0;
    for (int n : nested) {
      if (n < 0 || size_t(n) >= i)
        throw SceneError(fmt::format("{}: wraps material {}, which is not a material before it", name(i), n));
      e.may_pass_through = e.may_pass_through || entries_[size_t(n)].may_pass_through;
      e.stochastic = e.stochastic || entries_[size_t(n)].stochastic;
      if (std::holds_alternative<TwoSidedMaterial>(entries_[size_t(n)].desc))
        throw SceneError(fmt::format("{}: wraps material {}, which has two sides; a two-sided material must be "
                                     "the outermost (it is chosen per hit by the side seen)", name(i), n));
      count += leaves[size_t(n)];
      constant[i] = constant[i] && constant[size_t(n)];
    }
    if (std::holds_alternative<TwoSidedMaterial>(e.desc)) {
      constant[i] = false;  // never resolved itself: shading() picks a side first
      continue;
    }
    leaves[i] = count;
    if (count > SurfaceBsdf::kMaxComponents)
      throw SceneError(fmt::format("{}: blends {} materials; at most {} can be mixed at one surface", name(i),
                                   count, SurfaceBsdf::kMaxComponents));
    e.perturbations = entries_[size_t(nested[0])].perturbations;
    if (nested.size() == 2 && entries_[size_t(nested[1])].perturbations != e.perturbations)
      throw SceneError(fmt::format("{}: blends materials with different normal or bump maps (one shading frame per surface point)", name(i)));
    if (std::holds_alternative<NormalMapMaterial>(e.desc) || std::holds_alternative<BumpMapMaterial>(e.desc)) {
      const int map = std::holds_alternative<NormalMapMaterial>(e.desc) ? std::get<NormalMapMaterial>(e.desc).normal_map
                                                                        : std::get<BumpMapMaterial>(e.desc).height;
      if (map < 0 || size_t(map) >= textures.size())
        throw SceneError(fmt::format("{}: the normal or bump map is texture {}, which does not exist", name(i), map));
      e.perturbations.insert(e.perturbations.begin(), int(i));
    }
  }
  for (size_t i = 0; i < entries_.size(); ++i)
    if (constant[i]) entries_[i].constant = resolve(uint32_t(i), TextureEvalContext{});
}

SurfaceBsdf MaterialTable::resolve(uint32_t material, const TextureEvalContext& ctx) const {
  const MaterialDesc& desc = entries_[material].desc;
  if (nested_materials(desc).empty()) return SurfaceBsdf(build(entries_[material], ctx));
  SurfaceBsdf out;
  collect(int(material), 1, false, ctx, out);
  return out;
}

void MaterialTable::collect(int material, float weight, bool one_sided, const TextureEvalContext& ctx,
                            SurfaceBsdf& out) const {
  const Entry& entry = entries_[size_t(material)];
  const MaterialDesc& desc = entry.desc;
  auto clamp01 = [&](const FloatInput& f) { return std::clamp(textures_->eval(f, ctx), 0.0f, 1.0f); };
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, OneSidedMaterial>) {
          collect(m.material, weight, true, ctx, out);
        } else if constexpr (std::is_same_v<T, MaskMaterial>) {
          float opacity = clamp01(m.opacity);
          out.null_weight += weight * (1 - opacity);
          if (opacity > 0) collect(m.material, weight * opacity, one_sided, ctx, out);
        } else if constexpr (std::is_same_v<T, BlendMaterial>) {
          float t = clamp01(m.weight);
          if (t < 1) collect(m.material0, weight * (1 - t), one_sided, ctx, out);
          if (t > 0) collect(m.material1, weight * t, one_sided, ctx, out);
        } else if constexpr (std::is_same_v<T, NormalMapMaterial> || std::is_same_v<T, BumpMapMaterial>) {
          collect(m.material, weight, one_sided, ctx, out);
        } else if constexpr (std::is_same_v<T, InterfaceMaterial>) {
          out.null_weight += weight;  // no surface: a wrapped interface lets the ray pass
        } else {
          // Every other material is a BSDF of its own (build()). (A two-sided material is never
          // collected: it is the outermost, and a side is picked first.)
          if (out.count < SurfaceBsdf::kMaxComponents) out.add(build(entry, ctx), weight, one_sided);
        }
      },
      desc);
}

Shading MaterialTable::shading(uint32_t material, const TextureEvalContext& ctx, const SurfaceHit& hit,
                               const Vec3& wo) const {
  if (const auto* sides = std::get_if<TwoSidedMaterial>(&entries_[material].desc))
    material = uint32_t(dot(wo, hit.ng) >= 0 ? sides->front : sides->back);
  Shading s{one_side_bsdf(material, ctx), Frame::from_normal_tangent(hit.ns, hit.dpdu)};
  const Entry& e = entries_[material];
  // Layered BSDFs draw their random walks from a seed per shading point: the hit point's bits,
  // which are the same in every run whatever the thread count (materials/layered.h).
  if (e.stochastic) {
    const uint32_t seed = uint32_t(hash_values(std::bit_cast<uint32_t>(hit.p.x), std::bit_cast<uint32_t>(hit.p.y),
                                               std::bit_cast<uint32_t>(hit.p.z), hit.shape, hit.primitive));
    for (int k = 0; k < s.bsdf.count; ++k)
      std::visit(
          [&](auto& b) {
            if constexpr (has(std::decay_t<decltype(b)>::flags, BsdfFlags::Stochastic)) b.seed = seed;
          },
          s.bsdf.components[size_t(k)].bsdf);
  }
  if (e.perturbations.empty()) return s;
  const Normal3 original = s.frame.n;
  bool shadowing = false;
  for (int map : e.perturbations) shadowing |= perturb(map, ctx, hit, wo, s.frame);
  s.bsdf.check_side = true;
  s.bsdf.original_normal = s.frame.to_local(original);
  if (shadowing) {
    // The tilt's tan^2 (Mitsuba's tan_theta_2 of the perturbed normal in the original frame).
    float cos2 = sqr(s.bsdf.original_normal.z), sin2 = std::max(0.0f, 1 - cos2);
    s.bsdf.terminator_alpha2 = cos2 > 0 ? std::min(0.125f * sin2 / cos2, 1.0f) : 1.0f;
  }
  return s;
}

bool MaterialTable::perturb(int map, const TextureEvalContext& ctx, const SurfaceHit& hit, const Vec3& wo,
                            Frame& frame) const {
  const TextureSet& tex = *textures_;
  Vec3 n_local;
  PerturbedNormalOptions options;
  if (const auto* nm = std::get_if<NormalMapMaterial>(&entries_[size_t(map)].desc)) {
    options = nm->options;
    ColorInput in;
    in.texture = nm->normal_map;
    RGB c = tex.eval(in, ctx);
    n_local = Vec3(2 * c.r - 1, 2 * c.g - 1, 2 * c.b - 1);
  } else {
    const auto& bm = std::get<BumpMapMaterial>(entries_[size_t(map)].desc);
    options = bm.options;
    FloatInput height;
    height.texture = bm.height;
    // The height's gradient in (u, v) by central differences a hundredth of a texel wide (within a
    // texel a bilinear image is linear, so this is its exact gradient there, as Mitsuba's
    // eval_1_grad computes it); chain-ruled through the texture's own uv mapping.
    auto [res_x, res_y] = tex.resolution(bm.height);
    const float du = 0.01f / float(std::max(1, res_x)), dv = 0.01f / float(std::max(1, res_y));
    auto h_at = [&](float ou, float ov) {
      TextureEvalContext c = ctx;
      c.uv = ctx.uv + Vec2(ou, ov);
      return tex.eval(height, c);
    };
    float grad_u = bm.scale * (h_at(du, 0) - h_at(-du, 0)) / (2 * du);
    float grad_v = bm.scale * (h_at(0, dv) - h_at(0, -dv)) / (2 * dv);
    const Vec3 n = frame.n;
    Vec3 dpdu = hit.dpdu, dpdv = hit.dpdv;
    if (!(length_squared(dpdu) > 0)) dpdu = frame.s;
    if (!(length_squared(dpdv) > 0)) dpdv = cross(n, dpdu) * (length(dpdu) > 0 ? 1.0f : 0.0f);
    Vec3 pu = dpdu + n * (grad_u - dot(n, dpdu)), pv = dpdv + n * (grad_v - dot(n, dpdv));
    Vec3 c = cross(pu, pv);
    if (dot(c, hit.ng) < 0) c = -c;
    n_local = frame.to_local(c);
  }
  float len = length(n_local);
  if (!(len > 0) || !std::isfinite(len)) return false;
  n_local = n_local / len;
  if (options.flip_invalid_normals) {
    // Keep the tilted normal on wo's side of the surface (Mitsuba after Schuessler et al. 2017):
    // mirror it about the original normal where wo would be below it.
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z * dot(wo_local, n_local) <= 0) n_local = Vec3(-n_local.x, -n_local.y, n_local.z);
  }
  Vec3 n = normalize(frame.to_world(n_local));
  frame = Frame::from_normal_tangent(n, frame.s);
  return options.shadowing_function;
}

Bsdf MaterialTable::build(const Entry& entry, const TextureEvalContext& ctx) const {
  const MaterialDesc& desc = entry.desc;
  const TextureSet& tex = *textures_;
  auto color = [&](const ColorInput& c) { return tex.eval(c, ctx); };
  // Clamp reflectances to [0, 1]: a texture brighter than 1 would create energy.
  auto albedo = [&](const ColorInput& c) {
    RGB v = tex.eval(c, ctx);
    return RGB(std::clamp(v.r, 0.0f, 1.0f), std::clamp(v.g, 0.0f, 1.0f), std::clamp(v.b, 0.0f, 1.0f));
  };
  auto distribution = [&](const Roughness& r) { return microfacet(r, tex, ctx); };
  // The slab of a layered material at the hit (pbrt-v4 clamps g to [-1, 1]; here a little inside,
  // where Henyey-Greenstein stays finite).
  auto set_layer = [&](auto& b, const LayerSlab& layer) {
    b.thickness = std::max(0.0f, tex.eval(layer.thickness, ctx));
    b.albedo = albedo(layer.albedo);
    b.g = std::clamp(tex.eval(layer.g, ctx), -0.999f, 0.999f);
    b.max_depth = uint16_t(std::clamp(layer.max_depth, 1, 65535));
    b.samples = uint16_t(std::clamp(layer.samples, 1, 65535));
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
          return DielectricBsdf{m.ior, albedo(m.reflectance), albedo(m.transmittance), distribution(m.roughness), m.thin};
        } else if constexpr (std::is_same_v<T, ConductorMaterial>) {
          RGB eta = color(m.eta), k = color(m.k);
          if (m.reflectance) {
            eta = RGB(1.0f);
            k = conductor_k_from_reflectance(albedo(*m.reflectance));
          }
          return ConductorBsdf{eta, k, albedo(m.specular_tint), distribution(m.roughness)};
        } else if constexpr (std::is_same_v<T, CoatedDiffuseMaterial>) {
          return CoatedDiffuseBsdf{albedo(m.reflectance), albedo(m.specular), m.ior, distribution(m.roughness),
                                   m.nonlinear, entry.coat_table.get()};
        } else if constexpr (std::is_same_v<T, LayeredDiffuseMaterial>) {
          LayeredDiffuseBsdf b;
          b.top = CoatInterface{m.ior, distribution(m.roughness)};
          b.bottom = DiffuseBsdf{albedo(m.reflectance)};
          set_layer(b, m.layer);
          return b;
        } else if constexpr (std::is_same_v<T, LayeredConductorMaterial>) {
          LayeredConductorBsdf b;
          b.top = CoatInterface{m.ior, distribution(m.roughness)};
          RGB eta = color(m.eta), k = color(m.k);
          if (m.reflectance) {
            eta = RGB(1.0f);
            k = conductor_k_from_reflectance(albedo(*m.reflectance));
          }
          // The conductor lies under the coat: its index relative to the coat's (as pbrt-v4).
          b.bottom = ConductorBsdf{eta / m.ior, k / m.ior, RGB(1.0f), distribution(m.conductor_roughness)};
          set_layer(b, m.layer);
          return b;
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
        } else if constexpr (std::is_same_v<T, HairMaterial>) {
          // As pbrt-v4's HairMaterial: h = -1 + 2 v across the fibre, beta_m and beta_n at least
          // 0.01, sigma_a by precedence from sigma_a, the colour or the melanin concentrations.
          const float beta_n = std::clamp(tex.eval(m.beta_n, ctx), 0.01f, 1.0f);
          HairBsdf b(2 * ctx.uv.y - 1, std::max(tex.eval(m.eta, ctx), 1e-3f), RGB(0.0f),
                     std::clamp(tex.eval(m.beta_m, ctx), 0.01f, 1.0f), beta_n, tex.eval(m.alpha, ctx));
          if (m.sigma_a) {
            b.sigma_a = color(*m.sigma_a).map([](float x) { return std::max(x, 0.0f); });
          } else if (m.reflectance) {
            b.color = albedo(*m.reflectance);
            b.sigma_a_from_color = true;
            b.resolve_color();
          } else {
            b.sigma_a = hair_sigma_a_from_concentration(std::max(tex.eval(m.eumelanin, ctx), 0.0f),
                                                        std::max(tex.eval(m.pheomelanin, ctx), 0.0f));
          }
          return b;
        } else if constexpr (std::is_same_v<T, BlackMaterial>) {
          return BlackBsdf{};
        } else if constexpr (std::is_same_v<T, InterfaceMaterial>) {
          return BlackBsdf{};  // never shaded: the integrator passes through (and collect() makes it null)
        } else if constexpr (std::is_same_v<T, OneSidedMaterial> || std::is_same_v<T, TwoSidedMaterial> ||
                             std::is_same_v<T, MaskMaterial> || std::is_same_v<T, BlendMaterial> ||
                             std::is_same_v<T, NormalMapMaterial> || std::is_same_v<T, BumpMapMaterial>) {
          return BlackBsdf{};  // wrappers are never built: resolve() and collect() take them apart
        } else {
          static_assert(always_false<T>, "a material must say which BSDF it builds");
        }
      },
      desc);
}

}  // namespace candela
