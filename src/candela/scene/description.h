#pragma once
// The format-neutral scene description: plain structs with defaults that every reader (JSON, pbrt-v4,
// later Mitsuba and glTF) fills in and that scene/build turns into a render scene. Nothing after this
// point knows which file format a scene came from. Units are whatever the scene uses; colours are linear RGB.
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"

namespace candela {

// ---------------------------------------------------------------- materials

// Lambertian reflector.
struct DiffuseMaterial {
  RGB reflectance{0.5f};
};

// The paper's material model (Häkkinen 2002, sec. 4.6): a diffuse lobe, a normalised Phong lobe and
// ideal refraction, chosen per path vertex by Russian roulette with probabilities d, s, t
// (d + s + t <= 1; the rest absorbs). The BSDF is d*diffuse/pi + s*specular*phong + t*transmission*delta.
struct PhongMaterial {
  RGB diffuse{0.5f};
  RGB specular{1.0f};
  float exponent = 32;  // Phong exponent n of cos^n around the mirror direction
  RGB transmission{1.0f};
  float ior = 1.5f;  // index of refraction inside / outside, for the transmitted part
  float d = 1, s = 0, t = 0;
};

// Ideal specular reflector.
struct MirrorMaterial {
  RGB reflectance{1.0f};
};

// Smooth dielectric interface (glass): Fresnel-weighted choice of reflection and refraction.
struct GlassMaterial {
  float ior = 1.5f;
  RGB reflectance{1.0f};
  RGB transmittance{1.0f};
};

// Absorbs everything: for pure emitters and light blockers.
struct BlackMaterial {};

using MaterialDesc = std::variant<DiffuseMaterial, PhongMaterial, MirrorMaterial, GlassMaterial, BlackMaterial>;

// ---------------------------------------------------------------- shapes

struct TriangleMesh {
  std::vector<Point3> positions;
  std::vector<Normal3> normals;  // empty or one per position (shading normals)
  std::vector<Vec2> uvs;         // empty or one per position
  std::vector<uint32_t> indices;  // three per triangle
  size_t triangle_count() const { return indices.size() / 3; }
};

// Sphere of `radius` around `center`, in object space (then to_world applies).
struct SphereShape {
  Point3 center{0.0f};
  float radius = 1;
};

// Infinite plane through `point` with normal `normal` (object space).
struct PlaneShape {
  Point3 point{0.0f};
  Normal3 normal{0, 1, 0};
};

// Axis-aligned box [lo, hi] in object space; to_world may rotate and scale it.
struct BoxShape {
  Point3 lo{-1.0f}, hi{1.0f};
};

// Parallelogram corner + s*edge_u + t*edge_v, (s,t) in [0,1]^2; normal = normalize(cross(edge_u, edge_v)).
struct RectangleShape {
  Point3 corner{-1, -1, 0};
  Vec3 edge_u{2, 0, 0}, edge_v{0, 2, 0};
};

struct MeshShape {
  TriangleMesh mesh;
};

using ShapeGeometry = std::variant<SphereShape, PlaneShape, BoxShape, RectangleShape, MeshShape>;

// Diffuse emission attached to a shape (an area light). One-sided: emits on the side the surface
// normal points to, unless two_sided.
struct AreaEmission {
  RGB radiance{1.0f};
  bool two_sided = false;
};

struct ShapeDesc {
  ShapeGeometry geometry;
  Transform to_world;
  int material = -1;  // index into SceneDesc::materials; -1 = the default diffuse 0.5
  std::optional<AreaEmission> emission;
  // A moving shape: its transform at SceneDesc::transform_times[1] (to_world holds the one at
  // transform_times[0]); in between the matrix is interpolated linearly, as Embree does.
  std::optional<Transform> to_world_end;
  // Flips the surface normal (pbrt's ReverseOrientation): which side a one-sided emitter lights.
  // Independently of this, a to_world that swaps handedness keeps normals equal to the object-space
  // normals transformed as normals (pbrt-v4's convention).
  bool reverse_orientation = false;
  std::string name;  // for messages
};

// ---------------------------------------------------------------- lights (those that are not shapes)

struct PointLight {
  Point3 position{0.0f};
  RGB intensity{1.0f};  // W/sr
};

// Light from infinitely far away in every direction. Constant when zenith == horizon == ground;
// otherwise radiance blends linearly in cos(theta) from horizon to zenith above the horizon and is
// `ground` below it.
struct SkyLight {
  RGB zenith{1.0f};
  RGB horizon{1.0f};
  RGB ground{1.0f};
  Vec3 up{0, 1, 0};
  bool is_constant() const { return zenith == horizon && horizon == ground; }
};

using LightDesc = std::variant<PointLight, SkyLight>;

// ---------------------------------------------------------------- camera, film, settings

enum class FovAxis { X, Y, Smaller, Larger, Diagonal };

struct CameraDesc {
  // Maps camera space (+x image right, +y image up, +z forward) to world space.
  Transform world_from_camera;
  float fov_degrees = 40;
  FovAxis fov_axis = FovAxis::Y;  // JSON gives a vertical fov; pbrt-v4 gives it on the smaller axis
  // Thin lens (depth of field): 0 = pinhole. Points at focus_distance along +z are sharp.
  float lens_radius = 0;
  float focus_distance = 1e6f;
  // Each camera path gets a time uniformly in [shutter_open, shutter_close] (motion blur).
  float shutter_open = 0, shutter_close = 1;
};

struct FilmDesc {
  int width = 512;
  int height = 512;
  std::string filename;  // empty = the command line's default
};

// How pixel samples are placed (Häkkinen 2002, sec. 4.3).
enum class SamplerType {
  Independent,  // uniform random numbers
  Stratified,   // jittered strata in every dimension, shuffled per pixel (pbrt-v4's StratifiedSampler)
  Poisson,      // Poisson-disc pixel positions with a minimum distance; other dimensions independent
  ZSobol        // Owen-scrambled Sobol' points in Morton order over the image (pbrt-v4's ZSobolSampler)
};
struct SamplerDesc {
  // Independent here; the readers choose ZSobol when a scene names no sampler (pbrt-v4's default,
  // and the most efficient measured in docs/performance.md).
  SamplerType type = SamplerType::Independent;
  bool jitter = true;  // stratified: false puts each sample at its stratum's centre
};

// Pixel reconstruction filters; every sample contributes to its own pixel only, with the weight
// f(offset) / pdf(offset) of filter importance sampling (pbrt-v4).
enum class FilterType { Box, Tent, Gaussian, Mitchell };
struct FilterDesc {
  FilterType type = FilterType::Box;
  Vec2 radius{0.5f, 0.5f};    // in pixels; pbrt's defaults: box 0.5, triangle 2, gaussian 1.5, mitchell 2
  float gaussian_sigma = 0.5f;
  float mitchell_b = 1.0f / 3, mitchell_c = 1.0f / 3;
};

// A filter of the given type with pbrt-v4's default parameters.
inline FilterDesc default_filter(FilterType type) {
  FilterDesc f;
  f.type = type;
  float r = type == FilterType::Box ? 0.5f : type == FilterType::Gaussian ? 1.5f : 2.0f;
  f.radius = {r, r};
  return f;
}

// How the next direction is chosen at non-delta vertices (sec. 4.7).
enum class DirectionSampling {
  Bsdf,     // importance-sample the BSDF's lobes
  Cosine,   // cosine-weighted hemisphere, weighted by the BSDF
  Uniform   // uniform hemisphere (the paper's eq. 11), weighted by the BSDF
};

// How shadow rays are spent at each vertex (sec. 4.5).
enum class LightSelection {
  Power,   // `shadow_rays` rays, each to one light chosen with probability proportional to its power
  Paper    // every light gets a share of `shadow_rays` proportional to power x projected solid angle
           // as seen from the vertex (stratified over rectangles), kept unbiased
};

struct RenderSettings {
  int spp = 16;
  int max_depth = 16;  // maximum number of scattering events; 1 = direct lighting only
  uint64_t seed = 0;
  std::string integrator = "path";
  int rr_start_depth = 3;  // Russian roulette on throughput starts after this many bounces
  SamplerDesc sampler;
  FilterDesc filter;
  DirectionSampling direction_sampling = DirectionSampling::Bsdf;
  bool mis = true;  // false: light sampling for direct light, emission found by bounces ignored
  LightSelection light_selection = LightSelection::Power;
  int shadow_rays = 1;
  // Adaptive sampling (sec. 4.3): after every batch of `adaptive_batch` samples (a power of two),
  // pixels whose relative standard error exceeds the threshold get another batch, up to
  // `adaptive_max_spp`. 0 = off: every pixel gets `spp`.
  float adaptive_threshold = 0;
  int adaptive_batch = 16;
  int adaptive_max_spp = 1024;
};

struct SceneDesc {
  CameraDesc camera;
  FilmDesc film;
  RenderSettings settings;
  std::vector<MaterialDesc> materials;
  std::vector<ShapeDesc> shapes;
  std::vector<LightDesc> lights;
  // The times at which ShapeDesc::to_world and to_world_end hold (pbrt's TransformTimes).
  float transform_start_time = 0, transform_end_time = 1;
  std::string source_file;  // the file it was read from, for messages and image metadata
};

}  // namespace candela
