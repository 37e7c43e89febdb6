#include "candela/geometry/loop_subdivision.h"

#include <fmt/format.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <utility>

#include "candela/base/error.h"

namespace candela {

namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// A point in double precision, in the form OpenSubdiv's PrimvarRefiner interpolates.
struct LoopPoint {
  double x = 0, y = 0, z = 0;
  void Clear(void* = nullptr) { x = y = z = 0; }
  void AddWithWeight(const LoopPoint& p, float weight) {
    x += weight * p.x;
    y += weight * p.y;
    z += weight * p.z;
  }
  LoopPoint operator+(const LoopPoint& b) const { return {x + b.x, y + b.y, z + b.z}; }
  LoopPoint operator-(const LoopPoint& b) const { return {x - b.x, y - b.y, z - b.z}; }
  LoopPoint operator*(double s) const { return {x * s, y * s, z * s}; }
  LoopPoint& operator+=(const LoopPoint& b) { return *this = *this + b; }
};

LoopPoint cross(const LoopPoint& a, const LoopPoint& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

double length(const LoopPoint& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

// The most edges or faces around a vertex OpenSubdiv accepts.
constexpr size_t kMaxValence = size_t(Far::VALENCE_LIMIT);

// PrimvarRefiner takes its arrays by reference to something indexable.
using Points = std::vector<LoopPoint>;

// pbrt-v4's one-ring of vertex v of `level`, as indices of its neighbours: for an interior vertex
// clockwise about the winding normal (OpenSubdiv orders a manifold vertex's edges counter-clockwise),
// for a boundary vertex counter-clockwise from one boundary neighbour to the other (OpenSubdiv's
// order there). pbrt's valence is the ring's size.
void pbrt_ring(const Far::TopologyLevel& level, Far::Index v, std::vector<Far::Index>& ring) {
  Far::ConstIndexArray edges = level.GetVertexEdges(v);
  ring.clear();
  for (int i = 0; i < edges.size(); ++i) {
    Far::ConstIndexArray ends = level.GetEdgeVertices(edges[i]);
    ring.push_back(ends[0] == v ? ends[1] : ends[0]);
  }
  if (!level.IsVertexBoundary(v)) std::reverse(ring.begin(), ring.end());
}

// Warren's vertex weight, pbrt-v4's beta().
double pbrt_beta(int valence) { return valence == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * valence); }

// (1 - n w) p + w (sum of the ring): pbrt-v4's weightOneRing.
LoopPoint weight_one_ring(const Points& p, Far::Index v, const std::vector<Far::Index>& ring, double w) {
  LoopPoint sum = p[v] * (1 - double(ring.size()) * w);
  for (Far::Index r : ring) sum += p[r] * w;
  return sum;
}

// (1 - 2 w) p + w (the two boundary neighbours): pbrt-v4's weightBoundary.
LoopPoint weight_boundary(const Points& p, Far::Index v, const std::vector<Far::Index>& ring, double w) {
  return p[v] * (1 - 2 * w) + (p[ring.front()] + p[ring.back()]) * w;
}

// pbrt-v4's limit-surface normal S x T at vertex v, from the limit positions `p` of v and its ring.
LoopPoint pbrt_limit_normal(const Points& p, Far::Index v, const std::vector<Far::Index>& ring, bool boundary) {
  const int n = int(ring.size());
  LoopPoint s, t;
  if (!boundary) {
    for (int j = 0; j < n; ++j) {
      double angle = 2 * std::numbers::pi * j / n;
      s += p[ring[j]] * std::cos(angle);
      t += p[ring[j]] * std::sin(angle);
    }
  } else {
    const LoopPoint& centre = p[v];
    s = p[ring[n - 1]] - p[ring[0]];
    if (n == 2) {
      t = p[ring[0]] + p[ring[1]] - centre * 2;
    } else if (n == 3) {
      t = p[ring[1]] - centre;
    } else if (n == 4) {  // regular
      t = p[ring[0]] * -1 + p[ring[1]] * 2 + p[ring[2]] * 2 + p[ring[3]] * -1 + centre * -2;
    } else {
      double theta = std::numbers::pi / (n - 1);
      t = (p[ring[0]] + p[ring[n - 1]]) * std::sin(theta);
      for (int k = 1; k < n - 1; ++k) t += p[ring[k]] * ((2 * std::cos(theta) - 2) * std::sin(k * theta));
      t = t * -1;
    }
  }
  return cross(s, t);
}

}  // namespace

uint64_t loop_subdivision_triangle_count(uint64_t triangles, int levels) {
  for (int i = 0; i < levels; ++i) {
    if (triangles > UINT64_MAX / 4) return UINT64_MAX;
    triangles *= 4;
  }
  return triangles;
}

std::string loop_subdivision_problem(size_t point_count, const std::vector<int>& indices, int levels) {
  if (levels < 0) return fmt::format("levels is {}: it must be at least 0", levels);
  if (indices.empty()) return "there are no triangles";
  if (indices.size() % 3 != 0)
    return fmt::format("{} indices is not a multiple of 3 (three per triangle)", indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || size_t(indices[i]) >= point_count)
      return fmt::format("index {} (number {}) is out of range: there are {} points", indices[i], i + 1, point_count);
  for (size_t t = 0; t < indices.size(); t += 3) {
    int a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a == b || b == c || a == c)
      return fmt::format("triangle {} ({} {} {}) names a point twice: Loop subdivision needs three distinct corners",
                         t / 3 + 1, a, b, c);
  }
  // OpenSubdiv's limit on the triangles and the edges around a vertex.
  std::vector<uint32_t> triangles_at(point_count, 0);
  std::vector<std::pair<int, int>> neighbours;  // (point, neighbour) for both directions of every edge
  neighbours.reserve(2 * indices.size());
  for (size_t t = 0; t < indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      int a = indices[t + k], b = indices[t + (k + 1) % 3];
      ++triangles_at[size_t(a)];
      neighbours.emplace_back(a, b);
      neighbours.emplace_back(b, a);
    }
  std::sort(neighbours.begin(), neighbours.end());
  neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
  for (size_t i = 0; i < neighbours.size();) {
    size_t j = i;
    while (j < neighbours.size() && neighbours[j].first == neighbours[i].first) ++j;
    int point = neighbours[i].first;
    if (j - i > kMaxValence || triangles_at[size_t(point)] > kMaxValence)
      return fmt::format("point {} has {} triangles and {} neighbours around it; OpenSubdiv allows at most {}", point,
                         triangles_at[size_t(point)], j - i, kMaxValence);
    i = j;
  }
  uint64_t triangles = loop_subdivision_triangle_count(indices.size() / 3, levels);
  if (triangles > kMaxLoopSubdivisionTriangles)
    return fmt::format("{} levels of subdivision make {} triangles of the {} given, more than the {} candela "
                       "subdivides one mesh into; use fewer levels",
                       levels, triangles == UINT64_MAX ? std::string("too many") : std::to_string(triangles),
                       indices.size() / 3, kMaxLoopSubdivisionTriangles);
  return {};
}

TriangleMesh loop_subdivide(const std::vector<Point3>& points, const std::vector<int>& indices, int levels,
                            LoopRules rules) {
  if (std::string problem = loop_subdivision_problem(points.size(), indices, levels); !problem.empty())
    throw InternalError("loop_subdivide: " + problem);

  // The control mesh without the points no triangle uses.
  std::vector<int> remap(points.size(), -1);
  std::vector<int> face_vertices(indices.size());
  Points control;
  for (size_t i = 0; i < indices.size(); ++i) {
    int& slot = remap[size_t(indices[i])];
    if (slot < 0) {
      slot = int(control.size());
      const Point3& p = points[size_t(indices[i])];
      control.push_back({p.x, p.y, p.z});
    }
    face_vertices[i] = slot;
  }
  const int face_count = int(indices.size() / 3);
  std::vector<int> vertices_per_face(size_t(face_count), 3);
  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = int(control.size());
  descriptor.numFaces = face_count;
  descriptor.numVertsPerFace = vertices_per_face.data();
  descriptor.vertIndicesPerFace = face_vertices.data();
  Sdc::Options options;
  options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);  // boundaries are creases
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(descriptor, Factory::Options(Sdc::SCHEME_LOOP, options)));
  if (!refiner) throw InternalError("loop_subdivide: OpenSubdiv could not build the control mesh's topology");
  if (levels > 0) {
    Far::TopologyRefiner::UniformOptions uniform(levels);
    uniform.fullTopologyInLastLevel = true;  // the last level's rings, for the limit
    refiner->RefineUniform(uniform);
  }
  const Far::PrimvarRefiner primvars(*refiner);

  // Refine: Loop's edge points (and OpenSubdiv's rules where there is no manifold ring) from
  // PrimvarRefiner, then pbrt-v4's vertex points in place of Loop's.
  Points p = std::move(control);
  std::vector<Far::Index> ring;
  for (int level = 1; level <= levels; ++level) {
    const Far::TopologyLevel& parent = refiner->GetLevel(level - 1);
    Points child(size_t(refiner->GetLevel(level).GetNumVertices()));
    primvars.Interpolate(level, p, child);
    if (rules == LoopRules::PbrtV4)
      for (Far::Index v = 0; v < parent.GetNumVertices(); ++v) {
        if (parent.IsVertexNonManifold(v)) continue;
        pbrt_ring(parent, v, ring);
        child[size_t(parent.GetVertexChildVertex(v))] =
            parent.IsVertexBoundary(v) ? weight_boundary(p, v, ring, 1.0 / 8.0)
                                       : weight_one_ring(p, v, ring, pbrt_beta(int(ring.size())));
      }
    p = std::move(child);
  }

  // Limit positions and normals: OpenSubdiv's (everywhere with its rules, else only where pbrt-v4's
  // have no ring), then pbrt-v4's.
  const Far::TopologyLevel& last = refiner->GetLevel(levels);
  const size_t vertex_count = size_t(last.GetNumVertices());
  Points limit(vertex_count), normal(vertex_count);
  bool manifold = true;
  for (Far::Index v = 0; v < last.GetNumVertices() && manifold; ++v) manifold = !last.IsVertexNonManifold(v);
  if (rules == LoopRules::OpenSubdiv || !manifold) {
    Points du(vertex_count), dv(vertex_count);
    primvars.Limit(p, limit, du, dv);
    // OpenSubdiv's tangents face du x dv along the winding normal; pbrt's normals face the other way.
    for (size_t v = 0; v < vertex_count; ++v) normal[v] = cross(dv[v], du[v]);
  }
  if (rules == LoopRules::PbrtV4) {
    for (Far::Index v = 0; v < last.GetNumVertices(); ++v) {
      if (last.IsVertexNonManifold(v)) continue;
      pbrt_ring(last, v, ring);
      const int n = int(ring.size());
      limit[size_t(v)] = last.IsVertexBoundary(v)
                             ? weight_boundary(p, v, ring, 1.0 / 5.0)
                             : weight_one_ring(p, v, ring, 1.0 / (n + 3.0 / (8.0 * pbrt_beta(n))));
    }
    // The tangents are taken over the ring's limit points, so after all of them are known.
    for (Far::Index v = 0; v < last.GetNumVertices(); ++v) {
      if (last.IsVertexNonManifold(v)) continue;
      pbrt_ring(last, v, ring);
      normal[size_t(v)] = pbrt_limit_normal(limit, v, ring, last.IsVertexBoundary(v));
    }
  }

  TriangleMesh mesh;
  mesh.positions.reserve(vertex_count);
  for (const LoopPoint& q : limit) mesh.positions.emplace_back(float(q.x), float(q.y), float(q.z));
  mesh.indices.reserve(3 * size_t(last.GetNumFaces()));
  for (Far::Index f = 0; f < last.GetNumFaces(); ++f) {
    Far::ConstIndexArray corners = last.GetFaceVertices(f);
    for (int c = 0; c < 3; ++c) mesh.indices.push_back(uint32_t(corners[c]));
  }
  // Unit normals; where the limit normal vanishes (or is not finite), the adjacent triangles'
  // area-weighted normal on the same side (opposite the winding).
  mesh.normals.resize(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) {
    LoopPoint n = normal[v];
    double len = length(n);
    if (!(len > 0) || !std::isfinite(len)) {
      n = {};
      for (Far::Index f : last.GetVertexFaces(Far::Index(v))) {
        Far::ConstIndexArray c = last.GetFaceVertices(f);
        n += cross(limit[size_t(c[2])] - limit[size_t(c[0])], limit[size_t(c[1])] - limit[size_t(c[0])]);
      }
      len = length(n);
    }
    mesh.normals[v] = len > 0 && std::isfinite(len) ? Normal3(float(n.x / len), float(n.y / len), float(n.z / len))
                                                   : Normal3(0, 0, 1);
  }
  return mesh;
}

}  // namespace candela
