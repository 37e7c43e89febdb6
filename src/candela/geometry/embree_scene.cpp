#include "candela/geometry/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "candela/base/error.h"
#include "candela/math/vec3d.h"

namespace candela {
namespace {

void report_embree_error(void*, RTCError code, const char* message) {
  // Errors from Embree are programming or resource errors, not user input errors.
  throw InternalError("Embree error " + std::to_string(int(code)) + ": " + (message ? message : ""));
}

// A ray as a user-geometry callback sees it; time is Embree's, in [0,1].
struct UserRay {
  Vec3d o, d;
  double t_near, t_far;
  float time;
};

// Whether the point `offset` from a partial sphere's centre (object space, on the sphere up to
// rounding) is in the part kept: its height, moved onto the sphere, within [z_min, z_max] (tested
// only where the cut is inside the sphere, as pbrt-v4 does) and its azimuth at most phi_max.
bool partial_sphere_keeps(const SphereGeometry& s, const Vec3d& offset) {
  double len = std::sqrt(dot(offset, offset));
  double z = len > 0 ? offset.z * (double(s.radius) / len) : 0;
  if ((s.z_min > -s.radius && z < s.z_min) || (s.z_max < s.radius && z > s.z_max)) return false;
  double phi = std::atan2(offset.y, offset.x);
  if (phi < 0) phi += 2 * std::numbers::pi;
  return phi <= double(s.phi_max);
}

// Nearest root of the ray-sphere quadratic in (t_near, t_far), solved in object space (reached with
// `inv`, the world-to-object matrix) in double precision with the cancellation-free quadratic formula.
// A partial sphere takes the far root where the near one is cut away.
bool intersect_sphere_in_object_space(const SphereGeometry& s, const Matrix4& inv, const UserRay& ray, double& t_hit) {
  const double t_near = ray.t_near, t_far = ray.t_far;
  Vec3d o = apply(inv, ray.o, 1);
  Vec3d d = apply(inv, ray.d, 0);
  Vec3d f{o.x - s.center.x, o.y - s.center.y, o.z - s.center.z};
  double a = dot(d, d);
  double b_half = dot(f, d);
  // Discriminant from the perpendicular distance (Ray Tracing Gems, ch. 7): stable for distant rays.
  double inv_len = 1.0 / std::sqrt(a);
  Vec3d dn{d.x * inv_len, d.y * inv_len, d.z * inv_len};
  double fd = dot(f, dn);
  Vec3d perp{f.x - fd * dn.x, f.y - fd * dn.y, f.z - fd * dn.z};
  double r = s.radius;
  double disc = (r - std::sqrt(dot(perp, perp))) * (r + std::sqrt(dot(perp, perp)));
  if (disc < 0) return false;
  double c = dot(f, f) - r * r;
  double q = -(b_half + std::copysign(std::sqrt(a * disc), b_half));
  double t0 = q / a, t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  if (s.partial) {
    for (double t : {t0, t1})
      if (t > t_near && t < t_far && partial_sphere_keeps(s, {f.x + t * d.x, f.y + t * d.y, f.z + t * d.z})) {
        t_hit = t;
        return true;
      }
    return false;
  }
  if (t0 > t_near && t0 < t_far) { t_hit = t0; return true; }
  if (t1 > t_near && t1 < t_far) { t_hit = t1; return true; }
  return false;
}

bool intersect_sphere(const SphereGeometry& s, const UserRay& ray, double& t_hit) {
  return intersect_sphere_in_object_space(s, s.to_world.inverse_matrix(), ray, t_hit);
}

// A moving sphere is intersected with its transform at the ray's time (a per-ray inverse that static
// spheres do not pay for).
bool intersect_moving_sphere(const SphereGeometry& s, const UserRay& ray, double& t_hit) {
  std::optional<Transform> to_world = interpolate_transform(s.to_world, *s.to_world_end, ray.time);
  return to_world && intersect_sphere_in_object_space(s, to_world->inverse_matrix(), ray, t_hit);
}

// The unit disk (z = 0, x^2 + y^2 <= 1) or open unit cylinder (x^2 + y^2 = 1, 0 <= z <= 1, the
// azimuths up to phi_max), in object space, in double precision.
bool intersect_unit_quadric_d(QuadricGeometry::Kind kind, const Vec3d& o, const Vec3d& d, double t_near, double t_far,
                              double& t_hit, float phi_max) {
  if (kind == QuadricGeometry::Kind::Disk) {
    if (d.z == 0) return false;
    double t = -o.z / d.z;
    if (!(t > t_near && t < t_far)) return false;
    double x = o.x + t * d.x, y = o.y + t * d.y;
    if (x * x + y * y > 1) return false;
    t_hit = t;
    return true;
  }
  // The tube: the 2D ray (o.xy + t d.xy) against the unit circle, roots in increasing order, the
  // first in (t_near, t_far) whose height is within [0, 1] (and azimuth within [0, phi_max], so that
  // through a cut the far side is hit). The discriminant comes from the
  // perpendicular distance to the axis, which stays accurate for distant rays (as for spheres).
  double a = d.x * d.x + d.y * d.y;
  if (!(a > 0)) return false;
  double b_half = o.x * d.x + o.y * d.y;
  double inv_len = 1.0 / std::sqrt(a);
  double dnx = d.x * inv_len, dny = d.y * inv_len;
  double fd = o.x * dnx + o.y * dny;
  double px = o.x - fd * dnx, py = o.y - fd * dny;
  double perp = std::sqrt(px * px + py * py);
  double disc = (1 - perp) * (1 + perp);
  if (disc < 0) return false;
  double c = o.x * o.x + o.y * o.y - 1;
  double q = -(b_half + std::copysign(std::sqrt(a * disc), b_half));
  double t0 = q / a, t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  const bool cut = phi_max < 2 * kPi;
  for (double t : {t0, t1}) {
    if (!(t > t_near && t < t_far)) continue;
    double z = o.z + t * d.z;
    if (!(z >= 0 && z <= 1)) continue;
    if (cut) {
      double phi = std::atan2(o.y + t * d.y, o.x + t * d.x);
      if (phi < 0) phi += 2 * std::numbers::pi;
      if (phi > double(phi_max)) continue;
    }
    t_hit = t;
    return true;
  }
  return false;
}

bool intersect_quadric(const QuadricGeometry& q, const UserRay& ray, double& t_hit) {
  const Matrix4* inv = &q.to_world.inverse_matrix();
  std::optional<Transform> at_time;
  if (q.to_world_end) {
    // A moving shape is intersected under its transform at the ray's time.
    at_time = interpolate_transform(q.to_world, *q.to_world_end, ray.time);
    if (!at_time) return false;
    inv = &at_time->inverse_matrix();
  }
  Vec3d o = apply(*inv, ray.o, 1);
  Vec3d d = apply(*inv, ray.d, 0);
  return intersect_unit_quadric_d(q.kind, o, d, ray.t_near, ray.t_far, t_hit, q.phi_max);
}

bool intersect_plane(const PlaneGeometry& pl, float extent, const UserRay& ray, double& t_hit) {
  const Vec3d &o = ray.o, &d = ray.d;
  const double t_near = ray.t_near, t_far = ray.t_far;
  Vec3d n{pl.normal.x, pl.normal.y, pl.normal.z};
  double denom = dot(d, n);
  if (denom == 0) return false;
  Vec3d po{pl.point.x - o.x, pl.point.y - o.y, pl.point.z - o.z};
  double t = dot(po, n) / denom;
  if (!(t > t_near && t < t_far)) return false;
  // Stay inside the finite bounds given to Embree.
  double px = o.x + t * d.x - pl.point.x, py = o.y + t * d.y - pl.point.y, pz = o.z + t * d.z - pl.point.z;
  if (std::abs(px) > extent || std::abs(py) > extent || std::abs(pz) > extent) return false;
  t_hit = t;
  return true;
}

// The first crossing of the surface of an SDF grid's voxel, found in the grid's index space (where
// t is unchanged: the direction is transformed, not normalised).
bool intersect_sdf_voxel(const SdfGridGeometry& sdf, const Matrix4& static_world_to_index, uint32_t voxel,
                         const UserRay& ray, double& t_hit) {
  const Matrix4* to_index = &static_world_to_index;
  std::optional<Transform> at_time;
  if (sdf.to_world_end) {
    at_time = sdf.index_to_world(ray.time);
    if (!at_time) return false;
    to_index = &at_time->inverse_matrix();
  }
  std::optional<double> t =
      sdf.grid->intersect_voxel(voxel, apply(*to_index, ray.o, 1), apply(*to_index, ray.d, 0), ray.t_near, ray.t_far);
  if (!t) return false;
  t_hit = *t;
  return true;
}

template <typename Args>
UserRay read_ray(const Args* args, unsigned i) {
  RTCRayN* ray = nullptr;
  if constexpr (std::is_same_v<Args, RTCIntersectFunctionNArguments>)
    ray = RTCRayHitN_RayN(args->rayhit, args->N);
  else
    ray = args->ray;
  unsigned N = args->N;
  return {{RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i)},
          {RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i)},
          RTCRayN_tnear(ray, N, i),
          RTCRayN_tfar(ray, N, i),
          RTCRayN_time(ray, N, i)};
}

void write_hit(const RTCIntersectFunctionNArguments* args, unsigned i, double t) {
  unsigned N = args->N;
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, N);
  RTCRayN_tfar(ray, N, i) = float(t);
  RTCHitN_u(hit, N, i) = 0;
  RTCHitN_v(hit, N, i) = 0;
  RTCHitN_Ng_x(hit, N, i) = 0;
  RTCHitN_Ng_y(hit, N, i) = 0;
  RTCHitN_Ng_z(hit, N, i) = 1;
  RTCHitN_primID(hit, N, i) = args->primID;
  RTCHitN_geomID(hit, N, i) = args->geomID;
  RTCHitN_instID(hit, N, i, 0) = args->context->instID[0];
}

template <typename Shape, typename IntersectFn>
void user_intersect(const RTCIntersectFunctionNArguments* args, const Shape& shape, IntersectFn fn) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    double t;
    if (fn(shape, read_ray(args, i), t)) write_hit(args, i, t);
  }
}

template <typename Shape, typename IntersectFn>
void user_occluded(const RTCOccludedFunctionNArguments* args, const Shape& shape, IntersectFn fn) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    double t;
    if (fn(shape, read_ray(args, i), t)) RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}

// Embree's callbacks for a user geometry whose data is a Record and whose rays `hit` tests.
template <typename Record, bool (*hit)(const Record&, const UserRay&, double&)>
void intersect_callback(const RTCIntersectFunctionNArguments* args) {
  user_intersect(args, *static_cast<const Record*>(args->geometryUserPtr), hit);
}
template <typename Record, bool (*hit)(const Record&, const UserRay&, double&)>
void occluded_callback(const RTCOccludedFunctionNArguments* args) {
  user_occluded(args, *static_cast<const Record*>(args->geometryUserPtr), hit);
}

}  // namespace

Bounds3 sphere_world_bounds(const SphereGeometry& s, const Transform& to_world) {
  Bounds3 b;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner(i & 1 ? s.radius : -s.radius, i & 2 ? s.radius : -s.radius, i & 4 ? s.radius : -s.radius);
    b.extend(to_world.point(s.center + corner));
  }
  return b;
}

Bounds3 quadric_world_bounds(const QuadricGeometry& q, const Transform& to_world) {
  Bounds3 b;
  const bool disk = q.kind == QuadricGeometry::Kind::Disk;
  for (int i = 0; i < 8; ++i) {
    Point3 corner(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, disk ? 0.0f : (i & 4 ? 1.0f : 0.0f));
    b.extend(to_world.point(corner));
  }
  return b;
}

Bounds3 sdf_voxel_world_bounds(const SdfGrid& grid, uint32_t voxel, const Transform& to_world) {
  // The voxel's cube grown by a thousandth of a voxel, so that no rounding in Embree's box tests
  // loses a hit on a face; intersect_voxel clips to the exact cube itself.
  const Transform index_to_world = to_world * grid.index_to_object();
  const std::array<int, 3> corner = grid.voxel_corner(voxel);
  Bounds3 b;
  for (int i = 0; i < 8; ++i) {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = float(corner[size_t(a)]) + ((i >> a & 1) ? 1.001f : -0.001f);
    b.extend(index_to_world.point(p));
  }
  return b;
}

std::optional<Transform> SdfGridGeometry::to_world_at(float time) const {
  return to_world_end ? interpolate_transform(to_world, *to_world_end, time) : to_world;
}

std::optional<Transform> SdfGridGeometry::index_to_world(float time) const {
  std::optional<Transform> object_to_world = to_world_at(time);
  if (!object_to_world) return std::nullopt;
  return *object_to_world * grid->index_to_object();
}

bool intersect_unit_quadric(QuadricGeometry::Kind kind, const Point3& o, const Vec3& d, double t_near, double t_far,
                            double& t_hit, float phi_max) {
  return intersect_unit_quadric_d(kind, {o.x, o.y, o.z}, {d.x, d.y, d.z}, t_near, t_far, t_hit, phi_max);
}

EmbreeScene::EmbreeScene(float transform_start_time, float transform_end_time, bool compact)
    : time_start_(transform_start_time),
      // A zero-length interval leaves every shape at its start transform.
      time_scale_(transform_end_time > transform_start_time ? 1 / (transform_end_time - transform_start_time) : 0),
      compact_(compact) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw InternalError("cannot create an Embree device");
  rtcSetDeviceErrorFunction(device_, report_embree_error, nullptr);
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  if (compact_) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_COMPACT);
}

EmbreeScene::~EmbreeScene() {
  for (RTCScene object : objects_) rtcReleaseScene(object);
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

namespace {

// Embree reads vertices with 16-byte SSE loads: a shared buffer needs one float of padding at the end,
// so each time step gets its own copy with the padding rather than aliasing the std::vector.
void set_vertex_buffer(RTCGeometry geom, unsigned slot, const std::vector<Point3>& positions) {
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, slot,
                                                               RTC_FORMAT_FLOAT3, sizeof(Point3), positions.size()));
  std::copy_n(&positions[0].x, positions.size() * 3, vertices);
}

}  // namespace

void EmbreeScene::attach(RTCGeometry geom, uint32_t id, int object) {
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(object < 0 ? scene_ : objects_.at(size_t(object)), geom, id);
  rtcReleaseGeometry(geom);
}

RTCGeometry EmbreeScene::new_triangle_geometry(uint32_t id, const std::vector<Point3>& positions,
                                               const std::vector<uint32_t>& indices, bool shared) {
  if (compact_) {
    // The compact layout indexes vertices from its leaves, triangles or quads alike: pairs would
    // only add their own index buffer.
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (shared) {
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices.data(), 0,
                                 3 * sizeof(uint32_t), indices.size() / 3);
    } else {
      auto* tris = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                  3 * sizeof(uint32_t), indices.size() / 3));
      std::copy(indices.begin(), indices.end(), tris);
    }
    return geom;
  }
  if (triangle_pairs_.size() <= id) triangle_pairs_.resize(size_t(id) + 1);
  triangle_pairs_[id] = std::make_unique<TrianglePairs>(pair_triangles(indices, positions));
  const std::vector<uint32_t>& quads = triangle_pairs_[id]->quads;
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_QUAD);
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, quads.data(), 0, 4 * sizeof(uint32_t),
                             quads.size() / 4);
  return geom;
}

void EmbreeScene::add_shared_triangles(uint32_t id, const std::vector<Point3>& positions,
                                       const std::vector<uint32_t>& indices, int object) {
  if (positions.capacity() <= positions.size())
    throw InternalError("EmbreeScene::add_shared_triangles: the positions need one spare element of capacity");
  RTCGeometry geom = new_triangle_geometry(id, positions, indices, /*shared=*/true);
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, positions.data(), 0, sizeof(Point3),
                             positions.size());
  attach(geom, id, object);
}

int EmbreeScene::add_object() {
  RTCScene object = rtcNewScene(device_);
  rtcSetSceneBuildQuality(object, RTC_BUILD_QUALITY_HIGH);
  if (compact_) rtcSetSceneFlags(object, RTC_SCENE_FLAG_COMPACT);
  objects_.push_back(object);
  return int(objects_.size() - 1);
}

void EmbreeScene::add_instance(uint32_t id, int object, const Transform& to_world, const Transform* to_world_end) {
  if (!instance_ids_.empty() && id <= instance_ids_.back())
    throw InternalError("EmbreeScene::add_instance: instance ids must increase");
  RTCScene child = objects_.at(size_t(object));
  rtcCommitScene(child);  // idempotent: each object is built once, however many instances it has
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(geom, child);
  rtcSetGeometryTimeStepCount(geom, to_world_end ? 2 : 1);
  for (unsigned step = 0; step < (to_world_end ? 2u : 1u); ++step) {
    // Embree wants the 3x4 affine part, row-major here ("FLOAT3X4_ROW_MAJOR").
    const Matrix4& m = (step == 0 ? to_world : *to_world_end).matrix();
    float xfm[12];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) xfm[r * 4 + c] = float(m.m[r][c]);
    rtcSetGeometryTransform(geom, step, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
  }
  instance_ids_.push_back(id);
  attach(geom, id);
}

void EmbreeScene::add_moving_triangles(uint32_t id, const std::vector<Point3>& positions,
                                       const std::vector<Point3>& positions_end, const std::vector<uint32_t>& indices) {
  RTCGeometry geom = new_triangle_geometry(id, positions, indices, /*shared=*/false);
  rtcSetGeometryTimeStepCount(geom, 2);
  set_vertex_buffer(geom, 0, positions);
  set_vertex_buffer(geom, 1, positions_end);
  attach(geom, id);
}

void EmbreeScene::attach_user_geometry(uint32_t id, void* data, unsigned primitives, bool moving,
                                       RTCBoundsFunction bounds, RTCIntersectFunctionN intersect,
                                       RTCOccludedFunctionN occluded, int object) {
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, primitives);
  rtcSetGeometryUserData(geom, data);
  rtcSetGeometryBoundsFunction(geom, bounds, nullptr);
  // Moving: Embree interpolates the two time steps' boxes linearly; they contain the shape at every
  // time in between because each point of it moves linearly.
  if (moving) rtcSetGeometryTimeStepCount(geom, 2);
  rtcSetGeometryIntersectFunction(geom, intersect);
  rtcSetGeometryOccludedFunction(geom, occluded);
  attach(geom, id, object);
}

void EmbreeScene::add_sphere(uint32_t id, const SphereGeometry& sphere, int object) {
  spheres_.push_back(std::make_unique<SphereGeometry>(sphere));
  const bool moving = sphere.to_world_end.has_value();
  attach_user_geometry(id, spheres_.back().get(), 1, moving, sphere_bounds,
                       moving ? intersect_callback<SphereGeometry, intersect_moving_sphere>
                              : intersect_callback<SphereGeometry, intersect_sphere>,
                       moving ? occluded_callback<SphereGeometry, intersect_moving_sphere>
                              : occluded_callback<SphereGeometry, intersect_sphere>,
                       object);
}

void EmbreeScene::add_quadric(uint32_t id, const QuadricGeometry& q, int object) {
  quadrics_.push_back(std::make_unique<QuadricGeometry>(q));
  attach_user_geometry(id, quadrics_.back().get(), 1, q.to_world_end.has_value(), quadric_bounds,
                       intersect_callback<QuadricGeometry, intersect_quadric>,
                       occluded_callback<QuadricGeometry, intersect_quadric>, object);
}

void EmbreeScene::add_sdf_grid(uint32_t id, const SdfGridGeometry& sdf, int object) {
  sdf_grids_.push_back(std::make_unique<SdfGridRecord>(
      SdfGridRecord{sdf, (sdf.to_world * sdf.grid->index_to_object()).inverse_matrix()}));
  attach_user_geometry(id, sdf_grids_.back().get(), sdf.grid->voxel_count(), sdf.to_world_end.has_value(), sdf_bounds,
                       sdf_intersect, sdf_occluded, object);
}

namespace {

// Round curves are seen from outside only: a hit whose outward normal faces along the ray is the
// inside of a tube, left by a ray that starts on (or in) it.
void cull_tube_insides(const RTCFilterFunctionNArguments* args) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const float facing = RTCRayN_dir_x(args->ray, args->N, i) * RTCHitN_Ng_x(args->hit, args->N, i) +
                         RTCRayN_dir_y(args->ray, args->N, i) * RTCHitN_Ng_y(args->hit, args->N, i) +
                         RTCRayN_dir_z(args->ray, args->N, i) * RTCHitN_Ng_z(args->hit, args->N, i);
    if (facing > 0) args->valid[i] = 0;
  }
}

}  // namespace

void EmbreeScene::add_curves(uint32_t id, const CurveGeometry& c, int object) {
  static constexpr RTCGeometryType kTypes[] = {RTC_GEOMETRY_TYPE_FLAT_BEZIER_CURVE, RTC_GEOMETRY_TYPE_ROUND_BEZIER_CURVE,
                                               RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BEZIER_CURVE};
  RTCGeometry geom = rtcNewGeometry(device_, kTypes[int(c.kind)]);
  const size_t segments = c.segment_count();
  auto* first = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t), segments));
  for (size_t s = 0; s < segments; ++s) first[s] = uint32_t(4 * s);
  auto set_normals = [&](unsigned slot, const std::vector<Normal3>& normals) {
    // Copied: Embree may read 16 bytes from the last 12-byte normal.
    auto* out = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, slot, RTC_FORMAT_FLOAT3,
                                                            sizeof(Normal3), normals.size()));
    std::copy_n(&normals[0].x, 3 * normals.size(), out);
  };
  if (c.moving()) {
    rtcSetGeometryTimeStepCount(geom, 2);
    for (unsigned slot = 0; slot < 2; ++slot) {
      const std::vector<float>& control = slot == 0 ? c.control : c.control_end;
      auto* out = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, slot, RTC_FORMAT_FLOAT4,
                                                              4 * sizeof(float), control.size() / 4));
      std::copy(control.begin(), control.end(), out);
      if (c.kind == CurveGeometry::Kind::Ribbon) set_normals(slot, slot == 0 ? c.normals : c.normals_end);
    }
  } else {
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, c.control.data(), 0,
                               4 * sizeof(float), c.control.size() / 4);
    if (c.kind == CurveGeometry::Kind::Ribbon) set_normals(0, c.normals);
  }
  rtcSetGeometryTessellationRate(geom, float(c.tessellation));
  if (c.kind == CurveGeometry::Kind::Round) {
    rtcSetGeometryIntersectFilterFunction(geom, cull_tube_insides);
    rtcSetGeometryOccludedFilterFunction(geom, cull_tube_insides);
  }
  attach(geom, id, object);
}

void EmbreeScene::add_plane(uint32_t id, const PlaneGeometry& plane, float extent) {
  planes_.push_back(std::make_unique<PlaneRecord>(PlaneRecord{plane, extent}));
  attach_user_geometry(id, planes_.back().get(), 1, false, plane_bounds, plane_intersect, plane_occluded);
}

void EmbreeScene::commit() { rtcCommitScene(scene_); }

RTCRay EmbreeScene::embree_ray(const Ray& r) const {
  RTCRay ray;
  ray.org_x = r.origin.x;
  ray.org_y = r.origin.y;
  ray.org_z = r.origin.z;
  ray.tnear = r.t_min;
  ray.dir_x = r.direction.x;
  ray.dir_y = r.direction.y;
  ray.dir_z = r.direction.z;
  ray.time = normalized_time(r.time);
  ray.tfar = r.t_max;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

float EmbreeScene::normalized_time(float time) const {
  return std::clamp((time - time_start_) * time_scale_, 0.0f, 1.0f);
}

bool EmbreeScene::intersect(const Ray& r, EmbreeHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rayhit;
  rayhit.ray = embree_ray(r);
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  if (ray_log_) [[unlikely]] ray_log_->add(rayhit.ray, false);
  rtcIntersect1(scene_, &context, &rayhit);
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit = {rayhit.ray.tfar, rayhit.hit.geomID, rayhit.hit.primID, rayhit.hit.u, rayhit.hit.v, -1,
         Vec3(rayhit.hit.Ng_x, rayhit.hit.Ng_y, rayhit.hit.Ng_z)};
  if (hit.geometry < triangle_pairs_.size() && triangle_pairs_[hit.geometry]) {
    // A quad of paired triangles: report the triangle and its own barycentrics.
    TriangleHit th = quad_hit_to_triangle(triangle_pairs_[hit.geometry]->halves[hit.primitive], hit.u, hit.v);
    hit.primitive = th.triangle;
    hit.u = th.b1;
    hit.v = th.b2;
  }
  if (rayhit.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
    // Instance ids are handed out in increasing order, so the index is a binary search away.
    auto it = std::lower_bound(instance_ids_.begin(), instance_ids_.end(), rayhit.hit.instID[0]);
    hit.instance = int(it - instance_ids_.begin());
  }
  return true;
}

bool EmbreeScene::occluded(const Ray& r) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = embree_ray(r);
  if (ray_log_) [[unlikely]] ray_log_->add(ray, true);
  rtcOccluded1(scene_, &context, &ray);
  return ray.tfar < 0;
}

namespace {

// A user geometry's box for Embree, padded by a relative epsilon: the box is in float and the
// intersection in double.
void write_padded_bounds(const Bounds3& b, RTCBounds& out) {
  Vec3 pad = Vec3(1e-5f) * (1.0f + max_component(max(b.hi, -b.lo)));
  out.lower_x = b.lo.x - pad.x;
  out.lower_y = b.lo.y - pad.y;
  out.lower_z = b.lo.z - pad.z;
  out.upper_x = b.hi.x + pad.x;
  out.upper_y = b.hi.y + pad.y;
  out.upper_z = b.hi.z + pad.z;
}

}  // namespace

void EmbreeScene::sphere_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& s = *static_cast<const SphereGeometry*>(args->geometryUserPtr);
  Bounds3 b = sphere_world_bounds(s, args->timeStep == 0 ? s.to_world : *s.to_world_end);
  write_padded_bounds(b, *args->bounds_o);
}

void EmbreeScene::quadric_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& q = *static_cast<const QuadricGeometry*>(args->geometryUserPtr);
  Bounds3 b = quadric_world_bounds(q, args->timeStep == 0 ? q.to_world : *q.to_world_end);
  write_padded_bounds(b, *args->bounds_o);
}

void EmbreeScene::sdf_bounds(const RTCBoundsFunctionArguments* args) {
  const SdfGridGeometry& sdf = static_cast<const SdfGridRecord*>(args->geometryUserPtr)->sdf;
  Bounds3 b = sdf_voxel_world_bounds(*sdf.grid, args->primID, args->timeStep == 0 ? sdf.to_world : *sdf.to_world_end);
  write_padded_bounds(b, *args->bounds_o);
}

void EmbreeScene::sdf_intersect(const RTCIntersectFunctionNArguments* args) {
  user_intersect(args, *static_cast<const SdfGridRecord*>(args->geometryUserPtr),
                 [voxel = args->primID](const SdfGridRecord& r, const UserRay& ray, double& t) {
                   return intersect_sdf_voxel(r.sdf, r.world_to_index, voxel, ray, t);
                 });
}

void EmbreeScene::sdf_occluded(const RTCOccludedFunctionNArguments* args) {
  user_occluded(args, *static_cast<const SdfGridRecord*>(args->geometryUserPtr),
                [voxel = args->primID](const SdfGridRecord& r, const UserRay& ray, double& t) {
                  return intersect_sdf_voxel(r.sdf, r.world_to_index, voxel, ray, t);
                });
}

void EmbreeScene::plane_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& r = *static_cast<const PlaneRecord*>(args->geometryUserPtr);
  const Point3& p = r.plane.point;
  args->bounds_o->lower_x = p.x - r.extent;
  args->bounds_o->lower_y = p.y - r.extent;
  args->bounds_o->lower_z = p.z - r.extent;
  args->bounds_o->upper_x = p.x + r.extent;
  args->bounds_o->upper_y = p.y + r.extent;
  args->bounds_o->upper_z = p.z + r.extent;
}

void EmbreeScene::plane_intersect(const RTCIntersectFunctionNArguments* args) {
  const auto& r = *static_cast<const PlaneRecord*>(args->geometryUserPtr);
  user_intersect(args, r, [](const PlaneRecord& rec, const UserRay& ray, double& t) {
    return intersect_plane(rec.plane, rec.extent, ray, t);
  });
}

void EmbreeScene::plane_occluded(const RTCOccludedFunctionNArguments* args) {
  const auto& r = *static_cast<const PlaneRecord*>(args->geometryUserPtr);
  user_occluded(args, r, [](const PlaneRecord& rec, const UserRay& ray, double& t) {
    return intersect_plane(rec.plane, rec.extent, ray, t);
  });
}

}  // namespace candela
