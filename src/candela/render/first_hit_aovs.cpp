#include "candela/render/first_hit_aovs.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "candela/render/camera_sample_tiles.h"
#include "candela/sampling/rng.h"

namespace candela {
namespace {

// Interfaces and pass-through events looked through before giving up (a ray between two coincident
// interfaces, a stack of masks).
constexpr int kMaxEvents = 64;

RGB clamp01(const RGB& c) {
  auto f = [](float v) { return v > 0 ? std::min(v, 1.0f) : 0.0f; };  // NaN -> 0
  return {f(c.r), f(c.g), f(c.b)};
}

// The ray on past `hit` in `direction`.
Ray continue_ray(const SurfaceHit& hit, const Vec3& direction, float time) {
  return Ray{offset_ray_origin(hit.p, hit.ng, direction), direction, std::numeric_limits<float>::infinity(), time};
}

// The offset of the point where the ray (origin, direction) meets the plane through `p` with normal
// `n` from p: one of pbrt-v4's ray-differential footprints (0 for a ray parallel to the plane).
Vec3 tangent_plane_offset(const Point3& origin, const Vec3& direction, const Point3& p, const Vec3& n) {
  const float along_normal = dot(n, direction);
  if (along_normal == 0 || !std::isfinite(along_normal)) return {0, 0, 0};
  const float t = dot(n, p - origin) / along_normal;
  const Vec3 offset = (origin + direction * t) - p;
  return std::isfinite(offset.x) && std::isfinite(offset.y) && std::isfinite(offset.z) ? offset : Vec3(0, 0, 0);
}

// A camera ray's point at unit depth along the viewing axis `forward` (its origin for an
// orthographic ray, whose direction is the axis): how it moves from pixel to pixel gives the steps.
Point3 unit_depth_point(const Ray& ray, const Vec3& forward) {
  return ray.origin + ray.direction / dot(ray.direction, forward);
}

}  // namespace

AovCameraFrame aov_camera_frame(const Camera& camera) {
  AovCameraFrame frame;
  if (camera.is_spherical()) {
    // No image plane: the camera's own axes, and no per-pixel step of a plane (depth derivatives 0).
    const Transform& to_world = camera.world_from_camera();
    frame.x = normalize(to_world.vector(Vec3(1, 0, 0)));
    frame.y = normalize(to_world.vector(Vec3(0, 1, 0)));
    frame.z = normalize(camera.forward());
    frame.origin = to_world.point(Point3(0.0f));
    return frame;
  }
  const Vec2 centre(0.5f * float(camera.width()), 0.5f * float(camera.height()));
  const Vec2 lens_centre(0.5f, 0.5f);
  const float time = camera.shutter_open();
  const Ray r0 = camera.generate_ray(centre, lens_centre, time);
  const Ray rx = camera.generate_ray(centre + Vec2(1, 0), lens_centre, time);
  const Ray ry = camera.generate_ray(centre + Vec2(0, 1), lens_centre, time);
  frame.orthographic = camera.is_orthographic();
  frame.z = normalize(camera.forward());
  const Point3 q0 = unit_depth_point(r0, frame.z);
  frame.pixel_dx = unit_depth_point(rx, frame.z) - q0;
  frame.pixel_dy = unit_depth_point(ry, frame.z) - q0;
  // Film y grows downwards; the camera's y axis points up.
  frame.x = normalize(frame.pixel_dx);
  frame.y = normalize(-frame.pixel_dy);
  frame.origin = r0.origin;
  return frame;
}

AovSample first_hit_aovs(const Scene& scene, const Ray& camera_ray, bool shade, int x, int y, uint64_t sample,
                         uint64_t seed) {
  // A stream of its own per (pixel, sample, seed): "AOV" tags it apart from every other use of the seed.
  Rng rng(hash_values(uint64_t(x), uint64_t(y), sample), hash_values(seed, 0x414f56));
  AovSample out;
  const Vec3 forward = scene.camera().forward();
  Ray ray = camera_ray;
  RGB throughput(1.0f);  // of the delta surfaces followed
  int specular_bounces = 0;
  for (int event = 0; event < kMaxEvents; ++event) {
    SurfaceHit hit;
    if (!scene.intersect(ray, hit)) return out;  // escaped: albedo 0, normal 0 (see the header)
    if (scene.is_interface(hit)) {
      ray = continue_ray(hit, ray.direction, ray.time);
      continue;
    }
    auto record_hit = [&] {
      if (out.hit) return;
      out.hit = true;
      out.position = hit.p;
      out.depth = dot(hit.p - camera_ray.origin, forward);
      const Vec3 n(hit.ng.x, hit.ng.y, hit.ng.z);
      out.geometric_normal = dot(n, ray.direction) > 0 ? -n : n;
      out.uv = hit.uv;
      // pbrt-v4's ray differentials: the camera rays one pixel right and one pixel down, met with
      // the hit's tangent plane.
      const AovCameraFrame frame = aov_camera_frame(scene.camera());
      const Vec3 unit_depth_direction = camera_ray.direction / dot(camera_ray.direction, frame.z);
      for (int axis = 0; axis < 2; ++axis) {
        const Vec3 step = axis == 0 ? frame.pixel_dx : frame.pixel_dy;
        const Point3 origin = frame.orthographic ? camera_ray.origin + step : camera_ray.origin;
        const Vec3 direction = frame.orthographic ? camera_ray.direction : unit_depth_direction + step;
        (axis == 0 ? out.dpdx : out.dpdy) = tangent_plane_offset(origin, direction, hit.p, n);
      }
    };
    // Only the hit is wanted, and nothing can be seen through this surface.
    if (!shade && !scene.may_pass_through(hit)) {
      record_hit();
      return out;
    }
    const Vec3 wo = -normalize(ray.direction);
    const Shading shading = scene.shading(hit, wo);
    const SurfaceBsdf& bsdf = shading.bsdf;
    const Vec3 wo_local = shading.frame.to_local(wo);
    std::optional<BsdfSample> bs;
    if (wo_local.z != 0 && !bsdf.is_black()) {
      const float u_lobe = rng.next_float();
      const Vec2 u(rng.next_float(), rng.next_float());
      bs = bsdf.sample(wo_local, u_lobe, u);
    }
    if (bs && bs->passes_through) {
      // A mask's absent part or a thin sheet: what lies behind is what is seen.
      throughput = clamp01(throughput * bs->weight);
      ray = continue_ray(hit, ray.direction, ray.time);
      continue;
    }
    record_hit();
    if (!shade) return out;
    // The sample's weight as reflectance: refraction's radiance scaling by 1 / eta'^2 undone.
    const RGB reflectance = bs ? clamp01(bs->weight * (bs->eta * bs->eta)) : RGB(0.0f);
    const bool delta_only = !bsdf.has_non_delta() && !bsdf.is_black();
    if (delta_only && bs && bs->is_delta && specular_bounces < kAovMaxSpecularBounces) {
      // A perfect mirror or smooth dielectric: follow the sampled reflection or refraction.
      throughput = throughput * reflectance;
      ++specular_bounces;
      ray = continue_ray(hit, normalize(shading.frame.to_world(bs->wi)), ray.time);
      continue;
    }
    out.albedo = clamp01(throughput * reflectance);
    out.normal = dot(shading.frame.n, wo) < 0 ? -shading.frame.n : shading.frame.n;
    return out;
  }
  return out;
}

void render_aovs(const Scene& scene, const RenderSettings& settings, AovFilm& aovs, const RenderOptions& options,
                 int spp) {
  RenderSettings s = settings;
  s.spp = spp;
  s.adaptive_threshold = 0;
  s.adaptive_spp = 0;
  RenderOptions o;
  o.threads = options.threads;
  o.progress = false;
  o.cancel = options.cancel;
  o.cluster = options.cluster;
  o.part_index = options.part_index;
  o.part_count = options.part_count;
  o.only_x = options.only_x;
  o.only_y = options.only_y;
  o.aovs = &aovs;
  // The colour is not wanted: a film of its own takes the (black) samples.
  Film scratch(aovs.width(), aovs.height());
  CameraSampleTiles tiles(
      [](const Ray&, auto&, RayCounts&, const PixelSample&, const Wavelengths*) { return RGB(0.0f); });
  render_tiles(scene, s, scratch, o, tiles);
}

}  // namespace candela
