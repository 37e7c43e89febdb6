// Tests of the pbrt-v4 reader on valid scenes: defaults, render options, camera, transforms, basic shapes, lights.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/pbrt_reader.h"
#include "candela/description/scene_desc.h"
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
  SceneDesc scene = read_lines({"Integrator \"randomwalk\" \"integer maxdepth\" 7",
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
  // A likely typo gets the nearest name (of a type, of a parameter read there).
  expect_error({"Sampler \"zsobl\"", "WorldBegin"}, 1, "\"zsobl\"", "unknown sampler type \"zsobl\" (did you mean \"zsobol\"?)");
  expect_error({"Sampler \"zsobol\" \"integer pixelsample\" 4", "WorldBegin"}, 1, "\"integer pixelsample\"",
               "unused parameter \"integer pixelsample\" (did you mean \"pixelsamples\"?)");
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
  FilterDesc sinc = filter_of("PixelFilter \"sinc\" \"float tau\" 2");
  EXPECT_EQ(sinc.type, FilterType::LanczosSinc);
  expect_radius(sinc, 4, 4);  // pbrt-v4's default
  EXPECT_FLOAT_EQ(sinc.sinc_tau, 2);
  EXPECT_FLOAT_EQ(filter_of("PixelFilter \"sinc\"").sinc_tau, 3);
}

TEST(PbrtReader, BadPixelFilters) {
  expect_error({"PixelFilter \"tent\"", "WorldBegin"}, 1, "\"tent\"",
               "unknown pixel filter type \"tent\" (supported: \"box\", \"triangle\", \"gaussian\", \"mitchell\", "
               "\"sinc\")");
  expect_error({"PixelFilter \"sinc\" \"float tau\" 0", "WorldBegin"}, 1, "\"float tau\"", "\"tau\" must be positive");
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

// An orthographic camera's screen spans [-1, 1] on the film's shorter axis unless a screenwindow
// says otherwise; a perspective camera keeps its window as given.
TEST(PbrtReader, OrthographicCamerasAndScreenWindows) {
  SceneDesc wide = read_lines({"Camera \"orthographic\"", "Film \"rgb\" \"integer xresolution\" 200 "
                               "\"integer yresolution\" 100", "WorldBegin"});
  EXPECT_EQ(wide.camera.projection, Projection::Orthographic);
  EXPECT_EQ(wide.camera.screen_window, (std::array<float, 4>{-2, 2, -1, 1}));
  SceneDesc tall = read_lines({"Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 200",
                               "Camera \"orthographic\"", "WorldBegin"});
  EXPECT_EQ(tall.camera.screen_window, (std::array<float, 4>{-1, 1, -2, 2}));
  SceneDesc given = read_lines({"Camera \"orthographic\" \"float screenwindow\" [-2 2 -1.5 1.5]", "WorldBegin"});
  EXPECT_EQ(given.camera.screen_window, (std::array<float, 4>{-2, 2, -1.5f, 1.5f}));
  SceneDesc shifted =
      read_lines({"Camera \"perspective\" \"float fov\" 38 \"float screenwindow\" [-0.5 1 -0.5 0.5]", "WorldBegin"});
  EXPECT_EQ(shifted.camera.projection, Projection::Perspective);
  EXPECT_EQ(shifted.camera.screen_window, (std::array<float, 4>{-0.5f, 1, -0.5f, 0.5f}));
  EXPECT_FALSE(read_lines({"Camera \"perspective\"", "WorldBegin"}).camera.screen_window);
  expect_error({"Camera \"orthographic\" \"float screenwindow\" [1 -1 0 1]", "WorldBegin"}, 1,
               "\"float screenwindow\"", "must have x0 < x1 and y0 < y1");
  expect_error({"Camera \"orthographic\" \"float screenwindow\" [-1 1 0]", "WorldBegin"}, 1,
               "\"float screenwindow\"", "needs 4 values");
  expect_error({"Camera \"orthographic\" \"float lensradius\" 0.1", "WorldBegin"}, 1, "\"float lensradius\"",
               "depth of field with an orthographic camera is not supported");
  expect_error({"Camera \"orthographic\" \"float fov\" 30", "WorldBegin"}, 1, "\"float fov\"", "unused");
}

// pbrt-v4's cropwindow and pixelbounds: the film is that part of the image, the screen window narrowed
// to it, so that its pixels see what the full image's pixels there see.
TEST(PbrtReader, CropWindowsAndPixelBoundsNarrowTheFilm) {
  SceneDesc crop = read_lines({"Camera \"perspective\" \"float fov\" 38",
                               "Film \"rgb\" \"integer xresolution\" 128 \"integer yresolution\" 96 "
                               "\"float cropwindow\" [0.25 0.75 0.2 0.8]", "WorldBegin"});
  EXPECT_EQ(crop.film.width, 64);  // x: ceil(32) to ceil(96)
  EXPECT_EQ(crop.film.height, 57);  // y: ceil(19.2) = 20 to ceil(76.8) = 77
  ASSERT_TRUE(crop.film.crop);
  EXPECT_EQ(crop.film.crop->x, 32);
  EXPECT_EQ(crop.film.crop->y, 20);
  EXPECT_EQ(crop.film.crop->full_width, 128);
  EXPECT_EQ(crop.film.crop->full_height, 96);
  // The full window is [-4/3, 4/3] x [-1, 1]; rows go down while screen y goes up.
  ASSERT_TRUE(crop.camera.screen_window);
  const auto [x0, x1, y0, y1] = *crop.camera.screen_window;
  EXPECT_FLOAT_EQ(x0, -4.0f / 3 + 8.0f / 3 * 32 / 128);
  EXPECT_FLOAT_EQ(x1, -4.0f / 3 + 8.0f / 3 * 96 / 128);
  EXPECT_FLOAT_EQ(y0, 1 - 2.0f * 77 / 96);
  EXPECT_FLOAT_EQ(y1, 1 - 2.0f * 20 / 96);
  SceneDesc bounds = read_lines({"Film \"rgb\" \"integer xresolution\" 128 \"integer yresolution\" 96 "
                                 "\"integer pixelbounds\" [10 90 20 70]", "WorldBegin"});
  EXPECT_EQ(bounds.film.width, 80);
  EXPECT_EQ(bounds.film.height, 50);
  EXPECT_EQ(bounds.film.crop->x, 10);
  EXPECT_EQ(bounds.film.crop->y, 20);
  SceneDesc whole = read_lines({"Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32 "
                                "\"float cropwindow\" [0 1 0 1]", "WorldBegin"});
  EXPECT_FALSE(whole.film.crop);
  EXPECT_FALSE(whole.camera.screen_window);
  expect_error({"Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32 \"integer pixelbounds\" "
                "[10 90 0 10]", "WorldBegin"}, 1, "\"integer pixelbounds\"", "is not a non-empty part of the 64 x 32 image");
  expect_error({"Film \"rgb\" \"float cropwindow\" [0.5 0.5 0 1]", "WorldBegin"}, 1, "\"float cropwindow\"",
               "holds no pixel");
  expect_error({"Film \"rgb\" \"float cropwindow\" [0 1 0]", "WorldBegin"}, 1, "\"float cropwindow\"",
               "takes 4 values");
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

}  // namespace
}  // namespace candela
