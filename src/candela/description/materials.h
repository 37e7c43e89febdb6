#pragma once
// Material descriptions, one struct per material type, each with its schema (description/schema.h:
// the parameters' keys, ranges and help, declared once for every reader, writer and editor), and the
// MaterialDesc variant. Part of the format-neutral scene description (description/scene_desc.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/base/enum_names.h"
#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"
#include "candela/description/schema.h"
#include "candela/description/textures.h"

namespace candela {

// Lambertian reflector.
struct DiffuseMaterial {
  ColorInput reflectance{RGB(0.5f)};
};
template <>
struct SchemaOf<DiffuseMaterial> {
  static constexpr Field fields[] = {field<&DiffuseMaterial::reflectance>("reflectance", kAlbedo)};
  static constexpr TypeSchema schema{.name = "diffuse", .fields = fields, .help = "Lambertian reflector"};
};

// The paper's material model (Häkkinen 2002, sec. 4.6): a diffuse lobe, a normalised Phong lobe and
// ideal refraction, chosen per path vertex by Russian roulette with probabilities d, s, t
// (d + s + t <= 1; the rest absorbs). The BSDF is d*diffuse/pi + s*specular*phong + t*transmission*delta.
struct PhongMaterial {
  ColorInput diffuse{RGB(0.5f)};
  ColorInput specular{RGB(1.0f)};
  float exponent = 32;  // Phong exponent n of cos^n around the mirror direction
  ColorInput transmission{RGB(1.0f)};
  float ior = 1.5f;  // index of refraction inside / outside, for the transmitted part
  float d = 1, s = 0, t = 0;
};
inline std::optional<SchemaViolation> check_phong(const void* object) {
  const auto& p = *static_cast<const PhongMaterial*>(object);
  // The probabilities of Russian roulette's diffuse, specular and transmitted choices.
  double sum = double(p.d) + p.s + p.t;
  if (sum <= 1 + 1e-6) return std::nullopt;
  return SchemaViolation{"", fmt::format("d + s + t must be <= 1 (the rest is absorbed), got {} + {} + {} = {}", p.d,
                                         p.s, p.t, float(sum))};
}
template <>
struct SchemaOf<PhongMaterial> {
  using M = PhongMaterial;
  static constexpr Field fields[] = {
      field<&M::diffuse>("diffuse", kAlbedo, "the diffuse lobe's albedo"),
      field<&M::specular>("specular", kAlbedo, "the Phong lobe's albedo"),
      field<&M::exponent>("exponent", kNonNegative, "the Phong exponent n"),
      field<&M::transmission>("transmission", kAlbedo, "the refracted part's tint"),
      field<&M::ior>("ior", kPositive, "index of refraction inside / outside"),
      field<&M::d>("d", kUnitInterval, "probability of the diffuse lobe"),
      field<&M::s>("s", kUnitInterval, "probability of the Phong lobe"),
      field<&M::t>("t", kUnitInterval, "probability of refraction"),
  };
  static constexpr TypeSchema schema{.name = "phong", .fields = fields, .check = &check_phong,
                                     .help = "the paper's diffuse + Phong + refraction model"};
};

// Ideal specular reflector.
struct MirrorMaterial {
  ColorInput reflectance{RGB(1.0f)};
};
template <>
struct SchemaOf<MirrorMaterial> {
  static constexpr Field fields[] = {field<&MirrorMaterial::reflectance>("reflectance", kAlbedo)};
  static constexpr TypeSchema schema{.name = "mirror", .fields = fields, .help = "ideal specular reflector"};
};

// The microfacet normal distribution: Trowbridge-Reitz (GGX, the default) or Beckmann (Mitsuba's
// "beckmann"); alpha has the usual meaning for each (Beckmann: the RMS slope).
// GGX with pbrt-v4's height-correlated masking-shadowing 1 / (1 + Lambda(wo) + Lambda(wi)), or with
// Mitsuba's separable G1(wo) G1(wi) (GGXSeparable: what Mitsuba's rough BSDFs use); Beckmann (always
// separable, as Mitsuba's).
enum class MicrofacetDistribution { GGX, GGXSeparable, Beckmann };
constexpr std::string_view enum_name(MicrofacetDistribution v) {
  switch (v) {
    case MicrofacetDistribution::GGX: return "ggx";
    case MicrofacetDistribution::GGXSeparable: return "ggx_separable";
    case MicrofacetDistribution::Beckmann: return "beckmann";
  }
  return {};
}

// Microfacet roughness: the Trowbridge-Reitz (GGX) alpha along the shading frame's u and v axes.
// alpha < 1e-3 on both axes is treated as perfectly smooth (a delta BSDF), as pbrt-v4 does.
// remap = true reads u, v as pbrt's "roughness" and uses alpha = sqrt(roughness) (pbrt-v4's
// RoughnessToAlpha); false uses them as alpha directly (Mitsuba's "alpha").
struct Roughness {
  FloatInput u{0.0f}, v{0.0f};
  bool remap = false;
  MicrofacetDistribution distribution = MicrofacetDistribution::GGX;
};

// Metal: Fresnel reflection of a conductor with complex index of refraction eta + i k (per RGB
// channel), on a GGX microfacet surface. With `reflectance` set, eta and k are ignored and the
// normal-incidence reflectance is given instead (pbrt-v4's artist mode: eta = 1, k = 2 sqrt(r) / sqrt(1 - r)).
// The defaults are copper (pbrt-v4's default "metal-Cu-eta" / "metal-Cu-k", as RGB).
struct ConductorMaterial {
  ColorInput eta{RGB(0.200438f, 0.924033f, 1.102212f)};
  ColorInput k{RGB(3.912949f, 2.452848f, 2.142188f)};
  std::optional<ColorInput> reflectance;
  ColorInput specular_tint{RGB(1.0f)};  // multiplies the reflection (Mitsuba's specular_reflectance)
  Roughness roughness;
};
template <>
struct SchemaOf<ConductorMaterial> {
  using M = ConductorMaterial;
  static constexpr Field fields[] = {
      field<&M::eta>("eta", kNonNegative, "index of refraction (real part), per channel").ignored_where("reflectance"),
      field<&M::k>("k", kNonNegative, "absorption coefficient (imaginary part), per channel").ignored_where("reflectance"),
      field<&M::reflectance>("reflectance", kAlbedo, "normal-incidence reflectance instead of eta and k"),
      field<&M::specular_tint>("specular_tint", kAlbedo, "multiplies the reflection"),
      roughness_field<&M::roughness>(),
  };
  static constexpr TypeSchema schema{.name = "conductor", .fields = fields, .help = "metal"};
};

// Dielectric interface (glass, water): Fresnel-weighted reflection and refraction, smooth or GGX-rough.
// ior = n_inside / n_outside, inside being the side opposite the geometric normal.
struct DielectricMaterial {
  float ior = 1.5f;
  ColorInput reflectance{RGB(1.0f)};    // tints (Mitsuba's specular_reflectance / _transmittance); 1 = physical
  ColorInput transmittance{RGB(1.0f)};
  Roughness roughness;
  // A thin sheet (Mitsuba's "thindielectric"): light passes straight through without refraction,
  // with the Fresnel reflectance of the two interfaces and their internal reflections summed
  // (R' = R + T^2 R / (1 - R^2)); smooth only.
  bool thin = false;
};
template <>
struct SchemaOf<DielectricMaterial> {
  using M = DielectricMaterial;
  static constexpr std::string_view aliases[] = {"glass"};
  static constexpr Field fields[] = {
      field<&M::ior>("ior", kPositive, "index of refraction inside / outside"),
      field<&M::reflectance>("reflectance", kAlbedo, "tints the reflection"),
      field<&M::transmittance>("transmittance", kAlbedo, "tints the refraction"),
      roughness_field<&M::roughness>(),
      field<&M::thin>("thin", kAnyValue, "a thin sheet: no refraction"),
  };
  static constexpr TypeSchema schema{.name = "dielectric", .aliases = aliases, .fields = fields,
                                     .help = "glass, water"};
};

// Plastic / coated diffuse: a dielectric coat (smooth or GGX-rough) of index `ior` over a Lambertian
// base. Light refracted into the coat scatters diffusely and bounces between base and coat; the
// closed form for the infinite series of internal reflections (Mitsuba's plastic, after Weidlich and
// Wilkie) keeps it energy-consistent.
struct CoatedDiffuseMaterial {
  ColorInput reflectance{RGB(0.5f)};  // the diffuse base
  ColorInput specular{RGB(1.0f)};     // tints the coat's reflection (1 = physical)
  float ior = 1.5f;
  Roughness roughness;
  bool nonlinear = false;  // Mitsuba's "nonlinear": account for the colour shift of internal bounces
  // Mitsuba 3's roughplastic: the rough coat's transmittance and internal reflectance integrated
  // over its microfacets and tabulated (materials/rough_coat.h) instead of the smooth Fresnel
  // factors. Needs a constant roughness.
  bool tabulated_coat = false;
};
inline std::optional<SchemaViolation> check_coated_diffuse(const void* object) {
  const auto& c = *static_cast<const CoatedDiffuseMaterial*>(object);
  if (c.tabulated_coat && !(c.roughness.u.is_constant() && c.roughness.v.is_constant()))
    return SchemaViolation{"tabulated_coat", "a tabulated coat needs a constant roughness"};
  return std::nullopt;
}
template <>
struct SchemaOf<CoatedDiffuseMaterial> {
  using M = CoatedDiffuseMaterial;
  static constexpr std::string_view aliases[] = {"plastic"};
  static constexpr Field fields[] = {
      field<&M::reflectance>("reflectance", kAlbedo, "the diffuse base"),
      field<&M::specular>("specular", kAlbedo, "tints the coat's reflection"),
      field<&M::ior>("ior", kPositive, "the coat's index of refraction"),
      roughness_field<&M::roughness>(),
      field<&M::nonlinear>("nonlinear", kAnyValue, "the colour shift of internal bounces"),
      field<&M::tabulated_coat>("tabulated_coat", kAnyValue, "Mitsuba 3's tabulated rough coat"),
  };
  static constexpr TypeSchema schema{.name = "coated_diffuse", .aliases = aliases, .fields = fields,
                                     .check = &check_coated_diffuse, .help = "plastic: a dielectric coat over a diffuse base"};
};

// pbrt-v4's layered materials (its LayeredBxDF, materials/layered.h): a dielectric coat over an
// opaque base with a slab between them, evaluated and sampled by random walks through the layers.
// What lies between coat and base: a slab `thickness` mean free paths thick (unit extinction)
// holding a medium of single-scattering `albedo` (0: it only absorbs, exp(-thickness / |cos|) per
// crossing) and Henyey-Greenstein asymmetry `g`; each random walk follows at most `max_depth`
// scattering events, and eval() and pdf() average `samples` walks. pbrt-v4's defaults.
struct LayerSlab {
  FloatInput thickness{0.01f};
  ColorInput albedo{RGB(0.0f)};
  FloatInput g{0.0f};
  int max_depth = 10;
  int samples = 1;
};
inline constexpr ValueRange kHenyeyGreensteinG{.lo = -1, .hi = 1};
inline constexpr ValueRange kWalkCount{.lo = 1, .hi = 65535};

// pbrt-v4's "coateddiffuse": a dielectric coat (smooth or rough, index `ior`) over a Lambertian
// base, with the slab between. Costlier than coated_diffuse (Mitsuba's closed-form plastic, which
// sums the internal reflections of a coat with nothing between it and the base).
struct LayeredDiffuseMaterial {
  ColorInput reflectance{RGB(0.5f)};  // the diffuse base
  float ior = 1.5f;                   // the coat's
  Roughness roughness;                // the coat's
  LayerSlab layer;
};
template <>
struct SchemaOf<LayeredDiffuseMaterial> {
  using M = LayeredDiffuseMaterial;
  static constexpr Field fields[] = {
      field<&M::reflectance>("reflectance", kAlbedo, "the diffuse base"),
      field<&M::ior>("ior", kPositive, "the coat's index of refraction"),
      roughness_field<&M::roughness>("the coat's"),
      field<&M::layer, &LayerSlab::thickness>("thickness", kNonNegative, "of the slab, in mean free paths"),
      field<&M::layer, &LayerSlab::albedo>("albedo", kAlbedo, "the slab medium's single-scattering albedo"),
      field<&M::layer, &LayerSlab::g>("g", kHenyeyGreensteinG, "the slab medium's Henyey-Greenstein asymmetry"),
      field<&M::layer, &LayerSlab::max_depth>("max_depth", kWalkCount, "scattering events per random walk"),
      field<&M::layer, &LayerSlab::samples>("samples", kWalkCount, "random walks per estimate"),
  };
  static constexpr TypeSchema schema{.name = "layered_diffuse", .fields = fields,
                                     .help = "pbrt-v4's coateddiffuse: a coat over a diffuse base, random-walked"};
};

// pbrt-v4's "coatedconductor": a dielectric coat over a conductor, with the slab between. The
// conductor's eta and k are given relative to the outside, as for `conductor` (pbrt-v4 divides
// them by the coat's index, which is what the conductor sees); `reflectance` replaces them as
// pbrt-v4's artist mode does. Copper by default.
struct LayeredConductorMaterial {
  float ior = 1.5f;     // the coat's
  Roughness roughness;  // the coat's
  ColorInput eta{RGB(0.200438f, 0.924033f, 1.102212f)};
  ColorInput k{RGB(3.912949f, 2.452848f, 2.142188f)};
  std::optional<ColorInput> reflectance;
  Roughness conductor_roughness;
  LayerSlab layer;
};
template <>
struct SchemaOf<LayeredConductorMaterial> {
  using M = LayeredConductorMaterial;
  static constexpr std::string_view aliases[] = {"coated_conductor"};
  static constexpr Field fields[] = {
      field<&M::ior>("ior", kPositive, "the coat's index of refraction"),
      roughness_field<&M::roughness>("the coat's"),
      field<&M::eta>("eta", kNonNegative, "the conductor's index of refraction (real part), per channel")
          .ignored_where("reflectance"),
      field<&M::k>("k", kNonNegative, "the conductor's absorption coefficient, per channel").ignored_where("reflectance"),
      field<&M::reflectance>("reflectance", kAlbedo, "the conductor's normal-incidence reflectance instead of eta and k"),
      roughness_field_at<&M::conductor_roughness>("conductor_roughness", "the conductor's"),
      field<&M::layer, &LayerSlab::thickness>("thickness", kNonNegative, "of the slab, in mean free paths"),
      field<&M::layer, &LayerSlab::albedo>("albedo", kAlbedo, "the slab medium's single-scattering albedo"),
      field<&M::layer, &LayerSlab::g>("g", kHenyeyGreensteinG, "the slab medium's Henyey-Greenstein asymmetry"),
      field<&M::layer, &LayerSlab::max_depth>("max_depth", kWalkCount, "scattering events per random walk"),
      field<&M::layer, &LayerSlab::samples>("samples", kWalkCount, "random walks per estimate"),
  };
  static constexpr TypeSchema schema{.name = "layered_conductor", .aliases = aliases, .fields = fields,
                                     .help = "pbrt-v4's coatedconductor: a coat over a conductor, random-walked"};
};

// Lambertian reflection and Lambertian transmission to the other side (leaves, paper, lamp shades).
struct DiffuseTransmissionMaterial {
  ColorInput reflectance{RGB(0.25f)};
  ColorInput transmittance{RGB(0.25f)};
};
inline std::optional<SchemaViolation> check_diffuse_transmission(const void* object) {
  const auto& d = *static_cast<const DiffuseTransmissionMaterial*>(object);
  // Together they may not exceed 1 (checked for constants; textures are the scene's responsibility).
  static constexpr const char* kChannelNames[] = {"red", "green", "blue"};
  if (d.reflectance.is_constant() && d.transmittance.is_constant())
    for (int i = 0; i < 3; ++i)
      if (double(d.reflectance.value[i]) + d.transmittance.value[i] > 1 + 1e-6)
        return SchemaViolation{"", fmt::format("reflectance + transmittance must be <= 1 in each channel (more would "
                                               "create energy), got {} + {} in the {} channel",
                                               d.reflectance.value[i], d.transmittance.value[i], kChannelNames[i])};
  return std::nullopt;
}
template <>
struct SchemaOf<DiffuseTransmissionMaterial> {
  using M = DiffuseTransmissionMaterial;
  static constexpr Field fields[] = {
      field<&M::reflectance>("reflectance", kAlbedo),
      field<&M::transmittance>("transmittance", kAlbedo),
  };
  static constexpr TypeSchema schema{.name = "diffuse_transmission", .fields = fields,
                                     .check = &check_diffuse_transmission,
                                     .help = "Lambertian reflection and transmission"};
};

// Hair and fur (pbrt-v4's "hair": d'Eon et al. 2011 and Chiang et al. 2016, materials/hair.h): a
// rough dielectric fibre with an absorbing interior. The fibre runs along the hit's dp/du (a curve's
// tangent) and the hit's v across it (h = -1 + 2 v, as pbrt-v4's curves give it). Its absorption is,
// by precedence, `sigma_a` (per unit of the fibre's radius), else that of the colour `reflectance`
// (Chiang et al.'s fit, which depends on beta_n), else that of the melanin concentrations
// (pbrt-v4's default: eumelanin 1.3, brown hair). beta_m and beta_n are the longitudinal and
// azimuthal roughness (pbrt-v4 clamps them to at least 0.01), alpha the tilt of the cuticle's scales
// in degrees, eta the fibre's index of refraction.
struct HairMaterial {
  std::optional<ColorInput> sigma_a;
  std::optional<ColorInput> reflectance;
  FloatInput eumelanin{1.3f};
  FloatInput pheomelanin{0.0f};
  FloatInput eta{1.55f};
  FloatInput beta_m{0.3f};
  FloatInput beta_n{0.3f};
  FloatInput alpha{2.0f};
};
template <>
struct SchemaOf<HairMaterial> {
  using M = HairMaterial;
  static constexpr Field fields[] = {
      field<&M::sigma_a>("sigma_a", kNonNegative, "absorption inside the fibre, per unit of its radius"),
      field<&M::reflectance>("reflectance", kAlbedo, "the fibre's colour, instead of sigma_a").ignored_where("sigma_a"),
      field<&M::eumelanin>("eumelanin", kNonNegative, "concentration of the brown-black pigment")
          .ignored_where("sigma_a", "reflectance"),
      field<&M::pheomelanin>("pheomelanin", kNonNegative, "concentration of the red-yellow pigment")
          .ignored_where("sigma_a", "reflectance"),
      field<&M::eta>("eta", kPositive, "index of refraction of the fibre"),
      field<&M::beta_m>("beta_m", kUnitInterval, "longitudinal roughness"),
      field<&M::beta_n>("beta_n", kUnitInterval, "azimuthal roughness"),
      field<&M::alpha>("alpha", kAnyValue, "tilt of the cuticle's scales, in degrees"),
  };
  static constexpr TypeSchema schema{.name = "hair", .fields = fields,
                                     .help = "hair and fur: pbrt-v4's hair BSDF, on curves"};
};

// Absorbs everything: for pure emitters and light blockers.
struct BlackMaterial {};
template <>
struct SchemaOf<BlackMaterial> {
  static constexpr TypeSchema schema{.name = "black", .help = "absorbs everything"};
};

// No surface at all: rays pass straight through without counting as a bounce (pbrt-v4's
// "interface", Mitsuba's "null"). Marks the boundary of a participating medium, or hides a shape
// while keeping it as an emitter.
struct InterfaceMaterial {};
template <>
struct SchemaOf<InterfaceMaterial> {
  static constexpr std::string_view aliases[] = {"null"};
  static constexpr TypeSchema schema{.name = "interface", .aliases = aliases, .help = "no surface"};
};

// Mitsuba 3's principled BSDF (after the Disney BSDF, Burley 2015), with Mitsuba's exact definitions
// of every lobe and of how the parameters combine; `thin` selects Mitsuba's principledthin (a thin
// sheet: diffuse and specular transmission without refraction). glTF's metallic-roughness model is
// this with specular 0.5 and the other lobes off.
struct PrincipledMaterial {
  ColorInput base_color{RGB(0.5f)};
  FloatInput roughness{0.5f};
  FloatInput metallic{0.0f};
  FloatInput specular{0.5f};       // ignored where eta is given (eta_given)
  FloatInput specular_tint{0.0f};
  FloatInput anisotropic{0.0f};
  FloatInput sheen{0.0f};
  FloatInput sheen_tint{0.0f};
  FloatInput clearcoat{0.0f};
  FloatInput clearcoat_gloss{0.0f};
  FloatInput spec_trans{0.0f};
  float eta = 1.5f;
  bool eta_given = false;
  // principledthin only:
  bool thin = false;
  FloatInput diff_trans{0.0f};
  FloatInput flatness{0.0f};
};
template <>
struct SchemaOf<PrincipledMaterial> {
  using M = PrincipledMaterial;
  static constexpr ValueRange kUpToTwo{.lo = 0, .hi = 2};
  static constexpr Field fields[] = {
      field<&M::base_color>("base_color", kAlbedo),
      field<&M::roughness>("roughness", kUnitInterval),
      field<&M::metallic>("metallic", kUnitInterval),
      field<&M::specular>("specular", kUnitInterval, "ignored where eta is given"),
      field<&M::specular_tint>("specular_tint", kUnitInterval),
      field<&M::anisotropic>("anisotropic", kUnitInterval),
      field<&M::sheen>("sheen", kUnitInterval),
      field<&M::sheen_tint>("sheen_tint", kUnitInterval),
      field<&M::clearcoat>("clearcoat", kUnitInterval),
      field<&M::clearcoat_gloss>("clearcoat_gloss", kUnitInterval),
      field<&M::spec_trans>("spec_trans", kUnitInterval),
      number_if_given<&M::eta, &M::eta_given>("eta", kPositive, "index of refraction (else from specular)"),
      field<&M::thin>("thin", kAnyValue, "Mitsuba's principledthin"),
      field<&M::diff_trans>("diff_trans", kUpToTwo, "thin only: diffuse transmission"),
      field<&M::flatness>("flatness", kUnitInterval),
  };
  static constexpr TypeSchema schema{.name = "principled", .fields = fields,
                                     .help = "Mitsuba 3's principled BSDF (Disney)"};
};

// Wrappers around another material (indices into SceneDesc::materials, always smaller than the
// wrapper's own index). Mitsuba's BSDFs are one-sided unless wrapped in "twosided"; candela's are
// two-sided, so a reader of Mitsuba scenes wraps its opaque BSDFs in OneSidedMaterial.

// The material seen from the front (the side the shading normal points to); black from the back.
struct OneSidedMaterial {
  int material = -1;
};
template <>
struct SchemaOf<OneSidedMaterial> {
  static constexpr Field fields[] = {material_ref<&OneSidedMaterial::material>("material")};
  static constexpr TypeSchema schema{.name = "one_sided", .fields = fields, .help = "black from the back"};
};

// Different materials on the two sides (Mitsuba's "twosided" with two BSDFs): `front` where the
// direction the light leaves towards (the viewer) is on the side the geometric normal points to,
// `back` on the other side, each seen as from its own front. Chosen per hit, so it must be the
// outermost wrapper (no mask, blend or map around it).
struct TwoSidedMaterial {
  int front = -1, back = -1;
};
template <>
struct SchemaOf<TwoSidedMaterial> {
  static constexpr Field fields[] = {material_ref<&TwoSidedMaterial::front>("front"),
                                     material_ref<&TwoSidedMaterial::back>("back")};
  static constexpr TypeSchema schema{.name = "two_sided", .fields = fields, .help = "a material per side"};
};

// Alpha masking (Mitsuba's "mask"): with probability 1 - opacity the surface is not there and the
// ray passes straight through; otherwise `material` scatters.
struct MaskMaterial {
  FloatInput opacity{1.0f};
  int material = -1;
};
template <>
struct SchemaOf<MaskMaterial> {
  static constexpr Field fields[] = {field<&MaskMaterial::opacity>("opacity", kUnitInterval),
                                     material_ref<&MaskMaterial::material>("material")};
  static constexpr TypeSchema schema{.name = "mask", .fields = fields, .help = "alpha masking"};
};

// f = (1 - weight) f_material0 + weight f_material1 (Mitsuba's "blendbsdf").
struct BlendMaterial {
  FloatInput weight{0.5f};
  int material0 = -1, material1 = -1;
};
template <>
struct SchemaOf<BlendMaterial> {
  static constexpr Field fields[] = {
      field<&BlendMaterial::weight>("weight", kUnitInterval, "the second material's weight"),
      material_pair<&BlendMaterial::material0, &BlendMaterial::material1>("materials", "[weight 0, weight 1]"),
  };
  static constexpr TypeSchema schema{.name = "blend", .fields = fields, .help = "a mix of two materials"};
};

// What Mitsuba 3 (since 3.7.1) adds to a tilted shading normal, both off by default here (pbrt-v4
// and glTF have neither) and on in Mitsuba scenes (its defaults):
//   flip_invalid_normals  where the direction towards the previous vertex, wo, lies below the tilted
//                         normal, the normal is mirrored about the original one (Schuessler et al. 2017)
//   shadowing_function    the BSDF is scaled by a microfacet shadowing term of the sampled direction
//                         (Conty Estevez et al. 2019) that softens the terminator of a strong tilt
struct PerturbedNormalOptions {
  bool flip_invalid_normals = false;
  bool shadowing_function = false;
};

// Shading normals from a tangent-space normal map (Mitsuba's "normalmap"): the texture's RGB in
// [0, 1], read without any colour decoding, is n = 2 rgb - 1 in the frame (dp/du, dp/dv, n).
struct NormalMapMaterial {
  int normal_map = -1;  // index into SceneDesc::textures
  int material = -1;
  PerturbedNormalOptions options;
};
template <>
struct SchemaOf<NormalMapMaterial> {
  using M = NormalMapMaterial;
  using O = PerturbedNormalOptions;
  static constexpr Field fields[] = {
      texture_ref<&M::normal_map>("normal_map"),
      material_ref<&M::material>("material"),
      field<&M::options, &O::flip_invalid_normals>("flip_invalid_normals"),
      field<&M::options, &O::shadowing_function>("shadowing_function"),
  };
  static constexpr TypeSchema schema{.name = "normal_map", .fields = fields, .help = "shading normals from an image"};
};

// Shading normals from a height field (Mitsuba's "bumpmap"): the surface displaced by
// scale * height(u, v) along its normal; the height texture's finite differences in u and v tilt
// the normal.
struct BumpMapMaterial {
  int height = -1;  // index into SceneDesc::textures (its channel average is the height)
  float scale = 1;
  int material = -1;
  PerturbedNormalOptions options;
};
template <>
struct SchemaOf<BumpMapMaterial> {
  using M = BumpMapMaterial;
  using O = PerturbedNormalOptions;
  static constexpr Field fields[] = {
      texture_ref<&M::height>("height"),
      field<&M::scale>("scale", kAnyValue, "multiplies the height"),
      material_ref<&M::material>("material"),
      field<&M::options, &O::flip_invalid_normals>("flip_invalid_normals"),
      field<&M::options, &O::shadowing_function>("shadowing_function"),
  };
  static constexpr TypeSchema schema{.name = "bump_map", .fields = fields, .help = "shading normals from a height field"};
};

using MaterialDesc = std::variant<DiffuseMaterial, PhongMaterial, MirrorMaterial, DielectricMaterial, BlackMaterial,
                                  ConductorMaterial, CoatedDiffuseMaterial, DiffuseTransmissionMaterial,
                                  InterfaceMaterial, PrincipledMaterial, OneSidedMaterial, MaskMaterial,
                                  BlendMaterial, NormalMapMaterial, BumpMapMaterial, TwoSidedMaterial,
                                  LayeredDiffuseMaterial, LayeredConductorMaterial, HairMaterial>;

}  // namespace candela
