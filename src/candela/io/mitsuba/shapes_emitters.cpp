// The Mitsuba converter: shapes, shapegroups and instances; emitters.
#include "candela/io/mitsuba/converter.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "candela/film/image_io.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/io/mesh_io.h"

namespace candela::mitsuba {

// ---------------------------------------------------------------- shapes

// The cube of Mitsuba's "cube": [-1, 1]^3 as 24 vertices (per-face normals and uvs), 12 triangles.
TriangleMesh Converter::cube_mesh() {
  static const float p[24][3] = {{1, -1, -1}, {1, -1, 1},  {-1, -1, 1}, {-1, -1, -1}, {1, 1, -1},  {-1, 1, -1},
                                 {-1, 1, 1},  {1, 1, 1},   {1, -1, -1}, {1, 1, -1},   {1, 1, 1},   {1, -1, 1},
                                 {1, -1, 1},  {1, 1, 1},   {-1, 1, 1},  {-1, -1, 1},  {-1, -1, 1}, {-1, 1, 1},
                                 {-1, 1, -1}, {-1, -1, -1}, {1, 1, -1}, {1, -1, -1},  {-1, -1, -1}, {-1, 1, -1}};
  static const float n[6][3] = {{0, -1, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}};
  static const float uv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  TriangleMesh m;
  for (int i = 0; i < 24; ++i) {
    m.positions.push_back({p[i][0], p[i][1], p[i][2]});
    m.normals.push_back({n[i / 4][0], n[i / 4][1], n[i / 4][2]});
    m.uvs.push_back({uv[i % 4][0], uv[i % 4][1]});
  }
  for (uint32_t f = 0; f < 6; ++f) {
    uint32_t b = 4 * f;
    for (uint32_t k : {b, b + 1, b + 2, b + 3, b, b + 2}) m.indices.push_back(k);
  }
  return m;
}

TriangleMesh Converter::mesh_file(const Object& s) {
  fs::path file = resolve_file(s, "filename");
  const Property* name = find(s, "filename");
  SourceLocation at = name->where.loc();
  std::string ext = lower(file.extension().string());
  if (s.type == "serialized" && ext != ".serialized")
    throw_scene_error(at, "shape \"serialized\": \"{}\" is not a .serialized file", file.string());
  if (s.type == "obj" && ext != ".obj")
    throw_scene_error(at, "shape \"obj\": \"{}\" is not an .obj file", file.string());
  if (s.type == "ply" && ext != ".ply")
    throw_scene_error(at, "shape \"ply\": \"{}\" is not a .ply file", file.string());
  const int shape_index = s.type == "serialized" ? get_int(s, "shape_index", 0) : 0;
  TriangleMesh mesh = load_mesh_file(file, at, shape_index);
  if (s.type == "obj") {
    // Mitsuba's OBJ loader flips v (flip_tex_coords, on by default) so that its images, looked
    // up with v = 0 at the top row, appear upright; candela keeps Mitsuba's uvs.
    if (get_bool(s, "flip_tex_coords", true))
      for (Vec2& t : mesh.uvs) t.y = 1 - t.y;
  }
  if (get_bool(s, "face_normals", false)) mesh.normals.clear();
  return mesh;
}

// Mitsuba's sdfgrid: a one-channel .vol file; any to_world is accepted (Mitsuba warns about
// rotations, which its own intersection handles too).
SdfGridShape Converter::sdf_grid(const Object& s) {
  const std::string normals = get_string(s, "normals", "smooth");
  if (normals != "smooth" && normals != "analytic")
    throw_scene_error(find(s, "normals")->where.loc(), "sdfgrid: normals \"{}\" must be \"smooth\" or \"analytic\"",
                      normals);
  const fs::path file = resolve_file(s, "filename");
  return read_sdf_grid_file(file, find(s, "filename")->where.loc(),
                            normals == "smooth" ? SdfNormals::Smooth : SdfNormals::Analytic);
}

void Converter::shape(const Object& s, ObjectDesc* group) {
  ShapeDesc out;
  out.where = s.where.place();
  out.name = s.id.empty() ? s.type : s.id;
  out.to_world = get_transform(s, "to_world");
  const std::string& type = s.type;
  if (type == "obj" || type == "ply" || type == "serialized") {
    out.geometry = MeshShape{mesh_file(s)};
  } else if (type == "sphere") {
    SphereShape sp;
    if (std::optional<Vec3> c = get_vector(s, "center"); c) sp.center = *c;
    sp.radius = get_float(s, "radius", 1.0f);
    if (!(sp.radius > 0)) throw_scene_error(s.where.loc(), "sphere: the radius must be positive");
    out.geometry = sp;
  } else if (type == "rectangle") {
    out.geometry = RectangleShape{};
  } else if (type == "cube") {
    out.geometry = MeshShape{cube_mesh()};
  } else if (type == "disk") {
    out.geometry = DiskShape{};
  } else if (type == "cylinder") {
    CylinderShape c;
    if (std::optional<Vec3> p0 = get_vector(s, "p0"); p0) c.p0 = *p0;
    if (std::optional<Vec3> p1 = get_vector(s, "p1"); p1) c.p1 = *p1;
    c.radius = get_float(s, "radius", 1.0f);
    if (!(c.radius > 0) || length(c.p1 - c.p0) == 0)
      throw_scene_error(s.where.loc(), "cylinder: needs a positive radius and p0 != p1");
    out.geometry = c;
  } else if (type == "sdfgrid") {
    out.geometry = sdf_grid(s);
  } else if (type == "instance") {
    if (group) throw_scene_error(s.where.loc(), "an instance cannot be inside a shapegroup");
    auto groups = nested(s, "shape");
    if (groups.size() != 1 || groups[0].second->type != "shapegroup")
      throw_scene_error(s.where.loc(), "instance needs exactly one reference to a shapegroup");
    InstanceDesc inst;
    inst.where = s.where.place();
    inst.object = shapegroup(*groups[0].second);
    inst.to_world = out.to_world;
    check_all_used(s);
    desc_.instances.push_back(inst);
    return;
  } else if (type == "shapegroup") {
    throw_scene_error(s.where.loc(), "a shapegroup cannot be nested in another shape");
  } else {
    unknown_type(s, "shape", type, {"obj", "ply", "serialized", "sphere", "rectangle", "cube", "disk", "cylinder",
                                    "sdfgrid", "shapegroup", "instance"});
  }
  out.reverse_orientation = get_bool(s, "flip_normals", false);
  shape_media(s, out);
  auto bsdfs = nested(s, "bsdf");
  if (bsdfs.size() > 1) throw_scene_error(bsdfs[1].first->where.loc(), "a shape can have only one bsdf");
  out.material = bsdfs.empty() ? default_material() : bsdf(*bsdfs[0].second, false);
  auto emitters = nested(s, "emitter");
  if (emitters.size() > 1) throw_scene_error(emitters[1].first->where.loc(), "a shape can have only one emitter");
  if (!emitters.empty()) {
    const Object& e = *emitters[0].second;
    if (e.type != "area")
      throw_scene_error(e.where.loc(), "emitter \"{}\" cannot be attached to a shape (only \"area\" can)", e.type);
    if (type == "sdfgrid")
      throw_scene_error(e.where.loc(), "an sdfgrid cannot be an area emitter (nor can it in Mitsuba)");
    if (group) throw_scene_error(e.where.loc(), "emitters inside a shapegroup are not supported");
    AreaEmission em;
    ColorInput radiance = color(e, "radiance", RGB(1.0f), true);
    if (radiance.is_constant()) {
      em.radiance = radiance.value;
    } else {
      em.radiance = RGB(1.0f);
      em.texture = radiance.texture;
    }
    check_all_used(e);
    out.emission = em;
  }
  check_all_used(s);
  if (group) group->shapes.push_back(std::move(out));
  else desc_.shapes.push_back(std::move(out));
}

int Converter::shapegroup(const Object& g) {
  if (auto it = group_memo_.find(&g); it != group_memo_.end()) return it->second;
  ObjectDesc obj;
  obj.where = g.where.place();
  obj.name = g.id;
  for (size_t i = 0; i < g.props.size(); ++i) {
    const Property& p = g.props[i];
    if (p.kind != Property::Kind::Object && p.kind != Property::Kind::Ref) continue;
    const Object& child = deref(p);
    if (child.tag != "shape") continue;
    g.usage.mark_used_at(i);
    if (child.type == "shapegroup" || child.type == "instance")
      throw_scene_error(child.where.loc(), "a shapegroup cannot hold {} (instancing does not nest)",
                        child.type == "instance" ? "an instance" : "another shapegroup");
    shape(child, &obj);
  }
  check_all_used(g);
  if (obj.shapes.empty()) throw_scene_error(g.where.loc(), "the shapegroup holds no shapes");
  desc_.objects.push_back(std::move(obj));
  int index = int(desc_.objects.size()) - 1;
  group_memo_[&g] = index;
  return index;
}

// ---------------------------------------------------------------- emitters

void Converter::add_light(LightDesc l, const Where& where) {
  desc_.lights.push_back(std::move(l));
  desc_.places.lights.push_back(where.place());
}

Vec3 Converter::origin_of(const Transform& t) { return t.point({0, 0, 0}); }
                          
                          void Converter::emitter(const Object& e) {
  const std::string& type = e.type;
  if (type == "point") {
    PointLight l;
    Transform t = get_transform(e, "to_world");
    l.position = origin_of(t);
    if (std::optional<Vec3> p = get_vector(e, "position"); p) {
      if (!t.is_identity()) throw_scene_error(e.where.loc(), "point: give either position or to_world");
      l.position = *p;
    }
    l.intensity = constant_color(e, "intensity", RGB(1.0f));
    add_light(l, e.where);
  } else if (type == "constant") {
    SkyLight l;
    l.zenith = l.horizon = l.ground = constant_color(e, "radiance", RGB(1.0f));
    add_light(l, e.where);
  } else if (type == "envmap") {
    EnvironmentMap l;
    l.filename = resolve_file(e, "filename").string();
    l.scale = RGB(get_float(e, "scale", 1.0f));
    l.to_world = get_transform(e, "to_world");
    l.mapping = EnvironmentMapping::EquirectangularPoleRows;
    l.mis_compensation = get_bool(e, "mis_compensation", false);
    ignore(e, "filter_type");
    add_light(l, e.where);
  } else if (type == "directional") {
    DistantLight l;
    Transform t = get_transform(e, "to_world");
    l.direction = normalize(t.vector({0, 0, 1}));
    if (std::optional<Vec3> d = get_vector(e, "direction"); d) {
      if (!t.is_identity()) throw_scene_error(e.where.loc(), "directional: give either direction or to_world");
      if (length(*d) == 0) throw_scene_error(e.where.loc(), "directional: the direction is zero");
      l.direction = normalize(*d);
    }
    l.radiance = constant_color(e, "irradiance", RGB(1.0f));
    add_light(l, e.where);
  } else if (type == "spot") {
    SpotLight l;
    Transform t = get_transform(e, "to_world");
    l.position = origin_of(t);
    l.direction = normalize(t.vector({0, 0, 1}));
    l.up = normalize(t.vector({0, 1, 0}));
    l.intensity = constant_color(e, "intensity", RGB(1.0f));
    float cutoff = get_float(e, "cutoff_angle", 20.0f);
    float beam = get_float(e, "beam_width", cutoff * 0.75f);
    if (!(cutoff > 0 && cutoff <= 90) || !(beam >= 0 && beam <= cutoff))
      throw_scene_error(e.where.loc(), "spot: needs 0 < beam_width <= cutoff_angle <= 90");
    l.cone_angle = cutoff;
    l.cone_delta = cutoff - beam;
    l.falloff = SpotFalloff::Linear;
    if (const Property* p = find(e, "texture"); p) {
      if (p->kind != Property::Kind::Object && p->kind != Property::Kind::Ref) wrong_kind(e, *p, "a texture");
      l.texture = texture(deref(*p));
    }
    add_light(l, e.where);
  } else if (type == "projector") {
    ProjectorLight l;
    l.to_world = get_transform(e, "to_world");
    ColorInput irr = color(e, "irradiance", RGB(1.0f), true);
    l.irradiance = irr.is_constant() ? constant_texture(irr.value, e.where) : irr.texture;
    l.scale = RGB(get_float(e, "scale", 1.0f));
    std::string axis = get_string(e, "fov_axis", "x");
    if (!find(e, "fov")) axis = "diagonal";  // Mitsuba's default focal length of 50 mm
    float fov = get_float(e, "fov", kDefaultFovDiagonal);
    // Mitsuba's fov is on fov_axis of the image; candela's on the wider axis.
    auto [w, h] = texture_size(l.irradiance);
    float fov_x = fov, t = std::tan(radians(fov) / 2);
    if (axis == "y") fov_x = 2 * std::atan(t * float(w) / float(h)) * 180 / kPi;
    else if (axis == "diagonal") fov_x = 2 * std::atan(t * float(w) / std::hypot(float(w), float(h))) * 180 / kPi;
    else if (axis != "x") throw_scene_error(e.where.loc(), "projector: fov_axis \"{}\" (use x, y or diagonal)", axis);
    l.fov_degrees = w >= h ? fov_x : 2 * std::atan(std::tan(radians(fov_x) / 2) * float(h) / float(w)) * 180 / kPi;
    add_light(l, e.where);
  } else if (type == "area") {
    throw_scene_error(e.where.loc(), "an area emitter must be inside the shape it lights");
  } else {
    unknown_type(e, "emitter", type, {"area", "point", "spot", "projector", "directional", "constant", "envmap"});
  }
  check_all_used(e);
}

RGB Converter::constant_color(const Object& o, std::string_view name, RGB fallback) {
  ColorInput c = color(o, name, fallback, true);
  if (!c.is_constant())
    throw_scene_error(find(o, name)->where.loc(), "{}: a textured \"{}\" is not supported", o.describe(), name);
  return c.value;
}

std::pair<int, int> Converter::texture_size(int index) {
  const auto* img = std::get_if<ImageTexture>(&desc_.textures[index]);
  if (!img) return {1, 1};
  check_exr_header(img->filename);
  auto in = OIIO::ImageInput::open(img->filename);
  if (!in) return {1, 1};
  const OIIO::ImageSpec& spec = in->spec();
  return {std::max(1, spec.width), std::max(1, spec.height)};
}

}  // namespace candela::mitsuba
