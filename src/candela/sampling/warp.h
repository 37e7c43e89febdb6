#pragma once
// Warps from the unit square to common domains, each with its pdf (pbrt-v4 ch. A.5 / Mitsuba's warp.h).
// Directions on the hemisphere are in local coordinates with the normal along +z.
#include <cmath>

#include "candela/math/vec.h"

namespace candela {

inline Vec3 square_to_uniform_sphere(Vec2 u) {
  float z = 1 - 2 * u.x;
  float r = safe_sqrt(1 - z * z);
  float phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_sphere_pdf() { return kInv4Pi; }

// The paper's eq. 11: uniform directions on the hemisphere.
inline Vec3 square_to_uniform_hemisphere(Vec2 u) {
  float z = u.x;
  float r = safe_sqrt(1 - z * z);
  float phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_hemisphere_pdf(const Vec3& w) { return w.z >= 0 ? kInv2Pi : 0.0f; }

// Shirley-Chiu concentric mapping: area preserving, low distortion.
inline Vec2 square_to_concentric_disk(Vec2 u) {
  float ox = 2 * u.x - 1, oy = 2 * u.y - 1;
  if (ox == 0 && oy == 0) return {0, 0};
  float r, theta;
  if (std::abs(ox) > std::abs(oy)) {
    r = ox;
    theta = (kPi / 4) * (oy / ox);
  } else {
    r = oy;
    theta = kPi / 2 - (kPi / 4) * (ox / oy);
  }
  return {r * std::cos(theta), r * std::sin(theta)};
}
inline float concentric_disk_pdf(Vec2 p) { return p.x * p.x + p.y * p.y <= 1 ? kInvPi : 0.0f; }

// Malley's method: cosine-weighted hemisphere.
inline Vec3 square_to_cosine_hemisphere(Vec2 u) {
  Vec2 d = square_to_concentric_disk(u);
  float z = safe_sqrt(1 - d.x * d.x - d.y * d.y);
  return {d.x, d.y, z};
}
inline float cosine_hemisphere_pdf(const Vec3& w) { return w.z > 0 ? w.z * kInvPi : 0.0f; }

// Uniform directions in the cone of half-angle acos(cos_max) around +z.
inline Vec3 square_to_uniform_cone(Vec2 u, float cos_max) {
  float cos_theta = (1 - u.x) + u.x * cos_max;
  float sin_theta = safe_sqrt(1 - cos_theta * cos_theta);
  float phi = 2 * kPi * u.y;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}
inline float uniform_cone_pdf(float cos_max) { return 1 / (2 * kPi * (1 - cos_max)); }

// Normalised Phong lobe cos^n(alpha) around +z: pdf = (n + 1) / (2 pi) cos^n(alpha).
inline Vec3 square_to_phong_lobe(Vec2 u, float exponent) {
  float cos_alpha = std::pow(u.x, 1 / (exponent + 1));
  float sin_alpha = safe_sqrt(1 - cos_alpha * cos_alpha);
  float phi = 2 * kPi * u.y;
  return {sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha};
}
inline float phong_lobe_pdf(float cos_alpha, float exponent) {
  return cos_alpha > 0 ? (exponent + 1) * kInv2Pi * std::pow(cos_alpha, exponent) : 0.0f;
}

// Uniform barycentrics on a triangle (Heitz 2019, low distortion). Returns (b0, b1); b2 = 1 - b0 - b1.
inline Vec2 square_to_uniform_triangle(Vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2;
    b0 = u.x - b1;
  }
  return {b0, b1};
}

}  // namespace candela
