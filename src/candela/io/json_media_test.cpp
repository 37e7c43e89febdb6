// Tests of the JSON format's participating media: the "media" section (homogeneous and grid media,
// grids inline and from .vol files), the media of shapes and the camera, and the errors.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "candela/base/error.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/description/scene_desc.h"
#include "candela/testing/json_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::json_reader;

std::string with_media(const std::string& media, const std::string& rest = "") {
  return R"({"media": )" + media + (rest.empty() ? "" : ", " + rest) + "}";
}

std::string with_medium(const std::string& medium) { return with_media(R"({"m": )" + medium + "}"); }

// A directory of .vol files for one test, removed with it.
class VolumeFiles {
 public:
  VolumeFiles() : dir_(fs::temp_directory_path() / fmt::format("candela_json_media_{}", getpid())) {
    fs::create_directories(dir_);
  }
  ~VolumeFiles() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  const fs::path& dir() const { return dir_; }
  fs::path write(const std::string& name, std::array<int, 3> resolution, int channels, std::vector<float> values) {
    VolumeGrid grid;
    grid.resolution = resolution;
    grid.channels = channels;
    grid.values = std::move(values);
    write_volume_grid(dir_ / name, grid);
    return dir_ / name;
  }

 private:
  fs::path dir_;
};

// ---------------------------------------------------------------- valid media

TEST(JsonMedia, HomogeneousFromAbsorptionAndScattering) {
  SceneDesc scene = read(with_media(R"({
    "fog": {"type": "homogeneous", "sigma_a": [0.1, 0.2, 0.3], "sigma_s": [0.3, 0.2, 0.1], "scale": 2,
            "g": 0.4, "emission": [1, 2, 3]}})"));
  ASSERT_EQ(scene.media.size(), 1u);
  const MediumDesc& fog = scene.media[0];
  EXPECT_NEAR(fog.sigma_t.r, 0.4f, 1e-6f);
  EXPECT_NEAR(fog.albedo.constant.r, 0.75f, 1e-6f);
  EXPECT_NEAR(fog.albedo.constant.b, 0.25f, 1e-6f);
  EXPECT_TRUE(fog.is_homogeneous());
  EXPECT_FLOAT_EQ(fog.scale, 2);
  EXPECT_FLOAT_EQ(fog.g, 0.4f);
  EXPECT_EQ(fog.emission, RGB(1, 2, 3));
  EXPECT_EQ(fog.name, "fog");
  EXPECT_EQ(fog.where.line, 2);
  EXPECT_EQ(fog.where.key_path, "/media/fog");
}

TEST(JsonMedia, CoefficientDefaults) {
  SceneDesc scene = read(with_media(R"({
    "scattering only": {"type": "homogeneous", "sigma_s": 0.5},
    "absorbing only": {"type": "homogeneous", "sigma_a": [1, 2, 3]},
    "extinction only": {"type": "homogeneous", "sigma_t": 3},
    "albedo only": {"type": "homogeneous", "albedo": [0.9, 0.8, 0.7]}})"));
  ASSERT_EQ(scene.media.size(), 4u);
  EXPECT_EQ(scene.media[0].sigma_t, RGB(0.5f));  // sigma_a defaults to 0 when sigma_s is given
  EXPECT_EQ(scene.media[0].albedo.constant, RGB(1.0f));
  EXPECT_EQ(scene.media[1].sigma_t, RGB(1, 2, 3));
  EXPECT_EQ(scene.media[1].albedo.constant, RGB(0.0f));
  EXPECT_EQ(scene.media[2].sigma_t, RGB(3.0f));  // albedo defaults to 1
  EXPECT_EQ(scene.media[2].albedo.constant, RGB(1.0f));
  EXPECT_EQ(scene.media[3].sigma_t, RGB(1.0f));  // sigma_t defaults to 1
  EXPECT_EQ(scene.media[3].albedo.constant, RGB(0.9f, 0.8f, 0.7f));
  for (const MediumDesc& m : scene.media) {
    EXPECT_FLOAT_EQ(m.scale, 1);
    EXPECT_FLOAT_EQ(m.g, 0);
    EXPECT_EQ(m.emission, RGB(0.0f));
  }
}

TEST(JsonMedia, InlineGrids) {
  SceneDesc scene = read(with_media(R"({
    "smoke": {"type": "grid", "sigma_t": [1, 2, 3], "scale": 4,
              "density": {"resolution": [2, 1, 3], "values": [0, 1, 2, 3, 4, 5], "border": "zero",
                          "transform": [{"scale": [2, 1, 1]}, {"translate": [1, 0, 0]}]},
              "albedo": {"resolution": [1, 1, 2], "channels": 3, "values": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]}},
    "constant": {"type": "grid", "sigma_t": 1, "density": 0.5, "albedo": 0.9}})"));
  ASSERT_EQ(scene.media.size(), 2u);
  const MediumDesc& smoke = scene.media[0];
  EXPECT_FALSE(smoke.is_homogeneous());
  EXPECT_EQ(smoke.sigma_t, RGB(1, 2, 3));
  EXPECT_FLOAT_EQ(smoke.scale, 4);
  EXPECT_EQ(smoke.density.resolution, (std::array<int, 3>{2, 1, 3}));
  EXPECT_EQ(smoke.density.channels, 1);
  EXPECT_EQ(*smoke.density.values, (std::vector<float>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(smoke.density.border, VolumeBorder::Zero);
  EXPECT_TRUE(smoke.density.filename.empty());
  expect_near(smoke.density.to_world.point({1, 1, 1}), {3, 1, 1});
  EXPECT_EQ(smoke.albedo.channels, 3);
  EXPECT_EQ(smoke.albedo.border, VolumeBorder::Clamp);  // Mitsuba's default
  EXPECT_EQ(smoke.albedo.values->size(), 6u);
  const MediumDesc& constant = scene.media[1];
  EXPECT_TRUE(constant.density.is_constant());
  EXPECT_EQ(constant.density.constant, RGB(0.5f));
  EXPECT_EQ(constant.albedo.constant, RGB(0.9f));
}

// Emission that varies: a temperature's blackbody (pbrt-v4's) and an emission scale, each a number
// or a grid, with pbrt-v4's temperature mapping.
TEST(JsonMedia, TemperatureAndEmissionScale) {
  SceneDesc scene = read(with_media(R"({
    "fire": {"type": "grid", "sigma_t": 1, "albedo": 0, "density": 1,
             "temperature": {"resolution": [2, 1, 1], "values": [1500, 3000]},
             "emission_scale": 2, "temperature_scale": 1.5, "temperature_offset": 100, "temperature_cutoff": 200},
    "ember": {"type": "homogeneous", "sigma_t": 1, "albedo": 0, "temperature": 2000,
              "emission_scale": {"resolution": [1, 1, 2], "values": [0, 1]}}})"));
  ASSERT_EQ(scene.media.size(), 2u);
  const MediumDesc& fire = scene.media[0];
  ASSERT_TRUE(fire.temperature.has_value());
  EXPECT_EQ(*fire.temperature->values, (std::vector<float>{1500, 3000}));
  EXPECT_EQ(fire.emission_scale.constant, RGB(2.0f));
  EXPECT_FLOAT_EQ(fire.temperature_scale, 1.5f);
  EXPECT_FLOAT_EQ(fire.temperature_offset, 100);
  EXPECT_FLOAT_EQ(fire.temperature_cutoff, 200);
  const MediumDesc& ember = scene.media[1];
  ASSERT_TRUE(ember.temperature.has_value());
  EXPECT_TRUE(ember.temperature->is_constant());
  EXPECT_EQ(ember.temperature->constant, RGB(2000.0f));
  EXPECT_EQ(*ember.emission_scale.values, (std::vector<float>{0, 1}));
  // Errors name the place.
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "temperature": 2000, "emission": 1})"),
                          "at /media/m/emission: give either \"emission\" or \"temperature\", not both");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "emission_scale": -1})"),
                          "at /media/m/emission_scale");
  expect_error_containing(
      with_medium(R"({"type": "homogeneous", "sigma_t": 1, "temperature": {"resolution": [1, 1, 1], "channels": 3,
                                                                           "values": [1, 2, 3]}})"),
      "temperature needs 1");
  expect_error_containing(
      with_medium(R"({"type": "homogeneous", "sigma_t": 1, "emission_scale": {"resolution": [2, 1, 1], "values": [1, -1]}})"),
      "emission_scale value -1 (number 1) must be finite and >= 0");
}

TEST(JsonMedia, GridsFromVolFiles) {
  VolumeFiles files;
  files.write("density.vol", {2, 2, 1}, 1, {0, 1, 2, 3});
  files.write("albedo.vol", {1, 1, 1}, 3, {0.5f, 0.6f, 0.7f});
  SceneDesc scene = read(with_media(R"({
    "smoke": {"type": "grid", "sigma_t": 1, "density": {"filename": "density.vol"},
              "albedo": {"filename": "albedo.vol"}}})"),
                         files.dir());
  const MediumDesc& smoke = scene.media.at(0);
  EXPECT_EQ(smoke.density.resolution, (std::array<int, 3>{2, 2, 1}));
  EXPECT_EQ(*smoke.density.values, (std::vector<float>{0, 1, 2, 3}));
  EXPECT_EQ(smoke.density.filename, (files.dir() / "density.vol").string());
  EXPECT_EQ(smoke.albedo.channels, 3);
  EXPECT_EQ(*smoke.albedo.values, (std::vector<float>{0.5f, 0.6f, 0.7f}));
}

TEST(JsonMedia, ShapesAndTheCameraNameTheirMedia) {
  SceneDesc scene = read(with_media(R"({"air": {"type": "homogeneous", "sigma_s": 0.01},
                                       "water": {"type": "homogeneous", "sigma_a": [0.3, 0.1, 0.05]}})",
                                    R"("camera": {"medium": "air"},
    "materials": {"boundary": {"type": "interface"}},
    "objects": {"drop": {"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "interior": "water"}]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "boundary",
                "interior": "water", "exterior": "air"},
               {"type": "sphere", "center": [0, 3, 0], "radius": 1}])"));
  const int air = 0, water = 1;
  EXPECT_EQ(scene.camera.medium, air);
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_EQ(scene.shapes[0].interior_medium, water);
  EXPECT_EQ(scene.shapes[0].exterior_medium, air);
  EXPECT_TRUE(scene.shapes[0].is_medium_transition());
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(scene.materials.at(size_t(scene.shapes[0].material))));
  EXPECT_EQ(scene.shapes[1].interior_medium, -1);  // vacuum unless named
  EXPECT_EQ(scene.shapes[1].exterior_medium, -1);
  EXPECT_EQ(scene.objects.at(0).shapes.at(0).interior_medium, water);
  EXPECT_EQ(scene.objects.at(0).shapes.at(0).exterior_medium, -1);
  EXPECT_EQ(read("{}").camera.medium, -1);
}

// pbrt-v4's procedural cloud as a grid medium's density: its parameters and box, placed by "transform".
TEST(JsonMedia, ProceduralCloud) {
  SceneDesc scene = read(with_media(R"({
    "cloud": {"type": "grid", "sigma_a": 0.1, "sigma_s": 1, "g": 0.3,
              "density": {"cloud": {"density": 3, "wispiness": 0.5, "frequency": 4, "min": [-1, 0, -2],
                                    "max": [1, 2, 2]},
                          "transform": [{"translate": [0, 1, 0]}]}},
    "defaults": {"type": "grid", "sigma_t": 1, "density": {"cloud": {}}}})"));
  ASSERT_EQ(scene.media.size(), 2u);
  const MediumDesc& m = scene.media[0];
  EXPECT_FALSE(m.is_homogeneous());
  ASSERT_TRUE(m.density.cloud);
  EXPECT_FALSE(m.density.values);
  EXPECT_FLOAT_EQ(m.density.cloud->density, 3);
  EXPECT_FLOAT_EQ(m.density.cloud->wispiness, 0.5f);
  EXPECT_FLOAT_EQ(m.density.cloud->frequency, 4);
  EXPECT_EQ(m.density.cloud->box_min, Point3(-1, 0, -2));
  EXPECT_EQ(m.density.cloud->box_max, Point3(1, 2, 2));
  // The volume's unit cube is the box, then "transform" places the cloud's space.
  expect_near(m.density.to_world.point({0, 0, 0}), {-1, 1, -2});
  expect_near(m.density.to_world.point({1, 1, 1}), {1, 3, 2});
  EXPECT_EQ(*scene.media[1].density.cloud, CloudDensity{});  // pbrt-v4's defaults
  expect_near(scene.media[1].density.to_world.point({1, 1, 1}), {1, 1, 1});
}

// ---------------------------------------------------------------- errors

TEST(JsonMedia, ProceduralCloudErrors) {
  auto cloud = [](const std::string& density) {
    return with_medium(R"({"type": "grid", "sigma_t": 1, "density": )" + density + "}");
  };
  expect_error_containing(cloud(R"({"cloud": {"min": [0, 0, 0], "max": [1, 0, 1]}})"),
                          "at /media/m/density/cloud/max: the cloud's box must have volume");
  expect_error_containing(cloud(R"({"cloud": {"wispyness": 1}})"),
                          "at /media/m/density/cloud/wispyness: unknown key (did you mean \"wispiness\"?)");
  expect_error_containing(cloud(R"({"cloud": {}, "resolution": [1, 1, 1]})"),
                          "at /media/m/density/resolution: unknown key");
  expect_error_containing(cloud(R"({"cloud": {"frequency": "high"}})"), "at /media/m/density/cloud/frequency");
  expect_error_containing(with_medium(R"({"type": "grid", "sigma_t": 1, "density": 1, "albedo": {"cloud": {}}})"),
                          "at /media/m/albedo/cloud: only a medium's density may be a procedural cloud, not its albedo");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "density": {"cloud": {}}})"),
                          "a homogeneous medium's density is a constant");
}

TEST(JsonMedia, CoefficientErrors) {
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_a": 1, "sigma_t": 1})"),
                          "at /media/m: a medium takes \"sigma_a\" and \"sigma_s\", or \"sigma_t\" and \"albedo\", "
                          "not both");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "albedo": 0.5, "sigma_s": 1})"), "not both");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "g": 0.5})"),
                          "at /media/m: a medium needs its coefficients");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_a": [0.1, -0.1, 0]})"), "at /media/m/sigma_a");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": -1})"), "at /media/m/sigma_t");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "albedo": [0.5, 1.5, 0.5]})"),
                          "at /media/m/albedo");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "scale": -2})"),
                          "at /media/m/scale: expected a number >= 0");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "emission": -1})"),
                          "at /media/m/emission");
  for (const char* g : {"1", "-1", "2"})
    expect_error_containing(with_medium(std::string(R"({"type": "homogeneous", "sigma_t": 1, "g": )") + g + "}"),
                            "at /media/m/g: expected a number in (-1, 1), got");
}

TEST(JsonMedia, TypeAndKeyErrors) {
  expect_error_containing(with_medium(R"({"type": "vdb", "sigma_t": 1})"),
                          "at /media/m/type: unknown medium type \"vdb\"; expected one of: homogeneous, grid");
  expect_error_containing(with_medium(R"({"sigma_t": 1})"), "at /media/m: missing required key \"type\"");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1, "densty": 2})"),
                          "at /media/m/densty: unknown key (did you mean \"density\"?)");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1,
                                          "density": {"resolution": [1, 1, 1], "values": [0.5]}})"),
                          "at /media/m/density: a homogeneous medium's density is a constant; a grid of density needs "
                          "type \"grid\"");
  expect_error_containing(with_medium(R"({"type": "grid", "sigma_t": 1})"),
                          "at /media/m: missing required key \"density\"");
  expect_error_containing(with_medium(R"({"type": "homogeneous", "sigma_t": 1,
                                          "albedo": {"resolution": [1, 1, 1], "values": [0.5]}})"),
                          "at /media/m/albedo: a homogeneous medium's albedo is a constant; a grid of albedo needs "
                          "type \"grid\"");
  expect_error_containing(with_media("[]"), "at /media: expected an object mapping medium names to media");
}

TEST(JsonMedia, GridErrors) {
  auto grid = [](const std::string& density) {
    return with_medium(R"({"type": "grid", "sigma_t": 1, "density": )" + density + "}");
  };
  expect_error_containing(grid(R"({"resolution": [2, 1, 1], "values": [1, 2, 3]})"),
                          "at /media/m/density/values: expected 2 values (2 x 1 x 1 samples of 1 channel, x fastest, "
                          "then y, then z), got 3");
  expect_error_containing(grid(R"({"resolution": [2, 1, 1], "values": [1, -2]})"),
                          "at /media/m/density/values/1: density value -2 (number 1) must be finite and >= 0");
  expect_error_containing(grid(R"({"resolution": [1, 1, 1], "channels": 3, "values": [1, 2, 3]})"),
                          "at /media/m/density/channels: the grid has 3 channels; density needs 1");
  expect_error_containing(grid(R"({"resolution": [0, 1, 1], "values": []})"),
                          "at /media/m/density/resolution/0: expected an integer >= 1, got 0");
  expect_error_containing(grid(R"({"resolution": [1, 1], "values": [1]})"),
                          "at /media/m/density/resolution: expected an array of 3 integers");
  expect_error_containing(grid(R"({"values": [1]})"), "at /media/m/density: missing required key \"resolution\"");
  expect_error_containing(grid(R"({"transform": []})"),
                          "at /media/m/density: a grid takes either \"filename\" or inline \"resolution\" and "
                          "\"values\", and has neither");
  expect_error_containing(grid(R"({"filename": "a.vol", "values": [1]})"), "not both");
  expect_error_containing(grid(R"({"resolution": [1, 1, 1], "values": [1], "border": "wrap"})"),
                          "at /media/m/density/border: unknown grid border \"wrap\"; expected one of: clamp, zero");
  expect_error_containing(grid("-1"), "at /media/m/density: expected a number >= 0");
  expect_error_containing(with_medium(R"({"type": "grid", "sigma_t": 1, "density": 1,
                                          "albedo": {"resolution": [1, 1, 1], "channels": 2, "values": [1, 1]}})"),
                          "at /media/m/albedo/channels: the grid has 2 channels; albedo needs 1 or 3");
  expect_error_containing(with_medium(R"({"type": "grid", "sigma_t": 1, "density": 1,
                                          "albedo": {"resolution": [1, 1, 1], "values": [1.5]}})"),
                          "at /media/m/albedo/values/0: albedo value 1.5 (number 0) must be in [0, 1]");
}

TEST(JsonMedia, VolFileErrors) {
  VolumeFiles files;
  auto grid_file = [](const std::string& key, const std::string& file) {
    return with_medium(R"({"type": "grid", "sigma_t": 1, "density": 1, ")" + key + R"(": {"filename": ")" + file +
                       R"("}})");
  };
  auto error = [&](const std::string& text) {
    try {
      read(text, files.dir());
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(grid_file("albedo", "missing.vol")).find("at /media/m/albedo/filename: cannot read volume grid '"),
            std::string::npos);
  EXPECT_NE(error(grid_file("albedo", "missing.vol")).find("missing.vol': no such file"), std::string::npos);
  {
    std::ofstream truncated(files.dir() / "truncated.vol", std::ios::binary);
    truncated << "VOL";
  }
  std::string message = error(grid_file("albedo", "truncated.vol"));
  EXPECT_NE(message.find("at /media/m/albedo/filename: cannot read volume grid '"), std::string::npos) << message;
  EXPECT_NE(message.find("truncated.vol': truncated"), std::string::npos) << message;
  files.write("rgb.vol", {1, 1, 1}, 3, {1, 1, 1});
  const std::string density_rgb =
      with_medium(R"({"type": "grid", "sigma_t": 1, "density": {"filename": "rgb.vol"}})");
  message = error(density_rgb);
  EXPECT_NE(message.find("at /media/m/density/filename: volume grid '"), std::string::npos) << message;
  EXPECT_NE(message.find("rgb.vol' has 3 channels; density needs 1"), std::string::npos) << message;
  files.write("bright.vol", {2, 1, 1}, 1, {0.5f, 2});
  message = error(grid_file("albedo", "bright.vol"));
  EXPECT_NE(message.find("at /media/m/albedo/filename: albedo value 2 (number 1 in '"), std::string::npos) << message;
  EXPECT_NE(message.find("bright.vol') must be in [0, 1]"), std::string::npos) << message;
}

TEST(JsonMedia, UnknownMediumNamesTheirPointer) {
  const std::string shape = R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "exterior": "smoke"})";
  expect_error_containing(R"({"shapes": [)" + shape + "]}",
                          "at /shapes/0/exterior: unknown medium \"smoke\" (\"media\" defines none)");
  expect_error_containing(with_media(R"({"fog": {"type": "homogeneous", "sigma_s": 1},
                                         "air": {"type": "homogeneous", "sigma_s": 0.1}})",
                                     R"("shapes": [)" + shape + "]"),
                          "at /shapes/0/exterior: unknown medium \"smoke\"; defined: air, fog");
  expect_error_containing(with_media(R"({"fog": {"type": "homogeneous", "sigma_s": 1}})",
                                     R"("camera": {"medium": "mist"})"),
                          "at /camera/medium: unknown medium \"mist\"; defined: fog");
  expect_error_containing(R"({"camera": {"medium": 3}})", "at /camera/medium: expected a string");
}

}  // namespace
}  // namespace candela
