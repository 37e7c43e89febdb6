// Tests of the pbrt-v4 reader: the Cornell box, transforms and graphics-state scoping, Include /
// Import, and one test per kind of bad input, each checking the file:line:column of the message.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/named_spectra.h"
#include "candela/io/pbrt_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/description/scene_desc.h"
#include "candela/spectral/cie.h"
#include "candela/testing/command_line.h"
#include "candela/testing/gzip_bytes.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- the Cornell box

void expect_cornell_box(const SceneDesc& scene) {
  ASSERT_EQ(scene.shapes.size(), 8u);
  const RGB white(0.725f, 0.71f, 0.68f), red(0.63f, 0.065f, 0.05f), green(0.14f, 0.45f, 0.091f);
  // light, floor, ceiling, back wall, right (green) wall, left (red) wall, short block, tall block
  const RGB expected[8] = {white, white, white, white, green, red, white, white};
  const size_t triangles[8] = {2, 2, 2, 2, 2, 2, 10, 10};
  for (size_t i = 0; i < 8; ++i) {
    SCOPED_TRACE(scene.shapes[i].name);
    EXPECT_EQ(reflectance_of(scene, scene.shapes[i]), expected[i]);
    EXPECT_EQ(mesh_of(scene.shapes[i]).triangle_count(), triangles[i]);
    EXPECT_TRUE(scene.shapes[i].to_world.is_identity());
    EXPECT_FALSE(scene.shapes[i].reverse_orientation);
    EXPECT_EQ(scene.shapes[i].emission.has_value(), i == 0);
  }
  EXPECT_EQ(scene.shapes[0].emission->radiance, RGB(17, 12, 4));
  EXPECT_FALSE(scene.shapes[0].emission->two_sided);
  EXPECT_EQ(mesh_of(scene.shapes[0]).positions[0], Point3(343, 548.7f, 227));
  EXPECT_TRUE(scene.lights.empty());

  // The camera sits at (278, 273, -800) looking along +z with +y up, and world +x is image LEFT.
  const Transform& camera = scene.camera.world_from_camera;
  expect_near(camera.point(Point3(0, 0, 0)), Point3(278, 273, -800));
  expect_near(camera.vector(Vec3(0, 0, 1)), Vec3(0, 0, 1));
  expect_near(camera.vector(Vec3(0, 1, 0)), Vec3(0, 1, 0));
  expect_near(camera.vector(Vec3(1, 0, 0)), Vec3(-1, 0, 0));
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 39.3077f);
  EXPECT_EQ(scene.camera.fov_axis, FovAxis::Smaller);

  EXPECT_EQ(scene.film.width, 512);
  EXPECT_EQ(scene.film.height, 512);
  EXPECT_EQ(scene.film.filename, "cornell-box.exr");
  EXPECT_EQ(scene.settings.integrator, "path");
  EXPECT_EQ(scene.settings.max_depth, 16);
}

TEST(PbrtReader, ReadsTheSharedCornellBox) {
  SceneDesc scene = read_pbrt_scene(kSharedCornellBox);
  expect_cornell_box(scene);
  EXPECT_EQ(scene.settings.spp, 256);
  EXPECT_EQ(scene.source_file, kSharedCornellBox.string());
}

TEST(PbrtReader, RepositoryCornellBoxIsTheSharedSceneAt64Samples) {
  SceneDesc ours = read_pbrt_scene(kRepoCornellBox);
  expect_cornell_box(ours);
  EXPECT_EQ(ours.settings.spp, 64);
  SceneDesc shared = read_pbrt_scene(kSharedCornellBox);
  for (size_t i = 0; i < shared.shapes.size(); ++i) {
    EXPECT_EQ(mesh_of(ours.shapes[i]).positions, mesh_of(shared.shapes[i]).positions);
    EXPECT_EQ(mesh_of(ours.shapes[i]).indices, mesh_of(shared.shapes[i]).indices);
  }
  EXPECT_EQ(ours.camera.world_from_camera, shared.camera.world_from_camera);
}

// ---------------------------------------------------------------- defaults

TEST(PbrtReader, UsesPbrtDefaultsForAbsentDirectivesAndParameters) {
  SceneDesc scene = read_lines({"Camera \"perspective\"", "Film \"rgb\"", "Sampler \"zsobol\"",
                                "Integrator \"path\"", "WorldBegin", "Shape \"sphere\"", "Material \"diffuse\"",
                                "Shape \"sphere\""});
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 90);
  EXPECT_EQ(scene.camera.fov_axis, FovAxis::Smaller);
  EXPECT_TRUE(scene.camera.world_from_camera.is_identity());
  EXPECT_EQ(scene.film.width, 1280);
  EXPECT_EQ(scene.film.height, 720);
  EXPECT_EQ(scene.film.filename, "");
  EXPECT_EQ(scene.settings.spp, 16);
  EXPECT_EQ(scene.settings.max_depth, 5);
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[0].geometry).radius, 1);
  EXPECT_EQ(scene.shapes[0].material, -1);  // pbrt's default, diffuse 0.5
  EXPECT_EQ(reflectance_of(scene, scene.shapes[1]), RGB(0.5f));
}

TEST(PbrtReader, SceneWithOnlyWorldBeginGetsTheDefaults) {
  SceneDesc scene = read_lines({"WorldBegin"});
  EXPECT_EQ(scene.film.width, 1280);
  EXPECT_EQ(scene.settings.spp, 16);
  EXPECT_EQ(scene.settings.max_depth, 5);
  EXPECT_EQ(scene.settings.integrator, "path");
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 90);
  EXPECT_TRUE(scene.shapes.empty());
}

TEST(PbrtReader, OtherIntegratorsBecomePathAndStratifiedSampleCounts) {
  SceneDesc scene = read_lines({"Integrator \"sppm\" \"integer maxdepth\" 7",
                                "Sampler \"stratified\" \"integer xsamples\" 3 \"integer ysamples\" 5 "
                                "\"bool jitter\" false",
                                "WorldBegin"});
  EXPECT_EQ(scene.settings.integrator, "path");
  EXPECT_EQ(scene.settings.max_depth, 7);
  EXPECT_EQ(scene.settings.spp, 15);
}

TEST(PbrtReader, SamplerSeedSetsTheRenderSeed) {
  SceneDesc scene = read_lines({"Sampler \"zsobol\" \"integer pixelsamples\" 8 \"integer seed\" 42", "WorldBegin"});
  EXPECT_EQ(scene.settings.spp, 8);
  EXPECT_EQ(scene.settings.seed, 42u);
}

// ---------------------------------------------------------------- samplers, filters, light sampler

TEST(PbrtReader, DefaultSamplerAndFilterArePbrtsZSobolAndGaussian) {
  SceneDesc scene = read_lines({"WorldBegin"});
  EXPECT_EQ(scene.settings.sampler.type, SamplerType::ZSobol);
  EXPECT_EQ(scene.settings.spp, 16);
  EXPECT_EQ(scene.settings.filter.type, FilterType::Gaussian);
  EXPECT_FLOAT_EQ(scene.settings.filter.radius.x, 1.5f);
  EXPECT_FLOAT_EQ(scene.settings.filter.radius.y, 1.5f);
  EXPECT_FLOAT_EQ(scene.settings.filter.gaussian_sigma, 0.5f);
  EXPECT_EQ(scene.settings.light_selection, LightSelection::Bvh);  // pbrt-v4's volpath's default
}

TEST(PbrtReader, ReadsTheThreeSamplerTypes) {
  SceneDesc independent = read_lines({"Sampler \"independent\"", "WorldBegin"});
  EXPECT_EQ(independent.settings.sampler.type, SamplerType::Independent);
  EXPECT_EQ(independent.settings.spp, 4);  // pbrt-v4's default for this sampler
  SceneDesc stratified = read_lines(
      {"Sampler \"stratified\" \"integer xsamples\" 2 \"integer ysamples\" 3 \"bool jitter\" false", "WorldBegin"});
  EXPECT_EQ(stratified.settings.sampler.type, SamplerType::Stratified);
  EXPECT_FALSE(stratified.settings.sampler.jitter);
  EXPECT_EQ(stratified.settings.spp, 6);
  EXPECT_TRUE(read_lines({"Sampler \"stratified\"", "WorldBegin"}).settings.sampler.jitter);
  SceneDesc zsobol = read_lines(
      {"Sampler \"zsobol\" \"integer pixelsamples\" 64 \"string randomization\" \"owen\"", "WorldBegin"});
  EXPECT_EQ(zsobol.settings.sampler.type, SamplerType::ZSobol);
  EXPECT_EQ(zsobol.settings.spp, 64);
}

TEST(PbrtReader, BadSamplers) {
  expect_error({"Sampler \"random\"", "WorldBegin"}, 1, "\"random\"",
               "unknown sampler type \"random\" (supported: \"independent\", \"stratified\", \"zsobol\", \"sobol\", "
               "\"halton\", \"paddedsobol\", \"pmj02bn\")");
  expect_error({"Sampler \"pmj02bn\" \"string randomization\" \"owen\"", "WorldBegin"}, 1,
               "\"string randomization\"", "unused parameter");
  expect_error({"Sampler \"zsobol\" \"string randomization\" \"scrambled\"", "WorldBegin"}, 1,
               "\"string randomization\"", "must be \"none\", \"permutedigits\", \"fastowen\" or \"owen\"");
  expect_error({"Sampler \"independent\" \"string randomization\" \"owen\"", "WorldBegin"}, 1,
               "\"string randomization\"", "unused parameter");
  expect_error({"Sampler \"stratified\" \"integer pixelsamples\" 4", "WorldBegin"}, 1, "\"integer pixelsamples\"",
               "unused parameter");
  expect_error({"Sampler \"independent\" \"integer pixelsamples\" 0", "WorldBegin"}, 1, "\"integer pixelsamples\"",
               "must be positive");
  expect_error({"Sampler \"stratified\" \"integer xsamples\" 0", "WorldBegin"}, 1, "\"integer xsamples\"",
               "must be positive");
  expect_error({"Sampler \"zsobol\" \"integer seed\" -1", "WorldBegin"}, 1, "\"integer seed\"", "must not be negative");
}

void expect_radius(const FilterDesc& filter, float x, float y) {
  EXPECT_FLOAT_EQ(filter.radius.x, x);
  EXPECT_FLOAT_EQ(filter.radius.y, y);
}

TEST(PbrtReader, ReadsTheFourPixelFiltersWithPbrtDefaults) {
  auto filter_of = [](const std::string& directive) { return read_lines({directive, "WorldBegin"}).settings.filter; };
  FilterDesc box = filter_of("PixelFilter \"box\"");
  EXPECT_EQ(box.type, FilterType::Box);
  expect_radius(box, 0.5f, 0.5f);
  FilterDesc triangle = filter_of("PixelFilter \"triangle\"");
  EXPECT_EQ(triangle.type, FilterType::Tent);
  expect_radius(triangle, 2, 2);
  FilterDesc gaussian = filter_of("PixelFilter \"gaussian\" \"float sigma\" 0.7 \"float yradius\" 2.5");
  EXPECT_EQ(gaussian.type, FilterType::Gaussian);
  expect_radius(gaussian, 1.5f, 2.5f);
  EXPECT_FLOAT_EQ(gaussian.gaussian_sigma, 0.7f);
  FilterDesc mitchell = filter_of("PixelFilter \"mitchell\"");
  EXPECT_EQ(mitchell.type, FilterType::Mitchell);
  expect_radius(mitchell, 2, 2);
  EXPECT_FLOAT_EQ(mitchell.mitchell_b, 1.0f / 3);
  EXPECT_FLOAT_EQ(mitchell.mitchell_c, 1.0f / 3);
  FilterDesc catmull_rom = filter_of("PixelFilter \"mitchell\" \"float B\" 0 \"float C\" 0.5 \"float xradius\" 1");
  expect_radius(catmull_rom, 1, 2);
  EXPECT_FLOAT_EQ(catmull_rom.mitchell_b, 0);
  EXPECT_FLOAT_EQ(catmull_rom.mitchell_c, 0.5f);
  expect_radius(filter_of("PixelFilter \"box\" \"float xradius\" 1"), 1, 0.5f);
}

TEST(PbrtReader, BadPixelFilters) {
  expect_error({"PixelFilter \"sinc\"", "WorldBegin"}, 1, "\"sinc\"",
               "pixel filter type \"sinc\" is not supported yet (supported: \"box\", \"triangle\", \"gaussian\", "
               "\"mitchell\")");
  expect_error({"PixelFilter \"tent\"", "WorldBegin"}, 1, "\"tent\"", "unknown pixel filter type \"tent\"");
  expect_error({"PixelFilter \"box\" \"float xradius\" 0", "WorldBegin"}, 1, "\"float xradius\"",
               "\"xradius\" must be in (0, 64] pixels, got 0");
  expect_error({"PixelFilter \"triangle\" \"float yradius\" 1000", "WorldBegin"}, 1, "\"float yradius\"",
               "must be in (0, 64] pixels");
  expect_error({"PixelFilter \"gaussian\" \"float sigma\" -1", "WorldBegin"}, 1, "\"float sigma\"",
               "\"sigma\" must be positive");
  expect_error({"PixelFilter \"gaussian\" \"float B\" 0", "WorldBegin"}, 1, "\"float B\"", "unused parameter");
  expect_error({"PixelFilter \"box\" \"float sigma\" 1", "WorldBegin"}, 1, "\"float sigma\"", "unused parameter");
}

TEST(PbrtReader, LightSamplerPowerAndBvh) {
  for (auto [name, selection] : {std::pair{"power", LightSelection::Power}, {"bvh", LightSelection::Bvh}}) {
    SceneDesc scene = read_lines({"Integrator \"path\" \"string lightsampler\" \"" + std::string(name) + "\"", "WorldBegin"});
    EXPECT_EQ(scene.settings.light_selection, selection) << name;
  }
  // pbrt-v4's default for the integrators that read it; its BDPT and MLT choose by power.
  EXPECT_EQ(read_lines({"Integrator \"volpath\"", "WorldBegin"}).settings.light_selection, LightSelection::Bvh);
  EXPECT_EQ(read_lines({"Integrator \"bdpt\"", "WorldBegin"}).settings.light_selection, LightSelection::Power);
  expect_error({"Integrator \"path\" \"string lightsampler\" \"uniform\"", "WorldBegin"}, 1,
               "\"string lightsampler\"", "\"uniform\" is not supported yet");
  expect_error({"Integrator \"path\" \"string lightsampler\" \"nearest\"", "WorldBegin"}, 1,
               "\"string lightsampler\"", "must be \"bvh\", \"power\", \"uniform\" or \"exhaustive\"");
}

// ---------------------------------------------------------------- camera lens and shutter

TEST(PbrtReader, CameraLensAndShutter) {
  SceneDesc defaults = read_lines({"Camera \"perspective\"", "WorldBegin"});
  EXPECT_FLOAT_EQ(defaults.camera.lens_radius, 0);
  EXPECT_FLOAT_EQ(defaults.camera.focus_distance, 1e6f);
  EXPECT_FLOAT_EQ(defaults.camera.shutter_open, 0);
  EXPECT_FLOAT_EQ(defaults.camera.shutter_close, 1);
  SceneDesc scene = read_lines({"Camera \"perspective\" \"float lensradius\" 0.1 \"float focaldistance\" 7 "
                                "\"float shutteropen\" 0.25 \"float shutterclose\" 0.75",
                                "WorldBegin"});
  EXPECT_FLOAT_EQ(scene.camera.lens_radius, 0.1f);
  EXPECT_FLOAT_EQ(scene.camera.focus_distance, 7);
  EXPECT_FLOAT_EQ(scene.camera.shutter_open, 0.25f);
  EXPECT_FLOAT_EQ(scene.camera.shutter_close, 0.75f);
}

TEST(PbrtReader, BadLensAndShutter) {
  expect_error({"Camera \"perspective\" \"float lensradius\" -0.1", "WorldBegin"}, 1, "\"float lensradius\"",
               "\"lensradius\" must not be negative");
  expect_error({"Camera \"perspective\" \"float focaldistance\" 0", "WorldBegin"}, 1, "\"float focaldistance\"",
               "\"focaldistance\" must be positive");
  expect_error({"Camera \"perspective\" \"float shutteropen\" 0.5 \"float shutterclose\" 0.2", "WorldBegin"}, 1,
               "\"float shutterclose\"", "must not be less than \"shutteropen\" (0.5), got 0.2");
}

// ---------------------------------------------------------------- animated transforms

TEST(PbrtReader, ActiveTransformMakesAnimatedShapes) {
  SceneDesc scene = read_lines({"TransformTimes 2 5", "WorldBegin", "Translate 1 0 0", "ActiveTransform EndTime",
                                "Translate 0 3 0", "ActiveTransform All", "Scale 2 2 2", "Shape \"sphere\"",
                                "ActiveTransform StartTime", "Identity", "ActiveTransform All", "Shape \"sphere\""});
  EXPECT_FLOAT_EQ(scene.transform_start_time, 2);
  EXPECT_FLOAT_EQ(scene.transform_end_time, 5);
  ASSERT_EQ(scene.shapes.size(), 2u);
  const ShapeDesc& first = scene.shapes[0];
  expect_near(first.to_world.point(Point3(1, 0, 0)), Point3(3, 0, 0));
  ASSERT_TRUE(first.to_world_end.has_value());
  expect_near(first.to_world_end->point(Point3(1, 0, 0)), Point3(3, 3, 0));
  // Identity on the start CTM only: the second sphere moves from the origin to its end place.
  const ShapeDesc& second = scene.shapes[1];
  EXPECT_TRUE(second.to_world.is_identity());
  ASSERT_TRUE(second.to_world_end.has_value());
  expect_near(second.to_world_end->point(Point3(0, 0, 0)), Point3(1, 3, 0));
}

TEST(PbrtReader, StaticShapesHaveNoEndTransform) {
  SceneDesc scene = read_lines({"WorldBegin", "ActiveTransform EndTime", "ActiveTransform All", "Translate 1 2 3",
                                "Shape \"sphere\""});
  EXPECT_FALSE(scene.shapes.at(0).to_world_end.has_value());
  EXPECT_FLOAT_EQ(scene.transform_start_time, 0);
  EXPECT_FLOAT_EQ(scene.transform_end_time, 1);
}

TEST(PbrtReader, ActiveTransformIsScopedByAttributeBlocksAndResetByWorldBegin) {
  SceneDesc scene = read_lines({"ActiveTransform EndTime", "WorldBegin", "AttributeBegin", "ActiveTransform EndTime",
                                "AttributeEnd", "Translate 0 1 0", "Shape \"sphere\""});
  EXPECT_FALSE(scene.shapes.at(0).to_world_end.has_value());
  expect_near(scene.shapes[0].to_world.point(Point3(0, 0, 0)), Point3(0, 1, 0));
}

TEST(PbrtReader, CoordinateSystemsKeepBothTransforms) {
  SceneDesc scene = read_lines({"WorldBegin", "ActiveTransform EndTime", "Translate 1 0 0", "ActiveTransform All",
                                "CoordinateSystem \"moving\"", "Identity", "CoordSysTransform \"moving\"",
                                "Shape \"sphere\""});
  ASSERT_TRUE(scene.shapes.at(0).to_world_end.has_value());
  expect_near(scene.shapes[0].to_world_end->point(Point3(0, 0, 0)), Point3(1, 0, 0));
}

TEST(PbrtReader, AnimatedObjectInstances) {
  SceneDesc scene = read_lines({"WorldBegin", "ObjectBegin \"ball\"", "Shape \"sphere\"", "ObjectEnd",
                                "ActiveTransform EndTime", "Translate 0 0 4", "ActiveTransform All",
                                "ObjectInstance \"ball\"", "Identity", "ObjectInstance \"ball\""});
  EXPECT_TRUE(scene.shapes.empty());
  ASSERT_EQ(scene.objects.size(), 1u);
  ASSERT_EQ(scene.instances.size(), 2u);
  ASSERT_TRUE(scene.instances[0].to_world_end.has_value());
  EXPECT_TRUE(scene.instances[0].to_world.is_identity());
  expect_near(scene.instances[0].to_world_end->point(Point3(0, 0, 0)), Point3(0, 0, 4));
  EXPECT_FALSE(scene.instances[1].to_world_end.has_value());
}

TEST(PbrtReader, BadAnimatedTransforms) {
  expect_error({"ActiveTransform Later", "WorldBegin"}, 1, "Later",
               "ActiveTransform: expected StartTime, EndTime or All, got Later");
  expect_error({"ActiveTransform \"All\"", "WorldBegin"}, 1, "\"All\"", "expected StartTime, EndTime or All");
  expect_error({"TransformTimes 1 1", "WorldBegin"}, 1, "TransformTimes",
               "the start time must be less than the end time, got 1 and 1");
  expect_error({"TransformTimes 0", "WorldBegin"}, 2, "WorldBegin", "TransformTimes: expected 2 numbers");
  expect_error({"WorldBegin", "TransformTimes 0 1"}, 2, "TransformTimes", "not allowed after WorldBegin");
  expect_error({"ActiveTransform EndTime", "Translate 0 0 1", "Camera \"perspective\"", "WorldBegin"}, 3, "Camera",
               "a moving camera is not supported");
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\"", "ActiveTransform EndTime", "Translate 1 0 0",
                "Shape \"sphere\""},
               5, "Shape", "area lights must not move");
  expect_error({"WorldBegin", "ActiveTransform StartTime", "Translate 1 0 0", "LightSource \"point\""}, 4,
               "LightSource", "lights must not move");
}

// ---------------------------------------------------------------- transforms

TEST(PbrtReader, TransformsComposeInFileOrder) {
  // pbrt post-multiplies: the last transform given is applied to the object first.
  SceneDesc scene = read_lines({"WorldBegin", "Translate 1 2 3", "Scale 2 2 2", "Rotate 90 0 0 1", "Shape \"sphere\""});
  const Transform& t = scene.shapes.at(0).to_world;
  expect_near(t.point(Point3(1, 0, 0)), Point3(1, 4, 3));  // rotate to (0,1,0), scale to (0,2,0), translate
  expect_near(t.point(Point3(0, 0, 0)), Point3(1, 2, 3));
}

TEST(PbrtReader, TransformIsColumnMajorAndConcatTransformMultiplies) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]",
                                "Shape \"sphere\"",
                                "ConcatTransform [ 2 0 0 0  0 2 0 0  0 0 2 0  1 0 0 1 ]",
                                "Shape \"sphere\""});
  expect_near(scene.shapes.at(0).to_world.point(Point3(0, 0, 0)), Point3(5, 6, 7));
  expect_near(scene.shapes.at(1).to_world.point(Point3(1, 1, 1)), Point3(8, 8, 9));
}

TEST(PbrtReader, AttributeBlocksScopeTheGraphicsState) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "Translate 1 0 0",
                                "AttributeBegin",
                                "  Translate 0 1 0",
                                "  Material \"dielectric\"",
                                "  AreaLightSource \"diffuse\" \"rgb L\" [ 1 2 3 ]",
                                "  ReverseOrientation",
                                "  Shape \"sphere\"",
                                "  AttributeBegin",
                                "    Scale 2 2 2",
                                "    Shape \"sphere\"",
                                "  AttributeEnd",
                                "AttributeEnd",
                                "Shape \"sphere\""});
  ASSERT_EQ(scene.shapes.size(), 3u);
  const ShapeDesc &inner = scene.shapes[0], &innermost = scene.shapes[1], &outer = scene.shapes[2];
  expect_near(inner.to_world.point(Point3(0, 0, 0)), Point3(1, 1, 0));
  EXPECT_TRUE(std::holds_alternative<DielectricMaterial>(scene.materials.at(inner.material)));
  ASSERT_TRUE(inner.emission.has_value());
  EXPECT_EQ(inner.emission->radiance, RGB(1, 2, 3));
  EXPECT_TRUE(inner.reverse_orientation);
  expect_near(innermost.to_world.point(Point3(1, 0, 0)), Point3(3, 1, 0));
  EXPECT_TRUE(innermost.emission.has_value());
  EXPECT_TRUE(innermost.reverse_orientation);
  // After AttributeEnd everything is back as it was.
  expect_near(outer.to_world.point(Point3(0, 0, 0)), Point3(1, 0, 0));
  EXPECT_EQ(outer.material, -1);
  EXPECT_FALSE(outer.emission.has_value());
  EXPECT_FALSE(outer.reverse_orientation);
}

TEST(PbrtReader, DeprecatedTransformBeginEndRestoreTheTransform) {
  SceneDesc scene = read_lines({"WorldBegin", "TransformBegin", "Translate 0 0 4", "Shape \"sphere\"", "TransformEnd",
                                "Shape \"sphere\""});
  expect_near(scene.shapes.at(0).to_world.point(Point3(0, 0, 0)), Point3(0, 0, 4));
  EXPECT_TRUE(scene.shapes.at(1).to_world.is_identity());
}

TEST(PbrtReader, WorldBeginAndIdentityResetTheTransform) {
  SceneDesc scene = read_lines({"Translate 5 5 5", "WorldBegin", "Shape \"sphere\"", "Translate 1 1 1", "Identity",
                                "Shape \"sphere\""});
  EXPECT_TRUE(scene.shapes.at(0).to_world.is_identity());
  EXPECT_TRUE(scene.shapes.at(1).to_world.is_identity());
}

TEST(PbrtReader, NamedCoordinateSystems) {
  SceneDesc scene = read_lines({"LookAt 0 0 -10  0 0 0  0 1 0",
                                "Camera \"perspective\" \"float fov\" 45",
                                "WorldBegin",
                                "Translate 3 0 0",
                                "CoordinateSystem \"shelf\"",
                                "Identity",
                                "CoordSysTransform \"shelf\"",
                                "Shape \"sphere\"",
                                "CoordSysTransform \"camera\"",
                                "Shape \"sphere\"",
                                "CoordSysTransform \"world\"",
                                "Shape \"sphere\""});
  expect_near(scene.shapes.at(0).to_world.point(Point3(0, 0, 0)), Point3(3, 0, 0));
  expect_near(scene.shapes.at(1).to_world.point(Point3(0, 0, 1)), Point3(0, 0, -9));  // 1 in front of the camera
  EXPECT_TRUE(scene.shapes.at(2).to_world.is_identity());
}

TEST(PbrtReader, CameraLooksAlongLookAtWithPbrtHandedness) {
  SceneDesc scene = read_lines({"LookAt 1 2 3  1 2 4  0 1 0", "Camera \"perspective\"", "WorldBegin"});
  const Transform& camera = scene.camera.world_from_camera;
  expect_near(camera.point(Point3(0, 0, 0)), Point3(1, 2, 3));
  expect_near(camera.vector(Vec3(0, 0, 1)), Vec3(0, 0, 1));
  // Without a mirror, pbrt's left-handed camera puts world +x on the image's right.
  expect_near(camera.vector(Vec3(1, 0, 0)), Vec3(1, 0, 0));
}

// ---------------------------------------------------------------- materials, lights, shapes

TEST(PbrtReader, ReadsDiffuseAndSmoothDielectricMaterials) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "Material \"dielectric\" \"float eta\" 1.33 \"float roughness\" 0",
                                "Shape \"sphere\"",
                                "MakeNamedMaterial \"paint\" \"string type\" \"diffuse\" "
                                "\"color reflectance\" [ 0.2 0.3 0.4 ]",
                                "Shape \"sphere\"",
                                "NamedMaterial \"paint\"",
                                "Shape \"sphere\""});
  const auto& glass = std::get<DielectricMaterial>(scene.materials.at(scene.shapes.at(0).material));
  EXPECT_FLOAT_EQ(glass.ior, 1.33f);
  EXPECT_EQ(scene.shapes.at(1).material, scene.shapes.at(0).material);  // MakeNamedMaterial does not select
  EXPECT_EQ(reflectance_of(scene, scene.shapes.at(2)), RGB(0.2f, 0.3f, 0.4f));
}

TEST(PbrtReader, PointLightIsPlacedByTheTransform) {
  SceneDesc scene = read_lines({"WorldBegin", "Translate 1 0 0",
                                "LightSource \"point\" \"rgb I\" [ 1 2 3 ] \"point3 from\" [ 0 1 0 ] "
                                "\"float scale\" 2"});
  const auto& light = std::get<PointLight>(scene.lights.at(0));
  expect_near(light.position, Point3(1, 1, 0));
  EXPECT_EQ(light.intensity, RGB(2, 4, 6));
}

TEST(PbrtReader, InfiniteLightIsAConstantSky) {
  SceneDesc scene = read_lines({"WorldBegin", "LightSource \"infinite\" \"rgb L\" [ 0.5 0.25 1 ] \"float scale\" 2"});
  const auto& sky = std::get<SkyLight>(scene.lights.at(0));
  EXPECT_TRUE(sky.is_constant());
  EXPECT_EQ(sky.zenith, RGB(1, 0.5f, 2));
}

TEST(PbrtReader, AreaLightScaleAndTwoSided) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "AttributeBegin",
                                "AreaLightSource \"diffuse\" \"rgb L\" [ 1 1 2 ] \"float scale\" 3 "
                                "\"bool twosided\" true",
                                "Shape \"sphere\"",
                                "AttributeEnd"});
  ASSERT_TRUE(scene.shapes.at(0).emission.has_value());
  EXPECT_EQ(scene.shapes.at(0).emission->radiance, RGB(3, 3, 6));
  EXPECT_TRUE(scene.shapes.at(0).emission->two_sided);
}

TEST(PbrtReader, TriangleMeshWithNormalsUvsAndImplicitIndices) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "Shape \"trianglemesh\" \"point P\" [ 0 0 0  1 0 0  0 1 0 ]",
                                "    \"normal N\" [ 0 0 1  0 0 1  0 0 1 ] \"point2 uv\" [ 0 0  1 0  0 1 ]"});
  const TriangleMesh& mesh = mesh_of(scene.shapes.at(0));
  EXPECT_EQ(mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_EQ(mesh.normals.size(), 3u);
  EXPECT_EQ(mesh.normals[2], Normal3(0, 0, 1));
  ASSERT_EQ(mesh.uvs.size(), 3u);
  EXPECT_FLOAT_EQ(mesh.uvs[1].x, 1);
}

TEST(PbrtReader, AcceptsBareSingleValuesQuotedBoolsEscapesAndComments) {
  SceneDesc scene = read_lines({"Film \"rgb\" \"integer xresolution\" 640 # a comment",
                                "  \"integer yresolution\" [ 480 ] \"string filename\" \"out \\\"1\\\".exr\"",
                                "Option \"disablepixeljitter\" true",
                                "ColorSpace \"srgb\"",
                                "WorldBegin",
                                "AreaLightSource \"diffuse\" \"bool twosided\" \"true\"",
                                "Shape \"sphere\" \"float radius\" +2.5e0"});
  EXPECT_EQ(scene.film.width, 640);
  EXPECT_EQ(scene.film.height, 480);
  EXPECT_EQ(scene.film.filename, "out \"1\".exr");
  EXPECT_TRUE(scene.shapes.at(0).emission->two_sided);
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes.at(0).geometry).radius, 2.5f);
}

// pbrt-v4: the shapes keep the CTM of their definition, an instance adds the CTM at ObjectInstance.
TEST(PbrtReader, ObjectInstancesFillObjectsAndInstances) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "ObjectBegin \"pair\"",
                                "  Material \"dielectric\"",
                                "  Translate 1 0 0",
                                "  Shape \"sphere\"",
                                "  ReverseOrientation",
                                "  Shape \"sphere\" \"float radius\" 0.5",
                                "ObjectEnd",
                                "ObjectBegin \"unused\"",
                                "  Shape \"sphere\"",
                                "ObjectEnd",
                                "Shape \"sphere\" \"float radius\" 3",  // ObjectEnd restored the state
                                "Translate 0 10 0",
                                "ObjectInstance \"pair\"",
                                "Translate 0 10 0",
                                "Scale 2 2 2",
                                "ObjectInstance \"pair\""});
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_TRUE(scene.shapes[0].to_world.is_identity());
  EXPECT_EQ(scene.shapes[0].material, -1);
  EXPECT_FALSE(scene.shapes[0].reverse_orientation);
  ASSERT_EQ(scene.objects.size(), 1u);  // "unused" is never instanced
  const ObjectDesc& pair = scene.objects[0];
  EXPECT_EQ(pair.name, "pair");
  ASSERT_EQ(pair.shapes.size(), 2u);
  expect_near(pair.shapes[0].to_world.point(Point3(0, 0, 0)), Point3(1, 0, 0));
  EXPECT_FLOAT_EQ(std::get<SphereShape>(pair.shapes[1].geometry).radius, 0.5f);
  EXPECT_TRUE(std::holds_alternative<DielectricMaterial>(scene.materials.at(pair.shapes[1].material)));
  EXPECT_FALSE(pair.shapes[0].reverse_orientation);
  EXPECT_TRUE(pair.shapes[1].reverse_orientation);
  ASSERT_EQ(scene.instances.size(), 2u);
  EXPECT_EQ(scene.instances[0].object, 0);
  EXPECT_EQ(scene.instances[1].object, 0);
  // world = instance.to_world * shape.to_world
  expect_near((scene.instances[0].to_world * pair.shapes[0].to_world).point(Point3(0, 0, 0)), Point3(1, 10, 0));
  expect_near((scene.instances[1].to_world * pair.shapes[0].to_world).point(Point3(0, 0, 0)), Point3(2, 20, 0));
}

// ---------------------------------------------------------------- Include and Import

TEST(PbrtReader, IncludeResolvesNamesBesideTheNamingFile) {
  SceneDesc scene = read_pbrt_scene(kTestData / "include/main.pbrt");
  EXPECT_EQ(scene.film.width, 64);
  ASSERT_EQ(scene.shapes.size(), 3u);
  expect_near(scene.shapes[0].to_world.point(Point3(0, 0, 0)), Point3(0, 0, 5));
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[0].geometry).radius, 2);
  for (const ShapeDesc& shape : scene.shapes) EXPECT_EQ(reflectance_of(scene, shape), RGB(0.1f, 0.2f, 0.9f));
  // The same .ply named relative to the including file and relative to the top-level file.
  EXPECT_EQ(mesh_of(scene.shapes[1]).triangle_count(), 1u);
  EXPECT_EQ(mesh_of(scene.shapes[2]).positions, mesh_of(scene.shapes[1]).positions);
  // A shape declared in an included file is placed in that file.
  EXPECT_EQ(scene.shapes[0].where.to_string(), (kTestData / "include/parts/spheres.pbrt").string() + ":3:5");
}

TEST(PbrtReader, ErrorInAnIncludedFileNamesThatFileAndLine) {
  fs::path main = kTestData / "include/bad_main.pbrt";
  std::string message = error_reading(main);
  std::string included = (kTestData / "include/parts/bad.pbrt").string();
  EXPECT_TRUE(message.starts_with(included + ":3:1: unknown directive \"Shap\"")) << message;
  EXPECT_NE(message.find(main.string() + ":3:9"), std::string::npos) << message;
}

TEST(PbrtReader, IncludeCycleIsAnError) {
  std::string message = error_reading(kTestData / "include/cycle_a.pbrt");
  EXPECT_NE(message.find("cycle_b.pbrt:1:9: \"" + (kTestData / "include/cycle_a.pbrt").string() + "\" includes itself"),
            std::string::npos)
      << message;
}

// Files for the tests below, in a directory of their own.
class PbrtFiles {
 public:
  PbrtFiles() : dir_(testing::fresh_test_directory("candela_pbrt_files")) {}
  ~PbrtFiles() { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }

 private:
  fs::path dir_;
};

TEST(PbrtReader, IncludeChainsDeeperThan64FilesAreRefused) {
  PbrtFiles files;
  for (int k = 1; k < 100; ++k) files.write(fmt::format("f{}.pbrt", k), fmt::format("Include \"f{}.pbrt\"\n", k + 1));
  files.write("f100.pbrt", "Shape \"sphere\"\n");
  const fs::path main = files.write("main.pbrt", "WorldBegin\nInclude \"f1.pbrt\"\n");
  const std::string message = error_reading(main);
  // The innermost places first, the top-level file's last; the 60 between them counted, not listed.
  EXPECT_EQ(message, fmt::format("{0}f63.pbrt:1:9: files are included more than 64 deep (in the file included at "
                                 "{0}f62.pbrt:1:9, included at {0}f61.pbrt:1:9, ... 60 more Includes ..., included at "
                                 "{1}:2:9)",
                                 (main.parent_path() / "").string(), main.string()));
}

TEST(PbrtReader, AFileIncludedManyTimesOverIsRefused) {
  // 20 levels of files that each include the next twice: 2^20 files to read.
  PbrtFiles files;
  for (int k = 1; k < 20; ++k)
    files.write(fmt::format("f{}.pbrt", k), fmt::format("Include \"f{0}.pbrt\"\nInclude \"f{0}.pbrt\"\n", k + 1));
  files.write("f20.pbrt", "");
  const fs::path main = files.write("main.pbrt", "WorldBegin\nInclude \"f1.pbrt\"\n");
  const std::string message = error_reading(main);
  EXPECT_NE(message.find(": more than 100000 files are included in all (a file included many times over?)"),
            std::string::npos)
      << message;
}

TEST(PbrtReader, GzippedIncludesImportsMeshesAndScenesAreRead) {
  PbrtFiles files;
  files.write("geometry.pbrt.gz", testing::gzip_bytes("Shape \"sphere\" \"float radius\" 2\n"));
  files.write("imported.pbrt.gz", testing::gzip_bytes("Material \"conductor\"\nShape \"sphere\"\n"));
  files.write("triangle.ply.gz", testing::gzip_bytes("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                                     "property float y\nproperty float z\nelement face 1\n"
                                                     "property list uchar int vertex_indices\nend_header\n"
                                                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  const std::string text = "WorldBegin\nInclude \"geometry.pbrt.gz\"\nImport \"imported.pbrt.gz\"\n"
                           "Shape \"plymesh\" \"string filename\" \"triangle.ply.gz\"\n";
  const fs::path main = files.write("main.pbrt", text);
  const SceneDesc scene = read_pbrt_scene(main);
  ASSERT_EQ(scene.shapes.size(), 3u);
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[0].geometry).radius, 2);
  EXPECT_EQ(scene.shapes[0].where.to_string(), (main.parent_path() / "geometry.pbrt.gz").string() + ":1:1");
  EXPECT_EQ(mesh_of(scene.shapes[2]).triangle_count(), 1u);
  // The whole scene gzipped, as pbrt-v4 reads it.
  const SceneDesc gzipped = read_scene_file(files.write("main.pbrt.gz", testing::gzip_bytes(text)));
  EXPECT_EQ(gzipped.shapes.size(), 3u);

  // A damaged one is an error at the Include that names it.
  const std::string whole = testing::gzip_bytes("Shape \"sphere\"\n");
  files.write("cut.pbrt.gz", whole.substr(0, whole.size() - 3));
  const fs::path cut = files.write("cut.pbrt", "WorldBegin\nInclude \"cut.pbrt.gz\"\n");
  EXPECT_EQ(error_reading(cut), fmt::format("{}:2:9: cannot read \"{}\": gzip: the compressed data is cut short",
                                            cut.string(), (cut.parent_path() / "cut.pbrt.gz").string()));
}

TEST(PbrtReader, ImportedGraphicsStateDoesNotLeak) {
  SceneDesc scene = read_pbrt_scene(kTestData / "include/import_main.pbrt");
  ASSERT_EQ(scene.shapes.size(), 2u);
  expect_near(scene.shapes[0].to_world.point(Point3(0, 0, 0)), Point3(10, 0, 0));
  EXPECT_TRUE(std::holds_alternative<DielectricMaterial>(scene.materials.at(scene.shapes[0].material)));
  EXPECT_TRUE(scene.shapes[1].to_world.is_identity());
  EXPECT_EQ(reflectance_of(scene, scene.shapes[1]), RGB(0.5f));
}

// ---------------------------------------------------------------- text not read from a file

TEST(PbrtReader, TextReadsAsItsFileWouldWithNamesResolvedInTheBaseDirectory) {
  const fs::path file = kTestData / "include/main.pbrt";
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  SceneDesc from_file = read_pbrt_scene(file);
  SceneDesc from_text = read_pbrt_string(text.str(), "main (as text)", file.parent_path());
  EXPECT_EQ(from_text.source_file, "main (as text)");
  EXPECT_EQ(from_text.film.width, from_file.film.width);
  ASSERT_EQ(from_text.shapes.size(), 3u);
  ASSERT_EQ(from_text.shapes.size(), from_file.shapes.size());
  for (size_t i = 0; i < from_file.shapes.size(); ++i) {
    EXPECT_EQ(from_text.shapes[i].to_world, from_file.shapes[i].to_world);
    EXPECT_EQ(from_text.shapes[i].where.to_string(), from_file.shapes[i].where.to_string());
    EXPECT_EQ(reflectance_of(from_text, from_text.shapes[i]), reflectance_of(from_file, from_file.shapes[i]));
  }
  EXPECT_EQ(mesh_of(from_text.shapes[1]).positions, mesh_of(from_file.shapes[1]).positions);

  // Messages name the text by the name given, and the files it includes by their paths.
  std::string message = error_of([&](Warnings& warnings) {
    read_pbrt_string("WorldBegin\nInclude \"parts/bad.pbrt\"\n", "inline", kTestData / "include", warnings);
  });
  EXPECT_TRUE(message.starts_with((kTestData / "include/parts/bad.pbrt").string() + ":3:1: unknown directive"))
      << message;
  EXPECT_NE(message.find("(in the file included at inline:2:9)"), std::string::npos) << message;
}

TEST(PbrtReader, RecordsWhereEachEntityIsDeclared) {
  ScratchFile png("wood.png");
  SceneDesc scene = read_lines({
      "WorldBegin",
      "Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"",
      "MakeNamedMaterial \"m\" \"string type\" \"diffuse\" \"texture reflectance\" \"wood\"",
      // "scale" makes a scale texture of "wood", which this directive declares
      "  Material \"diffusetransmission\" \"texture transmittance\" \"wood\" \"float scale\" 0.5",
      "LightSource \"point\"",
      "  Shape \"sphere\"",
      "ObjectBegin \"pair\"",
      "Shape \"sphere\"",
      "ObjectEnd",
      "  ObjectInstance \"pair\"",
  });
  auto places = [](const std::vector<SourceLocation>& where) {
    std::vector<std::string> text;
    for (const SourceLocation& w : where) text.push_back(w.to_string());
    return text;
  };
  ASSERT_EQ(scene.textures.size(), 2u);
  EXPECT_EQ(places(scene.places.textures), (std::vector<std::string>{"scene.pbrt:2:1", "scene.pbrt:4:3"}));
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_EQ(places(scene.places.materials), (std::vector<std::string>{"scene.pbrt:3:1", "scene.pbrt:4:3"}));
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(places(scene.places.lights), (std::vector<std::string>{"scene.pbrt:5:1"}));
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_EQ(scene.shapes[0].where.to_string(), "scene.pbrt:6:3");
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].where.to_string(), "scene.pbrt:7:1");
  EXPECT_EQ(scene.objects[0].shapes.at(0).where.to_string(), "scene.pbrt:8:1");
  ASSERT_EQ(scene.instances.size(), 1u);
  EXPECT_EQ(scene.instances[0].where.to_string(), "scene.pbrt:10:3");
}

TEST(PbrtReader, MissingIncludeFile) {
  ScratchScene scene({"WorldBegin", "Include \"no/such/file.pbrt\""});
  std::string message = error_reading(scene.path());
  EXPECT_TRUE(message.starts_with(scene.path().string() + ":2:9: Include: cannot find \"no/such/file.pbrt\""))
      << message;
}

TEST(PbrtReader, MissingPlyFile) {
  ScratchScene scene({"WorldBegin", "Shape \"plymesh\" \"string filename\" \"missing.ply\""});
  std::string message = error_reading(scene.path());
  EXPECT_TRUE(message.starts_with(scene.path().string() + ":2:17: Shape \"plymesh\": \"filename\": cannot find "
                                  "\"missing.ply\""))
      << message;
}

TEST(PbrtReader, MissingSceneFile) {
  fs::path file = kTestData / "no-such-scene.pbrt";
  EXPECT_EQ(error_reading(file), file.string() + ": no such scene file");
}

TEST(PbrtReader, ImportBeforeWorldBegin) {
  expect_error({"Import \"x.pbrt\""}, 1, "Import", "Import is not allowed before WorldBegin");
}

// ---------------------------------------------------------------- bad input: syntax

TEST(PbrtReader, UnknownDirective) {
  expect_error({"WorldBegin", "", "  Sphere \"x\""}, 3, "Sphere", "unknown directive \"Sphere\"");
}

TEST(PbrtReader, UnknownTextureTypeIsNamed) {
  expect_error({"WorldBegin", "Texture \"t\" \"spectrum\" \"fbm\""}, 2, "\"fbm\"",
               "texture type \"fbm\" is not supported: candela has no such texture (supported: \"imagemap\", "
               "\"checkerboard\", \"scale\", \"mix\", \"constant\")");
}

TEST(PbrtReader, WorldEndIsExplainedAsPbrtV3) {
  expect_error({"WorldBegin", "WorldEnd"}, 2, "WorldEnd", "pbrt-v3");
}

TEST(PbrtReader, UnterminatedString) {
  expect_error({"WorldBegin", "Shape \"sphere", "  \"float radius\" 1"}, 2, "\"sphere", "unterminated string");
}

TEST(PbrtReader, UnknownEscapeInString) {
  expect_error({"WorldBegin", "Shape \"sph\\qere\""}, 2, "\\q", "unknown escape sequence");
}

TEST(PbrtReader, TooFewNumbersForATransform) {
  expect_error({"Translate 1 2", "WorldBegin"}, 2, "WorldBegin", "Translate: expected 3 numbers, got WorldBegin");
}

TEST(PbrtReader, TransformNeedsBrackets) {
  expect_error({"WorldBegin", "Transform 1 0 0 0"}, 2, "1", "Transform: expected \"[\"");
}

TEST(PbrtReader, SingularTransformAndZeroScale) {
  expect_error({"WorldBegin", "Transform [ 0 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 ]"}, 2, "Transform", "singular");
  expect_error({"WorldBegin", "Scale 1 0 1"}, 2, "Scale", "non-zero");
}

TEST(PbrtReader, DegenerateLookAt) {
  expect_error({"LookAt 0 0 0  0 1 0  0 1 0", "WorldBegin"}, 1, "LookAt", "parallel");
}

TEST(PbrtReader, StrayStringWhereADirectiveShouldBe) {
  expect_error({"WorldBegin", "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"", "NamedMaterial \"a\" \"b\""}, 3,
               "\"b\"", "expected a directive (such as Shape or AttributeBegin), got \"b\"");
}

// ---------------------------------------------------------------- bad input: parameters

TEST(PbrtReader, UnusedParameter) {
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" 1 \"float radiu\" 2"}, 2, "\"float radiu\"",
               "unused parameter \"float radiu\" (parameters read here: radius, zmin, zmax, phimax, alpha)");
}

TEST(PbrtReader, ParameterOfTheWrongType) {
  expect_error({"WorldBegin", "Shape \"sphere\" \"integer radius\" 2"}, 2, "\"integer radius\"",
               "parameter \"radius\" must be of type \"float\", not \"integer\"");
  expect_error({"WorldBegin", "Shape \"trianglemesh\" \"float uv\" [ 0 0 1 0 0 1 ] \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ]"},
               2, "\"float uv\"", "must be of type \"point2\"");
}

TEST(PbrtReader, WrongNumberOfValues) {
  expect_error({"Camera \"perspective\" \"float fov\" [ 30 40 ]", "WorldBegin"}, 1, "\"float fov\"",
               "\"float fov\" takes exactly 1 value, got 2");
  expect_error({"WorldBegin", "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 ]"}, 2, "\"rgb reflectance\"",
               "takes exactly 3 values, got 2");
  expect_error({"WorldBegin", "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 ]"}, 2, "\"point3 P\"",
               "needs a multiple of 3 values, got 5");
}

TEST(PbrtReader, ValuesThatDoNotMatchTheDeclaredType) {
  expect_error({"Sampler \"zsobol\" \"integer pixelsamples\" 1.5", "WorldBegin"}, 1, "1.5",
               "expects integers, got 1.5");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" \"big\""}, 2, "\"big\"",
               "expects numbers, got \"big\"");
  expect_error({"Film \"rgb\" \"string filename\" out.exr", "WorldBegin"}, 1, "out.exr", "expects quoted strings");
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\" \"bool twosided\" 1"}, 2, "1", "expects true or false");
}

TEST(PbrtReader, MalformedParameterDeclarations) {
  expect_error({"Camera \"perspective\" \"floot fov\" 30", "WorldBegin"}, 1, "\"floot",
               "unknown parameter type \"floot\"");
  expect_error({"Camera \"perspective\" \"fov\" 30", "WorldBegin"}, 1, "\"fov\"", "declared as \"type name\"");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" [ ]"}, 2, "\"float radius\"", "has no values");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" [ 1"}, 2, "[", "never closed");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" 1 \"float radius\" 2"}, 2, "\"float radius\" 2",
               "given twice");
}

TEST(PbrtReader, BadSpectrumAndTextureParameters) {
  expect_error({"WorldBegin", "Material \"dielectric\" \"spectrum eta\" \"glass-XY\""}, 2, "\"spectrum eta\"",
               "\"glass-XY\" is not one of pbrt-v4's glasses");
  expect_error({"WorldBegin", "Material \"conductor\" \"spectrum eta\" \"metal-Xx-eta\""}, 2, "\"spectrum eta\"",
               "unknown named spectrum \"metal-Xx-eta\" (spectrum files are not supported; the named spectra are "
               "\"metal-Ag-eta\"");
  expect_error({"WorldBegin", "Material \"diffuse\" \"texture reflectance\" \"checks\""}, 2, "\"texture reflectance\"",
               "no spectrum texture named \"checks\" is defined (Texture must come first)");
  expect_error({"WorldBegin", "Material \"conductor\" \"spectrum eta\" [ 400 1  300 2 ]"}, 2, "\"spectrum eta\"",
               "the wavelengths must increase");
  expect_error({"WorldBegin", "Material \"conductor\" \"spectrum k\" [ 400 1  500 ]"}, 2, "\"spectrum k\"",
               "needs a multiple of 2 values, got 3");
  expect_error({"WorldBegin", "Material \"conductor\" \"spectrum k\" [ 400 \"metal-Cu-k\" ]"}, 2, "\"metal-Cu-k\"",
               "expects one spectrum name or (wavelength, value) pairs");
  expect_error({"WorldBegin", "LightSource \"point\" \"spectrum I\" \"metal-Cu-k\""}, 2, "\"spectrum I\"",
               "\"metal-Cu-k\" is a conductor's optical constant and does not fit here");
  expect_error({"WorldBegin", "Material \"conductor\" \"spectrum eta\" \"stdillum-D65\""}, 2, "\"spectrum eta\"",
               "\"stdillum-D65\" is an illuminant spectrum and does not fit here");
  expect_error({"WorldBegin", "Material \"diffuse\" \"blackbody reflectance\" 3000"}, 2, "\"blackbody reflectance\"",
               "must be of type \"rgb\", \"spectrum\" or \"texture\", not \"blackbody\"");
  expect_error({"WorldBegin", "LightSource \"point\" \"blackbody I\" [ 3000 2 ]"}, 2, "\"blackbody I\"",
               "takes one value, the temperature in kelvin, got 2");
}

TEST(PbrtReader, ReflectanceAboveOneOrNegativeColour) {
  expect_error({"WorldBegin", "Material \"diffuse\" \"rgb reflectance\" [ 1.2 0.5 0.5 ]"}, 2, "\"rgb reflectance\"",
               "must not exceed 1");
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\" \"rgb L\" [ -1 0 0 ]"}, 2, "\"rgb L\"", "negative");
}

// ---------------------------------------------------------------- bad input: values

TEST(PbrtReader, BadSphereRadius) {
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" nan"}, 2, "nan", "expects numbers, got nan");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" -1"}, 2, "\"float radius\"",
               "Shape \"sphere\": \"radius\" must be positive, got -1");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" 0"}, 2, "\"float radius\"", "must be positive, got 0");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" 1e999"}, 2, "1e999", "expects numbers");
}

TEST(PbrtReader, PartialSphere) {
  expect_error({"WorldBegin", "Shape \"sphere\" \"float phimax\" 180"}, 2, "\"float phimax\"", "partial spheres");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float zmax\" 0.5"}, 2, "\"float zmax\"", "partial spheres");
}

TEST(PbrtReader, BadTriangleIndices) {
  const std::string points = "\"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ]";
  expect_error({"WorldBegin", "Shape \"trianglemesh\" " + points + " \"integer indices\" [ 0 1 4 ]"}, 2,
               "\"integer indices\"", "value 4 (number 3) is out of range: \"P\" has 4 points");
  expect_error({"WorldBegin", "Shape \"trianglemesh\" " + points + " \"integer indices\" [ 0 -1 2 ]"}, 2,
               "\"integer indices\"", "out of range");
  expect_error({"WorldBegin", "Shape \"trianglemesh\" " + points + " \"integer indices\" [ 0 1 2 3 ]"}, 2,
               "\"integer indices\"", "not a multiple of 3");
  expect_error({"WorldBegin", "Shape \"trianglemesh\" " + points}, 2, "Shape", "\"indices\" is required");
  expect_error({"WorldBegin", "Shape \"trianglemesh\""}, 2, "Shape", "\"P\" is required");
  const std::string one_triangle = " \"integer indices\" [ 0 1 2 ] \"normal N\" [ 0 0 1 ]";
  expect_error({"WorldBegin", "Shape \"trianglemesh\" " + points + one_triangle}, 2, "\"normal N\"",
               "one normal per point");
}

TEST(PbrtReader, BadResolution) {
  expect_error({"Film \"rgb\" \"integer xresolution\" 0", "WorldBegin"}, 1, "\"integer xresolution\"",
               "\"xresolution\" must be between 1 and 65536, got 0");
  expect_error({"Film \"rgb\" \"integer yresolution\" 70000", "WorldBegin"}, 1, "\"integer yresolution\"",
               "must be between 1 and 65536, got 70000");
  expect_error({"Film \"rgb\" \"integer xresolution\" 20000 \"integer yresolution\" 20000", "WorldBegin"}, 1,
               "\"integer yresolution\"", "20000 x 20000 is too many pixels");
}

TEST(PbrtReader, BadSampleCountsAndDepth) {
  expect_error({"Sampler \"zsobol\" \"integer pixelsamples\" 0", "WorldBegin"}, 1, "\"integer", "must be positive");
  expect_error({"Integrator \"path\" \"integer maxdepth\" -1", "WorldBegin"}, 1, "\"integer", "must not be negative");
}

// ---------------------------------------------------------------- bad input: types

TEST(PbrtReader, UnknownAndUnsupportedTypes) {
  expect_error({"WorldBegin", "Shape \"spere\""}, 2, "\"spere\"",
               "unknown shape type \"spere\" (supported: \"sphere\", \"trianglemesh\", \"plymesh\", \"disk\", "
               "\"bilinearmesh\")");
  for (std::string type : {"cylinder", "curve", "loopsubdiv"})
    expect_error({"WorldBegin", "Shape \"" + type + "\""}, 2, "\"" + type + "\"",
                 "shape type \"" + type + "\" is not supported: candela has no primitive or tessellation for it");
  expect_error({"WorldBegin", "Material \"plastic\""}, 2, "\"plastic\"", "unknown material type \"plastic\"");
  for (std::string type : {"coatedconductor", "hair", "measured", "subsurface"})
    expect_error({"WorldBegin", "Material \"" + type + "\""}, 2, "\"" + type + "\"",
                 "material type \"" + type + "\" is not supported: candela has no BSDF for it");
  expect_error({"WorldBegin", "MakeNamedMaterial \"m\" \"string type\" \"hair\""}, 2, "\"string type\"",
               "not supported");
  expect_error({"WorldBegin", "LightSource \"sun\""}, 2, "\"sun\"", "unknown light type \"sun\"");
  for (std::string type : {"goniometric", "projection"})
    expect_error({"WorldBegin", "LightSource \"" + type + "\""}, 2, "\"" + type + "\"",
                 "light type \"" + type + "\" is not supported");
  expect_error({"Integrator \"whitted\"", "WorldBegin"}, 1, "\"whitted\"", "unknown integrator type \"whitted\"");
  expect_error({"Accelerator \"octree\"", "WorldBegin"}, 1, "\"octree\"", "unknown accelerator type");
  expect_error({"WorldBegin", "AreaLightSource \"glow\""}, 2, "\"glow\"", "unknown area light type");
  expect_error({"Camera \"orthographic\"", "WorldBegin"}, 1, "\"orthographic\"", "not supported yet");
  expect_error({"Film \"gbuffer\"", "WorldBegin"}, 1, "\"gbuffer\"", "not supported yet");
}

TEST(PbrtReader, UnsupportedFeaturesOfSupportedTypes) {
  expect_error({"WorldBegin", "LightSource \"infinite\" \"string filename\" \"sky.exr\""}, 2, "\"string filename\"",
               "cannot find \"sky.exr\"");
  expect_error({"WorldBegin", "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ] \"string filename\" \"sky.exr\""}, 2,
               "\"string filename\"", "cannot be given together with \"L\"");
  expect_error({"WorldBegin", "MakeNamedMaterial \"m\" \"rgb reflectance\" [ 1 1 1 ]"}, 2, "MakeNamedMaterial",
               "missing the \"string type\" parameter");
}

// ---------------------------------------------------------------- bad input: structure

TEST(PbrtReader, NamedMaterialMustBeDefined) {
  expect_error({"WorldBegin", "NamedMaterial \"gold\""}, 2, "\"gold\"", "no material named \"gold\"");
  expect_error({"WorldBegin", "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"",
                "MakeNamedMaterial \"a\" \"string type\" \"diffuse\""},
               3, "\"a\"", "already defined");
}

TEST(PbrtReader, UnbalancedAttributeBlocks) {
  expect_error({"WorldBegin", "AttributeEnd"}, 2, "AttributeEnd", "AttributeEnd without a matching AttributeBegin");
  expect_error({"WorldBegin", "AttributeBegin", "Shape \"sphere\""}, 2, "AttributeBegin",
               "AttributeBegin is never closed");
  expect_error({"WorldBegin", "ObjectBegin \"o\"", "AttributeEnd"}, 3, "AttributeEnd",
               "does not match the open ObjectBegin");
  expect_error({"WorldBegin", "ObjectEnd"}, 2, "ObjectEnd", "without a matching ObjectBegin");
}

TEST(PbrtReader, DirectivesInTheWrongSection) {
  expect_error({"Shape \"sphere\"", "WorldBegin"}, 1, "Shape", "Shape is not allowed before WorldBegin");
  expect_error({"AttributeBegin", "AttributeEnd", "WorldBegin"}, 1, "AttributeBegin", "not allowed before WorldBegin");
  expect_error({"WorldBegin", "Camera \"perspective\""}, 2, "Camera", "Camera is not allowed after WorldBegin");
  expect_error({"WorldBegin", "WorldBegin"}, 2, "WorldBegin", "not allowed after WorldBegin");
  expect_error({"Film \"rgb\"", "Shape \"sphere\""}, 2, "Shape", "not allowed before WorldBegin");
}

TEST(PbrtReader, SceneMustReachWorldBegin) {
  // The error is at the end of the text: line 3, after the last newline.
  EXPECT_EQ(error_reading_text({"Film \"rgb\"", "# no world"}),
            kSceneName + ":3:1: the scene ends before WorldBegin; the shapes and lights must follow a WorldBegin");
}

TEST(PbrtReader, ObjectInstancingErrors) {
  expect_error({"WorldBegin", "ObjectInstance \"tree\""}, 2, "\"tree\"", "no object named \"tree\"");
  expect_error({"WorldBegin", "ObjectBegin \"a\"", "ObjectBegin \"b\""}, 3, "ObjectBegin", "cannot nest");
  expect_error({"WorldBegin", "ObjectBegin \"a\"", "AreaLightSource \"diffuse\"", "Shape \"sphere\""}, 4, "Shape",
               "area lights in object instances are not supported");
  expect_error({"WorldBegin", "CoordSysTransform \"nowhere\""}, 2, "\"nowhere\"", "no coordinate system named");
}


TEST(PbrtReader, ShapesInsideObjectsCannotMove) {
  expect_error({"WorldBegin", "ObjectBegin \"a\"", "ActiveTransform EndTime", "Translate 1 0 0", "Shape \"sphere\""},
               5, "Shape", "shapes of an object cannot move");
}

TEST(PbrtReader, LightsCannotBeDefinedInsideObjects) {
  expect_error({"WorldBegin", "ObjectBegin \"a\"", "LightSource \"point\""}, 3, "LightSource",
               "lights cannot be part of an object definition");
}

// ---------------------------------------------------------------- samplers and integrators

TEST(PbrtReader, SobolAndOtherLowDiscrepancySamplersBecomeZSobol) {
  for (std::string type : {"sobol", "halton", "pmj02bn", "paddedsobol"}) {
    SCOPED_TRACE(type);
    std::vector<std::string> lines = {"Sampler \"" + type + "\" \"integer pixelsamples\" 32", "WorldBegin"};
    expect_warning(lines, 1, "\"" + type + "\"", type + ": using candela's zsobol sampler");
    SceneDesc scene = read_lines(lines);
    EXPECT_EQ(scene.settings.sampler.type, SamplerType::ZSobol);
    EXPECT_EQ(scene.settings.spp, 32);
  }
  expect_warning({"Sampler \"sobol\"", "WorldBegin"}, 1, "\"sobol\"",
                 "sobol: using candela's zsobol sampler (same Owen-scrambled Sobol' points, Morton-ordered)");
  EXPECT_EQ(read_lines({"Sampler \"halton\" \"string randomization\" \"owen\"", "WorldBegin"}).settings.spp, 16);
}

TEST(PbrtReader, BdptAndMltAreCandelasOwn) {
  SceneDesc bdpt = read_lines({"Integrator \"bdpt\" \"integer maxdepth\" 7", "WorldBegin"});
  EXPECT_EQ(bdpt.settings.integrator, "bdpt");
  EXPECT_EQ(bdpt.settings.max_depth, 7);
  expect_warning({"Integrator \"bdpt\" \"bool visualizestrategies\" true", "WorldBegin"}, 1, "\"bool visualizestrategies\"",
                 "--bdpt-strategies");
  // MLT's mutations per pixel are its sample count, whatever the Sampler says before or after.
  for (bool sampler_first : {false, true}) {
    std::vector<std::string> lines = {"Integrator \"mlt\" \"integer maxdepth\" 4 \"integer mutationsperpixel\" 40 "
                                      "\"integer bootstrapsamples\" 500 \"integer chains\" 20 "
                                      "\"float largestepprobability\" 0.25 \"float sigma\" 0.02",
                                      "WorldBegin"};
    lines.insert(lines.begin() + (sampler_first ? 0 : 1), "Sampler \"independent\" \"integer pixelsamples\" 8");
    SceneDesc mlt = read_lines(lines);
    EXPECT_EQ(mlt.settings.integrator, "mlt");
    EXPECT_EQ(mlt.settings.max_depth, 4);
    EXPECT_EQ(mlt.settings.spp, 40);
    EXPECT_EQ(mlt.settings.mlt.bootstrap, 500);
    EXPECT_EQ(mlt.settings.mlt.chains, 20);
    EXPECT_FLOAT_EQ(mlt.settings.mlt.large_step, 0.25f);
    EXPECT_FLOAT_EQ(mlt.settings.mlt.sigma, 0.02f);
  }
  EXPECT_EQ(read_lines({"Integrator \"mlt\"", "WorldBegin"}).settings.spp, 100);  // pbrt's default
  EXPECT_THROW(read_lines({"Integrator \"mlt\" \"float sigma\" 0", "WorldBegin"}), SceneError);
  EXPECT_THROW(read_lines({"Integrator \"mlt\" \"float largestepprobability\" 1.5", "WorldBegin"}), SceneError);
  EXPECT_THROW(read_lines({"Integrator \"mlt\" \"integer chains\" 0", "WorldBegin"}), SceneError);
}

TEST(PbrtReader, OtherPbrtIntegratorsAreRenderedWithOneThatConvergesToTheSameImage) {
  EXPECT_TRUE(read_warned({"Integrator \"path\" \"integer maxdepth\" 9", "WorldBegin"}).warnings.empty());
  for (std::string type : {"sppm", "lightpath", "randomwalk", "simplepath"}) {
    SCOPED_TRACE(type);
    std::vector<std::string> lines = {"Integrator \"" + type + "\" \"integer maxdepth\" 9", "WorldBegin"};
    expect_warning(lines, 1, "\"" + type + "\"",
                   "Integrator \"" + type + "\": using candela's path integrator with maxdepth 9");
    SceneDesc scene = read_lines(lines);
    EXPECT_EQ(scene.settings.integrator, "path");
    EXPECT_EQ(scene.settings.max_depth, 9);
  }
  Warned volpath = read_warned({"Integrator \"volpath\" \"integer maxdepth\" 7", "WorldBegin"});
  EXPECT_TRUE(volpath.warnings.empty()) << joined(volpath.warnings);
  EXPECT_EQ(volpath.scene.settings.integrator, "volpath");
  EXPECT_EQ(volpath.scene.settings.max_depth, 7);
  expect_warning({"Integrator \"simplevolpath\"", "WorldBegin"}, 1, "\"simplevolpath\"",
                 "Integrator \"simplevolpath\": using candela's volpath integrator with maxdepth 5");
  EXPECT_EQ(read_lines({"Integrator \"simplevolpath\"", "WorldBegin"}).settings.integrator, "volpath");
  EXPECT_THROW(read_lines({"Integrator \"ambientocclusion\"", "WorldBegin"}), SceneError);
  Warned sppm = read_warned({"Integrator \"sppm\" \"integer photonsperiteration\" 1000 \"float radius\" 0.1",
                             "WorldBegin"});
  ASSERT_EQ(sppm.warnings.size(), 3u) << joined(sppm.warnings);
  EXPECT_NE(sppm.warnings[0].find("\"photonsperiteration\" is ignored"), std::string::npos) << sppm.warnings[0];
  Warned regularized = read_warned({"Integrator \"path\" \"bool regularize\" true", "WorldBegin"});
  ASSERT_EQ(regularized.warnings.size(), 1u);
  EXPECT_NE(regularized.warnings[0].find(":1:19: warning: Integrator \"path\": \"regularize\" is ignored"),
            std::string::npos)
      << regularized.warnings[0];
  expect_error({"Integrator \"bdpt\" \"bool visualizestrategy\" true", "WorldBegin"}, 1, "\"bool visualizestrategy\"",
               "unused parameter");
}

TEST(PbrtReader, ColorSpaceFilmAndAcceleratorOptions) {
  EXPECT_TRUE(read_warned({"ColorSpace \"srgb\"", "Accelerator \"bvh\" \"integer maxnodeprims\" 4", "WorldBegin"})
                  .warnings.empty());
  expect_warning({"ColorSpace \"aces2065-1\"", "WorldBegin"}, 1, "\"aces2065-1\"", "reads every colour as linear sRGB");
  expect_warning({"Film \"rgb\" \"float maxcomponentvalue\" 10", "WorldBegin"}, 1, "\"float maxcomponentvalue\"",
                 "\"maxcomponentvalue\" is ignored");
  expect_error({"WorldBegin", "Accelerator \"bvh\""}, 2, "Accelerator", "not allowed after WorldBegin");
}

}  // namespace
}  // namespace candela
