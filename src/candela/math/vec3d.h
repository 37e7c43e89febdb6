#pragma once
// Double-precision 3-vectors for the analytic intersection routines (Embree user geometry), which
// solve in double what the rest of the renderer keeps in float.
#include "candela/math/transform.h"
#include "candela/math/vec.h"

namespace candela {

struct Vec3d {
  double x = 0, y = 0, z = 0;
  static Vec3d from(const Vec3& v) { return {v.x, v.y, v.z}; }
  Vec3 to_float() const { return {float(x), float(y), float(z)}; }
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  Vec3d operator+(const Vec3d& b) const { return {x + b.x, y + b.y, z + b.z}; }
  Vec3d operator-(const Vec3d& b) const { return {x - b.x, y - b.y, z - b.z}; }
  Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
};

inline double dot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// m (v, w): a point for w = 1, a direction for w = 0.
inline Vec3d apply(const Matrix4& m, const Vec3d& v, double w) {
  return {m.m[0][0] * v.x + m.m[0][1] * v.y + m.m[0][2] * v.z + m.m[0][3] * w,
          m.m[1][0] * v.x + m.m[1][1] * v.y + m.m[1][2] * v.z + m.m[1][3] * w,
          m.m[2][0] * v.x + m.m[2][1] * v.y + m.m[2][2] * v.z + m.m[2][3] * w};
}

}  // namespace candela
