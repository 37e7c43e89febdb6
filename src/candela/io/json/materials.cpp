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
  MaterialDesc material = default_of_named_type<MaterialDesc>(m, "material");
  if (auto* conductor = std::get_if<ConductorMaterial>(&material)) read_conductor_preset(m, conductor->eta, conductor->k);
  if (auto* coated = std::get_if<LayeredConductorMaterial>(&material)) read_conductor_preset(m, coated->eta, coated->k);
  read_schema_fields(m, material);
  m.finish();
  return material;
}

// GGX alpha (Roughness::remap = false): "roughness" for both axes, or "alpha_u" and "alpha_v" (each
// key after `prefix`: a coated conductor's "conductor_roughness").
Roughness JsonSceneReader::read_roughness(CheckedObject& m, std::string_view prefix) {
  const std::string p(prefix);
  const std::string k_roughness = p + "roughness", k_alpha_u = p + "alpha_u", k_alpha_v = p + "alpha_v";
  Roughness roughness;
  roughness.remap = false;
  const Json* isotropic = m.find(k_roughness);
  const Json* alpha_u = m.find(k_alpha_u);
  const Json* alpha_v = m.find(k_alpha_v);
  if (isotropic && (alpha_u || alpha_v))
    report_.fail(m.pointer_of(alpha_u ? k_alpha_u : k_alpha_v), "give either \"{}\" or \"{}\" and \"{}\", not both",
                 k_roughness, k_alpha_u, k_alpha_v);
  if (bool(alpha_u) != bool(alpha_v))
    report_.fail(m.pointer(), "missing required key \"{}\" (an anisotropic roughness needs {} and {})",
                 alpha_u ? k_alpha_v : k_alpha_u, k_alpha_u, k_alpha_v);
  if (isotropic) {
    roughness.u = roughness.v = read_float_input(*isotropic, m.pointer_of(k_roughness), kNonNegative);
  } else if (alpha_u) {
    roughness.u = read_float_input(*alpha_u, m.pointer_of(k_alpha_u), kNonNegative);
    roughness.v = read_float_input(*alpha_v, m.pointer_of(k_alpha_v), kNonNegative);
  }
  // pbrt-v4's remaproughness: the values are pbrt's "roughness", alpha = sqrt(roughness).
  roughness.remap = m.boolean_or(p + "remap_roughness", false);
  if (const Json* distribution = m.find(p + "distribution"))
    roughness.distribution = read_enum<MicrofacetDistribution>(
        report_, *distribution, m.pointer_of(p + "distribution"), "microfacet distribution");
  return roughness;
}

// JSON's shorthand for a conductor (and a coated conductor's): "metal": a named metal's eta and k.
// Only one of "eta"/"k", "reflectance" and "metal" may be given.
void JsonSceneReader::read_conductor_preset(CheckedObject& m, ColorInput& eta, ColorInput& k) const {
  bool has_ior = m.has("eta") || m.has("k");
  if (int(has_ior) + int(m.has("reflectance")) + int(m.has("metal")) > 1)
    report_.fail(m.pointer(), "a conductor takes only one of: \"eta\"/\"k\", \"reflectance\", \"metal\"");
  const Json* metal = m.find("metal");
  if (!metal) return;
  std::string name = read_string(report_, *metal, m.pointer_of("metal"));
  std::optional<ComplexIor> preset = named_metal(name);
  if (!preset)
    report_.fail(m.pointer_of("metal"), "unknown metal \"{}\"; expected one of: {}", name,
                 fmt::join(named_metal_names(), ", "));
  eta = preset->eta;
  k = preset->k;
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

// Two materials, each a name or an inline material object: a blend's [weight 0, weight 1].
std::array<int, 2> JsonSceneReader::material_pair(CheckedObject& m, std::string_view key) {
  const Json& list = m.require(key);
  std::string pointer = m.pointer_of(key);
  if (!list.is_array() || list.size() != 2)
    report_.fail(pointer, "expected two materials [weight 0, weight 1], got {}", describe(list));
  std::array<int, 2> index{};
  for (size_t i = 0; i < 2; ++i) {
    std::string item = child_pointer(pointer, i);
    if (list[i].is_string()) index[i] = material_by_name(list[i].get<std::string>(), item);
    else if (list[i].is_object()) index[i] = add_material(read_material(list[i], item), place(item));
    else report_.fail(item, "expected a material name or a material object, got {}", describe(list[i]));
  }
  return index;
}

int JsonSceneReader::black_material() {
  if (!black_material_) black_material_ = add_material(BlackMaterial{}, SourceLocation{});  // no place in the file
  return *black_material_;
}

}  // namespace candela::json
