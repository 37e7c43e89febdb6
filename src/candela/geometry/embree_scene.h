#pragma once
// The acceleration structure: every intersection and occlusion query goes through Embree.
// Triangle meshes are Embree quad geometry, their triangles paired across shared edges
// (triangle_pairs.h; hits are reported per triangle), or with the compact layout Embree triangles; spheres, disks, open cylinders and infinite planes
// are Embree user geometry intersected analytically in double precision (exact, not tessellated), and
// so are SDF grids, one primitive per voxel that holds surface.
// Moving shapes (motion blur, the paper's sec. 4.2) have two Embree time steps: their transform is
// interpolated linearly between the start and end transforms, as Embree interpolates vertices.
#include <embree3/rtcore.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "candela/description/shapes.h"
#include "candela/geometry/ray.h"
#include "candela/geometry/ray_log.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/geometry/triangle_pairs.h"
#include "candela/math/transform.h"

namespace candela {

struct EmbreeHit {
  float t;
  uint32_t geometry;   // the id returned by add_*
  uint32_t primitive;  // triangle index
  float u, v;          // Embree barycentrics: p = (1-u-v) p0 + u p1 + v p2 (curves: u along the segment)
  int instance = -1;   // the instance the geometry was reached through (index of add_instance), or -1
  Vec3 ng{0.0f};       // Embree's geometric normal, not normalised, in the geometry's own space (used for curves)
};

// Analytic shapes kept in object space with both transforms, so non-uniform scales work.
struct SphereGeometry {
  Transform to_world;
  Point3 center;
  float radius;
  // A moving sphere: its transform at Embree time 1 (to_world is the one at time 0).
  std::optional<Transform> to_world_end;
  SphereUv uv = SphereUv::Mitsuba;
  // A partial sphere (SphereShape::partial): only the points with z_min <= z <= z_max (heights above
  // the centre, within [-radius, radius]) and azimuth phi <= phi_max (radians) are hit; rays pass
  // through the rest to the far side. theta_z_min and theta_z_max (acos(z / radius) of the two)
  // place pbrt-v4's v.
  bool partial = false;
  float z_min = 0, z_max = 0, phi_max = 2 * kPi;
  float theta_z_min = kPi, theta_z_max = 0;
};
// A disk or an open cylinder: the unit shape in its own space (disk: x^2 + y^2 <= 1 in the plane
// z = 0; cylinder: x^2 + y^2 = 1, 0 <= z <= 1) placed by any invertible affine `to_world`
// (non-uniform scales and shears make ellipses and elliptic tubes, intersected exactly).
struct QuadricGeometry {
  enum class Kind : uint8_t { Disk, Cylinder };
  Kind kind = Kind::Disk;
  Transform to_world;
  std::optional<Transform> to_world_end;  // moving: the transform at Embree time 1
  // Cylinders: only the azimuths atan2(y, x) in [0, phi_max] of the unit tube are hit (a partial
  // cylinder when below 2 pi).
  float phi_max = 2 * kPi;
};
// An SDF grid (sdf_grid.h) placed by `to_world` (any invertible affine map); each voxel the surface
// passes through is one Embree primitive, intersected in double precision.
struct SdfGridGeometry {
  std::shared_ptr<const SdfGrid> grid;
  Transform to_world;  // object space ([0,1]^3) to world
  std::optional<Transform> to_world_end;  // moving: the transform at Embree time 1
  // Object space to world at Embree time `time`, and index space (sample (i, j, k) at (i, j, k)) to
  // world; nullopt where the interpolated transform is singular.
  std::optional<Transform> to_world_at(float time) const;
  std::optional<Transform> index_to_world(float time) const;
};
// Curves (geometry/curves.h): cubic Bézier segments of 4 control points each, (x, y, z, radius) as
// Embree takes them, in world space (an object's space for shapes of an object).
struct CurveGeometry {
  // Embree's flat (ray-facing ribbons), round (tubes) and normal-oriented curves.
  enum class Kind : uint8_t { Flat, Round, Ribbon };
  Kind kind = Kind::Flat;
  std::vector<float> control;      // 16 floats per segment
  std::vector<float> control_end;  // a moving curve's at Embree time 1 (empty: static)
  // Ribbons: the control normals of each segment's normal curve (4 per segment, Embree's normal
  // buffer), and the unit normals at its ends (2 per segment, pbrt-v4's, interpolated by slerp_normal);
  // the same at time 1 for a moving ribbon.
  std::vector<Normal3> normals, normals_end;
  std::vector<Normal3> end_normals, end_normals_end;
  unsigned tessellation = 4;  // flat curves: the pieces of Embree's polyline per segment
  size_t segment_count() const { return control.size() / 16; }
  bool moving() const { return !control_end.empty(); }
};

struct PlaneGeometry {
  Point3 point;
  Normal3 normal;  // unit length, world space
};

// Bounds of a sphere under `to_world`: the transformed corners of its object-space box.
Bounds3 sphere_world_bounds(const SphereGeometry& sphere, const Transform& to_world);
// Bounds of a disk or cylinder under `to_world`: the transformed corners of its object-space box.
Bounds3 quadric_world_bounds(const QuadricGeometry& q, const Transform& to_world);
// Bounds of voxel `voxel` of an SDF grid under `to_world` (the grid's object-to-world transform).
Bounds3 sdf_voxel_world_bounds(const SdfGrid& grid, uint32_t voxel, const Transform& to_world);
// The nearest intersection of (o + t d) with the unit disk or cylinder in its own space, t in
// (t_near, t_far), the cylinder cut to the azimuths up to phi_max; exposed for tests.
bool intersect_unit_quadric(QuadricGeometry::Kind kind, const Point3& o, const Vec3& d, double t_near, double t_far,
                            double& t_hit, float phi_max = 2 * kPi);

class EmbreeScene {
 public:
  // Ray::time is absolute: shapes move between transform_start_time (Embree time 0) and
  // transform_end_time (Embree time 1), and stand still outside.
  // `compact`: Embree's compact layout (leaves index the shared vertices instead of copying them).
  explicit EmbreeScene(float transform_start_time = 0, float transform_end_time = 1, bool compact = false);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Each attaches a geometry under the caller's id, reported back in hits; ids are unique across
  // the world and all objects. `object` is the object (from add_object) the geometry belongs to, or
  // -1 for the world.
  //
  // Triangles whose vertices Embree reads in place, without a copy: both arrays must outlive this
  // scene unchanged and unmoved (their buffers, that is; the vectors themselves may be moved), and
  // `positions` must have capacity for one more element (Embree reads vertices with 16-byte loads).
  // Embree sees them as quads of paired triangles (not with the compact layout); hits name the
  // triangle either way (index into `indices` / 3).
  void add_shared_triangles(uint32_t id, const std::vector<Point3>& positions, const std::vector<uint32_t>& indices,
                            int object = -1);
  // Triangles whose vertices move linearly from `positions` at time 0 to `positions_end` at time 1
  // (copied into Embree).
  void add_moving_triangles(uint32_t id, const std::vector<Point3>& positions, const std::vector<Point3>& positions_end,
                            const std::vector<uint32_t>& indices);
  void add_sphere(uint32_t id, const SphereGeometry& sphere, int object = -1);  // moving when sphere.to_world_end is set
  void add_quadric(uint32_t id, const QuadricGeometry& q, int object = -1);  // moving when q.to_world_end is set
  void add_sdf_grid(uint32_t id, const SdfGridGeometry& sdf, int object = -1);  // moving when sdf.to_world_end is set
  void add_plane(uint32_t id, const PlaneGeometry& plane, float extent);
  // Curves, read in place where static: `curve` (its control array) must outlive this scene unchanged
  // and unmoved. Round curves are hit only from outside (rays that leave a tube's surface, inwards or
  // outwards, pass through it: a fibre is crossed, as pbrt-v4's ray offsets cross it); Embree ignores
  // flat curves closer to a ray's origin than twice their radius.
  void add_curves(uint32_t id, const CurveGeometry& curve, int object = -1);
  // Objects for instancing: a separate acceleration structure, built once, placed by instances.
  int add_object();
  // Places `object` (complete by now) in the world under `to_world`, moving to `to_world_end` over
  // the shutter when given. `id` must differ from every geometry id; hits report the instance's
  // index (0, 1, ... in the order of these calls) in EmbreeHit::instance.
  void add_instance(uint32_t id, int object, const Transform& to_world, const Transform* to_world_end);
  void commit();

  bool intersect(const Ray& ray, EmbreeHit& hit) const;
  bool occluded(const Ray& ray) const;  // any hit in (0, ray.t_max)
  // Embree's time in [0,1] for an absolute ray time: where between the two transforms shapes are.
  float normalized_time(float time) const;

  // The ray as Embree takes it: Embree's time, every mask bit set.
  RTCRay embree_ray(const Ray& ray) const;

  // Records every ray traced from now on into `log` (null: stop recording); for benchmarks.
  void set_ray_log(RayLog* log) { ray_log_ = log; }
  // The committed Embree scene, for benchmarks that call Embree directly.
  RTCScene handle() const { return scene_; }

 private:
  static void sphere_bounds(const RTCBoundsFunctionArguments* args);
  static void quadric_bounds(const RTCBoundsFunctionArguments* args);
  static void sdf_bounds(const RTCBoundsFunctionArguments* args);
  static void sdf_intersect(const RTCIntersectFunctionNArguments* args);
  static void sdf_occluded(const RTCOccludedFunctionNArguments* args);
  static void plane_bounds(const RTCBoundsFunctionArguments* args);
  static void plane_intersect(const RTCIntersectFunctionNArguments* args);
  static void plane_occluded(const RTCOccludedFunctionNArguments* args);

  struct PlaneRecord {
    PlaneGeometry plane;
    float extent;
  };
  struct SdfGridRecord {
    SdfGridGeometry sdf;
    Matrix4 world_to_index;  // a static grid's, computed once rather than per ray and voxel
  };

  void attach(RTCGeometry geom, uint32_t id, int object = -1);
  // A user geometry of `primitives` primitives on `data` (kept alive by the caller), with two time
  // steps when `moving`.
  void attach_user_geometry(uint32_t id, void* data, unsigned primitives, bool moving, RTCBoundsFunction bounds,
                            RTCIntersectFunctionN intersect, RTCOccludedFunctionN occluded, int object = -1);
  // The Embree geometry for the triangles `indices` (vertices still to be set): quads of paired
  // triangles, the pairing kept under `id` for intersect(); with the compact layout, the triangles
  // themselves (reading `indices` in place when `shared`, else copying them).
  RTCGeometry new_triangle_geometry(uint32_t id, const std::vector<Point3>& positions,
                                    const std::vector<uint32_t>& indices, bool shared);

  float time_start_ = 0, time_scale_ = 1;  // Embree time = (time - time_start_) * time_scale_
  bool compact_ = false;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<RTCScene> objects_;
  RayLog* ray_log_ = nullptr;
  std::vector<uint32_t> instance_ids_;  // Embree geometry id of each instance, in add_instance order
  // Stable storage for user-geometry data (Embree keeps raw pointers to it).
  std::vector<std::unique_ptr<SphereGeometry>> spheres_;
  std::vector<std::unique_ptr<QuadricGeometry>> quadrics_;
  std::vector<std::unique_ptr<SdfGridRecord>> sdf_grids_;
  std::vector<std::unique_ptr<PlaneRecord>> planes_;
  // By geometry id: the triangle pairs of a mesh (Embree reads their quads in place), or null.
  std::vector<std::unique_ptr<TrianglePairs>> triangle_pairs_;
};

}  // namespace candela
