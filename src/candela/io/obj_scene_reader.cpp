// OBJ + MTL as a scene. The MTL model is loose (every exporter reads it a little differently), so
// each material becomes the closest candela material by these rules (docs/obj-format.md):
//   Ke > 0                          an area light of radiance Ke on the material below
//   illum 4, 6, 7, or d < 1         glass: a smooth dielectric of index Ni (1.5 when Ni <= 1)
//   illum 3 or 5 with Ks > 0        an ideal mirror of reflectance Ks
//   Ks > 0                          the paper's Phong material: diffuse Kd (x map_Kd), Phong lobe Ks with
//                                   exponent Ns, chosen with probabilities max(Kd) and max(Ks) (scaled
//                                   down together when they sum to more than 1, which would create energy)
//   otherwise                       Lambertian Kd (x map_Kd)
#include "candela/io/obj_scene_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mesh_io.h"
#include "candela/io/warnings.h"

namespace candela {
namespace {

float max_channel(const RGB& c) { return std::max({c.r, c.g, c.b}); }

// Kd as a material input: the map multiplied by Kd when there is one (Kd 1 1 1 leaves it alone).
ColorInput diffuse_input(const ObjMaterial& m, const RGB& kd, SceneDesc& scene) {
  if (m.diffuse_map.empty()) return kd;
  ImageTexture image;
  image.filename = m.diffuse_map;
  scene.textures.push_back(image);
  ColorInput map;
  map.texture = int(scene.textures.size() - 1);
  if (kd == RGB(1.0f)) return map;
  // ScaleTexture's factor is a float: a coloured Kd scales the map by its average (material_of warns).
  scene.textures.push_back(ScaleTexture{map, FloatInput(kd.average())});
  ColorInput scaled;
  scaled.texture = int(scene.textures.size() - 1);
  return scaled;
}

MaterialDesc material_of(const ObjMaterial& m, SceneDesc& scene, Warnings& warnings, const std::string& where) {
  auto warn = [&](const std::string& what) { warnings.warn(where, fmt::format("material \"{}\": {}", m.name, what)); };
  if (!m.diffuse_map.empty() && !(m.diffuse.r == m.diffuse.g && m.diffuse.g == m.diffuse.b))
    warn("a coloured Kd with map_Kd: the map is scaled by Kd's average, Kd's hue is dropped");
  const bool glass = m.illum == 4 || m.illum == 6 || m.illum == 7 || m.dissolve < 1;
  if (glass) {
    DielectricMaterial d;
    d.ior = m.ior > 1 ? m.ior : 1.5f;
    if (!(m.ior > 1)) warn(fmt::format("transparent with Ni {}: rendered as glass of index 1.5", m.ior));
    return d;
  }
  const float s = max_channel(m.specular);
  if ((m.illum == 3 || m.illum == 5) && s > 0) {
    if (max_channel(m.diffuse) > 0.05f) warn("a mirror (illum 3 or 5) with a diffuse Kd: Kd is dropped");
    return MirrorMaterial{RGB(std::min(m.specular.r, 1.0f), std::min(m.specular.g, 1.0f), std::min(m.specular.b, 1.0f))};
  }
  float d = max_channel(m.diffuse);
  if (s <= 0) {
    RGB kd = m.diffuse;
    if (d > 1) {
      warn(fmt::format("Kd above 1 (max {}): scaled to 1", d));
      kd = kd * (1 / d);
    }
    return DiffuseMaterial{diffuse_input(m, kd, scene)};
  }
  float scale = 1;
  if (d + s > 1) {
    scale = 1 / (d + s);
    warn(fmt::format("Kd + Ks = {} reflects more than arrives: both scaled by {:.3f}", d + s, scale));
  }
  PhongMaterial p;
  p.d = d * scale;
  p.s = s * scale;
  p.t = 0;
  p.diffuse = diffuse_input(m, d > 0 ? m.diffuse * (1 / d) : RGB(0.0f), scene);
  p.specular = m.specular * (1 / s);
  p.exponent = std::max(m.shininess, 0.0f);
  return p;
}

// A model brings no camera: one frames its meshes. Without emitters it would be black: a white sky
// lights it (and is what the user sees around it).
void frame_and_light(SceneDesc& scene, bool any_emitter) {
  Point3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const ShapeDesc& shape : scene.shapes)
    for (const Point3& p : std::get<MeshShape>(shape.geometry).mesh.positions) {
      lo = min(lo, p);
      hi = max(hi, p);
    }
  scene.camera = camera_framing(lo, hi);
  if (!any_emitter) scene.lights.push_back(SkyLight{});
}

}  // namespace

SceneDesc read_obj_scene(const std::filesystem::path& file, Warnings& warnings) {
  const SourceLocation where{file.string(), 0, 0, {}};
  ObjModel model = load_obj_model(file, where, warnings);

  SceneDesc scene;
  scene.settings.sampler.type = SamplerType::ZSobol;  // the most efficient measured (docs/performance.md)
  std::vector<int> material_index(model.materials.size(), -1);
  for (size_t i = 0; i < model.materials.size(); ++i) {
    scene.materials.push_back(material_of(model.materials[i], scene, warnings, file.string()));
    // The MTL library that defined it is not kept: the OBJ file that loads it, and its name.
    scene.places.materials.push_back({file.string(), 0, 0, "newmtl " + model.materials[i].name});
    material_index[i] = int(scene.materials.size() - 1);
  }
  bool any_emitter = false;
  for (ObjModel::Part& part : model.parts) {
    ShapeDesc shape;
    shape.material = part.material >= 0 ? material_index[size_t(part.material)] : -1;
    shape.name = part.material >= 0 ? model.materials[size_t(part.material)].name : file.filename().string();
    shape.where = {file.string(), 0, 0, part.material >= 0 ? "usemtl " + shape.name : std::string()};
    if (part.material >= 0) {
      const RGB& ke = model.materials[size_t(part.material)].emission;
      if (max_channel(ke) > 0) {
        shape.emission = AreaEmission{ke, false};
        any_emitter = true;
      }
    }
    shape.geometry = MeshShape{std::move(part.mesh)};
    scene.shapes.push_back(std::move(shape));
  }
  frame_and_light(scene, any_emitter);
  return scene;
}

SceneDesc read_obj_scene(const std::filesystem::path& file) {
  return read_printing_warnings([&](Warnings& warnings) { return read_obj_scene(file, warnings); });
}

SceneDesc read_mesh_scene(const std::filesystem::path& file) {
  SceneDesc scene;
  scene.settings.sampler.type = SamplerType::ZSobol;
  ShapeDesc shape;
  shape.name = file.filename().string();
  shape.where = {file.string(), 0, 0, {}};
  shape.geometry = MeshShape{load_mesh_file(file, shape.where)};
  scene.shapes.push_back(std::move(shape));
  frame_and_light(scene, false);
  return scene;
}

}  // namespace candela
