#include "candela/scene/parameters.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/base/overloaded.h"

namespace candela {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Where a parameter lives in the description and what it accepts.
struct Slot {
  std::string name;
  float* number = nullptr;
  float* number_too = nullptr;  // set together with `number` (isotropic roughness: u and v)
  RGB* color = nullptr;
  Transform* transform = nullptr;
  float lo = 0, hi = kInf;        // numbers: lo <= value <= hi, or lo < value where lo_open ...
  bool lo_open = false, hi_open = false;

  std::string range() const {
    if (color) return hi < kInf ? fmt::format("each component within [0, {}]", hi) : "each component finite and >= 0";
    if (transform) return "an invertible 4x4 matrix";
    std::string text = fmt::format("{} {} {}", lo, lo_open ? "<" : "<=", name.substr(name.rfind('.') + 1));
    if (hi < kInf) text += fmt::format(" {} {}", hi_open ? "<" : "<=", hi);
    return text;
  }
};

class Slots {
 public:
  explicit Slots(std::vector<Slot>& out) : out_(out) {}
  void number(std::string name, float& value, float lo = 0, float hi = kInf, bool lo_open = false, bool hi_open = false) {
    out_.push_back(Slot{std::move(name), &value, nullptr, nullptr, nullptr, lo, hi, lo_open, hi_open});
  }
  void number(const std::string& name, FloatInput& input, float lo = 0, float hi = kInf) {
    if (input.texture < 0) number(name, input.value, lo, hi);
  }
  void color(std::string name, RGB& value, float hi = kInf) {
    out_.push_back(Slot{std::move(name), nullptr, nullptr, &value, nullptr, 0, hi});
  }
  void color(const std::string& name, ColorInput& input) {
    if (input.texture < 0) color(name, input.value);
  }
  void transform(std::string name, Transform& value) {
    out_.push_back(Slot{std::move(name), nullptr, nullptr, nullptr, &value});
  }
  // One "roughness" for isotropic constant roughness, else each constant axis on its own.
  void roughness(const std::string& prefix, Roughness& r) {
    if (r.u.texture < 0 && r.v.texture < 0 && r.u.value == r.v.value) {
      out_.push_back(Slot{prefix + "roughness", &r.u.value, &r.v.value});
      return;
    }
    number(prefix + "roughness_u", r.u);
    number(prefix + "roughness_v", r.v);
  }

 private:
  std::vector<Slot>& out_;
};

// Names for the entries of a list: each entry's own name where it has one that no other entry
// shares, else its index.
std::vector<std::string> labels(const std::vector<std::string>& names) {
  std::map<std::string, int> uses;
  for (const std::string& n : names)
    if (!n.empty()) ++uses[n];
  std::vector<std::string> out;
  for (size_t i = 0; i < names.size(); ++i)
    out.push_back(!names[i].empty() && uses[names[i]] == 1 ? names[i] : std::to_string(i));
  return out;
}

// A material's name as its scene file gives it: a JSON key (/materials/NAME), an OBJ newmtl.
std::string material_name(const SceneDesc& scene, size_t i) {
  if (i >= scene.places.materials.size()) return "";
  const std::string& key = scene.places.materials[i].key_path;
  if (key.starts_with("/materials/") && key.find('/', 11) == std::string::npos) return key.substr(11);
  if (key.starts_with("newmtl ")) return key.substr(7);
  return "";
}

void material_slots(Slots& s, const std::string& p, MaterialDesc& material) {
  std::visit(overloaded{
                 [&](DiffuseMaterial& m) { s.color(p + "reflectance", m.reflectance); },
                 [&](PhongMaterial& m) {
                   s.color(p + "diffuse", m.diffuse);
                   s.color(p + "specular", m.specular);
                   s.number(p + "exponent", m.exponent);
                   s.color(p + "transmission", m.transmission);
                   s.number(p + "ior", m.ior, 0, kInf, true);
                 },
                 [&](MirrorMaterial& m) { s.color(p + "reflectance", m.reflectance); },
                 [&](ConductorMaterial& m) {
                   s.color(p + "eta", m.eta);
                   s.color(p + "k", m.k);
                   if (m.reflectance) s.color(p + "reflectance", *m.reflectance);
                   s.color(p + "specular_tint", m.specular_tint);
                   s.roughness(p, m.roughness);
                 },
                 [&](DielectricMaterial& m) {
                   s.number(p + "ior", m.ior, 0, kInf, true);
                   s.color(p + "reflectance", m.reflectance);
                   s.color(p + "transmittance", m.transmittance);
                   s.roughness(p, m.roughness);
                 },
                 [&](CoatedDiffuseMaterial& m) {
                   s.color(p + "reflectance", m.reflectance);
                   s.color(p + "specular", m.specular);
                   s.number(p + "ior", m.ior, 0, kInf, true);
                   s.roughness(p, m.roughness);
                 },
                 [&](DiffuseTransmissionMaterial& m) {
                   s.color(p + "reflectance", m.reflectance);
                   s.color(p + "transmittance", m.transmittance);
                 },
                 [&](PrincipledMaterial& m) {
                   s.color(p + "base_color", m.base_color);
                   s.number(p + "roughness", m.roughness, 0, 1);
                   s.number(p + "metallic", m.metallic, 0, 1);
                   s.number(p + "specular", m.specular, 0, kInf);
                   s.number(p + "specular_tint", m.specular_tint, 0, 1);
                   s.number(p + "anisotropic", m.anisotropic, 0, 1);
                   s.number(p + "sheen", m.sheen, 0, kInf);
                   s.number(p + "sheen_tint", m.sheen_tint, 0, 1);
                   s.number(p + "clearcoat", m.clearcoat, 0, kInf);
                   s.number(p + "clearcoat_gloss", m.clearcoat_gloss, 0, 1);
                   s.number(p + "spec_trans", m.spec_trans, 0, 1);
                   s.number(p + "diff_trans", m.diff_trans, 0, 2);
                   s.number(p + "flatness", m.flatness, 0, 1);
                 },
                 [&](MaskMaterial& m) { s.number(p + "opacity", m.opacity, 0, 1); },
                 [&](BlendMaterial& m) { s.number(p + "weight", m.weight, 0, 1); },
                 // Nothing constant of their own (the materials they wrap have their own entries).
                 [](BlackMaterial&) {}, [](InterfaceMaterial&) {}, [](OneSidedMaterial&) {},
                 [](TwoSidedMaterial&) {}, [](NormalMapMaterial&) {}, [](BumpMapMaterial&) {},
             },
             material);
}

void light_slots(Slots& s, const std::string& p, LightDesc& light) {
  std::visit(overloaded{
                 [&](PointLight& l) { s.color(p + "intensity", l.intensity); },
                 [&](SpotLight& l) { s.color(p + "intensity", l.intensity); },
                 [&](DistantLight& l) { s.color(p + "radiance", l.radiance); },
                 [&](SkyLight& l) {
                   s.color(p + "zenith", l.zenith);
                   s.color(p + "horizon", l.horizon);
                   s.color(p + "ground", l.ground);
                 },
                 [&](EnvironmentMap& l) {
                   s.color(p + "scale", l.scale);
                   s.transform(p + "to_world", l.to_world);
                 },
                 [&](ProjectorLight& l) {
                   s.color(p + "scale", l.scale);
                   s.transform(p + "to_world", l.to_world);
                 },
             },
             light);
}

std::vector<Slot> slots(SceneDesc& scene) {
  std::vector<Slot> out;
  Slots s(out);
  s.transform("camera.to_world", scene.camera.world_from_camera);
  if (scene.camera.projection == Projection::Perspective) s.number("camera.fov", scene.camera.fov_degrees, 0, 180, true, true);
  s.number("camera.lens_radius", scene.camera.lens_radius);
  s.number("camera.focus_distance", scene.camera.focus_distance, 0, kInf, true);
  std::vector<std::string> names;
  for (size_t i = 0; i < scene.materials.size(); ++i) names.push_back(material_name(scene, i));
  std::vector<std::string> material_labels = labels(names);
  for (size_t i = 0; i < scene.materials.size(); ++i)
    material_slots(s, "materials." + material_labels[i] + ".", scene.materials[i]);
  for (size_t i = 0; i < scene.lights.size(); ++i) light_slots(s, fmt::format("lights.{}.", i), scene.lights[i]);
  names.clear();
  for (const ShapeDesc& shape : scene.shapes) names.push_back(shape.name);
  std::vector<std::string> shape_labels = labels(names);
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    ShapeDesc& shape = scene.shapes[i];
    s.transform("shapes." + shape_labels[i] + ".to_world", shape.to_world);
    if (shape.emission && shape.emission->texture < 0) s.color("shapes." + shape_labels[i] + ".emission", shape.emission->radiance);
  }
  for (size_t i = 0; i < scene.instances.size(); ++i)
    s.transform(fmt::format("instances.{}.to_world", i), scene.instances[i].to_world);
  names.clear();
  for (const MediumDesc& medium : scene.media) names.push_back(medium.name);
  std::vector<std::string> medium_labels = labels(names);
  for (size_t i = 0; i < scene.media.size(); ++i) {
    MediumDesc& m = scene.media[i];
    const std::string p = "media." + medium_labels[i] + ".";
    s.color(p + "sigma_t", m.sigma_t);
    if (m.albedo.is_constant()) s.color(p + "albedo", m.albedo.constant, 1);
    s.number(p + "scale", m.scale);
    s.color(p + "emission", m.emission);
    s.number(p + "g", m.g, -1, 1, true, true);
  }
  return out;
}

ParameterValue value_of(const Slot& slot) {
  if (slot.number) return *slot.number;
  if (slot.color) return *slot.color;
  return slot.transform->matrix();
}

const char* kind_name(const ParameterValue& v) {
  return std::holds_alternative<float>(v) ? "a number" : std::holds_alternative<RGB>(v) ? "a colour" : "a 4x4 matrix";
}

// The slot named `name` among `all`; an unknown name throws, naming the nearest ones.
const Slot& find_slot(const std::vector<Slot>& all, const std::string& name) {
  const Slot* slot = nullptr;
  for (const Slot& s : all)
    if (s.name == name) slot = &s;
  if (!slot) {
    // The names that share the longest prefix with the one asked for, to point at a typo.
    std::string near;
    size_t best = 0;
    for (const Slot& s : all) {
      size_t common = 0;
      while (common < s.name.size() && common < name.size() && s.name[common] == name[common]) ++common;
      if (common > best) best = common, near.clear();
      if (common == best && best > 0 && near.size() < 200) near += (near.empty() ? "" : ", ") + s.name;
    }
    throw UnknownParameterError(fmt::format("no scene parameter '{}'{}", name, near.empty() ? "" : "; did you mean one of: " + near));
  }
  return *slot;
}

}  // namespace

std::vector<SceneParameter> scene_parameters(const SceneDesc& scene) {
  std::vector<SceneParameter> out;
  for (const Slot& slot : slots(const_cast<SceneDesc&>(scene)))  // read only
    out.push_back({slot.name, value_of(slot), slot.range()});
  return out;
}

ParameterValue scene_parameter(const SceneDesc& scene, const std::string& name) {
  std::vector<Slot> all = slots(const_cast<SceneDesc&>(scene));  // read only
  return value_of(find_slot(all, name));
}

void set_scene_parameter(SceneDesc& scene, const std::string& name, const ParameterValue& value) {
  std::vector<Slot> all = slots(scene);
  const Slot* slot = &find_slot(all, name);
  const ParameterValue current = value_of(*slot);
  if (value.index() != current.index())
    throw UsageError(fmt::format("{}: expected {}, got {}", name, kind_name(current), kind_name(value)));
  if (slot->number) {
    float v = std::get<float>(value);
    bool below = slot->lo_open ? !(v > slot->lo) : !(v >= slot->lo);
    bool above = slot->hi_open ? !(v < slot->hi) : !(v <= slot->hi);
    if (!std::isfinite(v) || below || above)
      throw UsageError(fmt::format("{}: {} is outside its range ({})", name, v, slot->range()));
    *slot->number = v;
    if (slot->number_too) *slot->number_too = v;
  } else if (slot->color) {
    RGB c = std::get<RGB>(value);
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(c[i]) || c[i] < 0 || c[i] > slot->hi)
        throw UsageError(fmt::format("{}: ({}, {}, {}) is outside its range ({})", name, c.r, c.g, c.b, slot->range()));
    *slot->color = c;
  } else {
    const Matrix4& m = std::get<Matrix4>(value);
    for (const auto& row : m.m)
      for (double x : row)
        if (!std::isfinite(x)) throw UsageError(fmt::format("{}: the matrix has a value that is not finite", name));
    std::optional<Transform> t = Transform::from_matrix(m);
    if (!t) throw UsageError(fmt::format("{}: the matrix is singular (it has no inverse)", name));
    *slot->transform = *t;
  }
}

}  // namespace candela
