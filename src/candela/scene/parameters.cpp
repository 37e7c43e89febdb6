#include "candela/scene/parameters.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/base/nearest_name.h"

namespace candela {
namespace {

// Where a parameter lives in the description and what it accepts.
struct Slot {
  std::string name;
  float* number = nullptr;
  float* number_too = nullptr;  // set together with `number` (isotropic roughness: u and v)
  RGB* color = nullptr;
  Transform* transform = nullptr;
  ValueRange range = kNonNegative;  // numbers; colours: each component
  // The scene type the parameter belongs to, whose cross-field rule a new value must keep.
  const TypeSchema* schema = nullptr;
  void* object = nullptr;

  std::string describe_range() const {
    if (color) return range.bounded_above() ? fmt::format("each component within [0, {}]", range.hi) : "each component finite and >= 0";
    if (transform) return "an invertible 4x4 matrix";
    return range.inequality(name.substr(name.rfind('.') + 1));
  }
};

class Slots {
 public:
  explicit Slots(std::vector<Slot>& out) : out_(out) {}
  void number(std::string name, float& value, ValueRange range = kNonNegative) {
    out_.push_back(Slot{.name = std::move(name), .number = &value, .range = range, .schema = schema_, .object = object_});
  }
  void number(const std::string& name, FloatInput& input, ValueRange range = kNonNegative) {
    if (input.texture < 0) number(name, input.value, range);
  }
  void color(std::string name, RGB& value, ValueRange range = kNonNegative) {
    out_.push_back(Slot{.name = std::move(name), .color = &value, .range = range, .schema = schema_, .object = object_});
  }
  void color(const std::string& name, ColorInput& input, ValueRange range = kNonNegative) {
    if (input.texture < 0) color(name, input.value, range);
  }
  void transform(std::string name, Transform& value) { out_.push_back(Slot{.name = std::move(name), .transform = &value}); }
  // One "roughness" for isotropic constant roughness, else each constant axis on its own.
  void roughness(const std::string& prefix, Roughness& r) {
    if (r.u.texture < 0 && r.v.texture < 0 && r.u.value == r.v.value) {
      out_.push_back(Slot{.name = prefix + "roughness", .number = &r.u.value, .number_too = &r.v.value,
                          .schema = schema_, .object = object_});
      return;
    }
    number(prefix + "roughness_u", r.u);
    number(prefix + "roughness_v", r.v);
  }
  // The constant numbers and colours of an object with a schema (description/schema.h), under `prefix`.
  void fields(const std::string& prefix, const TypeSchema& schema, void* object) {
    schema_ = &schema;
    object_ = object;
    for (const Field& f : schema.fields) {
      const std::string name = prefix + std::string(f.key);
      switch (f.kind) {
        case FieldKind::Color: color(name, field_value<ColorInput>(f, object), f.range); break;
        case FieldKind::OptionalColor:
          if (auto& c = field_value<std::optional<ColorInput>>(f, object)) color(name, *c, f.range);
          break;
        case FieldKind::Float: number(name, field_value<FloatInput>(f, object), f.range); break;
        case FieldKind::Number: number(name, field_value<float>(f, object), f.range); break;
        case FieldKind::NumberIfGiven:
          if (field_second<bool>(f, object)) number(name, field_value<float>(f, object), f.range);
          break;
        case FieldKind::Roughness: roughness(prefix + std::string(roughness_prefix(f)), field_value<Roughness>(f, object)); break;
        case FieldKind::Rgb: color(name, field_value<RGB>(f, object), f.range); break;
        // A colour that may vary over a grid: editable where it is a constant.
        case FieldKind::ColorVolume:
          if (auto& v = field_value<VolumeDesc>(f, object); v.is_constant()) color(name, v.constant, f.range);
          break;
        case FieldKind::Transform: transform(prefix + "to_world", field_value<Transform>(f, object)); break;
        // Not edited here: switches, names, positions and directions, and references to other
        // materials and textures.
        case FieldKind::Flag:
        case FieldKind::Material:
        case FieldKind::MaterialPair:
        case FieldKind::Texture:
        case FieldKind::Point:
        case FieldKind::Direction:
        case FieldKind::Vector:
        case FieldKind::Enum:
        case FieldKind::File:
        case FieldKind::Text:
        case FieldKind::UvMapping:
        case FieldKind::Integer:
        case FieldKind::ScalarVolume:
        case FieldKind::OptionalScalarVolume: break;
      }
    }
    schema_ = nullptr;
    object_ = nullptr;
  }

 private:
  std::vector<Slot>& out_;
  const TypeSchema* schema_ = nullptr;
  void* object_ = nullptr;
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

// A material's or texture's name as its scene file gives it: a JSON key (/materials/NAME,
// /textures/NAME), an OBJ newmtl.
std::string entry_name(const std::vector<SourceLocation>& places, size_t i, std::string_view section) {
  if (i >= places.size()) return "";
  const std::string& key = places[i].key_path;
  const std::string prefix = fmt::format("/{}/", section);
  if (key.starts_with(prefix) && key.find('/', prefix.size()) == std::string::npos) return key.substr(prefix.size());
  if (key.starts_with("newmtl ")) return key.substr(7);
  return "";
}

std::vector<Slot> slots(SceneDesc& scene) {
  std::vector<Slot> out;
  Slots s(out);
  s.transform("camera.to_world", scene.camera.world_from_camera);
  if (scene.camera.projection == Projection::Perspective) s.number("camera.fov", scene.camera.fov_degrees, ValueRange{.lo = 0, .hi = 180, .lo_open = true, .hi_open = true});
  s.number("camera.lens_radius", scene.camera.lens_radius);
  s.number("camera.focus_distance", scene.camera.focus_distance, kPositive);
  std::vector<std::string> names;
  for (size_t i = 0; i < scene.materials.size(); ++i) names.push_back(entry_name(scene.places.materials, i, "materials"));
  std::vector<std::string> material_labels = labels(names);
  for (size_t i = 0; i < scene.materials.size(); ++i)
    std::visit([&](auto& m) { s.fields("materials." + material_labels[i] + ".", SchemaOf<std::decay_t<decltype(m)>>::schema, &m); },
               scene.materials[i]);
  names.clear();
  for (size_t i = 0; i < scene.textures.size(); ++i) names.push_back(entry_name(scene.places.textures, i, "textures"));
  std::vector<std::string> texture_labels = labels(names);
  for (size_t i = 0; i < scene.textures.size(); ++i)
    std::visit([&](auto& t) { s.fields("textures." + texture_labels[i] + ".", SchemaOf<std::decay_t<decltype(t)>>::schema, &t); },
               scene.textures[i]);
  for (size_t i = 0; i < scene.lights.size(); ++i)
    std::visit([&](auto& l) { s.fields(fmt::format("lights.{}.", i), SchemaOf<std::decay_t<decltype(l)>>::schema, &l); },
               scene.lights[i]);
  names.clear();
  for (const ShapeDesc& shape : scene.shapes) names.push_back(shape.name);
  std::vector<std::string> shape_labels = labels(names);
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    ShapeDesc& shape = scene.shapes[i];
    s.transform("shapes." + shape_labels[i] + ".to_world", shape.to_world);
    if (shape.emission && shape.emission->texture < 0) s.color("shapes." + shape_labels[i] + ".emission", shape.emission->radiance);
    std::visit([&](auto& g) { s.fields("shapes." + shape_labels[i] + ".", SchemaOf<std::decay_t<decltype(g)>>::schema, &g); },
               shape.geometry);
  }
  for (size_t i = 0; i < scene.instances.size(); ++i)
    s.transform(fmt::format("instances.{}.to_world", i), scene.instances[i].to_world);
  names.clear();
  for (const MediumDesc& medium : scene.media) names.push_back(medium.name);
  std::vector<std::string> medium_labels = labels(names);
  for (size_t i = 0; i < scene.media.size(); ++i)
    s.fields("media." + medium_labels[i] + ".", SchemaOf<MediumDesc>::schema, &scene.media[i]);
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
    // A likely typo, else the names that share the longest prefix with the one asked for.
    std::vector<std::string_view> names;
    for (const Slot& s : all) names.push_back(s.name);
    if (std::optional<std::string_view> near = nearest_name(name, names))
      throw UnknownParameterError(fmt::format("no scene parameter '{}'; did you mean '{}'?", name, *near));
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

// After a change: the object's cross-field rule (Phong's d + s + t <= 1) must still hold, else the
// change is undone and refused.
template <typename Undo>
void keep_schema_rule(const Slot& slot, const std::string& name, Undo undo) {
  if (!slot.schema || !slot.schema->check) return;
  if (std::optional<SchemaViolation> violation = slot.schema->check(slot.object)) {
    undo();
    throw UsageError(fmt::format("{}: {}", name, violation->message));
  }
}

}  // namespace

std::vector<SceneParameter> scene_parameters(const SceneDesc& scene) {
  std::vector<SceneParameter> out;
  for (const Slot& slot : slots(const_cast<SceneDesc&>(scene)))  // read only
    out.push_back({slot.name, value_of(slot), slot.describe_range()});
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
    if (!std::isfinite(v) || !slot->range.contains(v))
      throw UsageError(fmt::format("{}: {} is outside its range ({})", name, v, slot->describe_range()));
    const float before = *slot->number;
    *slot->number = v;
    if (slot->number_too) *slot->number_too = v;
    keep_schema_rule(*slot, name, [&] {
      *slot->number = before;
      if (slot->number_too) *slot->number_too = before;
    });
  } else if (slot->color) {
    RGB c = std::get<RGB>(value);
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(c[i]) || c[i] < 0 || !slot->range.contains(c[i]))
        throw UsageError(fmt::format("{}: ({}, {}, {}) is outside its range ({})", name, c.r, c.g, c.b, slot->describe_range()));
    const RGB before = *slot->color;
    *slot->color = c;
    keep_schema_rule(*slot, name, [&] { *slot->color = before; });
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
