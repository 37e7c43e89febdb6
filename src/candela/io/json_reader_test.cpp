// Tests of the JSON scene reader on valid scenes: settings, camera, shapes, meshes, materials, lights, transforms.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/json_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::json_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- valid scenes

TEST(JsonReader, ReadsTheCornellBox) {
  SceneDesc scene = read_scene_file(kSourceDir / "scenes/cornell-box.json");
  EXPECT_EQ(scene.source_file, (kSourceDir / "scenes/cornell-box.json").string());
  ASSERT_EQ(scene.shapes.size(), 8u);
  ASSERT_EQ(scene.materials.size(), 3u);
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials[1]).reflectance.value, RGB(0.63f, 0.065f, 0.05f));  // file order
  ASSERT_TRUE(scene.shapes[0].emission.has_value());
  EXPECT_EQ(scene.shapes[0].emission->radiance, RGB(17, 12, 4));
  EXPECT_FALSE(scene.shapes[0].emission->two_sided);
  EXPECT_EQ(scene.shapes[0].name, "light");
  EXPECT_EQ(scene.shapes[0].material, 0);
  EXPECT_EQ(scene.shapes[4].material, 2);  // green
  EXPECT_EQ(std::get<MeshShape>(scene.shapes[6].geometry).mesh.triangle_count(), 10u);
  for (size_t i = 1; i < scene.shapes.size(); ++i) EXPECT_FALSE(scene.shapes[i].emission.has_value());
  EXPECT_EQ(scene.film.width, 512);
  EXPECT_EQ(scene.film.height, 512);
  EXPECT_EQ(scene.film.filename, "cornell-box.png");
  EXPECT_EQ(scene.settings.spp, 64);
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 39.3077f);
  EXPECT_EQ(scene.camera.fov_axis, FovAxis::Y);
  expect_near(scene.camera.world_from_camera.point({0, 0, 0}), {278, 273, -800});
  expect_near(scene.camera.world_from_camera.vector({0, 0, 1}), {0, 0, 1});
  expect_near(scene.camera.world_from_camera.vector({0, 1, 0}), {0, 1, 0});
  expect_near(scene.camera.world_from_camera.vector({1, 0, 0}), {-1, 0, 0});  // right-handed: +x image right
}

TEST(JsonReader, EmptySceneGetsDefaults) {
  SceneDesc scene = read("{}");
  EXPECT_EQ(scene.film.width, 512);
  EXPECT_EQ(scene.film.height, 512);
  EXPECT_TRUE(scene.film.filename.empty());
  EXPECT_EQ(scene.settings.spp, 16);
  EXPECT_EQ(scene.settings.max_depth, 16);
  EXPECT_EQ(scene.settings.seed, 0u);
  EXPECT_EQ(scene.settings.integrator, "path");
  EXPECT_EQ(scene.settings.rr_start_depth, 3);
  EXPECT_EQ(scene.settings.sampler.type, SamplerType::ZSobol);  // the default for scenes that name none
  EXPECT_EQ(scene.settings.filter.type, FilterType::Box);
  EXPECT_FLOAT_EQ(scene.settings.filter.radius.x, 0.5f);
  EXPECT_EQ(scene.settings.path.direction_sampling, DirectionSampling::Bsdf);
  EXPECT_TRUE(scene.settings.path.mis);
  EXPECT_EQ(scene.settings.light_selection, LightSelection::Power);
  EXPECT_EQ(scene.settings.path.shadow_rays, 1);
  EXPECT_EQ(scene.settings.adaptive_threshold, 0);  // off
  EXPECT_FLOAT_EQ(scene.transform_start_time, 0);
  EXPECT_FLOAT_EQ(scene.transform_end_time, 1);
  EXPECT_FLOAT_EQ(scene.camera.lens_radius, 0);
  EXPECT_FLOAT_EQ(scene.camera.shutter_open, 0);
  EXPECT_FLOAT_EQ(scene.camera.shutter_close, 1);
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 40);
  EXPECT_EQ(scene.camera.world_from_camera, Transform::look_at_right_handed({0, 0, 0}, {0, 0, 1}, {0, 1, 0}));
  EXPECT_TRUE(scene.shapes.empty());
  EXPECT_TRUE(scene.materials.empty());
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_EQ(scene.source_file, "test.json");
}

TEST(JsonReader, ReadsCameraAndRenderSettings) {
  SceneDesc scene = read(R"({
    "camera": {"position": [1, 2, 3], "look_at": [1, 2, 4], "up": [0, 2, 0], "fov": 60, "width": 640, "height": 480},
    "render": {"spp": 100, "max_depth": 5, "seed": 18446744073709551615, "integrator": "bdpt",
               "output": "out.exr", "rr_start_depth": 0}})");
  EXPECT_EQ(scene.film.width, 640);
  EXPECT_EQ(scene.film.height, 480);
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 60);
  expect_near(scene.camera.world_from_camera.point({0, 0, 0}), {1, 2, 3});
  EXPECT_EQ(scene.settings.spp, 100);
  EXPECT_EQ(scene.settings.max_depth, 5);
  EXPECT_EQ(scene.settings.seed, 18446744073709551615u);
  EXPECT_EQ(scene.settings.integrator, "bdpt");
  EXPECT_EQ(scene.film.filename, "out.exr");
  EXPECT_EQ(scene.settings.rr_start_depth, 0);
}

// A render key that the scene's integrator does not read is an error at that key, naming the
// integrator and those that read it (integrators/integrator.h); an unknown integrator is an error.
TEST(JsonReader, ARenderKeyTheIntegratorDoesNotReadIsAnError) {
  expect_error_containing(R"({"render": {"integrator": "whitted"}})",
                          "at /render/integrator: unknown integrator \"whitted\" (known: path, bdpt, mlt, volpath, "
                          "ambient_occlusion, light_path, sppm)");
  const std::pair<const char*, const char*> cases[] = {
      {R"({"render": {"integrator": "bdpt", "mis": false}})", "at /render/mis: the bdpt integrator does not read mis"},
      {R"({"render": {"integrator": "bdpt", "direction_sampling": "cosine"}})",
       "at /render/direction_sampling: the bdpt integrator does not read direction_sampling"},
      {R"({"render": {"integrator": "mlt", "shadow_rays": 2}})",
       "at /render/shadow_rays: the mlt integrator does not read shadow_rays"},
      {R"({"render": {"integrator": "bdpt", "light_selection": "paper"}})",
       "at /render/light_selection: the bdpt integrator does not read light_selection=paper"},
      {R"({"render": {"integrator": "mlt", "rr_start_depth": 2}})",
       "at /render/rr_start_depth: the mlt integrator does not read rr_start_depth"},
      {R"({"render": {"integrator": "mlt", "adaptive": {"threshold": 0.1}}})",
       "at /render/adaptive: the mlt integrator does not read adaptive (adaptive sampling; read by: path, bdpt, volpath, "
       "ambient_occlusion)"},
      {R"({"render": {"mlt": {"chains": 10}}})", "at /render/mlt: the path integrator does not read mlt"},
      {R"({"render": {"sppm": {"radius": 0.1}}})", "at /render/sppm: the path integrator does not read sppm"},
      {R"({"render": {"integrator": "sppm", "adaptive": {"threshold": 0.1}}})",
       "at /render/adaptive: the sppm integrator does not read adaptive"},
  };
  for (const auto& [text, message] : cases) EXPECT_NE(error_of(text).find(message), std::string::npos) << text;
  // What each integrator reads is accepted; power and uniform light selection by all.
  EXPECT_NO_THROW(read(R"({"render": {"integrator": "path", "mis": false, "shadow_rays": 2, "light_selection": "paper",
                                      "direction_sampling": "cosine", "rr_start_depth": 1, "adaptive": {"spp": 32}}})"));
  EXPECT_NO_THROW(read(R"({"render": {"integrator": "bdpt", "rr_start_depth": 1, "light_selection": "uniform"}})"));
  EXPECT_NO_THROW(read(R"({"render": {"integrator": "mlt", "mlt": {"chains": 10}, "light_selection": "power"}})"));
  const SceneDesc sppm =
      read(R"({"render": {"integrator": "sppm", "sppm": {"photons_per_iteration": 5000, "radius": 0.25}}})");
  EXPECT_EQ(sppm.settings.sppm.photons_per_iteration, 5000);
  EXPECT_EQ(sppm.settings.sppm.radius, 0.25f);
  EXPECT_NE(error_of(R"({"render": {"integrator": "sppm", "sppm": {"radius": 0}}})").find("/render/sppm/radius"),
            std::string::npos);
}

TEST(JsonReader, ReadsMetropolisSettings) {
  SceneDesc scene = read(R"({"render": {"integrator": "mlt", "spp": 64,
    "mlt": {"bootstrap": 5000, "chains": 32, "sigma": 0.02, "large_step": 0.5, "lens": 0.25, "caustic": 0.125}}})");
  EXPECT_EQ(scene.settings.integrator, "mlt");
  EXPECT_EQ(scene.settings.mlt.bootstrap, 5000);
  EXPECT_EQ(scene.settings.mlt.chains, 32);
  EXPECT_FLOAT_EQ(scene.settings.mlt.sigma, 0.02f);
  EXPECT_FLOAT_EQ(scene.settings.mlt.large_step, 0.5f);
  EXPECT_FLOAT_EQ(scene.settings.mlt.lens, 0.25f);
  EXPECT_FLOAT_EQ(scene.settings.mlt.caustic, 0.125f);
  SceneDesc defaults = read(R"({"render": {"integrator": "bdpt"}})");
  EXPECT_EQ(defaults.settings.integrator, "bdpt");
  EXPECT_EQ(defaults.settings.mlt.bootstrap, 100000);
  EXPECT_FLOAT_EQ(defaults.settings.mlt.large_step, 0.3f);
  expect_error_containing(R"({"render": {"mlt": {"chains": 0}}})", "/render/mlt/chains");
  expect_error_containing(R"({"render": {"mlt": {"sigma": 2}}})", "at /render/mlt/sigma: expected a number in [1e-06, 1], got 2");
  expect_error_containing(R"({"render": {"mlt": {"large_step": 1.5}}})", "/render/mlt/large_step");
  expect_error_containing(R"({"render": {"mlt": {"mutations": 5}}})", "mutations");
  expect_error_containing(R"({"render": {"mlt": {"large_step": 0.5, "lens": 0.5, "caustic": 0.25}}})",
                          "at /render/mlt: large_step + lens + caustic must be at most 1, got 1.25");
}

TEST(JsonReader, ReadsLensShutterAndMotion) {
  SceneDesc scene = read(R"({
    "camera": {"lens_radius": 0.05, "focus_distance": 4, "shutter": [0.25, 0.75]},
    "render": {"transform_times": [0, 2]},
    "shapes": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "transform": [{"translate": [1, 0, 0]}],
                "transform_end": [{"scale": 2}, {"translate": [0, 1, 0]}]},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1}]})");
  EXPECT_FLOAT_EQ(scene.camera.lens_radius, 0.05f);
  EXPECT_FLOAT_EQ(scene.camera.focus_distance, 4);
  EXPECT_FLOAT_EQ(scene.camera.shutter_open, 0.25f);
  EXPECT_FLOAT_EQ(scene.camera.shutter_close, 0.75f);
  EXPECT_FLOAT_EQ(scene.transform_start_time, 0);
  EXPECT_FLOAT_EQ(scene.transform_end_time, 2);
  expect_near(scene.shapes[0].to_world.point({1, 1, 1}), {2, 1, 1});
  ASSERT_TRUE(scene.shapes[0].to_world_end.has_value());
  expect_near(scene.shapes[0].to_world_end->point({1, 1, 1}), {2, 3, 2});
  EXPECT_FALSE(scene.shapes[1].to_world_end.has_value());
  // A zero-length shutter is an instant.
  EXPECT_FLOAT_EQ(read(R"({"camera": {"shutter": [0.5, 0.5]}})").camera.shutter_close, 0.5f);
}

TEST(JsonReader, ReadsSamplerAndFilter) {
  SceneDesc scene = read(R"({"render": {"sampler": {"type": "stratified", "jitter": false},
                                         "filter": {"type": "gaussian", "radius": [1, 2], "sigma": 0.3}}})");
  EXPECT_EQ(scene.settings.sampler.type, SamplerType::Stratified);
  EXPECT_FALSE(scene.settings.sampler.jitter);
  EXPECT_EQ(scene.settings.filter.type, FilterType::Gaussian);
  EXPECT_FLOAT_EQ(scene.settings.filter.radius.x, 1);
  EXPECT_FLOAT_EQ(scene.settings.filter.radius.y, 2);
  EXPECT_FLOAT_EQ(scene.settings.filter.gaussian_sigma, 0.3f);
  EXPECT_EQ(read(R"({"render": {"sampler": {"type": "poisson"}}})").settings.sampler.type, SamplerType::Poisson);
  EXPECT_EQ(read(R"({"render": {"sampler": {"type": "zsobol"}}})").settings.sampler.type, SamplerType::ZSobol);
  EXPECT_EQ(read(R"({"render": {"sampler": {"type": "independent"}}})").settings.sampler.type,
            SamplerType::Independent);
  // pbrt-v4's default radius per type; a single number sets both axes.
  auto filter_of = [](const std::string& filter) {
    return read(R"({"render": {"filter": )" + filter + "}}").settings.filter;
  };
  EXPECT_FLOAT_EQ(filter_of(R"({"type": "box"})").radius.y, 0.5f);
  EXPECT_FLOAT_EQ(filter_of(R"({"type": "tent"})").radius.x, 2);
  FilterDesc gaussian = filter_of(R"({"type": "gaussian"})");
  EXPECT_FLOAT_EQ(gaussian.radius.x, 1.5f);
  EXPECT_FLOAT_EQ(gaussian.gaussian_sigma, 0.5f);
  FilterDesc mitchell = filter_of(R"({"type": "mitchell", "radius": 1.5, "b": 0, "c": 0.5})");
  EXPECT_EQ(mitchell.type, FilterType::Mitchell);
  EXPECT_FLOAT_EQ(mitchell.radius.x, 1.5f);
  EXPECT_FLOAT_EQ(mitchell.radius.y, 1.5f);
  EXPECT_FLOAT_EQ(mitchell.mitchell_b, 0);
  EXPECT_FLOAT_EQ(mitchell.mitchell_c, 0.5f);
  FilterDesc mitchell_defaults = filter_of(R"({"type": "mitchell"})");
  EXPECT_FLOAT_EQ(mitchell_defaults.radius.x, 2);
  EXPECT_FLOAT_EQ(mitchell_defaults.mitchell_b, 1.0f / 3);
  EXPECT_FLOAT_EQ(mitchell_defaults.mitchell_c, 1.0f / 3);
}

TEST(JsonReader, ReadsIntegratorStrategiesAndAdaptiveSampling) {
  SceneDesc scene = read(R"({"render": {"direction_sampling": "uniform", "mis": false, "light_selection": "paper",
                                         "shadow_rays": 4,
                                         "adaptive": {"threshold": 0.02, "batch": 8, "max_spp": 512}}})");
  EXPECT_EQ(scene.settings.path.direction_sampling, DirectionSampling::Uniform);
  EXPECT_FALSE(scene.settings.path.mis);
  EXPECT_EQ(scene.settings.light_selection, LightSelection::Paper);
  EXPECT_EQ(scene.settings.path.shadow_rays, 4);
  EXPECT_FLOAT_EQ(scene.settings.adaptive_threshold, 0.02f);
  EXPECT_EQ(scene.settings.adaptive_batch, 8);
  EXPECT_EQ(scene.settings.adaptive_max_spp, 512);
  EXPECT_EQ(read(R"({"render": {"direction_sampling": "cosine"}})").settings.path.direction_sampling,
            DirectionSampling::Cosine);
  EXPECT_EQ(read(R"({"render": {"direction_sampling": "bsdf"}})").settings.path.direction_sampling, DirectionSampling::Bsdf);
  EXPECT_EQ(read(R"({"render": {"light_selection": "power"}})").settings.light_selection, LightSelection::Power);
  EXPECT_EQ(read(R"({"render": {"bvh": "compact"}})").settings.bvh, BvhLayout::Compact);
  EXPECT_EQ(read(R"({"render": {}})").settings.bvh, BvhLayout::Fast);
  // A threshold alone: batch and max_spp keep their defaults (16; 0 = 1024).
  SceneDesc defaults = read(R"({"render": {"adaptive": {"threshold": 0.1}}})");
  EXPECT_EQ(defaults.settings.adaptive_batch, 16);
  EXPECT_EQ(defaults.settings.adaptive_max_spp, 0);
  EXPECT_EQ(defaults.settings.adaptive_spp_limit(), 1024);
  EXPECT_EQ(defaults.settings.adaptive_spp, 0);
  // A budget alone: no threshold, at most 8 x the budget per pixel.
  SceneDesc budget = read(R"({"render": {"adaptive": {"spp": 64}}})");
  EXPECT_TRUE(budget.settings.adaptive());
  EXPECT_EQ(budget.settings.adaptive_threshold, 0);
  EXPECT_EQ(budget.settings.adaptive_spp, 64);
  EXPECT_EQ(budget.settings.adaptive_spp_limit(), 512);
}

TEST(JsonReader, AcceptsIntegralFloatsAndComments) {
  SceneDesc scene = read(R"({"_comment": "top", "camera": {"_comment": 3, "width": 640.0},
    "shapes": [{"_comment": ["any"], "type": "sphere", "center": [0, 0, 0], "radius": 1,
                "transform": [{"_comment": "step", "scale": 2}]}]})");
  EXPECT_EQ(scene.film.width, 640);
  EXPECT_EQ(scene.shapes.size(), 1u);
}

TEST(JsonReader, ReadsSphere) {
  SceneDesc scene = read(with_shape(
      R"({"type": "sphere", "center": [1, 2, 3], "radius": 0.5, "name": "ball", "reverse_orientation": true})"));
  ASSERT_EQ(scene.shapes.size(), 1u);
  const ShapeDesc& shape = scene.shapes[0];
  const auto& sphere = std::get<SphereShape>(shape.geometry);
  EXPECT_EQ(sphere.center, Vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(sphere.radius, 0.5f);
  EXPECT_EQ(shape.name, "ball");
  EXPECT_TRUE(shape.reverse_orientation);
  EXPECT_EQ(shape.material, -1);  // the default diffuse 0.5
  EXPECT_FALSE(shape.emission.has_value());
  EXPECT_TRUE(shape.to_world.is_identity());
}

TEST(JsonReader, ReadsPlaneWithNormalisedNormal) {
  SceneDesc scene = read(with_shape(R"({"type": "plane", "point": [0, -1, 0], "normal": [0, 3, 0]})"));
  const auto& plane = std::get<PlaneShape>(scene.shapes[0].geometry);
  EXPECT_EQ(plane.point, Vec3(0, -1, 0));
  expect_near(plane.normal, {0, 1, 0});
}

TEST(JsonReader, ReadsBox) {
  SceneDesc scene = read(with_shape(R"({"type": "box", "min": [-1, 0, -2], "max": [1, 3, 2]})"));
  const auto& box = std::get<BoxShape>(scene.shapes[0].geometry);
  EXPECT_EQ(box.lo, Vec3(-1, 0, -2));
  EXPECT_EQ(box.hi, Vec3(1, 3, 2));
}

TEST(JsonReader, ReadsRectangleWithTwoSidedEmission) {
  SceneDesc scene = read(with_shape(
      R"({"type": "rectangle", "corner": [0, 5, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0, 2],
          "emission": {"radiance": [10, 20, 30], "two_sided": true}})"));
  const ShapeDesc& shape = scene.shapes[0];
  const auto& rectangle = std::get<RectangleShape>(shape.geometry);
  EXPECT_EQ(rectangle.corner, Vec3(0, 5, 0));
  EXPECT_EQ(rectangle.edge_u, Vec3(1, 0, 0));
  EXPECT_EQ(rectangle.edge_v, Vec3(0, 0, 2));
  ASSERT_TRUE(shape.emission.has_value());
  EXPECT_EQ(shape.emission->radiance, RGB(10, 20, 30));
  EXPECT_TRUE(shape.emission->two_sided);
}

TEST(JsonReader, ReadsInlineMeshWithNormalsAndUvs) {
  SceneDesc scene = read(with_shape(R"({"type": "mesh",
      "positions": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], "indices": [0, 1, 2, 0, 2, 3],
      "normals": [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]], "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]]})"));
  const TriangleMesh& mesh = std::get<MeshShape>(scene.shapes[0].geometry).mesh;
  EXPECT_EQ(mesh.positions.size(), 4u);
  EXPECT_EQ(mesh.triangle_count(), 2u);
  EXPECT_EQ(mesh.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(mesh.normals.size(), 4u);
  ASSERT_EQ(mesh.uvs.size(), 4u);
  EXPECT_EQ(mesh.uvs[2].x, 1);
  EXPECT_EQ(mesh.uvs[2].y, 1);
}

TEST(JsonReader, SingleTriangleMeshMayOmitIndices) {
  SceneDesc scene = read(with_shape(R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]})"));
  EXPECT_EQ(std::get<MeshShape>(scene.shapes[0].geometry).mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(JsonReader, ReadsObjMeshFileRelativeToBaseDir) {
  SceneDesc scene = read(with_shape(R"({"type": "mesh", "file": "spot/spot.obj"})"), kSharedDir / "meshes");
  const TriangleMesh& mesh = std::get<MeshShape>(scene.shapes[0].geometry).mesh;
  EXPECT_EQ(mesh.triangle_count(), 5856u);
  EXPECT_FALSE(mesh.uvs.empty());
}

TEST(JsonReader, ReadsPlyMeshFile) {
  fs::path ply = kSharedDir / "meshes/bunny/stanford-original/bun_zipper_res4.ply";
  SceneDesc scene = read(with_shape(R"({"type": "mesh", "file": ")" + ply.string() + R"("})"));
  const TriangleMesh& mesh = std::get<MeshShape>(scene.shapes[0].geometry).mesh;
  EXPECT_EQ(mesh.triangle_count(), 948u);
}

TEST(JsonReader, ReadsEveryMaterialType) {
  SceneDesc scene = read(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"})",
                                    R"({"matte": {"type": "diffuse", "reflectance": 0.25},
      "plastic": {"type": "phong", "diffuse": [0.5, 0.4, 0.3], "specular": 0.9, "exponent": 200,
                  "transmission": [0.1, 0.2, 0.3], "ior": 1.33, "d": 0.6, "s": 0.3, "t": 0.1},
      "chrome": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]},
      "glass": {"type": "glass", "ior": 1.7, "reflectance": 0.95, "transmittance": [1, 0.9, 0.8]},
      "void": {"type": "black"},
      "plain": {"type": "phong"}})"));
  ASSERT_EQ(scene.materials.size(), 6u);
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials[0]).reflectance.value, RGB(0.25f));
  const auto& phong = std::get<PhongMaterial>(scene.materials[1]);
  EXPECT_EQ(phong.diffuse.value, RGB(0.5f, 0.4f, 0.3f));
  EXPECT_EQ(phong.specular.value, RGB(0.9f));
  EXPECT_FLOAT_EQ(phong.exponent, 200);
  EXPECT_EQ(phong.transmission.value, RGB(0.1f, 0.2f, 0.3f));
  EXPECT_FLOAT_EQ(phong.ior, 1.33f);
  EXPECT_FLOAT_EQ(phong.d, 0.6f);
  EXPECT_FLOAT_EQ(phong.s, 0.3f);
  EXPECT_FLOAT_EQ(phong.t, 0.1f);
  EXPECT_EQ(std::get<MirrorMaterial>(scene.materials[2]).reflectance.value, RGB(0.9f, 0.8f, 0.7f));
  const auto& glass = std::get<DielectricMaterial>(scene.materials[3]);
  EXPECT_FLOAT_EQ(glass.ior, 1.7f);
  EXPECT_EQ(glass.reflectance.value, RGB(0.95f));
  EXPECT_EQ(glass.transmittance.value, RGB(1, 0.9f, 0.8f));
  EXPECT_TRUE(std::holds_alternative<BlackMaterial>(scene.materials[4]));
  const auto& plain = std::get<PhongMaterial>(scene.materials[5]);  // all defaults from description.h
  EXPECT_EQ(plain.diffuse.value, PhongMaterial{}.diffuse.value);
  EXPECT_FLOAT_EQ(plain.d, 1);
  EXPECT_FLOAT_EQ(plain.exponent, 32);
  EXPECT_EQ(scene.shapes[0].material, 3);
}

TEST(JsonReader, InlineMaterialIsAppended) {
  SceneDesc scene =
      read(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": {"type": "mirror"}})",
                      R"({"red": {"type": "diffuse", "reflectance": [0.8, 0.1, 0.1]}})"));
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_EQ(scene.shapes[0].material, 1);
  EXPECT_EQ(std::get<MirrorMaterial>(scene.materials[1]).reflectance.value, RGB(1));
}

TEST(JsonReader, ReadsPointAndSkyLights) {
  SceneDesc scene = read(with_light(R"({"type": "point", "position": [1, 2, 3], "intensity": [100, 50, 25]},
      {"type": "sky", "radiance": 0.5},
      {"type": "sky", "zenith": [0.2, 0.3, 1], "up": [0, 0, 2]},
      {"type": "sky", "horizon": 1, "ground": 0.1})"));
  ASSERT_EQ(scene.lights.size(), 4u);
  const auto& point = std::get<PointLight>(scene.lights[0]);
  EXPECT_EQ(point.position, Vec3(1, 2, 3));
  EXPECT_EQ(point.intensity, RGB(100, 50, 25));
  const auto& constant = std::get<SkyLight>(scene.lights[1]);
  EXPECT_TRUE(constant.is_constant());
  EXPECT_EQ(constant.zenith, RGB(0.5f));
  const auto& zenith_only = std::get<SkyLight>(scene.lights[2]);
  EXPECT_EQ(zenith_only.horizon, RGB(0.2f, 0.3f, 1));  // horizon defaults to zenith
  EXPECT_EQ(zenith_only.ground, RGB(0.2f, 0.3f, 1));   // ground defaults to horizon
  expect_near(zenith_only.up, {0, 0, 1});
  const auto& gradient = std::get<SkyLight>(scene.lights[3]);
  EXPECT_EQ(gradient.zenith, RGB(1));  // zenith defaults to horizon
  EXPECT_EQ(gradient.ground, RGB(0.1f));
  EXPECT_FALSE(gradient.is_constant());
}

TEST(JsonReader, ShapeLightsBecomeEmittersWithOneSharedBlackMaterial) {
  SceneDesc scene = read(R"({"materials": {"white": {"type": "diffuse"}}, "lights": [
      {"type": "sphere", "center": [0, 5, 0], "radius": 2, "radiance": [4, 4, 8]},
      {"type": "rectangle", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0, 1, 0], "radiance": 3,
       "two_sided": true, "transform": [{"translate": [0, 0, 7]}]}]})");
  EXPECT_TRUE(scene.lights.empty());
  ASSERT_EQ(scene.shapes.size(), 2u);
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<BlackMaterial>(scene.materials[1]));
  const ShapeDesc& sphere = scene.shapes[0];
  EXPECT_FLOAT_EQ(std::get<SphereShape>(sphere.geometry).radius, 2);
  EXPECT_EQ(sphere.material, 1);
  ASSERT_TRUE(sphere.emission.has_value());
  EXPECT_EQ(sphere.emission->radiance, RGB(4, 4, 8));
  EXPECT_FALSE(sphere.emission->two_sided);
  const ShapeDesc& rectangle = scene.shapes[1];
  EXPECT_TRUE(std::holds_alternative<RectangleShape>(rectangle.geometry));
  EXPECT_EQ(rectangle.material, 1);
  EXPECT_TRUE(rectangle.emission->two_sided);
  expect_near(rectangle.to_world.point({0, 0, 0}), {0, 0, 7});
}

// ---------------------------------------------------------------- transforms

Transform transform_of(const std::string& steps) {
  SceneDesc scene =
      read(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "transform": )" + steps + "}"));
  return scene.shapes[0].to_world;
}

TEST(JsonReader, TransformStepsApplyInListedOrder) {
  Transform translate_then_rotate =
      transform_of(R"([{"translate": [1, 0, 0]}, {"rotate": {"angle": 90, "axis": [0, 0, 1]}}])");
  expect_near(translate_then_rotate.point({0, 0, 0}), {0, 1, 0});
  Transform rotate_then_translate =
      transform_of(R"([{"rotate": {"angle": 90, "axis": [0, 0, 1]}}, {"translate": [1, 0, 0]}])");
  expect_near(rotate_then_translate.point({0, 0, 0}), {1, 0, 0});
  expect_near(rotate_then_translate.point({1, 0, 0}), {1, 1, 0});
}

TEST(JsonReader, ReadsScaleAndMatrix) {
  expect_near(transform_of(R"([{"scale": 2}])").point({1, 2, 3}), {2, 4, 6});
  expect_near(transform_of(R"([{"scale": [1, -1, 3]}])").point({1, 2, 3}), {1, -2, 9});
  Transform matrix = transform_of(R"([{"matrix": [2, 0, 0, 5,  0, 1, 0, 6,  0, 0, 1, 7,  0, 0, 0, 1]}])");
  expect_near(matrix.point({1, 1, 1}), {7, 7, 8});  // row-major: the translation is the last column
  expect_near(matrix.inverse().point({7, 7, 8}), {1, 1, 1});
  EXPECT_TRUE(transform_of("[]").is_identity());
}

}  // namespace
}  // namespace candela
