// SceneDesc -> candela JSON. Each section mirrors what json_reader.cpp reads (docs/scene-format.md);
// a key is written only where the value differs from the reader's default, except where the reader
// requires it.
#include "candela/io/json_writer.h"

#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <system_error>

#include "candela/base/error.h"
#include "candela/base/overloaded.h"
#include "candela/description/integrator_traits.h"
#include "candela/description/render_options.h"


namespace candela {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

Json vec3(const Vec3& v) { return Json::array({v.x, v.y, v.z}); }
Json rgb(const RGB& c) { return Json::array({c.r, c.g, c.b}); }

// 16 numbers row by row, as a "matrix" transform step.
Json matrix_values(const Matrix4& m) {
  Json values = Json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) values.push_back(m.m[r][c]);
  return values;
}

Json matrix(const Transform& t) { return Json::array({Json{{"matrix", matrix_values(t.matrix())}}}); }

std::string texture_name(int index) { return fmt::format("texture{:05}", index); }
std::string material_name(int index) { return fmt::format("material{:05}", index); }
std::string object_name(int index) { return fmt::format("object{:05}", index); }

Json color(const ColorInput& in) { return in.is_constant() ? rgb(in.value) : Json(texture_name(in.texture)); }
Json number(const FloatInput& in) { return in.is_constant() ? Json(in.value) : Json(texture_name(in.texture)); }
std::string absolute(const std::string& file) { return fs::absolute(file).lexically_normal().string(); }

void write_mapping(const UVMapping& m, Json& j) {
  if (m.projection != TextureProjection::Surface) {
    j["projection"] = enum_name(m.projection);
    if (!m.to_world.is_identity()) j["projection_transform"] = matrix(m.to_world);
    if (m.projection == TextureProjection::Planar) {
      j["planar_s"] = vec3(m.planar_s);
      j["planar_t"] = vec3(m.planar_t);
    }
  }
  if (!m.is_axis_aligned()) {
    j["uv_matrix"] = Json::array({Json::array({m.su, m.s_from_v, m.du}), Json::array({m.t_from_u, m.sv, m.dv})});
    return;
  }
  if (m.su != 1 || m.sv != 1) j["uv_scale"] = Json::array({m.su, m.sv});
  if (m.du != 0 || m.dv != 0) j["uv_offset"] = Json::array({m.du, m.dv});
}

void write_roughness(const Roughness& r, Json& j, std::string_view prefix) {
  const std::string p(prefix);
  if (r.remap) j[p + "remap_roughness"] = true;
  if (r.u.is_constant() && r.v.is_constant() && r.u.value == r.v.value) {
    if (r.u.value != 0) j[p + "roughness"] = r.u.value;
  } else if (r.u.texture == r.v.texture && !r.u.is_constant()) {
    j[p + "roughness"] = number(r.u);
  } else {
    j[p + "alpha_u"] = number(r.u);
    j[p + "alpha_v"] = number(r.v);
  }
  if (r.distribution != MicrofacetDistribution::GGX) j[p + "distribution"] = enum_name(r.distribution);
}

// A grid from a file is written as its file name, one made in memory (pbrt's uniformgrid, an inline
// grid) with its samples, a procedural cloud as its parameters and box.
Json volume_json(const VolumeDesc& v) {
  Json j = Json::object();
  if (v.cloud) {
    const CloudDensity& c = *v.cloud;
    j["cloud"] = Json{{"density", c.density}, {"wispiness", c.wispiness}, {"frequency", c.frequency},
                      {"min", vec3(c.box_min)}, {"max", vec3(c.box_max)}};
    // The cloud's own placement: to_world less the unit cube's mapping onto the box.
    const Transform placement = v.to_world * c.unit_cube_to_cloud().inverse();
    if (!placement.is_identity()) j["transform"] = matrix(placement);
    return j;
  }
  if (!v.filename.empty()) {
    j["filename"] = absolute(v.filename);
    if (!v.grid_name.empty()) j["grid"] = v.grid_name;
  } else {
    j["resolution"] = v.resolution;
    if (v.channels != 1) j["channels"] = v.channels;
    j["values"] = v.values ? *v.values : std::vector<float>{};
  }
  // The scene's own placement; a VDB file brings its own.
  const Transform placement = v.to_world * v.file_to_world.inverse();
  if (!placement.is_identity()) j["transform"] = matrix(placement);
  if (v.border != VolumeBorder::Clamp) j["border"] = enum_name(v.border);
  return j;
}

Json scalar_or_grid(const VolumeDesc& v) { return v.is_constant() ? Json(v.constant.r) : volume_json(v); }

// The fields of a type's schema (description/schema.h), as read_fields reads them: every field that
// holds a value (not an unset optional, an absent texture, or one that another given field makes
// meaningless), defaults too, so the file says everything and shorthands that fill in missing keys
// from others (a sky's gradient) never come into play.
void write_fields(const TypeSchema& schema, const void* object, Json& j) {
  for (const Field& f : schema.fields) {
    if (field_ignored(schema, f, object)) continue;
    switch (f.kind) {
      case FieldKind::Color: j[f.key] = color(field_value<ColorInput>(f, object)); break;
      case FieldKind::OptionalColor:
        if (const auto& c = field_value<std::optional<ColorInput>>(f, object)) j[f.key] = color(*c);
        break;
      case FieldKind::Float: j[f.key] = number(field_value<FloatInput>(f, object)); break;
      case FieldKind::Number: j[f.key] = field_value<float>(f, object); break;
      case FieldKind::NumberIfGiven:
        if (field_second<bool>(f, object)) j[f.key] = field_value<float>(f, object);
        break;
      case FieldKind::Flag: j[f.key] = field_value<bool>(f, object); break;
      case FieldKind::Roughness: write_roughness(field_value<Roughness>(f, object), j, roughness_prefix(f)); break;
      case FieldKind::Material: j[f.key] = material_name(field_value<int>(f, object)); break;
      case FieldKind::MaterialPair:
        j[f.key] = Json::array({material_name(field_value<int>(f, object)), material_name(field_second<int>(f, object))});
        break;
      case FieldKind::Texture:
        if (f.required || field_value<int>(f, object) >= 0) j[f.key] = texture_name(field_value<int>(f, object));
        break;
      case FieldKind::Rgb: j[f.key] = rgb(field_value<RGB>(f, object)); break;
      case FieldKind::Point:
      case FieldKind::Vector:
      case FieldKind::Direction: j[f.key] = vec3(field_value<Vec3>(f, object)); break;
      case FieldKind::Transform: j[f.key] = matrix(field_value<Transform>(f, object)); break;
      case FieldKind::Enum: j[f.key] = f.names->name_of(f.member(const_cast<void*>(object))); break;
      case FieldKind::File: j[f.key] = absolute(field_value<std::string>(f, object)); break;
      case FieldKind::Text: j[f.key] = field_value<std::string>(f, object); break;
      case FieldKind::Integer: j[f.key] = field_value<int>(f, object); break;
      case FieldKind::ScalarVolume: j[f.key] = scalar_or_grid(field_value<VolumeDesc>(f, object)); break;
      case FieldKind::ColorVolume: {
        const auto& v = field_value<VolumeDesc>(f, object);
        j[f.key] = v.is_constant() ? rgb(v.constant) : volume_json(v);
        break;
      }
      case FieldKind::OptionalScalarVolume:
        if (const auto& v = field_value<std::optional<VolumeDesc>>(f, object)) j[f.key] = scalar_or_grid(*v);
        break;
      case FieldKind::UvMapping: write_mapping(field_value<UVMapping>(f, object), j); break;
    }
  }
}

// A description of a type with a schema: its "type" and fields.
template <typename... Ts>
Json schema_json(const std::variant<Ts...>& desc) {
  return std::visit(
      [](const auto& d) {
        const TypeSchema& schema = SchemaOf<std::decay_t<decltype(d)>>::schema;
        Json j{{"type", schema.name}};
        write_fields(schema, &d, j);
        return j;
      },
      desc);
}

Json mesh_json(const TriangleMesh& mesh) {
  Json j{{"type", "mesh"}};
  Json positions = Json::array();
  for (const Point3& p : mesh.positions) positions.push_back(vec3(p));
  j["positions"] = std::move(positions);
  j["indices"] = mesh.indices;
  if (!mesh.normals.empty()) {
    Json normals = Json::array();
    for (const Normal3& n : mesh.normals) normals.push_back(vec3(n));
    j["normals"] = std::move(normals);
  }
  if (!mesh.uvs.empty()) {
    Json uvs = Json::array();
    for (const Vec2& uv : mesh.uvs) uvs.push_back(Json::array({uv.x, uv.y}));
    j["uvs"] = std::move(uvs);
  }
  if (!mesh.attributes.empty()) {
    Json attributes = Json::array();
    for (const TriangleMesh::Attribute& a : mesh.attributes)
      attributes.push_back(
          Json{{"name", a.name}, {"per_face", a.per_face}, {"channels", a.channels}, {"values", a.values}});
    j["attributes"] = std::move(attributes);
  }
  return j;
}

// The geometry's schema fields; a mesh's, an SDF grid's and a curve's data beside them.
Json geometry_json(const ShapeGeometry& geometry) {
  Json j = schema_json(geometry);
  if (const auto* m = std::get_if<MeshShape>(&geometry)) j.update(mesh_json(m->mesh));
  if (const auto* c = std::get_if<CurveShape>(&geometry)) {
    Json points = Json::array();
    for (const Point3& p : c->points) points.push_back(vec3(p));
    j["points"] = std::move(points);
    if (!c->normals.empty()) {
      Json normals = Json::array();
      for (const Normal3& n : c->normals) normals.push_back(vec3(n));
      j["normals"] = std::move(normals);
    }
  }
  if (const auto* g = std::get_if<SdfGridShape>(&geometry)) {
    if (!g->filename.empty()) {
      j["filename"] = absolute(g->filename);
    } else {  // made in memory: the samples inline
      j["resolution"] = g->resolution;
      j["values"] = g->values ? *g->values : std::vector<float>{};
    }
  }
  return j;
}

// The names media are written under: their own where they are unique (as every reader makes them),
// numbered otherwise.
std::vector<std::string> medium_names(const std::vector<MediumDesc>& media) {
  std::set<std::string> used{"_comment"};  // the reader skips that key
  std::vector<std::string> names;
  for (size_t i = 0; i < media.size(); ++i) {
    const std::string base = media[i].name.empty() ? fmt::format("medium{:05}", i) : media[i].name;
    std::string name = base;
    for (int k = 2; !used.insert(name).second; ++k) name = fmt::format("{} {}", base, k);
    names.push_back(std::move(name));
  }
  return names;
}

// sigma_t and albedo as the description holds them (sigma_a and sigma_s would not round-trip exactly).
Json medium_json(const MediumDesc& m) {
  Json j{{"type", m.is_homogeneous() ? "homogeneous" : "grid"}};
  write_fields(SchemaOf<MediumDesc>::schema, &m, j);
  return j;
}

Json shape_json(const ShapeDesc& shape, const std::vector<std::string>& media) {
  Json j = geometry_json(shape.geometry);
  if (shape.material >= 0) j["material"] = material_name(shape.material);
  if (shape.emission) {
    Json e{{"radiance", rgb(shape.emission->radiance)}, {"two_sided", shape.emission->two_sided}};
    if (shape.emission->texture >= 0) e["texture"] = texture_name(shape.emission->texture);
    j["emission"] = std::move(e);
  }
  if (!shape.to_world.is_identity()) j["transform"] = matrix(shape.to_world);
  if (shape.to_world_end) j["transform_end"] = matrix(*shape.to_world_end);
  if (!shape.name.empty()) j["name"] = shape.name;
  if (shape.reverse_orientation) j["reverse_orientation"] = true;
  if (shape.interior_medium >= 0) j["interior"] = media[size_t(shape.interior_medium)];
  if (shape.exterior_medium >= 0) j["exterior"] = media[size_t(shape.exterior_medium)];
  if (shape.animation_node >= 0) j["animation_node"] = shape.animation_node;
  if (shape.deformation >= 0) j["deformation"] = shape.deformation;
  return j;
}

// ---- animation (docs/animation.md): always in the long form, nodes referred to by index (names
// need not be unique)

// {"interpolation", "times", "values"}: one value per time, a cubic spline's as [in, value, out]; a
// value is a number where `numbers` (the camera's), else an array of the track's width.
Json keyframes_json(const Keyframes& k, bool numbers = false) {
  const size_t w = size_t(k.width);
  auto value = [&](size_t offset) -> Json {
    if (numbers) return k.values[offset];
    return Json(std::vector<float>(k.values.begin() + std::ptrdiff_t(offset), k.values.begin() + std::ptrdiff_t(offset + w)));
  };
  Json values = Json::array();
  for (size_t key = 0; key < k.size(); ++key) {
    if (k.interpolation == Interpolation::CubicSpline)
      values.push_back(Json::array({value(3 * w * key), value(3 * w * key + w), value(3 * w * key + 2 * w)}));
    else
      values.push_back(value(w * key));
  }
  return Json{{"interpolation", enum_name(k.interpolation)}, {"times", k.times}, {"values", std::move(values)}};
}

// A node's constant parts only where they are not the identity's; keyframed ones as tracks (whose
// first value the reader makes the constant).
Json node_json(const AnimationNode& n) {
  Json j = Json::object();
  if (!n.name.empty()) j["name"] = n.name;
  if (n.parent >= 0) j["parent"] = n.parent;
  if (n.matrix) {
    j["matrix"] = matrix_values(*n.matrix);
  } else {
    const AnimatedTrs& trs = n.trs;
    if (trs.translation_keys) j["translation"] = keyframes_json(*trs.translation_keys);
    else if (trs.translation != std::array<float, 3>{0, 0, 0}) j["translation"] = trs.translation;
    if (trs.rotation_keys) j["rotation"] = keyframes_json(*trs.rotation_keys);
    else if (trs.rotation != std::array<float, 4>{0, 0, 0, 1}) j["rotation"] = trs.rotation;
    if (trs.scale_keys) j["scale"] = keyframes_json(*trs.scale_keys);
    else if (trs.scale != std::array<float, 3>{1, 1, 1}) j["scale"] = trs.scale;
  }
  if (n.weights_keys) j["weights"] = keyframes_json(*n.weights_keys);
  return j;
}

Json vec3_list(const std::vector<Vec3>& list) {
  Json j = Json::array();
  for (const Vec3& v : list) j.push_back(vec3(v));
  return j;
}

// Per-vertex arrays: each vertex's joints and weights, each target's displacements.
Json deformation_json(const MeshDeformation& d) {
  Json j = Json::object();
  if (d.skin >= 0) {
    j["skin"] = d.skin;
    const size_t k = size_t(d.influences);
    Json joints = Json::array(), weights = Json::array();
    for (size_t v = 0; k > 0 && v < d.joints.size() / k; ++v) {
      joints.push_back(std::vector<int>(d.joints.begin() + std::ptrdiff_t(v * k), d.joints.begin() + std::ptrdiff_t(v * k + k)));
      weights.push_back(std::vector<float>(d.weights.begin() + std::ptrdiff_t(v * k), d.weights.begin() + std::ptrdiff_t(v * k + k)));
    }
    j["joints"] = std::move(joints);
    j["weights"] = std::move(weights);
  }
  if (!d.target_positions.empty()) {
    Json targets = Json::array();
    for (const std::vector<Vec3>& t : d.target_positions) targets.push_back(vec3_list(t));
    j["target_positions"] = std::move(targets);
  }
  if (!d.target_normals.empty()) {
    Json targets = Json::array();
    for (const std::vector<Vec3>& t : d.target_normals) targets.push_back(vec3_list(t));
    j["target_normals"] = std::move(targets);
  }
  if (!d.default_weights.empty()) j["default_weights"] = d.default_weights;
  if (d.weights_node >= 0) j["weights_node"] = d.weights_node;
  return j;
}

Json animation_json(const SceneAnimation& a) {
  Json j = Json::object();
  Json nodes = Json::array();
  for (const AnimationNode& n : a.nodes) nodes.push_back(node_json(n));
  j["nodes"] = std::move(nodes);
  if (!a.skins.empty()) {
    Json skins = Json::array();
    for (const Skin& s : a.skins) {
      Json skin = Json::object();
      if (!s.name.empty()) skin["name"] = s.name;
      skin["joints"] = s.joints;
      Json inverse = Json::array();
      for (const Matrix4& m : s.inverse_bind) inverse.push_back(matrix_values(m));
      skin["inverse_bind"] = std::move(inverse);
      skins.push_back(std::move(skin));
    }
    j["skins"] = std::move(skins);
  }
  if (!a.deformations.empty()) {
    Json deformations = Json::array();
    for (const MeshDeformation& d : a.deformations) deformations.push_back(deformation_json(d));
    j["deformations"] = std::move(deformations);
  }
  return j;
}

Json camera_json(const SceneDesc& scene, const std::vector<std::string>& media) {
  const CameraDesc& c = scene.camera;
  const bool spherical = c.projection == Projection::Equirectangular || c.projection == Projection::EqualArea;
  Json j{{"transform", matrix(c.world_from_camera)}};
  if (!spherical) {  // a spherical camera has no field of view (nor a lens: its lens_radius is 0)
    j["fov"] = c.fov_keys ? keyframes_json(*c.fov_keys, true) : Json(c.fov_degrees);
    j["fov_axis"] = enum_name(c.fov_axis);
  }
  if (c.projection != Projection::Perspective) j["projection"] = enum_name(c.projection);
  if (c.near_clip != 0) j["near_clip"] = c.near_clip;
  if (c.screen_window) j["screen_window"] = *c.screen_window;
  j["width"] = scene.film.width;
  j["height"] = scene.film.height;
  if (const auto& crop = scene.film.crop)
    j["crop"] = Json::array({crop->x, crop->y, crop->full_width, crop->full_height});
  if (const FilmDesc::Sensor& sensor = scene.film.sensor; !sensor.changes_nothing())
    j["sensor"] = Json{{"exposure", sensor.exposure}, {"white_balance", sensor.white_balance},
                       {"max_component", sensor.max_component}};
  if ((c.lens_radius != 0 || c.lens_radius_keys || c.focus_distance_keys) && !spherical) {
    j["lens_radius"] = c.lens_radius_keys ? keyframes_json(*c.lens_radius_keys, true) : Json(c.lens_radius);
    j["focus_distance"] = c.focus_distance_keys ? keyframes_json(*c.focus_distance_keys, true) : Json(c.focus_distance);
  }
  j["shutter"] = Json::array({c.shutter_open, c.shutter_close});
  if (c.medium >= 0) j["medium"] = media[size_t(c.medium)];
  if (c.animation_node >= 0) j["animation_node"] = c.animation_node;
  return j;
}

// One option's value as the scene file holds it (description/render_options.h).
Json render_option_json(const RenderOption& option, const RenderRequest& request) {
  return std::visit(
      [&](auto member) -> Json {
        const auto& value = request.*member;
        using T = std::remove_cvref_t<decltype(value)>;
        if constexpr (std::is_same_v<T, bool>) return value != option.scene_negated;
        else if constexpr (std::is_same_v<T, std::string>) {
          if (!option.scene_true.empty()) return value == option.scene_true;
          return value;
        } else {
          return *value;
        }
      },
      option.field);
}

// The render options with a scene key, then the keys only a scene file gives.
Json render_json(const SceneDesc& scene) {
  const RenderSettings& s = scene.settings;
  Json j = Json::object();
  // Only the selective settings the integrator reads: the reader rejects the others.
  const IntegratorTraits* integrator = find_integrator_traits(s.integrator);
  for (const RenderOption& option : render_options()) {
    if (option.scene_key.empty()) continue;
    RenderRequest request;
    option.extract(scene, request);
    if (!option.given(request)) continue;
    if (option.selective_in(request) && !(integrator && integrator->reads_setting(option.reads))) continue;
    const size_t dot = option.scene_key.find('.');
    Json& holder = dot == std::string_view::npos ? j : j[std::string(option.scene_key.substr(0, dot))];
    holder[std::string(option.scene_key.substr(dot == std::string_view::npos ? 0 : dot + 1))] =
        render_option_json(option, request);
  }
  if (!scene.film.filename.empty()) j["output"] = scene.film.filename;
  if (!scene.film.aovs.empty()) j["aovs"] = scene.film.aovs;
  if (s.hide_emitters) j["hide_emitters"] = true;
  j["transform_times"] = Json::array({scene.transform_start_time, scene.transform_end_time});
  if (s.sampler.type == SamplerType::Stratified) j["sampler"]["jitter"] = s.sampler.jitter;
  j["filter"]["radius"] = Json::array({s.filter.radius.x, s.filter.radius.y});
  if (s.filter.type == FilterType::Gaussian) j["filter"]["sigma"] = s.filter.gaussian_sigma;
  if (s.filter.type == FilterType::LanczosSinc) j["filter"]["tau"] = s.filter.sinc_tau;
  if (s.filter.type == FilterType::Mitchell) {
    j["filter"]["b"] = s.filter.mitchell_b;
    j["filter"]["c"] = s.filter.mitchell_c;
  }
  return j;
}

}  // namespace

std::string scene_to_json(const SceneDesc& scene) {
  Json root;
  if (!scene.source_file.empty()) root["_comment"] = fmt::format("converted by candela from {}", scene.source_file);
  const std::vector<std::string> media = medium_names(scene.media);
  if (!scene.media.empty()) {
    Json named = Json::object();
    for (size_t i = 0; i < scene.media.size(); ++i) named[media[i]] = medium_json(scene.media[i]);
    root["media"] = std::move(named);
  }
  root["camera"] = camera_json(scene, media);
  root["render"] = render_json(scene);
  Json textures = Json::object();
  for (size_t i = 0; i < scene.textures.size(); ++i) textures[texture_name(int(i))] = schema_json(scene.textures[i]);
  root["textures"] = std::move(textures);
  Json materials = Json::object();
  for (size_t i = 0; i < scene.materials.size(); ++i)
    materials[material_name(int(i))] = schema_json(scene.materials[i]);
  root["materials"] = std::move(materials);
  Json objects = Json::object();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    Json shapes = Json::array();
    for (const ShapeDesc& shape : scene.objects[i].shapes) shapes.push_back(shape_json(shape, media));
    objects[object_name(int(i))] = Json{{"shapes", std::move(shapes)}};
  }
  if (!scene.objects.empty()) root["objects"] = std::move(objects);
  Json shapes = Json::array();
  for (const ShapeDesc& shape : scene.shapes) shapes.push_back(shape_json(shape, media));
  for (const InstanceDesc& instance : scene.instances) {
    Json j{{"type", "instance"}, {"object", object_name(instance.object)}};
    if (!instance.to_world.is_identity()) j["transform"] = matrix(instance.to_world);
    if (instance.to_world_end) j["transform_end"] = matrix(*instance.to_world_end);
    if (instance.animation_node >= 0) j["animation_node"] = instance.animation_node;
    shapes.push_back(std::move(j));
  }
  root["shapes"] = std::move(shapes);
  Json lights = Json::array();
  for (const LightDesc& light : scene.lights) lights.push_back(schema_json(light));
  root["lights"] = std::move(lights);
  const SceneAnimation& animation = scene.animation;
  if (!animation.nodes.empty() || !animation.skins.empty() || !animation.deformations.empty())
    root["animation"] = animation_json(animation);
  // Shortest round-tripping numbers (nlohmann writes doubles so that they read back exactly).
  return root.dump(1) + "\n";
}

void write_json_scene(const SceneDesc& scene, const fs::path& file) {
  const std::string text = scene_to_json(scene);
  fs::path temporary = file;
  temporary += ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw OutputError(fmt::format("{}: cannot write: {}", file.string(), std::strerror(errno)));
    out << text;
    out.close();
    if (!out) throw OutputError(fmt::format("{}: write failed", file.string()));
  }
  std::error_code ec;
  fs::rename(temporary, file, ec);
  if (ec) {
    fs::remove(temporary, ec);
    throw OutputError(fmt::format("{}: cannot write: {}", file.string(), ec.message()));
  }
}

}  // namespace candela
