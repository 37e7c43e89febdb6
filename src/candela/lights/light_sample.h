#pragma once
#include <limits>

#include "candela/lights/light_flags.h"
#include "candela/math/color.h"
#include "candela/math/frame.h"
#include "candela/math/vec.h"
#include "candela/sampling/warp.h"

namespace candela {

// Where light is gathered: a surface point and the normal of the side that gathers (zero vector
// when any direction may receive light).
struct LightSampleContext {
  Point3 p;
  Normal3 n;
};

struct LightSample {
  RGB radiance;    // arriving at ctx.p along wi, before visibility
  Vec3 wi;         // unit direction from ctx.p towards the light
  float distance = std::numeric_limits<float>::infinity();  // to the light point; infinite for the sky
  float pdf = 0;   // solid angle (1 for delta lights); 0 = no sample
  Point3 p_light;  // the sampled point on the light (for shadow rays)
  Normal3 n_light;
  bool is_delta = false;
};

// The scene's bounding sphere: lights at infinity emit light paths through a disk of its radius
// facing the direction of travel (pbrt's convention for sampling emission from infinity).
struct SceneSphere {
  Point3 center;
  float radius = 1;
};

// A ray of light leaving a light, for paths traced from the lights (bidirectional methods).
struct LightEmission {
  RGB radiance;       // carried along the ray: radiance for area lights and lights at infinity,
                      // intensity for point and spot lights, irradiance for distant lights
  Point3 p;           // where it starts
  Vec3 w;             // unit direction of travel
  Normal3 n;          // the surface normal at p for area lights; zero for points and lights at infinity
  float pdf_pos = 0;  // density of p: per area on area lights and on the disk of lights at infinity, 1 for points
  float pdf_dir = 0;  // solid-angle density of w (1 for the single direction of a distant light); 0 = no sample
};

// Densities with which sample_le would produce a given ray.
struct EmissionPdf {
  float pos = 0, dir = 0;
};

// Cosine-weighted emission direction about n (either side of it with probability 1/2 when two-sided),
// and its density.
inline Vec3 sample_cosine_emission(const Normal3& n, bool two_sided, Vec2 u, float& pdf) {
  float side = 1;
  if (two_sided) {
    side = u.x < 0.5f ? 1.0f : -1.0f;
    u.x = u.x < 0.5f ? 2 * u.x : 2 * u.x - 1;
    u.x = std::min(u.x, 0x1.fffffep-1f);
  }
  Vec3 local = square_to_cosine_hemisphere(u);
  pdf = cosine_hemisphere_pdf(local) * (two_sided ? 0.5f : 1.0f);
  return Frame(n * side).to_world(local);
}
inline float cosine_emission_pdf(const Normal3& n, bool two_sided, const Vec3& w) {
  float c = dot(n, w);
  if (two_sided) return std::abs(c) * kInvPi * 0.5f;
  return c > 0 ? c * kInvPi : 0.0f;
}

// A point on the disk of radius R through the scene centre facing w, moved back by R against w, so a
// ray from it along w crosses the whole scene: the origin of emission from a light at infinity.
inline Point3 point_on_scene_disk(const SceneSphere& s, const Vec3& w, Vec2 u) {
  Frame f(w);
  Vec2 d = square_to_concentric_disk(u);
  return s.center + (f.s * d.x + f.t * d.y - w) * s.radius;
}
// Whether the scene disk facing w covers p (a point outside the cylinder it sweeps never receives
// light paths from infinity along w).
inline bool scene_disk_covers(const SceneSphere& s, const Vec3& w, const Point3& p) {
  Vec3 d = p - s.center;
  return length_squared(d - w * dot(d, w)) <= s.radius * s.radius;
}

}  // namespace candela
