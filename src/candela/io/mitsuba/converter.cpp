// The Mitsuba converter: the scene's objects in turn, and the access to their properties.
#include "candela/io/mitsuba/converter.h"

#include <fmt/ranges.h>

#include <limits>

#include "candela/base/nearest_name.h"

namespace candela::mitsuba {

SceneDesc Converter::convert(const Object& scene) {
  desc_.settings.sampler.type = SamplerType::Independent;
  desc_.settings.spp = 4;  // Mitsuba's independent sampler default
  desc_.settings.max_depth = kUnboundedDepth;
  desc_.settings.integrator = "path";
  // Mitsuba picks the emitter of a shadow ray (and of a light path) uniformly.
  desc_.settings.light_selection = LightSelection::Uniform;
  desc_.settings.filter = gaussian_filter(0.5f);
  desc_.film.width = 768;
  desc_.film.height = 576;
  desc_.camera.fov_axis = FovAxis::Diagonal;
  desc_.camera.fov_degrees = kDefaultFovDiagonal;
  desc_.camera.near_clip = 0.01f;
  desc_.camera.world_from_camera = Transform::scale({-1, 1, 1});

  bool have_sensor = false, have_integrator = false;
  for (const Property& p : scene.props) {
    const Object* o = p.kind == Property::Kind::Object ? p.object : nullptr;
    if (p.kind == Property::Kind::Ref)
      throw_scene_error(p.where.loc(), "a <ref> directly inside <scene> has no effect; refer to \"{}\" from a "
                                       "shape or another object",
                        p.text);
    if (!o) throw_scene_error(p.where.loc(), "a {} property \"{}\" cannot occur directly inside <scene>",
                              kind_name(p.kind), p.name);
    if (o->tag == "sensor") {
      if (have_sensor) throw_scene_error(o->where.loc(), "more than one sensor; candela renders one camera");
      have_sensor = true;
      sensor(*o);
    } else if (o->tag == "integrator") {
      if (have_integrator) throw_scene_error(o->where.loc(), "more than one integrator");
      have_integrator = true;
      integrator(*o);
    } else if (o->tag == "shape") {
      if (o->type == "shapegroup") continue;  // instantiated where an instance refers to it
      shape(*o, nullptr);
    } else if (o->tag == "emitter") {
      emitter(*o);
    } else if (o->tag == "bsdf" || o->tag == "texture" || o->tag == "medium") {
      continue;  // used where referenced
    } else {
      throw_scene_error(o->where.loc(), "<{}> cannot occur directly inside <scene>", o->tag);
    }
  }
  if (!have_sensor)
    warn(scene.where, "the scene has no sensor: Mitsuba's default camera (at the origin looking along +z, 768 x "
                      "576) is used");
  return std::move(desc_);
}

// ---------------------------------------------------------------- property access

const Property* Converter::find(const Object& o, std::string_view name) {
  const Property* found = nullptr;
  for (const Property& p : o.props)
    if (p.name == name) {
      if (found) throw_scene_error(p.where.loc(), "{}: \"{}\" is given twice", o.describe(), name);
      found = &p;
    }
  o.usage.ask(name);
  return found;
}

[[noreturn]] void Converter::wrong_kind(const Object& o, const Property& p, const char* expected) {
  throw_scene_error(p.where.loc(), "{}: \"{}\" must be {}, not a {}", o.describe(), p.name, expected,
                    kind_name(p.kind));
}

float Converter::get_float(const Object& o, std::string_view name, float fallback) {
  const Property* p = find(o, name);
  if (!p) return fallback;
  if (p->kind == Property::Kind::Float || p->kind == Property::Kind::Integer) return float(p->number);
  wrong_kind(o, *p, "a float");
}

int Converter::get_int(const Object& o, std::string_view name, int fallback) {
  const Property* p = find(o, name);
  if (!p) return fallback;
  if (p->kind != Property::Kind::Integer) wrong_kind(o, *p, "an integer");
  // Mitsuba's integers are 64-bit, candela's parameters int: a value beyond int is refused, not cast
  // (which is undefined behaviour).
  if (!(p->number >= std::numeric_limits<int>::min() && p->number <= std::numeric_limits<int>::max()))
    throw_scene_error(p->where.loc(), "{}: \"{}\" is {}, beyond the integers candela takes ({} to {})", o.describe(),
                      p->name, p->number, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
  return int(p->number);
}

bool Converter::get_bool(const Object& o, std::string_view name, bool fallback) {
  const Property* p = find(o, name);
  if (!p) return fallback;
  if (p->kind == Property::Kind::Boolean) return p->boolean;
  wrong_kind(o, *p, "a boolean");
}

std::string Converter::get_string(const Object& o, std::string_view name, const std::string& fallback) {
  const Property* p = find(o, name);
  if (!p) return fallback;
  if (p->kind == Property::Kind::String) return p->text;
  wrong_kind(o, *p, "a string");
}

std::optional<Vec3> Converter::get_vector(const Object& o, std::string_view name) {
  const Property* p = find(o, name);
  if (!p) return std::nullopt;
  if (p->kind == Property::Kind::Vector) return p->vector;
  wrong_kind(o, *p, "a point or vector");
}

Transform Converter::get_transform(const Object& o, std::string_view name) {
  const Property* p = find(o, name);
  if (!p) return {};
  if (p->kind == Property::Kind::Transform) return p->transform;
  wrong_kind(o, *p, "a <transform>");
}

// Accepts a parameter that changes nothing candela can show.
void Converter::ignore(const Object& o, std::string_view name, const char* why) {
  const Property* p = find(o, name);
  if (p && why) warn(p->where, "{}: \"{}\" is ignored: {}", o.describe(), name, why);
}

void Converter::unknown_type(const Object& o, std::string_view what, std::string_view type,
                             std::initializer_list<std::string_view> supported) {
  std::vector<std::string_view> names(supported);
  throw_scene_error(o.where.loc(), "unknown {} type \"{}\"{} (supported: {})", what, type, did_you_mean(type, names),
                    fmt::join(names, ", "));
}

// Every property must have been read by the plugin.
void Converter::check_all_used(const Object& o) {
  const ParameterUsage::Parameter* unused = o.usage.first_unused();
  if (!unused) return;
  const Property& p = o.props[size_t(unused - o.usage.given().data())];
  if (p.kind == Property::Kind::Object || p.kind == Property::Kind::Ref)
    throw_scene_error(p.where.loc(), "{}: unexpected nested {}", o.describe(),
                      p.kind == Property::Kind::Ref ? fmt::format("reference to \"{}\"", p.text)
                                                    : "<" + p.object->tag + ">");
  throw_scene_error(p.where.loc(), "{}: unknown parameter \"{}\"{}", o.describe(), p.name, o.usage.did_you_mean(p.name));
}

const Object& Converter::deref(const Property& p) {
  if (p.kind == Property::Kind::Object) return *p.object;
  auto it = tree_.ids.find(p.text);
  if (it == tree_.ids.end()) throw_scene_error(p.where.loc(), "reference to an undefined id \"{}\"", p.text);
  return *it->second;
}

// The nested objects (and references) of `o` whose tag is `tag`, marked used.
std::vector<std::pair<const Property*, const Object*>> Converter::nested(const Object& o, std::string_view tag) {
  std::vector<std::pair<const Property*, const Object*>> out;
  for (size_t i = 0; i < o.props.size(); ++i) {
    const Property& p = o.props[i];
    if (p.kind != Property::Kind::Object && p.kind != Property::Kind::Ref) continue;
    const Object& target = deref(p);
    if (target.tag != tag) continue;
    o.usage.mark_used_at(i);
    out.emplace_back(&p, &target);
  }
  return out;
}

fs::path Converter::resolve_file(const Object& o, std::string_view name_param) {
  const Property* p = find(o, name_param);
  if (!p) throw_scene_error(o.where.loc(), "{}: \"{}\" is required", o.describe(), name_param);
  if (p->kind != Property::Kind::String) wrong_kind(o, *p, "a string");
  std::optional<fs::path> file = tree_.resolve(p->text);
  if (!file)
    throw_scene_error(p->where.loc(), "{}: file \"{}\" not found (searched {})", o.describe(), p->text,
                      tree_.search_path_text());
  return *file;
}

}  // namespace candela::mitsuba
