// The glTF reader: meshes and their primitives; the camera and the lights.
#include "candela/io/gltf/reader.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace candela::gltf {

// ---------------------------------------------------------------- meshes

void GltfReader::build_meshes() {
  for (const MeshUse& use : uses_)
    if (!converted_.count(use.mesh)) converted_[use.mesh] = convert_mesh(use.mesh);
  // A rigid mesh placed more than once becomes an object and its instances, unless it emits (each
  // emitting shape is a light of its own); a deforming one is a shape of its own at every use.
  std::map<int, int> rigid_uses;
  for (const MeshUse& use : uses_)
    if (!use.deforms) ++rigid_uses[use.mesh];
  auto instanced = [&](const MeshUse& use) {
    const std::vector<Primitive>& primitives = converted_[use.mesh];
    return !use.deforms && rigid_uses[use.mesh] > 1 &&
           std::none_of(primitives.begin(), primitives.end(), [](const Primitive& p) { return p.emission; });
  };
  // The last use that needs a mesh's triangles (a shape, or the first instance, which makes the
  // object) takes them; the earlier ones copy them.
  std::map<int, size_t> last_taker;
  {
    std::set<int> has_object;
    for (size_t u = 0; u < uses_.size(); ++u)
      if (!instanced(uses_[u]) || has_object.insert(uses_[u].mesh).second) last_taker[uses_[u].mesh] = u;
  }
  std::map<int, int> object_of_mesh;
  for (size_t u = 0; u < uses_.size(); ++u) {
    const MeshUse& use = uses_[u];
    const int m = use.mesh;
    std::vector<Primitive>& primitives = converted_[m];
    const bool take = last_taker[m] == u;
    // Where the model is over its animation (at rest when static), for the bounds the camera frames.
    const std::vector<Transform> placements = placements_over_time(use);
    if (instanced(use)) {
      auto found = object_of_mesh.find(m);
      if (found == object_of_mesh.end()) {
        ObjectDesc object;
        object.where = at(fmt::format("/meshes/{}", m));
        object.name = model_.meshes[size_t(m)].name.empty() ? fmt::format("mesh {}", m) : model_.meshes[size_t(m)].name;
        Bounds3 bounds;
        for (Primitive& p : primitives) {
          for (const Point3& q : p.mesh.positions) bounds.extend(q);
          ShapeDesc shape;
          shape.where = at(p.pointer);
          shape.geometry = MeshShape{take ? std::move(p.mesh) : p.mesh};
          shape.material = p.material;
          shape.name = p.name;
          object.shapes.push_back(std::move(shape));
        }
        object_bounds_.push_back(bounds);
        found = object_of_mesh.emplace(m, int(scene_.objects.size())).first;
        scene_.objects.push_back(std::move(object));
      }
      InstanceDesc instance;
      instance.where = at(use.pointer);
      instance.object = found->second;
      instance.to_world = use.to_world;
      instance.animation_node = use.animation_node;
      const Bounds3& b = object_bounds_[size_t(found->second)];
      if (!b.empty())
        for (const Transform& placement : placements)
          for (int corner = 0; corner < 8; ++corner)
            bounds_.extend(placement.point(
                {corner & 1 ? b.hi.x : b.lo.x, corner & 2 ? b.hi.y : b.lo.y, corner & 4 ? b.hi.z : b.lo.z}));
      scene_.instances.push_back(instance);
      continue;
    }
    for (Primitive& p : primitives) {
      ShapeDesc shape;
      shape.where = at(p.pointer);
      shape.deformation = use.deforms ? add_deformation(use, p) : -1;
      if (shape.deformation >= 0) {
        // The bounds of the deformed mesh over the animation (in world space when skinned).
        const SceneAnimation& animation = scene_.animation;
        for (float t : framing_times()) {
          std::vector<Point3> positions = p.mesh.positions;
          std::vector<Normal3> no_normals;
          animation.deform(animation.deformations[size_t(shape.deformation)], t, positions, no_normals);
          const Matrix4 place = use.animation_node >= 0 ? animation.world_matrix(use.animation_node, t) * use.to_world.matrix()
                                                        : use.to_world.matrix();
          if (const auto T = Transform::from_matrix(place))
            for (const Point3& q : positions) bounds_.extend(T->point(q));
        }
      } else {
        for (const Transform& placement : placements)
          for (const Point3& q : p.mesh.positions) bounds_.extend(placement.point(q));
      }
      shape.geometry = MeshShape{take ? std::move(p.mesh) : p.mesh};
      shape.to_world = use.to_world;
      shape.animation_node = use.animation_node;
      shape.material = p.material;
      shape.emission = p.emission;
      shape.name = p.name;
      scene_.shapes.push_back(std::move(shape));
    }
  }
}

std::vector<Primitive> GltfReader::convert_mesh(int m) {
  const tg::Mesh& mesh = model_.meshes[size_t(m)];
  std::vector<Primitive> out;
  for (size_t p = 0; p < mesh.primitives.size(); ++p) {
    const std::string pointer = fmt::format("/meshes/{}/primitives/{}", m, p);
    std::optional<Primitive> primitive = convert_primitive(mesh, mesh.primitives[p], pointer);
    if (primitive) {
      primitive->pointer = pointer;
      primitive->name = fmt::format("{}: mesh \"{}\" primitive {}", file_.filename().string(), mesh.name, p);
      out.push_back(std::move(*primitive));
    }
  }
  return out;
}

std::optional<Primitive> GltfReader::convert_primitive(const tg::Mesh& mesh, const tg::Primitive& prim, const std::string& pointer) {
  if (prim.extensions.count("KHR_draco_mesh_compression")) {
    // Not required by the file: the uncompressed accessors are there as a fallback.
  }
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP ||
      mode == TINYGLTF_MODE_LINE_STRIP) {
    warn(pointer, "mesh \"{}\": {} are not surfaces and are skipped", mesh.name, mode == 0 ? "points" : "lines");
    return std::nullopt;
  }
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
    fail(pointer + "/mode", "unknown primitive mode {}", mode);
  auto position = prim.attributes.find("POSITION");
  if (position == prim.attributes.end()) {
    warn(pointer, "mesh \"{}\": the primitive has no POSITION and is skipped", mesh.name);
    return std::nullopt;
  }
  Primitive result;
  TriangleMesh& tm = result.mesh;
  AccessorData pos = read_accessor(position->second, pointer + "/attributes/POSITION");
  if (pos.components != 3) fail(pointer + "/attributes/POSITION", "POSITION must be VEC3");
  const size_t n = pos.count;
  tm.positions.resize(n);
  for (size_t i = 0; i < n; ++i) tm.positions[i] = Point3(float(pos.at(i, 0)), float(pos.at(i, 1)), float(pos.at(i, 2)));

  MaterialInfo material = material_info(prim.material, prim.attributes.count("COLOR_0") > 0);
  result.material = material.material;
  result.emission = material.emission;

  if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
    AccessorData nor = read_accessor(it->second, pointer + "/attributes/NORMAL");
    if (nor.components != 3 || nor.count != n) fail(pointer + "/attributes/NORMAL", "NORMAL must be VEC3, one per position");
    tm.normals.resize(n);
    bool degenerate = false;
    for (size_t i = 0; i < n; ++i) {
      Normal3 v(float(nor.at(i, 0)), float(nor.at(i, 1)), float(nor.at(i, 2)));
      if (!(length_squared(v) > 1e-20f)) degenerate = true;
      tm.normals[i] = v;
    }
    if (degenerate) {
      warn(pointer + "/attributes/NORMAL", "some normals are zero; the primitive is shaded with its face normals");
      tm.normals.clear();
    }
  }
  const std::string uv_name = fmt::format("TEXCOORD_{}", material.uv_set);
  if (auto it = prim.attributes.find(uv_name); it != prim.attributes.end()) {
    AccessorData uv = read_accessor(it->second, pointer + "/attributes/" + uv_name);
    if (uv.components != 2 || uv.count != n) fail(pointer + "/attributes/" + uv_name, "{} must be VEC2, one per position", uv_name);
    tm.uvs.resize(n);
    // glTF's (0, 0) is the image's top-left corner; candela's t = 0 is its bottom row.
    for (size_t i = 0; i < n; ++i) tm.uvs[i] = Vec2(float(uv.at(i, 0)), float(1 - uv.at(i, 1)));
  } else if (material_has_textures_.count(prim.material)) {
    warn(pointer, "mesh \"{}\": the material's textures use {}, which the primitive does not have", mesh.name, uv_name);
  }
  if (material.uses_vertex_colors) {
    auto it = prim.attributes.find("COLOR_0");
    AccessorData color = read_accessor(it->second, pointer + "/attributes/COLOR_0");
    if ((color.components != 3 && color.components != 4) || color.count != n)
      fail(pointer + "/attributes/COLOR_0", "COLOR_0 must be VEC3 or VEC4, one per position");
    RGB factor = base_color_factor(prim.material);
    TriangleMesh::Attribute attribute;
    attribute.name = "color";
    attribute.channels = 3;
    attribute.values.resize(3 * n);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) attribute.values[3 * i + size_t(c)] = float(color.at(i, c)) * factor[c];
    tm.attributes.push_back(std::move(attribute));
  }

  // Skinning and morph targets, per vertex in the order above (which the triangles index).
  if (!model_.skins.empty()) read_skinning_attributes(prim, pointer, result);
  if (!prim.targets.empty()) read_morph_targets(prim, pointer, result);

  // Indices, then strips and fans as triangles.
  std::vector<uint32_t> index;
  if (prim.indices >= 0) {
    AccessorData ind = read_accessor(prim.indices, pointer + "/indices");
    if (ind.components != 1) fail(pointer + "/indices", "indices must be SCALAR");
    index.resize(ind.count);
    for (size_t i = 0; i < ind.count; ++i) {
      double v = ind.values[i];
      if (!(v >= 0 && v < double(n))) fail(pointer + "/indices", "index {} at {} is out of range (the primitive has {} vertices)", v, i, n);
      index[i] = uint32_t(v);
    }
  } else {
    index.resize(n);
    for (size_t i = 0; i < n; ++i) index[i] = uint32_t(i);
  }
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (a == b || b == c || a == c) return;  // degenerate
    tm.indices.insert(tm.indices.end(), {a, b, c});
  };
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    if (index.size() % 3 != 0) warn(pointer, "{} indices are not a multiple of 3; the last ones are ignored", index.size());
    tm.indices.reserve(index.size());
    for (size_t i = 0; i + 2 < index.size(); i += 3) add(index[i], index[i + 1], index[i + 2]);
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    // The specification's p_i = {v_i, v_(i + 1 + i % 2), v_(i + 2 - i % 2)}: every second one reversed.
    for (size_t i = 0; i + 2 < index.size(); ++i)
      add(index[i], index[i + 1 + i % 2], index[i + 2 - i % 2]);
  } else {
    // Fans: p_i = {v_(i + 1), v_(i + 2), v_0}.
    for (size_t i = 0; i + 2 < index.size(); ++i) add(index[i + 1], index[i + 2], index[0]);
  }
  if (tm.indices.empty()) return std::nullopt;
  return result;
}

// ---------------------------------------------------------------- camera and lights

void GltfReader::add_camera() {
  CameraDesc& cam = scene_.camera;
  if (camera_) {
    const auto& [index, T, pointer, animation_node] = *camera_;
    // On a moving node, T is the identity and the node places the camera.
    cam.animation_node = animation_node;
    if (size_t(index) >= model_.cameras.size()) fail(pointer + "/camera", "camera {} does not exist", index);
    const tg::Camera& c = model_.cameras[size_t(index)];
    const std::string cpointer = fmt::format("/cameras/{}", index);
    if (other_cameras_ > 0)
      warn(pointer, "{} more camera node(s) in the scene are ignored; the first one is used", other_cameras_);
    // glTF cameras look down their -z with +y up; candela's camera space looks down +z.
    const Transform flip = Transform::scale({1, 1, -1});
    const int width = options_.film_width;
    if (c.type == "orthographic") {
      const double xmag = std::abs(c.orthographic.xmag), ymag = std::abs(c.orthographic.ymag);
      if (!(xmag > 0) || !(ymag > 0)) fail(cpointer + "/orthographic", "xmag and ymag must not be zero");
      cam.projection = Projection::Orthographic;
      // The film spans x in [-1, 1] and y in [-1 / aspect, 1 / aspect]: scaled by xmag, with
      // aspect xmag / ymag, that is glTF's [-xmag, xmag] x [-ymag, ymag].
      cam.world_from_camera = T * Transform::scale({float(xmag), float(xmag), -1});
      scene_.film.width = width;
      scene_.film.height = std::clamp(int(std::lround(width * ymag / xmag)), 1, kMaxResolution);
      cam.near_clip = float(c.orthographic.znear);
    } else if (c.type == "perspective") {
      if (!(c.perspective.yfov > 0) || c.perspective.yfov >= std::numbers::pi)
        fail(cpointer + "/perspective/yfov", "yfov must be in (0, pi), got {}", c.perspective.yfov);
      cam.world_from_camera = T * flip;
      cam.fov_degrees = float(c.perspective.yfov * 180 / std::numbers::pi);
      cam.fov_axis = FovAxis::Y;
      const double aspect = c.perspective.aspectRatio > 0 ? c.perspective.aspectRatio : 4.0 / 3.0;
      scene_.film.width = width;
      scene_.film.height = std::clamp(int(std::lround(width / aspect)), 1, kMaxResolution);
      cam.near_clip = float(c.perspective.znear);
    } else {
      fail(cpointer + "/type", "unknown camera type \"{}\"", c.type);
    }
    return;
  }
  // No camera: frame the bounding box from +z (glTF's front), looking down -z.
  Bounds3 b = bounds_;
  if (b.empty()) b.extend(Point3(0.0f));
  cam = camera_framing(b.lo, b.hi, 40, 1.05f);
  scene_.film.width = options_.film_width;
  scene_.film.height = std::max(1, options_.film_width * 3 / 4);
}

void GltfReader::add_lights() {
  for (const auto& [index, T, pointer, animation_node] : lights_) {
    if (index < 0 || size_t(index) >= model_.lights.size())
      fail(pointer + "/extensions/KHR_lights_punctual/light", "light {} does not exist", index);
    const tg::Light& l = model_.lights[size_t(index)];
    const std::string lpointer = fmt::format("/extensions/KHR_lights_punctual/lights/{}", index);
    const RGB color = rgb_of(l.color, RGB(1.0f)) * float(l.intensity);
    if (l.range > 0)
      warn(lpointer + "/range", "range is ignored: candela's lights fall off with the inverse square everywhere");
    const Point3 position = T.point(Point3(0.0f));
    Vec3 direction = T.vector({0, 0, -1});
    direction = length(direction) > 0 ? normalize(direction) : Vec3(0, 0, -1);
    if (l.type == "point") {
      scene_.lights.push_back(PointLight{position, color});
      scene_.places.lights.push_back(at(pointer));
    } else if (l.type == "spot") {
      SpotLight s;
      s.position = position;
      s.direction = direction;
      s.intensity = color;
      const double outer = std::clamp(l.spot.outerConeAngle, 1e-4, std::numbers::pi / 2);
      const double inner = std::clamp(l.spot.innerConeAngle, 0.0, outer);
      s.cone_angle = float(outer * 180 / std::numbers::pi);
      s.cone_delta = float((outer - inner) * 180 / std::numbers::pi);
      scene_.lights.push_back(s);
      scene_.places.lights.push_back(at(pointer));
    } else if (l.type == "directional") {
      scene_.lights.push_back(DistantLight{direction, color});
      scene_.places.lights.push_back(at(pointer));
    } else {
      fail(lpointer + "/type", "unknown light type \"{}\"", l.type);
    }
  }
  if (lights_.empty()) {
    // Without lights the model would be lit only by its own emission: a uniform white sky
    // (radiance 1) shows it as a viewer would.
    warn("", "the scene has no KHR_lights_punctual lights; a uniform white sky (radiance 1) lights it");
    scene_.lights.push_back(SkyLight{});
    scene_.places.lights.push_back(SourceLocation{});
  }
}

}  // namespace candela::gltf
