#include "candela/io/json/reader.h"

namespace candela::json {

// ---- lights

void JsonSceneReader::read_lights(const Json& value, const std::string& pointer) {
  check_is_array(report_, value, pointer, "lights");
  for (size_t i = 0; i < value.size(); ++i) read_light(value[i], child_pointer(pointer, i));
}

void JsonSceneReader::read_light(const Json& value, const std::string& pointer) {
  CheckedObject light(report_, value, pointer);
  // Each adds a light to SceneDesc::lights, or (sphere, rectangle) an emitting shape to its shapes.
  using Reader = void (*)(JsonSceneReader&, CheckedObject&);
  using R = JsonSceneReader;
  using L = CheckedObject;
  static constexpr NamedReader<Reader> kLights[] = {
      {"point",
       [](R& r, L& light) {
         r.scene_.lights.push_back(PointLight{light.vec3("position"), light.rgb("intensity", ColorKind::Emission)});
       }},
      {"spot", [](R& r, L& light) { r.scene_.lights.push_back(r.read_spot(light)); }},
      {"distant",
       [](R& r, L& light) {
         r.scene_.lights.push_back(
             DistantLight{normalize(light.direction("direction")), light.rgb("radiance", ColorKind::Emission)});
       }},
      {"sky", [](R& r, L& light) { r.scene_.lights.push_back(r.read_sky(light)); }},
      {"environment", [](R& r, L& light) { r.scene_.lights.push_back(r.read_environment(light)); }},
      {"sphere", [](R& r, L& light) { r.scene_.shapes.push_back(r.read_shape_light(light, read_sphere(light))); }},
      {"rectangle",
       [](R& r, L& light) { r.scene_.shapes.push_back(r.read_shape_light(light, r.read_rectangle(light))); }},
      {"projector", [](R& r, L& light) { r.scene_.lights.push_back(r.read_projector(light)); }},
  };
  const NamedReader<Reader>& reader = reader_for(kLights, light, "light");
  const size_t light_count = scene_.lights.size();
  reader.read(*this, light);
  if (scene_.lights.size() > light_count) scene_.places.lights.push_back(place(pointer));
  light.finish();
}

// Sphere and rectangle lights are emitting shapes that reflect nothing.
ShapeDesc JsonSceneReader::read_shape_light(CheckedObject& light, ShapeGeometry geometry) {
  ShapeDesc shape;
  shape.geometry = std::move(geometry);
  shape.material = black_material();
  shape.emission = AreaEmission{light.rgb("radiance", ColorKind::Emission), light.boolean_or("two_sided", false)};
  shape.to_world = read_transform_key(light);
  shape.where = place(light.pointer());
  return shape;
}

// Either one constant "radiance", or a gradient where a missing horizon takes the zenith's value,
// a missing zenith the horizon's, and a missing ground the horizon's.
SkyLight JsonSceneReader::read_sky(CheckedObject& light) const {
  SkyLight sky;
  bool constant = light.has("radiance");
  std::optional<RGB> zenith = light.optional_rgb("zenith", ColorKind::Emission);
  std::optional<RGB> horizon = light.optional_rgb("horizon", ColorKind::Emission);
  std::optional<RGB> ground = light.optional_rgb("ground", ColorKind::Emission);
  if (constant && (zenith || horizon || ground))
    report_.fail(light.pointer(), "a sky takes either \"radiance\" or \"zenith\"/\"horizon\"/\"ground\", not both");
  if (constant) {
    sky.zenith = sky.horizon = sky.ground = light.rgb("radiance", ColorKind::Emission);
  } else {
    if (!zenith && !horizon)
      report_.fail(light.pointer(), "a sky needs \"radiance\", or a gradient with \"zenith\" and/or \"horizon\"");
    sky.zenith = zenith.value_or(horizon.value_or(RGB()));
    sky.horizon = horizon.value_or(sky.zenith);
    sky.ground = ground.value_or(sky.horizon);
  }
  sky.up = normalize(light.direction_or("up", sky.up));
  return sky;
}

// Mitsuba's projector: an image projected from the origin of "transform" along its +z.
ProjectorLight JsonSceneReader::read_projector(CheckedObject& light) {
  ProjectorLight projector;
  projector.to_world = read_transform_key(light);
  projector.fov_degrees = light.number_or("fov", projector.fov_degrees);
  if (!(projector.fov_degrees > 0 && projector.fov_degrees < 180))
    report_.fail(light.pointer_of("fov"), "the field of view must be in (0, 180) degrees, got {}",
                 projector.fov_degrees);
  projector.irradiance = texture_reference(light, "irradiance");
  projector.scale = light.rgb_or("scale", ColorKind::Emission, projector.scale);
  return projector;
}

SpotLight JsonSceneReader::read_spot(CheckedObject& light) {
  SpotLight spot;
  spot.position = light.vec3("position");
  bool has_direction = light.has("direction"), has_look_at = light.has("look_at");
  if (has_direction && has_look_at)
    report_.fail(light.pointer_of("look_at"), "a spot light takes either \"direction\" or \"look_at\", not both");
  if (has_direction) {
    spot.direction = normalize(light.direction("direction"));
  } else if (has_look_at) {
    Vec3 direction = light.vec3("look_at") - spot.position;
    if (length_squared(direction) == 0 || !is_finite(normalize(direction)))
      report_.fail(light.pointer_of("look_at"), "look_at must differ from position (it sets the light's direction)");
    spot.direction = normalize(direction);
  } else {
    report_.fail(light.pointer(), "a spot light needs \"direction\" or \"look_at\"");
  }
  spot.intensity = light.rgb("intensity", ColorKind::Emission);
  spot.cone_angle = light.number_or("cone_angle", spot.cone_angle);
  if (!(spot.cone_angle > 0 && spot.cone_angle <= 180))
    report_.fail(light.pointer_of("cone_angle"), "the cone angle must be in (0, 180] degrees, got {}",
                 spot.cone_angle);
  spot.cone_delta = light.number_or("cone_delta", std::min(spot.cone_delta, spot.cone_angle));
  if (!(spot.cone_delta >= 0 && spot.cone_delta <= spot.cone_angle))
    report_.fail(light.pointer_of("cone_delta"), "cone_delta must be in [0, cone_angle] = [0, {}] degrees, got {}",
                 spot.cone_angle, spot.cone_delta);
  if (const Json* falloff = light.find("falloff"))
    spot.mitsuba_falloff = read_name<bool>(report_, *falloff, light.pointer_of("falloff"), "spot falloff",
                                           {{"smoothstep", false}, {"linear", true}});
  if (light.has("texture")) spot.texture = texture_reference(light, "texture");
  spot.up = normalize(light.direction_or("up", spot.up));
  return spot;
}

EnvironmentMap JsonSceneReader::read_environment(CheckedObject& light) const {
  EnvironmentMap environment;
  environment.filename = existing_file(light, "filename", "environment map");
  if (const Json* mapping = light.find("mapping"))
    environment.mapping =
        read_enum<EnvironmentMapping>(report_, *mapping, light.pointer_of("mapping"), "environment mapping");
  environment.scale = light.rgb_or("scale", ColorKind::Emission, environment.scale);
  environment.mis_compensation = light.boolean_or("mis_compensation", environment.mis_compensation);
  environment.to_world = read_environment_orientation(light, environment.mapping);
  return environment;
}

// Either "up" (where the map's own up axis points) and "rotate" (degrees about it), or a "transform".
Transform JsonSceneReader::read_environment_orientation(CheckedObject& light, EnvironmentMapping mapping) const {
  bool has_up = light.has("up"), has_rotate = light.has("rotate");
  if (const Json* steps = light.find("transform")) {
    std::string pointer = light.pointer_of("transform");
    if (has_up || has_rotate)
      report_.fail(pointer, "an environment map takes either \"transform\" or \"up\"/\"rotate\", not both");
    Transform transform = read_transform(*steps, pointer);
    check_rotation(transform, pointer);
    return transform;
  }
  Vec3 local_up = mapping == EnvironmentMapping::EqualAreaOctahedral ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
  Vec3 up = normalize(light.direction_or("up", local_up));
  float degrees = light.number_or("rotate", 0);
  Transform spin = degrees == 0 ? Transform() : Transform::rotate(degrees, local_up);
  return rotation_between(local_up, up) * spin;
}

// The rotation taking unit vector `from` to unit vector `to` about their common perpendicular.
Transform JsonSceneReader::rotation_between(Vec3 from, Vec3 to) {
  float cosine = std::clamp(dot(from, to), -1.0f, 1.0f);
  if (cosine >= 1 - 1e-7f) return {};
  Vec3 axis = cross(from, to);
  // Opposite vectors: any perpendicular axis will do; x is perpendicular to both possible local ups.
  if (length(axis) < 1e-6f) return Transform::rotate(180, {1, 0, 0});
  return Transform::rotate(std::acos(cosine) * (180 / kPi), axis);
}

// Light from infinitely far away depends on directions only: its transform may only rotate or mirror.
void JsonSceneReader::check_rotation(const Transform& transform, const std::string& pointer) const {
  const Matrix4& m = transform.matrix();
  if (m.m[0][3] != 0 || m.m[1][3] != 0 || m.m[2][3] != 0)
    report_.fail(pointer, "an environment map's transform may only rotate (or mirror) it, not translate it");
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double column_dot = m.m[0][i] * m.m[0][j] + m.m[1][i] * m.m[1][j] + m.m[2][i] * m.m[2][j];
      if (std::abs(column_dot - (i == j ? 1 : 0)) > 1e-4)
        report_.fail(pointer, "an environment map's transform may only rotate (or mirror) it, not scale or shear it");
    }
}

}  // namespace candela::json
