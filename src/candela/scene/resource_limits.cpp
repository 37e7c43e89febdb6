#include "candela/scene/resource_limits.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <variant>

#include "candela/film/film.h"
#include "candela/film/image_io.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/base/error.h"
#include "candela/base/overloaded.h"
#include "candela/lights/light.h"

namespace candela {
namespace {

constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();

uint64_t add(uint64_t a, uint64_t b) {
  uint64_t r;
  return __builtin_add_overflow(a, b, &r) ? kMax : r;
}
uint64_t mul(uint64_t a, uint64_t b) {
  uint64_t r;
  return __builtin_mul_overflow(a, b, &r) ? kMax : r;
}
uint64_t non_negative(int64_t v) { return v < 0 ? 0 : uint64_t(v); }

// ---------------------------------------------------------------- film

constexpr uint64_t kOutputBytesPerPixel = 3 * sizeof(float) + 3;  // the mean Image and an 8-bit copy for PNG
// The renderer's per-pixel masks, counts, errors and smoothing buffers.
constexpr uint64_t kAdaptiveBytesPerPixel = 2 * sizeof(uint8_t) + sizeof(int) + sizeof(uint64_t) + 6 * sizeof(double);

uint64_t film_pixels(const FilmDesc& film) { return mul(non_negative(film.width), non_negative(film.height)); }

uint64_t film_bytes(const SceneDesc& desc) {
  uint64_t per_pixel = sizeof(PixelSums) + kOutputBytesPerPixel;
  if (desc.settings.adaptive()) per_pixel += kAdaptiveBytesPerPixel;
  return mul(film_pixels(desc.film), per_pixel);
}

// ---------------------------------------------------------------- shapes

struct ShapeCost {
  uint64_t bytes = 0;
  uint64_t triangles = 0;
};

ShapeCost triangle_cost(uint64_t vertices, uint64_t triangles, bool normals, bool uvs, bool moving, bool emissive) {
  const uint64_t steps = moving ? 2 : 1;
  uint64_t per_vertex = mul(steps, sizeof(Point3) + (normals ? sizeof(Normal3) : 0));  // ShapeRecord
  if (uvs) per_vertex += sizeof(Vec2);
  per_vertex += steps * sizeof(Point3);  // Embree's vertex buffer per time step
  uint64_t per_triangle = 3 * sizeof(uint32_t) * 2;  // ShapeRecord and Embree index buffers
  per_triangle += steps * kEmbreeBvhBytesPerTriangle;
  if (emissive) per_triangle += sizeof(Light) + 2 * sizeof(float);  // a light each, and its distribution entry
  return {add(add(mul(vertices, per_vertex), mul(triangles, per_triangle)), kBytesPerSimpleShape), triangles};
}

ShapeCost shape_cost(const ShapeDesc& shape) {
  const bool moving = shape.to_world_end.has_value();
  const bool emissive = shape.emission.has_value();
  const ShapeCost simple{kBytesPerSimpleShape, 0};
  return std::visit(
      overloaded{[&](const MeshShape& mesh) {
                   const TriangleMesh& m = mesh.mesh;
                   return triangle_cost(m.positions.size(), m.triangle_count(), !m.normals.empty(), !m.uvs.empty(),
                                        moving, emissive);
                 },
                 [&](const BoxShape&) { return triangle_cost(24, 12, true, true, moving, emissive); },
                 [&](const RectangleShape&) { return triangle_cost(4, 2, true, true, moving, emissive); },
                 [&](const SdfGridShape& sdf) {
                   // The grid's values are the SceneDesc's own (shared); each voxel holding surface adds its
                   // index and a BVH leaf, as a triangle would.
                   const uint64_t voxels = count_surface_voxels(sdf);
                   return ShapeCost{add(mul(voxels, sizeof(uint32_t) + (moving ? 2 : 1) * kEmbreeBvhBytesPerTriangle),
                                        kBytesPerSimpleShape),
                                    0};
                 },
                 [&](const CurveShape& curve) {
                   // Per segment: 4 control points of 4 floats per time step (shared with Embree where
                   // static, copied where moving), ribbons' 6 normals per step, Embree's index and a BVH leaf.
                   const uint64_t steps = moving ? 2 : 1;
                   uint64_t per_segment = steps * 16 * sizeof(float) * (moving ? 2 : 1) + sizeof(uint32_t) +
                                          steps * kEmbreeBvhBytesPerTriangle;
                   if (curve.type == CurveType::Ribbon) per_segment += steps * 10 * sizeof(Normal3);
                   return ShapeCost{add(mul(curve.segment_count(), per_segment), kBytesPerSimpleShape), 0};
                 },
                 [&](const SphereShape&) { return simple; }, [&](const PlaneShape&) { return simple; },
                 [&](const DiskShape&) { return simple; }, [&](const CylinderShape&) { return simple; }},
      shape.geometry);
}

// ---------------------------------------------------------------- images

// Bytes for one image read into a float RGB Image, from its header; 0 when it cannot be opened.
// Throws SceneError at `where` (the scene's entry naming the image) for an image larger than
// candela reads at all (film/image_io.h), whatever the memory.
uint64_t image_bytes(const std::string& filename, uint64_t extra_per_texel, const SourceLocation& where) {
  if (filename.empty()) return 0;
  try {
    check_exr_header(filename);
  } catch (const FileContentError& malformed) {
    throw_scene_error(where, "{}", malformed.what());
  }
  auto in = OIIO::ImageInput::open(filename);
  if (!in) {
    (void)OIIO::geterror();  // reading the image later reports the problem; don't leave it pending
    return 0;
  }
  const OIIO::ImageSpec& spec = in->spec();
  try {
    check_image_size(filename, spec.width, spec.height);
  } catch (const FileContentError& too_large) {
    throw_scene_error(where, "{}", too_large.what());
  }
  const uint64_t texels = mul(non_negative(spec.width), non_negative(spec.height));
  const uint64_t file_pixel = mul(non_negative(spec.nchannels), spec.format.size());
  in->close();
  return mul(texels, add(add(3 * sizeof(float), file_pixel), extra_per_texel));
}

// The image a texture reads, in memory.
uint64_t texture_image_bytes(const TextureDesc& texture, const SourceLocation& where) {
  return std::visit(overloaded{[&](const ImageTexture& image) { return image_bytes(image.filename, 0, where); },
                               // the others have no images of their own
                               [](const auto&) { return uint64_t(0); }},
                    texture);
}

// The image a light reads, in memory with its sampling distribution (an environment map's two
// floats per texel; a goniometric light's one-channel copy and its distribution, three). Spot and
// projector lights name textures, counted with the textures.
uint64_t light_image_bytes(const LightDesc& light, const SourceLocation& where) {
  return std::visit(
      overloaded{[&](const EnvironmentMap& env) { return image_bytes(env.filename, 2 * sizeof(float), where); },
                 [&](const GoniometricLight& g) { return image_bytes(g.filename, 3 * sizeof(float), where); },
                 [](const PointLight&) { return uint64_t(0); }, [](const SkyLight&) { return uint64_t(0); },
                 [](const SpotLight&) { return uint64_t(0); }, [](const DistantLight&) { return uint64_t(0); },
                 [](const ProjectorLight&) { return uint64_t(0); }},
      light);
}

}  // namespace

// ---------------------------------------------------------------- estimate and checks

MemoryEstimate estimate_memory(const SceneDesc& desc) {
  MemoryEstimate e;
  e.film_bytes = film_bytes(desc);
  uint64_t scene = 0;
  const auto count = [&](const ShapeDesc& shape) {
    const ShapeCost cost = shape_cost(shape);
    scene = add(scene, cost.bytes);
    e.triangles = add(e.triangles, cost.triangles);
  };
  for (const ShapeDesc& shape : desc.shapes) count(shape);
  for (const ObjectDesc& object : desc.objects)
    for (const ShapeDesc& shape : object.shapes) count(shape);
  scene = add(scene, mul(desc.instances.size(), kBytesPerInstance));
  scene = add(scene, mul(desc.lights.size() + desc.materials.size() + desc.textures.size(), 256));

  // Where the scene declares entry i, else the scene file.
  const auto place = [&](const std::vector<SourceLocation>& places, size_t i) {
    return i < places.size() ? places[i] : SourceLocation{desc.source_file};
  };
  for (size_t i = 0; i < desc.textures.size(); ++i)
    e.texture_bytes = add(e.texture_bytes, texture_image_bytes(desc.textures[i], place(desc.places.textures, i)));
  for (size_t i = 0; i < desc.lights.size(); ++i)
    e.texture_bytes = add(e.texture_bytes, light_image_bytes(desc.lights[i], place(desc.places.lights, i)));

  e.scene_bytes = add(scene, e.texture_bytes);
  e.total = add(e.film_bytes, e.scene_bytes);
  return e;
}

std::string format_bytes(uint64_t bytes) {
  static const char* const kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return fmt::format("{} bytes", bytes);
  double value = double(bytes) / 1024;
  int unit = 0;
  while (value >= 1024 && unit < 5) {
    value /= 1024;
    ++unit;
  }
  return fmt::format("{:.1f} {}", value, kUnits[unit]);
}

void check_resolution(const SceneDesc& desc) {
  const SourceLocation where{desc.source_file};
  const int w = desc.film.width, h = desc.film.height;
  if (w <= 0 || h <= 0) throw_scene_error(where, "the film resolution {} x {} is not positive", w, h);
  const uint64_t pixels = film_pixels(desc.film);
  if (uint64_t(w) > kMaxFilmSide || uint64_t(h) > kMaxFilmSide || pixels > kMaxFilmPixels)
    throw_scene_error(where,
                      "the film resolution {} x {} ({} pixels) is too large: candela renders at most {} pixels on a "
                      "side and {} pixels in all",
                      w, h, pixels, kMaxFilmSide, kMaxFilmPixels);
}

void check_memory(const SceneDesc& desc, uint64_t available_bytes) {
  check_resolution(desc);
  const MemoryEstimate e = estimate_memory(desc);
  if (e.total <= available_bytes) return;
  std::string scene = fmt::format("scene {}", format_bytes(e.scene_bytes));
  if (e.triangles > 0) scene += fmt::format(" for {} triangles", e.triangles);
  if (e.texture_bytes > 0) scene += fmt::format(" and {} of textures", format_bytes(e.texture_bytes));
  throw_scene_error(SourceLocation{desc.source_file},
                    "the render needs about {} (film {} for {} x {} pixels, {}) but only {} of memory is available",
                    format_bytes(e.total), format_bytes(e.film_bytes), desc.film.width, desc.film.height, scene,
                    format_bytes(available_bytes));
}

// ---------------------------------------------------------------- available memory

namespace {

std::optional<uint64_t> read_number_file(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  if (!(in >> word) || word == "max") return std::nullopt;
  try {
    size_t used = 0;
    const unsigned long long v = std::stoull(word, &used);
    if (used != word.size()) return std::nullopt;
    return uint64_t(v);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// A "Key:   123 kB" line of /proc/meminfo or /proc/self/status, in bytes.
std::optional<uint64_t> read_kb_field(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    std::istringstream fields(line.substr(key.size() + 1));
    uint64_t kb = 0;
    if (fields >> kb) return mul(kb, 1024);
  }
  return std::nullopt;
}

uint64_t limit_less_usage(std::optional<uint64_t> limit, std::optional<uint64_t> usage) {
  if (!limit) return kMax;
  const uint64_t used = usage.value_or(0);
  return *limit > used ? *limit - used : 0;
}

// The smallest limit less usage over a cgroup directory and its parents up to the mount point.
uint64_t cgroup_tree_available(const std::string& mount, std::string dir, const char* limit_file,
                               const char* usage_file) {
  uint64_t available = kMax;
  while (true) {
    const std::string base = mount + (dir == "/" ? std::string() : dir);
    available = std::min(available, limit_less_usage(read_number_file(base + "/" + limit_file),
                                                     read_number_file(base + "/" + usage_file)));
    if (dir.empty() || dir == "/") return available;
    const size_t slash = dir.find_last_of('/');
    dir = slash == 0 || slash == std::string::npos ? "/" : dir.substr(0, slash);
  }
}

// cgroup v2: memory.max less memory.current of this process's cgroup and every parent up to the
// mount point; v1: memory.limit_in_bytes less memory.usage_in_bytes the same way ("no limit" is a
// huge number there, which min() ignores naturally).
uint64_t cgroup_available() {
  std::string v2_path, v1_path;
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    // "hierarchy-id:controllers:path"; v2 has id 0 and no controllers.
    const size_t first = line.find(':'), second = first == std::string::npos ? first : line.find(':', first + 1);
    if (second == std::string::npos) continue;
    std::string controllers = ",";
    controllers.append(line, first + 1, second - first - 1).append(",");
    const std::string path = line.substr(second + 1);
    if (line.rfind("0::", 0) == 0) v2_path = path;
    else if (controllers.find(",memory,") != std::string::npos) v1_path = path;
  }
  return std::min(cgroup_tree_available("/sys/fs/cgroup", v2_path, "memory.max", "memory.current"),
                  cgroup_tree_available("/sys/fs/cgroup/memory", v1_path, "memory.limit_in_bytes",
                                        "memory.usage_in_bytes"));
}

uint64_t address_space_available() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return kMax;
  return limit_less_usage(uint64_t(limit.rlim_cur), read_kb_field("/proc/self/status", "VmSize"));
}

}  // namespace

uint64_t available_memory_bytes() {
  uint64_t available = read_kb_field("/proc/meminfo", "MemAvailable").value_or(kMax);
  available = std::min(available, cgroup_available());
  available = std::min(available, address_space_available());
  return available;
}

void check_resources(const SceneDesc& desc) { check_memory(desc, available_memory_bytes()); }

}  // namespace candela
