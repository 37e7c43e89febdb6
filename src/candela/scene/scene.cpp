#include "candela/scene/scene.h"

#include <algorithm>
#include <cmath>

#include "candela/film/image_io.h"
#include "candela/geometry/curves.h"
#include "candela/geometry/quadric_uv.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/base/error.h"
#include "candela/base/overloaded.h"
#include "candela/math/frame.h"

namespace candela {
namespace {

TriangleMesh box_mesh(const BoxShape& box) {
  TriangleMesh m;
  const Point3 &a = box.lo, &b = box.hi;
  for (int i = 0; i < 8; ++i) m.positions.push_back({i & 1 ? b.x : a.x, i & 2 ? b.y : a.y, i & 4 ? b.z : a.z});
  // Six faces, counter-clockwise seen from outside so normals point out.
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  return m;
}

TriangleMesh rectangle_mesh(const RectangleShape& r) {
  TriangleMesh m;
  m.positions = {r.corner, r.corner + r.edge_u, r.corner + r.edge_u + r.edge_v, r.corner + r.edge_v};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

std::string shape_label(const ShapeDesc& desc, size_t index) {
  return desc.name.empty() ? fmt::format("shape {}", index) : fmt::format("shape {} (\"{}\")", index, desc.name);
}

// The shape's end transform when it really moves; an end transform equal to the start is static.
const Transform* moving_end_transform(const ShapeDesc& desc) {
  return desc.to_world_end && *desc.to_world_end != desc.to_world ? &*desc.to_world_end : nullptr;
}

Vec3 lerp(float t, const Vec3& a, const Vec3& b) { return a * (1 - t) + b * t; }

// A partial sphere's or cylinder's phi_max (degrees, in (0, 360]) in radians: exactly 2 pi for a full turn.
float phi_max_radians(float degrees, const std::string& shape) {
  if (!(degrees > 0 && degrees <= 360))
    throw SceneError(fmt::format("{}: phi_max must be in (0, 360] degrees, got {}", shape, degrees));
  return degrees == 360 ? 2 * kPi : radians(degrees);
}

// Object-space shading normals to world space, in place (flipped by reverse orientation).
void place_normals(std::vector<Normal3>& normals, const Transform& T, bool reverse) {
  for (auto& n : normals) n = normalize(T.normal(n)) * (reverse ? -1.0f : 1.0f);
}

// The mesh of a shape, to take its arrays from, or null (not a mesh, or not to be taken).
TriangleMesh* mesh_to_take(SceneDesc* take_meshes, std::vector<ShapeDesc>& shapes, size_t i) {
  if (!take_meshes) return nullptr;
  auto* mesh = std::get_if<MeshShape>(&shapes[i].geometry);
  return mesh ? &mesh->mesh : nullptr;
}

// The place of entry i of a list the reader may have left shorter (unknown places).
const SourceLocation& place_in(const std::vector<SourceLocation>& places, size_t i) {
  static const SourceLocation unknown;
  return i < places.size() ? places[i] : unknown;
}

}  // namespace

static_assert(std::is_nothrow_move_constructible_v<ShapeRecord>,
              "Embree shares ShapeRecord's vertex and index arrays: moving records must never copy them");

Scene::Scene(const SceneDesc& desc)
    : source_file_(desc.source_file.empty() ? "scene" : desc.source_file),
      embree_(desc.transform_start_time, desc.transform_end_time, desc.settings.bvh == BvhLayout::Compact) {
  build(desc, nullptr);
}

Scene::Scene(SceneDesc& desc, MeshData mesh_data)
    : source_file_(desc.source_file.empty() ? "scene" : desc.source_file),
      embree_(desc.transform_start_time, desc.transform_end_time, desc.settings.bvh == BvhLayout::Compact) {
  build(desc, mesh_data == MeshData::Take ? &desc : nullptr);
}

std::string Scene::place(const SourceLocation& where) const {
  return where.file.empty() ? source_file_ : where.to_string();
}

// Runs make() and puts `where` in front of the message of a SceneError it throws (the lights'
// own checks do not know the file).
template <typename Make>
auto Scene::with_place(const SourceLocation& where, Make make) const -> decltype(make()) {
  try {
    return make();
  } catch (const SceneError& e) {
    throw SceneError(fmt::format("{}: {}", place(where), e.what()));
  }
}

void Scene::build(const SceneDesc& desc, SceneDesc* take_meshes) {
  textures_ = TextureSet(desc.textures, [&](size_t i) { return place(place_in(desc.places.textures, i)); });
  materials_ = MaterialTable(desc.materials, textures_,
                             [&](size_t i) { return place(place_in(desc.places.materials, i)); });
  for (const MediumDesc& m : desc.media) {
    with_place(m.where, [&] {
      if (std::string problem = medium_problem(m); !problem.empty())
        throw SceneError(fmt::format("medium \"{}\": {}", m.name, problem));
      return 0;
    });
    media_.emplace_back(m);
  }
  camera_medium_ = desc.camera.medium;
  if (camera_medium_ < -1 || camera_medium_ >= int(media_.size()))
    throw SceneError(fmt::format("{}: the camera is in medium {}, which does not exist", source_file_, camera_medium_));
  for (size_t i = 0; i < desc.shapes.size(); ++i)
    add_shape(desc.shapes[i], i, -1, take_meshes ? mesh_to_take(take_meshes, take_meshes->shapes, i) : nullptr);
  add_objects_and_instances(desc, take_meshes);

  // Infinite planes get finite bounds far beyond everything else.
  float scene_size = bounds_.empty() ? 1.0f : std::max(1.0f, length(bounds_.diagonal()));
  for (size_t id = 0; id < shapes_.size(); ++id)
    if (shapes_[id].kind == ShapeRecord::Kind::Plane) embree_.add_plane(uint32_t(id), shapes_[id].plane, 1e4f * scene_size);
  embree_.commit();

  float radius = bounds_.empty() ? 1.0f : std::max(1e-3f, length(bounds_.diagonal()) / 2);
  for (size_t i = 0; i < desc.lights.size(); ++i) {
    const LightDesc& l = desc.lights[i];
    Light light = with_place(place_in(desc.places.lights, i), [&] { return std::visit(
        overloaded{
            [&](const PointLight& p) -> Light { return PointLightSource{p.position, p.intensity}; },
            [&](const SkyLight& s) -> Light {
              return SkyLightSource{s.zenith, s.horizon, s.ground, normalize(s.up), radius};
            },
            [&](const SpotLight& spot) -> Light { return make_spot_light(spot, &textures_); },
            [&](const ProjectorLight& projector) -> Light { return make_projector_light(projector, &textures_); },
            [&](const GoniometricLight& goniometric) -> Light { return make_goniometric_light(goniometric); },
            [&](const DistantLight& distant) -> Light { return make_distant_light(distant, radius); },
            [&](const EnvironmentMap& env) -> Light { return make_environment_light(env, radius); }},
        l); });
    if (has(light_flags(light), LightFlags::Infinite)) infinite_lights_.push_back(uint32_t(lights_.size()));
    lights_.push_back(std::move(light));
  }

  // Which light a shadow ray (or a light path) starts from: by power, or (LightSelection::Uniform)
  // every emitter equally, the triangles of an emissive mesh among themselves by power (= by area),
  // or (LightSelection::Bvh, ::Paper) through the light BVH, light paths still by power.
  std::vector<float> power;
  for (const auto& l : lights_) power.push_back(light_power(l));
  if (desc.settings.light_selection == LightSelection::Uniform) {
    std::vector<float> weight(lights_.size(), 1.0f);
    for (const ShapeRecord& rec : shapes_) {
      if (!rec.is_emissive() || !(rec.kind == ShapeRecord::Kind::Triangles && rec.light_per_triangle)) continue;
      size_t first = size_t(rec.first_light), count = rec.indices.size() / 3;
      double group = 0;
      for (size_t i = first; i < first + count; ++i) group += power[i];
      for (size_t i = first; i < first + count; ++i) weight[i] = group > 0 ? float(power[i] / group) : 0.0f;
    }
    power = std::move(weight);
  }
  const LightSelection selection = desc.settings.light_selection;
  light_sampler_ = LightSampler(lights_, power,
                                selection == LightSelection::Bvh     ? LightSampler::Mode::Bvh
                                : selection == LightSelection::Paper ? LightSampler::Mode::Paper
                                                                     : LightSampler::Mode::Weights);

  int w = desc.film.width, h = desc.film.height;
  // Camera rays reach the filter's radius beyond the outermost pixel centres.
  Vec2 r = desc.settings.filter.radius;
  camera_ = PerspectiveCamera(desc.camera, w, h, {std::max(0.0f, r.x - 0.5f), std::max(0.0f, r.y - 0.5f)});
  film_sensor_ = FilmSensor(desc.film.sensor);
  bounding_sphere_ = {bounds_.empty() ? Point3(0.0f) : bounds_.center(), radius};
  for (const auto& rec : shapes_) {
    has_interfaces_ = has_interfaces_ || materials_.is_interface(rec.material);
    has_motion_ = has_motion_ || rec.is_moving();
  }
  for (const auto& inst : instances_) has_motion_ = has_motion_ || inst.to_world_end.has_value();
  // Fog everywhere: a camera medium that no boundary around the camera accounts for.
  if (camera_medium_ >= 0 && medium_at(desc.camera.world_from_camera.point({0, 0, 0}), desc.camera.shutter_open) < 0)
    ambient_medium_ = camera_medium_;
}

int Scene::medium_at(const Point3& p, float time) const {
  if (media_.empty()) return -1;
  // Any direction will do for consistent boundaries; an irrational-looking one avoids grazing
  // axis-aligned geometry.
  const Vec3 dir = normalize(Vec3(0.5412f, 0.6180f, 0.5703f));
  Ray ray{p, dir, std::numeric_limits<float>::infinity(), time};
  for (int crossed = 0; crossed < 256; ++crossed) {
    SurfaceHit hit;
    if (!intersect(ray, hit)) break;
    const ShapeRecord& rec = shapes_[hit.shape];
    // Leaving along the normal means p is inside.
    if (rec.interior_medium != rec.exterior_medium)
      return dot(dir, hit.ng) > 0 ? rec.interior_medium : rec.exterior_medium;
    ray.origin = offset_ray_origin(hit.p, hit.ng, dir);
  }
  return ambient_medium_;
}

void Scene::add_objects_and_instances(const SceneDesc& desc, SceneDesc* take_meshes) {
  // Each object becomes one Embree scene; its shapes' records stay in object space.
  std::vector<int> embree_objects;
  std::vector<Bounds3> object_bounds;
  Bounds3 world_bounds = bounds_;
  for (size_t o = 0; o < desc.objects.size(); ++o) {
    const ObjectDesc& object = desc.objects[o];
    std::string label = object.name.empty() ? fmt::format("object {}", o) : fmt::format("object \"{}\"", object.name);
    bounds_ = Bounds3();
    embree_objects.push_back(embree_.add_object());
    for (size_t i = 0; i < object.shapes.size(); ++i) {
      const ShapeDesc& shape = object.shapes[i];
      std::string what = fmt::format("{}: {}: {}", place(shape.where.file.empty() ? object.where : shape.where), label,
                                     shape_label(shape, i));
      if (shape.emission) throw SceneError(fmt::format("{}: emissive shapes cannot be instanced", what));
      if (moving_end_transform(shape))
        throw SceneError(fmt::format("{}: shapes inside an object cannot move (move the instance instead)", what));
      if (std::holds_alternative<PlaneShape>(shape.geometry))
        throw SceneError(fmt::format("{}: an infinite plane cannot be instanced", what));
      add_shape(shape, i, embree_objects.back(),
                take_meshes ? mesh_to_take(take_meshes, take_meshes->objects[o].shapes, i) : nullptr);
    }
    object_bounds.push_back(bounds_);
  }
  bounds_ = world_bounds;

  // Instances go into the world under ids above every shape's.
  const uint32_t first_id = uint32_t(shapes_.size());
  for (size_t i = 0; i < desc.instances.size(); ++i) {
    const InstanceDesc& inst = desc.instances[i];
    if (inst.object < 0 || size_t(inst.object) >= desc.objects.size())
      throw SceneError(fmt::format("{}: instance {} refers to object {}, which does not exist", place(inst.where), i,
                                   inst.object));
    const Transform* end = inst.to_world_end && *inst.to_world_end != inst.to_world ? &*inst.to_world_end : nullptr;
    if (end && end->swaps_handedness() != inst.to_world.swaps_handedness())
      throw SceneError(fmt::format("{}: instance {}: the end transform mirrors it relative to the start transform",
                                   place(inst.where), i));
    instances_.push_back({inst.to_world, end ? std::optional<Transform>(*end) : std::nullopt});
    embree_.add_instance(first_id + uint32_t(i), embree_objects[size_t(inst.object)], inst.to_world, end);
    const Bounds3& ob = object_bounds[size_t(inst.object)];
    if (ob.empty()) continue;
    for (const Transform* T : {&inst.to_world, end})
      if (T)
        for (int c = 0; c < 8; ++c)
          bounds_.extend(T->point({c & 1 ? ob.hi.x : ob.lo.x, c & 2 ? ob.hi.y : ob.lo.y, c & 4 ? ob.hi.z : ob.lo.z}));
  }
}

void Scene::add_shape(const ShapeDesc& desc, size_t index, int object, TriangleMesh* take_mesh) {
  ShapeRecord rec;
  rec.name = place(desc.where) + ": " + shape_label(desc, index);
  rec.material = desc.material >= 0 && size_t(desc.material) < materials_.size() - 1 ? uint32_t(desc.material)
                                                                                    : materials_.default_material();
  rec.flip_normal = desc.reverse_orientation;
  rec.interior_medium = desc.interior_medium;
  rec.exterior_medium = desc.exterior_medium;
  for (int m : {desc.interior_medium, desc.exterior_medium})
    if (m < -1 || m >= int(media_.size()))
      throw SceneError(fmt::format("{}: refers to medium {}, which does not exist", rec.name, m));
  const Transform& T = desc.to_world;
  const Transform* T_end = moving_end_transform(desc);
  const auto* mesh_shape = std::get_if<MeshShape>(&desc.geometry);
  const MeshShape* deforming = mesh_shape && !mesh_shape->positions_end.empty() ? mesh_shape : nullptr;
  // Lights are sampled at fixed positions, so emitters stay put.
  if ((T_end || deforming) && desc.emission)
    throw SceneError(fmt::format("{}: area lights must not move (an emissive shape has an end transform)",
                                 rec.name));
  if (desc.emission && desc.emission->texture >= 0) {
    if (size_t(desc.emission->texture) >= textures_.size())
      throw SceneError(fmt::format("{}: the emission texture {} does not exist", rec.name,
                                   desc.emission->texture));
  }

  auto triangles = [&](TriangleMesh mesh, bool rectangle) {
    add_triangles(std::move(rec), std::move(mesh), T, T_end, desc.reverse_orientation, desc.emission, rectangle,
                  object, deforming);
  };
  std::visit(
      overloaded{
          [&](const SphereShape& s) {
            add_sphere(std::move(rec), s, T, T_end, desc.reverse_orientation, desc.emission, object);
          },
          [&](const PlaneShape& p) {
            if (desc.emission)
              throw SceneError(fmt::format("{}: an infinite plane cannot emit light (its power would be infinite)",
                                           rec.name));
            if (T_end)
              throw SceneError(fmt::format("{}: an infinite plane must not move (it has an end transform)",
                                           rec.name));
            rec.kind = ShapeRecord::Kind::Plane;
            rec.plane = PlaneGeometry{T.point(p.point), normalize(T.normal(p.normal))};
            // Its Embree geometry is added once the size of everything else is known (see the constructor).
            shapes_.push_back(std::move(rec));
          },
          [&](const DiskShape&) {
            add_quadric(std::move(rec), QuadricGeometry::Kind::Disk, T, T_end, desc.emission, object);
          },
          [&](const CylinderShape& c) {
            // The unit tube placed on the segment p0-p1 with the radius (Mitsuba's to_frame of the axis,
            // so phi = 0 lies along the axis frame's first vector), then to_world.
            Vec3 d = c.p1 - c.p0;
            float len = length(d);
            if (!(len > 0) || !(c.radius > 0) || !std::isfinite(len) || !std::isfinite(c.radius))
              throw SceneError(fmt::format("{}: a cylinder needs a positive radius and two distinct end points",
                                           rec.name));
            const float phi_max = phi_max_radians(c.phi_max, rec.name);
            Frame f(d / len);
            Matrix4 m = Matrix4::identity();
            for (int r = 0; r < 3; ++r) {
              m.m[r][0] = double(f.s[r]) * c.radius;
              m.m[r][1] = double(f.t[r]) * c.radius;
              m.m[r][2] = double(d[r]);
              m.m[r][3] = double(c.p0[r]);
            }
            Transform place = *Transform::from_matrix(m);
            Transform unit = T * place;
            std::optional<Transform> unit_end;
            if (T_end) unit_end = *T_end * place;
            add_quadric(std::move(rec), QuadricGeometry::Kind::Cylinder, unit, unit_end ? &*unit_end : nullptr,
                        desc.emission, object, phi_max);
          },
          [&](const SdfGridShape& g) {
            if (desc.emission)
              throw SceneError(fmt::format(
                  "{}: an SDF grid cannot emit light (as in Mitsuba: it has no area to sample)", rec.name));
            add_sdf_grid(std::move(rec), g, T, T_end, object);
          },
          [&](const CurveShape& c) {
            if (desc.emission)
              throw SceneError(fmt::format("{}: a curve cannot emit light (nor can it in pbrt-v4, which has no way "
                                           "to sample points on a curve)", rec.name));
            if (desc.is_medium_transition())
              throw SceneError(fmt::format("{}: a curve has no inside, so it cannot bound a medium: give it the "
                                           "same medium on both sides", rec.name));
            add_curve(std::move(rec), c, T, T_end, object);
          },
          [&](const BoxShape& b) { triangles(box_mesh(b), false); },
          [&](const RectangleShape& r) { triangles(rectangle_mesh(r), true); },
          [&](const MeshShape& m) {
            if (take_mesh) triangles(std::move(*take_mesh), false);
            else triangles(m.mesh, false);
          }},
      desc.geometry);
}

void Scene::add_sphere(ShapeRecord rec, const SphereShape& s, const Transform& T, const Transform* T_end,
                       bool reverse, const std::optional<AreaEmission>& emission, int object) {
  rec.kind = ShapeRecord::Kind::Sphere;
  rec.sphere = SphereGeometry{T, s.center, s.radius, T_end ? std::optional<Transform>(*T_end) : std::nullopt, s.uv};
  const float phi_max = phi_max_radians(s.phi_max, rec.name);
  if ((s.z_min_given && !std::isfinite(s.z_min)) || (s.z_max_given && !std::isfinite(s.z_max)))
    throw SceneError(fmt::format("{}: the sphere's z_min and z_max must be finite numbers", rec.name));
  if (s.z_min_given && s.z_max_given && !(s.z_min < s.z_max))
    throw SceneError(fmt::format("{}: the sphere's z_max ({}) must exceed its z_min ({})", rec.name, s.z_max, s.z_min));
  if (s.partial()) {
    // pbrt-v4's partial sphere: the heights clamped to the sphere, the polar angles of the two cuts.
    SphereGeometry& g = rec.sphere;
    g.partial = true;
    g.z_min = s.z_lo();
    g.z_max = s.z_hi();
    if (!(g.z_min < g.z_max))
      throw SceneError(fmt::format("{}: the sphere's heights z_min {} to z_max {} leave nothing of it (radius {})",
                                   rec.name, s.z_min_given ? s.z_min : -s.radius, s.z_max_given ? s.z_max : s.radius,
                                   s.radius));
    g.phi_max = phi_max;
    g.theta_z_min = std::acos(std::clamp(g.z_min / s.radius, -1.0f, 1.0f));
    g.theta_z_max = std::acos(std::clamp(g.z_max / s.radius, -1.0f, 1.0f));
  }
  for (const Transform* X : {&T, T_end})
    if (X) bounds_.extend(sphere_world_bounds(rec.sphere, *X));
  if (emission) {
    // Sampling by solid angle needs a true sphere in world space: allow only similarity transforms.
    Vec3 ex = T.vector({1, 0, 0}), ey = T.vector({0, 1, 0}), ez = T.vector({0, 0, 1});
    float lx = length(ex), ly = length(ey), lz = length(ez);
    if (std::abs(lx - ly) > 1e-4f * lx || std::abs(lx - lz) > 1e-4f * lx || std::abs(dot(ex, ey)) > 1e-4f * lx * ly ||
        std::abs(dot(ex, ez)) > 1e-4f * lx * lz || std::abs(dot(ey, ez)) > 1e-4f * ly * lz)
      throw SceneError(fmt::format("{}: an emissive sphere must not be scaled non-uniformly or sheared",
                                   rec.name));
    rec.first_light = int(lights_.size());
    rec.radiance = emission->radiance;
    rec.two_sided_emission = emission->two_sided;
    rec.emission_texture = emission->texture;
    if (rec.sphere.partial) {
      // Sampled uniformly by area over the part kept (uniform in height and azimuth).
      const SphereGeometry& g = rec.sphere;
      const float radius = s.radius * lx, z_min = g.z_min * lx, z_max = g.z_max * lx;
      PartialSphereLight light{T.point(s.center), ex / lx, ey / ly, ez / lz, radius, z_min, z_max, g.phi_max,
                               g.phi_max * radius * (z_max - z_min), rec.radiance, rec.two_sided_emission, reverse};
      light.emission_texture = {&textures_, rec.emission_texture};
      light.pbrt_uv = s.uv == SphereUv::Pbrt;
      light.theta_z_min = g.theta_z_min;
      light.theta_z_max = g.theta_z_max;
      lights_.push_back(light);
    } else {
      SphereLight light{T.point(s.center), s.radius * lx, rec.radiance, rec.two_sided_emission, reverse};
      light.emission_texture = {&textures_, rec.emission_texture};
      light.object_x = ex / lx;
      light.object_y = ey / ly;
      // pbrt-v4's v = 1 - theta / pi is Mitsuba's v of the point mirrored in z (u unchanged).
      light.object_z = (s.uv == SphereUv::Pbrt ? -ez : ez) / lz;
      lights_.push_back(light);
    }
  }
  embree_.add_sphere(uint32_t(shapes_.size()), rec.sphere, object);
  shapes_.push_back(std::move(rec));
}

void Scene::add_quadric(ShapeRecord rec, QuadricGeometry::Kind kind, const Transform& M, const Transform* M_end,
                        const std::optional<AreaEmission>& emission, int object, float phi_max) {
  const bool disk = kind == QuadricGeometry::Kind::Disk;
  rec.kind = disk ? ShapeRecord::Kind::Disk : ShapeRecord::Kind::Cylinder;
  if (!Transform::from_matrix(M.matrix()) || (M_end && !Transform::from_matrix(M_end->matrix())))
    throw SceneError(fmt::format("{}: the transform is singular", rec.name));
  rec.quadric = QuadricGeometry{kind, M, M_end ? std::optional<Transform>(*M_end) : std::nullopt, phi_max};
  for (const Transform* X : {&M, M_end})
    if (X) bounds_.extend(quadric_world_bounds(rec.quadric, *X));
  if (emission) {
    rec.first_light = int(lights_.size());
    rec.radiance = emission->radiance;
    rec.two_sided_emission = emission->two_sided;
    rec.emission_texture = emission->texture;
    const EmissionTexture texture{&textures_, rec.emission_texture};
    Vec3 eu = M.vector({1, 0, 0}), ev = M.vector({0, 1, 0}), ez = M.vector({0, 0, 1});
    if (disk) {
      Normal3 n = normalize(M.normal({0, 0, 1}));
      if (rec.flip_normal) n = -n;
      lights_.push_back(DiskLight{M.point(Point3(0.0f)), eu, ev, n, kPi * length(cross(eu, ev)), rec.radiance,
                                  rec.two_sided_emission, texture});
    } else {
      // Uniform sampling by area needs a circular, right cylinder in world space.
      float lu = length(eu), lv = length(ev), lz = length(ez);
      if (std::abs(lu - lv) > 1e-4f * lu || std::abs(dot(eu, ev)) > 1e-4f * lu * lv ||
          std::abs(dot(eu, ez)) > 1e-4f * lu * lz || std::abs(dot(ev, ez)) > 1e-4f * lv * lz)
        throw SceneError(fmt::format(
            "{}: an emissive cylinder must stay circular (no non-uniform scale across its axis, no shear)",
            rec.name));
      lights_.push_back(CylinderLight{M.point(Point3(0.0f)), eu / lu, ev / lv, ez, lu, phi_max * lu * lz,
                                      rec.radiance, rec.two_sided_emission, rec.flip_normal, texture, phi_max});
    }
  }
  embree_.add_quadric(uint32_t(shapes_.size()), rec.quadric, object);
  shapes_.push_back(std::move(rec));
}

void Scene::add_sdf_grid(ShapeRecord rec, const SdfGridShape& grid, const Transform& T, const Transform* T_end,
                         int object) {
  if (std::string problem = sdf_grid_problem(grid); !problem.empty())
    throw SceneError(fmt::format("{}: SDF grid: {}", rec.name, problem));
  if (!Transform::from_matrix(T.matrix()) || (T_end && !Transform::from_matrix(T_end->matrix())))
    throw SceneError(fmt::format("{}: the transform is singular", rec.name));
  rec.kind = ShapeRecord::Kind::SdfGrid;
  rec.sdf = SdfGridGeometry{std::make_shared<const SdfGrid>(grid), T, T_end ? std::optional<Transform>(*T_end) : std::nullopt};
  rec.sdf_normals = grid.normals;
  // The whole grid's box: the surface is somewhere inside [0,1]^3.
  for (const Transform* X : {&T, T_end})
    if (X)
      for (int c = 0; c < 8; ++c) bounds_.extend(X->point({float(c & 1), float(c >> 1 & 1), float(c >> 2)}));
  embree_.add_sdf_grid(uint32_t(shapes_.size()), rec.sdf, object);
  shapes_.push_back(std::move(rec));
}

void Scene::add_curve(ShapeRecord rec, const CurveShape& shape, const Transform& T, const Transform* T_end,
                      int object) {
  if (std::string problem = curve_problem(shape); !problem.empty())
    throw SceneError(fmt::format("{}: curve: {}", rec.name, problem));
  rec.kind = ShapeRecord::Kind::Curve;
  const BezierSegments segments = curve_bezier_segments(shape);
  auto curve = std::make_shared<CurveGeometry>();
  curve->kind = shape.type == CurveType::Flat       ? CurveGeometry::Kind::Flat
                : shape.type == CurveType::Cylinder ? CurveGeometry::Kind::Round
                                                    : CurveGeometry::Kind::Ribbon;
  curve->tessellation = flat_curve_tessellation(segments.control, segments.width);
  // The control points placed by X, each with its radius: half the width, linear along the segment
  // (the Bézier interpolation of radii spaced evenly is linear in u), scaled as object-space lengths
  // are on average (|det|^(1/3); exact for rotations and uniform scales).
  auto place = [&](const Transform& X, std::vector<float>& control, std::vector<Normal3>& normals,
                   std::vector<Normal3>& end_normals) {
    const double det = X.matrix().determinant();
    if (!(std::abs(det) > 0) || !std::isfinite(det))
      throw SceneError(fmt::format("{}: the transform is singular", rec.name));
    const float scale = float(std::cbrt(std::abs(det)));
    control.reserve(16 * segments.segment_count());
    for (size_t s = 0; s < segments.segment_count(); ++s) {
      for (int i = 0; i < 4; ++i) {
        const Point3 p = X.point(segments.control[4 * s + size_t(i)]);
        const float t = float(i) / 3;
        const float radius = 0.5f * scale * ((1 - t) * segments.width[2 * s] + t * segments.width[2 * s + 1]);
        control.insert(control.end(), {p.x, p.y, p.z, radius});
        bounds_.extend(p - Vec3(radius));
        bounds_.extend(p + Vec3(radius));
      }
      if (curve->kind == CurveGeometry::Kind::Ribbon) {
        const Normal3 n0 = normalize(X.normal(segments.normals[2 * s])), n1 = normalize(X.normal(segments.normals[2 * s + 1]));
        end_normals.insert(end_normals.end(), {n0, n1});
        const std::array<Normal3, 4> control_normals = bezier_normals(n0, n1);
        normals.insert(normals.end(), control_normals.begin(), control_normals.end());
      }
    }
  };
  place(T, curve->control, curve->normals, curve->end_normals);
  if (T_end) place(*T_end, curve->control_end, curve->normals_end, curve->end_normals_end);
  embree_.add_curves(uint32_t(shapes_.size()), *curve, object);
  rec.curve = std::move(curve);
  shapes_.push_back(std::move(rec));
}

void Scene::add_triangles(ShapeRecord rec, TriangleMesh mesh, const Transform& T, const Transform* T_end,
                          bool reverse, const std::optional<AreaEmission>& emission, bool rectangle,
                          int object, const MeshShape* deforming) {
  rec.kind = ShapeRecord::Kind::Triangles;
  if (T_end || deforming) {
    // The winding below is baked once from the start transform: an end transform of the other
    // handedness would turn the shape inside out on the way (flattening it at some time).
    if (T_end && T_end->swaps_handedness() != T.swaps_handedness())
      throw SceneError(fmt::format("{}: the end transform mirrors the shape relative to the start transform",
                                   rec.name));
    // Where the vertices are at the end: a deforming mesh's end vertices, or its own, under the end
    // transform (or the one transform of a mesh that only deforms).
    const Transform& E = T_end ? *T_end : T;
    const std::vector<Point3>& end_positions = deforming ? deforming->positions_end : mesh.positions;
    if (end_positions.size() != mesh.positions.size())
      throw SceneError(fmt::format("{}: the mesh has {} vertices at the end of its motion, {} at the start", rec.name,
                                   end_positions.size(), mesh.positions.size()));
    rec.positions_end.reserve(end_positions.size());
    for (const auto& p : end_positions) {
      rec.positions_end.push_back(E.point(p));
      bounds_.extend(rec.positions_end.back());
    }
    rec.normals_end = deforming && !deforming->normals_end.empty() ? deforming->normals_end : mesh.normals;
    place_normals(rec.normals_end, E, reverse);
  }
  // The mesh's own arrays become the record's, placed in world space where they are.
  rec.positions = std::move(mesh.positions);
  for (auto& p : rec.positions) {
    p = T.point(p);
    bounds_.extend(p);
  }
  rec.normals = std::move(mesh.normals);
  place_normals(rec.normals, T, reverse);
  rec.uvs = std::move(mesh.uvs);
  rec.indices = std::move(mesh.indices);
  if (!mesh.attributes.empty())
    rec.attributes = std::make_shared<const std::vector<TriangleMesh::Attribute>>(std::move(mesh.attributes));
  // Keep cross(p1-p0, p2-p0) equal to the object-space normal transformed as a normal: a mirroring
  // transform reverses the winding, and so does reverse orientation.
  rec.winding_swapped = T.swaps_handedness() != reverse;
  if (rec.winding_swapped)
    for (size_t i = 0; i < rec.indices.size(); i += 3) std::swap(rec.indices[i + 1], rec.indices[i + 2]);
  triangle_count_ += rec.indices.size() / 3;

  if (emission) {
    rec.first_light = int(lights_.size());
    rec.radiance = emission->radiance;
    rec.two_sided_emission = emission->two_sided;
    rec.emission_texture = emission->texture;
  }
  if (emission && rectangle) {
    // One light for the whole parallelogram (its two triangles share it), so that light samples
    // stratify over all of it. Corner p0, edges to p1 and p3 as rectangle_mesh lays them out.
    const Point3 &p0 = rec.positions[0], &p1 = rec.positions[1], &p3 = rec.positions[3];
    const Point3 &a = rec.positions[rec.indices[0]], &b = rec.positions[rec.indices[1]], &c = rec.positions[rec.indices[2]];
    Vec3 oriented = cross(b - a, c - a);  // after the winding was baked: the emitting side
    float area = length(cross(p1 - p0, p3 - p0));
    rec.light_per_triangle = false;
    RectangleLight light{p0, p1 - p0, p3 - p0, normalize(oriented), area, rec.radiance, rec.two_sided_emission};
    light.emission_texture = {&textures_, rec.emission_texture};
    lights_.push_back(light);
  } else if (emission) {
    for (size_t i = 0; i < rec.indices.size(); i += 3) {
      const Point3 &p0 = rec.positions[rec.indices[i]], &p1 = rec.positions[rec.indices[i + 1]],
                   &p2 = rec.positions[rec.indices[i + 2]];
      Vec3 c = cross(p1 - p0, p2 - p0);
      float len = length(c);
      Normal3 n = len > 0 ? c / len : Normal3(0, 0, 1);
      if (!rec.normals.empty()) {
        Normal3 ns = rec.normals[rec.indices[i]] + rec.normals[rec.indices[i + 1]] + rec.normals[rec.indices[i + 2]];
        n = face_forward(n, ns);
      }
      // Degenerate triangles get a zero-area light that is never chosen (zero power).
      TriangleLight light{p0, p1, p2, n, len / 2, rec.radiance, rec.two_sided_emission};
      if (rec.emission_texture >= 0) {
        light.emission_texture = {&textures_, rec.emission_texture};
        if (!rec.uvs.empty()) {
          light.uv0 = rec.uvs[rec.indices[i]];
          light.uv1 = rec.uvs[rec.indices[i + 1]];
          light.uv2 = rec.uvs[rec.indices[i + 2]];
        }
      }
      lights_.push_back(light);
    }
  }
  if (!rec.indices.empty()) {
    if (rec.is_moving()) {
      embree_.add_moving_triangles(uint32_t(shapes_.size()), rec.positions, rec.positions_end, rec.indices);
    } else {
      // Embree reads the record's arrays in place (they never move: records are moved, not copied),
      // and reads the last vertex with a 16-byte load, hence one spare vertex of capacity.
      rec.positions.reserve(rec.positions.size() + 1);
      embree_.add_shared_triangles(uint32_t(shapes_.size()), rec.positions, rec.indices, object);
    }
  }
  shapes_.push_back(std::move(rec));
}

const Transform& Scene::transform_at(const Transform& to_world, const std::optional<Transform>& to_world_end,
                                     float time, std::optional<Transform>& storage) const {
  if (to_world_end) {
    storage = interpolate_transform(to_world, *to_world_end, embree_.normalized_time(time));
    if (storage) return *storage;
  }
  return to_world;
}

bool Scene::intersect(const Ray& world_ray, SurfaceHit& hit) const {
  EmbreeHit eh;
  if (!embree_.intersect(world_ray, eh)) return false;
  const ShapeRecord& rec = shapes_[eh.geometry];
  hit.t = eh.t;
  hit.shape = eh.geometry;
  hit.primitive = eh.primitive;
  // A hit through an instance is reconstructed in object space, then placed in the world.
  const Transform* instance_to_world = nullptr;
  std::optional<Transform> at_time;
  Ray ray = world_ray;
  if (eh.instance >= 0) {
    const InstanceRecord& inst = instances_[size_t(eh.instance)];
    instance_to_world = &transform_at(inst.to_world, inst.to_world_end, ray.time, at_time);
    const Transform& to_object = instance_to_world->inverse();
    ray.origin = to_object.point(world_ray.origin);
    ray.direction = to_object.vector(world_ray.direction);  // not normalised: t stays the world's
  }
  switch (rec.kind) {
    case ShapeRecord::Kind::Triangles:
      reconstruct_triangle_hit(rec, eh, ray.time, hit);
      break;
    case ShapeRecord::Kind::Sphere:
      reconstruct_sphere_hit(rec, ray, eh.t, hit);
      break;
    case ShapeRecord::Kind::Disk:
    case ShapeRecord::Kind::Cylinder:
      reconstruct_quadric_hit(rec, ray, eh.t, hit);
      break;
    case ShapeRecord::Kind::SdfGrid:
      reconstruct_sdf_hit(rec, ray, eh.t, eh.primitive, hit);
      break;
    case ShapeRecord::Kind::Curve:
      reconstruct_curve_hit(rec, ray, eh, hit);
      break;
    case ShapeRecord::Kind::Plane: {
      hit.p = ray.at(eh.t);
      hit.ng = rec.flip_normal ? -rec.plane.normal : rec.plane.normal;
      hit.ns = hit.ng;
      hit.uv = {0, 0};
      hit.dpdu = hit.dpdv = Vec3(0.0f);
      break;
    }
  }
  if (instance_to_world) {
    const Transform& T = *instance_to_world;
    hit.p = T.point(hit.p);
    hit.ng = normalize(T.normal(hit.ng));
    hit.ns = normalize(T.normal(hit.ns));
    hit.dpdu = T.vector(hit.dpdu);
    hit.dpdv = T.vector(hit.dpdv);
  }
  return true;
}

void Scene::reconstruct_triangle_hit(const ShapeRecord& rec, const EmbreeHit& eh, float time, SurfaceHit& hit) const {
  uint32_t i0 = rec.indices[3 * eh.primitive], i1 = rec.indices[3 * eh.primitive + 1],
           i2 = rec.indices[3 * eh.primitive + 2];
  float b0 = 1 - eh.u - eh.v;
  hit.bary = {eh.u, eh.v};
  Point3 p0 = rec.positions[i0], p1 = rec.positions[i1], p2 = rec.positions[i2];
  const bool moving = rec.is_moving();
  // A moving triangle is where Embree found it: its vertices interpolated at the ray's time.
  const float t = moving ? embree_.normalized_time(time) : 0;
  if (moving) {
    p0 = lerp(t, p0, rec.positions_end[i0]);
    p1 = lerp(t, p1, rec.positions_end[i1]);
    p2 = lerp(t, p2, rec.positions_end[i2]);
  }
  hit.p = p0 * b0 + p1 * eh.u + p2 * eh.v;
  hit.ng = normalize(cross(p1 - p0, p2 - p0));
  if (!rec.normals.empty()) {
    Normal3 n0 = rec.normals[i0], n1 = rec.normals[i1], n2 = rec.normals[i2];
    if (moving) {
      n0 = lerp(t, n0, rec.normals_end[i0]);
      n1 = lerp(t, n1, rec.normals_end[i1]);
      n2 = lerp(t, n2, rec.normals_end[i2]);
    }
    Normal3 ns = n0 * b0 + n1 * eh.u + n2 * eh.v;
    float len = length(ns);
    hit.ns = len > 0 ? ns / len : hit.ng;
    hit.ng = face_forward(hit.ng, hit.ns);
  } else {
    hit.ns = hit.ng;
  }
  if (rec.uvs.empty()) {
    // Barycentric uvs in the mesh's own vertex order, whatever winding was baked for orientation.
    hit.uv = rec.winding_swapped ? Vec2(eh.v, eh.u) : Vec2(eh.u, eh.v);
    hit.dpdu = rec.winding_swapped ? p2 - p0 : p1 - p0;
    hit.dpdv = rec.winding_swapped ? p1 - p0 : p2 - p0;
  } else {
    const Vec2 &uv0 = rec.uvs[i0], &uv1 = rec.uvs[i1], &uv2 = rec.uvs[i2];
    hit.uv = uv0 * b0 + uv1 * eh.u + uv2 * eh.v;
    // dp/du from the triangle's uv parameterisation (pbrt-v4's Triangle::InteractionFromIntersection).
    Vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
    float det = duv02.x * duv12.y - duv02.y * duv12.x;
    hit.dpdu = std::abs(det) > 1e-12f ? ((p0 - p2) * duv12.y - (p1 - p2) * duv02.y) / det : p1 - p0;
    hit.dpdv = std::abs(det) > 1e-12f ? ((p1 - p2) * duv02.x - (p0 - p2) * duv12.x) / det : p2 - p0;
  }
}

void Scene::reconstruct_sphere_hit(const ShapeRecord& rec, const Ray& ray, float t, SurfaceHit& hit) const {
  const SphereGeometry& s = rec.sphere;
  // A moving sphere is where Embree found it: under its transform at the ray's time (invertible
  // there, or it would not have been hit).
  std::optional<Transform> at_time;
  const Transform* to_world = &transform_at(s.to_world, s.to_world_end, ray.time, at_time);
  hit.p = ray.at(t);
  // Re-project onto the surface in object space to remove the error of o + t d, then map back.
  Point3 po = to_world->inverse().point(hit.p) - s.center;
  po = po * (s.radius / length(po));
  hit.p = to_world->point(s.center + po);
  hit.ng = normalize(to_world->normal(po));
  if (rec.flip_normal) hit.ng = -hit.ng;
  hit.ns = hit.ng;
  float rho = std::sqrt(po.x * po.x + po.y * po.y);
  if (s.partial && s.uv == SphereUv::Pbrt) {
    // pbrt-v4's (u, v) of the part kept: u = phi / phi_max, v from theta(z_min) to theta(z_max);
    // dp/du = phi_max (-y, x, 0), dp/dv = (theta(z_max) - theta(z_min)) (z cos phi, z sin phi, -r sin theta).
    const float dtheta = s.theta_z_max - s.theta_z_min;
    hit.uv = partial_sphere_uv(Vec3(po.x, po.y, po.z), s.phi_max, s.theta_z_min, s.theta_z_max);
    hit.dpdu = to_world->vector(Vec3(-po.y, po.x, 0) * s.phi_max);
    hit.dpdv = rho > 0 ? to_world->vector(Vec3(po.z * po.x / rho, po.z * po.y / rho, -rho) * dtheta) : Vec3(0.0f);
    return;
  }
  // pbrt-v4's v = 1 - theta / pi is Mitsuba's v of the point mirrored in z (u unchanged).
  const float v_sign = s.uv == SphereUv::Pbrt ? -1.0f : 1.0f;
  hit.uv = sphere_uv(Vec3(po.x, po.y, v_sign * po.z));
  hit.dpdu = to_world->vector(Vec3(-po.y, po.x, 0) * (2 * kPi));
  // v = theta / pi: dp/dv = pi (z cos phi, z sin phi, -r sin theta); negated for 1 - theta / pi.
  hit.dpdv = rho > 0 ? to_world->vector(Vec3(po.z * po.x / rho, po.z * po.y / rho, -rho) * (v_sign * kPi)) : Vec3(0.0f);
}

void Scene::reconstruct_quadric_hit(const ShapeRecord& rec, const Ray& ray, float t, SurfaceHit& hit) const {
  const QuadricGeometry& q = rec.quadric;
  // Where a moving quadric is at the ray's time, as for spheres.
  std::optional<Transform> at_time;
  const Transform* M = &transform_at(q.to_world, q.to_world_end, ray.time, at_time);
  // Back to the unit shape, projected onto it (removing the error of o + t d), and out again.
  Point3 local = M->inverse().point(ray.at(t));
  if (q.kind == QuadricGeometry::Kind::Disk) {
    // Mitsuba's disk: (u, v) = (r, phi / 2 pi), dp/du the radial direction.
    local.z = 0;
    hit.uv = disk_uv(local.x, local.y);
    float r = hit.uv.x;
    hit.dpdu = M->vector(r > 0 ? Vec3(local.x / r, local.y / r, 0) : Vec3(1, 0, 0));
    hit.dpdv = M->vector(Vec3(-local.y, local.x, 0) * (2 * kPi));
    hit.ng = normalize(M->normal({0, 0, 1}));
  } else {
    // Mitsuba's cylinder: (u, v) = (phi / 2 pi, height along the axis / its length),
    // dp/du = 2 pi (-y, x, 0) in the tube's space; the normal points away from the axis. Cut to
    // phi_max (pbrt-v4's): u = phi / phi_max, dp/du = phi_max (-y, x, 0).
    float rho = std::sqrt(local.x * local.x + local.y * local.y);
    float x = rho > 0 ? local.x / rho : 1.0f, y = rho > 0 ? local.y / rho : 0.0f;
    local = {x, y, std::clamp(local.z, 0.0f, 1.0f)};
    hit.uv = cylinder_uv(x, y, local.z, q.phi_max);
    hit.dpdu = M->vector(Vec3(-y, x, 0) * q.phi_max);
    hit.dpdv = M->vector(Vec3(0, 0, 1));
    hit.ng = normalize(M->normal({x, y, 0}));
  }
  hit.p = M->point(local);
  if (rec.flip_normal) hit.ng = -hit.ng;
  hit.ns = hit.ng;
}

void Scene::reconstruct_sdf_hit(const ShapeRecord& rec, const Ray& ray, float t, uint32_t voxel, SurfaceHit& hit) const {
  const SdfGridGeometry& sdf = rec.sdf;
  const SdfGrid& grid = *sdf.grid;
  // A moving grid is where Embree found it: under its transform at the ray's time (invertible
  // there, or it would not have been hit).
  const Transform to_world = sdf.to_world_at(embree_.normalized_time(ray.time)).value_or(sdf.to_world);
  const Transform index_to_world = to_world * grid.index_to_object();
  // The hit point in the grid's index space, in double, moved onto the surface of the voxel found.
  const Matrix4& to_index = index_to_world.inverse_matrix();
  Vec3d p = apply(to_index, Vec3d::from(ray.origin), 1) + apply(to_index, Vec3d::from(ray.direction), 0) * double(t);
  p = grid.project_to_surface(voxel, p);
  hit.p = apply(index_to_world.matrix(), p, 1).to_float();
  // Distances grow outwards, so the gradient is the outward normal.
  Normal3 ng = to_world.normal(grid.gradient(voxel, p).to_float());
  hit.ng = length_squared(ng) > 0 ? normalize(ng) : -normalize(ray.direction);
  hit.ns = hit.ng;
  if (rec.sdf_normals == SdfNormals::Smooth) {
    // Kept only where it leans to the same side as the geometric normal (as SurfaceHit promises).
    Normal3 ns = to_world.normal(grid.smooth_normal(p).to_float());
    if (length_squared(ns) > 0 && dot(ns, hit.ng) > 0) hit.ns = normalize(ns);
  }
  if (rec.flip_normal) {
    hit.ng = -hit.ng;
    hit.ns = -hit.ns;
  }
  // No (u, v) parameterisation (as in Mitsuba): u = v = 0, and the tangents of the shading frame.
  hit.uv = {0, 0};
  const Frame frame(hit.ns);
  hit.dpdu = frame.s;
  hit.dpdv = frame.t;
}

// A curve hit: u is the segment's own parameter (Embree's, as pbrt-v4's), v runs across the width from
// 0 to 1 along b = cross(ray direction, tangent) (pbrt-v4's, so that a hair BSDF finds its offset
// h = 2 v - 1 across the fibre), dp/du is the tangent and dp/dv the width along the direction v grows.
// Normals: a tube's is the surface's own (outwards); a flat curve's faces back along the ray, square
// to the tangent; a ribbon's is Embree's on the side of the ribbon's normal there.
void Scene::reconstruct_curve_hit(const ShapeRecord& rec, const Ray& ray, const EmbreeHit& eh, SurfaceHit& hit) const {
  const CurveGeometry& c = *rec.curve;
  const size_t s = eh.primitive;
  // A moving curve is where Embree found it: its control points interpolated at the ray's time.
  const float time = c.moving() ? embree_.normalized_time(ray.time) : 0;
  std::array<Point3, 4> cp;
  std::array<float, 4> radius;
  for (size_t i = 0; i < 4; ++i) {
    const float* v = &c.control[16 * s + 4 * i];
    cp[i] = Point3(v[0], v[1], v[2]);
    radius[i] = v[3];
    if (c.moving()) {
      const float* e = &c.control_end[16 * s + 4 * i];
      cp[i] = lerp(time, cp[i], Point3(e[0], e[1], e[2]));
      radius[i] = (1 - time) * radius[i] + time * e[3];
    }
  }
  const float u = std::clamp(eh.u, 0.0f, 1.0f);
  const Point3 axis = bezier_point(cp, u);
  Vec3 dpdu = bezier_derivative(cp, u);
  if (!(length_squared(dpdu) > 0)) dpdu = cp[3] - cp[0];  // a segment that stops at an end: along its chord
  const Vec3 tangent = length_squared(dpdu) > 0 ? normalize(dpdu) : Vec3(1, 0, 0);
  const float width = 2 * bezier_point(radius, u);
  hit.p = ray.at(eh.t);
  const Vec3 d = normalize(ray.direction);
  Vec3 across = cross(d, tangent);  // where pbrt-v4's v grows
  across = length_squared(across) > 1e-12f ? normalize(across) : Frame(tangent).s;
  Normal3 n;
  float offset = dot(hit.p - axis, across);  // signed distance from the axis along which v grows
  Vec3 dpdv_direction = across;
  switch (c.kind) {
    case CurveGeometry::Kind::Round:
      n = length_squared(eh.ng) > 0 ? normalize(eh.ng) : normalize(hit.p - axis);
      if (const Vec3 around = cross(tangent, n); length_squared(around) > 1e-12f) dpdv_direction = normalize(around);
      break;
    case CurveGeometry::Kind::Flat:
      n = normalize(cross(across, tangent));  // -d made square to the tangent
      break;
    case CurveGeometry::Kind::Ribbon: {
      const size_t e = 2 * s;
      Normal3 n0 = c.end_normals[e], n1 = c.end_normals[e + 1];
      if (c.moving()) {
        n0 = normalize(lerp(time, n0, c.end_normals_end[e]));
        n1 = normalize(lerp(time, n1, c.end_normals_end[e + 1]));
      }
      const Normal3 ribbon = slerp_normal(n0, n1, u);
      n = length_squared(eh.ng) > 0 ? face_forward(normalize(eh.ng), ribbon) : ribbon;
      // The band's width lies along cross(normal, tangent); pbrt-v4's v grows along its side facing `across`.
      Vec3 band = cross(ribbon, tangent);
      band = length_squared(band) > 0 ? normalize(band) : across;
      if (dot(band, across) < 0) band = -band;
      offset = dot(hit.p - axis, band);
      dpdv_direction = band;
      break;
    }
  }
  hit.uv = {u, width > 0 ? std::clamp(0.5f + offset / width, 0.0f, 1.0f) : 0.5f};
  hit.dpdu = dpdu;
  hit.dpdv = dpdv_direction * width;
  hit.ng = rec.flip_normal ? -n : n;
  hit.ns = hit.ng;
}

TextureEvalContext Scene::texture_context(const SurfaceHit& hit) const {
  TextureEvalContext ctx{hit.p, hit.uv, {}, hit.ng};
  const ShapeRecord& rec = shapes_[hit.shape];
  if (rec.attributes && rec.kind == ShapeRecord::Kind::Triangles && 3 * size_t(hit.primitive) + 2 < rec.indices.size()) {
    ctx.mesh.attributes = rec.attributes.get();
    ctx.mesh.face = hit.primitive;
    for (int k = 0; k < 3; ++k) ctx.mesh.vertex[k] = rec.indices[3 * size_t(hit.primitive) + size_t(k)];
    ctx.mesh.b1 = hit.bary.x;
    ctx.mesh.b2 = hit.bary.y;
  }
  return ctx;
}

RGB Scene::emitted(const SurfaceHit& hit, const Vec3& wo) const {
  const ShapeRecord& rec = shapes_[hit.shape];
  if (!rec.is_emissive()) return RGB(0.0f);
  if (!rec.two_sided_emission && dot(hit.ng, wo) <= 0) return RGB(0.0f);
  if (rec.emission_texture < 0) return rec.radiance;
  ColorInput texture;
  texture.texture = rec.emission_texture;
  return rec.radiance * textures_.eval(texture, texture_context(hit));
}

int Scene::light_index(const SurfaceHit& hit) const {
  const ShapeRecord& rec = shapes_[hit.shape];
  if (!rec.is_emissive()) return -1;
  return rec.kind == ShapeRecord::Kind::Triangles && rec.light_per_triangle ? rec.first_light + int(hit.primitive)
                                                                           : rec.first_light;
}

}  // namespace candela
