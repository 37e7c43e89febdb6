#pragma once
// Triangles paired into quads across shared edges, so that Embree builds its BVH over quads: half
// the primitives, leaves that hold two triangles per slot (about half the memory per triangle) and
// a build over half as many references. Embree splits a quad (v0, v1, v2, v3) into the triangles
// (v0, v1, v3) and (v2, v3, v1) and reports hits in the quad's own parametrisation: u along v0->v1,
// v along v0->v3, u + v > 1 on the second triangle, whose own barycentrics are then (1 - u, 1 - v).
// A triangle left without a partner becomes (v0, v1, v2, v2), whose second half is degenerate.
#include <cstdint>
#include <vector>

#include "candela/math/vec.h"

namespace candela {

struct QuadTriangles {
  static constexpr uint32_t kNone = UINT32_MAX;
  uint32_t first = 0, second = kNone;  // triangle indices of the quad's halves (v0, v1, v3) and (v2, v3, v1)
  // Where each half starts in its triangle's own vertex order: (v0, v1, v3) is the first triangle's
  // vertices (r, r + 1, r + 2) mod 3 for r = first_rotation; likewise (v2, v3, v1) for the second.
  uint8_t first_rotation = 0, second_rotation = 0;
};

struct TrianglePairs {
  std::vector<uint32_t> quads;         // four vertex indices per quad
  std::vector<QuadTriangles> halves;   // per quad
};

// Pairs each triangle (three indices into `positions` each) with an unpaired neighbour across an
// edge that the two traverse in opposite directions (so the quad keeps both triangles'
// orientation), the longest such edge, greedily in triangle order: deterministic, and for closed or
// scanned meshes nearly every triangle is paired.
TrianglePairs pair_triangles(const std::vector<uint32_t>& indices, const std::vector<Point3>& positions);

// A hit on a quad as a hit on one of its triangles: the triangle's index and the barycentric
// weights (b1, b2) of its vertices 1 and 2 in its own order (vertex 0 has 1 - b1 - b2).
struct TriangleHit {
  uint32_t triangle;
  float b1, b2;
};
inline TriangleHit quad_hit_to_triangle(const QuadTriangles& q, float u, float v) {
  float w[3];
  uint32_t tri;
  int r;
  if (u + v <= 1 || q.second == QuadTriangles::kNone) {
    // (v0, v1, v3) with weights (1 - u - v, u, v).
    tri = q.first;
    r = q.first_rotation;
    w[r] = 1 - u - v;
    w[(r + 1) % 3] = u;
    w[(r + 2) % 3] = v;
  } else {
    // (v2, v3, v1) with weights (u + v - 1, 1 - u, 1 - v).
    tri = q.second;
    r = q.second_rotation;
    w[r] = u + v - 1;
    w[(r + 1) % 3] = 1 - u;
    w[(r + 2) % 3] = 1 - v;
  }
  return {tri, w[1], w[2]};
}

}  // namespace candela
