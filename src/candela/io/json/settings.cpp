// The "camera" and "render" sections: the camera, the film's size and the render settings.
#include "candela/io/json/reader.h"

#include <limits>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/film/aov_film.h"
#include "candela/description/integrator_traits.h"

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
  float fov = camera.number_or("fov", 40);
  if (!(fov > 0 && fov < 180))
    report_.fail(camera.pointer_of("fov"), "the field of view must be in (0, 180) degrees, got {}", fov);
  if (const Json* axis = camera.find("fov_axis"))
    scene_.camera.fov_axis = read_enum<FovAxis>(report_, *axis, camera.pointer_of("fov_axis"), "field of view axis");
  else
    scene_.camera.fov_axis = FovAxis::Y;
  if (const Json* projection = camera.find("projection"))
    scene_.camera.projection =
        read_enum<Projection>(report_, *projection, camera.pointer_of("projection"), "projection");
  scene_.camera.near_clip = camera.number_or("near_clip", scene_.camera.near_clip, Bound::NonNegative);
  scene_.film.width = camera.integer_or("width", scene_.film.width, 1, kMaxResolution);
  scene_.film.height = camera.integer_or("height", scene_.film.height, 1, kMaxResolution);
  read_lens_and_shutter(camera);
  scene_.camera.medium = medium_reference(camera, "medium");
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

void JsonSceneReader::read_lens_and_shutter(CheckedObject& camera) {
  CameraDesc& desc = scene_.camera;
  desc.lens_radius = camera.number_or("lens_radius", desc.lens_radius, Bound::NonNegative);
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

void JsonSceneReader::read_render(const Json& value, const std::string& pointer) {
  CheckedObject render(report_, value, pointer);
  constexpr int64_t kIntMax = std::numeric_limits<int>::max();
  RenderSettings& settings = scene_.settings;
  settings.spp = render.integer_or("spp", settings.spp, 1, kIntMax);
  settings.max_depth = render.integer_or("max_depth", settings.max_depth, 1, kIntMax);
  if (const Json* seed = render.find("seed")) settings.seed = read_uint64(report_, *seed, render.pointer_of("seed"));
  // A scene with media renders with the volumetric path tracer unless it names another integrator.
  settings.integrator = render.string_or("integrator", scene_.media.empty() ? settings.integrator : "volpath");
  if (settings.integrator.empty()) report_.fail(render.pointer_of("integrator"), "the integrator name is empty");
  scene_.film.filename = render.string_or("output", "");
  scene_.film.aovs = render.string_or("aovs", "");
  if (!scene_.film.aovs.empty()) {
    try {
      parse_aovs(scene_.film.aovs);
    } catch (const UsageError& e) {
      report_.fail(render.pointer_of("aovs"), "{}", e.what());
    }
  }
  settings.rr_start_depth = render.integer_or("rr_start_depth", settings.rr_start_depth, 0, kIntMax);
  if (const Json* times = render.find("transform_times"))
    read_transform_times(*times, render.pointer_of("transform_times"));
  if (const Json* sampler = render.find("sampler"))
    settings.sampler = read_sampler(*sampler, render.pointer_of("sampler"));
  else
    settings.sampler.type = SamplerType::ZSobol;  // the most efficient measured (docs/performance.md)
  if (const Json* filter = render.find("filter")) settings.filter = read_filter(*filter, render.pointer_of("filter"));
  read_integrator_strategies(render, settings);
  if (const Json* adaptive = render.find("adaptive"))
    read_adaptive(*adaptive, render.pointer_of("adaptive"), settings);
  if (const Json* mlt = render.find("mlt")) read_mlt(*mlt, render.pointer_of("mlt"), settings);
  render.finish();
  check_integrator_reads(value, render, settings);
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

// Metropolis light transport's parameters (integrator "mlt").
void JsonSceneReader::read_mlt(const Json& value, const std::string& pointer, RenderSettings& settings) const {
  CheckedObject object(report_, value, pointer);
  constexpr int64_t kIntMax = std::numeric_limits<int>::max();
  settings.mlt.bootstrap = object.integer_or("bootstrap", settings.mlt.bootstrap, 1, kIntMax);
  settings.mlt.chains = object.integer_or("chains", settings.mlt.chains, 1, kIntMax);
  settings.mlt.sigma = object.number_or("sigma", settings.mlt.sigma, Bound::Positive);
  if (settings.mlt.sigma > 1) report_.fail(object.pointer_of("sigma"), "sigma must be at most 1, got {}", settings.mlt.sigma);
  settings.mlt.large_step = object.number_or("large_step", settings.mlt.large_step, Bound::UnitInterval);
  settings.mlt.lens = object.number_or("lens", settings.mlt.lens, Bound::UnitInterval);
  settings.mlt.caustic = object.number_or("caustic", settings.mlt.caustic, Bound::UnitInterval);
  if (std::string problem = settings.mlt.problem(); !problem.empty()) report_.fail(pointer, "{}", problem);
  object.finish();
}

void JsonSceneReader::read_transform_times(const Json& value, const std::string& pointer) {
  Vec2 times = read_vec2(report_, value, pointer);
  // Shapes are interpolated between the two times, so they must span an interval.
  if (!(times.x < times.y))
    report_.fail(pointer, "the start time must be less than the end time, got [{}, {}]", times.x, times.y);
  scene_.transform_start_time = times.x;
  scene_.transform_end_time = times.y;
}

SamplerDesc JsonSceneReader::read_sampler(const Json& value, const std::string& pointer) const {
  CheckedObject object(report_, value, pointer);
  SamplerDesc sampler;
  sampler.type = read_enum<SamplerType>(report_, object.require("type"), object.pointer_of("type"), "sampler type");
  if (sampler.type == SamplerType::Stratified) sampler.jitter = object.boolean_or("jitter", sampler.jitter);
  object.finish();
  return sampler;
}

// Each type starts from pbrt-v4's defaults; only the keys of that type's parameters are allowed.
FilterDesc JsonSceneReader::read_filter(const Json& value, const std::string& pointer) const {
  CheckedObject object(report_, value, pointer);
  FilterType type = read_enum<FilterType>(report_, object.require("type"), object.pointer_of("type"), "filter type");
  FilterDesc filter = default_filter(type);
  if (const Json* radius = object.find("radius"))
    filter.radius = read_filter_radius(*radius, object.pointer_of("radius"));
  if (type == FilterType::Gaussian)
    filter.gaussian_sigma = object.number_or("sigma", filter.gaussian_sigma, Bound::Positive);
  if (type == FilterType::Mitchell) {
    filter.mitchell_b = object.number_or("b", filter.mitchell_b);
    filter.mitchell_c = object.number_or("c", filter.mitchell_c);
  }
  object.finish();
  return filter;
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

void JsonSceneReader::read_integrator_strategies(CheckedObject& render, RenderSettings& settings) const {
  if (const Json* value = render.find("direction_sampling"))
    settings.path.direction_sampling = read_enum<DirectionSampling>(
        report_, *value, render.pointer_of("direction_sampling"), "direction sampling");
  settings.path.mis = render.boolean_or("mis", settings.path.mis);
  settings.hide_emitters = render.boolean_or("hide_emitters", settings.hide_emitters);
  settings.spectral = render.boolean_or("spectral", settings.spectral);
  if (const Json* value = render.find("light_selection"))
    settings.light_selection =
        read_enum<LightSelection>(report_, *value, render.pointer_of("light_selection"), "light selection");
  settings.path.shadow_rays = render.integer_or("shadow_rays", settings.path.shadow_rays, 1, std::numeric_limits<int>::max());
  if (const Json* value = render.find("bvh"))
    settings.bvh = read_enum<BvhLayout>(report_, *value, render.pointer_of("bvh"), "BVH layout");
}

// Present = on (RenderSettings): a threshold on the pixels' relative error, a budget of samples
// per pixel on average, or both.
void JsonSceneReader::read_adaptive(const Json& value, const std::string& pointer, RenderSettings& settings) const {
  CheckedObject adaptive(report_, value, pointer);
  constexpr int64_t kIntMax = std::numeric_limits<int>::max();
  settings.adaptive_threshold = adaptive.number_or("threshold", 0, Bound::Positive);
  settings.adaptive_spp = adaptive.integer_or("spp", 0, 1, kIntMax);
  if (!settings.adaptive()) report_.fail(pointer, "expected \"threshold\", \"spp\" or both");
  settings.adaptive_batch = adaptive.integer_or("batch", settings.adaptive_batch, 1, kIntMax);
  // Batches of a power of two keep every sampler's stratification within a batch.
  if ((settings.adaptive_batch & (settings.adaptive_batch - 1)) != 0)
    report_.fail(adaptive.pointer_of("batch"), "expected a power of two, got {}", settings.adaptive_batch);
  if (settings.adaptive_spp > 0 && settings.adaptive_spp < settings.adaptive_batch)
    report_.fail(adaptive.pointer_of("spp"), "spp ({}) must be at least the batch size ({})", settings.adaptive_spp,
                 settings.adaptive_batch);
  settings.adaptive_max_spp = adaptive.integer_or("max_spp", 0, 1, kIntMax);
  if (settings.adaptive_max_spp > 0 && settings.adaptive_max_spp < settings.adaptive_batch)
    report_.fail(adaptive.pointer_of("max_spp"), "max_spp ({}) must be at least the batch size ({})",
                 settings.adaptive_max_spp, settings.adaptive_batch);
  if (settings.adaptive_max_spp > 0 && settings.adaptive_max_spp < settings.adaptive_spp)
    report_.fail(adaptive.pointer_of("max_spp"), "max_spp ({}) must be at least spp ({})", settings.adaptive_max_spp,
                 settings.adaptive_spp);
  adaptive.finish();
}

}  // namespace candela::json
