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
#include "candela/scene/description.h"
#include "candela/spectral/cie.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

const fs::path kSharedCornellBox = fs::path(CANDELA_SHARED_DIR) / "scenes/cornell-box/cornell-box.pbrt";
const fs::path kRepoCornellBox = fs::path(CANDELA_SOURCE_DIR) / "scenes/cornell-box.pbrt";
const fs::path kTestData = fs::path(CANDELA_SOURCE_DIR) / "tests/data/pbrt";

// The directory of the scratch scenes and files of this test process.
fs::path scratch_dir() { return fs::temp_directory_path() / fmt::format("candela_pbrt_reader_{}", getpid()); }

// A scene written to its own file, for the tests whose point is reading files; named after the test
// so that tests can run in parallel processes; the file is removed again when the object goes out of
// scope.
class ScratchScene {
 public:
  explicit ScratchScene(const std::vector<std::string>& lines) {
    static int counter = 0;
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path dir = scratch_dir();
    fs::create_directories(dir);
    path_ = dir / fmt::format("{}_{}.pbrt", test->name(), counter++);
    std::ofstream out(path_);
    for (const std::string& line : lines) out << line << '\n';
  }
  ScratchScene(const ScratchScene&) = delete;
  ScratchScene& operator=(const ScratchScene&) = delete;
  ~ScratchScene() {
    std::error_code ignored;
    fs::remove(path_, ignored);
    fs::remove(path_.parent_path(), ignored);  // only succeeds once the directory is empty
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// An empty file beside the scratch scenes, for parameters that name files the reader only looks up
// (images); removed again when the object goes out of scope.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& name) : path_(scratch_dir() / name) {
    fs::create_directories(path_.parent_path());
    std::ofstream out(path_);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() {
    std::error_code ignored;
    fs::remove(path_, ignored);
    fs::remove(path_.parent_path(), ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

// The scenes of most tests are text, read with read_pbrt_string: this is their name in messages,
// and the files they name (ScratchFile) are looked up in scratch_dir().
const std::string kSceneName = "scene.pbrt";

SceneDesc read_lines(const std::vector<std::string>& lines) {
  std::vector<std::string> warnings;
  return read_pbrt_string(joined(lines), kSceneName, scratch_dir(), warnings);
}

struct Warned {
  SceneDesc scene;
  std::vector<std::string> warnings;
};

Warned read_warned(const std::vector<std::string>& lines) {
  Warned result;
  result.scene = read_pbrt_string(joined(lines), kSceneName, scratch_dir(), result.warnings);
  return result;
}

// The message of the error `read` throws, or "" when it reads without one.
template <typename Read>
std::string error_of(Read read) {
  try {
    std::vector<std::string> warnings;
    read(warnings);
  } catch (const SceneError& error) {
    return error.what();
  }
  return "";
}

std::string error_reading(const fs::path& file) {
  return error_of([&](std::vector<std::string>& warnings) { read_pbrt_scene(file, warnings); });
}

std::string error_reading_text(const std::vector<std::string>& lines) {
  return error_of([&](std::vector<std::string>& warnings) {
    read_pbrt_string(joined(lines), kSceneName, scratch_dir(), warnings);
  });
}

// Expects the scene to fail with a message that starts "<file>:<line>:<column>: ", where the column
// is that of `marker` in the line, and that contains `fragment`.
void expect_error(const std::vector<std::string>& lines, int line, std::string_view marker, std::string_view fragment) {
  size_t column = lines.at(line - 1).find(marker);
  ASSERT_NE(column, std::string::npos) << "marker " << marker << " is not in line " << line;
  std::string message = error_reading_text(lines);
  std::string place = fmt::format("{}:{}:{}: ", kSceneName, line, column + 1);
  EXPECT_TRUE(message.starts_with(place)) << "expected the error at " << place << "\ngot: " << message;
  EXPECT_NE(message.find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << message;
}

// Expects the scene to read with exactly one warning, "<file>:<line>:<column>: warning: ...", where
// the column is that of `marker` in the line, containing `fragment`.
void expect_warning(const std::vector<std::string>& lines, int line, std::string_view marker,
                    std::string_view fragment) {
  size_t column = lines.at(line - 1).find(marker);
  ASSERT_NE(column, std::string::npos) << "marker " << marker << " is not in line " << line;
  std::vector<std::string> warnings = read_warned(lines).warnings;
  ASSERT_EQ(warnings.size(), 1u) << joined(warnings);
  std::string place = fmt::format("{}:{}:{}: warning: ", kSceneName, line, column + 1);
  EXPECT_TRUE(warnings[0].starts_with(place)) << "expected the warning at " << place << "\ngot: " << warnings[0];
  EXPECT_NE(warnings[0].find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << warnings[0];
}

void expect_near(const Vec3& actual, const Vec3& expected, float tolerance = 1e-4f) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

const TriangleMesh& mesh_of(const ShapeDesc& shape) { return std::get<MeshShape>(shape.geometry).mesh; }

RGB reflectance_of(const SceneDesc& scene, const ShapeDesc& shape) {
  return std::get<DiffuseMaterial>(scene.materials.at(shape.material)).reflectance.value;
}

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
  EXPECT_EQ(scene.settings.light_selection, LightSelection::Power);
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

TEST(PbrtReader, LightSamplerPowerAndBvhChooseLightsByPower) {
  for (std::string name : {"power", "bvh"}) {
    SceneDesc scene = read_lines({"Integrator \"path\" \"string lightsampler\" \"" + name + "\"", "WorldBegin"});
    EXPECT_EQ(scene.settings.light_selection, LightSelection::Power) << name;
  }
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
  std::string message = error_of([&](std::vector<std::string>& warnings) {
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

// ---------------------------------------------------------------- the Bitterli scenes

const fs::path kBitterli = fs::path(CANDELA_SHARED_DIR) / "scenes/bitterli";

Warned read_bitterli(std::string_view name) {
  Warned result;
  result.scene = read_pbrt_scene(kBitterli / name / "scene-v4.pbrt", result.warnings);
  return result;
}

size_t emitter_count(const SceneDesc& scene) {
  return std::count_if(scene.shapes.begin(), scene.shapes.end(), [](const ShapeDesc& s) { return s.emission; });
}

void expect_sobol_warning(const Warned& read, int line) {
  ASSERT_FALSE(read.warnings.empty());
  EXPECT_NE(read.warnings[0].find(fmt::format("scene-v4.pbrt:{}:9: warning: sobol: using candela's zsobol sampler "
                                              "(same Owen-scrambled Sobol' points, Morton-ordered)",
                                              line)),
            std::string::npos)
      << read.warnings[0];
}

TEST(PbrtReaderBitterli, CornellBox) {
  Warned read = read_bitterli("cornell-box");
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(read.warnings.size(), 1u) << joined(read.warnings);
  expect_sobol_warning(read, 3);
  EXPECT_EQ(scene.shapes.size(), 8u);
  EXPECT_EQ(emitter_count(scene), 1u);
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_TRUE(scene.textures.empty());
  EXPECT_EQ(scene.materials.size(), 8u);
  EXPECT_EQ(scene.settings.integrator, "path");
  EXPECT_EQ(scene.settings.max_depth, 65);
  EXPECT_EQ(scene.settings.spp, 512);
  EXPECT_EQ(scene.settings.sampler.type, SamplerType::ZSobol);
  EXPECT_EQ(scene.settings.filter.type, FilterType::Gaussian);
  EXPECT_EQ(scene.film.width, 1024);
  EXPECT_FLOAT_EQ(scene.camera.fov_degrees, 19.5f);
  expect_near(scene.camera.world_from_camera.point(Point3(0, 0, 0)), Point3(0, 1, 6.8f));
  const ShapeDesc& light = scene.shapes.back();
  ASSERT_TRUE(light.emission.has_value());
  EXPECT_EQ(light.emission->radiance, RGB(17, 12, 4));
  EXPECT_EQ(reflectance_of(scene, light), RGB(0.0f));
  EXPECT_EQ(reflectance_of(scene, scene.shapes[3]), RGB(0.14f, 0.45f, 0.091f));  // the right wall
}

TEST(PbrtReaderBitterli, VeachMis) {
  Warned read = read_bitterli("veach-mis");
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(read.warnings.size(), 1u) << joined(read.warnings);
  expect_sobol_warning(read, 4);
  EXPECT_EQ(scene.shapes.size(), 9u);
  EXPECT_EQ(emitter_count(scene), 3u);
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_EQ(scene.materials.size(), 6u);
  EXPECT_EQ(scene.settings.max_depth, 3);
  EXPECT_EQ(scene.settings.spp, 64);
  EXPECT_EQ(scene.settings.filter.type, FilterType::Tent);
  EXPECT_FLOAT_EQ(scene.settings.filter.radius.x, 1);
  const float radii[3] = {1, 0.5f, 0.05f};
  const float radiance[3] = {7.599088f, 30.396353f, 3039.6353f};
  int sphere = 0;
  for (const ShapeDesc& shape : scene.shapes) {
    if (!shape.emission) continue;
    SCOPED_TRACE(shape.name);
    EXPECT_FLOAT_EQ(std::get<SphereShape>(shape.geometry).radius, radii[sphere]);
    EXPECT_FLOAT_EQ(shape.emission->radiance.g, radiance[sphere]);
    ++sphere;
  }
  const auto& smooth = std::get<ConductorMaterial>(scene.materials.at(scene.shapes[0].material));
  EXPECT_EQ(smooth.eta.value, RGB(0.200438f, 0.924033f, 1.102212f));
  EXPECT_EQ(smooth.k.value, RGB(3.912949f, 2.452848f, 2.142188f));
  EXPECT_FLOAT_EQ(smooth.roughness.u.value, 0.01f);
  EXPECT_FLOAT_EQ(smooth.roughness.v.value, 0.01f);
  EXPECT_FALSE(smooth.roughness.remap);
  EXPECT_FALSE(smooth.reflectance.has_value());
}

TEST(PbrtReaderBitterli, VeachAjar) {
  Warned read = read_bitterli("veach-ajar");
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(read.warnings.size(), 4u) << joined(read.warnings);  // sobol, three "trilinear" filters
  expect_sobol_warning(read, 4);
  for (int i = 1; i < 4; ++i)
    EXPECT_NE(read.warnings[i].find("filter \"trilinear\" is read as \"bilinear\""), std::string::npos);
  EXPECT_EQ(scene.shapes.size(), 22u);
  EXPECT_EQ(emitter_count(scene), 1u);
  EXPECT_EQ(scene.materials.size(), 13u);
  ASSERT_EQ(scene.textures.size(), 3u);
  const char* files[3] = {"landscape-with-a-lake.tga", "Good Textures_005844.tga", "cherry-wood-texture.tga"};
  for (int i = 0; i < 3; ++i) {
    const auto& texture = std::get<ImageTexture>(scene.textures[i]);
    EXPECT_TRUE(fs::is_regular_file(texture.filename)) << texture.filename;
    EXPECT_EQ(fs::path(texture.filename).filename(), files[i]);
    // pbrt-v4 reads 8-bit .tga files as sRGB (the reference render agrees), so: sRGB for 8-bit files.
    EXPECT_EQ(texture.encoding, ColorEncoding::Auto);
    EXPECT_TRUE(texture.bilinear);
  }
  // "Landscape" (the first MakeNamedMaterial) is the diffuse reflectance of texture 0.
  const auto& landscape = std::get<DiffuseMaterial>(scene.materials[0]);
  EXPECT_EQ(landscape.reflectance.texture, 0);
  const auto& door = std::get<DiffuseMaterial>(scene.materials[3]);
  EXPECT_EQ(door.reflectance.texture, 2);
  const auto& handle = std::get<ConductorMaterial>(scene.materials[2]);
  EXPECT_EQ(handle.eta.value, RGB(1.65746f, 0.880369f, 0.521229f));
  EXPECT_EQ(handle.k.value, RGB(9.223869f, 6.269523f, 4.837001f));
  EXPECT_FLOAT_EQ(handle.roughness.u.value, 0.25f);
  const auto& glass = std::get<DielectricMaterial>(scene.materials[11]);
  EXPECT_FLOAT_EQ(glass.ior, 1.5f);
  EXPECT_TRUE(scene.shapes[0].emission.has_value());
  EXPECT_EQ(scene.shapes[0].emission->radiance, RGB(1000.0f));
  // The shapes with Transform blocks carry them.
  expect_near(scene.shapes[3].to_world.point(Point3(0, 0, 0)), Point3(2.3f, 0, 0));
}

TEST(PbrtReaderBitterli, VeachBidir) {
  Warned read = read_bitterli("veach-bidir");
  const SceneDesc& scene = read.scene;
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  EXPECT_EQ(scene.settings.integrator, "bdpt");
  EXPECT_EQ(scene.settings.max_depth, 7);
  EXPECT_EQ(scene.settings.sampler.type, SamplerType::Independent);
  EXPECT_EQ(scene.settings.spp, 64);
  EXPECT_EQ(scene.shapes.size(), 14u);
  EXPECT_EQ(emitter_count(scene), 2u);
  EXPECT_EQ(scene.materials.size(), 4u);
  EXPECT_EQ(scene.shapes[2].material, 0);  // the emitters keep the "Diffuse" named before their block
  EXPECT_EQ(scene.shapes[3].emission->radiance, RGB(12048.179f, 8605.842f, 6196.206f));
  const auto& lamp = std::get<ConductorMaterial>(scene.materials[2]);
  EXPECT_EQ(lamp.eta.value, RGB(2.865601f, 2.119182f, 1.940077f));
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

TEST(PbrtReader, OtherPbrtIntegratorsAreRenderedWithThePathIntegrator) {
  EXPECT_TRUE(read_warned({"Integrator \"path\" \"integer maxdepth\" 9", "WorldBegin"}).warnings.empty());
  for (std::string type : {"sppm", "lightpath", "randomwalk", "simplepath", "simplevolpath"}) {
    SCOPED_TRACE(type);
    std::vector<std::string> lines = {"Integrator \"" + type + "\" \"integer maxdepth\" 9", "WorldBegin"};
    expect_warning(lines, 1, "\"" + type + "\"",
                   "Integrator \"" + type + "\": using candela's path integrator with maxdepth 9");
    SceneDesc scene = read_lines(lines);
    EXPECT_EQ(scene.settings.integrator, "path");
    EXPECT_EQ(scene.settings.max_depth, 9);
  }
  expect_warning({"Integrator \"volpath\"", "WorldBegin"}, 1, "\"volpath\"",
                 "without participating media (which candela does not render) it is the same integrator");
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

// ---------------------------------------------------------------- materials

TEST(PbrtReader, DiffuseReflectanceFromRgbSpectrumOrTexture) {
  ScratchFile image("wood.png");
  SceneDesc scene = read_lines({"WorldBegin",
                                "Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"",
                                "Material \"diffuse\" \"texture reflectance\" \"wood\"",
                                "Material \"diffuse\" \"spectrum reflectance\" [ 300 0.5  800 0.5 ]",
                                "Material \"diffuse\" \"rgb reflectance\" [ 0.1 0.2 0.3 ]"});
  ASSERT_EQ(scene.materials.size(), 3u);
  const auto& textured = std::get<DiffuseMaterial>(scene.materials[0]);
  EXPECT_FALSE(textured.reflectance.is_constant());
  EXPECT_EQ(textured.reflectance.texture, 0);
  const auto& flat = std::get<DiffuseMaterial>(scene.materials[1]);
  expect_near(Vec3(flat.reflectance.value.r, flat.reflectance.value.g, flat.reflectance.value.b), Vec3(0.5f));
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials[2]).reflectance.value, RGB(0.1f, 0.2f, 0.3f));
}

TEST(PbrtReader, ConductorMaterials) {
  SceneDesc scene = read_lines(
      {"WorldBegin",
       "Texture \"rough\" \"float\" \"scale\" \"float tex\" 0.5 \"float scale\" 0.2",
       "Material \"conductor\"",
       "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.2",
       "Material \"conductor\" \"rgb eta\" [ 0.2 0.9 1.1 ] \"rgb k\" [ 3.9 2.4 2.1 ] \"float uroughness\" 0.01 "
       "\"float vroughness\" 0.05 \"bool remaproughness\" false",
       "Material \"conductor\" \"rgb reflectance\" [ 0.9 0.6 0.3 ] \"texture roughness\" \"rough\""});
  ASSERT_EQ(scene.materials.size(), 4u);
  const auto& copper = std::get<ConductorMaterial>(scene.materials[0]);
  EXPECT_EQ(copper.eta.value, ConductorMaterial{}.eta.value);  // pbrt-v4's default "metal-Cu-eta"
  EXPECT_EQ(copper.k.value, ConductorMaterial{}.k.value);
  EXPECT_FALSE(copper.reflectance.has_value());
  EXPECT_FLOAT_EQ(copper.roughness.u.value, 0);
  EXPECT_TRUE(copper.roughness.remap);  // pbrt-v4's default
  const auto& gold = std::get<ConductorMaterial>(scene.materials[1]);
  EXPECT_EQ(gold.eta.value, RGB(0.143119f, 0.374957f, 1.442479f));
  EXPECT_EQ(gold.k.value, RGB(3.983160f, 2.385721f, 1.603215f));
  EXPECT_FLOAT_EQ(gold.roughness.u.value, 0.2f);
  EXPECT_FLOAT_EQ(gold.roughness.v.value, 0.2f);
  const auto& anisotropic = std::get<ConductorMaterial>(scene.materials[2]);
  EXPECT_EQ(anisotropic.eta.value, RGB(0.2f, 0.9f, 1.1f));
  EXPECT_FLOAT_EQ(anisotropic.roughness.u.value, 0.01f);
  EXPECT_FLOAT_EQ(anisotropic.roughness.v.value, 0.05f);
  EXPECT_FALSE(anisotropic.roughness.remap);
  const auto& artist = std::get<ConductorMaterial>(scene.materials[3]);
  ASSERT_TRUE(artist.reflectance.has_value());
  EXPECT_EQ(artist.reflectance->value, RGB(0.9f, 0.6f, 0.3f));
  EXPECT_EQ(artist.roughness.u.texture, 0);
  EXPECT_EQ(artist.roughness.v.texture, 0);
  expect_error({"WorldBegin", "Material \"conductor\" \"rgb eta\" [ 1 1 1 ] \"rgb reflectance\" [ 0.5 0.5 0.5 ]"}, 2,
               "\"rgb reflectance\"", "cannot be given together with \"eta\"");
  expect_error({"WorldBegin", "Material \"conductor\" \"float roughness\" -0.1"}, 2, "\"float roughness\"",
               "must not be negative");
}

TEST(PbrtReader, DielectricMaterials) {
  Warned read = read_warned({"WorldBegin",
                             "Material \"dielectric\" \"float eta\" 1.33 \"float roughness\" 0.1",
                             "Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"",
                             "Material \"dielectric\" \"spectrum eta\" [ 300 1.6  800 1.4 ]",
                             "Material \"dielectric\" \"rgb eta\" [ 1.4 1.5 1.6 ]",
                             "Material \"dielectric\" \"float uroughness\" 0.1 \"float vroughness\" 0.3 "
                             "\"bool remaproughness\" false",
                             "Material \"dielectric\""});
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(scene.materials.size(), 6u);
  const auto& water = std::get<DielectricMaterial>(scene.materials[0]);
  EXPECT_FLOAT_EQ(water.ior, 1.33f);
  EXPECT_FLOAT_EQ(water.roughness.u.value, 0.1f);
  EXPECT_TRUE(water.roughness.remap);
  EXPECT_NEAR(std::get<DielectricMaterial>(scene.materials[1]).ior, 1.5185f, 1e-4f);  // BK7 at 550 nm
  EXPECT_NEAR(std::get<DielectricMaterial>(scene.materials[2]).ior, 1.5f, 1e-5f);
  EXPECT_FLOAT_EQ(std::get<DielectricMaterial>(scene.materials[3]).ior, 1.5f);
  const auto& rough = std::get<DielectricMaterial>(scene.materials[4]);
  EXPECT_FLOAT_EQ(rough.roughness.v.value, 0.3f);
  EXPECT_FALSE(rough.roughness.remap);
  EXPECT_FLOAT_EQ(std::get<DielectricMaterial>(scene.materials[5]).ior, 1.5f);
  ASSERT_EQ(read.warnings.size(), 1u) << joined(read.warnings);
  EXPECT_NE(read.warnings[0].find("the green value 1.5 is the index of refraction"), std::string::npos);
  expect_error({"WorldBegin", "Material \"dielectric\" \"float eta\" 0"}, 2, "\"float eta\"", "must be positive");
  expect_error({"WorldBegin", "Material \"thindielectric\""}, 2, "\"thindielectric\"",
               "material type \"thindielectric\" is not supported: candela has no thin-sheet BSDF");
}

TEST(PbrtReader, CoatedDiffuseIsTheClosedFormPlastic) {
  Warned read = read_warned({"WorldBegin",
                             "Material \"coateddiffuse\" \"rgb reflectance\" [ 0.2 0.4 0.6 ] \"float roughness\" 0.1 "
                             "\"float eta\" 1.6 \"integer maxdepth\" 20 \"integer nsamples\" 4 "
                             "\"rgb albedo\" [ 0 0 0 ] "
                             "\"float g\" 0.3",
                             "Material \"coateddiffuse\""});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  const auto& coated = std::get<CoatedDiffuseMaterial>(read.scene.materials.at(0));
  EXPECT_EQ(coated.reflectance.value, RGB(0.2f, 0.4f, 0.6f));
  EXPECT_FLOAT_EQ(coated.ior, 1.6f);
  EXPECT_FLOAT_EQ(coated.roughness.u.value, 0.1f);
  EXPECT_TRUE(coated.roughness.remap);
  EXPECT_EQ(coated.specular.value, RGB(1.0f));
  const auto& defaults = std::get<CoatedDiffuseMaterial>(read.scene.materials.at(1));
  EXPECT_EQ(defaults.reflectance.value, RGB(0.5f));
  EXPECT_FLOAT_EQ(defaults.ior, 1.5f);
  EXPECT_FLOAT_EQ(defaults.roughness.u.value, 0);
  expect_warning({"WorldBegin", "Material \"coateddiffuse\" \"rgb albedo\" [ 0.5 0.5 0.5 ]"}, 2, "\"rgb albedo\"",
                 "\"albedo\" is ignored: candela's coated diffuse has no scattering medium");
  expect_warning({"WorldBegin", "Material \"coateddiffuse\" \"float thickness\" 0.1"}, 2, "\"float thickness\"",
                 "\"thickness\" is ignored");
}

TEST(PbrtReader, DiffuseTransmissionInterfaceAndDisplacement) {
  ScratchFile image("leaf.png");
  SceneDesc scene = read_lines(
      {"WorldBegin",
       "Texture \"leaf\" \"spectrum\" \"imagemap\" \"string filename\" \"leaf.png\"",
       "Material \"diffusetransmission\" \"rgb reflectance\" [ 0.5 0.5 0.5 ] \"rgb transmittance\" [ 0.4 0.2 0.8 ] "
       "\"float scale\" 0.5",
       "Material \"diffusetransmission\"",
       "Material \"diffusetransmission\" \"texture transmittance\" \"leaf\" \"float scale\" 2",
       "Material \"interface\"",
       "Material \"none\""});
  ASSERT_EQ(scene.materials.size(), 5u);
  const auto& leaf = std::get<DiffuseTransmissionMaterial>(scene.materials[0]);
  EXPECT_EQ(leaf.reflectance.value, RGB(0.25f));
  EXPECT_EQ(leaf.transmittance.value, RGB(0.2f, 0.1f, 0.4f));
  const auto& defaults = std::get<DiffuseTransmissionMaterial>(scene.materials[1]);
  EXPECT_EQ(defaults.reflectance.value, RGB(0.25f));
  EXPECT_EQ(defaults.transmittance.value, RGB(0.25f));
  // A textured input with a scale becomes a ScaleTexture after the texture it scales.
  const auto& textured = std::get<DiffuseTransmissionMaterial>(scene.materials[2]);
  ASSERT_EQ(scene.textures.size(), 2u);
  EXPECT_EQ(textured.transmittance.texture, 1);
  const auto& scale = std::get<ScaleTexture>(scene.textures[1]);
  EXPECT_EQ(scale.tex.texture, 0);
  EXPECT_FLOAT_EQ(scale.scale.value, 2);
  EXPECT_EQ(textured.reflectance.value, RGB(0.5f));
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(scene.materials[3]));
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(scene.materials[4]));
  expect_warning({"WorldBegin", "Material \"diffuse\" \"float displacement\" 0.1"}, 2, "\"float displacement\"",
                 "Material \"diffuse\": \"displacement\" is ignored: displacement mapping is not supported");
  expect_warning({"WorldBegin", "Material \"conductor\" \"string normalmap\" \"n.png\""}, 2, "\"string normalmap\"",
                 "\"normalmap\" is ignored: normal maps are not supported");
}

TEST(PbrtReader, MixMaterialSelectsWithAConstantAmountOnly) {
  std::vector<std::string> prefix = {"WorldBegin", "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"",
                                     "MakeNamedMaterial \"b\" \"string type\" \"conductor\""};
  auto with = [&](std::string line) {
    std::vector<std::string> lines = prefix;
    lines.push_back(line);
    return lines;
  };
  SceneDesc first = read_lines(with("Material \"mix\" \"string materials\" [ \"a\" \"b\" ] \"float amount\" 0"));
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(first.materials.back()));
  SceneDesc second = read_lines(with("Material \"mix\" \"string materials\" [ \"a\" \"b\" ] \"float amount\" 1"));
  EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(second.materials.back()));
  SceneDesc same = read_lines(with("Material \"mix\" \"string materials\" [ \"b\" \"b\" ]"));
  EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(same.materials.back()));
  expect_error(with("Material \"mix\" \"string materials\" [ \"a\" \"b\" ] \"float amount\" 0.3"), 4, "\"mix\"",
               "material type \"mix\" is not supported: candela cannot blend two materials");
  expect_error(with("Material \"mix\" \"string materials\" [ \"a\" \"c\" ]"), 4, "\"string materials\"",
               "names \"c\", which no MakeNamedMaterial before it defines");
  expect_error(with("Material \"mix\" \"string materials\" \"a\""), 4, "\"string materials\"",
               "must name exactly two materials");
}

// ---------------------------------------------------------------- textures

TEST(PbrtReader, ImageTextures) {
  ScratchFile png("wood.png"), tga("stone.tga"), exr("sky.exr");
  Warned read = read_warned(
      {"WorldBegin",
       "Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"",
       "Texture \"b\" \"spectrum\" \"imagemap\" \"string filename\" \"stone.tga\" \"string filter\" \"point\" "
       "\"string wrap\" \"clamp\" \"float scale\" 2 \"bool invert\" true \"float uscale\" 4 \"float vscale\" 3 "
       "\"float udelta\" 0.5 \"float vdelta\" 0.25",
       "Texture \"c\" \"float\" \"imagemap\" \"string filename\" \"stone.tga\" \"string encoding\" \"sRGB\" "
       "\"string wrap\" \"black\"",
       "Texture \"d\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\" \"string encoding\" \"linear\"",
       "Texture \"e\" \"spectrum\" \"imagemap\" \"string filename\" \"sky.exr\" \"string encoding\" \"gamma 2.2\"",
       "Texture \"f\" \"spectrum\" \"imagemap\" \"string filename\" \"sky.exr\" \"string mapping\" \"uv\"",
       "Material \"diffuse\" \"texture reflectance\" \"b\"",
       "Material \"conductor\" \"texture roughness\" \"c\""});
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(scene.textures.size(), 6u);
  const auto& a = std::get<ImageTexture>(scene.textures[0]);
  EXPECT_EQ(fs::path(a.filename), scratch_dir() / "wood.png");  // beside the scene file
  EXPECT_EQ(a.encoding, ColorEncoding::Auto);                     // sRGB for 8-bit files, as pbrt-v4
  EXPECT_TRUE(a.bilinear);
  EXPECT_EQ(a.wrap, TextureWrap::Repeat);
  EXPECT_FLOAT_EQ(a.scale, 1);
  EXPECT_FALSE(a.invert);
  EXPECT_FLOAT_EQ(a.mapping.su, 1);
  const auto& b = std::get<ImageTexture>(scene.textures[1]);
  EXPECT_EQ(b.encoding, ColorEncoding::Auto);
  EXPECT_FALSE(b.bilinear);
  EXPECT_EQ(b.wrap, TextureWrap::Clamp);
  EXPECT_FLOAT_EQ(b.scale, 2);
  EXPECT_TRUE(b.invert);
  EXPECT_FLOAT_EQ(b.mapping.su, 4);
  EXPECT_FLOAT_EQ(b.mapping.sv, 3);
  EXPECT_FLOAT_EQ(b.mapping.du, 0.5f);
  EXPECT_FLOAT_EQ(b.mapping.dv, 0.25f);
  const auto& c = std::get<ImageTexture>(scene.textures[2]);
  EXPECT_EQ(c.encoding, ColorEncoding::SRGB);
  EXPECT_EQ(c.wrap, TextureWrap::Black);
  EXPECT_EQ(std::get<ImageTexture>(scene.textures[3]).encoding, ColorEncoding::Linear);
  EXPECT_EQ(std::get<ImageTexture>(scene.textures[4]).encoding, ColorEncoding::SRGB);
  EXPECT_EQ(std::get<ImageTexture>(scene.textures[5]).encoding, ColorEncoding::Auto);
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials[0]).reflectance.texture, 1);
  EXPECT_EQ(std::get<ConductorMaterial>(scene.materials[1]).roughness.u.texture, 2);
  ASSERT_EQ(read.warnings.size(), 1u) << joined(read.warnings);
  EXPECT_NE(read.warnings[0].find("\"encoding\" \"gamma 2.2\" is read as sRGB"), std::string::npos);
}

TEST(PbrtReader, TrilinearAndEwaFiltersAreBilinearWithAWarning) {
  ScratchFile png("wood.png");
  for (std::string filter : {"trilinear", "ewa"})
    expect_warning({"WorldBegin", "Texture \"a\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\" "
                    "\"string filter\" \"" + filter + "\" \"float maxanisotropy\" 4"},
                   2, "\"string filter\"",
                   "filter \"" + filter + "\" is read as \"bilinear\": candela does not mipmap");
}

TEST(PbrtReader, BadImageTextures) {
  ScratchFile png("wood.png");
  const std::string texture = "Texture \"a\" \"spectrum\" \"imagemap\" ";
  expect_error({"WorldBegin", texture + "\"string filename\" \"nope.png\""}, 2, "\"string filename\"",
               "\"filename\": cannot find \"nope.png\"");
  expect_error({"WorldBegin", texture}, 2, "Texture", "\"filename\" is required");
  const std::string wood = texture + "\"string filename\" \"wood.png\" ";
  expect_error({"WorldBegin", wood + "\"string wrap\" \"octahedralsphere\""}, 2, "\"string wrap\"",
               "\"octahedralsphere\" is not supported for image textures");
  expect_error({"WorldBegin", wood + "\"string filter\" \"gaussian\""}, 2, "\"string filter\"",
               "must be \"point\", \"bilinear\", \"trilinear\" or \"ewa\"");
  expect_error({"WorldBegin", wood + "\"string encoding\" \"gamma 1.8\""}, 2, "\"string encoding\"",
               "\"gamma 1.8\" is not supported");
  expect_error({"WorldBegin", wood + "\"string mapping\" \"spherical\""}, 2, "\"string mapping\"",
               "\"spherical\" is not supported (only \"uv\")");
  expect_error({"WorldBegin", wood, texture + "\"string filename\" \"wood.png\""}, 3, "\"a\"",
               "spectrum texture \"a\" is already defined at");
  expect_error({"WorldBegin", "Texture \"a\" \"color\" \"imagemap\""}, 2, "\"color\"",
               "the value type must be \"spectrum\" or \"float\"");
  expect_error({"WorldBegin", "Texture \"r\" \"float\" \"constant\"",
                "Material \"diffuse\" \"texture reflectance\" \"r\""},
               3, "\"texture reflectance\"", "there is a \"float\" texture of that name");
  expect_error({"WorldBegin", "Texture \"r\" \"spectrum\" \"constant\"",
                "Material \"conductor\" \"texture roughness\" \"r\""},
               3, "\"texture roughness\"", "there is a \"spectrum\" texture of that name");
}

TEST(PbrtReader, ProceduralTexturesComeAfterTheTexturesTheyUse) {
  ScratchFile png("wood.png");
  SceneDesc scene = read_lines(
      {"WorldBegin",
       "Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"",
       "Texture \"checks\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [ 1 0 0 ] \"texture tex2\" \"img\" "
       "\"float uscale\" 8",
       "Texture \"scaled\" \"spectrum\" \"scale\" \"texture tex\" \"checks\" \"float scale\" 0.5",
       "Texture \"amount\" \"float\" \"checkerboard\" \"float tex1\" 0.25 \"float tex2\" 0.75",
       "Texture \"mixed\" \"spectrum\" \"mix\" \"texture tex1\" \"scaled\" \"rgb tex2\" [ 0 0 1 ] "
       "\"texture amount\" \"amount\"",
       "Texture \"k\" \"spectrum\" \"constant\" \"rgb value\" [ 0.1 0.2 0.3 ]",
       "Material \"diffuse\" \"texture reflectance\" \"mixed\"",
       "Material \"diffuse\" \"texture reflectance\" \"k\""});
  ASSERT_EQ(scene.textures.size(), 5u);  // the constant texture is no texture
  const auto& checks = std::get<CheckerboardTexture>(scene.textures[1]);
  EXPECT_EQ(checks.tex1.value, RGB(1, 0, 0));
  EXPECT_EQ(checks.tex2.texture, 0);
  EXPECT_FLOAT_EQ(checks.mapping.su, 8);
  const auto& scaled = std::get<ScaleTexture>(scene.textures[2]);
  EXPECT_EQ(scaled.tex.texture, 1);
  EXPECT_FLOAT_EQ(scaled.scale.value, 0.5f);
  const auto& amount = std::get<CheckerboardTexture>(scene.textures[3]);
  EXPECT_EQ(amount.tex1.value, RGB(0.25f));
  EXPECT_EQ(amount.tex2.value, RGB(0.75f));
  const auto& mixed = std::get<MixTexture>(scene.textures[4]);
  EXPECT_EQ(mixed.tex1.texture, 2);
  EXPECT_EQ(mixed.tex2.value, RGB(0, 0, 1));
  EXPECT_EQ(mixed.amount.texture, 3);
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials[0]).reflectance.texture, 4);
  const auto& constant = std::get<DiffuseMaterial>(scene.materials[1]).reflectance;
  EXPECT_TRUE(constant.is_constant());
  EXPECT_EQ(constant.value, RGB(0.1f, 0.2f, 0.3f));
  expect_error({"WorldBegin", "Texture \"c\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3"}, 2,
               "\"integer dimension\"", "solid (3D) checkerboards are not supported");
  expect_error({"WorldBegin", "Texture \"c\" \"spectrum\" \"scale\" \"texture tex\" \"later\""}, 2, "\"texture tex\"",
               "no spectrum texture named \"later\" is defined (Texture must come first)");
}

// ---------------------------------------------------------------- lights

TEST(PbrtReader, SpotLights) {
  SceneDesc scene = read_lines({"WorldBegin", "Translate 1 0 0",
                                "LightSource \"spot\" \"rgb I\" [ 2 2 2 ] \"point3 from\" [ 0 1 0 ] "
                                "\"point3 to\" [ 0 1 5 ] \"float coneangle\" 20 \"float conedeltaangle\" 4 "
                                "\"float scale\" 3",
                                "LightSource \"spot\""});
  ASSERT_EQ(scene.lights.size(), 2u);
  const auto& spot = std::get<SpotLight>(scene.lights[0]);
  expect_near(spot.position, Point3(1, 1, 0));
  expect_near(spot.direction, Vec3(0, 0, 1));
  EXPECT_EQ(spot.intensity, RGB(6.0f));
  EXPECT_FLOAT_EQ(spot.cone_angle, 20);
  EXPECT_FLOAT_EQ(spot.cone_delta, 4);
  const auto& defaults = std::get<SpotLight>(scene.lights[1]);
  EXPECT_FLOAT_EQ(defaults.cone_angle, 30);
  EXPECT_FLOAT_EQ(defaults.cone_delta, 5);
  EXPECT_EQ(defaults.intensity, RGB(1.0f));
  expect_near(defaults.position, Point3(1, 0, 0));
  expect_error({"WorldBegin", "LightSource \"spot\" \"float coneangle\" 10 \"float conedeltaangle\" 20"}, 2,
               "\"float conedeltaangle\"", "must be in [0, \"coneangle\" = 10] degrees");
  expect_error({"WorldBegin", "LightSource \"spot\" \"point3 to\" [ 0 0 0 ]"}, 2, "\"point3 to\"", "must differ");
}

TEST(PbrtReader, PointAndSpotLightPower) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "LightSource \"point\" \"rgb I\" [ 1 0.5 0.25 ] \"float power\" 100",
                                "LightSource \"spot\" \"float power\" 10"});
  const float pi = std::numbers::pi_v<float>;
  RGB point = std::get<PointLight>(scene.lights[0]).intensity;
  EXPECT_NEAR(point.r, 100 / (4 * pi), 1e-4f);
  EXPECT_NEAR(point.b, 0.25f * 100 / (4 * pi), 1e-4f);
  float cos_end = std::cos(30 * pi / 180), cos_start = std::cos(25 * pi / 180);
  EXPECT_NEAR(std::get<SpotLight>(scene.lights[1]).intensity.g,
              10 / (2 * pi * ((1 - cos_start) + (cos_start - cos_end) / 2)), 1e-3f);
}

TEST(PbrtReader, DistantLight) {
  SceneDesc scene = read_lines({"WorldBegin", "Rotate 90 1 0 0",
                                "LightSource \"distant\" \"rgb L\" [ 1 2 3 ] \"float scale\" 2 \"float illuminance\" 5",
                                "LightSource \"distant\" \"point3 from\" [ 0 0 0 ] \"point3 to\" [ 1 0 0 ]"});
  const auto& sun = std::get<DistantLight>(scene.lights[0]);
  expect_near(sun.direction, Vec3(0, -1, 0));  // +z (from "from" to "to") turned by the CTM
  EXPECT_EQ(sun.radiance, RGB(10, 20, 30));
  expect_near(std::get<DistantLight>(scene.lights[1]).direction, Vec3(1, 0, 0));
}

TEST(PbrtReader, InfiniteLights) {
  ScratchFile exr("sky.exr");
  Warned read = read_warned({"WorldBegin",
                             "LightSource \"infinite\" \"rgb L\" [ 1 2 3 ] \"float illuminance\" 3.14159265",
                             "AttributeBegin",
                             "Rotate -90 1 0 0",
                             "LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 2",
                             "AttributeEnd"});
  const SceneDesc& scene = read.scene;
  EXPECT_TRUE(read.warnings.empty());
  ASSERT_EQ(scene.lights.size(), 2u);
  const auto& sky = std::get<SkyLight>(scene.lights[0]);
  EXPECT_TRUE(sky.is_constant());
  expect_near(Vec3(sky.zenith.r, sky.zenith.g, sky.zenith.b), Vec3(1, 2, 3));  // illuminance pi: L unchanged
  const auto& map = std::get<EnvironmentMap>(scene.lights[1]);
  EXPECT_EQ(fs::path(map.filename), scratch_dir() / "sky.exr");
  EXPECT_EQ(map.mapping, EnvironmentMapping::EqualAreaOctahedral);
  EXPECT_EQ(map.scale, RGB(2.0f));
  expect_near(map.to_world.vector(Vec3(0, 0, 1)), Vec3(0, 1, 0));  // pbrt's +z up turned to +y
  expect_warning({"WorldBegin", "LightSource \"infinite\" \"point3 portal\" [ 0 0 0  1 0 0  1 1 0  0 1 0 ]"}, 2,
                 "\"point3 portal\"", "\"portal\" is ignored");
  expect_error({"WorldBegin", "LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float illuminance\" 10"}, 2,
               "\"float illuminance\"", "is not supported with an image");
}

TEST(PbrtReader, EmissionSpectra) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "LightSource \"point\" \"spectrum I\" \"stdillum-D65\"",
                                "LightSource \"point\" \"spectrum I\" \"stdillum-A\" \"float scale\" 2",
                                "LightSource \"point\" \"blackbody I\" 2700",
                                "LightSource \"point\" \"blackbody I\" 6500",
                                "LightSource \"point\" \"spectrum I\" [ 300 5  900 5 ]"});
  auto intensity = [&](size_t i) { return std::get<PointLight>(scene.lights.at(i)).intensity; };
  EXPECT_EQ(intensity(0), RGB(1.0f));  // D65 is the sRGB white; pbrt-v4 normalises to luminance 1
  RGB a = intensity(1);
  EXPECT_NEAR(a.luminance(), 2, 2e-3f);
  EXPECT_GT(a.r, a.g);
  EXPECT_GT(a.g, a.b);
  RGB warm = intensity(2);
  EXPECT_NEAR(warm.luminance(), 1, 1e-3f);
  EXPECT_GT(warm.r, warm.g);
  EXPECT_GT(warm.g, warm.b);
  RGB daylight = intensity(3);
  EXPECT_NEAR(daylight.luminance(), 1, 1e-3f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(daylight[c], 1, 0.15f) << c;
  RGB equal_energy = intensity(4);  // a flat spectrum is normalised too: its scale does not matter
  EXPECT_NEAR(equal_energy.luminance(), 1, 1e-3f);
  EXPECT_GT(equal_energy.r, equal_energy.b);
}

// Sum of a mesh's triangle areas after `to_world`.
double mesh_area(const TriangleMesh& mesh, const Transform& to_world = Transform()) {
  double area = 0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    Point3 a = to_world.point(mesh.positions[mesh.indices[3 * t]]);
    Point3 b = to_world.point(mesh.positions[mesh.indices[3 * t + 1]]);
    Point3 c = to_world.point(mesh.positions[mesh.indices[3 * t + 2]]);
    area += 0.5 * length(cross(b - a, c - a));
  }
  return area;
}

TEST(PbrtReader, AreaLightPowerIsPerPrimitiveAsInPbrt) {
  const float pi = std::numbers::pi_v<float>;
  const std::string quad = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  2 0 0  2 1 0  0 1 0 ] "
                           "\"integer indices\" [ 0 1 2  0 2 3 ]";
  SceneDesc scene = read_lines(
      {"WorldBegin",
       "AttributeBegin",
       "AreaLightSource \"diffuse\" \"rgb L\" [ 1 0.5 1 ] \"float power\" 10",
       quad,  // two triangles of area 1, each emitting 10
       "Scale 3 3 3",
       "Shape \"sphere\" \"float radius\" 2",  // pbrt: the object-space area 16 pi, whatever the CTM's scale
       "AttributeEnd",
       "AttributeBegin",
       "AreaLightSource \"diffuse\" \"float power\" 10 \"bool twosided\" true \"float scale\" 3",
       "Shape \"disk\"",
       "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 2 0  0 0 1  2 0 1  0 2 1 ] "
       "\"integer indices\" [ 0 1 2  3 4 5 ]",  // areas 1 and 2
       "AttributeEnd"});
  ASSERT_EQ(scene.shapes.size(), 5u);
  EXPECT_NEAR(scene.shapes[0].emission->radiance.r, 10 / pi, 1e-4f);
  EXPECT_NEAR(scene.shapes[0].emission->radiance.g, 0.5f * 10 / pi, 1e-4f);  // the RGB is not normalised
  EXPECT_NEAR(scene.shapes[1].emission->radiance.r, 10 / (pi * 16 * pi), 1e-5f);
  EXPECT_NEAR(scene.shapes[2].emission->radiance.r, 3 * 10 / (pi * 2 * pi), 1e-4f);  // disk of area pi, two-sided
  // The mesh with triangles of different areas becomes one shape per area.
  EXPECT_EQ(mesh_of(scene.shapes[3]).triangle_count(), 1u);
  EXPECT_EQ(mesh_of(scene.shapes[4]).triangle_count(), 1u);
  EXPECT_NEAR(scene.shapes[3].emission->radiance.r, 3 * 10 / (pi * 2 * 1), 1e-4f);
  EXPECT_NEAR(scene.shapes[4].emission->radiance.r, 3 * 10 / (pi * 2 * 2), 1e-4f);
  EXPECT_NEAR(mesh_area(mesh_of(scene.shapes[4])), 2, 1e-6);
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\" \"string filename\" \"e.exr\""}, 2, "\"string filename\"",
               "textured area lights are not supported");
}

// ---------------------------------------------------------------- shapes

TEST(PbrtReader, DisksAreTriangulatedWithTheirAreaAndParameterisation) {
  const double pi = std::numbers::pi;
  SceneDesc scene = read_lines({"WorldBegin", "Shape \"disk\" \"float radius\" 2 \"float height\" 0.5",
                                "Shape \"disk\" \"float radius\" 2 \"float innerradius\" 1 \"float phimax\" 90"});
  const TriangleMesh& disk = mesh_of(scene.shapes[0]);
  EXPECT_NEAR(mesh_area(disk), pi * 4, pi * 4 * 1e-3);
  EXPECT_NEAR(mesh_area(disk), pi * 4, pi * 4 * 1e-5);  // the rings are stretched to keep it exact
  ASSERT_EQ(disk.uvs.size(), disk.positions.size());
  ASSERT_EQ(disk.normals.size(), disk.positions.size());
  for (size_t i = 0; i < disk.positions.size(); ++i) {
    const Point3& p = disk.positions[i];
    EXPECT_FLOAT_EQ(p.z, 0.5f);
    EXPECT_LE(length(Vec3(p.x, p.y, 0)), 2 * 1.0003f);
    EXPECT_EQ(disk.normals[i], Normal3(0, 0, 1));
    float r = length(Vec3(p.x, p.y, 0));
    if (r > 1) {  // pbrt: u = phi / phimax, v = (radius - r) / (radius - innerradius)
      EXPECT_FLOAT_EQ(disk.uvs[i].y, 0);
      float phi = std::atan2(p.y, p.x);
      if (phi < 0) phi += 2 * std::numbers::pi_v<float>;
      if (disk.uvs[i].x < 1) {
        EXPECT_NEAR(disk.uvs[i].x, phi / (2 * std::numbers::pi_v<float>), 1e-5f);
      }
    } else {
      EXPECT_FLOAT_EQ(disk.uvs[i].y, 1);
    }
  }
  for (size_t t = 0; t < disk.triangle_count(); ++t) {  // every triangle faces +z
    const Point3 &a = disk.positions[disk.indices[3 * t]], &b = disk.positions[disk.indices[3 * t + 1]],
                 &c = disk.positions[disk.indices[3 * t + 2]];
    EXPECT_GT(cross(b - a, c - a).z, 0);
  }
  const TriangleMesh& quarter = mesh_of(scene.shapes[1]);
  EXPECT_NEAR(mesh_area(quarter), 0.5 * (pi / 2) * (4 - 1), 3 * pi / 4 * 1e-5);
  for (const Point3& p : quarter.positions) {
    EXPECT_GE(p.x, -1e-5f);
    EXPECT_GE(p.y, -1e-5f);
    float r = length(p);
    EXPECT_TRUE(r >= 1 && r <= 2 * 1.0003f) << r;
  }
  expect_error({"WorldBegin", "Shape \"disk\" \"float innerradius\" 2"}, 2, "\"float innerradius\"",
               "must be in [0, \"radius\" = 1)");
}

TEST(PbrtReader, BilinearMeshes) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ]",
                                "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 1 ]",
                                "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0  2 0 0  2 1 0 ] "
                                "\"integer indices\" [ 0 1 2 3  1 4 3 5 ] "
                                "\"point2 uv\" [ 0 0  1 0  0 1  1 1  2 0  2 1 ] "
                                "\"normal N\" [ 0 0 1  0 0 1  0 0 1  0 0 1  0 0 1  0 0 1 ]"});
  // A planar patch: two triangles facing dp/du x dp/dv (+z), with pbrt's default uvs.
  const TriangleMesh& flat = mesh_of(scene.shapes[0]);
  ASSERT_EQ(flat.triangle_count(), 2u);
  EXPECT_TRUE(flat.normals.empty());
  for (size_t t = 0; t < 2; ++t) {
    const Point3 &a = flat.positions[flat.indices[3 * t]], &b = flat.positions[flat.indices[3 * t + 1]],
                 &c = flat.positions[flat.indices[3 * t + 2]];
    EXPECT_GT(cross(b - a, c - a).z, 0);
  }
  EXPECT_NEAR(mesh_area(flat), 1, 1e-6);
  for (size_t i = 0; i < flat.positions.size(); ++i) {
    EXPECT_FLOAT_EQ(flat.uvs[i].x, flat.positions[i].x);
    EXPECT_FLOAT_EQ(flat.uvs[i].y, flat.positions[i].y);
  }
  // A twisted patch: 16 x 16 quads on the bilinear surface with its normals.
  const TriangleMesh& twisted = mesh_of(scene.shapes[1]);
  EXPECT_EQ(twisted.triangle_count(), 2u * 16 * 16);
  ASSERT_EQ(twisted.normals.size(), twisted.positions.size());
  bool found_centre = false;
  for (size_t i = 0; i < twisted.positions.size(); ++i) {
    EXPECT_NEAR(twisted.positions[i].z, twisted.positions[i].x * twisted.positions[i].y, 1e-5f);
    if (twisted.uvs[i].x == 0.5f && twisted.uvs[i].y == 0.5f) {
      found_centre = true;
      expect_near(twisted.positions[i], Point3(0.5f, 0.5f, 0.25f));
      expect_near(twisted.normals[i], normalize(Vec3(-0.5f, -0.5f, 1)));
    }
  }
  EXPECT_TRUE(found_centre);
  // Two patches with their own uvs and normals.
  const TriangleMesh& strip = mesh_of(scene.shapes[2]);
  EXPECT_EQ(strip.triangle_count(), 4u);
  ASSERT_EQ(strip.normals.size(), strip.positions.size());
  EXPECT_NEAR(mesh_area(strip), 2, 1e-6);
  for (size_t i = 0; i < strip.positions.size(); ++i) EXPECT_FLOAT_EQ(strip.uvs[i].x, strip.positions[i].x);
  expect_error({"WorldBegin", "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0 ] "
                "\"integer indices\" [ 0 1 2 ]"},
               2, "\"integer indices\"", "not a multiple of 4");
  expect_error({"WorldBegin", "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ]"}, 2, "Shape",
               "\"indices\" is required unless \"P\" has exactly 4 points");
}

TEST(PbrtReader, BilinearPatchPowerIsPerPatch) {
  const float pi = std::numbers::pi_v<float>;
  SceneDesc scene = read_lines({"WorldBegin", "AreaLightSource \"diffuse\" \"float power\" 1",
                                "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0  1 1 0  3 0 0  3 2 0 ] "
                                "\"integer indices\" [ 0 1 2 3  1 4 3 5 ]"});  // areas 1 and 3
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_NEAR(scene.shapes[0].emission->radiance.r, 1 / (pi * 1), 1e-5f);
  EXPECT_EQ(mesh_of(scene.shapes[0]).triangle_count(), 2u);
  EXPECT_NEAR(scene.shapes[1].emission->radiance.r, 1 / (pi * 3), 1e-5f);
}

TEST(PbrtReader, AlphaAndOtherShapeParameters) {
  SceneDesc scene = read_lines({"WorldBegin", "Shape \"sphere\" \"float alpha\" 1"});
  EXPECT_EQ(scene.shapes.size(), 1u);
  expect_error({"WorldBegin", "Shape \"sphere\" \"float alpha\" 0.5"}, 2, "\"float alpha\"",
               "below 1 is not supported");
  expect_error({"WorldBegin", "Texture \"a\" \"float\" \"constant\"", "Shape \"sphere\" \"texture alpha\" \"a\""}, 3,
               "\"texture alpha\"", "textures are not supported: an alpha texture cuts the surface out");
  expect_warning({"WorldBegin", "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] "
                  "\"vector3 S\" [ 1 0 0  1 0 0  1 0 0 ]"},
                 2, "\"vector3 S\"", "\"S\" is ignored");
}

// ---------------------------------------------------------------- graphics state

TEST(PbrtReader, ReverseOrientationToggles) {
  SceneDesc scene = read_lines({"WorldBegin", "ReverseOrientation", "Shape \"sphere\"", "ReverseOrientation",
                                "Shape \"sphere\""});
  EXPECT_TRUE(scene.shapes.at(0).reverse_orientation);
  EXPECT_FALSE(scene.shapes.at(1).reverse_orientation);
}

TEST(PbrtReader, AttributeSetsDefaultParametersForABlock) {
  ScratchFile png("wood.png");
  Warned read = read_warned({"WorldBegin",
                             "AttributeBegin",
                             "Attribute \"shape\" \"float radius\" 2",
                             "Attribute \"light\" \"float scale\" 2",
                             "Attribute \"material\" \"rgb reflectance\" [ 0.1 0.2 0.3 ]",
                             "Attribute \"texture\" \"float uscale\" 4",
                             "Shape \"sphere\"",
                             "Shape \"sphere\" \"float radius\" 3",
                             "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ]",
                             "LightSource \"point\"",
                             "Material \"diffuse\"",
                             "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"",
                             "AreaLightSource \"diffuse\"",
                             "Attribute \"shape\" \"float radius\" 5",
                             "Shape \"sphere\"",
                             "AttributeEnd",
                             "Shape \"sphere\"",
                             "Material \"diffuse\""});
  const SceneDesc& scene = read.scene;
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  ASSERT_EQ(scene.shapes.size(), 5u);
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[0].geometry).radius, 2);
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[1].geometry).radius, 3);  // its own parameter wins
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[3].geometry).radius, 5);  // a later Attribute replaces
  EXPECT_EQ(scene.shapes[3].emission->radiance, RGB(2.0f));
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[4].geometry).radius, 1);  // AttributeEnd restored
  EXPECT_EQ(std::get<PointLight>(scene.lights.at(0)).intensity, RGB(2.0f));
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials.at(0)).reflectance.value, RGB(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials.at(1)).reflectance.value, RGB(0.5f));
  EXPECT_FLOAT_EQ(std::get<ImageTexture>(scene.textures.at(0)).mapping.su, 4);
  expect_error({"WorldBegin", "Attribute \"camera\" \"float fov\" 30"}, 2, "\"camera\"",
               "Attribute: unknown target \"camera\"");
  expect_error({"WorldBegin", "Attribute \"shape\" \"string radius\" \"big\"", "Shape \"sphere\""}, 2,
               "\"string radius\"", "parameter \"radius\" must be of type \"float\", not \"string\"");
  expect_warning({"WorldBegin", "Attribute \"medium\" \"rgb sigma_a\" [ 1 1 1 ]"}, 2, "Attribute",
                 "Attribute \"medium\" is ignored");
}

TEST(PbrtReader, MediaAreIgnoredWithWarnings) {
  Warned read = read_warned({"MediumInterface \"\" \"fog\"",
                             "WorldBegin",
                             "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 1 1 1 ]",
                             "MediumInterface \"\"",
                             "MediumInterface \"fog\" \"\"",
                             "Shape \"sphere\""});
  EXPECT_EQ(read.scene.shapes.size(), 1u);
  ASSERT_EQ(read.warnings.size(), 3u) << joined(read.warnings);
  EXPECT_NE(read.warnings[0].find(":1:1: warning: MediumInterface \"\" \"fog\": participating media are not supported"),
            std::string::npos);
  EXPECT_NE(read.warnings[1].find(":3:1: warning: MakeNamedMedium \"fog\": participating media are not supported"),
            std::string::npos);
  EXPECT_NE(read.warnings[2].find(":5:1: warning: MediumInterface \"fog\" \"\""), std::string::npos);
}

TEST(PbrtReader, PrintedWarningsAreCappedPerKind) {
  std::vector<std::string> warnings;
  for (int line = 1; line <= 5; ++line) warnings.push_back(fmt::format("a.pbrt:{}:1: warning: same thing", line));
  warnings.push_back("a.pbrt:9:1: warning: other thing");
  ::testing::internal::CaptureStderr();
  print_pbrt_warnings(warnings, 3);
  std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed,
            "a.pbrt:1:1: warning: same thing\na.pbrt:2:1: warning: same thing\na.pbrt:3:1: warning: same thing\n"
            "a.pbrt:9:1: warning: other thing\n(2 more warnings like \"same thing\")\n");
}

// ---------------------------------------------------------------- named spectra

TEST(PbrtNamedSpectra, MetalsGlassesAndIlluminants) {
  using namespace pbrt_spectra;
  EXPECT_EQ(find_named("metal-Cu-eta")->rgb, ConductorMaterial{}.eta.value);
  EXPECT_EQ(find_named("metal-Cu-k")->rgb, ConductorMaterial{}.k.value);
  EXPECT_EQ(find_named("metal-Al-eta")->rgb, RGB(1.657460f, 0.880369f, 0.521229f));  // veach-ajar's "rgb eta"
  for (std::string_view metal : {"Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"})
    for (std::string_view part : {"eta", "k"}) {
      auto named = find_named(fmt::format("metal-{}-{}", metal, part));
      ASSERT_TRUE(named.has_value()) << metal << part;
      EXPECT_EQ(named->kind, NamedKind::Metal);
      EXPECT_GE(named->rgb.min_component(), 0);
    }
  for (std::string_view glass : {"BK7", "BAF10", "FK51A", "LASF9", "F5", "F10", "F11"}) {
    auto named = find_named(fmt::format("glass-{}", glass));
    ASSERT_TRUE(named.has_value()) << glass;
    EXPECT_TRUE(named->ior_550nm > 1.45f && named->ior_550nm < 1.9f) << glass;
  }
  EXPECT_NEAR(find_named("glass-BK7")->ior_550nm, 1.5185f, 1e-4f);
  EXPECT_NEAR(find_named("glass-F11")->ior_550nm, 1.7911f, 1e-4f);
  EXPECT_EQ(find_named("stdillum-D65")->rgb, RGB(1.0f));
  for (std::string_view name : {"stdillum-A", "stdillum-D50", "stdillum-F1", "stdillum-F12", "illum-acesD60"}) {
    auto named = find_named(name);
    ASSERT_TRUE(named.has_value()) << name;
    EXPECT_NEAR(named->rgb.luminance(), 1, 2e-3f) << name;
  }
  EXPECT_FALSE(find_named("glass-SF5").has_value());  // pbrt-v4 calls it "glass-F5"
  EXPECT_FALSE(find_named("metal-Fe-eta").has_value());
}

TEST(PbrtNamedSpectra, SampledSpectraAndBlackbodies) {
  using namespace pbrt_spectra;
  const double flat[] = {300, 0.5, 900, 0.5};
  RGB reflectance = sampled_spectrum_rgb(flat, Role::Reflectance);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(reflectance[c], 0.5f, 1e-5f);
  EXPECT_NEAR(sampled_spectrum_rgb(flat, Role::Illuminant).luminance(), 1, 1e-3f);
  const double ramp[] = {400, 1, 500, 2, 600, 4};
  EXPECT_FLOAT_EQ(sampled_spectrum_at(ramp, 450), 1.5f);
  EXPECT_FLOAT_EQ(sampled_spectrum_at(ramp, 300), 1);
  EXPECT_FLOAT_EQ(sampled_spectrum_at(ramp, 700), 4);
  RGB candle = blackbody_rgb(1900), sky = blackbody_rgb(12000);
  EXPECT_NEAR(candle.luminance(), 1, 1e-3f);
  EXPECT_GT(candle.r, candle.b);
  EXPECT_GT(sky.b, sky.r);
  // Tungsten's copper, reproduced from pbrt-v4's copper table by the same conversion to about 1%.
  RGB xyz_white = cie::xyz_to_linear_srgb(0.95047, 1.0, 1.08883);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(xyz_white[c], 1, 1e-3f);
}

}  // namespace
}  // namespace candela
