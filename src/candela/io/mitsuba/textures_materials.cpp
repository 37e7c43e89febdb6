// The Mitsuba converter: colours, spectra and textures; bsdfs.
#include "candela/io/mitsuba/converter.h"

#include <cmath>

#include "candela/io/named_spectra.h"
#include "candela/spectral/blackbody.h"

namespace candela::mitsuba {

namespace ms = mitsuba_spectra;

namespace {

// Mitsuba treats these names as unbounded spectra (no clamping to [0, 1]).
bool is_unbounded_name(std::string_view name) {
  return name == "eta" || name == "k" || name == "int_ior" || name == "ext_ior";
}

}  // namespace

// ---------------------------------------------------------------- colours and textures

// Mitsuba's blackbody spectrum: Planck's law in W m^-2 sr^-1 nm^-1 (physical units: the scene
// should be in metres), zero outside [lambda_min, lambda_max]. Mitsuba's RGB variants refuse it;
// here it becomes the RGB a spectral variant's film would record, through the same CIE
// integration as a tabulated spectrum (1 nm steps).
RGB Converter::blackbody(const Object& t) {
  const Property* temperature = find(t, "temperature");
  if (!temperature) throw_scene_error(t.where.loc(), "blackbody: \"temperature\" (in kelvin) is required");
  const double kelvin = get_float(t, "temperature", 0);
  if (!(kelvin > 0)) throw_scene_error(temperature->where.loc(), "blackbody: the temperature must be positive");
  const double lo = get_float(t, "lambda_min", 360), hi = get_float(t, "lambda_max", 830);
  if (!(lo < hi)) throw_scene_error(t.where.loc(), "blackbody: lambda_min must be below lambda_max");
  std::vector<double> wavelengths, values;
  for (double nm = std::floor(lo); nm <= std::ceil(hi); nm += 1) {
    const double radiance = nm < lo || nm > hi ? 0.0 : planck(nm, kelvin, kMitsubaPlanck);
    wavelengths.push_back(nm);
    values.push_back(radiance * ms::kCieYNormalization);
  }
  return ms::spectrum_list_to_srgb(wavelengths, values, false);
}

RGB Converter::spectrum_rgb(const Property& p, bool within_emitter) {
  bool bounded = !(within_emitter || is_unbounded_name(p.name));
  if (p.wavelengths.empty()) return RGB(float(p.number));
  std::vector<double> v = p.values;
  for (double& x : v) x *= ms::kCieYNormalization;
  return ms::spectrum_list_to_srgb(p.wavelengths, v, bounded);
}

std::optional<ColorInput> Converter::color_input(const Object& o, std::string_view name, bool within_emitter,
                                                 TextureLookup lookup) {
  const Property* p = find(o, name);
  if (!p) return std::nullopt;
  switch (p->kind) {
    case Property::Kind::RGB: return ColorInput(RGB(p->vector.x, p->vector.y, p->vector.z));
    case Property::Kind::Float:
    case Property::Kind::Integer: return ColorInput(RGB(float(p->number)));
    case Property::Kind::Spectrum: return ColorInput(spectrum_rgb(*p, within_emitter));
    case Property::Kind::Object:
    case Property::Kind::Ref: {
      const Object& t = deref(*p);
      if (t.tag != "texture") throw_scene_error(p->where.loc(), "{}: \"{}\" must be a texture, not a <{}>",
                                                o.describe(), name, t.tag);
      if (t.type == "blackbody") return ColorInput(blackbody(t));  // a constant: no texture lookups
      ColorInput c;
      c.texture = texture(t, lookup);
      return c;
    }
    case Property::Kind::Boolean:
    case Property::Kind::String:
    case Property::Kind::Vector:
    case Property::Kind::Transform: break;
  }
  wrong_kind(o, *p, "a colour (rgb, spectrum, float or texture)");
}

ColorInput Converter::color(const Object& o, std::string_view name, RGB fallback, bool within_emitter) {
  return color_input(o, name, within_emitter).value_or(ColorInput(fallback));
}

FloatInput Converter::float_input(const Object& o, std::string_view name, float fallback) {
  const Property* p = find(o, name);
  if (!p) return FloatInput(fallback);
  switch (p->kind) {
    case Property::Kind::Float:
    case Property::Kind::Integer: return FloatInput(float(p->number));
    case Property::Kind::Spectrum:
      if (p->wavelengths.empty()) return FloatInput(float(p->number));
      break;
    case Property::Kind::RGB:
      if (p->vector.x == p->vector.y && p->vector.y == p->vector.z) return FloatInput(p->vector.x);
      break;
    case Property::Kind::Object:
    case Property::Kind::Ref: {
      const Object& t = deref(*p);
      if (t.tag != "texture") throw_scene_error(p->where.loc(), "{}: \"{}\" must be a texture, not a <{}>",
                                                o.describe(), name, t.tag);
      FloatInput f;
      f.texture = texture(t, TextureLookup::Scalar);
      return f;
    }
    case Property::Kind::Boolean:
    case Property::Kind::String:
    case Property::Kind::Vector:
    case Property::Kind::Transform: break;
  }
  wrong_kind(o, *p, "a float or a texture");
}

int Converter::add_texture(TextureDesc t, const Where& where) {
  desc_.textures.push_back(std::move(t));
  desc_.places.textures.push_back(where.place());
  return int(desc_.textures.size()) - 1;
}

// A constant colour as a texture (for parameters that must be textures).
int Converter::constant_texture(RGB value, const Where& where) {
  ScaleTexture s;
  s.tex = ColorInput(value);
  s.scale = FloatInput(1.0f);
  return add_texture(s, where);
}

// Mitsuba's to_uv, an affine map of the texture coordinates (its 2D part; z is ignored):
// uv' = (a00 u + a01 v + a03, a10 u + a11 v + a13).
UVMapping Converter::to_uv(const Object& o) {
  const Property* p = find(o, "to_uv");
  UVMapping m;
  if (!p) return m;
  if (p->kind != Property::Kind::Transform) wrong_kind(o, *p, "a <transform>");
  const Matrix4& a = p->transform.matrix();
  m.su = float(a.m[0][0]);
  m.s_from_v = float(a.m[0][1]);
  m.du = float(a.m[0][3]);
  m.t_from_u = float(a.m[1][0]);
  m.sv = float(a.m[1][1]);
  m.dv = float(a.m[1][3]);
  return m;
}

int Converter::texture(const Object& t, TextureLookup lookup) {
  if (auto it = texture_memo_.find({&t, lookup}); it != texture_memo_.end()) return it->second;
  int index = -1;
  if (t.type == "bitmap") {
    ImageTexture img;
    img.filename = resolve_file(t, "filename").string();
    std::string filter = get_string(t, "filter_type", "bilinear");
    if (filter == "nearest") img.filter = TextureFilter::Nearest;
    else if (filter != "bilinear")
      throw_scene_error(t.where.loc(), "bitmap: filter_type \"{}\" (use bilinear or nearest)", filter);
    std::string wrap = get_string(t, "wrap_mode", "repeat");
    if (wrap == "repeat") img.wrap = TextureWrap::Repeat;
    else if (wrap == "mirror") img.wrap = TextureWrap::Mirror;
    else if (wrap == "clamp") img.wrap = TextureWrap::Clamp;
    else throw_scene_error(t.where.loc(), "bitmap: wrap_mode \"{}\" (use repeat, mirror or clamp)", wrap);
    if (get_bool(t, "raw", false)) img.encoding = ColorEncoding::Linear;
    UVMapping m = to_uv(t);
    // Mitsuba looks images up with v = 0 at the top row; candela's t = 0 is the bottom row, so
    // t' = 1 - v' (the surface's uvs are Mitsuba's).
    img.mapping = m;
    img.mapping.t_from_u = -m.t_from_u;
    img.mapping.sv = -m.sv;
    img.mapping.dv = 1 - m.dv;
    // A float parameter reads an RGB image's luminance (Mitsuba's eval_1 and eval_1_grad).
    img.luminance = lookup == TextureLookup::Scalar;
    ignore(t, "format");  // "variant" / "rgb": the channels are read as RGB either way
    ignore(t, "accel");
    index = add_texture(img, t.where);
  } else if (t.type == "checkerboard") {
    CheckerboardTexture c;
    c.tex1 = color_input(t, "color0", false, lookup).value_or(ColorInput(RGB(0.4f)));
    c.tex2 = color_input(t, "color1", false, lookup).value_or(ColorInput(RGB(0.2f)));
    // Mitsuba: color0 where (u mod 1 < 0.5) == (v mod 1 < 0.5), i.e. where floor(2u) + floor(2v) is even.
    // Its scalar lookup (eval_1: roughness, metallic, blend weights, ...) keeps a legacy convention
    // with the colours the other way round.
    if (lookup == TextureLookup::Scalar) std::swap(c.tex1, c.tex2);
    UVMapping m = to_uv(t);
    c.mapping = {2 * m.su, 2 * m.sv, 2 * m.du, 2 * m.dv, 2 * m.s_from_v, 2 * m.t_from_u};
    index = add_texture(c, t.where);
  } else if (t.type == "mesh_attribute") {
    std::string name = get_string(t, "name", "");
    MeshAttributeTexture a;
    if (name.starts_with("vertex_")) a.name = name.substr(7);
    else if (name.starts_with("face_")) {
      a.name = name.substr(5);
      a.per_face = true;
    }
    else
      throw_scene_error(t.where.loc(), "mesh_attribute: \"name\" must start with vertex_ or face_ (got \"{}\")", name);
    get_float(t, "scale", 1);  // Mitsuba's mesh_attribute has no scale; accepted when 1
    index = add_texture(a, t.where);
  } else if (t.type == "rawconstant" || t.type == "uniform" || t.type == "srgb") {
    RGB v(1.0f);
    if (std::optional<Vec3> vec = get_vector(t, "value"); vec) v = RGB(vec->x, vec->y, vec->z);
    else if (std::optional<ColorInput> c = color_input(t, t.type == "srgb" ? "color" : "value"); c) {
      if (!c->is_constant()) throw_scene_error(t.where.loc(), "{}: the value must be a constant", t.describe());
      v = c->value;
    }
    index = constant_texture(v, t.where);
  } else if (t.type == "blackbody") {
    index = constant_texture(blackbody(t), t.where);
  } else {
    unknown_type(t, "texture", t.type, {"bitmap", "checkerboard", "mesh_attribute", "rawconstant"});
  }
  check_all_used(t);
  texture_memo_[{&t, lookup}] = index;
  return index;
}

// ---------------------------------------------------------------- materials

// bumpmap's and normalmap's two switches, on by default since Mitsuba 3.7.1.
PerturbedNormalOptions Converter::perturbed_normal_options(const Object& b) {
  return {get_bool(b, "flip_invalid_normals", true), get_bool(b, "use_shadowing_function", true)};
}

int Converter::add_material(MaterialDesc m, const Where& where) {
  desc_.materials.push_back(std::move(m));
  desc_.places.materials.push_back(where.place());
  return int(desc_.materials.size()) - 1;
}

// Mitsuba's opaque BSDFs are one-sided; candela's are two-sided.
int Converter::one_sided(MaterialDesc m, bool two_sided, const Where& where) {
  int inner = add_material(std::move(m), where);
  if (two_sided) return inner;
  return add_material(OneSidedMaterial{inner}, where);
}

float Converter::ior_value(const Object& o, std::string_view name, float fallback) {
  const Property* p = find(o, name);
  if (!p) return fallback;
  if (p->kind == Property::Kind::Float || p->kind == Property::Kind::Integer) return float(p->number);
  if (p->kind == Property::Kind::String) {
    std::optional<float> v = ms::named_ior(p->text);
    if (!v) {
      std::string names;
      for (std::string_view n : ms::named_ior_names()) names += (names.empty() ? "" : ", ") + std::string(n);
      throw_scene_error(p->where.loc(), "{}: unknown {} \"{}\" (known: {})", o.describe(), name, p->text, names);
    }
    return *v;
  }
  wrong_kind(o, *p, "a number or an IOR name");
}

float Converter::relative_ior(const Object& o, float int_default, float ext_default) {
  if (const Property* eta = find(o, "eta"); eta) {
    if (eta->kind != Property::Kind::Float && eta->kind != Property::Kind::Integer) wrong_kind(o, *eta, "a float");
    return float(eta->number);
  }
  return ior_value(o, "int_ior", int_default) / ior_value(o, "ext_ior", ext_default);
}

Roughness Converter::roughness(const Object& o, float alpha_default) {
  Roughness r;
  std::string dist = get_string(o, "distribution", "beckmann");
  if (dist == "beckmann") r.distribution = MicrofacetDistribution::Beckmann;
  else if (dist == "ggx") r.distribution = MicrofacetDistribution::GGXSeparable;
  else throw_scene_error(o.where.loc(), "{}: distribution \"{}\" (use beckmann or ggx)", o.describe(), dist);
  bool has_alpha = find(o, "alpha") != nullptr;
  if (has_alpha) {
    r.u = r.v = float_input(o, "alpha", alpha_default);
    if (find(o, "alpha_u") || find(o, "alpha_v"))
      throw_scene_error(o.where.loc(), "{}: give either alpha or alpha_u/alpha_v", o.describe());
  } else {
    r.u = float_input(o, "alpha_u", alpha_default);
    r.v = float_input(o, "alpha_v", alpha_default);
  }
  r.remap = false;
  ignore(o, "sample_visible");
  return r;
}

void Converter::conductor_ior(const Object& o, ConductorMaterial& c) {
  std::string material = get_string(o, "material", "none");
  bool has_eta = find(o, "eta") != nullptr, has_k = find(o, "k") != nullptr;
  if (has_eta || has_k || material == "none") {
    if ((has_eta || has_k) && material != "none")
      throw_scene_error(o.where.loc(), "{}: give either eta/k or material, not both", o.describe());
    c.eta = color(o, "eta", RGB(0.0f));
    c.k = color(o, "k", RGB(1.0f));
    return;
  }
  std::optional<ms::Conductor> named = ms::named_conductor(material);
  if (!named) {
    std::string names;
    for (std::string_view n : ms::named_conductor_names()) names += (names.empty() ? "" : ", ") + std::string(n);
    throw_scene_error(find(o, "material")->where.loc(), "{}: conductor material \"{}\" is not among the presets "
                                                        "candela knows ({}); give eta and k",
                      o.describe(), material, names);
  }
  c.eta = ColorInput(named->eta);
  c.k = ColorInput(named->k);
}

int Converter::single_nested_bsdf(const Object& o, bool two_sided, int expected) {
  auto bsdfs = nested(o, "bsdf");
  if (int(bsdfs.size()) != expected)
    throw_scene_error(o.where.loc(), "{} needs exactly {} nested bsdf, got {}", o.describe(), expected, bsdfs.size());
  return bsdf(*bsdfs[0].second, two_sided);
}

int Converter::bsdf(const Object& b, bool two_sided) {
  auto key = std::make_pair(&b, two_sided);
  if (auto it = bsdf_memo_.find(key); it != bsdf_memo_.end()) return it->second;
  const std::string& type = b.type;
  int index = -1;
  if (type == "diffuse") {
    index = one_sided(DiffuseMaterial{color(b, "reflectance", RGB(0.5f))}, two_sided, b.where);
  } else if (type == "dielectric" || type == "roughdielectric" || type == "thindielectric") {
    DielectricMaterial d;
    d.ior = relative_ior(b, 1.5046f, 1.000277f);
    d.reflectance = color(b, "specular_reflectance", RGB(1.0f));
    d.transmittance = color(b, "specular_transmittance", RGB(1.0f));
    if (type == "roughdielectric") d.roughness = roughness(b, 0.1f);
    d.thin = type == "thindielectric";
    index = add_material(d, b.where);
  } else if (type == "conductor" || type == "roughconductor") {
    ConductorMaterial c;
    conductor_ior(b, c);
    c.specular_tint = color(b, "specular_reflectance", RGB(1.0f));
    if (type == "roughconductor") c.roughness = roughness(b, 0.1f);
    index = one_sided(c, two_sided, b.where);
  } else if (type == "plastic" || type == "roughplastic") {
    CoatedDiffuseMaterial c;
    c.reflectance = color(b, "diffuse_reflectance", RGB(0.5f));
    c.specular = color(b, "specular_reflectance", RGB(1.0f));
    c.ior = relative_ior(b, 1.49f, 1.000277f);
    c.nonlinear = get_bool(b, "nonlinear", false);
    if (type == "roughplastic") {
      c.roughness = roughness(b, 0.1f);
      if (!c.roughness.u.is_constant() || c.roughness.u.value != c.roughness.v.value)
        throw_scene_error(b.where.loc(), "roughplastic: Mitsuba's roughplastic is isotropic with a constant alpha");
      c.tabulated_coat = true;  // Mitsuba's tables of the rough coat
    }
    index = one_sided(c, two_sided, b.where);
  } else if (type == "twosided") {
    auto bsdfs = nested(b, "bsdf");
    if (bsdfs.empty() || bsdfs.size() > 2)
      throw_scene_error(b.where.loc(), "twosided needs one or two nested bsdfs, got {}", bsdfs.size());
    index = bsdf(*bsdfs[0].second, true);
    // Two BSDFs: the first for the front, the second for the back, each seen as from its front.
    if (bsdfs.size() == 2 && bsdfs[0].second != bsdfs[1].second)
      index = add_material(TwoSidedMaterial{index, bsdf(*bsdfs[1].second, true)}, b.where);
  } else if (type == "mask") {
    MaskMaterial m;
    m.opacity = float_input(b, "opacity", 0.5f);
    m.material = single_nested_bsdf(b, two_sided);
    index = add_material(m, b.where);
  } else if (type == "normalmap") {
    NormalMapMaterial n;
    const Property* p = find(b, "normalmap");
    if (!p) throw_scene_error(b.where.loc(), "normalmap: the texture \"normalmap\" is required");
    if (p->kind != Property::Kind::Object && p->kind != Property::Kind::Ref)
      wrong_kind(b, *p, "a texture");
    n.normal_map = texture(deref(*p));
    if (auto* img = std::get_if<ImageTexture>(&desc_.textures[n.normal_map]); img)
      img->encoding = ColorEncoding::Linear;  // Mitsuba reads normal maps raw
    n.material = single_nested_bsdf(b, two_sided);
    n.options = perturbed_normal_options(b);
    index = add_material(n, b.where);
  } else if (type == "bumpmap") {
    BumpMapMaterial m;
    auto textures = nested(b, "texture");
    if (textures.size() != 1) throw_scene_error(b.where.loc(), "bumpmap needs exactly one nested texture");
    m.height = texture(*textures[0].second, TextureLookup::Scalar);  // Mitsuba's eval_1_grad
    m.scale = get_float(b, "scale", 1.0f);
    m.material = single_nested_bsdf(b, two_sided);
    m.options = perturbed_normal_options(b);
    index = add_material(m, b.where);
  } else if (type == "blendbsdf") {
    BlendMaterial m;
    m.weight = float_input(b, "weight", 0.5f);
    auto bsdfs = nested(b, "bsdf");
    if (bsdfs.size() != 2) throw_scene_error(b.where.loc(), "blendbsdf needs two nested bsdfs, got {}", bsdfs.size());
    m.material0 = bsdf(*bsdfs[0].second, two_sided);
    m.material1 = bsdf(*bsdfs[1].second, two_sided);
    index = add_material(m, b.where);
  } else if (type == "null") {
    index = add_material(InterfaceMaterial{}, b.where);
  } else if (type == "principled" || type == "principledthin") {
    PrincipledMaterial p;
    p.thin = type == "principledthin";
    p.base_color = color(b, "base_color", RGB(0.5f));
    p.roughness = float_input(b, "roughness", 0.5f);
    p.anisotropic = float_input(b, "anisotropic", 0.0f);
    p.spec_trans = float_input(b, "spec_trans", 0.0f);
    p.specular_tint = float_input(b, "spec_tint", 0.0f);
    p.sheen = float_input(b, "sheen", 0.0f);
    p.sheen_tint = float_input(b, "sheen_tint", 0.0f);
    if (const Property* eta = find(b, "eta"); eta) {
      if (eta->kind != Property::Kind::Float && eta->kind != Property::Kind::Integer) wrong_kind(b, *eta, "a float");
      p.eta = float(eta->number);
      p.eta_given = true;
    }
    if (p.thin) {
      p.diff_trans = float_input(b, "diff_trans", 0.0f);
      p.flatness = float_input(b, "flatness", 0.0f);
      if (!p.eta_given) p.eta = 1.5f, p.eta_given = true;
    } else {
      p.metallic = float_input(b, "metallic", 0.0f);
      p.specular = float_input(b, "specular", 0.5f);
      p.clearcoat = float_input(b, "clearcoat", 0.0f);
      p.clearcoat_gloss = float_input(b, "clearcoat_gloss", 0.0f);
      ignore(b, "main_specular_sampling_rate");
      ignore(b, "clearcoat_sampling_rate");
      ignore(b, "diffuse_reflectance_sampling_rate");
    }
    ignore(b, "spec_trans_sampling_rate");
    ignore(b, "diffuse_transmittance_sampling_rate");
    // Mitsuba's principled scatters from both sides (its transmission lobes need the back), so
    // it is not wrapped in a OneSidedMaterial; the materials engineer implements its side rules.
    index = add_material(p, b.where);
  } else {
    unknown_type(b, "bsdf", type, {"diffuse", "dielectric", "roughdielectric", "thindielectric", "conductor",
                                   "roughconductor", "plastic", "roughplastic", "twosided", "mask", "normalmap",
                                   "bumpmap", "blendbsdf", "null", "principled", "principledthin"});
  }
  check_all_used(b);
  bsdf_memo_[key] = index;
  return index;
}

int Converter::default_material() {
  if (default_material_ < 0) default_material_ = one_sided(DiffuseMaterial{ColorInput(RGB(0.5f))}, false, Where{});
  return default_material_;
}

}  // namespace candela::mitsuba
