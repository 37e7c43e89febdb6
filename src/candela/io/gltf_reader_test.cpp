// Tests of the glTF 2.0 reader on Khronos' sample models (../shared/meshes/gltf-sample-assets): every
// model loads (Draco is refused by name), transforms and instancing place meshes where the file says,
// strips and fans and interleaved or unindexed buffers give the same geometry as their plain
// versions, materials, texture transforms, lights, cameras and emission strengths are mapped as
// docs/gltf-format.md says, a few renders show the model where expected, and malformed files fail
// with a SceneError naming the file.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/gltf_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/description/scene_desc.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kAssets = fs::path(CANDELA_SHARED_DIR) / "meshes/gltf-sample-assets";

fs::path asset(const std::string& model, const std::string& variant = "glTF") {
  return kAssets / model / variant / (model + (variant == "glTF-Binary" ? ".glb" : ".gltf"));
}

Json read_json(const fs::path& file) {
  std::ifstream in(file);
  return Json::parse(in);
}

SceneDesc load_gltf(const fs::path& file, Warnings* warnings_out = nullptr) {
  Warnings warnings;
  SceneDesc scene = read_gltf_scene(file, warnings);
  if (warnings_out) *warnings_out = warnings;
  return scene;
}

const TriangleMesh& mesh_of(const ShapeDesc& shape) { return std::get<MeshShape>(shape.geometry).mesh; }

// Every triangle of the scene's shapes in world space (corners in file order), and its normal by
// candela's convention: the object-space winding normal transformed as a normal.
struct WorldTriangle {
  Point3 p[3];
  Vec3 normal;
};
std::vector<WorldTriangle> world_triangles(const SceneDesc& scene) {
  std::vector<WorldTriangle> out;
  for (const ShapeDesc& shape : scene.shapes) {
    const TriangleMesh& m = mesh_of(shape);
    for (size_t i = 0; i < m.indices.size(); i += 3) {
      WorldTriangle t;
      const Point3& a = m.positions[m.indices[i]];
      const Point3& b = m.positions[m.indices[i + 1]];
      const Point3& c = m.positions[m.indices[i + 2]];
      t.p[0] = shape.to_world.point(a);
      t.p[1] = shape.to_world.point(b);
      t.p[2] = shape.to_world.point(c);
      t.normal = normalize(shape.to_world.normal(cross(b - a, c - a)));
      out.push_back(t);
    }
  }
  return out;
}

double total_area(const std::vector<WorldTriangle>& triangles) {
  double a = 0;
  for (const WorldTriangle& t : triangles) a += 0.5 * length(cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
  return a;
}

void expect_same_geometry(const SceneDesc& a, const SceneDesc& b) {
  std::vector<WorldTriangle> ta = world_triangles(a), tb = world_triangles(b);
  ASSERT_EQ(ta.size(), tb.size());
  ASSERT_FALSE(ta.empty());
  for (size_t i = 0; i < ta.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(ta[i].p[k][c], tb[i].p[k][c], 1e-6f) << "triangle " << i;
    EXPECT_GT(dot(ta[i].normal, tb[i].normal), 0.999f);
  }
  ASSERT_EQ(a.shapes.size(), b.shapes.size());
  for (size_t s = 0; s < a.shapes.size(); ++s) {
    const TriangleMesh &ma = mesh_of(a.shapes[s]), &mb = mesh_of(b.shapes[s]);
    ASSERT_EQ(ma.normals.size(), mb.normals.size());
    for (size_t i = 0; i < ma.indices.size(); ++i) {
      if (ma.normals.empty()) break;
      Vec3 na = ma.normals[ma.indices[i]], nb = mb.normals[mb.indices[i]];
      EXPECT_NEAR(dot(na, nb), 1.0f, 1e-5f);
    }
  }
}

// A file in this test process's scratch directory, removed at the end of the test.
class Scratch {
 public:
  Scratch() : dir_(fs::temp_directory_path() / fmt::format("candela_gltf_test_{}_{}", getpid(), counter_++)) {
    fs::create_directories(dir_);
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  fs::path write(const std::string& name, const std::string& bytes) {
    fs::path p = dir_ / name;
    std::ofstream out(p, std::ios::binary);
    out << bytes;
    return p;
  }
  const fs::path& dir() const { return dir_; }

 private:
  static inline int counter_ = 0;
  fs::path dir_;
};

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The message of the SceneError that read() throws; a failure ("<what> loaded") and "" where it throws none.
std::string scene_error_of(const std::function<void()>& read, const std::string& what) {
  try {
    read();
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << what << " loaded";
  return "";
}

// ---------------------------------------------------------------- every sample model

std::vector<std::string> sample_files() {
  std::vector<std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(kAssets, ec); it != fs::recursive_directory_iterator(); ++it) {
    std::string ext = it->path().extension().string();
    if (ext == ".gltf" || ext == ".glb") files.push_back(fs::relative(it->path(), kAssets).string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

class GltfSampleModel : public ::testing::TestWithParam<std::string> {};

TEST_P(GltfSampleModel, Loads) {
  const fs::path file = kAssets / GetParam();
  if (GetParam().find("Draco") != std::string::npos) {
    std::string message = scene_error_of([&] { load_gltf(file); }, "a Draco-compressed file");
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("Draco"), std::string::npos) << message;
    EXPECT_NE(message.find("mesh \""), std::string::npos) << message;
    return;
  }
  SceneDesc scene = load_gltf(file);
  EXPECT_FALSE(scene.shapes.empty() && scene.instances.empty());
  EXPECT_FALSE(scene.lights.empty());
  EXPECT_GT(scene.film.width, 0);
  EXPECT_GT(scene.film.height, 0);
  // What the renderer will check: every texture file exists, references are in range.
  for (const TextureDesc& t : scene.textures) {
    if (const auto* image = std::get_if<ImageTexture>(&t)) {
      EXPECT_TRUE(fs::exists(image->filename)) << image->filename;
    }
  }
  for (const ShapeDesc& shape : scene.shapes) {
    EXPECT_LT(shape.material, int(scene.materials.size()));
    const TriangleMesh& m = mesh_of(shape);
    for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
    EXPECT_TRUE(m.uvs.empty() || m.uvs.size() == m.positions.size());
    EXPECT_TRUE(m.normals.empty() || m.normals.size() == m.positions.size());
  }
}

INSTANTIATE_TEST_SUITE_P(Khronos, GltfSampleModel, ::testing::ValuesIn(sample_files()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum((unsigned char)c)) c = '_';
                           return name;
                         });

TEST(GltfSampleModels, AllTwentySevenArePresent) { EXPECT_GE(sample_files().size(), 27u); }

// ---------------------------------------------------------------- geometry and transforms

TEST(GltfGeometry, BoxInterleavedIsBox) {
  expect_same_geometry(load_gltf(asset("Box")), load_gltf(asset("BoxInterleaved")));
}

TEST(GltfGeometry, EmbeddedAndBinaryAreTheSame) {
  expect_same_geometry(load_gltf(asset("Box")), load_gltf(asset("Box", "glTF-Embedded")));
  expect_same_geometry(load_gltf(asset("Box")), load_gltf(asset("Box", "glTF-Binary")));
}

TEST(GltfGeometry, TriangleWithoutIndicesIsTriangle) {
  expect_same_geometry(load_gltf(asset("Triangle")), load_gltf(asset("TriangleWithoutIndices")));
}

TEST(GltfGeometry, StripsAndFansBecomeFrontFacingTriangles) {
  Warnings warnings;
  SceneDesc scene = load_gltf(asset("MeshPrimitiveModes"), &warnings);
  // Points and the three kinds of lines are skipped with a warning each.
  EXPECT_EQ(std::count_if(warnings.begin(), warnings.end(),
                          [](const std::string& w) { return w.find("are not surfaces") != std::string::npos; }),
            4);
  ASSERT_EQ(scene.shapes.size(), 3u);  // triangles, strip, fan
  double reference_area = -1;
  for (const ShapeDesc& shape : scene.shapes) {
    SceneDesc one;
    one.shapes = {shape};
    std::vector<WorldTriangle> triangles = world_triangles(one);
    ASSERT_GE(triangles.size(), 2u) << shape.name;
    // The modes' meshes all face the viewer (+z), so every converted triangle must too.
    for (const WorldTriangle& t : triangles) EXPECT_GT(t.normal.z, 0.99f) << shape.name;
    double area = total_area(triangles);
    if (reference_area < 0) reference_area = area;
    EXPECT_NEAR(area, reference_area, 1e-5) << shape.name;
  }
}

TEST(GltfTransforms, OrientationTestNodesAreWhereTheFileSays) {
  SceneDesc scene = load_gltf(asset("OrientationTest"));
  Json j = read_json(asset("OrientationTest"));
  int checked = 0;
  for (const Json& node : j["nodes"]) {
    if (!node.contains("translation") || !node.contains("mesh")) continue;
    Point3 expected(node["translation"][0].get<float>(), node["translation"][1].get<float>(),
                    node["translation"][2].get<float>());
    std::string mesh_name = j["meshes"][node["mesh"].get<int>()].value("name", "");
    bool found = false;
    for (const ShapeDesc& shape : scene.shapes)
      if (shape.name.find("\"" + mesh_name + "\"") != std::string::npos) {
        Point3 origin = shape.to_world.point(Point3(0.0f));
        EXPECT_NEAR(distance(origin, expected), 0, 1e-5f) << mesh_name;
        found = true;
      }
    EXPECT_TRUE(found) << mesh_name;
    ++checked;
  }
  EXPECT_EQ(checked, 3);  // ArrowX1, ArrowY1, ArrowZ1 at 5 along their axes
}

TEST(GltfTransforms, NegativeScaleKeepsFrontFacesAndNormalsTogether) {
  SceneDesc scene = load_gltf(asset("NegativeScaleTest"));
  int mirrored = 0;
  for (const ShapeDesc& shape : scene.shapes) {
    if (shape.to_world.swaps_handedness()) ++mirrored;
    EXPECT_FALSE(shape.reverse_orientation);
    const TriangleMesh& m = mesh_of(shape);
    if (m.normals.empty()) continue;
    // glTF's front face under a mirroring transform is the one its (transformed) normals point to;
    // candela's geometric normal is the winding normal transformed as a normal: they must agree.
    int agree = 0, total = 0;
    for (size_t i = 0; i < m.indices.size(); i += 3) {
      const Point3 &a = m.positions[m.indices[i]], &b = m.positions[m.indices[i + 1]], &c = m.positions[m.indices[i + 2]];
      Vec3 ng = shape.to_world.normal(cross(b - a, c - a));
      Vec3 ns = shape.to_world.normal(m.normals[m.indices[i]] + m.normals[m.indices[i + 1]] + m.normals[m.indices[i + 2]]);
      agree += dot(ng, ns) > 0;
      ++total;
    }
    EXPECT_EQ(agree, total) << shape.name;
  }
  EXPECT_GT(mirrored, 0);
}

TEST(GltfTransforms, SimpleInstancingMakesOneObjectAndItsInstances) {
  SceneDesc scene = load_gltf(asset("SimpleInstancing"));
  ASSERT_EQ(scene.objects.size(), 1u);
  ASSERT_EQ(scene.instances.size(), 125u);  // EXT_mesh_gpu_instancing's 125 TRS triples
  EXPECT_TRUE(scene.shapes.empty());
  Bounds3 origins;
  for (const InstanceDesc& inst : scene.instances) origins.extend(inst.to_world.point(Point3(0.0f)));
  // TRANSLATION spans [0, 10]^3 (the accessor's min and max).
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(origins.lo[c], 0, 1e-5f);
    EXPECT_NEAR(origins.hi[c], 10, 1e-5f);
  }
}

// Shapes, objects, instances, textures, materials and lights name their place in the file: the
// file and a JSON pointer (SceneDesc::places for the last three, parallel to their vectors).
TEST(GltfPlaces, DescriptionsNameTheirElements) {
  Scratch scratch;
  Warnings warnings;
  SceneDesc cube = read_gltf_scene(asset("Cube"), warnings, GltfOptions{.cache_dir = scratch.dir() / "cache"});
  EXPECT_EQ(cube.shapes.at(0).where.file, asset("Cube").string());
  EXPECT_EQ(cube.shapes[0].where.key_path, "/meshes/0/primitives/0");
  ASSERT_EQ(cube.places.materials.size(), cube.materials.size());
  EXPECT_EQ(cube.places.materials[size_t(cube.shapes[0].material)].key_path, "/materials/0");
  ASSERT_EQ(cube.places.textures.size(), cube.textures.size());
  ASSERT_FALSE(cube.textures.empty());
  for (const SourceLocation& t : cube.places.textures) EXPECT_TRUE(t.key_path.starts_with("/materials/0/")) << t.key_path;
  ASSERT_EQ(cube.places.lights.size(), cube.lights.size());  // the sky added for a file without lights
  EXPECT_TRUE(cube.places.lights[0].file.empty());

  SceneDesc instancing = load_gltf(asset("SimpleInstancing"));
  ASSERT_EQ(instancing.objects.size(), 1u);
  EXPECT_TRUE(instancing.objects[0].where.key_path.starts_with("/meshes/")) << instancing.objects[0].where.key_path;
  ASSERT_FALSE(instancing.instances.empty());
  EXPECT_TRUE(instancing.instances[0].where.key_path.ends_with("/extensions/EXT_mesh_gpu_instancing[0]"))
      << instancing.instances[0].where.key_path;

  SceneDesc lamp = load_gltf(asset("LightsPunctualLamp"));
  ASSERT_EQ(lamp.places.lights.size(), lamp.lights.size());
  for (const SourceLocation& l : lamp.places.lights) EXPECT_TRUE(l.key_path.starts_with("/nodes/")) << l.key_path;
}

// ---------------------------------------------------------------- materials

TEST(GltfMaterials, MetalRoughSpheresHaveTheirFactors) {
  SceneDesc scene = load_gltf(asset("MetalRoughSpheresNoTextures"));
  Json j = read_json(asset("MetalRoughSpheresNoTextures"));
  size_t triangles = 0;
  for (const ShapeDesc& s : scene.shapes) triangles += mesh_of(s).triangle_count();
  EXPECT_GT(triangles, 1000000u);
  // Every sphere's material: base colour, metallic and roughness as the file's factors (glTF's
  // perceptual roughness is Mitsuba principled's roughness: both square it into alpha).
  // Shapes are made in node order, one per sphere node: compare each with its node's material.
  std::vector<const Json*> node_materials;
  std::function<void(int)> walk = [&](int n) {
    const Json& node = j["nodes"][n];
    if (node.contains("mesh"))
      for (const Json& prim : j["meshes"][node["mesh"].get<int>()]["primitives"])
        node_materials.push_back(prim.contains("material") ? &j["materials"][prim["material"].get<int>()] : nullptr);
    if (node.contains("children"))
      for (const Json& c : node["children"]) walk(c.get<int>());
  };
  for (const Json& root : j["scenes"][0]["nodes"]) walk(root.get<int>());
  ASSERT_EQ(node_materials.size(), scene.shapes.size());
  int with_material = 0;
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    if (!node_materials[i]) continue;  // the labels use the default material
    ++with_material;
    const Json& pbr = (*node_materials[i])["pbrMetallicRoughness"];
    const auto& p = std::get<PrincipledMaterial>(scene.materials[size_t(scene.shapes[i].material)]);
    EXPECT_TRUE(p.metallic.is_constant() && p.roughness.is_constant());
    EXPECT_FLOAT_EQ(p.metallic.value, pbr.value("metallicFactor", 1.0f));
    EXPECT_FLOAT_EQ(p.roughness.value, pbr.value("roughnessFactor", 1.0f));
    EXPECT_FLOAT_EQ(p.base_color.value.r, pbr["baseColorFactor"][0].get<float>());
    EXPECT_FLOAT_EQ(p.specular.value, 0.5f);
  }
  EXPECT_GT(with_material, 90);
}

TEST(GltfMaterials, TexturesMapChannelsAndColourSpaces) {
  // Cube: base colour (sRGB) and a metallicRoughness texture whose B and G become two derived
  // single-channel images (linear), with the factors as their scale.
  Scratch scratch;
  GltfOptions options;
  options.cache_dir = scratch.dir() / "cache";
  Warnings warnings;
  SceneDesc scene = read_gltf_scene(asset("Cube"), warnings, options);
  ASSERT_EQ(scene.shapes.size(), 1u);
  const auto& p = std::get<PrincipledMaterial>(scene.materials[size_t(scene.shapes[0].material)]);
  ASSERT_GE(p.base_color.texture, 0);
  const auto& base = std::get<ImageTexture>(scene.textures[size_t(p.base_color.texture)]);
  EXPECT_EQ(base.encoding, ColorEncoding::SRGB);
  EXPECT_EQ(fs::path(base.filename).filename(), "Cube_BaseColor.png");
  ASSERT_GE(p.metallic.texture, 0);
  ASSERT_GE(p.roughness.texture, 0);
  const auto& metal = std::get<ImageTexture>(scene.textures[size_t(p.metallic.texture)]);
  const auto& rough = std::get<ImageTexture>(scene.textures[size_t(p.roughness.texture)]);
  EXPECT_EQ(metal.encoding, ColorEncoding::Linear);
  EXPECT_NE(metal.filename, rough.filename);
  EXPECT_EQ(fs::path(metal.filename).parent_path(), options.cache_dir);
  // uvs are flipped to candela's bottom-row origin: t = 1 - v.
  Json j = read_json(asset("Cube"));
  EXPECT_FALSE(mesh_of(scene.shapes[0]).uvs.empty());
}

TEST(GltfMaterials, TextureTransformOffsetsRotatesAndScales) {
  Warnings warnings;
  SceneDesc scene = load_gltf(asset("TextureTransformTest"), &warnings);
  Json j = read_json(asset("TextureTransformTest"));
  // Material name -> the glTF transform (offset, rotation, scale), as the file states it.
  struct Transform {
    double ox, oy, rotation, sx, sy;
  };
  std::map<std::string, Transform> want = {{"Offset U", {0.5, 0, 0, 1, 1}},   {"Offset V", {0, 0.5, 0, 1, 1}},
                                           {"Offset UV", {0.5, 0.5, 0, 1, 1}}, {"Rotation", {0, 0, 0.39269908169872414, 1, 1}},
                                           {"Scale", {0, 0, 0, 1.5, 1.5}},     {"All", {-0.2, -0.1, 0.3, 1.5, 1.5}}};
  int checked = 0;
  for (const ShapeDesc& shape : scene.shapes) {
    // The shape's material's base colour texture; shapes name their mesh, whose material names the case.
    const MaterialDesc* m = &scene.materials[size_t(shape.material)];
    while (const auto* mask = std::get_if<MaskMaterial>(m)) m = &scene.materials[size_t(mask->material)];
    const auto* p = std::get_if<PrincipledMaterial>(m);
    if (!p || p->base_color.texture < 0) continue;
    const auto& tex = std::get<ImageTexture>(scene.textures[size_t(p->base_color.texture)]);
    for (const Json& mesh : j["meshes"]) {
      if (shape.name.find("\"" + mesh.value("name", "") + "\"") == std::string::npos) continue;
      std::string material = j["materials"][mesh["primitives"][0]["material"].get<int>()].value("name", "");
      auto w = want.find(material);
      if (w == want.end()) continue;
      // The glTF matrix T R S with R = [[cos, sin], [-sin, cos]] (the extension's definition), applied
      // to glTF uvs (v down the image), must equal candela's mapping on t = 1 - v, read back as 1 - t'.
      const Transform& g = w->second;
      const double c = std::cos(g.rotation), sn = std::sin(g.rotation);
      for (Vec2 uv : {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(0.3f, 0.7f)}) {
        const double su = g.sx * uv.x, sv = g.sy * uv.y;
        const double u_gltf = c * su + sn * sv + g.ox, v_gltf = -sn * su + c * sv + g.oy;
        const UVMapping& mp = tex.mapping;
        const float t = 1 - uv.y;
        const float s_out = mp.su * uv.x + mp.s_from_v * t + mp.du, t_out = mp.t_from_u * uv.x + mp.sv * t + mp.dv;
        EXPECT_NEAR(s_out, u_gltf, 1e-5) << material << " at " << uv.x << ", " << uv.y;
        EXPECT_NEAR(1 - t_out, v_gltf, 1e-5) << material << " at " << uv.x << ", " << uv.y;
      }
      EXPECT_EQ(tex.mapping.is_axis_aligned(), g.rotation == 0) << material;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 6);
  EXPECT_EQ(std::count_if(warnings.begin(), warnings.end(),
                          [](const std::string& w) { return w.find("rotation") != std::string::npos; }),
            0);
}

TEST(GltfMaterials, EmissiveStrengthMultipliesTheFactor) {
  SceneDesc scene = load_gltf(asset("EmissiveStrengthTest"));
  Json j = read_json(asset("EmissiveStrengthTest"));
  std::vector<float> strengths;
  for (const ShapeDesc& shape : scene.shapes) {
    if (!shape.emission) continue;
    // Emit1..Emit16: factor (0.1, 0.5, 0.9) x strength.
    float s = shape.emission->radiance.g / 0.5f;
    EXPECT_NEAR(shape.emission->radiance.r, 0.1f * s, 1e-5f);
    EXPECT_NEAR(shape.emission->radiance.b, 0.9f * s, 1e-5f);
    strengths.push_back(std::round(s));
  }
  std::sort(strengths.begin(), strengths.end());
  EXPECT_EQ(strengths, (std::vector<float>{1, 2, 4, 8, 16}));
}

TEST(GltfMaterials, AlphaBlendModesBecomeMasks) {
  SceneDesc scene = load_gltf(asset("AlphaBlendModeTest"));
  int masks = 0, textured = 0;
  for (const MaterialDesc& m : scene.materials)
    if (const auto* mask = std::get_if<MaskMaterial>(&m)) {
      ++masks;
      textured += mask->opacity.texture >= 0;
    }
  EXPECT_GE(masks, 4);
  EXPECT_GE(textured, 3);
}

// ---------------------------------------------------------------- lights and cameras

TEST(GltfLights, PunctualLampPointLights) {
  SceneDesc scene = load_gltf(asset("LightsPunctualLamp"));
  Json j = read_json(asset("LightsPunctualLamp"));
  const Json& lights = j["extensions"]["KHR_lights_punctual"]["lights"];
  std::vector<PointLight> points;
  for (const LightDesc& l : scene.lights) {
    EXPECT_FALSE(std::holds_alternative<SkyLight>(l));  // lights present: no sky added
    if (const auto* p = std::get_if<PointLight>(&l)) points.push_back(*p);
  }
  ASSERT_EQ(points.size(), 5u);
  size_t i = 0;
  for (const Json& node : j["nodes"]) {
    if (!node.contains("extensions")) continue;
    const Json& light = lights[node["extensions"]["KHR_lights_punctual"]["light"].get<int>()];
    const Json& m = node["matrix"];  // column-major: the translation is elements 12..14
    Point3 position(m[12].get<float>(), m[13].get<float>(), m[14].get<float>());
    EXPECT_NEAR(distance(points[i].position, position), 0, 1e-5f);
    float intensity = light["intensity"].get<float>();
    RGB color = light.contains("color") ? RGB(light["color"][0].get<float>(), light["color"][1].get<float>(),
                                              light["color"][2].get<float>())
                                        : RGB(1.0f);
    EXPECT_NEAR(points[i].intensity.r, color.r * intensity, 1e-4f);
    EXPECT_NEAR(points[i].intensity.b, color.b * intensity, 1e-4f);
    ++i;
  }
}

TEST(GltfLights, SpotAndDirectional) {
  Scratch scratch;
  // A triangle lit by a spot light looking down -y and a directional light along -z.
  std::string gltf = R"({
    "asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "spot", "intensity": 20, "color": [1, 0.5, 0.25], "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
      {"type": "directional", "intensity": 3, "range": 5}]}},
    "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
    "nodes": [
      {"translation": [0, 4, 0], "rotation": [-0.7071068, 0, 0, 0.7071068], "extensions": {"KHR_lights_punctual": {"light": 0}}},
      {"extensions": {"KHR_lights_punctual": {"light": 1}}},
      {"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]
  })";
  Warnings warnings;
  SceneDesc scene = read_gltf_scene(scratch.write("lights.gltf", gltf), warnings);
  ASSERT_EQ(scene.lights.size(), 2u);
  const auto& spot = std::get<SpotLight>(scene.lights[0]);
  EXPECT_NEAR(distance(spot.position, Point3(0, 4, 0)), 0, 1e-5f);
  EXPECT_NEAR(spot.direction.y, -1, 1e-5f);  // -z rotated by -90 degrees about x
  EXPECT_NEAR(spot.cone_angle, 0.5f * 180 / std::numbers::pi_v<float>, 1e-3f);
  EXPECT_NEAR(spot.cone_delta, 0.3f * 180 / std::numbers::pi_v<float>, 1e-3f);
  EXPECT_NEAR(spot.intensity.g, 10, 1e-4f);
  const auto& sun = std::get<DistantLight>(scene.lights[1]);
  EXPECT_NEAR(sun.direction.z, -1, 1e-6f);
  EXPECT_NEAR(sun.radiance.r, 3, 1e-6f);
  EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(),
                          [](const std::string& w) { return w.find("range is ignored") != std::string::npos; }));
}

TEST(GltfCameras, PerspectiveCameraFromTheFirstCameraNode) {
  SceneDesc scene = load_gltf(asset("Cameras"));
  const CameraDesc& c = scene.camera;
  EXPECT_EQ(c.projection, Projection::Perspective);
  EXPECT_EQ(c.fov_axis, FovAxis::Y);
  EXPECT_NEAR(c.fov_degrees, 0.7f * 180 / std::numbers::pi_v<float>, 1e-4f);
  EXPECT_EQ(scene.film.width, scene.film.height);  // aspectRatio 1
  EXPECT_NEAR(distance(c.world_from_camera.point(Point3(0.0f)), Point3(0.5f, 0.5f, 3)), 0, 1e-6f);
  Vec3 forward = normalize(c.world_from_camera.vector({0, 0, 1}));
  EXPECT_NEAR(forward.z, -1, 1e-6f);  // glTF cameras look down their -z
  Vec3 up = c.world_from_camera.vector({0, 1, 0});
  EXPECT_NEAR(up.y, 1, 1e-6f);
  Vec3 right = c.world_from_camera.vector({1, 0, 0});
  EXPECT_NEAR(right.x, 1, 1e-6f);
}

TEST(GltfCameras, OrthographicCameraScalesByMagnification) {
  Scratch scratch;
  Json j = read_json(asset("Cameras"));
  j["cameras"][1]["orthographic"]["xmag"] = 2.0;
  j["cameras"][1]["orthographic"]["ymag"] = 1.0;
  j["scenes"][0]["nodes"] = Json::array({0, 2});  // the orthographic camera's node only
  fs::copy_file(kAssets / "Cameras/glTF/simpleSquare.bin", scratch.dir() / "simpleSquare.bin");
  SceneDesc scene = load_gltf(scratch.write("ortho.gltf", j.dump()));
  const CameraDesc& c = scene.camera;
  EXPECT_EQ(c.projection, Projection::Orthographic);
  EXPECT_EQ(scene.film.width, 2 * scene.film.height);  // xmag / ymag
  // Camera x in [-1, 1] spans [-xmag, xmag] in the world, y in [-1/aspect, 1/aspect] spans [-ymag, ymag].
  EXPECT_NEAR(length(c.world_from_camera.vector({1, 0, 0})), 2, 1e-6f);
  EXPECT_NEAR(c.world_from_camera.vector({0, 0.5f, 0}).y, 1, 1e-6f);
  EXPECT_LT(c.world_from_camera.vector({0, 0, 1}).z, 0);
}

TEST(GltfCameras, NoCameraFramesTheModelUnderASky) {
  SceneDesc scene = load_gltf(asset("Box"));
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SkyLight>(scene.lights[0]));
  const CameraDesc& c = scene.camera;
  Point3 eye = c.world_from_camera.point(Point3(0.0f));
  Vec3 forward = normalize(c.world_from_camera.vector({0, 0, 1}));
  EXPECT_GT(eye.z, 1);  // in front of the unit box, looking at it down -z
  EXPECT_NEAR(forward.z, -1, 1e-5f);
}

// ---------------------------------------------------------------- renders

// A sample model rendered from its own camera on a width x height film: the mean image.
Image render_model(const std::string& model, int width, int height, int spp, int max_depth) {
  SceneDesc scene = load_gltf(asset(model));
  scene.film = {width, height, ""};
  scene.settings.spp = spp;
  scene.settings.max_depth = max_depth;
  return testing::render_description(scene).mean_image();
}

// The box under the white sky (radiance 1): the background is exactly 1, the red box (base colour
// (0.8, 0, 0), dielectric) is redder than it is green, and nothing exceeds what a convex object
// under a unit sky can reflect (1).
TEST(GltfRender, BoxIsVisibleAgainstTheSky) {
  Image img = render_model("Box", 48, 36, 16, 4);
  auto corner = [&](int x, int y) { return x < 4 && y < 4; };
  auto centre = [&](int x, int y) { return std::abs(x - 24) < 4 && std::abs(y - 18) < 4; };
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(testing::region_mean(img, c, corner).mean, 1.0, 1e-3) << c;
  double red = testing::region_mean(img, 0, centre).mean, green = testing::region_mean(img, 1, centre).mean;
  EXPECT_LT(green, 0.5);  // not the sky: the box is in the middle of the frame
  EXPECT_GT(red, green + 0.1);
  EXPECT_LE(testing::region_mean(img, -1).mean, 1.0 + 1e-3);
}

// The emissive cubes, seen directly: the strongest (x16) is far brighter than the sky.
TEST(GltfRender, EmissiveStrengthOrdersBrightness) {
  Image img = render_model("EmissiveStrengthTest", 64, 48, 4, 1);
  double brightest = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) brightest = std::max<double>(brightest, img.at(x, y).b);
  // Emit16's blue radiance is 0.9 x 16 = 14.4; some pixel must see it (the cubes face the camera).
  EXPECT_GT(brightest, 5.0);
}

// ---------------------------------------------------------------- malformed input

TEST(GltfMalformed, TruncatedGlbNamesTheFile) {
  Scratch scratch;
  std::string bytes = read_bytes(asset("Box", "glTF-Binary"));
  fs::path file = scratch.write("truncated.glb", bytes.substr(0, bytes.size() / 2));
  std::string message = scene_error_of([&] { load_gltf(file); }, "a truncated .glb");
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
}

TEST(GltfMalformed, JsonSyntaxErrorNamesTheFile) {
  Scratch scratch;
  fs::path file = scratch.write("syntax.gltf", R"({"asset": {"version": "2.0"}, "nodes": [)");
  std::string message = scene_error_of([&] { read_scene_file(file); }, "malformed JSON");
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
}

TEST(GltfMalformed, IndexOutOfRangeNamesTheAccessor) {
  Scratch scratch;
  Json j = read_json(asset("Triangle"));
  // Three positions; make the index accessor read the positions' bytes as indices (huge values).
  j["accessors"][0]["bufferView"] = 1;
  j["accessors"][0]["componentType"] = 5125;
  j["accessors"][0]["count"] = 3;
  j["accessors"][0]["byteOffset"] = 12;  // from the second position on: 1.0f's bits as an index
  fs::copy_file(kAssets / "Triangle/glTF/simpleTriangle.bin", scratch.dir() / "simpleTriangle.bin");
  fs::path file = scratch.write("bad.gltf", j.dump());
  std::string message = scene_error_of([&] { load_gltf(file); }, "out-of-range indices");
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find("/meshes/0/primitives/0/indices"), std::string::npos) << message;
}

TEST(GltfMalformed, UnsupportedRequiredExtensionIsRefused) {
  Scratch scratch;
  Json j = read_json(asset("Triangle"));
  j["extensionsRequired"] = Json::array({"EXT_made_up"});
  j["extensionsUsed"] = Json::array({"EXT_made_up"});
  fs::copy_file(kAssets / "Triangle/glTF/simpleTriangle.bin", scratch.dir() / "simpleTriangle.bin");
  EXPECT_THROW(load_gltf(scratch.write("ext.gltf", j.dump())), SceneError);
}

}  // namespace
}  // namespace candela
