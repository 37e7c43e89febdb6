#pragma once
// The render scene: built once from a SceneDesc, immutable while rendering. Owns the Embree
// acceleration structure, the world-space shape data needed for shading, the materials, the lights
// with their power distribution, and the camera.
#include <memory>
#include <vector>

#include "candela/camera/camera.h"
#include "candela/geometry/embree_scene.h"
#include "candela/geometry/surface_hit.h"
#include "candela/lights/light.h"
#include "candela/lights/light_sampler.h"
#include "candela/materials/material.h"
#include "candela/media/medium.h"
#include "candela/description/scene_desc.h"
#include "candela/film/sensor.h"
#include "candela/textures/texture.h"

namespace candela {

struct ShapeRecord {
  enum class Kind : uint8_t { Triangles, Sphere, Plane, Disk, Cylinder, SdfGrid, Curve };
  Kind kind = Kind::Triangles;
  uint32_t material = 0;
  int first_light = -1;  // index of the light of primitive 0 when emissive
  bool light_per_triangle = true;  // meshes: one light per triangle; rectangles: one light
  RGB radiance;          // emitted radiance when emissive
  bool two_sided_emission = false;
  int emission_texture = -1;  // textured emitters: index into the scene's textures
  // The media on the side opposite the oriented normal and on its side (SceneDesc::media; -1 = vacuum).
  int interior_medium = -1, exterior_medium = -1;
  bool flip_normal = false;  // spheres, planes, disks, cylinders, SDF grids and curves: reverse orientation
  bool winding_swapped = false;  // triangles: indices 1 and 2 swapped to orient the normal
  // Triangles, in world space, winding baked so cross(p1-p0, p2-p0) is the oriented normal.
  std::vector<Point3> positions;
  std::vector<Normal3> normals;
  // Moving triangles: the same at the end of the motion (empty when static); positions and
  // unit normals are interpolated linearly in between.
  std::vector<Point3> positions_end;
  std::vector<Normal3> normals_end;
  std::vector<Vec2> uvs;
  std::vector<uint32_t> indices;
  SphereGeometry sphere;
  PlaneGeometry plane;
  QuadricGeometry quadric;  // disks and cylinders
  SdfGridGeometry sdf;
  SdfNormals sdf_normals = SdfNormals::Smooth;
  // Curves: their segments, which Embree reads in place (held here so that they never move).
  std::shared_ptr<const CurveGeometry> curve;
  // Triangles: the mesh's named attributes (mesh_attribute textures), shared; null when none.
  std::shared_ptr<const std::vector<TriangleMesh::Attribute>> attributes;
  std::string name;
  bool is_emissive() const { return first_light >= 0; }
  bool is_moving() const {
    return !positions_end.empty() || sphere.to_world_end.has_value() || quadric.to_world_end.has_value() ||
           sdf.to_world_end.has_value() || (curve && curve->moving());
  }
};

class Scene {
 public:
  // Throws SceneError for descriptions that cannot be rendered (e.g. an emissive infinite plane).
  explicit Scene(const SceneDesc& desc);
  // The same, with MeshData::Take moving each mesh's arrays out of `desc` as it is added (the
  // shapes keep everything else): each triangle is then held once, not twice, while the scene is
  // built, which is what bounds the peak memory of large scenes.
  enum class MeshData { Copy, Take };
  Scene(SceneDesc& desc, MeshData mesh_data);
  // Not copied: the light sampler points into lights_ (moving keeps that array where it is).
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  Scene(Scene&&) = default;
  Scene& operator=(Scene&&) = default;

  bool intersect(const Ray& ray, SurfaceHit& hit) const;
  bool occluded(const Ray& ray) const { return embree_.occluded(ray); }

  const ShapeRecord& shape(const SurfaceHit& hit) const { return shapes_[hit.shape]; }
  // The BSDF at the hit, its textured inputs evaluated there.
  SurfaceBsdf bsdf(const SurfaceHit& hit) const {
    return materials_.bsdf(shapes_[hit.shape].material, texture_context(hit));
  }
  // The BSDF at the hit with the shading frame it works in (the hit's, tilted by normal and bump
  // maps), for light leaving towards wo (which side of a two-sided material is seen).
  Shading shading(const SurfaceHit& hit, const Vec3& wo) const {
    return materials_.shading(shapes_[hit.shape].material, texture_context(hit), hit, wo);
  }
  // Where textures are looked up at the hit: its point, uv and (on meshes) the triangle for
  // mesh-attribute textures.
  TextureEvalContext texture_context(const SurfaceHit& hit) const;
  // Whether the surface hit is an interface without a surface of its own (rays pass through).
  bool is_interface(const SurfaceHit& hit) const { return materials_.is_interface(shapes_[hit.shape].material); }
  // Whether light may pass the hit's surface straight on (interfaces, masks, thin sheets).
  bool may_pass_through(const SurfaceHit& hit) const { return materials_.may_pass_through(shapes_[hit.shape].material); }

  // Participating media (SceneDesc::media), indexed as there.
  const std::vector<Medium>& media() const { return media_; }
  bool has_media() const { return !media_.empty(); }
  // The medium camera rays start in (-1 = vacuum).
  int camera_medium() const { return camera_medium_; }
  // The medium a ray that leaves the hit along `dir` travels in, given the one it arrived in
  // (`current`): the shape's interior or exterior by the side `dir` goes to where the two differ.
  int medium_after(const SurfaceHit& hit, const Vec3& dir, int current) const {
    const ShapeRecord& rec = shapes_[hit.shape];
    if (rec.interior_medium == rec.exterior_medium) return current;
    return dot(dir, hit.ng) > 0 ? rec.exterior_medium : rec.interior_medium;
  }

  // The medium at point p: the side facing p of the first medium boundary a ray from p meets, or
  // the ambient medium where none is met (for lights, which carry no medium of their own).
  int medium_at(const Point3& p, float time) const;
  // The medium of everything outside every medium boundary: the camera's when the camera sits in
  // a medium that no boundary encloses (fog everywhere), else -1 (vacuum).
  int ambient_medium() const { return ambient_medium_; }

  // Radiance emitted from the hit point towards wo (zero for non-emitters and their back faces).
  RGB emitted(const SurfaceHit& hit, const Vec3& wo) const;
  // The light of an emissive hit, or -1.
  int light_index(const SurfaceHit& hit) const;

  const std::vector<Light>& lights() const { return lights_; }
  // Which light a vertex sends its shadow ray to, and which light a light path starts from.
  const LightSampler& light_sampler() const { return light_sampler_; }
  // The lights at infinity (sky, environment maps) that rays escaping the scene see: indices into lights().
  const std::vector<uint32_t>& infinite_lights() const { return infinite_lights_; }
  // Radiance an escaping ray travelling along `dir` receives from infinite light `light`.
  RGB escaped_radiance(uint32_t light, const Vec3& dir) const {
    return light_escaped_radiance(lights_[light], dir);
  }
  const PerspectiveCamera& camera() const { return camera_; }
  // What the film's sensor makes of each sample's radiance (FilmDesc::Sensor).
  const FilmSensor& film_sensor() const { return film_sensor_; }
  const Bounds3& bounds() const { return bounds_; }
  // The sphere around bounds(): light paths from lights at infinity start on a disk of its radius.
  const SceneSphere& bounding_sphere() const { return bounding_sphere_; }
  // Whether any surface is an interface (rays pass through it): visibility must then look past them.
  bool has_interfaces() const { return has_interfaces_; }
  // Whether anything moves during the shutter interval (then each path needs its own time).
  bool has_motion() const { return has_motion_; }
  size_t triangle_count() const { return triangle_count_; }
  // The acceleration structure, for benchmarks (ray logs, raw Embree queries).
  EmbreeScene& embree() { return embree_; }
  const EmbreeScene& embree() const { return embree_; }

 private:
  // `object`: the Embree object the shape goes into (-1 = the world); object shapes keep their
  // object-space coordinates and are placed by instances.
  // `take_mesh`: the shape's own mesh, to move from (null: copy it).
  void build(const SceneDesc& desc, SceneDesc* take_meshes);
  void add_shape(const ShapeDesc& desc, size_t index, int object, TriangleMesh* take_mesh);
  void add_objects_and_instances(const SceneDesc& desc, SceneDesc* take_meshes);
  // rectangle: one RectangleLight instead of a light per triangle; deforming: a mesh whose vertices
  // move to MeshShape::positions_end (and normals_end) by the end of the motion.
  void add_triangles(ShapeRecord rec, TriangleMesh mesh, const Transform& to_world,
                     const Transform* to_world_end, bool reverse, const std::optional<AreaEmission>& emission,
                     bool rectangle, int object, const MeshShape* deforming = nullptr);
  void add_sphere(ShapeRecord rec, const SphereShape& sphere, const Transform& to_world,
                  const Transform* to_world_end, bool reverse, const std::optional<AreaEmission>& emission,
                  int object);
  // A disk, or a cylinder (cut to the azimuths up to phi_max radians when below 2 pi).
  void add_quadric(ShapeRecord rec, QuadricGeometry::Kind kind, const Transform& unit_to_world,
                   const Transform* unit_to_world_end, const std::optional<AreaEmission>& emission, int object,
                   float phi_max = 2 * kPi);
  void add_sdf_grid(ShapeRecord rec, const SdfGridShape& grid, const Transform& to_world,
                    const Transform* to_world_end, int object);
  void add_curve(ShapeRecord rec, const CurveShape& curve, const Transform& to_world, const Transform* to_world_end,
                 int object);
  // A shape or instance at a ray's time: to_world, or where it moves (to_world_end) and the
  // interpolation exists, that interpolated transform, kept in storage.
  const Transform& transform_at(const Transform& to_world, const std::optional<Transform>& to_world_end, float time,
                                std::optional<Transform>& storage) const;
  void reconstruct_quadric_hit(const ShapeRecord& rec, const Ray& ray, float t, SurfaceHit& hit) const;
  void reconstruct_sdf_hit(const ShapeRecord& rec, const Ray& ray, float t, uint32_t voxel, SurfaceHit& hit) const;
  void reconstruct_triangle_hit(const ShapeRecord& rec, const EmbreeHit& eh, float time, SurfaceHit& hit) const;
  void reconstruct_sphere_hit(const ShapeRecord& rec, const Ray& ray, float t, SurfaceHit& hit) const;
  void reconstruct_curve_hit(const ShapeRecord& rec, const Ray& ray, const EmbreeHit& eh, SurfaceHit& hit) const;

  std::string source_file_;  // for messages
  // "file:line:col" of a description entry, or the scene file where its place is unknown.
  std::string place(const SourceLocation& where) const;
  template <typename Make>
  auto with_place(const SourceLocation& where, Make make) const -> decltype(make());
  EmbreeScene embree_;
  FilmSensor film_sensor_;
  std::vector<ShapeRecord> shapes_;  // indexed by Embree geometry id (world and object shapes alike)
  struct InstanceRecord {
    Transform to_world;
    std::optional<Transform> to_world_end;
  };
  std::vector<InstanceRecord> instances_;  // indexed by EmbreeHit::instance
  TextureSet textures_;
  MaterialTable materials_;  // refers to textures_
  std::vector<Light> lights_;
  LightSampler light_sampler_;
  std::vector<uint32_t> infinite_lights_;
  std::vector<Medium> media_;
  int camera_medium_ = -1;
  int ambient_medium_ = -1;
  PerspectiveCamera camera_;
  Bounds3 bounds_;
  SceneSphere bounding_sphere_;
  bool has_interfaces_ = false;
  bool has_motion_ = false;
  size_t triangle_count_ = 0;
};

}  // namespace candela
