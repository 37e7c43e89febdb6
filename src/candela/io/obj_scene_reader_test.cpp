#include "candela/io/obj_scene_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/json_reader_helpers.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

const fs::path kCornell = fs::path(CANDELA_SHARED_DIR) / "meshes/cornell-box";

const ShapeDesc& shape_named(const SceneDesc& scene, const std::string& name) {
  for (const ShapeDesc& s : scene.shapes)
    if (s.name == name) return s;
  ADD_FAILURE() << "no shape " << name;
  return scene.shapes.front();
}

TEST(ObjScene, APlyMeshIsASceneFramedAndLitByASky) {
  SceneDesc scene = read_scene_file(fs::path(CANDELA_SHARED_DIR) / "meshes/ply-tests/cube.ply");
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_EQ(std::get<MeshShape>(scene.shapes[0].geometry).mesh.indices.size(), 36u);  // 6 quads, triangulated
  EXPECT_EQ(scene.shapes[0].material, -1);  // the default grey diffuse
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SkyLight>(scene.lights[0]));
  // The camera looks at the cube's centre from +z.
  const Matrix4& m = scene.camera.world_from_camera.matrix();
  EXPECT_GT(m.m[2][3], 1.0);
  EXPECT_NEAR(m.m[2][2], -1.0, 1e-6);  // camera +z (forward) is world -z
  EXPECT_NE(testing::json_reader::scene_file_error_of(fs::path(CANDELA_SHARED_DIR) / "meshes/ply-tests/points.ply").find("points.ply"),
            std::string::npos);
}

TEST(ObjScene, McGuiresCornellBoxGetsItsMaterialsLightAndAFramingCamera) {
  SceneDesc scene = read_scene_file(kCornell / "CornellBox-Original.obj");
  // One mesh per material used: 7, as the file gives the short box's faces before its
  // "usemtl shortBox" (so they are leftWall's, red, in any OBJ reader) and none after it.
  ASSERT_EQ(scene.shapes.size(), 7u);
  const ShapeDesc& light = shape_named(scene, "light");
  ASSERT_TRUE(light.emission);
  EXPECT_EQ(light.emission->radiance, RGB(17, 12, 4));
  const auto& left = std::get<DiffuseMaterial>(scene.materials[size_t(shape_named(scene, "leftWall").material)]);
  EXPECT_EQ(left.reflectance.value, RGB(1.0f, 0.065f, 0.05f));
  EXPECT_FALSE(shape_named(scene, "floor").emission);
  EXPECT_TRUE(scene.lights.empty()) << "a scene with emitters gets no sky";
  // Each shape and material records the OBJ file and its material's name, for messages.
  const SourceLocation& where = shape_named(scene, "light").where;
  EXPECT_EQ(where.file, (kCornell / "CornellBox-Original.obj").string());
  EXPECT_EQ(where.key_path, "usemtl light");
  ASSERT_EQ(scene.places.materials.size(), scene.materials.size());
  EXPECT_EQ(scene.places.materials[size_t(shape_named(scene, "leftWall").material)].key_path, "newmtl leftWall");
  // The camera looks at the box's centre (0, ~1, 0) along -z from in front of its open side.
  const Point3 eye = scene.camera.world_from_camera.point(Point3(0.0f));
  const Vec3 forward = normalize(scene.camera.world_from_camera.vector(Vec3(0, 0, 1)));
  EXPECT_NEAR(eye.x, 0, 0.05);
  EXPECT_GT(eye.z, 2);
  EXPECT_NEAR(forward.z, -1, 1e-4);
}

TEST(ObjScene, VisibleLightPixelsHoldKeAndTheBoxFillsTheFrame) {
  SceneDesc scene = read_scene_file(kCornell / "CornellBox-Original.obj");
  // The light is seen nearly edge-on from below: fine pixels, so that some see nothing else.
  scene.film.width = scene.film.height = 160;
  scene.settings.spp = 4;
  scene.settings.max_depth = 1;
  Image image = testing::render_description(scene).mean_image();
  // The brightest pixel sees the light (radiance Ke, reflected light adds a little: Kd 0.78 of the
  // irradiance under the light is far below 17).
  RGB brightest(0.0f);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.at(x, y).r > brightest.r) brightest = image.at(x, y);
  EXPECT_NEAR(brightest.r, 17, 0.3);
  EXPECT_NEAR(brightest.g, 12, 0.2);
  EXPECT_NEAR(brightest.b, 4, 0.1);
  // The framing camera sees the box, lit (its bounding sphere fits the image: a third of it).
  int lit = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) lit += image.at(x, y).average() > 1e-3f;
  EXPECT_GT(lit, image.width * image.height / 4);
  EXPECT_GT(image.at(80, 80).average(), 1e-3f);
}

TEST(ObjScene, GlossyMirrorAndWaterMaterials) {
  SceneDesc glossy = read_scene_file(kCornell / "CornellBox-Glossy.obj");
  const auto& sphere = std::get<PhongMaterial>(glossy.materials[size_t(shape_named(glossy, "sphere").material)]);
  EXPECT_LE(sphere.d + sphere.s, 1.0f + 1e-6f) << "Kd + Ks > 1 is scaled down";
  EXPECT_NEAR(sphere.d / sphere.s, 0.663f / 0.7f, 1e-4);
  EXPECT_EQ(sphere.exponent, 32);

  SceneDesc mirror = read_scene_file(kCornell / "CornellBox-Mirror.obj");
  const auto& tall = std::get<MirrorMaterial>(mirror.materials[size_t(shape_named(mirror, "tallBox").material)]);
  EXPECT_EQ(tall.reflectance.value, RGB(0.95f));

  SceneDesc water = read_scene_file(kCornell / "CornellBox-Water.obj");
  const auto& w = std::get<DielectricMaterial>(water.materials[size_t(shape_named(water, "water").material)]);
  EXPECT_FLOAT_EQ(w.ior, 1.33f);
}

TEST(ObjScene, MissingMaterialLibraryIsAWarningAndALitModel) {
  const fs::path dir = fs::temp_directory_path() / "candela_obj_scene_test";
  fs::create_directories(dir);
  const fs::path file = dir / "quad.obj";
  std::ofstream(file) << "mtllib nowhere.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  ::testing::internal::CaptureStderr();
  SceneDesc scene = read_scene_file(file);
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("nowhere.mtl"), std::string::npos) << err;
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_EQ(scene.shapes[0].material, -1);  // the default diffuse
  ASSERT_EQ(scene.lights.size(), 1u);       // no emitters: a sky lights it
  EXPECT_TRUE(std::holds_alternative<SkyLight>(scene.lights[0]));
}

TEST(ObjScene, MalformedObjNamesTheFile) {
  const fs::path dir = fs::temp_directory_path() / "candela_obj_scene_test";
  fs::create_directories(dir);
  const fs::path file = dir / "broken.obj";
  std::ofstream(file) << "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n";
  try {
    read_scene_file(file);
    FAIL() << "read a broken OBJ";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.obj"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace candela
