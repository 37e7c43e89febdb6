// Triangles paired into Embree quads: the pairing keeps every triangle exactly once with its
// orientation, the quad-to-triangle hit mapping reproduces Embree's documented quad
// parametrisation, and through the whole Scene every hit on a mesh lands on the triangle it reports,
// at the barycentrics it reports.
#include "candela/geometry/triangle_pairs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "candela/sampling/rng.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

// A latitude-longitude sphere of radius 1: quads of two triangles, fans at the poles.
TriangleMesh uv_sphere(int rings, int segments) {
  TriangleMesh m;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      float theta = kPi * float(i) / float(rings), phi = 2 * kPi * float(j) / float(segments);
      m.positions.push_back({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  auto at = [&](int i, int j) { return uint32_t(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      if (i > 0) m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i < rings - 1) m.indices.insert(m.indices.end(), {at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  return m;
}

// The point of Embree's quad parametrisation (u, v) (see triangle_pairs.h).
Point3 quad_point(const Point3 v[4], float u, float v_) {
  if (u + v_ <= 1) return v[0] + (v[1] - v[0]) * u + (v[3] - v[0]) * v_;
  return v[2] + (v[3] - v[2]) * (1 - u) + (v[1] - v[2]) * (1 - v_);
}

Point3 triangle_point(const TriangleMesh& m, const TriangleHit& h) {
  const uint32_t* t = &m.indices[3 * size_t(h.triangle)];
  return m.positions[t[0]] * (1 - h.b1 - h.b2) + m.positions[t[1]] * h.b1 + m.positions[t[2]] * h.b2;
}

TEST(TrianglePairs, EveryTriangleOnceInOrientationAndHitsMapToTheirTriangles) {
  TriangleMesh m = uv_sphere(12, 16);
  const size_t n = m.indices.size() / 3;
  TrianglePairs pairs = pair_triangles(m.indices, m.positions);
  ASSERT_EQ(pairs.quads.size(), 4 * pairs.halves.size());
  std::multiset<uint32_t> seen;
  size_t paired = 0;
  Rng rng(5, 1);
  for (size_t q = 0; q < pairs.halves.size(); ++q) {
    const QuadTriangles& h = pairs.halves[q];
    const uint32_t* quad = &pairs.quads[4 * q];
    seen.insert(h.first);
    // (v0, v1, v3) is the first triangle, rotated.
    const uint32_t* a = &m.indices[3 * size_t(h.first)];
    EXPECT_EQ(quad[0], a[h.first_rotation]);
    EXPECT_EQ(quad[1], a[(h.first_rotation + 1) % 3]);
    EXPECT_EQ(quad[3], a[(h.first_rotation + 2) % 3]);
    if (h.second != QuadTriangles::kNone) {
      ++paired;
      seen.insert(h.second);
      const uint32_t* b = &m.indices[3 * size_t(h.second)];
      EXPECT_EQ(quad[2], b[h.second_rotation]);
      EXPECT_EQ(quad[3], b[(h.second_rotation + 1) % 3]);
      EXPECT_EQ(quad[1], b[(h.second_rotation + 2) % 3]);
    } else {
      EXPECT_EQ(quad[2], quad[3]) << "a lone triangle is (v0, v1, v2, v2)";
    }
    // Points of the quad's parametrisation are where the mapped triangle hit says.
    Point3 v[4] = {m.positions[quad[0]], m.positions[quad[1]], m.positions[quad[2]], m.positions[quad[3]]};
    for (int k = 0; k < 20; ++k) {
      float u = rng.next_float(), w = rng.next_float();
      if (h.second == QuadTriangles::kNone && u + w > 1) {
        u = 1 - u;
        w = 1 - w;
      }
      TriangleHit th = quad_hit_to_triangle(h, u, w);
      Point3 expected = quad_point(v, u, w), got = triangle_point(m, th);
      EXPECT_LT(length(expected - got), 1e-5f) << "quad " << q << " at " << u << ", " << w;
      EXPECT_GE(std::min({th.b1, th.b2, 1 - th.b1 - th.b2}), -1e-6f);
    }
  }
  EXPECT_EQ(seen.size(), n);
  EXPECT_EQ(std::set<uint32_t>(seen.begin(), seen.end()).size(), n) << "each triangle exactly once";
  // The poles' fans pair too: only an odd one out per fan can be left alone.
  EXPECT_GE(2 * paired, n - 2);

  // Two triangles that traverse their shared edge in the same direction (inconsistent orientation)
  // are not paired: the quad would flip one of them.
  TrianglePairs flipped = pair_triangles({0, 1, 2, 0, 1, 3}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}});
  EXPECT_EQ(flipped.halves.size(), 2u);
}

TEST(TrianglePairs, SceneHitsLandOnTheTriangleTheyReport) {
  // Rays from random points outside a skewed sphere mesh towards random points inside: the hit
  // point rebuilt from the reported triangle and barycentrics is the ray's point at t, and lies in
  // that triangle. Both BVH layouts: quads of paired triangles, and the compact layout's triangles.
  for (BvhLayout layout : {BvhLayout::Fast, BvhLayout::Compact}) {
    SceneDesc d;
    d.settings.bvh = layout;
    MeshShape mesh;
    mesh.mesh = uv_sphere(24, 32);
    ShapeDesc s;
    s.geometry = mesh;
    s.to_world = Transform::scale({2, 1, 0.5f});
    d.shapes = {s};
    const Scene scene(d);
    Rng rng(9, 1);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
      Vec3 dir = normalize(Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
      Point3 target(0.5f * (rng.next_float() - 0.5f), 0.5f * (rng.next_float() - 0.5f), 0.2f * (rng.next_float() - 0.5f));
      Ray ray{target - dir * 5.0f, dir, std::numeric_limits<float>::infinity(), 0};
      SurfaceHit hit;
      if (!scene.intersect(ray, hit)) continue;
      ++hits;
      float t = dot(hit.p - ray.origin, ray.direction);
      EXPECT_LT(length(ray.at(t) - hit.p), 1e-4f) << "ray " << i;
      EXPECT_GE(std::min({hit.bary.x, hit.bary.y, 1 - hit.bary.x - hit.bary.y}), -1e-4f) << "ray " << i;
    }
    EXPECT_EQ(hits, 4000) << "every ray aims inside the closed mesh";
  }
}

}  // namespace
}  // namespace candela
