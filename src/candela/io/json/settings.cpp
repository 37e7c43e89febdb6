// The "camera" and "render" sections: the camera, the film's size and the render settings.
#include "candela/io/json/reader.h"

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/film/aov_film.h"
#include "candela/description/integrator_traits.h"
#include "candela/description/render_options.h"

namespace candela::json {

// ---- camera and render settings

void JsonSceneReader::read_camera(const Json& value, const std::string& pointer) {
  CheckedObject camera(report_, value, pointer);
  const Json* transform = camera.find("transform");
  if (transform && (camera.has("position") || camera.has("look_at") || camera.has("up")))
    report_.fail(camera.pointer_of("transform"),
                 "a camera takes either \"transform\" or \"position\"/\"look_at\"/\"up\", not both");
  Point3 position = camera.vec3_or("position", {0, 0, 0});
  Point3 look_at = camera.vec3_or("look_at", {0, 0, 1});
  Vec3 up = camera.direction_or("up", {0, 1, 0});
  float fov = 40;
  scene_.camera.fov_keys = camera_track(camera, "fov", {.lo = 0, .hi = 180, .lo_open = true, .hi_open = true}, fov);
  if (!scene_.camera.fov_keys) {
    fov = camera.number_or("fov", 40);
    if (!(fov > 0 && fov < 180))
      report_.fail(camera.pointer_of("fov"), "the field of view must be in (0, 180) degrees, got {}", fov);
  }
  if (const Json* axis = camera.find("fov_axis"))
    scene_.camera.fov_axis = read_enum<FovAxis>(report_, *axis, camera.pointer_of("fov_axis"), "field of view axis");
  else
    scene_.camera.fov_axis = FovAxis::Y;
  if (const Json* projection = camera.find("projection"))
    scene_.camera.projection =
        read_enum<Projection>(report_, *projection, camera.pointer_of("projection"), "projection");
  scene_.camera.near_clip = camera.number_or("near_clip", scene_.camera.near_clip, Bound::NonNegative);
  if (const Json* window = camera.find("screen_window"))
    scene_.camera.screen_window = read_screen_window(*window, camera.pointer_of("screen_window"));
  scene_.film.width = camera.integer_or("width", scene_.film.width, 1, kMaxResolution);
  scene_.film.height = camera.integer_or("height", scene_.film.height, 1, kMaxResolution);
  if (const Json* crop = camera.find("crop")) read_crop(*crop, camera.pointer_of("crop"));
  if (const Json* sensor = camera.find("sensor")) read_sensor(*sensor, camera.pointer_of("sensor"));
  read_lens_and_shutter(camera);
  if (scene_.camera.projection == Projection::Equirectangular || scene_.camera.projection == Projection::EqualArea)
    for (const char* projective : {"fov", "fov_axis", "lens_radius", "focus_distance"})
      if (camera.has(projective))
        report_.fail(camera.pointer_of(projective), "a spherical camera (\"projection\": \"{}\") sees every direction: "
                     "it has no \"{}\"", enum_name(scene_.camera.projection), projective);
  scene_.camera.medium = medium_reference(camera, "medium");
  scene_.camera.animation_node = animation_node_of(camera);
  camera.finish();
  if (int64_t(scene_.film.width) * scene_.film.height > kMaxPixels)
    report_.fail(pointer, "{} x {} pixels exceeds the limit of 2^28 pixels", scene_.film.width, scene_.film.height);
  if (transform) {
    // Camera space: +x image right, +y image up, +z the view direction.
    scene_.camera.world_from_camera = read_transform(*transform, camera.pointer_of("transform"));
  } else {
    check_view_direction(camera, position, look_at, up);
    scene_.camera.world_from_camera = Transform::look_at_right_handed(position, look_at, up);
  }
  scene_.camera.fov_degrees = fov;
}

// [x0, x1, y0, y1] with x0 < x1 and y0 < y1 (CameraDesc::screen_window).
std::array<float, 4> JsonSceneReader::read_screen_window(const Json& value, const std::string& pointer) const {
  if (!value.is_array() || value.size() != 4)
    report_.fail(pointer, "expected [x0, x1, y0, y1], got {}", describe(value));
  std::array<float, 4> window;
  for (size_t i = 0; i < 4; ++i) window[i] = read_float(report_, value[i], fmt::format("{}/{}", pointer, i));
  if (!(window[0] < window[1] && window[2] < window[3]))
    report_.fail(pointer, "the window must have x0 < x1 and y0 < y1, got [{}, {}, {}, {}]", window[0], window[1],
                 window[2], window[3]);
  return window;
}

// [x, y, full_width, full_height]: the image (width x height) at (x, y) of a larger one (FilmDesc::crop).
void JsonSceneReader::read_crop(const Json& value, const std::string& pointer) {
  if (!value.is_array() || value.size() != 4)
    report_.fail(pointer, "expected [x, y, full_width, full_height], got {}", describe(value));
  std::array<int, 4> c;
  for (size_t i = 0; i < 4; ++i) {
    const Json& v = value[i];
    if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > kMaxResolution)
      report_.fail(fmt::format("{}/{}", pointer, i), "expected an integer in [0, {}], got {}", kMaxResolution,
                   describe(v));
    c[i] = v.get<int>();
  }
  const FilmDesc& film = scene_.film;
  if (int64_t(c[0]) + film.width > c[2] || int64_t(c[1]) + film.height > c[3])
    report_.fail(pointer, "the {} x {} image at ({}, {}) does not fit in {} x {}", film.width, film.height, c[0], c[1],
                 c[2], c[3]);
  scene_.film.crop = FilmDesc::Crop{c[0], c[1], c[2], c[3]};
}

// {"exposure", "white_balance", "max_component"} (FilmDesc::Sensor).
void JsonSceneReader::read_sensor(const Json& value, const std::string& pointer) {
  CheckedObject object(report_, value, pointer);
  FilmDesc::Sensor& sensor = scene_.film.sensor;
  sensor.exposure = object.number_or("exposure", sensor.exposure, Bound::Positive);
  sensor.white_balance = object.number_or("white_balance", sensor.white_balance, Bound::NonNegative);
  if (sensor.white_balance != 0 && !(sensor.white_balance >= 1000 && sensor.white_balance <= 100000))
    report_.fail(object.pointer_of("white_balance"),
                 "expected 0 (none) or a colour temperature in [1000, 100000] kelvin, got {}", sensor.white_balance);
  sensor.max_component = object.number_or("max_component", sensor.max_component, Bound::NonNegative);
  object.finish();
}

void JsonSceneReader::read_lens_and_shutter(CheckedObject& camera) {
  CameraDesc& desc = scene_.camera;
  // Each a number, or keyframes (docs/animation.md).
  desc.lens_radius_keys = camera_track(camera, "lens_radius", Bound::NonNegative, desc.lens_radius);
  if (!desc.lens_radius_keys) desc.lens_radius = camera.number_or("lens_radius", desc.lens_radius, Bound::NonNegative);
  desc.focus_distance_keys = camera_track(camera, "focus_distance", Bound::Positive, desc.focus_distance);
  if (!desc.focus_distance_keys)
    desc.focus_distance = camera.number_or("focus_distance", desc.focus_distance, Bound::Positive);
  if (const Json* shutter = camera.find("shutter")) {
    Vec2 open_close = read_vec2(report_, *shutter, camera.pointer_of("shutter"));
    if (!(open_close.x <= open_close.y))
      report_.fail(camera.pointer_of("shutter"), "the shutter must not close before it opens, got [{}, {}]",
                   open_close.x, open_close.y);
    desc.shutter_open = open_close.x;
    desc.shutter_close = open_close.y;
  }
}

void JsonSceneReader::check_view_direction(const CheckedObject& camera, Point3 position, Point3 look_at, Vec3 up) const {
  Vec3 forward = look_at - position;
  if (length_squared(forward) == 0 || !is_finite(normalize(forward)))
    report_.fail(camera.pointer_of("look_at"), "look_at must differ from position (it sets the view direction)");
  if (length(cross(normalize(forward), normalize(up))) < 1e-6f)
    report_.fail(camera.pointer_of("up"), "up is parallel to the view direction, so the image has no defined up");
}

// The "render" object: first the render options' keys (description/render_options.h), read with
// the rules the command line checks them by and applied to the scene as the command line applies
// them; then the keys only a scene file gives (the output, the AOVs, hidden emitters, the transform
// times, the sampler's jitter, the filter's size and shape) and what depends on several.
void JsonSceneReader::read_render(const Json& value, const std::string& pointer) {
  CheckedObject render(report_, value, pointer);
  RenderSettings& settings = scene_.settings;
  // The format's own defaults: a scene with media renders with the volumetric path tracer, and the
  // sampler is the most efficient measured (docs/performance.md).
  if (!scene_.media.empty()) settings.integrator = "volpath";
  settings.sampler.type = SamplerType::ZSobol;
  RenderRequest request;
  std::map<std::string, CheckedObject, std::less<>> groups;  // "adaptive": {"spp": 64} holds adaptive.spp
  for (const RenderOption& option : render_options()) {
    if (option.scene_key.empty()) continue;
    const size_t dot = option.scene_key.find('.');
    CheckedObject* object = &render;
    if (dot != std::string_view::npos) {
      const std::string group(option.scene_key.substr(0, dot));
      auto it = groups.find(group);
      if (it == groups.end()) {
        const Json* given = render.find(group);
        if (!given) continue;
        it = groups.try_emplace(group, report_, *given, render.pointer_of(group)).first;
      }
      object = &it->second;
    }
    const std::string_view key = option.scene_key.substr(dot == std::string_view::npos ? 0 : dot + 1);
    if (const Json* given = object->find(key)) read_render_option(option, *given, object->pointer_of(key), request);
  }
  for (const RenderOption& option : render_options())
    if (!option.scene_key.empty() && option.given(request)) option.apply(request, scene_);
  read_film_outputs(render);
  settings.hide_emitters = render.boolean_or("hide_emitters", settings.hide_emitters);
  if (const Json* times = render.find("transform_times"))
    read_transform_times(*times, render.pointer_of("transform_times"));
  if (auto sampler = groups.find("sampler"); sampler != groups.end()) {
    sampler->second.require("type");
    if (settings.sampler.type == SamplerType::Stratified)
      settings.sampler.jitter = sampler->second.boolean_or("jitter", settings.sampler.jitter);
  }
  if (auto filter = groups.find("filter"); filter != groups.end()) {
    filter->second.require("type");
    read_filter_shape(filter->second, settings.filter);
  }
  if (auto adaptive = groups.find("adaptive"); adaptive != groups.end()) check_adaptive(adaptive->second, settings);
  if (auto mlt = groups.find("mlt"); mlt != groups.end())
    if (std::string problem = settings.mlt.problem(); !problem.empty()) report_.fail(mlt->second.pointer(), "{}", problem);
  for (const auto& [group, object] : groups) object.finish();
  render.finish();
  check_integrator_reads(value, render, settings);
}

// One option's value from the file into `request`, checked against the option's rule.
void JsonSceneReader::read_render_option(const RenderOption& option, const Json& value, const std::string& pointer,
                                         RenderRequest& request) const {
  std::string what = option.name;
  std::replace(what.begin(), what.end(), '_', ' ');
  std::visit(
      [&](auto member) {
        auto& field = request.*member;
        using T = std::remove_cvref_t<decltype(field)>;
        if constexpr (std::is_same_v<T, bool>) {
          field = read_bool(report_, value, pointer) != option.scene_negated;
        } else if constexpr (std::is_same_v<T, std::string>) {
          const auto* choice = std::get_if<ChoiceValue>(&option.rule);
          if (!option.scene_true.empty()) {
            // A flag in the file: true is `scene_true`, false the other of the two choices.
            const bool flag = read_bool(report_, value, pointer);
            for (const std::string& name : choice->names)
              if ((name == option.scene_true) == flag) field = name;
            return;
          }
          field = read_string(report_, value, pointer);
          if (field.empty()) report_.fail(pointer, "the {} name is empty", what);
          if (choice && std::find(choice->names.begin(), choice->names.end(), field) == choice->names.end()) {
            std::vector<std::string_view> names(choice->names.begin(), choice->names.end());
            report_.fail(pointer, "unknown {} \"{}\"{}; expected one of: {}", what, field, did_you_mean(field, names),
                         fmt::join(choice->names, ", "));
          }
        } else {
          using V = typename T::value_type;
          const auto* range = std::get_if<ValueRange>(&option.rule);
          if constexpr (std::is_same_v<V, uint64_t>) {
            field = read_uint64(report_, value, pointer);
          } else if constexpr (std::is_integral_v<V>) {
            const int64_t n = read_int64(report_, value, pointer);
            if (range && !range->contains(double(n))) {
              if (range->hi >= std::numeric_limits<int>::max())
                report_.fail(pointer, "expected an integer >= {}, got {}", range->lo, n);
              report_.fail(pointer, "expected an integer in [{}, {}], got {}", range->lo, range->hi, n);
            }
            field = V(n);
          } else {
            const ValueRange bound = range ? *range : std::holds_alternative<PositiveValue>(option.rule) ? kPositive
                                                                                                          : kAnyValue;
            field = V(check_bound(report_, read_float(report_, value, pointer), bound, pointer));
          }
        }
      },
      option.field);
}

// What the image is written to: the file and the extra layers.
void JsonSceneReader::read_film_outputs(CheckedObject& render) {
  scene_.film.filename = render.string_or("output", "");
  scene_.film.aovs = render.string_or("aovs", "");
  if (!scene_.film.aovs.empty()) {
    try {
      parse_aovs(scene_.film.aovs);
    } catch (const UsageError& e) {
      report_.fail(render.pointer_of("aovs"), "{}", e.what());
    }
  }
}

// The scene's integrator must exist and read every selective setting the scene gives
// (description/integrator_traits.h), as the command line's flags must. A scene names the integrator
// that renders it: choosing one (--integrator auto) is the command line's and the Python module's.
void JsonSceneReader::check_integrator_reads(const Json& value, const CheckedObject& render,
                                             const RenderSettings& settings) const {
  const IntegratorTraits* integrator = find_integrator_traits(settings.integrator);
  if (!integrator || integrator->chooses)
    report_.fail(render.pointer_of("integrator"), "unknown integrator \"{}\" (known: {})", settings.integrator,
                 integrator_names());
  for (const SelectiveSetting& setting : kSelectiveSettings) {
    // Every setting is a key of its own but the paper's light selection, a value of light_selection.
    const bool paper = setting.key == "light_selection=paper";
    const std::string key = paper ? "light_selection" : std::string(setting.key);
    const bool given = paper ? settings.light_selection == LightSelection::Paper : value.contains(key);
    if (given && !integrator->reads_setting(setting.key))
      report_.fail(render.pointer_of(key), "{}", unread_setting_message(*integrator, setting.key));
  }
}

void JsonSceneReader::read_transform_times(const Json& value, const std::string& pointer) {
  Vec2 times = read_vec2(report_, value, pointer);
  // Shapes are interpolated between the two times, so they must span an interval.
  if (!(times.x < times.y))
    report_.fail(pointer, "the start time must be less than the end time, got [{}, {}]", times.x, times.y);
  scene_.transform_start_time = times.x;
  scene_.transform_end_time = times.y;
}

// The filter's size and shape, each type from pbrt-v4's defaults (its type set them): only the keys
// of that type's parameters are allowed.
void JsonSceneReader::read_filter_shape(CheckedObject& object, FilterDesc& filter) const {
  if (const Json* radius = object.find("radius"))
    filter.radius = read_filter_radius(*radius, object.pointer_of("radius"));
  if (filter.type == FilterType::Gaussian)
    filter.gaussian_sigma = object.number_or("sigma", filter.gaussian_sigma, Bound::Positive);
  if (filter.type == FilterType::Mitchell) {
    filter.mitchell_b = object.number_or("b", filter.mitchell_b);
    filter.mitchell_c = object.number_or("c", filter.mitchell_c);
  }
  if (filter.type == FilterType::LanczosSinc)
    filter.sinc_tau = object.number_or("tau", filter.sinc_tau, Bound::Positive);
}

// One number for both axes, or [x, y].
Vec2 JsonSceneReader::read_filter_radius(const Json& value, const std::string& pointer) const {
  Vec2 radius = value.is_number() ? Vec2(read_float(report_, value, pointer), read_float(report_, value, pointer))
                                  : read_vec2(report_, value, pointer);
  for (float r : {radius.x, radius.y})
    if (!(r > 0 && r <= kMaxFilterRadius))
      report_.fail(pointer, "a filter radius must be in (0, {}] pixels, got {}", kMaxFilterRadius, r);
  return radius;
}

// Present = on (RenderSettings): a threshold on the pixels' relative error, a budget of samples
// per pixel on average, or both; the batch and the budgets agree (adaptive_problem).
void JsonSceneReader::check_adaptive(const CheckedObject& adaptive, const RenderSettings& settings) const {
  if (!settings.adaptive()) report_.fail(adaptive.pointer(), "expected \"threshold\", \"spp\" or both");
  if (std::optional<SettingProblem> problem = adaptive_problem(settings))
    report_.fail(adaptive.pointer_of(problem->scene_key.substr(problem->scene_key.find('.') + 1)), "{}",
                 problem->message);
}

}  // namespace candela::json
