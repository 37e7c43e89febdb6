#include "candela/io/json_writer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

const fs::path kShared(CANDELA_SHARED_DIR);

// The converted scene renders the same image bit for bit: every number round-trips, and the order
// of shapes and lights is kept.
class ConvertRoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(ConvertRoundTrip, JsonRendersTheSameImage) {
  const fs::path source = kShared / GetParam();
  SceneDesc original = read_scene_file(source);
  const fs::path json = fs::temp_directory_path() /
                        ("candela_convert_" + source.parent_path().filename().string() + "_" + source.stem().string() + ".json");
  write_json_scene(original, json);
  SceneDesc converted = read_scene_file(json);

  EXPECT_EQ(converted.shapes.size(), original.shapes.size());
  EXPECT_EQ(converted.instances.size(), original.instances.size());
  EXPECT_EQ(converted.lights.size(), original.lights.size());
  EXPECT_EQ(converted.film.width, original.film.width);
  EXPECT_EQ(converted.settings.max_depth, original.settings.max_depth);
  EXPECT_EQ(converted.settings.sampler.type, original.settings.sampler.type);

  for (SceneDesc* d : {&original, &converted}) {
    const double aspect = double(d->film.height) / d->film.width;
    d->film.width = 48;
    d->film.height = std::max(1, int(48 * aspect));
    d->settings.spp = 8;
    d->settings.seed = 7;
  }
  Image a = testing::render_description(original).mean_image();
  Image b = testing::render_description(converted).mean_image();
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  size_t identical = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) identical += a.rgb[i] == b.rgb[i];
  double e = testing::rel_mse(b, a);
  std::printf("%s: %zu of %zu pixel-channels identical, relMSE %.3g\n", GetParam(), identical, a.rgb.size(), e);
  EXPECT_EQ(identical, a.rgb.size());
  EXPECT_LT(e, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Scenes, ConvertRoundTrip,
                         ::testing::Values("scenes/cornell-box/cornell-box.pbrt", "scenes/bitterli/veach-mis/scene-v4.pbrt",
                                           "scenes/bitterli/veach-ajar/scene-v4.pbrt",
                                           "scenes/mitsuba-tests/tests/scenes/instancing/test_instancing_path.xml",
                                           "scenes/mitsuba-tests/tests/scenes/bsdf_spheres/test_constant_path.xml",
                                           "scenes/mitsuba-tests/tests/scenes/bsdf_spheres/test_pointlight_path.xml",
                                           "scenes/mitsuba-tests/tests/scenes/spot_light/test_spot_direct.xml",
                                           "scenes/mitsuba-tests/tests/scenes/various_shapes/test_various_shapes_path.xml",
                                           "meshes/gltf-sample-assets/BoxTextured/glTF/BoxTextured.gltf",
                                           "meshes/cornell-box/CornellBox-Glossy.obj"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           fs::path file(info.param);
                           std::string name = file.parent_path().filename().string() + "_" + file.stem().string();
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

TEST(ConvertJson, WrappersAndNewShapesRoundTrip) {
  SceneDesc scene;
  scene.textures.push_back(CheckerboardTexture{});
  scene.materials.push_back(DiffuseMaterial{RGB(0.2f, 0.4f, 0.6f)});
  scene.materials.push_back(OneSidedMaterial{0});
  MaskMaterial mask;
  mask.opacity.texture = 0;
  mask.material = 1;
  scene.materials.push_back(mask);
  scene.materials.push_back(TwoSidedMaterial{2, 0});
  ShapeDesc disk;
  disk.geometry = DiskShape{};
  disk.material = 2;
  scene.shapes.push_back(disk);
  ShapeDesc tube;
  tube.geometry = CylinderShape{{0, 0, 0}, {0, 1, 0}, 0.5f};
  tube.material = 3;
  scene.shapes.push_back(tube);
  scene.camera.projection = Projection::Orthographic;
  scene.camera.near_clip = 0.5f;
  const std::string text = scene_to_json(scene);
  SceneDesc back = read_json_scene(text, "converted.json", fs::temp_directory_path());
  ASSERT_EQ(back.shapes.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<DiskShape>(back.shapes[0].geometry));
  const auto& c = std::get<CylinderShape>(back.shapes[1].geometry);
  EXPECT_EQ(c.p1, Vec3(0, 1, 0));
  EXPECT_EQ(c.radius, 0.5f);
  const auto& m = std::get<MaskMaterial>(back.materials[size_t(back.shapes[0].material)]);
  EXPECT_GE(m.opacity.texture, 0);
  const auto& one_sided = std::get<OneSidedMaterial>(back.materials[size_t(m.material)]);
  EXPECT_EQ(std::get<DiffuseMaterial>(back.materials[size_t(one_sided.material)]).reflectance.value,
            RGB(0.2f, 0.4f, 0.6f));
  EXPECT_EQ(back.camera.projection, Projection::Orthographic);
  EXPECT_EQ(back.camera.near_clip, 0.5f);
  const auto& sides = std::get<TwoSidedMaterial>(back.materials[size_t(back.shapes[1].material)]);
  EXPECT_TRUE(std::holds_alternative<MaskMaterial>(back.materials[size_t(sides.front)]));
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(back.materials[size_t(sides.back)]));
}

}  // namespace
}  // namespace candela
