#pragma once
// An orthonormal frame around a normal: shading computations happen in its local coordinates
// where the normal is +z, so cos(theta) = w.z.
#include "candela/math/vec.h"

namespace candela {

struct Frame {
  Vec3 s, t, n;
  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  // Duff et al. 2017, "Building an Orthonormal Basis, Revisited": branchless and continuous.
  explicit Frame(const Vec3& normal) : n(normal) {
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3(b, sign + n.y * n.y * a, -n.y);
  }
  // The frame around `normal` whose first axis is `tangent` made orthogonal to it (Gram-Schmidt),
  // so anisotropic BSDFs line up with the surface's u direction; any frame when tangent is unusable.
  static Frame from_normal_tangent(const Vec3& normal, const Vec3& tangent) {
    Vec3 s = tangent - normal * dot(normal, tangent);
    float len2 = length_squared(s);
    if (!(len2 > 1e-12f * length_squared(tangent)) || !std::isfinite(len2)) return Frame(normal);
    Frame f;
    f.n = normal;
    f.s = s / std::sqrt(len2);
    f.t = cross(normal, f.s);
    return f;
  }
  Vec3 to_local(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace candela
