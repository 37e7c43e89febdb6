#include "candela/io/json/reader.h"

namespace candela::json {

// ---- lights

void JsonSceneReader::read_lights(const Json& value, const std::string& pointer) {
  check_is_array(report_, value, pointer, "lights");
  for (size_t i = 0; i < value.size(); ++i) read_light(value[i], child_pointer(pointer, i));
}

// Sphere and rectangle lights add an emitting shape to SceneDesc::shapes; the others, read by their
// schema (description/lights.h) and this format's shorthands, a light to SceneDesc::lights.
void JsonSceneReader::read_light(const Json& value, const std::string& pointer) {
  CheckedObject light(report_, value, pointer);
  const std::string type = light.string("type");
  // The shape's geometry, by its schema (description/shapes.h).
  auto geometry = [&](auto shape) {
    read_fields(light, SchemaOf<decltype(shape)>::schema, &shape);
    check_fields(light, SchemaOf<decltype(shape)>::schema, &shape);
    return shape;
  };
  if (type == "sphere") {
    scene_.shapes.push_back(read_shape_light(light, geometry(SphereShape{})));
  } else if (type == "rectangle") {
    scene_.shapes.push_back(read_shape_light(light, geometry(RectangleShape{})));
  } else {
    std::optional<LightDesc> desc = default_of_named_type<LightDesc>(light, "light", {"sphere", "rectangle"});
    std::visit(
        [&](auto& l) {
          using T = std::decay_t<decltype(l)>;
          read_fields(light, SchemaOf<T>::schema, &l);
          if constexpr (std::is_same_v<T, SpotLight>) read_spot_shorthands(light, l);
          if constexpr (std::is_same_v<T, SkyLight>) read_sky_shorthands(light, l);
          if constexpr (std::is_same_v<T, EnvironmentMap>) read_environment_orientation(light, l);
          check_fields(light, SchemaOf<T>::schema, &l);
        },
        *desc);
    scene_.lights.push_back(std::move(*desc));
    scene_.places.lights.push_back(place(pointer));
  }
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
void JsonSceneReader::read_sky_shorthands(CheckedObject& light, SkyLight& sky) const {
  const bool constant = light.has("radiance");
  const bool zenith = light.has("zenith"), horizon = light.has("horizon"), ground = light.has("ground");
  if (constant && (zenith || horizon || ground))
    report_.fail(light.pointer(), "a sky takes either \"radiance\" or \"zenith\"/\"horizon\"/\"ground\", not both");
  if (constant) {
    sky.zenith = sky.horizon = sky.ground = light.rgb("radiance", ColorKind::Emission);
    return;
  }
  if (!zenith && !horizon)
    report_.fail(light.pointer(), "a sky needs \"radiance\", or a gradient with \"zenith\" and/or \"horizon\"");
  if (!zenith) sky.zenith = sky.horizon;
  if (!horizon) sky.horizon = sky.zenith;
  if (!ground) sky.ground = sky.horizon;
}

// The axis as "direction" or as the point it aims at, "look_at"; cone_delta at most the cone angle
// when not given.
void JsonSceneReader::read_spot_shorthands(CheckedObject& light, SpotLight& spot) const {
  const bool has_direction = light.has("direction"), has_look_at = light.has("look_at");
  if (has_direction && has_look_at)
    report_.fail(light.pointer_of("look_at"), "a spot light takes either \"direction\" or \"look_at\", not both");
  if (has_look_at) {
    Vec3 direction = light.vec3("look_at") - spot.position;
    if (length_squared(direction) == 0 || !is_finite(normalize(direction)))
      report_.fail(light.pointer_of("look_at"), "look_at must differ from position (it sets the light's direction)");
    spot.direction = normalize(direction);
  } else if (!has_direction) {
    report_.fail(light.pointer(), "a spot light needs \"direction\" or \"look_at\"");
  }
  if (!light.has("cone_delta")) spot.cone_delta = std::min(spot.cone_delta, spot.cone_angle);
}

// Either a "transform" (rotations only), or "up" (where the map's own up axis points) and "rotate"
// (degrees about it).
void JsonSceneReader::read_environment_orientation(CheckedObject& light, EnvironmentMap& environment) const {
  const bool has_up = light.has("up"), has_rotate = light.has("rotate");
  if (light.has("transform")) {
    const std::string pointer = light.pointer_of("transform");
    if (has_up || has_rotate)
      report_.fail(pointer, "an environment map takes either \"transform\" or \"up\"/\"rotate\", not both");
    check_rotation(environment.to_world, pointer);
    return;
  }
  Vec3 local_up = environment.mapping == EnvironmentMapping::EqualAreaOctahedral ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
  Vec3 up = normalize(light.direction_or("up", local_up));
  float degrees = light.number_or("rotate", 0);
  Transform spin = degrees == 0 ? Transform() : Transform::rotate(degrees, local_up);
  environment.to_world = rotation_between(local_up, up) * spin;
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
