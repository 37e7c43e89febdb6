// Tests of the pbrt-v4 reader: materials, textures and named spectra.
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
#include "candela/testing/pbrt_reader_helpers.h"
#include "candela/testing/texture_expectations.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;
namespace fs = std::filesystem;

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
  // A thin sheet: pbrt-v4's thindielectric is Mitsuba's, candela's thin dielectric.
  SceneDesc thin = read_lines({"WorldBegin", "Material \"thindielectric\" \"float eta\" 1.33",
                               "Shape \"sphere\""});
  const auto& sheet = std::get<DielectricMaterial>(thin.materials.back());
  EXPECT_TRUE(sheet.thin);
  EXPECT_FLOAT_EQ(sheet.ior, 1.33f);
}

// pbrt-v4's "coateddiffuse" and "coatedconductor" are its layered BSDFs, every parameter read with
// pbrt-v4's defaults (materials/layered.h).
TEST(PbrtReader, CoatedDiffuseIsPbrtsLayeredBsdf) {
  Warned read = read_warned({"WorldBegin",
                             "Texture \"t\" \"float\" \"scale\" \"float tex\" 0.5 \"float scale\" 0.2",
                             "Material \"coateddiffuse\" \"rgb reflectance\" [ 0.2 0.4 0.6 ] \"float roughness\" 0.1 "
                             "\"float eta\" 1.6 \"integer maxdepth\" 20 \"integer nsamples\" 4 "
                             "\"rgb albedo\" [ 0.3 0.2 0.1 ] \"texture thickness\" \"t\" "
                             "\"float g\" 0.3",
                             "Material \"coateddiffuse\"",
                             "Material \"coateddiffuse\" \"float g\" -4"});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  const auto& coated = std::get<LayeredDiffuseMaterial>(read.scene.materials.at(0));
  EXPECT_EQ(coated.reflectance.value, RGB(0.2f, 0.4f, 0.6f));
  EXPECT_FLOAT_EQ(coated.ior, 1.6f);
  EXPECT_FLOAT_EQ(coated.roughness.u.value, 0.1f);
  EXPECT_TRUE(coated.roughness.remap);
  EXPECT_EQ(coated.layer.albedo.value, RGB(0.3f, 0.2f, 0.1f));
  EXPECT_FALSE(coated.layer.thickness.is_constant());
  EXPECT_FLOAT_EQ(coated.layer.g.value, 0.3f);
  EXPECT_EQ(coated.layer.max_depth, 20);
  EXPECT_EQ(coated.layer.samples, 4);
  const auto& defaults = std::get<LayeredDiffuseMaterial>(read.scene.materials.at(1));
  EXPECT_EQ(defaults.reflectance.value, RGB(0.5f));
  EXPECT_FLOAT_EQ(defaults.ior, 1.5f);
  EXPECT_FLOAT_EQ(defaults.roughness.u.value, 0);
  EXPECT_FLOAT_EQ(defaults.layer.thickness.value, 0.01f);
  EXPECT_EQ(defaults.layer.albedo.value, RGB(0.0f));
  EXPECT_FLOAT_EQ(defaults.layer.g.value, 0);
  EXPECT_EQ(defaults.layer.max_depth, 10);
  EXPECT_EQ(defaults.layer.samples, 1);
  EXPECT_FLOAT_EQ(std::get<LayeredDiffuseMaterial>(read.scene.materials.at(2)).layer.g.value, -1);  // clamped
  expect_error({"WorldBegin", "Material \"coateddiffuse\" \"integer maxdepth\" 0"}, 2, "\"integer maxdepth\"",
               "must be in [1, 65535], got 0");
  expect_error({"WorldBegin", "Material \"coateddiffuse\" \"float thickness\" -1"}, 2, "\"float thickness\"",
               "must not be negative");
}

TEST(PbrtReader, CoatedConductorIsPbrtsLayeredBsdf) {
  Warned read = read_warned(
      {"WorldBegin",
       "Material \"coatedconductor\" \"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\" "
       "\"float interface.roughness\" 0.05 \"float conductor.uroughness\" 0.2 \"float conductor.vroughness\" 0.1 "
       "\"float interface.eta\" 1.4 \"float thickness\" 0.1 \"rgb albedo\" [ 0.5 0.5 0.5 ] \"float g\" 0.2 "
       "\"integer maxdepth\" 5 \"integer nsamples\" 2 \"bool remaproughness\" false",
       "Material \"coatedconductor\"",
       "Material \"coatedconductor\" \"rgb reflectance\" [ 0.9 0.6 0.3 ]"});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  const auto& gold = std::get<LayeredConductorMaterial>(read.scene.materials.at(0));
  const SceneDesc bare = read_lines(
      {"WorldBegin", "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\""});
  const auto& bare_gold = std::get<ConductorMaterial>(bare.materials.at(0));
  EXPECT_EQ(gold.eta.value, bare_gold.eta.value);
  EXPECT_EQ(gold.k.value, bare_gold.k.value);
  EXPECT_FALSE(gold.reflectance);
  EXPECT_FLOAT_EQ(gold.ior, 1.4f);
  EXPECT_FLOAT_EQ(gold.roughness.u.value, 0.05f);
  EXPECT_FLOAT_EQ(gold.roughness.v.value, 0.05f);
  EXPECT_FALSE(gold.roughness.remap);
  EXPECT_FLOAT_EQ(gold.conductor_roughness.u.value, 0.2f);
  EXPECT_FLOAT_EQ(gold.conductor_roughness.v.value, 0.1f);
  EXPECT_FALSE(gold.conductor_roughness.remap);
  EXPECT_FLOAT_EQ(gold.layer.thickness.value, 0.1f);
  EXPECT_EQ(gold.layer.albedo.value, RGB(0.5f));
  EXPECT_FLOAT_EQ(gold.layer.g.value, 0.2f);
  EXPECT_EQ(gold.layer.max_depth, 5);
  EXPECT_EQ(gold.layer.samples, 2);
  const auto& copper = std::get<LayeredConductorMaterial>(read.scene.materials.at(1));
  EXPECT_EQ(copper.eta.value, ConductorMaterial{}.eta.value);
  EXPECT_EQ(copper.k.value, ConductorMaterial{}.k.value);
  EXPECT_FLOAT_EQ(copper.ior, 1.5f);
  EXPECT_FLOAT_EQ(copper.roughness.u.value, 0);
  EXPECT_FLOAT_EQ(copper.conductor_roughness.u.value, 0);
  EXPECT_TRUE(copper.roughness.remap);
  EXPECT_TRUE(copper.conductor_roughness.remap);
  EXPECT_FLOAT_EQ(copper.layer.thickness.value, 0.01f);
  const auto& artist = std::get<LayeredConductorMaterial>(read.scene.materials.at(2));
  ASSERT_TRUE(artist.reflectance);
  EXPECT_EQ(artist.reflectance->value, RGB(0.9f, 0.6f, 0.3f));
  expect_error({"WorldBegin", "Material \"coatedconductor\" \"rgb reflectance\" [ 0.5 0.5 0.5 ] \"rgb conductor.k\" [ 1 1 1 ]"},
               2, "\"rgb reflectance\"", "cannot be given together with \"conductor.k\"");
  expect_error({"WorldBegin", "Material \"coatedconductor\" \"float roughness\" 0.1"}, 2, "\"float roughness\"",
               "unused parameter");
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
}

TEST(PbrtReader, MixMaterialSelectsOrBlends) {
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
  // Anything else: pbrt-v4 picks one per hit, the second with probability amount; in expectation a blend.
  SceneDesc blended = read_lines(with("Material \"mix\" \"string materials\" [ \"a\" \"b\" ] \"float amount\" 0.3"));
  const auto& blend = std::get<BlendMaterial>(blended.materials.back());
  EXPECT_FLOAT_EQ(blend.weight.value, 0.3f);
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(blended.materials[size_t(blend.material0)]));
  EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(blended.materials[size_t(blend.material1)]));
  SceneDesc textured = read_lines({"WorldBegin", "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"",
                         "Texture \"t\" \"float\" \"checkerboard\" \"float tex1\" 0 \"float tex2\" 1",
                         "Material \"mix\" \"string materials\" [ \"a\" \"none\" ] \"texture amount\" \"t\""});
  const auto& cutout = std::get<BlendMaterial>(textured.materials.back());
  EXPECT_EQ(cutout.weight.texture, 0);
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(textured.materials[size_t(cutout.material1)]));
  expect_error(with("Material \"mix\" \"string materials\" [ \"a\" \"c\" ]"), 4, "\"string materials\"",
               "names \"c\", which no MakeNamedMaterial before it defines");
  expect_error(with("Material \"mix\" \"string materials\" \"a\""), 4, "\"string materials\"",
               "must name exactly two materials");
}

TEST(PbrtReader, HairMaterialAsPbrtV4ReadsIt) {
  Warned read = read_warned(
      {"WorldBegin", "Texture \"m\" \"float\" \"checkerboard\" \"float tex1\" 0.5 \"float tex2\" 4",
       "Material \"hair\"",
       "Material \"hair\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ] \"float eumelanin\" 2 \"float eta\" 1.6 "
       "\"float beta_m\" 0.2 \"float beta_n\" 0.005 \"float alpha\" 3",
       "Material \"hair\" \"rgb reflectance\" [ 0.4 0.3 0.2 ] \"float pheomelanin\" 1",
       "Material \"hair\" \"float pheomelanin\" 0.8",
       "Material \"hair\" \"texture eumelanin\" \"m\" \"texture beta_m\" \"m\"",
       "Material \"hair\" \"rgb color\" [ 0.5 0.5 0.5 ]"});
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(scene.materials.size(), 6u);
  // pbrt-v4's default: eumelanin 1.3, and its other defaults.
  const auto& brown = std::get<HairMaterial>(scene.materials[0]);
  EXPECT_FALSE(brown.sigma_a || brown.reflectance);
  EXPECT_FLOAT_EQ(brown.eumelanin.value, 1.3f);
  EXPECT_FLOAT_EQ(brown.pheomelanin.value, 0);
  EXPECT_FLOAT_EQ(brown.eta.value, 1.55f);
  EXPECT_FLOAT_EQ(brown.beta_m.value, 0.3f);
  EXPECT_FLOAT_EQ(brown.beta_n.value, 0.3f);
  EXPECT_FLOAT_EQ(brown.alpha.value, 2);
  // sigma_a wins (the melanin is ignored with a warning); beta_n clamped to pbrt-v4's 0.01.
  const auto& given = std::get<HairMaterial>(scene.materials[1]);
  ASSERT_TRUE(given.sigma_a);
  EXPECT_EQ(given.sigma_a->value, RGB(0.1f, 0.2f, 0.3f));
  EXPECT_FLOAT_EQ(given.eta.value, 1.6f);
  EXPECT_FLOAT_EQ(given.beta_m.value, 0.2f);
  EXPECT_FLOAT_EQ(given.beta_n.value, 0.01f);
  EXPECT_FLOAT_EQ(given.alpha.value, 3);
  const auto& coloured = std::get<HairMaterial>(scene.materials[2]);
  ASSERT_TRUE(coloured.reflectance);
  EXPECT_FALSE(coloured.sigma_a);
  EXPECT_EQ(coloured.reflectance->value, RGB(0.4f, 0.3f, 0.2f));
  // One concentration given alone leaves the other at 0 (pbrt-v4's null texture).
  const auto& red = std::get<HairMaterial>(scene.materials[3]);
  EXPECT_FLOAT_EQ(red.eumelanin.value, 0);
  EXPECT_FLOAT_EQ(red.pheomelanin.value, 0.8f);
  const auto& textured = std::get<HairMaterial>(scene.materials[4]);
  EXPECT_EQ(textured.eumelanin.texture, 0);
  EXPECT_EQ(textured.beta_m.texture, 0);
  // Older pbrt-v4 scenes name the colour "color".
  const auto& older = std::get<HairMaterial>(scene.materials[5]);
  ASSERT_TRUE(older.reflectance);
  EXPECT_EQ(older.reflectance->value, RGB(0.5f));
  const std::string warnings = joined(read.warnings);
  EXPECT_NE(warnings.find("\"eumelanin\" is ignored because \"sigma_a\" is given"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("\"pheomelanin\" is ignored because \"reflectance\" is given"), std::string::npos)
      << warnings;
  expect_error({"WorldBegin", "Material \"hair\" \"float eta\" 0"}, 2, "\"float eta\"", "must be positive");
  expect_error({"WorldBegin", "Material \"hair\" \"rgb reflectance\" [ 1 1 1 ] \"rgb color\" [ 1 1 1 ]"}, 2,
               "\"rgb color\"", "cannot be given together with \"reflectance\"");
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
  // The defaults: encoding Auto (sRGB for 8-bit files, as pbrt-v4), bilinear, repeated, no scale or offset.
  testing::expect_image_settings(a, ImageTexture{}, "a");
  const auto& b = std::get<ImageTexture>(scene.textures[1]);
  testing::expect_image_settings(b,
                                 {.wrap = TextureWrap::Clamp, .encoding = ColorEncoding::Auto, .filter = TextureFilter::Nearest,
                                  .scale = 2, .invert = true, .mapping = {.su = 4, .sv = 3, .du = 0.5f, .dv = 0.25f}},
                                 "b");
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
  expect_error({"WorldBegin", wood + "\"string mapping\" \"spheric\""}, 2, "\"string mapping\"",
               "must be \"uv\", \"spherical\", \"cylindrical\" or \"planar\", got \"spheric\"");
  // A spherical mapping takes no scale: pbrt-v4 leaves "uscale" unused, an error.
  expect_error({"WorldBegin", wood + "\"string mapping\" \"spherical\" \"float uscale\" 2"}, 2, "\"float uscale\"",
               "unused parameter");
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
  expect_error({"WorldBegin", "Texture \"c\" \"spectrum\" \"checkerboard\" \"integer dimension\" 4"}, 2,
               "\"integer dimension\"", "must be 2 or 3, got 4");
  expect_error({"WorldBegin", "Texture \"c\" \"spectrum\" \"scale\" \"texture tex\" \"later\""}, 2, "\"texture tex\"",
               "no spectrum texture named \"later\" is defined (Texture must come first)");
}

// pbrt-v4's procedural textures: solid ones read the transform current where they are declared.
TEST(PbrtReader, NoiseSolidAndPatternTexturesAreRead) {
  SceneDesc scene = read_lines(
      {"WorldBegin",
       "Texture \"b\" \"spectrum\" \"bilerp\" \"rgb v00\" [1 0 0] \"rgb v11\" [1 1 0] \"float uscale\" 2",
       "Texture \"d\" \"spectrum\" \"dots\" \"rgb inside\" [0.9 0.2 0.1] \"float vscale\" 8",
       "AttributeBegin", "Scale 2 2 2",
       "Texture \"c\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3 \"rgb tex2\" [0.1 0.1 0.1]",
       "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 6 \"float roughness\" 0.4",
       "AttributeEnd",
       "Texture \"w\" \"float\" \"wrinkled\"",
       "Texture \"m\" \"spectrum\" \"marble\" \"float scale\" 4 \"float variation\" 0.3",
       "Texture \"x\" \"spectrum\" \"directionmix\" \"rgb tex1\" [1 0 0] \"vector3 dir\" [0 0 3]"});
  ASSERT_EQ(scene.textures.size(), 7u);
  const auto& bilerp = std::get<BilerpTexture>(scene.textures[0]);
  EXPECT_EQ(bilerp.v00, RGB(1, 0, 0));
  EXPECT_EQ(bilerp.v01, RGB(1.0f));  // pbrt-v4's defaults: 0, 1, 0, 1
  EXPECT_EQ(bilerp.v10, RGB(0.0f));
  EXPECT_FLOAT_EQ(bilerp.mapping.su, 2);
  const auto& dots = std::get<DotsTexture>(scene.textures[1]);
  // pbrt-v4's "inside" colours the surroundings of its dots (see io/pbrt/textures.cpp).
  EXPECT_EQ(dots.outside.value, RGB(0.9f, 0.2f, 0.1f));
  EXPECT_EQ(dots.inside.value, RGB(0.0f));
  EXPECT_FLOAT_EQ(dots.mapping.sv, 8);
  const auto& solid = std::get<SolidCheckerboardTexture>(scene.textures[2]);
  EXPECT_EQ(solid.tex2.value, RGB(0.1f));
  EXPECT_FLOAT_EQ(solid.to_world.point(Point3(1, 0, 0)).x, 2);
  const auto& fbm = std::get<FbmTexture>(scene.textures[3]);
  EXPECT_EQ(fbm.octaves, 6);
  EXPECT_FLOAT_EQ(fbm.roughness, 0.4f);
  EXPECT_FLOAT_EQ(fbm.to_world.point(Point3(0, 1, 0)).y, 2);
  EXPECT_EQ(std::get<WrinkledTexture>(scene.textures[4]).octaves, 8);
  const auto& marble = std::get<MarbleTexture>(scene.textures[5]);
  EXPECT_FLOAT_EQ(marble.scale, 4);
  EXPECT_FLOAT_EQ(marble.variation, 0.3f);
  EXPECT_EQ(std::get<DirectionMixTexture>(scene.textures[6]).direction, Vec3(0, 0, 1));
  expect_error({"WorldBegin", "Texture \"f\" \"spectrum\" \"fbm\""}, 2, "\"fbm\"", "is a float texture only");
  expect_error({"WorldBegin", "Texture \"m\" \"float\" \"marble\""}, 2, "\"marble\"",
               "is a spectrum texture only");
  expect_error({"WorldBegin", "Texture \"x\" \"float\" \"directionmix\" \"vector3 dir\" [0 0 0]"}, 2,
               "\"vector3 dir\"", "must be a non-zero direction");
  expect_error({"WorldBegin", "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 0"}, 2,
               "\"integer octaves\"", "must be in [1, 32], got 0");
}

// pbrt-v4's mappings other than "uv" project the point in the texture's space, which the CTM places.
TEST(PbrtReader, TextureMappingsProjectThePointInTheTexturesSpace) {
  SceneDesc scene = read_lines(
      {"WorldBegin", "Translate 0 1 0",
       "Texture \"p\" \"spectrum\" \"checkerboard\" \"string mapping\" \"planar\" \"vector3 v1\" [4 0 0] "
       "\"vector3 v2\" [0 4 0] \"float udelta\" 0.5",
       "Texture \"s\" \"float\" \"checkerboard\" \"string mapping\" \"spherical\"",
       "Texture \"c\" \"spectrum\" \"dots\" \"string mapping\" \"cylindrical\""});
  ASSERT_EQ(scene.textures.size(), 3u);
  const UVMapping& planar = std::get<CheckerboardTexture>(scene.textures[0]).mapping;
  EXPECT_EQ(planar.projection, TextureProjection::Planar);
  EXPECT_EQ(planar.planar_s, Vec3(4, 0, 0));
  EXPECT_EQ(planar.planar_t, Vec3(0, 4, 0));
  EXPECT_FLOAT_EQ(planar.du, 0.5f);
  EXPECT_FLOAT_EQ(planar.to_world.point(Point3(0.0f)).y, 1);
  EXPECT_EQ(std::get<CheckerboardTexture>(scene.textures[1]).mapping.projection, TextureProjection::Spherical);
  EXPECT_EQ(std::get<DotsTexture>(scene.textures[2]).mapping.projection, TextureProjection::Cylindrical);
}

// pbrt-v4's normal maps and displacement wrap the material; the normal map wins where both are given.
TEST(PbrtReader, NormalMapsAndDisplacementWrapTheMaterial) {
  ScratchFile png("bumps.png");
  SceneDesc scene = read_lines(
      {"WorldBegin", "Texture \"h\" \"float\" \"wrinkled\"",
       "Material \"conductor\" \"string normalmap\" \"bumps.png\"",
       "MakeNamedMaterial \"rough\" \"string type\" \"diffuse\" \"texture displacement\" \"h\"",
       "Material \"diffuse\" \"string normalmap\" \"bumps.png\" \"texture displacement\" \"h\"",
       "Material \"diffuse\" \"float displacement\" 0.5"});
  ASSERT_EQ(scene.materials.size(), 7u);
  const auto& mapped = std::get<NormalMapMaterial>(scene.materials[1]);
  EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(scene.materials.at(size_t(mapped.material))));
  const auto& image = std::get<ImageTexture>(scene.textures.at(size_t(mapped.normal_map)));
  EXPECT_EQ(image.encoding, ColorEncoding::Linear);
  EXPECT_NE(image.filename.find("bumps.png"), std::string::npos);
  const auto& bumped = std::get<BumpMapMaterial>(scene.materials[3]);
  EXPECT_EQ(bumped.height, 0);
  EXPECT_FLOAT_EQ(bumped.scale, 1);
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(scene.materials.at(size_t(bumped.material))));
  EXPECT_TRUE(std::holds_alternative<NormalMapMaterial>(scene.materials[5]));
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(scene.materials[6]));  // a constant displacement
  expect_error({"WorldBegin", "Material \"diffuse\" \"string normalmap\" \"missing.png\""}, 2,
               "\"string normalmap\"", "cannot find \"missing.png\"");
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
