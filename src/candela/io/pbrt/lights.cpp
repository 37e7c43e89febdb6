// The light directives: LightSource, and AreaLightSource for the shapes that follow it.
#include <cmath>

#include "candela/io/pbrt/scene_parser.h"

namespace candela::pbrt {

void SceneParser::add_light(LightDesc light, const SourceLocation& where) {
  scene_.lights.push_back(std::move(light));
  scene_.places.lights.push_back(where);
}

// "scale" multiplies the emission; pbrt-v4 first normalises a spectrum to one nit, which for an RGB
// emission leaves the RGB as it is (see read_emission).
RGB SceneParser::read_light_scale(ParamList& params, RGB emitted) {
  float scale = params.get_float("scale", 1);
  if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
  return emitted * scale;
}

// Lights are placed once: an animated CTM (ActiveTransform) cannot move them.
void SceneParser::require_static_light(const Token& directive, const Token& type) const {
  if (state_.ctm.is_animated())
    throw_scene_error(at(directive), "LightSource \"{}\": lights must not move (the CTM is animated)", type.text);
}

void SceneParser::light_source(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the light type");
  ParamList params = read_params(d, fmt::format("LightSource \"{}\"", type.text), kLightAttributes);
  if (open_object_)
    throw_scene_error(at(d), "LightSource inside ObjectBegin \"{}\" (begun at {}): lights cannot be part of an "
                      "object definition", open_object_->name, open_object_->where.to_string());
  const Transform& ctm = state_.ctm.start;
  if (type.text == "point") {
    RGB intensity = read_light_scale(params, read_emission(params, "I").value_or(RGB(1.0f)));
    float power = params.get_float("power", -1);
    if (power > 0) intensity *= power / (4 * kPi);  // pbrt-v4: the power of an isotropic source
    Point3 from = params.get_point3("from", Point3(0.0f));
    params.reject_unused();
    require_static_light(d, type);
    add_light(PointLight{ctm.point(from), intensity}, at(d));
  } else if (type.text == "spot") {
    RGB intensity = read_light_scale(params, read_emission(params, "I").value_or(RGB(1.0f)));
    float cone_angle = params.get_float("coneangle", 30);
    float cone_delta = params.get_float("conedeltaangle", 5);
    if (!(cone_angle > 0 && cone_angle <= 180))
      params.fail("coneangle", "must be in (0, 180] degrees, got {}", cone_angle);
    if (!(cone_delta >= 0 && cone_delta <= cone_angle))
      params.fail("conedeltaangle", "must be in [0, \"coneangle\" = {}] degrees, got {}", cone_angle, cone_delta);
    float power = params.get_float("power", -1);
    if (power > 0) {
      float cos_end = std::cos(cone_angle * kPi / 180), cos_start = std::cos((cone_angle - cone_delta) * kPi / 180);
      intensity *= power / (2 * kPi * ((1 - cos_start) + (cos_start - cos_end) / 2));
    }
    Point3 from = params.get_point3("from", Point3(0.0f));
    Point3 to = params.get_point3("to", Point3(0, 0, 1));
    if (from == to) params.fail("to", "must differ from \"from\" (the spot light points from \"from\" to \"to\")");
    params.reject_unused();
    require_static_light(d, type);
    add_light(
        SpotLight{ctm.point(from), normalize(ctm.vector(to - from)), intensity, cone_angle, cone_delta}, at(d));
  } else if (type.text == "distant") {
    RGB radiance = read_light_scale(params, read_emission(params, "L").value_or(RGB(1.0f)));
    float illuminance = params.get_float("illuminance", -1);
    if (illuminance > 0) radiance *= illuminance;  // pbrt-v4: the illuminance of a surface facing the light
    Point3 from = params.get_point3("from", Point3(0.0f));
    Point3 to = params.get_point3("to", Point3(0, 0, 1));
    if (from == to) params.fail("to", "must differ from \"from\" (the light travels from \"from\" to \"to\")");
    params.reject_unused();
    require_static_light(d, type);
    add_light(DistantLight{normalize(ctm.vector(to - from)), radiance}, at(d));
  } else if (type.text == "infinite") {
    if (params.has("L") && params.has("filename"))
      params.fail("filename", "cannot be given together with \"L\" (as in pbrt-v4)");
    if (params.has_own("portal")) {
      params.get_vec3_array("portal", "point3");
      warn(params.where("portal"),
           "{}: \"portal\" is ignored: the light is sampled over the whole sphere (the same image where the "
           "portal is the only opening, with more noise)",
           params.owner());
    } else {
      params.take_any("portal");
    }
    float scale = params.get_float("scale", 1);
    if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
    float illuminance = params.get_float("illuminance", -1);
    if (params.has("filename")) {
      if (illuminance > 0)
        params.fail("illuminance", "is not supported with an image (\"filename\"): it needs the image's "
                    "illuminance; give \"scale\" instead");
      std::string name = params.get_string("filename", "");
      fs::path file = resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner()));
      params.reject_unused();
      require_static_light(d, type);
      EnvironmentMap map;
      map.filename = file.string();
      map.mapping = EnvironmentMapping::EqualAreaOctahedral;
      map.filter = TextureFilter::Nearest;  // pbrt-v4 looks its image lights up at the nearest texel
      map.scale = RGB(scale);
      map.to_world = ctm;
      add_light(map, at(d));
    } else {
      RGB radiance = read_emission(params, "L").value_or(RGB(1.0f)) * scale;
      // pbrt-v4: the illuminance a uniform sky of radiance L gives an upward-facing surface is pi L.
      if (illuminance > 0) radiance *= illuminance / kPi;
      params.reject_unused();
      SkyLight sky;
      sky.zenith = sky.horizon = sky.ground = radiance;
      add_light(sky, at(d));
    }
  } else if (type.text == "goniometric") {
    // pbrt-v4's GoniometricLight: intensity I x scale times a square equal-area image of the
    // directions, the CTM's y axis at the image's centre (pbrt swaps y and z; GoniometricLight in
    // description/lights.h). pbrt-v4 only warns about a missing image and then has none to look up.
    RGB intensity = read_light_scale(params, read_emission(params, "I").value_or(RGB(1.0f)));
    if (!params.has("filename")) params.fail("filename", "is required: name the square equal-area image");
    const std::string name = params.get_string("filename", "");
    GoniometricLight light;
    light.filename =
        resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner())).string();
    light.intensity = intensity;
    // pbrt-v4's "power": I times power / (4 pi x the image's mean), applied when the image is read.
    const float power = params.get_float("power", -1);
    if (power > 0) light.power = power;
    light.to_world = ctm;
    params.reject_unused();
    require_static_light(d, type);
    add_light(light, at(d));
  } else if (type.text == "projection") {
    // pbrt-v4's ProjectionLight: the intensity is scale x the image's nearest texel inside a pinhole
    // frustum along the CTM's +z, with "fov" on the image's shorter axis. pbrt reads the image at
    // screen position ((x + aspect tan) / (2 aspect tan), (tan - y) / (2 tan)) of the CTM-space
    // direction (x, y, 1) (it flips y; row 0 the top): the projector's Mitsuba uv mirrored in both
    // axes, and texture t = 1 is the top row, so the texture reads (1 - u, 1 - v).
    float scale = params.get_float("scale", 1);
    if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
    const float fov = params.get_float("fov", 90);
    if (!(fov > 0 && fov < 180)) params.fail("fov", "must be in (0, 180) degrees, got {}", fov);
    if (!params.has("filename")) params.fail("filename", "is required: name the projected image");
    ImageTexture image;
    const std::string name = params.get_string("filename", "");
    image.filename =
        resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner())).string();
    image.filter = TextureFilter::Nearest;
    image.wrap = TextureWrap::Clamp;
    image.mapping.su = -1;
    image.mapping.du = 1;
    image.mapping.sv = -1;
    image.mapping.dv = 1;
    ProjectorLight light;
    light.to_world = ctm;
    light.fov_degrees = fov;
    light.fov_axis = ProjectorFovAxis::Smaller;
    light.radiometry = ProjectorRadiometry::Intensity;
    light.scale = RGB(scale);
    // pbrt-v4's "power": scale times power / (the power with scale 1), applied when the image is read.
    const float power = params.get_float("power", -1);
    if (power > 0) light.power = power;
    params.reject_unused();
    require_static_light(d, type);
    light.irradiance = add_texture(image, at(d));
    add_light(light, at(d));
  } else {
    reject_type(at(type), "light", type.text, {"point", "spot", "distant", "infinite", "goniometric", "projection"},
                {});
  }
}

void SceneParser::area_light_source(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the area light type");
  if (type.text != "diffuse") reject_type(at(type), "area light", type.text, {"diffuse"}, {});
  ParamList params = read_params(d, "AreaLightSource \"diffuse\"", kLightAttributes);
  AreaLightSpec light;
  if (params.has("filename")) {
    // pbrt-v4's image area light: radiance scale x the image's linear RGB at the hit's (u, 1 - v),
    // clamped at the image's edges.
    if (params.has("L")) params.fail("filename", "cannot be given together with \"L\" (as in pbrt-v4)");
    if (params.has("power"))
      params.fail("power", "is not supported with an image (\"filename\"): it would need the image's mean "
                  "luminance; give \"scale\" instead");
    ImageTexture image;
    const std::string name = params.get_string("filename", "");
    image.filename =
        resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner())).string();
    image.wrap = TextureWrap::Clamp;
    light.texture = add_texture(image, at(d));
    light.radiance = read_light_scale(params, RGB(1.0f));
  } else {
    light.radiance = read_light_scale(params, read_emission(params, "L").value_or(RGB(1.0f)));
  }
  light.two_sided = params.get_bool("twosided", false);
  float power = params.get_float("power", -1);
  if (power > 0) light.power = power;
  light.where = at(d);
  params.reject_unused();
  state_.area_light = light;
}

}  // namespace candela::pbrt
