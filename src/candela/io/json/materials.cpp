#include "candela/io/json/reader.h"

namespace candela::json {

// ---- materials

// Named materials may wrap (one_sided, mask, blend, normal_map, bump_map) materials named anywhere
// in the file: each is read when first needed, after what it wraps, as named textures are.
void JsonSceneReader::read_materials(const Json& value, const std::string& pointer) {
  for (const std::string& name : collect_named(value, pointer, "material", named_materials_))
    material_by_name(name, named_materials_[name].pointer);
}

int JsonSceneReader::add_material(MaterialDesc material, SourceLocation where) {
  scene_.materials.push_back(std::move(material));
  scene_.places.materials.push_back(std::move(where));
  return int(scene_.materials.size()) - 1;
}

MaterialDesc JsonSceneReader::read_material(const Json& value, const std::string& pointer) {
  CheckedObject m(report_, value, pointer);
  using Reader = MaterialDesc (*)(JsonSceneReader&, CheckedObject&);
  using R = JsonSceneReader;
  using M = CheckedObject;
  static constexpr NamedReader<Reader> kMaterials[] = {
      {"diffuse",
       [](R& r, M& m) -> MaterialDesc {
         return DiffuseMaterial{r.color_input_or(m, "reflectance", ColorKind::Albedo, DiffuseMaterial{}.reflectance)};
       }},
      {"phong", [](R& r, M& m) -> MaterialDesc { return r.read_phong(m); }},
      {"mirror",
       [](R& r, M& m) -> MaterialDesc {
         return MirrorMaterial{r.color_input_or(m, "reflectance", ColorKind::Albedo, MirrorMaterial{}.reflectance)};
       }},
      {"conductor", [](R& r, M& m) -> MaterialDesc { return r.read_conductor(m); }},
      {"dielectric", [](R& r, M& m) -> MaterialDesc { return r.read_dielectric(m); }},
      {"glass", [](R& r, M& m) -> MaterialDesc { return r.read_dielectric(m); }},
      {"coated_diffuse", [](R& r, M& m) -> MaterialDesc { return r.read_coated_diffuse(m); }},
      {"plastic", [](R& r, M& m) -> MaterialDesc { return r.read_coated_diffuse(m); }},
      {"diffuse_transmission", [](R& r, M& m) -> MaterialDesc { return r.read_diffuse_transmission(m); }},
      {"interface", [](R&, M&) -> MaterialDesc { return InterfaceMaterial{}; }},
      {"null", [](R&, M&) -> MaterialDesc { return InterfaceMaterial{}; }},
      {"black", [](R&, M&) -> MaterialDesc { return BlackMaterial{}; }},
      {"principled", [](R& r, M& m) -> MaterialDesc { return r.read_principled(m); }},
      {"one_sided", [](R& r, M& m) -> MaterialDesc { return OneSidedMaterial{r.wrapped_material(m, "material")}; }},
      {"two_sided",
       [](R& r, M& m) -> MaterialDesc {
         return TwoSidedMaterial{r.wrapped_material(m, "front"), r.wrapped_material(m, "back")};
       }},
      {"mask",
       [](R& r, M& m) -> MaterialDesc {
         MaskMaterial mask;
         mask.opacity = r.float_input_or(m, "opacity", Bound::UnitInterval, mask.opacity);
         mask.material = r.wrapped_material(m, "material");
         return mask;
       }},
      {"blend", [](R& r, M& m) -> MaterialDesc { return r.read_blend(m); }},
      {"normal_map",
       [](R& r, M& m) -> MaterialDesc {
         NormalMapMaterial map;
         map.normal_map = r.texture_reference(m, "normal_map");
         map.material = r.wrapped_material(m, "material");
         map.options = read_perturbed_normal_options(m);
         return map;
       }},
      {"bump_map",
       [](R& r, M& m) -> MaterialDesc {
         BumpMapMaterial map;
         map.height = r.texture_reference(m, "height");
         map.scale = m.number_or("scale", map.scale);
         map.material = r.wrapped_material(m, "material");
         map.options = read_perturbed_normal_options(m);
         return map;
       }},
  };
  const NamedReader<Reader>& reader = reader_for(kMaterials, m, "material");
  MaterialDesc material = reader.read(*this, m);
  m.finish();
  return material;
}

PhongMaterial JsonSceneReader::read_phong(CheckedObject& m) {
  PhongMaterial p;
  p.diffuse = color_input_or(m, "diffuse", ColorKind::Albedo, p.diffuse);
  p.specular = color_input_or(m, "specular", ColorKind::Albedo, p.specular);
  p.exponent = m.number_or("exponent", p.exponent, Bound::NonNegative);
  p.transmission = color_input_or(m, "transmission", ColorKind::Albedo, p.transmission);
  p.ior = m.number_or("ior", p.ior, Bound::Positive);
  p.d = m.number_or("d", p.d, Bound::UnitInterval);
  p.s = m.number_or("s", p.s, Bound::UnitInterval);
  p.t = m.number_or("t", p.t, Bound::UnitInterval);
  // The probabilities of Russian roulette's diffuse, specular and transmitted choices.
  double sum = double(p.d) + p.s + p.t;
  if (sum > 1 + 1e-6)
    report_.fail(m.pointer(), "d + s + t must be <= 1 (the rest is absorbed), got {} + {} + {} = {}", p.d, p.s, p.t,
                 float(sum));
  return p;
}

// GGX alpha (Roughness::remap = false): "roughness" for both axes, or "alpha_u" and "alpha_v".
Roughness JsonSceneReader::read_roughness(CheckedObject& m) {
  Roughness roughness;
  roughness.remap = false;
  const Json* isotropic = m.find("roughness");
  const Json* alpha_u = m.find("alpha_u");
  const Json* alpha_v = m.find("alpha_v");
  if (isotropic && (alpha_u || alpha_v))
    report_.fail(m.pointer_of(alpha_u ? "alpha_u" : "alpha_v"),
                 "give either \"roughness\" or \"alpha_u\" and \"alpha_v\", not both");
  if (bool(alpha_u) != bool(alpha_v))
    report_.fail(m.pointer(), "missing required key \"{}\" (an anisotropic roughness needs alpha_u and alpha_v)",
                 alpha_u ? "alpha_v" : "alpha_u");
  if (isotropic) {
    roughness.u = roughness.v = read_float_input(*isotropic, m.pointer_of("roughness"), Bound::NonNegative);
  } else if (alpha_u) {
    roughness.u = read_float_input(*alpha_u, m.pointer_of("alpha_u"), Bound::NonNegative);
    roughness.v = read_float_input(*alpha_v, m.pointer_of("alpha_v"), Bound::NonNegative);
  }
  // pbrt-v4's remaproughness: the values are pbrt's "roughness", alpha = sqrt(roughness).
  roughness.remap = m.boolean_or("remap_roughness", false);
  if (const Json* distribution = m.find("distribution"))
    roughness.distribution = read_enum<MicrofacetDistribution>(
        report_, *distribution, m.pointer_of("distribution"), "microfacet distribution");
  return roughness;
}

// eta and k (default copper), or a named metal's, or the artist-friendly normal-incidence reflectance.
ConductorMaterial JsonSceneReader::read_conductor(CheckedObject& m) {
  ConductorMaterial c;
  bool has_ior = m.has("eta") || m.has("k");
  if (int(has_ior) + int(m.has("reflectance")) + int(m.has("metal")) > 1)
    report_.fail(m.pointer(), "a conductor takes only one of: \"eta\"/\"k\", \"reflectance\", \"metal\"");
  if (const Json* metal = m.find("metal")) {
    ComplexIor preset = read_metal(*metal, m.pointer_of("metal"));
    c.eta = preset.eta;
    c.k = preset.k;
  }
  if (const Json* eta = m.find("eta")) {
    c.eta = read_color_input(*eta, m.pointer_of("eta"), ColorKind::NonNegative);
    check_positive_color(c.eta, *eta, m.pointer_of("eta"));
  }
  c.k = color_input_or(m, "k", ColorKind::NonNegative, c.k);
  if (const Json* reflectance = m.find("reflectance"))
    c.reflectance = read_color_input(*reflectance, m.pointer_of("reflectance"), ColorKind::Albedo);
  c.specular_tint = color_input_or(m, "specular_tint", ColorKind::Albedo, c.specular_tint);
  c.roughness = read_roughness(m);
  return c;
}

ComplexIor JsonSceneReader::read_metal(const Json& value, const std::string& pointer) const {
  std::string name = read_string(report_, value, pointer);
  if (std::optional<ComplexIor> preset = named_metal(name)) return *preset;
  report_.fail(pointer, "unknown metal \"{}\"; expected one of: {}", name, fmt::join(named_metal_names(), ", "));
}

// A conductor's eta must be >= 0 in each channel (0 with k > 0 is a perfect mirror, Mitsuba's
// "none"); constants only, textures are not checked.
void JsonSceneReader::check_positive_color(const ColorInput& input, const Json& value, const std::string& pointer) const {
  if (!input.is_constant()) return;
  for (int i = 0; i < 3; ++i)
    if (!(input.value[i] >= 0))
      report_.fail(value.is_array() ? child_pointer(pointer, size_t(i)) : pointer,
                   "an index of refraction must be >= 0 in each channel, got {}", input.value[i]);
}

DielectricMaterial JsonSceneReader::read_dielectric(CheckedObject& m) {
  DielectricMaterial d;
  d.ior = m.number_or("ior", d.ior, Bound::Positive);
  d.reflectance = color_input_or(m, "reflectance", ColorKind::Albedo, d.reflectance);
  d.transmittance = color_input_or(m, "transmittance", ColorKind::Albedo, d.transmittance);
  d.roughness = read_roughness(m);
  d.thin = m.boolean_or("thin", d.thin);
  return d;
}

CoatedDiffuseMaterial JsonSceneReader::read_coated_diffuse(CheckedObject& m) {
  CoatedDiffuseMaterial c;
  c.reflectance = color_input_or(m, "reflectance", ColorKind::Albedo, c.reflectance);
  c.specular = color_input_or(m, "specular", ColorKind::Albedo, c.specular);
  c.ior = m.number_or("ior", c.ior, Bound::Positive);
  c.roughness = read_roughness(m);
  c.nonlinear = m.boolean_or("nonlinear", c.nonlinear);
  c.tabulated_coat = m.boolean_or("tabulated_coat", c.tabulated_coat);
  if (c.tabulated_coat && !(c.roughness.u.is_constant() && c.roughness.v.is_constant()))
    m.report().fail(m.pointer_of("tabulated_coat"), "a tabulated coat needs a constant roughness");
  return c;
}

DiffuseTransmissionMaterial JsonSceneReader::read_diffuse_transmission(CheckedObject& m) {
  static constexpr const char* kChannelNames[] = {"red", "green", "blue"};
  DiffuseTransmissionMaterial d;
  d.reflectance = color_input_or(m, "reflectance", ColorKind::Albedo, d.reflectance);
  d.transmittance = color_input_or(m, "transmittance", ColorKind::Albedo, d.transmittance);
  // Together they may not exceed 1 (checked for constants; textures are the scene's responsibility).
  if (d.reflectance.is_constant() && d.transmittance.is_constant())
    for (int i = 0; i < 3; ++i)
      if (double(d.reflectance.value[i]) + d.transmittance.value[i] > 1 + 1e-6)
        report_.fail(m.pointer(),
                     "reflectance + transmittance must be <= 1 in each channel (more would create energy), got "
                     "{} + {} in the {} channel",
                     d.reflectance.value[i], d.transmittance.value[i], kChannelNames[i]);
  return d;
}

int JsonSceneReader::material_by_name(const std::string& name, const std::string& pointer) {
  NamedEntry& material = find_named(named_materials_, name, pointer, "material");
  if (material.index >= 0) return material.index;
  if (material.reading) report_.fail(pointer, "material \"{}\" wraps itself (a cycle of wrapping materials)", name);
  material.reading = true;
  MaterialDesc desc = read_material(*material.value, material.pointer);
  material.reading = false;
  material.index = add_material(std::move(desc), place(material.pointer));
  return material.index;
}

// The material a wrapper wraps: a name or an inline material object, read (and added) before it.
int JsonSceneReader::wrapped_material(CheckedObject& m, std::string_view key) {
  const Json& value = m.require(key);
  std::string pointer = m.pointer_of(key);
  int index = -1;
  if (value.is_string()) index = material_by_name(value.get<std::string>(), pointer);
  else if (value.is_object()) index = add_material(read_material(value, pointer), place(pointer));
  else report_.fail(pointer, "expected a material name or a material object, got {}", describe(value));
  if (std::holds_alternative<TwoSidedMaterial>(scene_.materials[size_t(index)]))
    report_.fail(pointer, "a two_sided material cannot be wrapped (it picks its side per hit, so it must be outermost)");
  return index;
}

// A texture given by name or inline object (not a constant): normal and bump maps.
int JsonSceneReader::texture_reference(CheckedObject& m, std::string_view key) {
  const Json& value = m.require(key);
  std::string pointer = m.pointer_of(key);
  if (value.is_string()) return named_texture(value.get<std::string>(), pointer);
  if (value.is_object()) return add_texture(read_texture(value, pointer), place(pointer));
  report_.fail(pointer, "expected a texture (a name or an object), got {}", describe(value));
}

PrincipledMaterial JsonSceneReader::read_principled(CheckedObject& m) {
  PrincipledMaterial p;
  p.base_color = color_input_or(m, "base_color", ColorKind::Albedo, p.base_color);
  auto unit = [&](std::string_view key, FloatInput& input) { input = float_input_or(m, key, Bound::UnitInterval, input); };
  unit("roughness", p.roughness);
  unit("metallic", p.metallic);
  unit("specular", p.specular);
  unit("specular_tint", p.specular_tint);
  unit("anisotropic", p.anisotropic);
  unit("sheen", p.sheen);
  unit("sheen_tint", p.sheen_tint);
  unit("clearcoat", p.clearcoat);
  unit("clearcoat_gloss", p.clearcoat_gloss);
  unit("spec_trans", p.spec_trans);
  if (m.has("eta")) {
    p.eta = m.number("eta", Bound::Positive);
    p.eta_given = true;
  }
  p.thin = m.boolean_or("thin", p.thin);
  unit("diff_trans", p.diff_trans);
  unit("flatness", p.flatness);
  return p;
}

PerturbedNormalOptions JsonSceneReader::read_perturbed_normal_options(CheckedObject& m) {
  PerturbedNormalOptions o;
  o.flip_invalid_normals = m.boolean_or("flip_invalid_normals", o.flip_invalid_normals);
  o.shadowing_function = m.boolean_or("shadowing_function", o.shadowing_function);
  return o;
}

BlendMaterial JsonSceneReader::read_blend(CheckedObject& m) {
  BlendMaterial b;
  b.weight = float_input_or(m, "weight", Bound::UnitInterval, b.weight);
  const Json& list = m.require("materials");
  std::string pointer = m.pointer_of("materials");
  if (!list.is_array() || list.size() != 2)
    report_.fail(pointer, "expected two materials [weight 0, weight 1], got {}", describe(list));
  int index[2];
  for (size_t i = 0; i < 2; ++i) {
    std::string item = child_pointer(pointer, i);
    if (list[i].is_string()) index[i] = material_by_name(list[i].get<std::string>(), item);
    else if (list[i].is_object()) index[i] = add_material(read_material(list[i], item), place(item));
    else report_.fail(item, "expected a material name or a material object, got {}", describe(list[i]));
  }
  b.material0 = index[0];
  b.material1 = index[1];
  return b;
}

int JsonSceneReader::black_material() {
  if (!black_material_) black_material_ = add_material(BlackMaterial{}, SourceLocation{});  // no place in the file
  return *black_material_;
}

}  // namespace candela::json
