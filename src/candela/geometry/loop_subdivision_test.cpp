// Loop subdivision (pbrt-v4's "loopsubdiv"): counts after n levels, the limit points of control
// vertices in closed form and independent of the level, convexity and smoothness of a convex
// control mesh's surface, planes staying planar, limit normals against the refined mesh's own
// normals, the boundary rule (the boundary is the cubic B-spline of the boundary polygon; pbrt's
// 1/5 limit rule off it by a known amount), the two rule sets agreeing where every vertex is
// regular, the normals' side, non-manifold input and the problems reported.
#include "candela/geometry/loop_subdivision.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include "candela/base/error.h"

namespace candela {
namespace {

struct ControlMesh {
  std::vector<Point3> points;
  std::vector<int> indices;
};

// The octahedron |x| + |y| + |z| = 1, its triangles wound counter-clockwise seen from outside (the
// probe shape_loopsubdiv's control mesh).
ControlMesh octahedron() {
  return {{{0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}, {0, -1, 0}},
          {0, 2, 1, 0, 3, 2, 0, 4, 3, 0, 1, 4, 5, 1, 2, 5, 2, 3, 5, 3, 4, 5, 4, 1}};
}

// An n x n grid of unit squares in z = 0, each split along a diagonal that alternates (so vertices
// have valence 4, 6 and 8), wound counter-clockwise seen from +z.
ControlMesh plane(int n) {
  ControlMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.points.emplace_back(float(i), float(j), 0.0f);
  auto at = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = at(i, j), b = at(i + 1, j), c = at(i, j + 1), d = at(i + 1, j + 1);
      if ((i + j) % 2) m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
      else m.indices.insert(m.indices.end(), {a, b, c, b, d, c});
    }
  return m;
}

// A torus of rings x segments vertices, every quad split along the same diagonal: every vertex has
// valence 6 (the regular case), wound so that the winding normal points out.
ControlMesh torus(int rings, int segments) {
  ControlMesh m;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      float u = 2 * kPi * float(i) / float(rings), v = 2 * kPi * float(j) / float(segments);
      m.points.emplace_back((2 + std::cos(v)) * std::cos(u), (2 + std::cos(v)) * std::sin(u), std::sin(v));
    }
  auto at = [&](int i, int j) { return (i % rings) * segments + (j % segments); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j)
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1),
                                         at(i, j + 1)});
  return m;
}

// A fan of triangles around point 0 whose outer points 1..n form the boundary polygon (not planar).
ControlMesh fan(int n) {
  ControlMesh m;
  m.points.emplace_back(0.1f, -0.2f, 0.5f);
  for (int i = 0; i < n; ++i) {
    float a = 2 * kPi * float(i) / float(n);
    m.points.emplace_back((1.5f + 0.4f * std::sin(3 * a)) * std::cos(a), std::sin(a), 0.3f * std::cos(2 * a));
  }
  for (int i = 0; i < n; ++i) m.indices.insert(m.indices.end(), {0, 1 + i, 1 + (i + 1) % n});
  return m;
}

TriangleMesh subdivide(const ControlMesh& m, int levels, LoopRules rules = LoopRules::PbrtV4) {
  return loop_subdivide(m.points, m.indices, levels, rules);
}

double angle_degrees(Vec3 a, Vec3 b) {
  double c = dot(normalize(a), normalize(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180 / std::numbers::pi;
}

// The index of the vertex of `mesh` nearest to `p`, and its distance.
std::pair<size_t, float> nearest_vertex(const TriangleMesh& mesh, Point3 p) {
  size_t best = 0;
  for (size_t i = 1; i < mesh.positions.size(); ++i)
    if (distance(mesh.positions[i], p) < distance(mesh.positions[best], p)) best = i;
  return {best, distance(mesh.positions[best], p)};
}

// Per vertex, the area-weighted normal of the triangles around it, on the side opposite the winding
// (the side loop_subdivide's normals face).
std::vector<Vec3> face_normals_per_vertex(const TriangleMesh& mesh) {
  std::vector<Vec3> sum(mesh.positions.size(), Vec3(0.0f));
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Point3 &a = mesh.positions[mesh.indices[t]], &b = mesh.positions[mesh.indices[t + 1]],
                 &c = mesh.positions[mesh.indices[t + 2]];
    Vec3 n = cross(c - a, b - a);
    for (int k = 0; k < 3; ++k) sum[mesh.indices[t + k]] += n;
  }
  return sum;
}

// Each undirected edge of the mesh once.
std::set<std::pair<uint32_t, uint32_t>> edges_of(const TriangleMesh& mesh) {
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  return edges;
}

void expect_well_formed(const TriangleMesh& mesh) {
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  EXPECT_TRUE(mesh.uvs.empty());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_TRUE(is_finite(mesh.positions[i])) << i;
    EXPECT_NEAR(length(mesh.normals[i]), 1, 1e-5) << i;
  }
  for (uint32_t index : mesh.indices) EXPECT_LT(index, mesh.positions.size());
}

TEST(LoopSubdivision, EachLevelQuadruplesTheTrianglesAndAddsAVertexPerEdge) {
  for (const ControlMesh& control : {octahedron(), plane(3), fan(5)}) {
    size_t vertices = control.points.size(), triangles = control.indices.size() / 3;
    size_t edges = edges_of(subdivide(control, 0)).size();
    for (int levels = 0; levels <= 4; ++levels) {
      TriangleMesh mesh = subdivide(control, levels);
      expect_well_formed(mesh);
      EXPECT_EQ(mesh.triangle_count(), triangles) << levels;
      EXPECT_EQ(mesh.positions.size(), vertices) << levels;
      EXPECT_EQ(edges_of(mesh).size(), edges) << levels;
      EXPECT_EQ(mesh.triangle_count(), control.indices.size() / 3 * (size_t(1) << (2 * levels)));
      vertices += edges;  // a new vertex on every edge
      edges = 2 * edges + 3 * triangles;  // every edge split, three new inside every triangle
      triangles *= 4;
    }
  }
  // Closed and of genus 0: V = F / 2 + 2.
  EXPECT_EQ(subdivide(octahedron(), 3).positions.size(), 8u * 64 / 2 + 2);
  EXPECT_EQ(loop_subdivision_triangle_count(8316, 3), 8316u * 64);
  EXPECT_EQ(loop_subdivision_triangle_count(1, 40), UINT64_MAX);
}

// pbrt-v4's weights at a vertex of valence 4: beta = 3/32, so its limit is half its point plus an
// eighth of its ring: the octahedron's corners go to 0.5. Loop's own weights (OpenSubdiv's) put them
// at 96/220. The limit point of a control vertex does not depend on how often the mesh is refined.
TEST(LoopSubdivision, ControlVerticesGoToTheirLimitPointsWhateverTheLevel) {
  for (auto [rules, expected] : {std::pair{LoopRules::PbrtV4, 0.5}, std::pair{LoopRules::OpenSubdiv, 96.0 / 220}})
    for (int levels = 0; levels <= 4; ++levels) {
      TriangleMesh mesh = subdivide(octahedron(), levels, rules);
      for (Point3 corner : octahedron().points) {
        auto [index, miss] = nearest_vertex(mesh, corner * float(expected));
        EXPECT_LT(miss, 1e-6f) << int(rules) << " " << levels;
        // The corner's normal is its axis, pointing in (pbrt's side).
        EXPECT_LT(distance(mesh.normals[index], -corner), 1e-5f) << int(rules) << " " << levels;
      }
    }
}

// Smooth: the largest angle between the normals at the two ends of an edge shrinks with the edges.
// With Loop's weights it halves per level (32.5, 16.7, 8.6, 4.4 degrees at levels 2 to 5), with
// pbrt-v4's more slowly near the valence-4 corners (43.9, 31.8, 22.3, 15.3).
TEST(LoopSubdivision, ConvexControlMeshGivesASmoothConvexSurfaceInsideItsHull) {
  for (auto [rules, rate] : {std::pair{LoopRules::PbrtV4, 0.75}, std::pair{LoopRules::OpenSubdiv, 0.55}}) {
    double previous_kink = 180;
    for (int levels = 2; levels <= 5; ++levels) {
      TriangleMesh mesh = subdivide(octahedron(), levels, rules);
      for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const Point3& p = mesh.positions[i];
        // Inside the octahedron (the control points' convex hull)...
        EXPECT_LE(std::abs(p.x) + std::abs(p.y) + std::abs(p.z), 1 + 1e-6f) << i;
        // ...and the normals point in (pbrt's side of the outward-wound triangles).
        EXPECT_LT(dot(mesh.normals[i], normalize(p)), -0.9f) << i;
      }
      // Convex: no vertex lies outside the plane of another's limit tangent plane.
      for (size_t i = 0; i < mesh.positions.size(); i += 7)
        for (size_t j = 0; j < mesh.positions.size(); ++j)
          ASSERT_GE(dot(mesh.positions[j] - mesh.positions[i], mesh.normals[i]), -1e-4f) << i << " " << j;
      double kink = 0;
      for (auto [a, b] : edges_of(mesh)) kink = std::max(kink, angle_degrees(mesh.normals[a], mesh.normals[b]));
      EXPECT_LT(kink, rate * previous_kink) << int(rules) << " " << levels;
      previous_kink = kink;
    }
  }
}

TEST(LoopSubdivision, APlaneStaysPlanarWithItsNormalOppositeTheWinding) {
  for (LoopRules rules : {LoopRules::PbrtV4, LoopRules::OpenSubdiv})
    for (int levels = 0; levels <= 3; ++levels) {
      TriangleMesh mesh = subdivide(plane(4), levels, rules);
      expect_well_formed(mesh);
      for (size_t i = 0; i < mesh.positions.size(); ++i) {
        EXPECT_EQ(mesh.positions[i].z, 0) << i;
        EXPECT_LT(distance(mesh.normals[i], Vec3(0, 0, -1)), 1e-6f) << i;
        EXPECT_GE(mesh.positions[i].x, 0);
        EXPECT_LE(mesh.positions[i].x, 4);
      }
    }
}

// The limit normals against the normals of the refined mesh itself (the area-weighted normal of the
// triangles around each vertex): never further apart at the next level, and close at level 5 (the
// worst at the octahedron's valence-4 corners, 0.57 degrees with pbrt's rules, 0.35 with Loop's).
TEST(LoopSubdivision, LimitNormalsAgreeWithTheRefinedMeshsNormals) {
  for (LoopRules rules : {LoopRules::PbrtV4, LoopRules::OpenSubdiv})
    for (auto [control, bound] : {std::pair{octahedron(), 0.6}, std::pair{torus(8, 6), 0.05}}) {
      double previous = 180;
      for (int levels = 2; levels <= 5; ++levels) {
        TriangleMesh mesh = subdivide(control, levels, rules);
        std::vector<Vec3> finite_difference = face_normals_per_vertex(mesh);
        double worst = 0;
        for (size_t i = 0; i < mesh.positions.size(); ++i)
          worst = std::max(worst, angle_degrees(mesh.normals[i], finite_difference[i]));
        EXPECT_LT(worst, previous) << int(rules) << " " << levels;
        previous = worst;
      }
      EXPECT_LT(previous, bound) << int(rules);
    }
}

// Where every vertex has valence 6, Warren's weights and pbrt's limit masks are Loop's: both rule
// sets give the same points. pbrt's normals, taken over the ring's limit points, differ from the
// exact ones by 2.2 degrees on this coarse torus at level 0, and by less at each level after.
TEST(LoopSubdivision, TheRuleSetsAgreeWhereEveryVertexIsRegular) {
  double previous = 2.5;
  for (int levels = 0; levels <= 4; ++levels) {
    TriangleMesh pbrt = subdivide(torus(9, 7), levels, LoopRules::PbrtV4);
    TriangleMesh exact = subdivide(torus(9, 7), levels, LoopRules::OpenSubdiv);
    ASSERT_EQ(pbrt.indices, exact.indices);
    double worst = 0;
    for (size_t i = 0; i < pbrt.positions.size(); ++i) {
      EXPECT_LT(distance(pbrt.positions[i], exact.positions[i]), 1e-5f) << i;
      worst = std::max(worst, angle_degrees(pbrt.normals[i], exact.normals[i]));
      // The winding normal points out of the torus, the normals in.
      Point3 p = pbrt.positions[i];
      Point3 ring_centre = normalize(Vec3(p.x, p.y, 0)) * 2;
      EXPECT_LT(dot(pbrt.normals[i], p - ring_centre), 0) << i;
    }
    EXPECT_LT(worst, levels == 0 ? previous : 0.6 * previous) << levels;
    previous = worst;
  }
}

// Boundary edges and vertices follow the crease rules (1/2 - 1/2, 1/8 - 3/4 - 1/8): the boundary is
// the uniform cubic B-spline of the boundary polygon. Exactly on it with OpenSubdiv's limit; pbrt's
// boundary limit rule 1/5 - 3/5 - 1/5 (the B-spline's is 1/6 - 2/3 - 1/6) leaves a control vertex
// off it by (1/5 - 1/6) (c[i-1] - 2 c[i] + c[i+1]) / 4^levels.
TEST(LoopSubdivision, TheBoundaryIsTheCubicBSplineOfTheBoundaryPolygon) {
  const int n = 7;
  ControlMesh control = fan(n);
  auto c = [&](int i) { return control.points[size_t(1 + (i % n + n) % n)]; };
  for (LoopRules rules : {LoopRules::PbrtV4, LoopRules::OpenSubdiv})
    for (int levels = 0; levels <= 4; ++levels) {
      TriangleMesh mesh = subdivide(control, levels, rules);
      for (int i = 0; i < n; ++i) {
        Vec3 second_difference = c(i - 1) - c(i) * 2 + c(i + 1);
        Point3 on_spline = (c(i - 1) + c(i) * 4 + c(i + 1)) / 6;
        Point3 expected = on_spline;
        if (rules == LoopRules::PbrtV4)
          expected += second_difference * float((1.0 / 5 - 1.0 / 6) / std::pow(4, levels));
        EXPECT_LT(nearest_vertex(mesh, expected).second, 1e-5f) << int(rules) << " " << levels << " " << i;
        if (rules == LoopRules::OpenSubdiv && levels >= 1) {
          // The boundary edge's midpoint: the spline halfway between c[i] and c[i+1].
          Point3 halfway = (c(i - 1) + c(i) * 23 + c(i + 1) * 23 + c(i + 2)) / 48;
          EXPECT_LT(nearest_vertex(mesh, halfway).second, 1e-5f) << levels << " " << i;
        }
      }
    }
}

// pbrt-v4's ring masks on an open mesh: checked against values worked out by hand for a single
// triangle (every vertex a boundary vertex of valence 2) and levels 0.
TEST(LoopSubdivision, PbrtsBoundaryRulesOnASingleTriangle) {
  ControlMesh triangle{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
  TriangleMesh mesh = subdivide(triangle, 0);
  ASSERT_EQ(mesh.positions.size(), 3u);
  // 3/5 of the vertex and 1/5 of each neighbour.
  EXPECT_LT(distance(mesh.positions[0], Point3(0.2f, 0.2f, 0)), 1e-6f);
  EXPECT_LT(distance(mesh.positions[1], Point3(0.6f, 0.2f, 0)), 1e-6f);
  for (const Normal3& normal : mesh.normals) EXPECT_LT(distance(normal, Vec3(0, 0, -1)), 1e-6f);
  // Reversing the winding reverses the normals.
  TriangleMesh reversed = subdivide({triangle.points, {0, 2, 1}}, 2);
  for (const Normal3& normal : reversed.normals) EXPECT_LT(distance(normal, Vec3(0, 0, 1)), 1e-6f);
}

TEST(LoopSubdivision, PointsNoTriangleUsesAreLeftOut) {
  ControlMesh m = octahedron();
  m.points.insert(m.points.begin(), Point3(5, 5, 5));
  for (int& index : m.indices) ++index;
  TriangleMesh with_unused = subdivide(m, 2);
  TriangleMesh without = subdivide(octahedron(), 2);
  EXPECT_EQ(with_unused.positions, without.positions);
  EXPECT_EQ(with_unused.indices, without.indices);
}

// Edges of three triangles, triangles that disagree about their shared edge's direction, fans
// meeting at one vertex: OpenSubdiv's rules there (creases and corners), a well-formed mesh out.
TEST(LoopSubdivision, NonManifoldControlMeshesAreSubdividedAsOpenSubdivDoes) {
  std::vector<Point3> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}};
  for (const std::vector<int>& indices : {std::vector<int>{0, 1, 2, 1, 0, 4, 0, 1, 5},  // a fin
                                          std::vector<int>{0, 1, 2, 0, 1, 4},           // inconsistent winding
                                          std::vector<int>{0, 1, 2, 0, 3, 4},           // a bow tie
                                          std::vector<int>{0, 1, 2, 0, 1, 2}})          // the same triangle twice
    for (LoopRules rules : {LoopRules::PbrtV4, LoopRules::OpenSubdiv}) {
      TriangleMesh mesh = loop_subdivide(points, indices, 3, rules);
      expect_well_formed(mesh);
      EXPECT_EQ(mesh.triangle_count(), indices.size() / 3 * 64);
    }
}

TEST(LoopSubdivision, ProblemsAreReported) {
  const std::vector<int> triangle = {0, 1, 2};
  EXPECT_EQ(loop_subdivision_problem(3, triangle, 3), "");
  EXPECT_EQ(loop_subdivision_problem(3, triangle, -1), "levels is -1: it must be at least 0");
  EXPECT_EQ(loop_subdivision_problem(3, {}, 1), "there are no triangles");
  EXPECT_EQ(loop_subdivision_problem(3, {0, 1, 2, 0}, 1), "4 indices is not a multiple of 3 (three per triangle)");
  EXPECT_EQ(loop_subdivision_problem(3, {0, 1, 3}, 1), "index 3 (number 3) is out of range: there are 3 points");
  EXPECT_EQ(loop_subdivision_problem(3, {0, -1, 2}, 1), "index -1 (number 2) is out of range: there are 3 points");
  EXPECT_EQ(loop_subdivision_problem(3, {0, 1, 2, 2, 1, 2}, 1),
            "triangle 2 (2 1 2) names a point twice: Loop subdivision needs three distinct corners");
  EXPECT_EQ(loop_subdivision_problem(3, triangle, 11), "");  // 4.2 million triangles
  EXPECT_EQ(loop_subdivision_problem(3, triangle, 12),
            "12 levels of subdivision make 16777216 triangles of the 1 given, more than the 4194304 candela "
            "subdivides one mesh into; use fewer levels");
  // A fan of 70000 triangles around point 0: more than OpenSubdiv takes.
  std::vector<int> fan_indices;
  for (int i = 0; i < 70000; ++i) fan_indices.insert(fan_indices.end(), {0, 1 + i, 1 + (i + 1) % 70000});
  EXPECT_EQ(loop_subdivision_problem(70001, fan_indices, 1),
            "point 0 has 70000 triangles and 70000 neighbours around it; OpenSubdiv allows at most 65535");
  EXPECT_NE(loop_subdivision_problem(3, triangle, 1000).find("make too many triangles"), std::string::npos);
  EXPECT_THROW(loop_subdivide({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 1}, 1), InternalError);
}

}  // namespace
}  // namespace candela
