#pragma once
// The (u, v) parameterisations of the analytic shapes (Mitsuba's; pbrt-v4's of partial spheres and
// cylinders), in each shape's own space: one place for both the ray hits (Scene::reconstruct_sphere_hit,
// reconstruct_quadric_hit) and the area lights that sample points on those shapes (textured emission
// must read the texture at the same (u, v)).
#include <algorithm>
#include <cmath>

#include "candela/math/vec.h"

namespace candela {

// The azimuth of (x, y), in [0, 2 pi).
inline float azimuth(float x, float y) {
  float phi = std::atan2(y, x);
  return phi < 0 ? phi + 2 * kPi : phi;
}

// Sphere: (phi / 2 pi, theta / pi) of a point's offset from the centre (of any length), theta from +z.
inline Vec2 sphere_uv(const Vec3& offset) {
  float len = length(offset);
  float cos_theta = len > 0 ? std::clamp(offset.z / len, -1.0f, 1.0f) : 1.0f;
  return {azimuth(offset.x, offset.y) * kInv2Pi, std::acos(cos_theta) * kInvPi};
}

// pbrt-v4's (u, v) of a partial sphere (description/shapes.h: SphereShape), of a point's offset from the
// centre: u = phi / phi_max, v = (theta - theta_z_min) / (theta_z_max - theta_z_min), theta from +z and
// theta_z = acos(z / radius) of the lowest and highest heights kept (both clamped to [0, 1]).
inline Vec2 partial_sphere_uv(const Vec3& offset, float phi_max, float theta_z_min, float theta_z_max) {
  float len = length(offset);
  float cos_theta = len > 0 ? std::clamp(offset.z / len, -1.0f, 1.0f) : 1.0f;
  float u = azimuth(offset.x, offset.y) / phi_max;
  float v = (std::acos(cos_theta) - theta_z_min) / (theta_z_max - theta_z_min);
  return {std::clamp(u, 0.0f, 1.0f), std::clamp(v, 0.0f, 1.0f)};
}

// Disk: (r, phi / 2 pi) of the point (x, y) of the unit disk.
inline Vec2 disk_uv(float x, float y) { return {std::sqrt(x * x + y * y), azimuth(x, y) * kInv2Pi}; }

// Cylinder: (phi / 2 pi, z) of the point (x, y, z) of the unit tube (z from 0 to 1 along the axis).
inline Vec2 cylinder_uv(float x, float y, float z) { return {azimuth(x, y) * kInv2Pi, z}; }
// The same for a tube cut to the azimuths up to phi_max (pbrt-v4's): (phi / phi_max, z).
inline Vec2 cylinder_uv(float x, float y, float z, float phi_max) {
  if (phi_max >= 2 * kPi) return cylinder_uv(x, y, z);
  return {std::min(azimuth(x, y) / phi_max, 1.0f), z};
}

}  // namespace candela
