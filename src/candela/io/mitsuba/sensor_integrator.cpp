// The Mitsuba converter: sensor, film, reconstruction filter, sampler and integrator.
#include "candela/io/mitsuba/converter.h"

#include <algorithm>
#include <cmath>

namespace candela::mitsuba {

namespace {

float diagonal_fov_from_focal_length(double mm) {
  return float(2 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2 * mm)) * 180 / 3.14159265358979);
}

}  // namespace

// ---------------------------------------------------------------- sensor, film, sampler, integrator

FilterDesc Converter::gaussian_filter(float stddev) {
  FilterDesc f;
  f.type = FilterType::Gaussian;
  f.gaussian_sigma = stddev;
  f.radius = {4 * stddev, 4 * stddev};  // Mitsuba truncates its gaussian at 4 standard deviations
  return f;
}

void Converter::sensor(const Object& s) {
  CameraDesc& cam = desc_.camera;
  Transform to_world = get_transform(s, "to_world");
  // Mitsuba's camera space has +x to the image's left; candela's to its right.
  cam.world_from_camera = to_world * Transform::scale({-1, 1, 1});
  cam.near_clip = get_float(s, "near_clip", 0.01f);
  float far_clip = get_float(s, "far_clip", 10000.0f);
  if (!(cam.near_clip > 0) || !(far_clip > cam.near_clip))
    throw_scene_error(s.where.loc(), "{}: needs 0 < near_clip < far_clip", s.describe());
  if (far_clip < 1e3f * 0.999f)
    warn(s.where, "{}: far_clip {} is ignored: candela sees everything beyond near_clip", s.describe(), far_clip);
  for (const char* name : {"principal_point_offset_x", "principal_point_offset_y"})
    if (get_float(s, name, 0) != 0)
      throw_scene_error(s.where.loc(), "{}: {} is not supported", s.describe(), name);
  auto media = nested(s, "medium");
  if (media.size() > 1) throw_scene_error(media[1].first->where.loc(), "{}: more than one medium", s.describe());
  if (!media.empty()) cam.medium = medium(*media[0].second);
  ignore(s, "shutter_open");
  ignore(s, "shutter_close");
  ignore(s, "srf", nullptr);
  if (s.type == "perspective" || s.type == "thinlens") {
    cam.projection = Projection::Perspective;
    std::string axis = get_string(s, "fov_axis", "x");
    if (axis == "x") cam.fov_axis = FovAxis::X;
    else if (axis == "y") cam.fov_axis = FovAxis::Y;
    else if (axis == "diagonal") cam.fov_axis = FovAxis::Diagonal;
    else if (axis == "smaller") cam.fov_axis = FovAxis::Smaller;
    else if (axis == "larger") cam.fov_axis = FovAxis::Larger;
    else throw_scene_error(s.where.loc(), "{}: fov_axis \"{}\" (use x, y, diagonal, smaller or larger)",
                           s.describe(), axis);
    const Property* fov = find(s, "fov");
    std::string focal = get_string(s, "focal_length", "");
    if (fov && !focal.empty()) throw_scene_error(s.where.loc(), "{}: give either fov or focal_length", s.describe());
    if (fov) {
      cam.fov_degrees = get_float(s, "fov", 0);
    } else {
      if (focal.empty()) focal = "50mm";
      std::string digits = focal.ends_with("mm") ? focal.substr(0, focal.size() - 2) : focal;
      std::optional<double> mm = parse_double(digits);
      if (!mm || !(*mm > 0)) throw_scene_error(s.where.loc(), "{}: focal_length \"{}\"", s.describe(), focal);
      // Mitsuba: the 35 mm film equivalent, on the film's diagonal.
      cam.fov_degrees = diagonal_fov_from_focal_length(*mm);
      cam.fov_axis = FovAxis::Diagonal;
    }
    if (!(cam.fov_degrees > 0 && cam.fov_degrees < 180))
      throw_scene_error(s.where.loc(), "{}: fov must be in (0, 180)", s.describe());
    if (s.type == "thinlens") {
      cam.lens_radius = get_float(s, "aperture_radius", 1.0f);
      cam.focus_distance = get_float(s, "focus_distance", 0);
      if (!(cam.focus_distance > 0)) throw_scene_error(s.where.loc(), "thinlens: focus_distance is required");
    }
  } else if (s.type == "orthographic") {
    cam.projection = Projection::Orthographic;
  } else {
    unknown_type(s, "sensor", s.type, {"perspective", "thinlens", "orthographic"});
  }
  for (auto& [prop, o] : nested(s, "film")) film(*o);
  for (auto& [prop, o] : nested(s, "sampler")) sampler(*o);
  check_all_used(s);
}

void Converter::film(const Object& f) {
  if (f.type != "hdrfilm" && f.type != "specfilm")
    unknown_type(f, "film", f.type, {"hdrfilm", "specfilm"});
  desc_.film.width = get_int(f, "width", 768);
  desc_.film.height = get_int(f, "height", 576);
  if (desc_.film.width <= 0 || desc_.film.height <= 0 || desc_.film.width > 65536 || desc_.film.height > 65536)
    throw_scene_error(f.where.loc(), "hdrfilm: width and height must be in 1..65536");
  int cx = get_int(f, "crop_offset_x", 0), cy = get_int(f, "crop_offset_y", 0);
  int cw = get_int(f, "crop_width", desc_.film.width), ch = get_int(f, "crop_height", desc_.film.height);
  if (cx != 0 || cy != 0 || cw != desc_.film.width || ch != desc_.film.height)
    throw_scene_error(f.where.loc(), "hdrfilm: crop windows are not supported");
  std::string pixel_format = get_string(f, "pixel_format", "rgb");
  if (pixel_format != "rgb" && pixel_format != "rgba")
    warn(f.where, "hdrfilm: pixel_format \"{}\" is written as RGB", pixel_format);
  ignore(f, "component_format");
  ignore(f, "file_format");
  ignore(f, "banner");
  ignore(f, "rfilter");
  ignore(f, "compensate");
  ignore(f, "sample_border");
  for (auto& [prop, o] : nested(f, "rfilter")) rfilter(*o);
  check_all_used(f);
}

void Converter::rfilter(const Object& r) {
  FilterDesc& f = desc_.settings.filter;
  if (r.type == "box") {
    f = default_filter(FilterType::Box);
    float radius = get_float(r, "radius", 0.5f);
    f.radius = {radius, radius};
  } else if (r.type == "gaussian") {
    f = gaussian_filter(get_float(r, "stddev", 0.5f));
  } else if (r.type == "tent") {
    f = default_filter(FilterType::Tent);
    float radius = get_float(r, "radius", 1.0f);
    f.radius = {radius, radius};
  } else if (r.type == "mitchell" || r.type == "catmullrom") {
    f = default_filter(FilterType::Mitchell);
    f.mitchell_b = get_float(r, "B", r.type == "mitchell" ? 1.0f / 3 : 0.0f);
    f.mitchell_c = get_float(r, "C", r.type == "mitchell" ? 1.0f / 3 : 0.5f);
    f.radius = {2, 2};
  } else if (r.type == "lanczos") {
    // Mitsuba's lanczos: sinc(x) sinc(x / lobes) out to `lobes` pixels.
    f = default_filter(FilterType::LanczosSinc);
    int lobes = get_int(r, "lobes", 3);
    if (lobes < 1 || lobes > int(kMaxFilterRadius))
      throw_scene_error(r.where.loc(), "{}: lobes must be in [1, {}], got {}", r.describe(), int(kMaxFilterRadius),
                        lobes);
    f.sinc_tau = float(lobes);
    f.radius = {float(lobes), float(lobes)};
  } else {
    unknown_type(r, "rfilter", r.type, {"box", "gaussian", "tent", "mitchell", "catmullrom", "lanczos"});
  }
  check_all_used(r);
}

void Converter::sampler(const Object& s) {
  RenderSettings& rs = desc_.settings;
  rs.spp = get_int(s, "sample_count", 4);
  if (rs.spp <= 0) throw_scene_error(s.where.loc(), "sampler: sample_count must be positive");
  rs.seed = uint64_t(get_int(s, "seed", 0));
  if (s.type == "independent") {
    rs.sampler.type = SamplerType::Independent;
  } else if (s.type == "stratified" || s.type == "multijitter" || s.type == "orthogonal") {
    rs.sampler.type = SamplerType::Stratified;
    rs.sampler.jitter = get_bool(s, "jitter", true);
    if (s.type == "orthogonal") ignore(s, "strength");
    warn(s.where, "sampler \"{}\": using candela's stratified sampler", s.type);
  } else if (s.type == "ldsampler") {
    rs.sampler.type = SamplerType::ZSobol;
    warn(s.where, "sampler \"ldsampler\": using candela's zsobol sampler");
  } else {
    unknown_type(s, "sampler", s.type, {"independent", "stratified", "multijitter", "orthogonal", "ldsampler"});
  }
  check_all_used(s);
}

// Mitsuba's max_depth counts path segments (1: emitters seen directly, 2: direct lighting);
// candela's counts scattering events.
int Converter::candela_depth(int mitsuba_depth) {
  if (mitsuba_depth < 0) return kUnboundedDepth;
  return std::max(0, mitsuba_depth - 1);
}

void Converter::integrator(const Object& i) {
  RenderSettings& rs = desc_.settings;
  if (i.type == "moment") {
    auto inner = nested(i, "integrator");
    if (inner.size() != 1) throw_scene_error(i.where.loc(), "moment needs one nested integrator");
    warn(i.where, "integrator \"moment\": rendering its nested integrator (candela's film keeps the second moments)");
    check_all_used(i);
    integrator(*inner[0].second);
    return;
  }
  if (i.type == "path" || i.type == "ptracer" || i.type == "volpath" || i.type == "volpathmis") {
    // A particle tracer's strength, paths from the lights connected to the camera, is BDPT's
    // t = 1 strategy: BDPT renders ptracer scenes with it (and the other strategies, under MIS).
    // volpath and volpathmis (the same expectation; candela's volpath always does spectral MIS).
    rs.integrator = i.type == "ptracer" ? "bdpt" : i.type == "path" ? "path" : "volpath";
    rs.max_depth = candela_depth(get_int(i, "max_depth", -1));
    // Russian roulette from the rr_depth-th bounce on: path.cpp tests depth >= rr_depth after counting
    // the bounce, volpath.cpp depth > rr_depth at the top of its loop, one bounce later.
    // (max(2, rr) - 1, not max(1, rr - 1): rr - 1 overflows at INT_MIN.)
    int rr = get_int(i, "rr_depth", 5);
    rs.rr_start_depth = rs.integrator == "volpath" ? std::max(1, rr) : std::max(2, rr) - 1;
    rs.hide_emitters = get_bool(i, "hide_emitters", false);
    if (i.type == "ptracer")
      warn(i.where, "integrator \"ptracer\": rendering with candela's bidirectional path tracer (the same expectation)");
    ignore(i, "samples_per_pass");
  } else if (i.type == "direct") {
    rs.integrator = "path";
    rs.max_depth = 1;
    int es = get_int(i, "emitter_samples", get_int(i, "shading_samples", 1));
    int bs = get_int(i, "bsdf_samples", find(i, "shading_samples") ? es : 1);
    if (es != 1 || bs != 1)
      warn(i.where, "integrator \"direct\": emitter_samples/bsdf_samples are ignored (one of each, with MIS)");
    rs.hide_emitters = get_bool(i, "hide_emitters", false);
  } else {
    unknown_type(i, "integrator", i.type, {"path", "volpath", "volpathmis", "direct", "ptracer", "moment"});
  }
  check_all_used(i);
}

}  // namespace candela::mitsuba
