#pragma once
// Warps from the unit square to common domains, each with its pdf (pbrt-v4 ch. A.5 / Mitsuba's warp.h).
// Directions on the hemisphere are in local coordinates with the normal along +z.
#include <algorithm>
#include <cmath>
#include <limits>

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

// sin and cos of a in [-pi/4, pi/4] by their Taylor series to a^9 and a^8 (truncation errors below
// 2e-9 and 3e-8, under half a float ulp of the results), with no range reduction and no libm call:
// the concentric disk's angles are always in this range, and it is on the hot path (every diffuse
// bounce).
inline Vec2 cos_sin_quarter_pi(float a) {
  float a2 = a * a;
  float s = a * (1 + a2 * (-1.0f / 6 + a2 * (1.0f / 120 + a2 * (-1.0f / 5040 + a2 * (1.0f / 362880)))));
  float c = 1 + a2 * (-0.5f + a2 * (1.0f / 24 + a2 * (-1.0f / 720 + a2 * (1.0f / 40320))));
  return {c, s};
}

// Shirley-Chiu concentric mapping: area preserving, low distortion.
inline Vec2 square_to_concentric_disk(Vec2 u) {
  float ox = 2 * u.x - 1, oy = 2 * u.y - 1;
  if (ox == 0 && oy == 0) return {0, 0};
  if (std::abs(ox) > std::abs(oy)) {
    Vec2 cs = cos_sin_quarter_pi((kPi / 4) * (oy / ox));  // theta = a
    return {ox * cs.x, ox * cs.y};
  }
  Vec2 cs = cos_sin_quarter_pi((kPi / 4) * (ox / oy));  // theta = pi/2 - a: cos theta = sin a, sin theta = cos a
  return {oy * cs.y, oy * cs.x};
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

// Clarberg's equal-area mapping between the unit square and the sphere ("Fast Equal-Area Mapping of
// the (Hemi)Sphere using SIMD", 2008), the parameterisation of pbrt-v4's image infinite lights.
// With (u', v') = 2p - 1, the inner diamond |u'| + |v'| < 1 covers the +z hemisphere and the four
// corner triangles fold over onto -z; the edges of the square fold onto themselves ((u', +-1) and
// (-u', +-1) are one direction, as are (+-1, v') and (+-1, -v')). Equal areas of the square map to
// equal solid angles, so a uniform point gives a uniform direction (pdf 1 / (4 pi)).
inline Vec3 equal_area_square_to_sphere(Vec2 p) {
  // Work in [-1,1]^2, folded into the first quadrant; the signs pick the quadrant back at the end.
  float u = 2 * p.x - 1, v = 2 * p.y - 1;
  float au = std::abs(u), av = std::abs(v);
  // Signed distance from the diamond's edge: positive inside (+z). Its complement r is the radius of
  // the ring of directions: concentric diamonds become circles of constant z = +-(1 - r^2).
  float signed_distance = 1 - (au + av);
  float r = 1 - std::abs(signed_distance);
  // Position along the diamond ring, linear in the azimuth within the quadrant.
  float phi = (r == 0 ? 1 : (av - au) / r + 1) * (kPi / 4);
  float z = std::copysign(1 - r * r, signed_distance);
  // sin(theta) = sqrt(1 - z^2) = r sqrt(2 - r^2).
  float sin_theta = r * safe_sqrt(2 - r * r);
  return {std::copysign(std::cos(phi), u) * sin_theta, std::copysign(std::sin(phi), v) * sin_theta, z};
}

// The inverse: a unit direction to its point in [0,1]^2.
inline Vec2 equal_area_sphere_to_square(const Vec3& d) {
  float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  // Ring radius from |z| (inverting |z| = 1 - r^2) and the azimuth within the quadrant as a
  // fraction t of pi/2.
  float r = safe_sqrt(1 - az);
  float t = std::atan2(ay, ax) * (2 / kPi);
  // Upper hemisphere: the point on the diamond |u'| + |v'| = r at fraction t along the ring.
  float v = t * r;
  float u = r - v;
  // Lower hemisphere: fold the corner triangle out (reflect across the diamond's edge).
  if (d.z < 0) {
    float fu = 1 - v, fv = 1 - u;
    u = fu;
    v = fv;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {0.5f * (u + 1), 0.5f * (v + 1)};
}

// Equiangular sampling (Kulla and Fajardo, "Importance Sampling Techniques for Path Tracing in
// Participating Media", EGSR 2012, sec. 4.1): a distance t in [t0, t1) along a line, with density
// proportional to 1 / (h^2 + (t - delta)^2), the inverse squared distance to a point at distance h > 0
// from the line whose foot on it is at t = delta: uniform in the angle under which the point sees the
// line. t1 may be infinite. The density is 0 (no sample) where h is not positive (or so small that h^2
// underflows) or the interval is empty; equiangular_pdf gives what sample_equiangular does, for the
// same arguments.
struct EquiangularSegment {
  float delta = 0, h = 0;              // the foot of the point on the line, and its distance from it
  float theta_a = 0, theta_b = 0;      // the angles of t0 and t1 as the point sees them
  bool valid() const { return theta_b > theta_a; }
};
inline EquiangularSegment equiangular_segment(float delta, float h, float t0, float t1) {
  // (h^2 must be a normal float: the density's peak h / (h^2 (theta_b - theta_a)) stays finite.)
  if (!(h * h >= std::numeric_limits<float>::min()) || !(t1 > t0) || !std::isfinite(delta) || !std::isfinite(h))
    return {};
  const float theta_a = std::atan2(t0 - delta, h);
  const float theta_b = std::isinf(t1) ? kPi / 2 : std::atan2(t1 - delta, h);
  return {delta, h, theta_a, theta_b};
}
inline float equiangular_pdf(const EquiangularSegment& s, float t) {
  if (!s.valid()) return 0;
  const float x = t - s.delta;
  return s.h / ((s.theta_b - s.theta_a) * (s.h * s.h + x * x));
}
// The distance for u in [0, 1), clamped into [t0, t1) against rounding; pdf: equiangular_pdf there.
inline float sample_equiangular(const EquiangularSegment& s, float u, float t0, float t1) {
  float t = s.delta + s.h * std::tan(s.theta_a + u * (s.theta_b - s.theta_a));
  return std::clamp(t, t0, std::nextafter(t1, t0));
}

}  // namespace candela
