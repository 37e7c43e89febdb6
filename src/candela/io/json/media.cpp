// The "media" section (participating media), and the media that shapes and the camera name.
#include <cmath>
#include <limits>
#include <memory>

#include "candela/geometry/sdf_grid.h"
#include "candela/io/grid_files.h"
#include "candela/io/json/reader.h"
#include "candela/media/medium.h"

namespace candela::json {

void JsonSceneReader::read_media(const Json& value, const std::string& pointer) {
  if (!value.is_object())
    report_.fail(pointer, "expected an object mapping medium names to media, got {}", describe(value));
  for (auto it = value.begin(); it != value.end(); ++it) {
    if (it.key() == "_comment") continue;
    const std::string medium_pointer = child_pointer(pointer, it.key());
    MediumDesc medium = read_medium(it.value(), medium_pointer);
    medium.name = it.key();
    medium.where = place(medium_pointer);
    medium_index_[it.key()] = int(scene_.media.size());
    scene_.media.push_back(std::move(medium));
  }
}

// "homogeneous": the same coefficients everywhere. "grid": a density (and optionally an albedo) that
// varies over a grid's box, or a procedural cloud's density over its box; the medium has no density
// outside the density's box. The fields
// are the medium's schema (description/media.h); "sigma_a" and "sigma_s" are another way to give
// sigma_t and the albedo.
MediumDesc JsonSceneReader::read_medium(const Json& value, const std::string& pointer) {
  CheckedObject m(report_, value, pointer);
  static constexpr std::string_view kTypes[] = {"homogeneous", "grid"};
  const std::string type = m.string("type");
  if (type != kTypes[0] && type != kTypes[1])
    report_.fail(m.pointer_of("type"), "unknown medium type \"{}\"{}; expected one of: {}", type,
                 did_you_mean(type, kTypes), fmt::join(kTypes, ", "));
  const bool grid = type == "grid";

  MediumDesc medium;
  const bool absorption_scattering = m.has("sigma_a") || m.has("sigma_s");
  const bool extinction_albedo = m.has("sigma_t") || m.has("albedo");
  if (absorption_scattering && extinction_albedo)
    report_.fail(pointer, "a medium takes \"sigma_a\" and \"sigma_s\", or \"sigma_t\" and \"albedo\", not both");
  if (!absorption_scattering && !extinction_albedo)
    report_.fail(pointer, "a medium needs its coefficients: \"sigma_a\" and \"sigma_s\", or \"sigma_t\" and "
                 "\"albedo\"");
  if (absorption_scattering)
    set_sigma_a_sigma_s(medium, m.rgb_or("sigma_a", ColorKind::NonNegative, RGB(0.0f)),
                        m.rgb_or("sigma_s", ColorKind::NonNegative, RGB(0.0f)));
  if (!grid)
    for (std::string_view key : {"albedo", "density"})
      if (const Json* given = m.find(key); given && given->is_object())
        report_.fail(m.pointer_of(key), "a homogeneous medium's {} is a constant; a grid of {} needs type \"grid\"", key, key);
  if (grid) m.require("density");
  const TypeSchema& schema = SchemaOf<MediumDesc>::schema;
  read_fields(m, schema, &medium);
  check_fields(m, schema, &medium);
  m.finish();
  // The keys were checked one by one above; this is the renderer's own account of what it can render,
  // so that the two cannot drift apart.
  if (std::string problem = medium_problem(medium); !problem.empty()) report_.fail(pointer, "{}", problem);
  return medium;
}

// A grid of values over the unit cube of its space, which "transform" places: a Mitsuba .vol file, an
// OpenVDB or NanoVDB grid, or the samples inline; or, for a density, pbrt-v4's procedural "cloud". `what` is "density" or "emission_scale" (1 channel,
// values >= 0), "temperature" (1 channel, finite values) or "albedo" (1 or 3 channels, values in [0, 1]).
VolumeDesc JsonSceneReader::read_volume(const Json& value, const std::string& pointer, std::string_view what) const {
  CheckedObject v(report_, value, pointer);
  // pbrt-v4's procedural cloud (CloudDensity) instead of samples: its parameters and its box in the
  // cloud's own space, which "transform" places; the volume's unit cube is that box.
  if (const Json* cloud_value = v.find("cloud")) {
    if (what != "density")
      report_.fail(v.pointer_of("cloud"), "only a medium's density may be a procedural cloud, not its {}", what);
    CheckedObject c(report_, *cloud_value, v.pointer_of("cloud"));
    CloudDensity cloud;
    cloud.density = c.number_or("density", cloud.density);
    cloud.wispiness = c.number_or("wispiness", cloud.wispiness);
    cloud.frequency = c.number_or("frequency", cloud.frequency);
    cloud.box_min = c.vec3_or("min", cloud.box_min);
    cloud.box_max = c.vec3_or("max", cloud.box_max);
    if (!(cloud.box_max.x > cloud.box_min.x && cloud.box_max.y > cloud.box_min.y && cloud.box_max.z > cloud.box_min.z))
      report_.fail(c.has("max") ? c.pointer_of("max") : c.pointer(),
                   "the cloud's box must have volume: \"max\" ({}, {}, {}) must exceed \"min\" ({}, {}, {}) on every "
                   "axis", cloud.box_max.x, cloud.box_max.y, cloud.box_max.z, cloud.box_min.x, cloud.box_min.y,
                   cloud.box_min.z);
    c.finish();
    VolumeDesc volume;
    volume.to_world = read_transform_key(v) * cloud.unit_cube_to_cloud();
    volume.cloud = cloud;
    v.finish();
    return volume;
  }
  const bool is_albedo = what == "albedo", is_temperature = what == "temperature";
  const bool from_file = v.has("filename");
  const bool inline_data = v.has("resolution") || v.has("values") || v.has("channels");
  if (from_file == inline_data)
    report_.fail(pointer, "a grid takes either \"filename\" or inline \"resolution\" and \"values\", {}",
                 from_file ? "not both" : "and has neither");
  auto check_channels = [&](int channels, const std::string& at, const std::string& source) {
    if (is_albedo ? channels != 1 && channels != 3 : channels != 1)
      report_.fail(at, "{} has {} channels; {} needs {}", source, channels, what, is_albedo ? "1 or 3" : "1");
  };
  VolumeDesc volume;
  std::vector<float> values;
  std::string values_pointer;  // where a bad value is reported: the file name, or the inline values
  if (from_file) {
    values_pointer = v.pointer_of("filename");
    volume.filename = existing_file(v, "filename", "volume grid");
    // OpenVDB and NanoVDB files hold named grids; a .vol file is one grid.
    VolumeDesc file = read_grid_file(volume.filename, v.string_or("grid", std::string(what)),
                                     report_.location(values_pointer));
    volume.grid_name = file.grid_name;
    volume.resolution = file.resolution;
    volume.channels = file.channels;
    volume.file_to_world = file.file_to_world;
    volume.border = file.border;
    check_channels(volume.channels, values_pointer, fmt::format("volume grid '{}'", volume.filename));
    values = *file.values;
  } else {
    const Json& resolution = v.require("resolution");
    const std::string resolution_pointer = v.pointer_of("resolution");
    if (!resolution.is_array() || resolution.size() != 3)
      report_.fail(resolution_pointer, "expected an array of 3 integers, got {}", describe(resolution));
    for (size_t i = 0; i < 3; ++i) {
      const int64_t n = read_int64(report_, resolution[i], child_pointer(resolution_pointer, i));
      if (n < 1 || n > std::numeric_limits<int>::max())
        report_.fail(child_pointer(resolution_pointer, i), "expected an integer >= 1, got {}", n);
      volume.resolution[i] = int(n);
    }
    volume.channels = v.integer_or("channels", 1, 1, 3);
    check_channels(volume.channels, v.pointer_of("channels"), "the grid");
    const Json& samples = v.require("values");
    values_pointer = v.pointer_of("values");
    check_is_array(report_, samples, values_pointer, "grid values");
    const double expected =
        double(volume.resolution[0]) * volume.resolution[1] * volume.resolution[2] * volume.channels;
    if (double(samples.size()) != expected)
      report_.fail(values_pointer, "expected {} values ({} x {} x {} samples of {} channel{}, x fastest, then y, "
                   "then z), got {}", expected, volume.resolution[0], volume.resolution[1], volume.resolution[2],
                   volume.channels, volume.channels == 1 ? "" : "s", samples.size());
    values.resize(samples.size());
    for (size_t k = 0; k < samples.size(); ++k) values[k] = read_float_element(report_, samples, k, values_pointer);
  }
  const float max_value = is_albedo ? 1.0f : std::numeric_limits<float>::max();
  const float min_value = is_temperature ? -std::numeric_limits<float>::max() : 0.0f;
  const std::string in_file = from_file ? fmt::format(" in '{}'", volume.filename) : std::string();
  for (size_t k = 0; k < values.size(); ++k)
    if (!(values[k] >= min_value && values[k] <= max_value))
      report_.fail(from_file ? values_pointer : child_pointer(values_pointer, k), "{} value {} (number {}{}) must be {}",
                   what, values[k], k, in_file, is_albedo ? "in [0, 1]" : is_temperature ? "finite" : "finite and >= 0");
  volume.values = std::make_shared<const std::vector<float>>(std::move(values));
  volume.to_world = read_transform_key(v) * volume.file_to_world;
  if (const Json* border = v.find("border"))
    volume.border = read_enum<VolumeBorder>(report_, *border, v.pointer_of("border"), "grid border");
  v.finish();
  return volume;
}

int JsonSceneReader::medium_by_name(const std::string& name, const std::string& pointer) const {
  auto it = medium_index_.find(name);
  if (it != medium_index_.end()) return it->second;
  std::vector<std::string> names;
  for (const auto& entry : medium_index_) names.push_back(entry.first);
  if (names.empty()) report_.fail(pointer, "unknown medium \"{}\" (\"media\" defines none)", name);
  report_.fail(pointer, "unknown medium \"{}\"; defined: {}", name, fmt::join(names, ", "));
}

// The medium named by `key` (-1, the vacuum, when it is absent).
int JsonSceneReader::medium_reference(CheckedObject& object, std::string_view key) const {
  return object.has(key) ? medium_by_name(object.string(key), object.pointer_of(key)) : -1;
}

}  // namespace candela::json
