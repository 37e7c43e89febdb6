#include "candela/io/json_writer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "candela/base/error.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/io/pbrt_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/media/medium.h"
#include "candela/sampling/rng.h"
#include "candela/testing/json_reader_helpers.h"
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
                                           "scenes/pbrt-v4-features/shape_partial_sphere.pbrt",
                                           "scenes/pbrt-v4-features/shape_cylinder.pbrt",
                                           "scenes/bitterli/veach-ajar/scene-v4.pbrt",
                                           "scenes/mitsuba-tests/tests/scenes/instancing/test_instancing_path.xml",
                                           "scenes/mitsuba-tests/tests/scenes/bsdf_spheres/test_constant_path.xml",
                                           "scenes/mitsuba-tests/tests/scenes/bsdf_spheres/test_pointlight_path.xml",
                                           "scenes/mitsuba-tests/tests/scenes/spot_light/test_spot_direct.xml",
                                           "scenes/mitsuba-tests/tests/scenes/various_shapes/test_various_shapes_path.xml",
                                           "meshes/gltf-sample-assets/BoxTextured/glTF/BoxTextured.gltf",
                                           "meshes/cornell-box/CornellBox-Glossy.obj",
                                           // pbrt-v4's layered materials (materials/layered.h)
                                           "scenes/pbrt-v4-features/mat_coateddiffuse.pbrt",
                                           "scenes/pbrt-v4-features/mat_coatedconductor.pbrt",
                                           // a dielectric filled with a subsurface medium
                                           "scenes/pbrt-v4-features/mat_subsurface_named.pbrt",
                                           // pbrt-v4's hair on curves (materials/hair.h)
                                           "scenes/pbrt-v4-features/mat_hair_on_curves.pbrt"),
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

void expect_same_volume(const VolumeDesc& back, const VolumeDesc& original) {
  EXPECT_EQ(back.is_constant(), original.is_constant());
  EXPECT_EQ(back.constant, original.constant);
  if (original.is_constant()) return;
  EXPECT_EQ(back.cloud, original.cloud);
  if (original.cloud) {
    // The file holds the cloud's placement (to_world less the box), so to_world comes back rounded.
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(back.to_world.matrix().m[r][c], original.to_world.matrix().m[r][c], 1e-6f);
    return;
  }
  EXPECT_EQ(back.resolution, original.resolution);
  EXPECT_EQ(back.channels, original.channels);
  EXPECT_EQ(*back.values, *original.values);
  EXPECT_EQ(back.to_world.matrix(), original.to_world.matrix());
  EXPECT_EQ(back.border, original.border);
  EXPECT_EQ(back.filename, original.filename);
}

void expect_same_media(const SceneDesc& back, const SceneDesc& original) {
  ASSERT_EQ(back.media.size(), original.media.size());
  for (size_t i = 0; i < original.media.size(); ++i) {
    const MediumDesc &b = back.media[i], &o = original.media[i];
    EXPECT_EQ(b.sigma_t, o.sigma_t) << i;
    EXPECT_EQ(b.scale, o.scale) << i;
    EXPECT_EQ(b.g, o.g) << i;
    EXPECT_EQ(b.emission, o.emission) << i;
    expect_same_volume(b.density, o.density);
    expect_same_volume(b.albedo, o.albedo);
    expect_same_volume(b.emission_scale, o.emission_scale);
    ASSERT_EQ(b.temperature.has_value(), o.temperature.has_value()) << i;
    if (o.temperature) expect_same_volume(*b.temperature, *o.temperature);
    EXPECT_EQ(b.temperature_scale, o.temperature_scale) << i;
    EXPECT_EQ(b.temperature_offset, o.temperature_offset) << i;
    EXPECT_EQ(b.temperature_cutoff, o.temperature_cutoff) << i;
  }
}

// pbrt-v4's procedural cloud, read from pbrt and written as JSON: the same description back, and the
// same density everywhere.
TEST(ConvertJson, CloudMediumRoundTrip) {
  SceneDesc scene = read_pbrt_string(
      "WorldBegin\nRotate 30 0 1 0\nTranslate 0.5 1 -2\n"
      "MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float density\" 3 \"float wispiness\" 0.7 "
      "\"float frequency\" 6 \"rgb sigma_s\" [ 1 1 1 ] \"rgb sigma_a\" [ 0.1 0.2 0.3 ] \"float g\" 0.4 "
      "\"point3 p0\" [ -0.8 0 -0.8 ] \"point3 p1\" [ 0.8 1.6 0.8 ]\n",
      "cloud.pbrt", fs::temp_directory_path());
  ASSERT_EQ(scene.media.size(), 1u);
  const std::string text = scene_to_json(scene);
  EXPECT_NE(text.find("\"cloud\""), std::string::npos) << text;
  SceneDesc back = read_json_scene(text, "converted.json", fs::temp_directory_path());
  expect_same_media(back, scene);
  EXPECT_EQ(back.media.at(0).density.cloud->box_max, Point3(0.8f, 1.6f, 0.8f));
  const Medium original(scene.media[0]), converted(back.media[0]);
  const Transform& to_world = scene.media[0].density.to_world;
  Rng rng(5, 7);
  for (int i = 0; i < 100; ++i) {
    const Point3 p = to_world.point({1.2f * rng.next_float() - 0.1f, 1.2f * rng.next_float() - 0.1f,
                                     1.2f * rng.next_float() - 0.1f});
    EXPECT_NEAR(converted.density(p), original.density(p), 1e-3f) << i;
  }
}

// Media, with grids inline and from files, and the names shapes, objects and the camera refer to
// them by.
TEST(ConvertJson, MediaRoundTrip) {
  const fs::path albedo_file = fs::temp_directory_path() / "candela_convert_media_albedo.vol";
  VolumeGrid albedo_grid;
  albedo_grid.resolution = {1, 2, 1};
  albedo_grid.channels = 3;
  albedo_grid.values = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  write_volume_grid(albedo_file, albedo_grid);

  SceneDesc scene;
  MediumDesc fog;
  set_sigma_a_sigma_s(fog, RGB(0.1f, 0.2f, 0.3f), RGB(0.7f, 0.3f, 0.1f));
  fog.scale = 2.5f;
  fog.g = 0.3f;
  fog.emission = RGB(1, 0.5f, 0.25f);
  fog.name = "fog";
  scene.media.push_back(fog);
  MediumDesc smoke;
  smoke.sigma_t = RGB(3, 2, 1);
  smoke.density.resolution = {2, 1, 1};
  smoke.density.values = std::make_shared<const std::vector<float>>(std::vector<float>{0.5f, 1.25f});
  smoke.density.to_world = Transform::translate({1, 2, 3}) * Transform::scale({2, 2, 0.5f});
  smoke.density.border = VolumeBorder::Zero;
  smoke.albedo.resolution = albedo_grid.resolution;
  smoke.albedo.channels = 3;
  smoke.albedo.values = std::make_shared<const std::vector<float>>(albedo_grid.values);
  smoke.albedo.filename = albedo_file.string();
  smoke.name = "smoke";
  scene.media.push_back(smoke);
  MediumDesc thin;  // a constant density other than 1, and a name already taken
  thin.density.constant = RGB(0.5f);
  thin.name = "fog";
  scene.media.push_back(thin);
  scene.media.push_back(MediumDesc{});  // no name

  scene.camera.medium = 1;
  ShapeDesc ball;
  ball.geometry = SphereShape{};
  ball.interior_medium = 0;
  ball.exterior_medium = 2;
  scene.shapes.push_back(ball);
  ShapeDesc plain;
  plain.geometry = SphereShape{};
  scene.shapes.push_back(plain);
  ObjectDesc object;
  ShapeDesc drop;
  drop.geometry = SphereShape{};
  drop.interior_medium = 3;
  object.shapes.push_back(drop);
  scene.objects.push_back(object);
  scene.instances.push_back(InstanceDesc{});

  const std::string text = scene_to_json(scene);
  SceneDesc back = read_json_scene(text, "converted.json", fs::temp_directory_path());
  expect_same_media(back, scene);
  ASSERT_EQ(back.media.size(), 4u);
  EXPECT_EQ(back.media[0].name, "fog");
  EXPECT_EQ(back.media[1].name, "smoke");
  EXPECT_EQ(back.media[2].name, "fog 2");
  EXPECT_EQ(back.media[3].name, "medium00003");
  EXPECT_NE(text.find(albedo_file.string()), std::string::npos);  // the file, not its samples
  EXPECT_EQ(back.camera.medium, 1);
  ASSERT_EQ(back.shapes.size(), 2u);
  EXPECT_EQ(back.shapes[0].interior_medium, 0);
  EXPECT_EQ(back.shapes[0].exterior_medium, 2);
  EXPECT_EQ(back.shapes[1].interior_medium, -1);
  EXPECT_EQ(back.shapes[1].exterior_medium, -1);
  EXPECT_EQ(back.objects.at(0).shapes.at(0).interior_medium, 3);
  fs::remove(albedo_file);

  SceneDesc empty = read_json_scene(scene_to_json(SceneDesc{}), "converted.json", fs::temp_directory_path());
  EXPECT_TRUE(empty.media.empty());
  EXPECT_EQ(empty.camera.medium, -1);
}

// pbrt-v4's pixel sensor (exposure, white balance, limit) survives `candela convert`; the default
// sensor writes nothing.
TEST(ConvertJson, FilmSensorRoundTrips) {
  SceneDesc scene;
  EXPECT_EQ(scene_to_json(scene).find("\"sensor\""), std::string::npos);
  scene.film.sensor = FilmDesc::Sensor{.exposure = 2.5f, .white_balance = 5200, .max_component = 10};
  const SceneDesc back = read_json_scene(scene_to_json(scene), "converted.json", fs::temp_directory_path());
  EXPECT_FLOAT_EQ(back.film.sensor.exposure, 2.5f);
  EXPECT_FLOAT_EQ(back.film.sensor.white_balance, 5200);
  EXPECT_FLOAT_EQ(back.film.sensor.max_component, 10);
  using testing::json_reader::expect_error_containing;
  expect_error_containing(R"({"camera": {"sensor": {"white_balance": 500}}})",
                          "at /camera/sensor/white_balance: expected 0 (none) or a colour temperature");
  expect_error_containing(R"({"camera": {"sensor": {"exposure": 0}}})", "at /camera/sensor/exposure");
  expect_error_containing(R"({"camera": {"sensor": {"iso": 400}}})", "at /camera/sensor/iso: unknown key");
}

// Photon mapping's parameters survive `candela convert` (pbrt-v4's sppm included); other integrators'
// scenes write none (their readers would refuse them).
TEST(ConvertJson, SppmSettingsRoundTrip) {
  SceneDesc scene;
  scene.settings.integrator = "sppm";
  scene.settings.sppm = SppmSettings{.photons_per_iteration = 20000, .radius = 0.125f};
  const SceneDesc back = read_json_scene(scene_to_json(scene), "converted.json", fs::temp_directory_path());
  EXPECT_EQ(back.settings.integrator, "sppm");
  EXPECT_EQ(back.settings.sppm, scene.settings.sppm);
  scene.settings.sppm = SppmSettings{};  // one photon per pixel: no key
  EXPECT_EQ(read_json_scene(scene_to_json(scene), "converted.json", fs::temp_directory_path()).settings.sppm,
            SppmSettings{});
  scene.settings.integrator = "path";
  scene.settings.sppm.radius = 0.5f;
  EXPECT_EQ(scene_to_json(scene).find("\"sppm\""), std::string::npos);
  const SceneDesc pbrt = read_pbrt_string(
      "Integrator \"sppm\" \"integer photonsperiteration\" 777 \"float radius\" 0.3\nWorldBegin\n", "sppm.pbrt",
      fs::temp_directory_path());
  const SceneDesc pbrt_back = read_json_scene(scene_to_json(pbrt), "converted.json", fs::temp_directory_path());
  EXPECT_EQ(pbrt_back.settings.integrator, "sppm");
  EXPECT_EQ(pbrt_back.settings.sppm.photons_per_iteration, 777);
  EXPECT_EQ(pbrt_back.settings.sppm.radius, 0.3f);
}

// A camera's screen window and the projections of textures survive `candela convert`.
TEST(ConvertJson, ScreenWindowsCropsSincFiltersAndTextureProjectionsRoundTrip) {
  SceneDesc scene;
  scene.camera.projection = Projection::Orthographic;
  scene.camera.screen_window = std::array<float, 4>{-2, 2, -1.5f, 1.5f};
  UVMapping planar{.du = 0.5f, .projection = TextureProjection::Planar};
  planar.to_world = Transform::translate(Vec3(0, 1, 0));
  planar.planar_s = Vec3(4, 0, 0);
  scene.textures.push_back(CheckerboardTexture{ColorInput(RGB(1.0f)), ColorInput(RGB(0.0f)), planar});
  scene.textures.push_back(ImageTexture{.filename = (fs::path(CANDELA_SOURCE_DIR) / "tests/data/textures/checker.ppm").string(),
                                        .mapping = UVMapping{.projection = TextureProjection::Spherical}});
  const SceneDesc back = read_json_scene(scene_to_json(scene), "converted.json", fs::temp_directory_path());
  EXPECT_EQ(back.camera.screen_window, scene.camera.screen_window);
  EXPECT_FALSE(back.film.crop);
  scene.film.width = 30;
  scene.film.height = 20;
  scene.film.crop = FilmDesc::Crop{5, 7, 64, 48};
  scene.settings.filter = default_filter(FilterType::LanczosSinc);
  scene.settings.filter.sinc_tau = 2;
  const SceneDesc cropped = read_json_scene(scene_to_json(scene), "converted.json", fs::temp_directory_path());
  ASSERT_TRUE(cropped.film.crop);
  EXPECT_EQ(cropped.film.crop->x, 5);
  EXPECT_EQ(cropped.film.crop->y, 7);
  EXPECT_EQ(cropped.film.crop->full_width, 64);
  EXPECT_EQ(cropped.film.crop->full_height, 48);
  EXPECT_EQ(cropped.settings.filter.type, FilterType::LanczosSinc);
  EXPECT_FLOAT_EQ(cropped.settings.filter.sinc_tau, 2);
  EXPECT_FLOAT_EQ(cropped.settings.filter.radius.x, 4);
  scene.film.crop = FilmDesc::Crop{40, 7, 64, 48};  // 40 + 30 > 64
  EXPECT_THROW(read_json_scene(scene_to_json(scene), "converted.json", fs::temp_directory_path()), SceneError);
  const UVMapping& read_planar = std::get<CheckerboardTexture>(back.textures.at(0)).mapping;
  EXPECT_EQ(read_planar.projection, TextureProjection::Planar);
  EXPECT_EQ(read_planar.planar_s, Vec3(4, 0, 0));
  EXPECT_EQ(read_planar.planar_t, Vec3(0, 1, 0));
  EXPECT_FLOAT_EQ(read_planar.du, 0.5f);
  EXPECT_FLOAT_EQ(read_planar.to_world.point(Point3(0.0f)).y, 1);
  EXPECT_EQ(std::get<ImageTexture>(back.textures.at(1)).mapping.projection, TextureProjection::Spherical);
  EXPECT_FALSE(read_json_scene(scene_to_json(SceneDesc{}), "converted.json", fs::temp_directory_path())
                   .camera.screen_window);
}

// pbrt's media convert too: a uniformgrid's samples are written inline.
// pbrt-v4's hair, read from pbrt and written as JSON (`candela convert`): the same materials back,
// and the same image bit for bit (on spheres, where h runs over v as on a curve).
TEST(ConvertJson, HairRoundTrip) {
  Warnings warnings;
  SceneDesc pbrt = read_pbrt_string(
      "LookAt 0 0 6  0 0 0  0 1 0\n"
      "Camera \"perspective\" \"float fov\" 40\n"
      "Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 24\n"
      "WorldBegin\n"
      "LightSource \"infinite\" \"rgb L\" [ 0.4 0.4 0.5 ]\n"
      "LightSource \"distant\" \"point3 from\" [ 1 2 3 ] \"rgb L\" [ 3 3 3 ]\n"
      "Texture \"pigment\" \"float\" \"checkerboard\" \"float tex1\" 0.2 \"float tex2\" 3\n"
      "Material \"hair\"\n"
      "Translate -1.5 0 0\n"
      "Shape \"sphere\" \"float radius\" 0.7\n"
      "Material \"hair\" \"rgb sigma_a\" [ 0.2 0.5 1.5 ] \"float beta_m\" 0.15 \"float alpha\" 4\n"
      "Translate 1 0 0\n"
      "Shape \"sphere\" \"float radius\" 0.5\n"
      "Material \"hair\" \"rgb reflectance\" [ 0.8 0.5 0.2 ] \"float beta_n\" 0.6 \"float eta\" 1.5\n"
      "Translate 1 0 0\n"
      "Shape \"sphere\" \"float radius\" 0.5\n"
      "Material \"hair\" \"texture eumelanin\" \"pigment\" \"float pheomelanin\" 0.7\n"
      "Translate 1 0 0\n"
      "Shape \"sphere\" \"float radius\" 0.5\n",
      "hair.pbrt", fs::temp_directory_path(), warnings);
  SceneDesc back = read_json_scene(scene_to_json(pbrt), "converted.json", fs::temp_directory_path());
  ASSERT_EQ(back.materials.size(), pbrt.materials.size());
  int hairs = 0;
  for (size_t i = 0; i < pbrt.materials.size(); ++i) {
    const auto* o = std::get_if<HairMaterial>(&pbrt.materials[i]);
    if (!o) continue;
    ++hairs;
    const auto& b = std::get<HairMaterial>(back.materials[i]);
    EXPECT_EQ(b.sigma_a.has_value(), o->sigma_a.has_value()) << i;
    if (o->sigma_a) {
      EXPECT_EQ(b.sigma_a->value, o->sigma_a->value) << i;
    }
    EXPECT_EQ(b.reflectance.has_value(), o->reflectance.has_value()) << i;
    if (o->reflectance) {
      EXPECT_EQ(b.reflectance->value, o->reflectance->value) << i;
    }
    if (!o->sigma_a && !o->reflectance) {
      EXPECT_EQ(b.eumelanin.value, o->eumelanin.value) << i;
      EXPECT_EQ(b.eumelanin.texture >= 0, o->eumelanin.texture >= 0) << i;
      EXPECT_EQ(b.pheomelanin.value, o->pheomelanin.value) << i;
    }
    for (auto member : {&HairMaterial::eta, &HairMaterial::beta_m, &HairMaterial::beta_n, &HairMaterial::alpha})
      EXPECT_EQ((b.*member).value, (o->*member).value) << i;
  }
  EXPECT_EQ(hairs, 4);
  for (SceneDesc* d : {&pbrt, &back}) {
    d->settings.spp = 8;
    d->settings.seed = 3;
  }
  Image a = testing::render_description(pbrt).mean_image();
  Image b = testing::render_description(back).mean_image();
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  double sum = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    ASSERT_EQ(a.rgb[i], b.rgb[i]) << i;
    sum += a.rgb[i];
  }
  EXPECT_GT(sum, 0);
}

TEST(ConvertJson, PbrtMediaRoundTrip) {
  Warnings warnings;
  SceneDesc pbrt = read_pbrt_string(
      "MakeNamedMedium \"air\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [ 0.01 0.02 0.03 ] \"float g\" 0.2\n"
      "MediumInterface \"\" \"air\"\n"
      "Camera \"perspective\"\n"
      "WorldBegin\n"
      "Rotate 30 0 1 0\n"
      "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"integer nz\" 2\n"
      "  \"float density\" [ 0 0.25 0.5 1 ] \"point3 p0\" [ -1 -1 -1 ] \"point3 p1\" [ 1 1 1 ]\n"
      "MediumInterface \"smoke\" \"air\"\n"
      "Material \"interface\"\n"
      "Shape \"sphere\"\n"
      "MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [ 1 2 ]\n"
      "  \"float temperature\" [ 1500 2500 ] \"float Lescale\" [ 2 3 ] \"float temperaturescale\" 1.5\n"
      "  \"float temperatureoffset\" 10 \"float temperaturecutoff\" 300\n",
      "media.pbrt", fs::temp_directory_path(), warnings);
  SceneDesc back = read_json_scene(scene_to_json(pbrt), "converted.json", fs::temp_directory_path());
  expect_same_media(back, pbrt);
  EXPECT_EQ(back.media.at(1).name, "smoke");
  EXPECT_EQ(back.media.at(1).density.border, VolumeBorder::Zero);
  EXPECT_EQ(back.camera.medium, pbrt.camera.medium);
  ASSERT_EQ(back.shapes.size(), 1u);
  EXPECT_EQ(back.shapes[0].interior_medium, 1);
  EXPECT_EQ(back.shapes[0].exterior_medium, 0);
}

}  // namespace
}  // namespace candela
