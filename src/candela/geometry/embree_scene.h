#pragma once
// The acceleration structure: every intersection and occlusion query goes through Embree.
// Triangle meshes are Embree triangle geometry; spheres and infinite planes are Embree user
// geometry intersected analytically in double precision (exact, not tessellated).
#include <embree3/rtcore.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "candela/geometry/ray.h"
#include "candela/math/transform.h"

namespace candela {

struct EmbreeHit {
  float t;
  uint32_t geometry;   // the id returned by add_*
  uint32_t primitive;  // triangle index
  float u, v;          // Embree barycentrics: p = (1-u-v) p0 + u p1 + v p2
};

// Analytic shapes kept in object space with both transforms, so non-uniform scales work.
struct SphereGeometry {
  Transform to_world;
  Point3 center;
  float radius;
};
struct PlaneGeometry {
  Point3 point;
  Normal3 normal;  // unit length, world space
};

class EmbreeScene {
 public:
  EmbreeScene();
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Each attaches a geometry under the caller's id, reported back in hits. Vertex and index data
  // are copied into Embree.
  void add_triangles(uint32_t id, const std::vector<Point3>& positions, const std::vector<uint32_t>& indices);
  void add_sphere(uint32_t id, const SphereGeometry& sphere);
  void add_plane(uint32_t id, const PlaneGeometry& plane, float extent);
  void commit();

  bool intersect(const Ray& ray, EmbreeHit& hit) const;
  bool occluded(const Ray& ray) const;  // any hit in (0, ray.t_max)

 private:
  static void sphere_bounds(const RTCBoundsFunctionArguments* args);
  static void sphere_intersect(const RTCIntersectFunctionNArguments* args);
  static void sphere_occluded(const RTCOccludedFunctionNArguments* args);
  static void plane_bounds(const RTCBoundsFunctionArguments* args);
  static void plane_intersect(const RTCIntersectFunctionNArguments* args);
  static void plane_occluded(const RTCOccludedFunctionNArguments* args);

  struct PlaneRecord {
    PlaneGeometry plane;
    float extent;
  };

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  // Stable storage for user-geometry data (Embree keeps raw pointers to it).
  std::vector<std::unique_ptr<SphereGeometry>> spheres_;
  std::vector<std::unique_ptr<PlaneRecord>> planes_;
};

}  // namespace candela
