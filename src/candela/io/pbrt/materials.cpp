// The material directives: Material, MakeNamedMaterial and NamedMaterial.
#include <algorithm>

#include "candela/io/pbrt/scene_parser.h"

namespace candela::pbrt {

using pbrt_spectra::Role;

// c * scale, with a ScaleTexture when c is a texture (declared by the directive at `where`).
ColorInput SceneParser::scaled(ColorInput c, float scale, const SourceLocation& where) {
  if (scale == 1) return c;
  if (c.is_constant()) return ColorInput(c.value * scale);
  ScaleTexture t;
  t.tex = c;
  t.scale = FloatInput(scale);
  ColorInput result;
  result.texture = add_texture(t, where);
  return result;
}

int SceneParser::add_material(MaterialDesc material, const SourceLocation& where) {
  scene_.materials.push_back(std::move(material));
  scene_.places.materials.push_back(where);
  return static_cast<int>(scene_.materials.size()) - 1;
}

MaterialDesc SceneParser::make_material(const std::string& type, const SourceLocation& type_where,
                                       ParamList& params) {
  if (type == "diffuse") {
    DiffuseMaterial m;
    m.reflectance = read_color(params, "reflectance", Role::Reflectance).value_or(ColorInput(RGB(0.5f)));
    read_shading_normals(params);
    return m;
  }
  if (type == "conductor") {
    ConductorMaterial m;  // pbrt-v4's default is copper, as ConductorMaterial's
    std::optional<ColorInput> eta = read_color(params, "eta", Role::Unbounded);
    std::optional<ColorInput> k = read_color(params, "k", Role::Unbounded);
    std::optional<ColorInput> reflectance = read_color(params, "reflectance", Role::Reflectance);
    if (reflectance && (eta || k))
      params.fail("reflectance", "cannot be given together with \"{}\" (as in pbrt-v4: the normal-incidence "
                  "reflectance replaces the optical constants)", eta ? "eta" : "k");
    if (eta) m.eta = *eta;
    if (k) m.k = *k;
    m.reflectance = reflectance;
    m.roughness = read_roughness(params);
    read_shading_normals(params);
    return m;
  }
  if (type == "dielectric") {
    DielectricMaterial m;
    m.ior = read_ior(params, "eta").value_or(1.5f);
    m.roughness = read_roughness(params);
    read_shading_normals(params);
    return m;
  }
  // A thin sheet: light goes straight through or reflects, with every internal reflection summed
  // (R' = 2R / (1 + R), as pbrt-v4's ThinDielectricBxDF and Mitsuba's thindielectric).
  if (type == "thindielectric") {
    DielectricMaterial m;
    m.ior = read_ior(params, "eta").value_or(1.5f);
    m.thin = true;
    read_shading_normals(params);
    return m;
  }
  // pbrt-v4's layered materials: a coat over a base with a slab between, random-walked
  // (materials/layered.h), with every parameter as pbrt-v4 reads it.
  if (type == "coateddiffuse") {
    LayeredDiffuseMaterial m;
    m.reflectance = read_color(params, "reflectance", Role::Reflectance).value_or(ColorInput(RGB(0.5f)));
    m.roughness = read_roughness(params);
    m.ior = read_ior(params, "eta").value_or(1.5f);
    m.layer = read_layer_slab(params);
    read_shading_normals(params);
    return m;
  }
  if (type == "coatedconductor") {
    LayeredConductorMaterial m;  // the conductor is copper by default, as in pbrt-v4
    m.roughness = read_roughness(params, "interface.");
    m.ior = read_ior(params, "interface.eta").value_or(1.5f);
    std::optional<ColorInput> eta = read_color(params, "conductor.eta", Role::Unbounded);
    std::optional<ColorInput> k = read_color(params, "conductor.k", Role::Unbounded);
    std::optional<ColorInput> reflectance = read_color(params, "reflectance", Role::Reflectance);
    if (reflectance && (eta || k))
      params.fail("reflectance", "cannot be given together with \"{}\" (as in pbrt-v4: the normal-incidence "
                  "reflectance replaces the conductor's optical constants)", eta ? "conductor.eta" : "conductor.k");
    if (eta) m.eta = *eta;
    if (k) m.k = *k;
    m.reflectance = reflectance;
    m.conductor_roughness = read_roughness(params, "conductor.");
    m.layer = read_layer_slab(params);
    read_shading_normals(params);
    return m;
  }
  if (type == "diffusetransmission") {
    DiffuseTransmissionMaterial m;
    ColorInput reflectance = read_color(params, "reflectance", Role::Reflectance).value_or(ColorInput(RGB(0.25f)));
    ColorInput transmittance = read_color(params, "transmittance", Role::Reflectance).value_or(ColorInput(RGB(0.25f)));
    float scale = params.get_float("scale", 1);
    if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
    // pbrt-v4 clamps scale * value to [0, 1].
    auto clamp01 = [](ColorInput c) {
      if (c.is_constant())
        c.value = c.value.map([](float v) { return std::clamp(v, 0.0f, 1.0f); });
      return c;
    };
    m.reflectance = clamp01(scaled(reflectance, scale, params.directive()));
    m.transmittance = clamp01(scaled(transmittance, scale, params.directive()));
    read_shading_normals(params);
    return m;
  }
  if (type == "subsurface") return make_subsurface_material(params);  // io/pbrt/media.cpp
  if (type == "hair") return make_hair_material(params);
  if (type == "interface" || type == "none" || type.empty()) return InterfaceMaterial{};
  if (type == "mix") {
    std::vector<std::string> names = params.get_strings("materials");
    if (names.size() != 2)
      params.fail("materials", "must name exactly two materials (made with MakeNamedMaterial), got {}", names.size());
    FloatInput amount = read_float_texture(params, "amount").value_or(FloatInput(0.5f));
    int chosen[2];
    for (int i = 0; i < 2; ++i) {
      if (names[i].empty() || names[i] == "none" || names[i] == "interface") {
        chosen[i] = -2;  // pbrt's "no material": an interface
        continue;
      }
      auto named = named_materials_.find(names[i]);
      if (named == named_materials_.end())
        params.fail("materials", "names \"{}\", which no MakeNamedMaterial before it defines", names[i]);
      chosen[i] = named->second.first;
    }
    // pbrt-v4 takes the first material where amount <= 0 and the second where amount >= 1.
    int pick = -1;
    if (chosen[0] == chosen[1])
      pick = 0;
    else if (amount.is_constant() && amount.value <= 0)
      pick = 0;
    else if (amount.is_constant() && amount.value >= 1)
      pick = 1;
    if (pick >= 0) {
      if (auto filled = subsurface_media_.find(chosen[pick]); filled != subsurface_media_.end())
        pending_subsurface_medium_ = filled->second;  // the mix is that subsurface material
      return chosen[pick] == -2 ? MaterialDesc(InterfaceMaterial{}) : scene_.materials.at(chosen[pick]);
    }
    for (int i = 0; i < 2; ++i)
      if (subsurface_media_.contains(chosen[i]))
        params.fail("materials", "mixes the subsurface material \"{}\" with another: candela fills a shape with a "
                    "subsurface material's medium, which cannot change from hit to hit; give the shape one material",
                    names[i]);
    // pbrt-v4 picks one of the two at each hit, the second with probability amount (clamped to
    // [0, 1]): in expectation the blend of the two with weight amount.
    BlendMaterial blend;
    blend.weight = amount;
    blend.material0 = chosen[0] == -2 ? add_material(InterfaceMaterial{}, type_where) : chosen[0];
    blend.material1 = chosen[1] == -2 ? add_material(InterfaceMaterial{}, type_where) : chosen[1];
    return blend;
  }
  reject_type(type_where, "material", type,
              {"diffuse", "conductor", "dielectric", "thindielectric", "coateddiffuse", "coatedconductor",
               "diffusetransmission", "hair", "interface", "mix", "subsurface"},
              {"measured"}, "candela has no BSDF for it");
}

// pbrt-v4's "hair" (materials/hair.h): its absorption from "sigma_a", else from the colour
// "reflectance" (older pbrt-v4: "color"), else from "eumelanin" and "pheomelanin" (one given alone
// leaves the other 0), else pbrt-v4's default, eumelanin 1.3; what the chosen one makes meaningless
// is ignored with a warning, as pbrt-v4 does. Every parameter may be a texture; constants are
// clamped as pbrt-v4 clamps them at each hit (concentrations to >= 0, beta_m and beta_n to
// [0.01, 1]).
MaterialDesc SceneParser::make_hair_material(ParamList& params) {
  HairMaterial m;
  m.sigma_a = read_color(params, "sigma_a", Role::Unbounded);
  std::optional<ColorInput> reflectance = read_color(params, "reflectance", Role::Reflectance);
  if (std::optional<ColorInput> color = read_color(params, "color", Role::Reflectance)) {
    if (reflectance) params.fail("color", "cannot be given together with \"reflectance\" (its newer name)");
    reflectance = color;
  }
  const char* reflectance_name = params.has("color") ? "color" : "reflectance";
  std::optional<FloatInput> eumelanin = read_float_texture(params, "eumelanin");
  std::optional<FloatInput> pheomelanin = read_float_texture(params, "pheomelanin");
  auto ignored = [&](const char* name, const char* because) {
    if (params.has(name))
      warn(params.where(name), "{}: \"{}\" is ignored because \"{}\" is given (as in pbrt-v4)", params.owner(),
           name, because);
  };
  if (m.sigma_a) {
    ignored(reflectance_name, "sigma_a");
    ignored("eumelanin", "sigma_a");
    ignored("pheomelanin", "sigma_a");
  } else if (reflectance) {
    m.reflectance = reflectance;
    ignored("eumelanin", reflectance_name);
    ignored("pheomelanin", reflectance_name);
  } else if (eumelanin || pheomelanin) {
    auto concentration = [](FloatInput c) {
      if (c.is_constant()) c.value = std::max(c.value, 0.0f);
      return c;
    };
    m.eumelanin = concentration(eumelanin.value_or(FloatInput(0.0f)));
    m.pheomelanin = concentration(pheomelanin.value_or(FloatInput(0.0f)));
  }
  m.eta = read_float_texture(params, "eta").value_or(FloatInput(1.55f));
  if (m.eta.is_constant() && !(m.eta.value > 0)) params.fail("eta", "must be positive, got {}", m.eta.value);
  auto roughness = [&](const char* name) {
    FloatInput b = read_float_texture(params, name).value_or(FloatInput(0.3f));
    if (b.is_constant()) b.value = std::clamp(b.value, 0.01f, 1.0f);
    return b;
  };
  m.beta_m = roughness("beta_m");
  m.beta_n = roughness("beta_n");
  m.alpha = read_float_texture(params, "alpha").value_or(FloatInput(2.0f));
  return m;
}

LayerSlab SceneParser::read_layer_slab(ParamList& params) {
  LayerSlab slab;
  slab.thickness = read_float_texture(params, "thickness").value_or(FloatInput(0.01f));
  if (slab.thickness.is_constant() && slab.thickness.value < 0)
    params.fail("thickness", "must not be negative, got {}", slab.thickness.value);
  slab.albedo = read_color(params, "albedo", Role::Reflectance).value_or(ColorInput(RGB(0.0f)));
  slab.g = read_float_texture(params, "g").value_or(FloatInput(0.0f));
  if (slab.g.is_constant()) slab.g.value = std::clamp(slab.g.value, -1.0f, 1.0f);  // as pbrt-v4 (textures: per hit)
  slab.max_depth = params.get_int("maxdepth", 10);
  slab.samples = params.get_int("nsamples", 1);
  if (slab.max_depth < 1 || slab.max_depth > 65535)
    params.fail("maxdepth", "must be in [1, 65535], got {}", slab.max_depth);
  if (slab.samples < 1 || slab.samples > 65535) params.fail("nsamples", "must be in [1, 65535], got {}", slab.samples);
  return slab;
}

// pbrt-v4's "string normalmap" (an image of tangent-space normals, 2 rgb - 1, read without colour
// decoding and repeated) and "texture displacement" (a float texture that moves the surface along its
// normal: bump mapping). Where both are given pbrt-v4 uses the normal map; so does candela.
void SceneParser::read_shading_normals(ParamList& params) {
  if (params.has("normalmap")) {
    const std::string name = params.get_string("normalmap", "");
    ImageTexture image;
    image.filename =
        resolve_path(name, params.where("normalmap"), fmt::format("{}: \"normalmap\"", params.owner())).string();
    image.encoding = ColorEncoding::Linear;
    shading_normals_.normal_map = add_texture(image, params.where("normalmap"));
  }
  shading_normals_.displacement = read_float_texture(params, "displacement");
}

int SceneParser::wrap_shading_normals(int material, const SourceLocation& where) {
  const ShadingNormals normals = std::exchange(shading_normals_, {});
  if (normals.normal_map >= 0)
    return add_material(NormalMapMaterial{.normal_map = normals.normal_map, .material = material}, where);
  // A constant displacement moves the surface without tilting it: nothing to do.
  if (normals.displacement && !normals.displacement->is_constant())
    return add_material(BumpMapMaterial{.height = normals.displacement->texture, .material = material}, where);
  return material;
}

void SceneParser::material(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the material type");
  ParamList params = read_params(d, fmt::format("Material \"{}\"", type.text), kMaterialAttributes);
  shading_normals_ = {};
  MaterialDesc desc = make_material(type.text, at(type), params);
  params.reject_unused();
  state_.material = wrap_shading_normals(add_material(std::move(desc), at(d)), at(d));
  claim_subsurface_medium(state_.material);
}

void SceneParser::make_named_material(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the material name");
  if (auto earlier = named_materials_.find(name.text); earlier != named_materials_.end())
    throw_scene_error(at(name), "MakeNamedMaterial: \"{}\" is already defined at {}", name.text,
                      earlier->second.second.to_string());
  ParamList params = read_params(d, fmt::format("MakeNamedMaterial \"{}\"", name.text), kMaterialAttributes);
  if (!params.has("type"))
    throw_scene_error(at(d), "MakeNamedMaterial \"{}\": missing the \"string type\" parameter", name.text);
  std::string type = params.get_string("type", "");
  shading_normals_ = {};
  MaterialDesc desc = make_material(type, params.where("type"), params);
  params.reject_unused();
  named_materials_[name.text] = {wrap_shading_normals(add_material(std::move(desc), at(d)), at(d)), at(name)};
  claim_subsurface_medium(named_materials_[name.text].first);
}

void SceneParser::named_material(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the material name");
  auto named = named_materials_.find(name.text);
  if (named == named_materials_.end())
    throw_scene_error(at(name),
                      "NamedMaterial: no material named \"{}\" is defined (MakeNamedMaterial must come first)",
                      name.text);
  state_.material = named->second.first;
}


}  // namespace candela::pbrt
