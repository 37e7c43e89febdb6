// Tests of the pbrt-v4 reader's participating media: MakeNamedMedium ("homogeneous", "uniformgrid"),
// MediumInterface on shapes, object instances and the camera, Attribute "medium", and the errors.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/grid_files.h"
#include "candela/io/named_spectra.h"
#include "candela/media/medium.h"
#include "candela/spectral/blackbody.h"
#include "candela/io/pbrt_reader.h"
#include "candela/description/scene_desc.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;

void expect_rgb_near(const RGB& actual, const RGB& expected, float tolerance = 1e-5f) {
  EXPECT_NEAR(actual.r, expected.r, tolerance);
  EXPECT_NEAR(actual.g, expected.g, tolerance);
  EXPECT_NEAR(actual.b, expected.b, tolerance);
}

// ---------------------------------------------------------------- homogeneous

TEST(PbrtMedia, HomogeneousReadsEveryParameter) {
  Warned read = read_warned({"WorldBegin",
                             "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ]",
                             "  \"rgb sigma_s\" [ 0.3 0.2 0.1 ] \"float scale\" 2 \"float g\" 0.4",
                             "  \"rgb Le\" [ 1 2 3 ] \"float Lescale\" 0.5"});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  ASSERT_EQ(read.scene.media.size(), 1u);
  const MediumDesc& fog = read.scene.media[0];
  expect_rgb_near(fog.sigma_t, RGB(0.4f));
  expect_rgb_near(fog.albedo.constant, RGB(0.75f, 0.5f, 0.25f));
  EXPECT_TRUE(fog.is_homogeneous());
  EXPECT_EQ(fog.density.constant, RGB(1.0f));
  EXPECT_FLOAT_EQ(fog.scale, 2);
  EXPECT_FLOAT_EQ(fog.g, 0.4f);
  EXPECT_EQ(fog.emission, RGB(0.5f, 1, 1.5f));  // an RGB Le is used as given, times Lescale
  EXPECT_EQ(fog.name, "fog");
  EXPECT_EQ(fog.where.line, 2);
}

TEST(PbrtMedia, HomogeneousDefaultsArePbrtV4s) {
  SceneDesc scene = read_lines({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\""});
  ASSERT_EQ(scene.media.size(), 1u);
  const MediumDesc& m = scene.media[0];
  EXPECT_EQ(m.sigma_t, RGB(2.0f));  // sigma_a = sigma_s = 1
  EXPECT_EQ(m.albedo.constant, RGB(0.5f));
  EXPECT_FLOAT_EQ(m.scale, 1);
  EXPECT_FLOAT_EQ(m.g, 0);
  EXPECT_EQ(m.emission, RGB(0.0f));
}

TEST(PbrtMedia, SpectraAsElsewhere) {
  SceneDesc scene = read_lines({"MakeNamedMedium \"m\" \"string type\" \"homogeneous\"",
                                "  \"spectrum sigma_a\" [ 300 0.5 800 0.5 ] \"spectrum sigma_s\" \"metal-Cu-k\"",
                                "  \"blackbody Le\" 3000 \"float Lescale\" 4",
                                "WorldBegin"});
  const MediumDesc& m = scene.media.at(0);
  const std::vector<double> pairs = {300, 0.5, 800, 0.5};
  const RGB sigma_a = pbrt_spectra::sampled_spectrum_rgb(pairs, pbrt_spectra::Role::Unbounded);
  const RGB sigma_s = pbrt_spectra::find_named("metal-Cu-k")->rgb;
  expect_rgb_near(m.sigma_t, sigma_a + sigma_s);
  expect_rgb_near(m.albedo.constant, RGB(sigma_s.r / m.sigma_t.r, sigma_s.g / m.sigma_t.g, sigma_s.b / m.sigma_t.b));
  expect_rgb_near(m.emission, pbrt_spectra::blackbody_rgb(3000) * 4);  // normalised as lights' are
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"spectrum Le\" \"metal-Cu-k\""},
               2, "\"spectrum Le\"", "does not fit here");
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"texture sigma_a\" \"t\""}, 2,
               "\"texture sigma_a\"", "a texture is not accepted here; give \"rgb\" or \"spectrum\"");
}

TEST(PbrtMedia, ScatteringPresets) {
  SceneDesc scene = read_lines({"WorldBegin", "MakeNamedMedium \"skin\" \"string type\" \"homogeneous\" "
                                              "\"string preset\" \"Skin1\" \"float scale\" 10"});
  const MediumDesc& skin = scene.media.at(0);
  // Jensen et al. 2001: sigma_s' = (0.74, 0.88, 1.01), sigma_a = (0.032, 0.17, 0.48) per mm.
  expect_rgb_near(skin.sigma_t, RGB(0.772f, 1.05f, 1.49f));
  expect_rgb_near(skin.albedo.constant, RGB(0.74f / 0.772f, 0.88f / 1.05f, 1.01f / 1.49f));
  EXPECT_FLOAT_EQ(skin.scale, 10);
  SceneDesc spaced = read_lines({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" "
                                               "\"string preset\" \"Pacific Ocean Surface Water\""});
  EXPECT_GT(spaced.media.at(0).sigma_t.r, 0);
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"string preset\" \"Skin3\""}, 2,
               "\"string preset\"", "names no scattering preset: \"Skin3\" (the presets are \"Apple\", ");
  // The preset replaces the coefficients, so they are unused parameters (as in pbrt-v4).
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"string preset\" \"Apple\" "
                              "\"rgb sigma_a\" [ 1 1 1 ]"},
               2, "\"rgb sigma_a\"", "unused parameter \"rgb sigma_a\"");
}

// ---------------------------------------------------------------- uniformgrid

TEST(PbrtMedia, UniformGridIsPlacedByTheCtmAndTheBox) {
  Warned read = read_warned({"WorldBegin", "Translate 1 2 3",
                             "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 2 "
                             "\"integer ny\" 1 \"integer nz\" 3",
                             "  \"float density\" [ 0 1 2 3 4 5 ] \"point3 p0\" [ -1 0 0 ] \"point3 p1\" [ 1 1 2 ]",
                             "  \"rgb sigma_a\" [ 1 1 1 ] \"rgb sigma_s\" [ 3 3 3 ] \"float scale\" 0.5 "
                             "\"float g\" -0.3",
                             "Translate 5 5 5"});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  const MediumDesc& smoke = read.scene.media.at(0);
  EXPECT_FALSE(smoke.is_homogeneous());
  EXPECT_EQ(smoke.sigma_t, RGB(4.0f));
  EXPECT_EQ(smoke.albedo.constant, RGB(0.75f));
  EXPECT_FLOAT_EQ(smoke.scale, 0.5f);
  EXPECT_FLOAT_EQ(smoke.g, -0.3f);
  const VolumeDesc& d = smoke.density;
  EXPECT_EQ(d.resolution, (std::array<int, 3>{2, 1, 3}));
  EXPECT_EQ(d.channels, 1);
  ASSERT_TRUE(d.values);
  EXPECT_EQ(*d.values, (std::vector<float>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(d.border, VolumeBorder::Zero);  // pbrt's SampledGrid is zero beyond its samples
  EXPECT_TRUE(d.filename.empty());
  // The unit cube onto the box from p0 to p1, then the CTM at MakeNamedMedium.
  expect_near(d.to_world.point({0, 0, 0}), {0, 2, 3});
  expect_near(d.to_world.point({1, 1, 1}), {2, 3, 5});

  // The box is the one between the corners, whichever way round (pbrt's Bounds3f).
  SceneDesc swapped = read_lines({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" "
                                                "\"float density\" 1 \"point3 p0\" [ 1 1 1 ] \"point3 p1\" [ 0 0 0 ]"});
  expect_near(swapped.media.at(0).density.to_world.point({0, 0, 0}), {0, 0, 0});
  expect_near(swapped.media.at(0).density.to_world.point({1, 1, 1}), {1, 1, 1});
}

// pbrt-v4's GridMedium emission: "Le" times "Lescale" looked up as a grid (one value: a one-voxel
// grid, which fades to half at the box's faces), or the blackbody of a "temperature" grid.
TEST(PbrtMedia, UniformGridEmission) {
  const std::string fire = "MakeNamedMedium \"fire\" \"string type\" \"uniformgrid\" \"float density\" [ 1 2 ] "
                           "\"integer nx\" 2 ";
  {
    const Medium m(read_lines({"WorldBegin", fire + "\"rgb Le\" [ 1 0.5 0 ] \"float Lescale\" 3"}).media.at(0));
    ASSERT_TRUE(m.is_emissive());
    expect_rgb_near(m.emission(Point3(0.5f, 0.5f, 0.5f)), RGB(3, 1.5f, 0));     // the one sample
    expect_rgb_near(m.emission(Point3(0.0f, 0.5f, 0.5f)), RGB(1.5f, 0.75f, 0));  // a face: half
    expect_rgb_near(m.emission(Point3(0.0f, 0.0f, 0.0f)), RGB(0.375f, 0.1875f, 0));  // a corner: an eighth
  }
  {
    // A value per voxel, at the voxel centres x = 1/4 and 3/4.
    const Medium m(read_lines({"WorldBegin", fire + "\"rgb Le\" [ 1 1 1 ] \"float Lescale\" [ 2 4 ]"}).media.at(0));
    expect_rgb_near(m.emission(Point3(0.25f, 0.5f, 0.5f)), RGB(2.0f));
    expect_rgb_near(m.emission(Point3(0.75f, 0.5f, 0.5f)), RGB(4.0f));
    expect_rgb_near(m.emission(Point3(0.5f, 0.5f, 0.5f)), RGB(3.0f));
  }
  {
    // Temperatures 1000 and 2000, offset by 100 and doubled: 1800 K and 3800 K at the voxel centres;
    // "Le" is ignored with a warning, as pbrt-v4 ignores it.
    Warned read = read_warned({"WorldBegin", fire + "\"float temperature\" [ 1000 2000 ] \"float temperatureoffset\" 100 "
                                                    "\"float temperaturescale\" 2 \"float Lescale\" [ 1 0.5 ] "
                                                    "\"rgb Le\" [ 1 1 1 ]"});
    ASSERT_EQ(read.warnings.size(), 1u);
    EXPECT_NE(read.warnings[0].find("\"Le\" is not used where there is a \"temperature\" grid"), std::string::npos);
    const Medium m(read.scene.media.at(0));
    ASSERT_TRUE(m.is_emissive());
    const RGB bb1800 = blackbody_peak_normalised_rgb(1800);  // its blue is negative: clipped
    ASSERT_LT(bb1800.b, 0);
    expect_rgb_near(m.emission(Point3(0.25f, 0.5f, 0.5f)), RGB(bb1800.r, bb1800.g, 0.0f), 1e-7f);
    expect_rgb_near(m.emission(Point3(0.75f, 0.5f, 0.5f)), blackbody_peak_normalised_rgb(3800) * 0.5f, 1e-6f);
  }
  {
    // At or below the cutoff (100 K by default, as pbrt-v4's grid medium), nothing.
    const Medium m(read_lines({"WorldBegin", fire + "\"float temperature\" [ 90 5000 ]"}).media.at(0));
    EXPECT_EQ(m.emission(Point3(0.25f, 0.5f, 0.5f)), RGB(0.0f));
    EXPECT_GT(m.emission(Point3(0.75f, 0.5f, 0.5f)).luminance(), 0.1f);
    const Medium cut(read_lines({"WorldBegin", fire + "\"float temperature\" [ 90 5000 ] \"float temperaturecutoff\" "
                                                      "6000"}).media.at(0));
    EXPECT_EQ(cut.emission(Point3(0.75f, 0.5f, 0.5f)), RGB(0.0f));
  }
  // Without "Le" or a temperature the medium does not glow.
  EXPECT_FALSE(Medium(read_lines({"WorldBegin", fire}).media.at(0)).is_emissive());
}

// pbrt-v4's NanoVDBMedium glows where its file has a "temperature" grid: the blackbody of the
// offset and scaled temperature, times "Lescale".
TEST(PbrtMedia, NanoVdbTemperatureGridGlows) {
  for (const char* name : {"fire.nvdb", "fire.vdb"}) {
    const fs::path file = scratch_dir() / name;
    fs::create_directories(scratch_dir());
    // 2 x 1 x 1 voxels of size 1 at indices (0..1, 0, 0): VDB puts their centres at x = 0 and 1.
    write_grid_file(file, {{"density", {1.0f, 2.0f}}, {"temperature", {1500.0f, 3000.0f}}}, {2, 1, 1}, 1.0f);
    const Medium m(read_lines({"WorldBegin", std::string("MakeNamedMedium \"fire\" \"string type\" \"nanovdb\" "
                                                         "\"string filename\" \"") + name + "\" \"float Lescale\" 4 "
                                                         "\"float temperaturescale\" 2"}).media.at(0));
    ASSERT_TRUE(m.is_emissive()) << name;
    expect_rgb_near(m.emission(Point3(0.0f)), blackbody_peak_normalised_rgb(3000) * 4.0f, 1e-5f);
    expect_rgb_near(m.emission(Point3(1.0f, 0.0f, 0.0f)), blackbody_peak_normalised_rgb(6000) * 4.0f, 1e-5f);
    // A file without one: no emission.
    write_grid_file(file, "density", {2, 1, 1}, {1.0f, 2.0f}, 1.0f);
    EXPECT_FALSE(Medium(read_lines({"WorldBegin", std::string("MakeNamedMedium \"fire\" \"string type\" \"nanovdb\" "
                                                              "\"string filename\" \"") + name + "\""}).media.at(0))
                     .is_emissive());
  }
}

// ---------------------------------------------------------------- MediumInterface

TEST(PbrtMedia, InterfaceAppliesToTheShapesThatFollow) {
  SceneDesc scene = read_lines({"MakeNamedMedium \"air\" \"string type\" \"homogeneous\"",
                                "MediumInterface \"\" \"air\"",
                                "Camera \"perspective\"",
                                "WorldBegin",
                                "MakeNamedMedium \"water\" \"string type\" \"homogeneous\"",
                                "Shape \"sphere\"",
                                "AttributeBegin",
                                "  MediumInterface \"water\" \"air\"",
                                "  Shape \"sphere\"",
                                "  MediumInterface \"water\"",
                                "  Shape \"sphere\"",
                                "  ObjectBegin \"drop\"",
                                "    MediumInterface \"water\" \"\"",
                                "    Shape \"sphere\"",
                                "  ObjectEnd",
                                "AttributeEnd",
                                "Shape \"sphere\"",
                                "ObjectInstance \"drop\""});
  ASSERT_EQ(scene.media.size(), 2u);
  const int air = 0, water = 1;
  EXPECT_EQ(scene.media[air].name, "air");
  EXPECT_EQ(scene.media[water].name, "water");
  EXPECT_EQ(scene.camera.medium, air);  // the outside medium at Camera
  ASSERT_EQ(scene.shapes.size(), 4u);
  EXPECT_EQ(scene.shapes[0].interior_medium, -1);  // the interface of the options section holds on
  EXPECT_EQ(scene.shapes[0].exterior_medium, air);
  EXPECT_EQ(scene.shapes[1].interior_medium, water);
  EXPECT_EQ(scene.shapes[1].exterior_medium, air);
  EXPECT_TRUE(scene.shapes[1].is_medium_transition());
  EXPECT_EQ(scene.shapes[2].interior_medium, water);  // one name: both sides
  EXPECT_EQ(scene.shapes[2].exterior_medium, water);
  EXPECT_EQ(scene.shapes[3].interior_medium, -1);  // AttributeEnd restored the outer interface
  EXPECT_EQ(scene.shapes[3].exterior_medium, air);
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].shapes.at(0).interior_medium, water);
  EXPECT_EQ(scene.objects[0].shapes.at(0).exterior_medium, -1);
}

TEST(PbrtMedia, WithoutAnInterfaceEverythingIsInVacuum) {
  SceneDesc scene = read_lines({"Camera \"perspective\"", "WorldBegin", "Shape \"sphere\""});
  EXPECT_TRUE(scene.media.empty());
  EXPECT_EQ(scene.camera.medium, -1);
  EXPECT_EQ(scene.shapes.at(0).interior_medium, -1);
  EXPECT_EQ(scene.shapes.at(0).exterior_medium, -1);
}

// As in pbrt-v4, which looks the names up once the scene is read, an interface may name a medium
// that is defined further on.
TEST(PbrtMedia, AMediumMayBeDefinedAfterTheInterfaceNamesIt) {
  SceneDesc scene = read_lines({"MediumInterface \"fog\"", "Camera \"perspective\"", "WorldBegin",
                                "Shape \"sphere\"",
                                "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"float g\" 0.5"});
  ASSERT_EQ(scene.media.size(), 1u);
  EXPECT_FLOAT_EQ(scene.media[0].g, 0.5f);
  EXPECT_EQ(scene.media[0].where.line, 5);
  EXPECT_EQ(scene.camera.medium, 0);
  EXPECT_EQ(scene.shapes.at(0).interior_medium, 0);
}

// pbrt-v4's default integrator, volpath, renders media; candela's default for pbrt scenes, path, is
// the same without them.
TEST(PbrtMedia, ScenesWithMediaDefaultToVolpath) {
  const std::string fog = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"";
  EXPECT_EQ(read_lines({fog, "WorldBegin"}).settings.integrator, "volpath");
  EXPECT_EQ(read_lines({"WorldBegin"}).settings.integrator, "path");
  EXPECT_EQ(read_lines({"Integrator \"path\"", fog, "WorldBegin"}).settings.integrator, "path");  // as asked
  EXPECT_EQ(read_lines({"Integrator \"bdpt\"", "WorldBegin", fog}).settings.integrator, "bdpt");
}

// ---------------------------------------------------------------- Attribute "medium"

TEST(PbrtMedia, AttributeSetsDefaultsForTheMediaOfTheBlock) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "AttributeBegin",
                                "  Attribute \"medium\" \"float g\" 0.7 \"rgb sigma_s\" [ 2 2 2 ] \"float density\" 1",
                                "  MakeNamedMedium \"a\" \"string type\" \"homogeneous\"",
                                "  MakeNamedMedium \"b\" \"string type\" \"homogeneous\" \"float g\" -0.2",
                                "AttributeEnd",
                                "MakeNamedMedium \"c\" \"string type\" \"homogeneous\""});
  ASSERT_EQ(scene.media.size(), 3u);
  EXPECT_FLOAT_EQ(scene.media[0].g, 0.7f);
  EXPECT_EQ(scene.media[0].sigma_t, RGB(3.0f));
  EXPECT_FLOAT_EQ(scene.media[1].g, -0.2f);  // its own parameter wins
  EXPECT_FLOAT_EQ(scene.media[2].g, 0);      // AttributeEnd restored the defaults
  EXPECT_EQ(scene.media[2].sigma_t, RGB(2.0f));
  // A default of the wrong type is an error at the Attribute.
  expect_error({"WorldBegin", "Attribute \"medium\" \"string g\" \"big\"",
                "MakeNamedMedium \"a\" \"string type\" \"homogeneous\""},
               2, "\"string g\"", "parameter \"g\" must be of type \"float\", not \"string\"");
}

// ---------------------------------------------------------------- errors

TEST(PbrtMedia, NamesMustBeDefinedOnce) {
  expect_error({"WorldBegin", "MediumInterface \"fog\" \"\"", "Shape \"sphere\""}, 2, "\"fog\"",
               "MediumInterface: no medium named \"fog\" is defined");
  expect_error({"WorldBegin", "MakeNamedMedium \"a\" \"string type\" \"homogeneous\"", "MediumInterface \"a\" \"b\"",
                "MediumInterface \"c\""},
               3, "\"b\"", "no medium named \"b\"");  // the first name never defined
  expect_error({"WorldBegin", "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"",
                "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\""},
               3, "\"fog\"", "MakeNamedMedium: medium \"fog\" is already defined at scene.pbrt:2:");
  expect_error({"WorldBegin", "MakeNamedMedium \"\" \"string type\" \"homogeneous\""}, 2, "\"\"",
               "the name must not be empty");
}

TEST(PbrtMedia, TypeErrors) {
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"rgb sigma_a\" [ 1 1 1 ]"}, 2, "MakeNamedMedium",
               "MakeNamedMedium \"m\": \"string type\" is required");
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"fog\""}, 2, "\"string type\"",
               "unknown medium type \"fog\" (supported: \"homogeneous\", \"uniformgrid\", \"nanovdb\", \"cloud\")");
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"nanovdb\" \"string filename\" \"a.nvdb\""}, 2,
               "\"string filename\"", "a.nvdb");
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"rgbgrid\""}, 2, "\"string type\"",
               "medium type \"rgbgrid\" is not supported: grids of RGB coefficients are not supported yet");
  expect_error({"WorldBegin", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float density\" 2"}, 2,
               "\"float density\"", "unused parameter \"float density\"");
}

TEST(PbrtMedia, CoefficientErrors) {
  const std::string homogeneous = "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" ";
  expect_error({"WorldBegin", homogeneous + "\"rgb sigma_a\" [ 1 -1 1 ]"}, 2, "\"rgb sigma_a\"",
               "\"sigma_a\" has a negative component");
  expect_error({"WorldBegin", homogeneous + "\"spectrum sigma_s\" [ 400 1 700 -1 ]"}, 2, "\"spectrum sigma_s\"",
               "the value at 700 nm is negative");
  expect_error({"WorldBegin", homogeneous + "\"float scale\" -1"}, 2, "\"float scale\"", "must not be negative");
  expect_error({"WorldBegin", homogeneous + "\"float Lescale\" -2"}, 2, "\"float Lescale\"", "must not be negative");
  expect_error({"WorldBegin", homogeneous + "\"rgb Le\" [ -1 0 0 ]"}, 2, "\"rgb Le\"", "negative component");
  for (const char* g : {"1", "-1", "1.5"})
    expect_error({"WorldBegin", homogeneous + "\"float g\" " + g}, 2, "\"float g\"",
                 "must be between -1 and 1, exclusive");
}

TEST(PbrtMedia, GridErrors) {
  const std::string grid = "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" ";
  expect_error({"WorldBegin", grid + "\"integer nx\" 2"}, 2, "MakeNamedMedium",
               "a \"uniformgrid\" medium needs \"float density\"");
  expect_error({"WorldBegin", grid + "\"integer nx\" 2 \"integer nz\" 2 \"float density\" [ 1 2 3 ]"}, 2,
               "\"float density\"", "\"float density\" has 3 values; nx ny nz = 2 x 1 x 2 needs 4");
  expect_error({"WorldBegin", grid + "\"integer nx\" 2 \"float density\" [ 1 -2 ]"}, 2, "\"float density\"",
               "value -2 (number 2, x fastest) must be finite and not negative");
  expect_error({"WorldBegin", grid + "\"integer ny\" 0 \"float density\" [ 1 ]"}, 2, "\"integer ny\"",
               "must be at least 1");
  expect_error({"WorldBegin", grid + "\"float density\" 1 \"point3 p0\" [ 0 0 0 ] \"point3 p1\" [ 1 0 1 ]"}, 2,
               "\"point3 p1\"", "the grid's box has no volume");
  expect_error({"WorldBegin", grid + "\"integer nx\" 2 \"float density\" [ 1 2 ] \"float temperature\" [ 900 ]"},
               2, "\"float temperature\"", "\"float temperature\" has 1 values; nx ny nz = 2 x 1 x 1 needs 2");
  expect_error({"WorldBegin", grid + "\"integer nx\" 3 \"float density\" [ 1 2 3 ] \"float Lescale\" [ 1 2 ]"}, 2,
               "\"float Lescale\"", "\"float Lescale\" has 2 values; nx ny nz = 3 x 1 x 1 needs 3");
  expect_error({"WorldBegin", grid + "\"integer nx\" 2 \"float density\" [ 1 2 ] \"float Lescale\" [ 1 -2 ]"}, 2,
               "\"float Lescale\"", "value -2 (number 2, x fastest) must be finite and not negative");
  expect_error({"WorldBegin", grid + "\"float density\" 1 \"float Lescale\" -1"}, 2, "\"float Lescale\"",
               "must be finite and not negative, got -1");
  expect_error({"WorldBegin", grid + "\"float density\" 1 \"string preset\" \"Apple\""}, 2, "\"string preset\"",
               "unused parameter \"string preset\"");
}

// ---------------------------------------------------------------- cloud

// pbrt-v4's CloudMedium: its parameters, the box in the medium's space placed by the CTM.
TEST(PbrtMedia, CloudReadsPbrtV4sParametersAndPlacesItsBox) {
  Warned read = read_warned({"WorldBegin", "Translate 1 2 3",
                             "MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float density\" 3 "
                             "\"float wispiness\" 0.5 \"float frequency\" 4",
                             "  \"rgb sigma_a\" [ 0.1 0.1 0.1 ] \"rgb sigma_s\" [ 1 1 1 ] \"float g\" 0.2",
                             "  \"point3 p0\" [ 0.8 1.6 0.8 ] \"point3 p1\" [ -0.8 0 -0.8 ]", "Translate 5 5 5"});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  const MediumDesc& c = read.scene.media.at(0);
  EXPECT_FALSE(c.is_homogeneous());
  expect_rgb_near(c.sigma_t, RGB(1.1f));
  expect_rgb_near(c.albedo.constant, RGB(1 / 1.1f));
  EXPECT_FLOAT_EQ(c.scale, 1);
  EXPECT_FLOAT_EQ(c.g, 0.2f);
  EXPECT_EQ(c.emission, RGB(0.0f));
  ASSERT_TRUE(c.density.cloud);
  EXPECT_FALSE(c.density.values);
  EXPECT_FLOAT_EQ(c.density.cloud->density, 3);
  EXPECT_FLOAT_EQ(c.density.cloud->wispiness, 0.5f);
  EXPECT_FLOAT_EQ(c.density.cloud->frequency, 4);
  // The box between the corners, whichever way round, then the CTM at MakeNamedMedium.
  EXPECT_EQ(c.density.cloud->box_min, Point3(-0.8f, 0, -0.8f));
  EXPECT_EQ(c.density.cloud->box_max, Point3(0.8f, 1.6f, 0.8f));
  expect_near(c.density.to_world.point({0, 0, 0}), {0.2f, 2, 2.2f});
  expect_near(c.density.to_world.point({1, 1, 1}), {1.8f, 3.6f, 3.8f});

  SceneDesc defaults = read_lines({"WorldBegin", "MakeNamedMedium \"c\" \"string type\" \"cloud\""});
  const MediumDesc& d = defaults.media.at(0);
  EXPECT_EQ(d.sigma_t, RGB(2.0f));  // sigma_a = sigma_s = 1
  EXPECT_EQ(*d.density.cloud, CloudDensity{});
  EXPECT_EQ(d.density.cloud->frequency, 5);
  expect_near(d.density.to_world.point({1, 1, 1}), {1, 1, 1});
}

TEST(PbrtMedia, CloudErrors) {
  const std::string cloud = "MakeNamedMedium \"m\" \"string type\" \"cloud\" ";
  expect_error({"WorldBegin", cloud + "\"float scale\" 2"}, 2, "\"float scale\"",
               "\"scale\" is not a parameter of a \"cloud\" medium");
  expect_error({"WorldBegin", cloud + "\"point3 p0\" [ 0 0 0 ] \"point3 p1\" [ 1 1 0 ]"}, 2, "\"point3 p1\"",
               "the cloud's box has no volume");
  expect_error({"WorldBegin", cloud + "\"float g\" 1"}, 2, "\"float g\"", "must be between -1 and 1, exclusive");
  expect_error({"WorldBegin", cloud + "\"rgb Le\" [ 1 1 1 ]"}, 2, "\"rgb Le\"", "unused parameter \"rgb Le\"");
  expect_error({"WorldBegin", cloud + "\"float density\" [ 1 2 ]"}, 2, "\"float density\"",
               "\"float density\" takes exactly 1 value, got 2");
}

// Errors in an included file name that file and where it was included from.
TEST(PbrtMedia, ErrorsInIncludedFilesNameThem) {
  ScratchScene media({"MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" 2"});
  std::string message = error_reading_text({fmt::format("Include \"{}\"", media.path().string()), "WorldBegin"});
  EXPECT_TRUE(message.starts_with(media.path().string() + ":1:")) << message;
  EXPECT_NE(message.find("(in the file included at scene.pbrt:1:9)"), std::string::npos) << message;
}

}  // namespace
}  // namespace candela
