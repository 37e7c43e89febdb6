// The rendering-option directives (before WorldBegin): Camera, Film, Sampler, Integrator,
// PixelFilter, Accelerator, Option and ColorSpace.
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>

#include "candela/io/pbrt/scene_parser.h"
#include "candela/spectral/cie.h"

namespace candela::pbrt {

namespace {

// pbrt's limits on what a scene may ask for, beyond which the request is surely a mistake.
constexpr int kMaxResolutionPerSide = 65536;
constexpr int64_t kMaxPixels = int64_t{1} << 28;

// The camera sensors pbrt-v4 knows by name (each with measured red, green and blue response curves).
constexpr std::string_view kPbrtCameraSensors[] = {
    "canon_eos_100d",    "canon_eos_1dx_mkii", "canon_eos_200d",  "canon_eos_200d_mkii", "canon_eos_5d",
    "canon_eos_5d_mkii", "canon_eos_5d_mkiii", "canon_eos_5d_mkiv", "canon_eos_5ds",     "canon_eos_m",
    "hasselblad_l1d_20c", "nikon_d810",        "nikon_d850",      "sony_ilce_6400",      "sony_ilce_7m3",
    "sony_ilce_7rm3",    "sony_ilce_9"};

bool is_pbrt_camera_sensor(std::string_view name) {
  return std::find(std::begin(kPbrtCameraSensors), std::end(kPbrtCameraSensors), name) != std::end(kPbrtCameraSensors);
}

std::string pbrt_camera_sensor_list() {
  std::string list;
  for (std::string_view name : kPbrtCameraSensors) list += fmt::format("{}\"{}\"", list.empty() ? "" : ", ", name);
  return list;
}

}  // namespace

void SceneParser::camera(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the camera type");
  if (type.text != "perspective" && type.text != "orthographic" && type.text != "spherical")
    reject_type(at(type), "camera", type.text, {"perspective", "orthographic", "spherical"}, {"realistic"});
  const bool orthographic = type.text == "orthographic", spherical = type.text == "spherical";
  const std::string camera_name = fmt::format("Camera \"{}\"", type.text);
  ParamList params = read_params(d, camera_name);
  // pbrt-v4's spherical camera: the whole sphere of directions in an equal-area square (its default)
  // or an equirectangular image. It reads and ignores the projective cameras' lens and screen.
  Projection projection = orthographic ? Projection::Orthographic : Projection::Perspective;
  if (spherical) {
    const SourceLocation where = params.where("mapping");
    const std::string mapping = params.get_string("mapping", "equalarea");
    if (mapping != "equalarea" && mapping != "equirectangular")
      throw_scene_error(where, "{}: unknown \"mapping\" \"{}\" (pbrt-v4 has \"equalarea\" and \"equirectangular\")",
                        camera_name, mapping);
    projection = mapping == "equalarea" ? Projection::EqualArea : Projection::Equirectangular;
    for (const char* ignored : {"lensradius", "focaldistance", "frameaspectratio", "screenwindow"})
      if (params.has(ignored)) {
        warn(params.where(ignored), "{}: \"{}\" does not apply to a spherical camera and is ignored, as in pbrt-v4",
             camera_name, ignored);
        params.take_any(ignored);
      }
  }
  float fov = orthographic || spherical ? 90 : params.get_float("fov", 90);
  if (!(fov > 0 && fov < 180)) params.fail("fov", "must be between 0 and 180 degrees, got {}", fov);
  float lens_radius = params.get_float("lensradius", 0);
  if (lens_radius < 0) params.fail("lensradius", "must not be negative, got {}", lens_radius);
  if (orthographic && lens_radius > 0)
    params.fail("lensradius", "{}: depth of field with an orthographic camera is not supported", lens_radius);
  std::optional<std::array<float, 4>> window;
  if (!spherical && params.has("screenwindow")) {
    const std::vector<double> w = params.get_floats("screenwindow");
    if (w.size() != 4) params.fail("screenwindow", "needs 4 values (x0 x1 y0 y1), got {}", w.size());
    if (!(w[0] < w[1] && w[2] < w[3]))
      params.fail("screenwindow", "must have x0 < x1 and y0 < y1, got [{} {} {} {}]", w[0], w[1], w[2], w[3]);
    window = std::array<float, 4>{float(w[0]), float(w[1]), float(w[2]), float(w[3])};
  }
  float focus_distance = params.get_float("focaldistance", 1e6f);
  if (!(focus_distance > 0)) params.fail("focaldistance", "must be positive, got {}", focus_distance);
  if (spherical) lens_radius = 0, focus_distance = 1e6f;  // ignored (warned above)
  float shutter_open = params.get_float("shutteropen", 0);
  float shutter_close = params.get_float("shutterclose", 1);
  // pbrt-v4 refuses a shutter that does not open: the exposure time (shutterclose - shutteropen)
  // scales the film's sensor, so the image would be black.
  if (shutter_close < shutter_open)
    params.fail("shutterclose", "must not be less than \"shutteropen\" ({}), got {}", shutter_open, shutter_close);
  if (shutter_close == shutter_open)
    params.fail("shutterclose", "equals \"shutteropen\" ({}): the shutter does not open, and pbrt-v4's film "
                "scales the image by the exposure time (a black image; pbrt-v4 refuses it too)", shutter_open);
  params.reject_unused();
  if (state_.ctm.is_animated())
    throw_scene_error(at(d),
                      "Camera: the camera transform is animated (ActiveTransform made the start and end CTMs "
                      "differ); a moving camera is not supported");

  // The CTM maps world space to camera space here; pbrt names the inverse "camera".
  CameraDesc& camera = scene_.camera;
  camera.world_from_camera = state_.ctm.start.inverse();
  camera.projection = projection;
  camera.screen_window = window;
  camera.fov_degrees = fov;
  camera.fov_axis = FovAxis::Smaller;
  camera.lens_radius = lens_radius;
  camera.focus_distance = focus_distance;
  camera.shutter_open = shutter_open;
  camera.shutter_close = shutter_close;
  camera.medium = state_.outside_medium;  // pbrt-v4's CameraMedium
  coordinate_systems_["camera"] = {camera.world_from_camera, camera.world_from_camera};
}

void SceneParser::film(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the film type");
  // pbrt-v4's gbuffer and spectral films are its rgb film (the same parameters, the same colour)
  // plus layers in the EXR: per-pixel geometry, or the radiance in wavelength buckets; candela's
  // AOVs with pbrt's layout (film/aov_film.h's "gbuffer" and "spectral").
  if (type.text != "rgb" && type.text != "gbuffer" && type.text != "spectral")
    reject_type(at(type), "film", type.text, {"rgb", "gbuffer", "spectral"}, {});
  const bool gbuffer = type.text == "gbuffer", spectral = type.text == "spectral";
  const std::string film_name = fmt::format("Film \"{}\"", type.text);
  ParamList params = read_params(d, film_name.c_str());
  int width = params.get_int("xresolution", 1280);
  int height = params.get_int("yresolution", 720);
  if (width < 1 || width > kMaxResolutionPerSide)
    params.fail("xresolution", "must be between 1 and {}, got {}", kMaxResolutionPerSide, width);
  if (height < 1 || height > kMaxResolutionPerSide)
    params.fail("yresolution", "must be between 1 and {}, got {}", kMaxResolutionPerSide, height);
  if (int64_t{width} * height > kMaxPixels)
    throw_scene_error(params.where(params.has("yresolution") ? "yresolution" : "xresolution"),
                      "{}: {} x {} is too many pixels (at most 2^28 = {})", film_name, width, height, kMaxPixels);
  std::string filename = params.get_string("filename", "");
  params.get_bool("savefp16", true);  // the precision of the output file only
  // The film's diagonal in mm only sizes pbrt-v4's realistic camera's sensor.
  if (float diagonal = params.get_float("diagonal", 35); !(diagonal > 0))
    params.fail("diagonal", "must be positive, got {}", diagonal);
  pixel_bounds_.reset();
  // pbrt-v4's image is the part of the full image inside pixelbounds [x0 x1 y0 y1] (in pixels, x1 and
  // y1 excluded) or else cropwindow [x0 x1 y0 y1] (fractions, rounded up to pixels); world_begin
  // narrows the camera's screen window to it.
  if (params.has("pixelbounds")) {
    std::vector<int> b = params.get_int_array("pixelbounds");
    if (b.size() != 4) params.fail("pixelbounds", "takes 4 values [x0 x1 y0 y1], got {}", b.size());
    if (!(0 <= b[0] && b[0] < b[1] && b[1] <= width && 0 <= b[2] && b[2] < b[3] && b[3] <= height))
      params.fail("pixelbounds", "[{} {} {} {}] is not a non-empty part of the {} x {} image", b[0], b[1], b[2], b[3],
                  width, height);
    if (params.has("cropwindow"))
      warn(params.where("cropwindow"), "{}: both \"pixelbounds\" and \"cropwindow\" are given; "
           "\"pixelbounds\" is used, as in pbrt-v4", film_name);
    params.take_any("cropwindow");
    pixel_bounds_ = {b[0], b[1], b[2], b[3]};
  } else if (params.has("cropwindow")) {
    std::vector<double> c = params.get_floats("cropwindow");
    if (c.size() != 4) params.fail("cropwindow", "takes 4 values [x0 x1 y0 y1], got {}", c.size());
    auto to_pixel = [](double fraction, int size) {
      return static_cast<int>(std::ceil(std::clamp(fraction, 0.0, 1.0) * size));
    };
    std::array<int, 4> b = {to_pixel(std::min(c[0], c[1]), width), to_pixel(std::max(c[0], c[1]), width),
                            to_pixel(std::min(c[2], c[3]), height), to_pixel(std::max(c[2], c[3]), height)};
    if (!(b[0] < b[1] && b[2] < b[3]))
      params.fail("cropwindow", "[{} {} {} {}] holds no pixel of the {} x {} image", c[0], c[1], c[2], c[3], width,
                  height);
    pixel_bounds_ = b;
  }
  // pbrt-v4's PixelSensor: its CIE 1931 sensor, ISO and white balance, and the limit on a sample's
  // largest sensor component. world_begin multiplies in the exposure time, the camera's shutter interval.
  FilmDesc::Sensor sensor;
  film_iso_ = params.get_float("iso", 100);
  if (!(film_iso_ > 0) || !std::isfinite(film_iso_)) params.fail("iso", "must be positive, got {}", film_iso_);
  sensor.white_balance = params.get_float("whitebalance", 0);
  if (!(sensor.white_balance == 0 || (sensor.white_balance >= 1000 && sensor.white_balance <= 100000)))
    params.fail("whitebalance", "must be 0 (none) or a colour temperature in [1000, 100000] kelvin, got {}",
                sensor.white_balance);
  if (params.has("sensor")) {
    const SourceLocation where = params.where("sensor");
    const std::string name = params.get_string("sensor", "cie1931");
    if (name != "cie1931") {
      if (!is_pbrt_camera_sensor(name))
        throw_scene_error(where, "{}: unknown sensor \"{}\" (pbrt-v4 has \"cie1931\" and the cameras {})",
                          film_name, name, pbrt_camera_sensor_list());
      // pbrt-v4 white-balances a camera's sensor to 6500 K unless told otherwise.
      if (sensor.white_balance == 0) sensor.white_balance = 6500;
      warn(where, "{}: sensor \"{}\": candela has no camera response curves; using the CIE 1931 "
           "sensor white-balanced to {} K (colours within a few percent of the camera's)", film_name, name,
           sensor.white_balance);
    }
  }
  if (params.has("maxcomponentvalue")) {
    sensor.max_component = params.get_float("maxcomponentvalue", 0);
    if (!(sensor.max_component > 0))
      params.fail("maxcomponentvalue", "must be positive, got {}", sensor.max_component);
    if (std::isinf(sensor.max_component)) sensor.max_component = 0;  // pbrt-v4's default: no limit
  }
  // pbrt-v4's HasExtension: ".exr" in any case.
  auto is_exr_name = [](const std::string& name) {
    if (name.size() <= 4) return false;
    const char* ext = name.c_str() + name.size() - 4;
    return ext[0] == '.' && (ext[1] | 0x20) == 'e' && (ext[2] | 0x20) == 'x' && (ext[3] | 0x20) == 'r';
  };
  // The gbuffer film's layers: positions, normals and dz/dx, dz/dy in camera space (pbrt-v4's
  // default) or world space; pbrt-v4 writes them to EXR files only.
  std::string film_aovs;
  if (gbuffer) {
    const SourceLocation where = params.where("coordinatesystem");
    const std::string system = params.get_string("coordinatesystem", "camera");
    if (system != "camera" && system != "world")
      throw_scene_error(where, "{}: unknown \"coordinatesystem\" \"{}\" (pbrt-v4 has \"camera\" and \"world\")",
                        film_name, system);
    film_aovs = system == "camera" ? "gbuffer" : "gbuffer,world_space";
  }
  // The spectral film's buckets: "nbuckets" equal intervals over ["lambdamin", "lambdamax"] nm,
  // within the visible range spectral transport samples (pbrt-v4's Lambda_min and Lambda_max).
  if (spectral) {
    const int buckets = params.get_int("nbuckets", 16);
    if (buckets < 1 || buckets > 1000) params.fail("nbuckets", "must be between 1 and 1000, got {}", buckets);
    const float lambda_min = params.get_float("lambdamin", cie::kLambdaMin);
    const float lambda_max = params.get_float("lambdamax", cie::kLambdaMax);
    if (!(lambda_min >= cie::kLambdaMin && lambda_min < lambda_max))
      params.fail("lambdamin", "must be at least {} nm and below \"lambdamax\" ({}), got {}", cie::kLambdaMin,
                  lambda_max, lambda_min);
    if (!(lambda_max <= cie::kLambdaMax))
      params.fail("lambdamax", "must be at most {} nm (the visible range spectral transport samples), got {}",
                  cie::kLambdaMax, lambda_max);
    film_aovs = fmt::format("spectral:{}:{}:{}", buckets, lambda_min, lambda_max);
  }
  if ((gbuffer || spectral) && !filename.empty() && !is_exr_name(filename))
    throw_scene_error(params.where("filename"), "{}: \"{}\": the {} film writes EXR files only", film_name, filename,
                      type.text);
  params.reject_unused();
  scene_.film.aovs = film_aovs;
  scene_.film.sensor = sensor;
  scene_.film.width = width;
  scene_.film.height = height;
  scene_.film.filename = filename;
}

void SceneParser::sampler(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the sampler type");
  const std::string& name = type.text;
  // pbrt-v4's other low-discrepancy samplers become candela's zsobol with the same sample count.
  bool replaced = name == "sobol" || name == "halton" || name == "pmj02bn" || name == "paddedsobol";
  if (name != "independent" && name != "stratified" && name != "zsobol" && !replaced)
    reject_type(at(type), "sampler", name,
                {"independent", "stratified", "zsobol", "sobol", "halton", "paddedsobol", "pmj02bn"}, {});
  ParamList params = read_params(d, fmt::format("Sampler \"{}\"", name));
  SamplerDesc sampler;
  int64_t spp = 0;
  if (name == "independent") {
    sampler.type = SamplerType::Independent;
    spp = params.get_int("pixelsamples", 4);
  } else if (name == "stratified") {
    // The stratified sampler takes a grid of xsamples x ysamples per pixel instead of pixelsamples.
    sampler.type = SamplerType::Stratified;
    int x = params.get_int("xsamples", 4), y = params.get_int("ysamples", 4);
    if (x < 1) params.fail("xsamples", "must be positive, got {}", x);
    if (y < 1) params.fail("ysamples", "must be positive, got {}", y);
    sampler.jitter = params.get_bool("jitter", true);
    spp = int64_t{x} * y;
    if (spp > INT_MAX) params.fail("ysamples", "makes {} samples per pixel, too many", spp);
  } else {
    sampler.type = SamplerType::ZSobol;
    spp = params.get_int("pixelsamples", 16);
    // candela's ZSobol is always Owen-scrambled; the other choices only change the sample pattern.
    if (name != "pmj02bn") {
      std::string randomization = params.get_string("randomization", "fastowen");
      if (randomization != "none" && randomization != "permutedigits" && randomization != "fastowen" &&
          randomization != "owen")
        params.fail("randomization", "must be \"none\", \"permutedigits\", \"fastowen\" or \"owen\", got \"{}\"",
                    randomization);
    }
  }
  if (spp < 1) params.fail("pixelsamples", "must be positive, got {}", spp);
  int seed = params.get_int("seed", 0);
  if (seed < 0) params.fail("seed", "must not be negative, got {}", seed);
  params.reject_unused();
  if (name == "sobol")
    warn(at(type), "sobol: using candela's zsobol sampler (same Owen-scrambled Sobol' points, Morton-ordered)");
  else if (replaced)
    warn(at(type), "{}: using candela's zsobol sampler (Owen-scrambled Sobol' points, Morton-ordered; the same "
         "number of samples, a different pattern)", name);
  options_.sampler = sampler;
  // Metropolis light transport counts mutations per pixel (its own parameter), not pixel samples.
  if (options_.integrator != "mlt") options_.spp = static_cast<int>(spp);
  if (params.has("seed")) options_.seed = static_cast<uint64_t>(seed);
}

// pbrt-v4's path, volpath, bdpt, mlt and sppm are rendered with candela's integrator of that name,
// ambientocclusion with its ambient_occlusion and lightpath with its light_path; the others with the one that converges to the same
// image (volpath for simplevolpath, path for the rest), at the scene's "maxdepth". Parameters candela
// has no use for are accepted with a warning.
void SceneParser::integrator(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the integrator type");
  static const std::map<std::string, std::vector<std::string_view>, std::less<>> kOwnParameters = {
      {"path", {}},
      {"volpath", {}},
      {"bdpt", {"visualizestrategies", "visualizeweights"}},
      {"mlt", {"bootstrapsamples", "chains", "mutationsperpixel", "largestepprobability", "sigma"}},
      {"sppm", {"photonsperiteration", "radius", "seed"}},
      {"lightpath", {}},
      {"randomwalk", {}},
      {"simplepath", {"samplelights", "samplebsdf"}},
      {"simplevolpath", {}},
  };
  // Ambient occlusion reads its own two parameters and no "maxdepth" (pbrt-v4 rejects that as unused).
  if (type.text == "ambientocclusion") {
    ParamList params = read_params(d, "Integrator \"ambientocclusion\"");
    AmbientOcclusionSettings ao;
    ao.cosine_sampling = params.get_bool("cossample", ao.cosine_sampling);
    ao.max_distance = params.get_float("maxdistance", ao.max_distance);
    if (!(ao.max_distance > 0)) params.fail("maxdistance", "must be positive, got {}", ao.max_distance);
    params.reject_unused();
    options_.integrator = "ambient_occlusion";
    options_.integrator_given = true;
    options_.ambient_occlusion = ao;
    return;
  }
  auto known = kOwnParameters.find(type.text);
  if (known == kOwnParameters.end())
    reject_type(at(type), "integrator", type.text,
                {"path", "volpath", "bdpt", "mlt", "sppm", "lightpath", "randomwalk",
                 "simplepath", "simplevolpath", "ambientocclusion"},
                {});
  ParamList params = read_params(d, fmt::format("Integrator \"{}\"", type.text));
  int max_depth = params.get_int("maxdepth", 5);
  if (max_depth < 0) params.fail("maxdepth", "must not be negative, got {}", max_depth);
  if (type.text == "path" || type.text == "volpath" || type.text == "bdpt")
    read_light_sampler(params, type.text == "bdpt" ? "power" : "bvh");
  if (type.text == "path" || type.text == "volpath" || type.text == "bdpt" || type.text == "mlt") {
    if (params.get_bool("regularize", false))
      warn(params.where("regularize"), "Integrator \"{}\": \"regularize\" is ignored: candela does not roughen "
           "near-specular surfaces (the image keeps the caustics pbrt would blur)", type.text);
  }
  std::string integrator = "path";
  if (type.text == "bdpt") {
    integrator = "bdpt";
    for (std::string_view name : known->second)
      ignore_param(params, name, "use candela's --bdpt-strategies DIR (and --bdpt-unweighted) instead");
  } else if (type.text == "mlt") {
    integrator = "mlt";
    int mutations = params.get_int("mutationsperpixel", 100);
    if (mutations < 1) params.fail("mutationsperpixel", "must be positive, got {}", mutations);
    int bootstrap = params.get_int("bootstrapsamples", 100000);
    if (bootstrap < 1) params.fail("bootstrapsamples", "must be positive, got {}", bootstrap);
    int chains = params.get_int("chains", 1000);
    if (chains < 1) params.fail("chains", "must be positive, got {}", chains);
    float large_step = params.get_float("largestepprobability", 0.3f);
    if (!(large_step >= 0 && large_step <= 1))
      params.fail("largestepprobability", "must be in [0, 1], got {}", large_step);
    float sigma = params.get_float("sigma", 0.01f);
    if (!(sigma > 0 && sigma <= 1)) params.fail("sigma", "must be in (0, 1], got {}", sigma);
    options_.spp = mutations;
    options_.mlt = RenderDirectives::Metropolis{bootstrap, chains, large_step, sigma};
  } else if (type.text == "sppm") {
    // Stochastic progressive photon mapping: pbrt-v4's -1 photons per iteration is one per pixel
    // (candela's 0); its "seed" seeds candela's whole render, as the sampler's does.
    integrator = "sppm";
    const int photons = params.get_int("photonsperiteration", -1);
    if (photons == 0 || photons < -1) params.fail("photonsperiteration", "must be positive or -1, got {}", photons);
    options_.sppm.photons_per_iteration = photons > 0 ? photons : 0;
    options_.sppm.radius = params.get_float("radius", 1.0f);
    if (!(options_.sppm.radius > 0 && std::isfinite(options_.sppm.radius)))
      params.fail("radius", "must be positive, got {}", options_.sppm.radius);
    if (params.has("seed")) {
      const int seed = params.get_int("seed", 0);
      if (seed < 0) params.fail("seed", "must not be negative, got {}", seed);
      options_.seed = static_cast<uint64_t>(seed);
    }
  } else if (type.text == "lightpath") {
    // pbrt-v4's light tracer is candela's light_path (the same estimator: its image, black where the
    // camera sees glass, mirrors, emitters or the sky).
    integrator = "light_path";
  } else {
    if (type.text == "volpath" || type.text == "simplevolpath") integrator = "volpath";
    for (std::string_view name : known->second)
      ignore_param(params, name, fmt::format("candela's {} integrator has no such setting", integrator));
  }
  params.reject_unused();
  if (type.text != integrator && type.text != "lightpath" && type.text != "sppm")
    warn(at(type), "Integrator \"{}\": using candela's {} integrator with maxdepth {} (it converges to the "
         "same image, with different noise)", type.text, integrator, max_depth);
  options_.integrator = integrator;
  options_.integrator_given = true;
  options_.max_depth = max_depth;
}

// pbrt's "power" and its default "bvh" (a light BVH weighing each light by power, distance and
// orientation from the shading point) are candela's LightSelection::Power and ::Bvh. The default is
// "bvh" but for pbrt-v4's BDPT ("power").
void SceneParser::read_light_sampler(ParamList& params, const char* default_sampler) {
  std::string light_sampler = params.get_string("lightsampler", default_sampler);
  if (light_sampler == "uniform" || light_sampler == "exhaustive")
    params.fail("lightsampler", "\"{}\" is not supported yet (supported: \"power\", \"bvh\")", light_sampler);
  if (light_sampler != "bvh" && light_sampler != "power")
    params.fail("lightsampler", "must be \"bvh\", \"power\", \"uniform\" or \"exhaustive\", got \"{}\"",
                light_sampler);
  options_.light_sampler = light_sampler == "bvh" ? LightSelection::Bvh : LightSelection::Power;
}

void SceneParser::pixel_filter(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the filter type");
  FilterDesc filter;
  if (type.text == "box")
    filter = default_filter(FilterType::Box);
  else if (type.text == "triangle")
    filter = default_filter(FilterType::Tent);
  else if (type.text == "gaussian")
    filter = default_filter(FilterType::Gaussian);
  else if (type.text == "mitchell")
    filter = default_filter(FilterType::Mitchell);
  else if (type.text == "sinc")
    filter = default_filter(FilterType::LanczosSinc);
  else
    reject_type(at(type), "pixel filter", type.text, {"box", "triangle", "gaussian", "mitchell", "sinc"}, {});
  ParamList params = read_params(d, fmt::format("PixelFilter \"{}\"", type.text));
  filter.radius = {params.get_float("xradius", filter.radius.x), params.get_float("yradius", filter.radius.y)};
  for (auto [name, radius] : {std::pair{"xradius", filter.radius.x}, std::pair{"yradius", filter.radius.y}})
    if (!(radius > 0 && radius <= kMaxFilterRadius))
      params.fail(name, "must be in (0, {}] pixels, got {}", kMaxFilterRadius, radius);
  if (filter.type == FilterType::Gaussian) {
    filter.gaussian_sigma = params.get_float("sigma", filter.gaussian_sigma);
    if (!(filter.gaussian_sigma > 0)) params.fail("sigma", "must be positive, got {}", filter.gaussian_sigma);
  }
  if (filter.type == FilterType::Mitchell) {
    filter.mitchell_b = params.get_float("B", filter.mitchell_b);
    filter.mitchell_c = params.get_float("C", filter.mitchell_c);
  }
  if (filter.type == FilterType::LanczosSinc) {
    filter.sinc_tau = params.get_float("tau", filter.sinc_tau);
    if (!(filter.sinc_tau > 0)) params.fail("tau", "must be positive, got {}", filter.sinc_tau);
  }
  params.reject_unused();
  options_.filter = filter;
}

void SceneParser::option(const Token& d) {
  expect_string(d, "the option name");
  Token value = tokens_->next();
  if (value.kind != TokenKind::Word && value.kind != TokenKind::String)
    throw_scene_error(at(value), "Option: expected a value, got {}", describe(value));
}

void SceneParser::color_space(const Token& d) {
  Token name = expect_string(d, "the colour space name");
  if (name.text != "srgb")
    warn(at(name), "ColorSpace \"{}\" is ignored: candela reads every colour as linear sRGB (Rec. 709 primaries)",
         name.text);
}

// The acceleration structure is Embree's whatever pbrt's choice; the image does not depend on it.
void SceneParser::accelerator(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the accelerator type");
  if (type.text != "bvh" && type.text != "kdtree")
    reject_type(at(type), "accelerator", type.text, {"bvh", "kdtree"}, {});
  read_params(d, fmt::format("Accelerator \"{}\"", type.text));  // its parameters only tune the structure
}


// The one place that writes RenderSettings: what the directives above chose, or pbrt-v4's defaults.
void SceneParser::write_render_settings(RenderSettings& settings) const {
  settings.spp = options_.spp;
  settings.sampler = options_.sampler;
  if (options_.seed) settings.seed = *options_.seed;
  settings.filter = options_.filter;
  settings.max_depth = options_.max_depth;
  // pbrt-v4's default integrator is volpath; candela's path tracer is the same for scenes without
  // media, and faster.
  settings.integrator = !options_.integrator_given && !scene_.media.empty() ? "volpath" : options_.integrator;
  settings.spectral = true;  // pbrt-v4 renders spectrally; RGB parameters become spectra as there
  // pbrt-v4's default integrator (volpath) chooses lights with its BVH.
  if (options_.light_sampler) settings.light_selection = *options_.light_sampler;
  else if (!options_.integrator_given) settings.light_selection = LightSelection::Bvh;
  settings.ambient_occlusion = options_.ambient_occlusion;
  settings.sppm = options_.sppm;
  if (options_.mlt) {
    settings.mlt.bootstrap = options_.mlt->bootstrap;
    settings.mlt.chains = options_.mlt->chains;
    settings.mlt.large_step = options_.mlt->large_step;
    settings.mlt.sigma = options_.mlt->sigma;
  }
}

}  // namespace candela::pbrt
