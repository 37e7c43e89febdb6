#pragma once
// Mitsuba's (u, v) parameterisations of the analytic shapes, in each shape's own space: one place for
// both the ray hits (Scene::reconstruct_sphere_hit, reconstruct_quadric_hit) and the area lights that
// sample points on those shapes (textured emission must read the texture at the same (u, v)).
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

// Disk: (r, phi / 2 pi) of the point (x, y) of the unit disk.
inline Vec2 disk_uv(float x, float y) { return {std::sqrt(x * x + y * y), azimuth(x, y) * kInv2Pi}; }

// Cylinder: (phi / 2 pi, z) of the point (x, y, z) of the unit tube (z from 0 to 1 along the axis).
inline Vec2 cylinder_uv(float x, float y, float z) { return {azimuth(x, y) * kInv2Pi, z}; }

}  // namespace candela
