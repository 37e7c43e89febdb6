#pragma once
// What the shading code needs to know about a ray-surface intersection.
#include <cstdint>

#include "candela/math/vec.h"

namespace candela {

struct SurfaceHit {
  Point3 p;
  float t = 0;
  Normal3 ng;  // geometric normal: the emitting side of one-sided emitters, the outside of dielectrics
  Normal3 ns;  // shading normal (interpolated vertex normals), same side as ng
  Vec2 uv;
  Vec3 dpdu;  // surface tangent along u (world space, not normalised; zero when unknown): the
              // shading frame's first axis, which anisotropic roughness is measured along
  Vec3 dpdv;  // surface tangent along v (world space, not normalised; zero when unknown): bump mapping
  uint32_t shape = 0;      // index into Scene::shapes
  uint32_t primitive = 0;  // triangle index within a mesh
  Vec2 bary;               // triangles: the weights of the triangle's vertices 1 and 2 (vertex 0 has 1 - x - y)
};

}  // namespace candela
