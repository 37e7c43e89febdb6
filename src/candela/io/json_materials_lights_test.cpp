// Tests of the JSON scene reader: textures, microfacet and layered materials, spot, distant and
// environment lights, and instancing.
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
#include "candela/testing/texture_expectations.h"

namespace candela {
namespace {

using namespace candela::testing::json_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- textures

const fs::path kTextureDir = kSourceDir / "tests/data/textures";  // checker.ppm (8-bit), sky.hdr (float)

SceneDesc read_textured(const std::string& text) { return read(text, kTextureDir); }

std::string textured_error_of(const std::string& text) { return error_of(text, kTextureDir); }

void expect_textured_error(const std::string& text, const std::string& fragment) {
  std::string message = textured_error_of(text);
  EXPECT_NE(message.find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << message;
}

// A named texture `t` and a material using it.
std::string with_texture(const std::string& texture) {
  return R"({"textures": {"t": )" + texture + R"(}, "materials": {"m": {"type": "diffuse", "reflectance": "t"}}})";
}

TEST(JsonReader, ReadsTexturesWithDependenciesFirst) {
  SceneDesc scene = read_textured(R"({"textures": {
      "mixed": {"type": "mix", "tex1": "checks", "tex2": {"type": "scale", "tex": "wood", "scale": 0.5},
                "amount": 0.25},
      "checks": {"type": "checkerboard", "tex1": [0.9, 0.8, 0.7], "tex2": 0.1, "uv_scale": [4, 8],
                 "uv_offset": [0.5, 0.25]},
      "wood": {"type": "image", "filename": "checker.ppm", "wrap": "mirror", "encoding": "srgb", "filter": "nearest",
               "scale": 2, "invert": true, "uv_scale": 3, "uv_offset": [1, 2]}},
    "materials": {"m": {"type": "diffuse", "reflectance": "mixed"}}})");
  // "mixed" needs "checks" and an inline scale texture, which needs "wood": each comes after what it uses.
  ASSERT_EQ(scene.textures.size(), 4u);
  const auto& checks = std::get<CheckerboardTexture>(scene.textures[0]);
  EXPECT_TRUE(checks.tex1.is_constant());
  EXPECT_EQ(checks.tex1.value, RGB(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(checks.tex2.value, RGB(0.1f));
  testing::expect_mapping(checks.mapping, {.su = 4, .sv = 8, .du = 0.5f, .dv = 0.25f}, "checks");
  const auto& wood = std::get<ImageTexture>(scene.textures[1]);
  EXPECT_EQ(wood.filename, (kTextureDir / "checker.ppm").string());  // relative to the scene's directory
  testing::expect_image_settings(wood,
                                 {.wrap = TextureWrap::Mirror, .encoding = ColorEncoding::SRGB, .filter = TextureFilter::Nearest,
                                  .scale = 2, .invert = true, .mapping = {.su = 3, .sv = 3, .du = 1, .dv = 2}},
                                 "wood");
  const auto& scale = std::get<ScaleTexture>(scene.textures[2]);
  EXPECT_EQ(scale.tex.texture, 1);
  EXPECT_TRUE(scale.scale.is_constant());
  EXPECT_FLOAT_EQ(scale.scale.value, 0.5f);
  const auto& mixed = std::get<MixTexture>(scene.textures[3]);
  EXPECT_EQ(mixed.tex1.texture, 0);
  EXPECT_EQ(mixed.tex2.texture, 2);
  EXPECT_FLOAT_EQ(mixed.amount.value, 0.25f);
  const auto& diffuse = std::get<DiffuseMaterial>(scene.materials[0]);
  EXPECT_FALSE(diffuse.reflectance.is_constant());
  EXPECT_EQ(diffuse.reflectance.texture, 3);
}

TEST(JsonReader, TexturesGetTheDescriptionDefaults) {
  std::string absolute = (kTextureDir / "checker.ppm").string();
  SceneDesc scene = read(R"({"textures": {"image": {"type": "image", "filename": ")" + absolute + R"("},
      "checks": {"type": "checkerboard"}, "scaled": {"type": "scale"}, "mixed": {"type": "mix"}, "unused": {
      "type": "scale", "tex": 0.5}}})");  // an absolute path does not depend on the scene's directory
  // Unused named textures are kept, like materials.
  ASSERT_EQ(scene.textures.size(), 5u);
  const auto& image = std::get<ImageTexture>(scene.textures[0]);
  EXPECT_EQ(image.filename, absolute);
  testing::expect_image_settings(image, ImageTexture{}, "image");
  const auto& checks = std::get<CheckerboardTexture>(scene.textures[1]);
  EXPECT_EQ(checks.tex1.value, RGB(1));
  EXPECT_EQ(checks.tex2.value, RGB(0));
  EXPECT_EQ(std::get<ScaleTexture>(scene.textures[2]).scale.value, 1);
  EXPECT_FLOAT_EQ(std::get<MixTexture>(scene.textures[3]).amount.value, 0.5f);
  EXPECT_EQ(std::get<ScaleTexture>(scene.textures[4]).tex.value, RGB(0.5f));
  // Texture constants are not reflectances: they may exceed 1.
  EXPECT_NO_THROW(read(R"({"textures": {"t": {"type": "checkerboard", "tex1": 4}}})"));
}

TEST(JsonReader, MaterialParametersTakeConstantsNamesOrInlineTextures) {
  SceneDesc scene = read_textured(R"({"textures": {"rough": {"type": "image", "filename": "checker.ppm"}},
    "materials": {
      "a": {"type": "phong", "diffuse": {"type": "checkerboard", "tex1": 0.8, "tex2": 0.2}, "specular": "rough"},
      "b": {"type": "conductor", "roughness": "rough", "specular_tint": 0.9},
      "c": {"type": "dielectric", "alpha_u": {"type": "scale", "tex": "rough", "scale": 0.1}, "alpha_v": 0.05},
      "d": {"type": "mirror", "reflectance": "rough"}}})");
  ASSERT_EQ(scene.textures.size(), 3u);  // the named image, then the inline textures as they come
  const auto& phong = std::get<PhongMaterial>(scene.materials[0]);
  EXPECT_EQ(phong.diffuse.texture, 1);
  EXPECT_TRUE(std::holds_alternative<CheckerboardTexture>(scene.textures[1]));
  EXPECT_EQ(phong.specular.texture, 0);
  EXPECT_TRUE(phong.transmission.is_constant());
  const auto& conductor = std::get<ConductorMaterial>(scene.materials[1]);
  EXPECT_EQ(conductor.roughness.u.texture, 0);
  EXPECT_EQ(conductor.roughness.v.texture, 0);
  EXPECT_FALSE(conductor.roughness.remap);
  EXPECT_EQ(conductor.specular_tint.value, RGB(0.9f));
  const auto& dielectric = std::get<DielectricMaterial>(scene.materials[2]);
  EXPECT_EQ(dielectric.roughness.u.texture, 2);
  EXPECT_EQ(std::get<ScaleTexture>(scene.textures[2]).tex.texture, 0);
  EXPECT_TRUE(dielectric.roughness.v.is_constant());
  EXPECT_FLOAT_EQ(dielectric.roughness.v.value, 0.05f);
  EXPECT_EQ(std::get<MirrorMaterial>(scene.materials[3]).reflectance.texture, 0);
}

TEST(JsonReader, UvMatrixRotatesTextureCoordinates) {
  SceneDesc scene = read_textured(R"({"textures": {"t": {"type": "checkerboard", "uv_matrix": [[0, -2, 1], [2, 0, 0.5]]}},
      "materials": {"m": {"type": "diffuse", "reflectance": "t"}}, "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  const auto& c = std::get<CheckerboardTexture>(scene.textures[0]);
  EXPECT_FLOAT_EQ(c.mapping.su, 0);
  EXPECT_FLOAT_EQ(c.mapping.s_from_v, -2);
  EXPECT_FLOAT_EQ(c.mapping.du, 1);
  EXPECT_FLOAT_EQ(c.mapping.t_from_u, 2);
  EXPECT_FLOAT_EQ(c.mapping.sv, 0);
  EXPECT_FLOAT_EQ(c.mapping.dv, 0.5f);
  // Written back as a matrix and read again unchanged.
  SceneDesc back = read_json_scene(scene_to_json(scene), "back.json", kTextureDir);
  const auto& b = std::get<CheckerboardTexture>(back.textures[0]);
  EXPECT_EQ(b.mapping.s_from_v, -2);
  EXPECT_EQ(b.mapping.t_from_u, 2);
  EXPECT_EQ(b.mapping.dv, 0.5f);
  expect_textured_error(R"({"textures": {"t": {"type": "checkerboard", "uv_matrix": [[1, 2, 0], [2, 4, 0]]}}})",
                        "at /textures/t/uv_matrix: the uv matrix is singular");
  expect_textured_error(R"({"textures": {"t": {"type": "checkerboard", "uv_matrix": [[1, 0, 0], [0, 1, 0]], "uv_scale": 2}}})",
                        "either uv_matrix or uv_scale");
  expect_textured_error(R"({"textures": {"t": {"type": "checkerboard", "uv_matrix": [1, 0, 0, 1]}}})",
                        "expected [[su, s_from_v, du], [t_from_u, sv, dv]]");
}

TEST(JsonReader, TextureErrorsNameTheirJsonPointer) {
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "wrapp": "clamp"})"),
                        "at /textures/t/wrapp: unknown key (did you mean \"wrap\"?); expected one of: type, filename, wrap, encoding, filter, "
                        "scale, invert, luminance, uv_matrix, uv_scale, uv_offset");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "wrap": "tile"})"),
                        "at /textures/t/wrap: unknown wrap \"tile\"; expected one of: repeat, clamp, black, "
                        "mirror");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "encoding": "gamma"})"),
                        "at /textures/t/encoding: unknown encoding \"gamma\"; expected one of: auto, linear, "
                        "srgb");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "filter": "trilinear"})"),
                        "at /textures/t/filter: unknown filter \"trilinear\" (did you mean \"bilinear\"?); expected one of: bilinear, "
                        "nearest");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "filter": "nearst"})"),
                        "at /textures/t/filter: unknown filter \"nearst\" (did you mean \"nearest\"?); expected one of");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "scale": -1})"),
                        "at /textures/t/scale: expected a number >= 0, got -1");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "uv_scale": [1, 0]})"),
                        "at /textures/t/uv_scale: uv_scale factors must be non-zero, got [1, 0]");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "checker.ppm", "invert": 1})"),
                        "at /textures/t/invert: expected true or false");
  expect_textured_error(with_texture(R"({"type": "image"})"), "at /textures/t: missing required key \"filename\"");
  expect_textured_error(with_texture(R"({"type": "image", "filename": ""})"),
                        "at /textures/t/filename: the image file name is empty");
  expect_textured_error(with_texture(R"({"type": "image", "filename": "."})"), "it is a directory, not a file");
  expect_textured_error(with_texture(R"({"type": "noise"})"),
                        "at /textures/t/type: unknown texture type \"noise\"; expected one of: image, checkerboard, "
                        "scale, mix");
  expect_textured_error(with_texture(R"({"type": "mix", "amount": 1.5})"),
                        "at /textures/t/amount: expected a number in [0, 1], got 1.5");
  expect_textured_error(with_texture(R"({"type": "mix", "amount": [0.5]})"),
                        "at /textures/t/amount: expected a number or a texture (a name or an object), got an array");
  expect_textured_error(with_texture(R"({"type": "scale", "scale": -2})"),
                        "at /textures/t/scale: expected a number >= 0, got -2");
  expect_textured_error(with_texture(R"({"type": "checkerboard", "tex2": [0, -1, 0]})"),
                        "at /textures/t/tex2/1: colour components must be >= 0");
  expect_textured_error(with_texture(R"({"type": "checkerboard", "tex1": {"type": "scale", "tex": 1, "x": 2}})"),
                        "at /textures/t/tex1/x: unknown key");
  expect_textured_error(R"({"textures": []})", "at /textures: expected an object mapping texture names to textures");
  expect_textured_error(R"({"textures": {"a": {"type": "checkerboard"}, "b": {"type": "checkerboard"}},
                            "materials": {"m": {"type": "diffuse", "reflectance": "c"}}})",
                        "at /materials/m/reflectance: unknown texture \"c\"; defined: a, b");
}

TEST(JsonReader, MissingImageFileNamesTheFileAndPointer) {
  std::string message =
      error_of(with_texture(R"({"type": "image", "filename": "no-such-wood.png"})"), "/tmp/candela-no-dir");
  EXPECT_NE(message.find("at /textures/t/filename: cannot read image '/tmp/candela-no-dir/no-such-wood.png': no such "
                         "file"),
            std::string::npos)
      << message;
  // Inline textures are checked as they are read, wherever they are.
  message = error_of(with_material(R"({"type": "diffuse", "reflectance": {"type": "image", "filename": "x.png"}})"),
                     "/tmp/candela-no-dir");
  EXPECT_NE(message.find("at /materials/m/reflectance/filename: cannot read image"), std::string::npos) << message;
}

TEST(JsonReader, CyclicTexturesAreAnError) {
  expect_textured_error(R"({"textures": {"a": {"type": "scale", "tex": "b"}, "b": {"type": "mix", "tex1": "a"}}})",
                        "at /textures/b/tex1: textures refer to each other in a cycle: a -> b -> a");
  expect_textured_error(R"({"textures": {"a": {"type": "scale", "tex": "a"}}})",
                        "at /textures/a/tex: textures refer to each other in a cycle: a -> a");
  // Through an inline texture and a float parameter, starting past the first texture.
  expect_textured_error(R"({"textures": {"x": {"type": "checkerboard"},
                                         "a": {"type": "scale", "tex": {"type": "mix", "amount": "b"}},
                                         "b": {"type": "scale", "scale": "a"}}})",
                        "at /textures/b/scale: textures refer to each other in a cycle: a -> b -> a");
  // The message points at the name that closes the cycle, in the text too.
  EXPECT_EQ(textured_error_of("{\"textures\": {\n  \"a\": {\"type\": \"scale\", \"tex\": \"b\"},\n"
                              "  \"b\": {\"type\": \"mix\", \"tex1\": \"a\"}}}"),
            "test.json:3:24: at /textures/b/tex1: textures refer to each other in a cycle: a -> b -> a");
  // Deep nesting is an error, not a stack overflow.
  std::string deep = "{\"type\": \"checkerboard\"}";
  for (int i = 0; i < 100; ++i) deep = "{\"type\": \"scale\", \"tex\": " + deep + "}";
  expect_textured_error(with_texture(deep), "textures nest too deeply: more than 64 levels");
  std::string chain = R"({"textures": {)";  // t0 uses t1, which uses t2, ... t99, all defined later
  for (int i = 0; i < 99; ++i)
    chain += "\"t" + std::to_string(i) + R"(": {"type": "scale", "tex": "t)" + std::to_string(i + 1) + "\"}, ";
  expect_textured_error(chain + R"("t99": {"type": "checkerboard"}}})", "textures nest too deeply");
  // Two textures using a third is no cycle.
  EXPECT_EQ(read(R"({"textures": {"a": {"type": "mix", "tex1": "c", "tex2": "c"}, "c": {"type": "checkerboard"}}})")
                .textures.size(),
            2u);
}

// ---------------------------------------------------------------- microfacet and layered materials

TEST(JsonReader, ReadsConductors) {
  SceneDesc scene = read(with_material(R"({"type": "conductor"}, "gold": {"type": "conductor", "metal": "Au",
      "roughness": 0.2}, "custom": {"type": "conductor", "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.1],
      "alpha_u": 0.1, "alpha_v": 0.3, "specular_tint": [1, 0.9, 0.8]},
      "artist": {"type": "conductor", "reflectance": [0.9, 0.6, 0.3]})"));
  ASSERT_EQ(scene.materials.size(), 4u);
  const auto& copper = std::get<ConductorMaterial>(scene.materials[0]);
  EXPECT_EQ(copper.eta.value, ConductorMaterial{}.eta.value);
  EXPECT_EQ(copper.k.value, ConductorMaterial{}.k.value);
  EXPECT_FALSE(copper.reflectance.has_value());
  EXPECT_FLOAT_EQ(copper.roughness.u.value, 0);  // smooth
  EXPECT_FLOAT_EQ(copper.roughness.v.value, 0);
  EXPECT_FALSE(copper.roughness.remap);  // JSON gives GGX alpha
  const auto& gold = std::get<ConductorMaterial>(scene.materials[1]);
  EXPECT_NEAR(gold.eta.value.r, 0.1431189557f, 1e-6f);
  EXPECT_NEAR(gold.k.value.b, 1.6032152899f, 1e-6f);
  EXPECT_FLOAT_EQ(gold.roughness.u.value, 0.2f);
  EXPECT_FLOAT_EQ(gold.roughness.v.value, 0.2f);
  const auto& custom = std::get<ConductorMaterial>(scene.materials[2]);
  EXPECT_EQ(custom.eta.value, RGB(0.2f, 0.9f, 1.1f));
  EXPECT_EQ(custom.k.value, RGB(3.9f, 2.4f, 2.1f));
  EXPECT_FLOAT_EQ(custom.roughness.u.value, 0.1f);
  EXPECT_FLOAT_EQ(custom.roughness.v.value, 0.3f);
  EXPECT_EQ(custom.specular_tint.value, RGB(1, 0.9f, 0.8f));
  const auto& artist = std::get<ConductorMaterial>(scene.materials[3]);
  ASSERT_TRUE(artist.reflectance.has_value());
  EXPECT_EQ(artist.reflectance->value, RGB(0.9f, 0.6f, 0.3f));
  // Every preset reads: pbrt-v4's named metals and the further ones from Tungsten's table.
  for (const char* metal : {"Ag", "Al", "Au", "Cu", "CuZn", "Be", "Cr", "Hg", "Ir", "K", "Li", "Mo", "Na", "Nb", "Ni",
                            "Rh", "Ta", "TiN", "V", "W"})
    EXPECT_NO_THROW(read(with_material(std::string(R"({"type": "conductor", "metal": ")") + metal + "\"}"))) << metal;
  // The copper preset is the description's default.
  SceneDesc copper_scene = read(with_material(R"({"type": "conductor", "metal": "Cu"})"));
  const auto& cu = std::get<ConductorMaterial>(copper_scene.materials[0]);
  EXPECT_NEAR(cu.eta.value.g, ConductorMaterial{}.eta.value.g, 1e-6f);
  EXPECT_NEAR(cu.k.value.r, ConductorMaterial{}.k.value.r, 1e-6f);
}

TEST(JsonReader, ReadsDielectricsWithGlassAlias) {
  SceneDesc scene = read(with_material(R"({"type": "dielectric", "ior": 1.33, "roughness": 0.05,
      "reflectance": 0.9, "transmittance": [0.8, 0.9, 1]}, "old": {"type": "glass"})"));
  const auto& water = std::get<DielectricMaterial>(scene.materials[0]);
  EXPECT_FLOAT_EQ(water.ior, 1.33f);
  EXPECT_FLOAT_EQ(water.roughness.u.value, 0.05f);
  EXPECT_FLOAT_EQ(water.roughness.v.value, 0.05f);
  EXPECT_FALSE(water.roughness.remap);
  EXPECT_EQ(water.reflectance.value, RGB(0.9f));
  EXPECT_EQ(water.transmittance.value, RGB(0.8f, 0.9f, 1));
  const auto& glass = std::get<DielectricMaterial>(scene.materials[1]);
  EXPECT_FLOAT_EQ(glass.ior, 1.5f);
  EXPECT_FLOAT_EQ(glass.roughness.u.value, 0);
  EXPECT_EQ(glass.transmittance.value, RGB(1));
}

TEST(JsonReader, ReadsCoatedDiffuseWithPlasticAlias) {
  SceneDesc scene = read(with_material(R"({"type": "plastic", "reflectance": [0.1, 0.2, 0.6], "specular": 0.8,
      "ior": 1.6, "roughness": 0.15, "nonlinear": true}, "plain": {"type": "coated_diffuse"})"));
  const auto& plastic = std::get<CoatedDiffuseMaterial>(scene.materials[0]);
  EXPECT_EQ(plastic.reflectance.value, RGB(0.1f, 0.2f, 0.6f));
  EXPECT_EQ(plastic.specular.value, RGB(0.8f));
  EXPECT_FLOAT_EQ(plastic.ior, 1.6f);
  EXPECT_FLOAT_EQ(plastic.roughness.u.value, 0.15f);
  EXPECT_FLOAT_EQ(plastic.roughness.v.value, 0.15f);
  EXPECT_TRUE(plastic.nonlinear);
  const auto& plain = std::get<CoatedDiffuseMaterial>(scene.materials[1]);
  EXPECT_EQ(plain.reflectance.value, RGB(0.5f));
  EXPECT_EQ(plain.specular.value, RGB(1));
  EXPECT_FLOAT_EQ(plain.ior, 1.5f);
  EXPECT_FALSE(plain.nonlinear);
  EXPECT_FALSE(plain.tabulated_coat);
}

// pbrt-v4's layered materials: the coat's keys as coated_diffuse's, the slab's, and (for the coated
// conductor) the conductor's as a conductor's, its roughness under "conductor_".
TEST(JsonReader, ReadsLayeredMaterials) {
  SceneDesc scene = read(with_material(R"({"type": "layered_diffuse", "reflectance": [0.2, 0.4, 0.7], "ior": 1.4,
      "roughness": 0.1, "remap_roughness": true, "thickness": 0.05, "albedo": [0.5, 0.5, 0.1], "g": -0.3,
      "max_depth": 20, "samples": 4},
      "lacquered gold": {"type": "coated_conductor", "metal": "Au", "roughness": 0.05, "conductor_alpha_u": 0.3,
      "conductor_alpha_v": 0.1, "conductor_distribution": "beckmann"},
      "painted": {"type": "layered_conductor", "reflectance": [0.9, 0.5, 0.2], "conductor_roughness": 0.2,
      "conductor_remap_roughness": true},
      "default": {"type": "layered_conductor"})"));
  const auto& diffuse = std::get<LayeredDiffuseMaterial>(scene.materials[0]);
  EXPECT_EQ(diffuse.reflectance.value, RGB(0.2f, 0.4f, 0.7f));
  EXPECT_FLOAT_EQ(diffuse.ior, 1.4f);
  EXPECT_FLOAT_EQ(diffuse.roughness.u.value, 0.1f);
  EXPECT_TRUE(diffuse.roughness.remap);
  EXPECT_FLOAT_EQ(diffuse.layer.thickness.value, 0.05f);
  EXPECT_EQ(diffuse.layer.albedo.value, RGB(0.5f, 0.5f, 0.1f));
  EXPECT_FLOAT_EQ(diffuse.layer.g.value, -0.3f);
  EXPECT_EQ(diffuse.layer.max_depth, 20);
  EXPECT_EQ(diffuse.layer.samples, 4);
  const auto& gold = std::get<LayeredConductorMaterial>(scene.materials[1]);
  const SceneDesc bare = read(with_material(R"({"type": "conductor", "metal": "Au"})"));
  const auto& au = std::get<ConductorMaterial>(bare.materials[0]);
  EXPECT_EQ(gold.eta.value, au.eta.value);
  EXPECT_EQ(gold.k.value, au.k.value);
  EXPECT_FLOAT_EQ(gold.roughness.u.value, 0.05f);
  EXPECT_FLOAT_EQ(gold.conductor_roughness.u.value, 0.3f);
  EXPECT_FLOAT_EQ(gold.conductor_roughness.v.value, 0.1f);
  EXPECT_EQ(gold.conductor_roughness.distribution, MicrofacetDistribution::Beckmann);
  EXPECT_EQ(gold.roughness.distribution, MicrofacetDistribution::GGX);
  const auto& painted = std::get<LayeredConductorMaterial>(scene.materials[2]);
  ASSERT_TRUE(painted.reflectance);
  EXPECT_EQ(painted.reflectance->value, RGB(0.9f, 0.5f, 0.2f));
  EXPECT_TRUE(painted.conductor_roughness.remap);
  EXPECT_FALSE(painted.roughness.remap);
  const auto& defaults = std::get<LayeredConductorMaterial>(scene.materials[3]);
  EXPECT_FLOAT_EQ(defaults.ior, 1.5f);
  EXPECT_FLOAT_EQ(defaults.layer.thickness.value, 0.01f);
  EXPECT_EQ(defaults.layer.albedo.value, RGB(0.0f));
  EXPECT_EQ(defaults.layer.max_depth, 10);
  EXPECT_EQ(defaults.layer.samples, 1);
  EXPECT_EQ(defaults.eta.value, ConductorMaterial{}.eta.value);  // copper, as pbrt-v4's

  expect_error_containing(with_material(R"({"type": "layered_diffuse", "samples": 0})"),
                          "at /materials/m/samples: expected an integer in [1, 65535], got 0");
  expect_error_containing(with_material(R"({"type": "layered_diffuse", "g": 1.5})"), "at /materials/m/g");
  expect_error_containing(with_material(R"({"type": "coated_conductor", "conductor_alpha_u": 0.2})"),
                          "missing required key \"conductor_alpha_v\"");
  expect_error_containing(with_material(R"({"type": "coated_conductor", "metal": "Au", "reflectance": 0.5})"),
                          "a conductor takes only one of");
  expect_error_containing(with_material(R"({"type": "coated_conductor", "conductor_roughnes": 0.2})"),
                          "conductor_roughness");
}

TEST(JsonReader, TabulatedCoatNeedsAConstantRoughness) {
  SceneDesc scene = read(with_material(R"({"type": "plastic", "roughness": 0.1, "tabulated_coat": true})"));
  EXPECT_TRUE(std::get<CoatedDiffuseMaterial>(scene.materials[0]).tabulated_coat);
  expect_error_containing(
      with_material(R"({"type": "plastic", "tabulated_coat": true,
          "roughness": {"type": "checkerboard", "tex1": 0.1, "tex2": 0.3}})"),
      "/tabulated_coat: a tabulated coat needs a constant roughness");
}

TEST(JsonReader, ReadsDiffuseTransmissionAndInterface) {
  SceneDesc scene = read(with_material(R"({"type": "diffuse_transmission", "reflectance": 0.3,
      "transmittance": [0.6, 0.7, 0.2]}, "leaf": {"type": "diffuse_transmission"}, "boundary": {"type": "interface"},
      "nothing": {"type": "null"})"));
  const auto& lamp_shade = std::get<DiffuseTransmissionMaterial>(scene.materials[0]);
  EXPECT_EQ(lamp_shade.reflectance.value, RGB(0.3f));
  EXPECT_EQ(lamp_shade.transmittance.value, RGB(0.6f, 0.7f, 0.2f));
  const auto& leaf = std::get<DiffuseTransmissionMaterial>(scene.materials[1]);
  EXPECT_EQ(leaf.reflectance.value, RGB(0.25f));
  EXPECT_EQ(leaf.transmittance.value, RGB(0.25f));
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(scene.materials[2]));
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(scene.materials[3]));
}

TEST(JsonReader, ReadsHair) {
  SceneDesc scene = read(with_material(R"({"type": "hair"},
      "dyed": {"type": "hair", "sigma_a": [0.2, 0.5, 1.5], "eta": 1.5, "beta_m": 0.2, "beta_n": 0.5, "alpha": 3},
      "blond": {"type": "hair", "reflectance": [0.8, 0.6, 0.3]},
      "red": {"type": "hair", "eumelanin": 0.3, "pheomelanin": {"type": "checkerboard", "tex1": 0.5, "tex2": 2}})"));
  const auto& brown = std::get<HairMaterial>(scene.materials[0]);
  EXPECT_FALSE(brown.sigma_a || brown.reflectance);
  EXPECT_EQ(brown.eumelanin.value, 1.3f);
  EXPECT_EQ(brown.pheomelanin.value, 0.0f);
  EXPECT_EQ(brown.eta.value, 1.55f);
  EXPECT_EQ(brown.beta_m.value, 0.3f);
  EXPECT_EQ(brown.beta_n.value, 0.3f);
  EXPECT_EQ(brown.alpha.value, 2.0f);
  const auto& dyed = std::get<HairMaterial>(scene.materials[1]);
  EXPECT_EQ(dyed.sigma_a->value, RGB(0.2f, 0.5f, 1.5f));
  EXPECT_EQ(dyed.eta.value, 1.5f);
  EXPECT_EQ(dyed.beta_m.value, 0.2f);
  EXPECT_EQ(dyed.beta_n.value, 0.5f);
  EXPECT_EQ(dyed.alpha.value, 3.0f);
  EXPECT_EQ(std::get<HairMaterial>(scene.materials[2]).reflectance->value, RGB(0.8f, 0.6f, 0.3f));
  const auto& red = std::get<HairMaterial>(scene.materials[3]);
  EXPECT_EQ(red.eumelanin.value, 0.3f);
  EXPECT_GE(red.pheomelanin.texture, 0);
  expect_error_containing(with_material(R"({"type": "hair", "sigma_a": 1, "reflectance": 0.5})"),
                          "at /materials/m/reflectance: give either \"reflectance\" or \"sigma_a\", not both");
  expect_error_containing(with_material(R"({"type": "hair", "reflectance": 0.5, "eumelanin": 2})"),
                          "at /materials/m/eumelanin: give either \"eumelanin\" or \"reflectance\", not both");
  expect_error_containing(with_material(R"({"type": "hair", "sigma_a": 1, "pheomelanin": 2})"),
                          "at /materials/m/pheomelanin: give either \"pheomelanin\" or \"sigma_a\", not both");
  expect_error_containing(with_material(R"({"type": "hair", "reflectance": 1.5})"),
                          "at /materials/m/reflectance: a reflectance must be <= 1");
  expect_error_containing(with_material(R"({"type": "hair", "sigma_a": -1})"),
                          "at /materials/m/sigma_a: colour components must be >= 0");
  expect_error_containing(with_material(R"({"type": "hair", "beta_m": 1.5})"),
                          "at /materials/m/beta_m: expected a number in [0, 1], got 1.5");
  expect_error_containing(with_material(R"({"type": "hair", "eta": 0})"),
                          "at /materials/m/eta: expected a positive number, got 0");
}

TEST(JsonReader, BadMicrofacetMaterialValuesAreErrors) {
  expect_error_containing(with_material(R"({"type": "conductor", "roughness": -0.1})"),
                          "at /materials/m/roughness: expected a number >= 0, got -0.1");
  expect_error_containing(with_material(R"({"type": "dielectric", "alpha_u": 0.1, "alpha_v": -1})"),
                          "at /materials/m/alpha_v: expected a number >= 0, got -1");
  expect_error_containing(with_material(R"({"type": "plastic", "alpha_u": 0.1})"),
                          "at /materials/m: missing required key \"alpha_v\" (an anisotropic roughness needs alpha_u "
                          "and alpha_v)");
  expect_error_containing(
      with_material(R"({"type": "conductor", "roughness": 0.1, "alpha_v": 0.2})"),
      "at /materials/m/alpha_v: give either \"roughness\" or \"alpha_u\" and \"alpha_v\", not both");
  expect_error_containing(with_material(R"({"type": "conductor", "roughness": [0.1, 0.2]})"),
                          "at /materials/m/roughness: expected a number or a texture");
  expect_error_containing(with_material(R"({"type": "conductor", "eta": [1, -0.5, 1]})"),
                          "at /materials/m/eta/1: colour components must be >= 0");
  expect_error_containing(with_material(R"({"type": "conductor", "k": -1})"),
                          "at /materials/m/k: colour components must be >= 0");
  expect_error_containing(with_material(R"({"type": "conductor", "metal": "Unobtainium"})"),
                          "at /materials/m/metal: unknown metal \"Unobtainium\"; expected one of: Ag, Al, Au, Be, "
                          "Cr, Cu, CuZn, Hg, Ir, K, Li, MgO, Mo, Na, Nb, Ni, Rh, Ta, TiN, TiO2, V, W");
  expect_error_containing(with_material(R"({"type": "conductor", "metal": "Au", "k": [1, 1, 1]})"),
                          "at /materials/m: a conductor takes only one of: \"eta\"/\"k\", \"reflectance\", \"metal\"");
  expect_error_containing(with_material(R"({"type": "conductor", "reflectance": 1.5})"),
                          "at /materials/m/reflectance: a reflectance must be <= 1");
  expect_error_containing(with_material(R"({"type": "conductor", "specular_tint": [1, 2, 1]})"),
                          "at /materials/m/specular_tint/1: a reflectance must be <= 1");
  expect_error_containing(with_material(R"({"type": "conductor", "ior": 1.5})"), "at /materials/m/ior: unknown key");
  expect_error_containing(with_material(R"({"type": "dielectric", "ior": 0})"),
                          "at /materials/m/ior: expected a positive number, got 0");
  expect_error_containing(with_material(R"({"type": "dielectric", "ior": "glass"})"),
                          "at /materials/m/ior: expected a number, got string");
  expect_error_containing(with_material(R"({"type": "coated_diffuse", "ior": -1.5})"),
                          "at /materials/m/ior: expected a positive number");
  expect_error_containing(with_material(R"({"type": "coated_diffuse", "nonlinear": 1})"),
                          "at /materials/m/nonlinear: expected true or false");
  expect_error_containing(with_material(R"({"type": "diffuse_transmission", "reflectance": 0.6,
                                            "transmittance": [0.3, 0.5, 0.3]})"),
                          "at /materials/m: reflectance + transmittance must be <= 1 in each channel (more would "
                          "create energy), got 0.6 + 0.5 in the green channel");
  expect_error_containing(with_material(R"({"type": "interface", "ior": 1})"), "at /materials/m/ior: unknown key");
  expect_error_containing(with_material(R"({"type": "diffuse", "roughness": 0.1})"),
                          "at /materials/m/roughness: unknown key");
}

// ---------------------------------------------------------------- spot, distant and environment lights

TEST(JsonReader, ReadsSpotAndDistantLights) {
  SceneDesc scene = read(with_light(R"(
      {"type": "spot", "position": [0, 4, 0], "direction": [0, -2, 0], "intensity": [50, 40, 30],
       "cone_angle": 25, "cone_delta": 10},
      {"type": "spot", "position": [1, 1, 1], "look_at": [1, 1, 5], "intensity": 20},
      {"type": "spot", "position": [0, 0, 0], "direction": [1, 0, 0], "intensity": 1, "cone_angle": 3},
      {"type": "distant", "direction": [0, -3, 4], "radiance": [3, 3, 2.5]})"));
  ASSERT_EQ(scene.lights.size(), 4u);
  const auto& down = std::get<SpotLight>(scene.lights[0]);
  EXPECT_EQ(down.position, Vec3(0, 4, 0));
  expect_near(down.direction, {0, -1, 0});
  EXPECT_EQ(down.intensity, RGB(50, 40, 30));
  EXPECT_FLOAT_EQ(down.cone_angle, 25);
  EXPECT_FLOAT_EQ(down.cone_delta, 10);
  const auto& aimed = std::get<SpotLight>(scene.lights[1]);
  expect_near(aimed.direction, {0, 0, 1});
  EXPECT_FLOAT_EQ(aimed.cone_angle, 30);  // the description's defaults
  EXPECT_FLOAT_EQ(aimed.cone_delta, 5);
  const auto& narrow = std::get<SpotLight>(scene.lights[2]);
  EXPECT_FLOAT_EQ(narrow.cone_delta, 3);  // the default fall-off never exceeds the cone
  const auto& sun = std::get<DistantLight>(scene.lights[3]);
  expect_near(sun.direction, {0, -0.6f, 0.8f});
  EXPECT_EQ(sun.radiance, RGB(3, 3, 2.5f));
}

TEST(JsonReader, ReadsEnvironmentMaps) {
  SceneDesc scene = read_textured(with_light(R"(
      {"type": "environment", "filename": "sky.hdr"},
      {"type": "environment", "filename": "sky.hdr", "mapping": "equal_area", "up": [0, 1, 0], "scale": [1, 0.5, 2]},
      {"type": "environment", "filename": "sky.hdr", "rotate": 90},
      {"type": "environment", "filename": "sky.hdr", "up": [0, 0, -1], "rotate": 90},
      {"type": "environment", "filename": "sky.hdr", "up": [0, -1, 0]},
      {"type": "environment", "filename": "sky.hdr", "scale": 3,
       "transform": [{"rotate": {"angle": 90, "axis": [1, 0, 0]}}, {"scale": [-1, 1, 1]}]})"));
  ASSERT_EQ(scene.lights.size(), 6u);
  const auto& plain = std::get<EnvironmentMap>(scene.lights[0]);
  EXPECT_EQ(plain.filename, (kTextureDir / "sky.hdr").string());
  EXPECT_EQ(plain.mapping, EnvironmentMapping::Equirectangular);
  EXPECT_EQ(plain.scale, RGB(1));
  EXPECT_TRUE(plain.to_world.is_identity());
  const auto& octahedral = std::get<EnvironmentMap>(scene.lights[1]);
  EXPECT_EQ(octahedral.mapping, EnvironmentMapping::EqualAreaOctahedral);
  EXPECT_EQ(octahedral.scale, RGB(1, 0.5f, 2));
  expect_near(octahedral.to_world.vector({0, 0, 1}), {0, 1, 0});  // its own up is +z
  const auto& spun = std::get<EnvironmentMap>(scene.lights[2]);
  expect_near(spun.to_world.vector({0, 1, 0}), {0, 1, 0});
  expect_near(spun.to_world.vector({0, 0, 1}), {1, 0, 0});  // right-hand rule about +y
  const auto& tilted = std::get<EnvironmentMap>(scene.lights[3]);
  expect_near(tilted.to_world.vector({0, 1, 0}), {0, 0, -1});
  expect_near(tilted.to_world.vector({0, 0, 1}), {1, 0, 0});  // rotated about its own up first
  const auto& flipped = std::get<EnvironmentMap>(scene.lights[4]);
  expect_near(flipped.to_world.vector({0, 1, 0}), {0, -1, 0});
  const auto& transformed = std::get<EnvironmentMap>(scene.lights[5]);
  EXPECT_EQ(transformed.scale, RGB(3));
  expect_near(transformed.to_world.vector({0, 1, 0}), {0, 0, 1});
  expect_near(transformed.to_world.vector({1, 0, 0}), {-1, 0, 0});  // mirrors are allowed
}

TEST(JsonReader, BadSpotDistantAndEnvironmentLightsAreErrors) {
  auto spot = [](const std::string& extra) {
    return with_light(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, 0, 1], "intensity": 1)" + extra +
                      "}");
  };
  expect_error_containing(spot(R"(, "cone_angle": 0)"),
                          "at /lights/0/cone_angle: expected a number in (0, 180], got 0");
  expect_error_containing(spot(R"(, "cone_angle": 181)"), "expected a number in (0, 180], got 181");
  EXPECT_NO_THROW(read(spot(R"(, "cone_angle": 180)")));
  expect_error_containing(spot(R"(, "cone_angle": 30, "cone_delta": 40)"),
                          "at /lights/0/cone_delta: cone_delta must be in [0, cone_angle] = [0, 30] degrees, got 40");
  expect_error_containing(spot(R"(, "cone_delta": -1)"), "at /lights/0/cone_delta: expected a number in [0, 180], got -1");
  expect_error_containing(spot(R"(, "look_at": [0, 0, 1])"),
                          "at /lights/0/look_at: a spot light takes either \"direction\" or \"look_at\", not both");
  expect_error_containing(spot(R"(, "radius": 1)"), "at /lights/0/radius: unknown key");
  expect_error_containing(with_light(R"({"type": "spot", "position": [0, 0, 0], "intensity": 1})"),
                          "at /lights/0: a spot light needs \"direction\" or \"look_at\"");
  expect_error_containing(
      with_light(R"({"type": "spot", "position": [1, 2, 3], "look_at": [1, 2, 3], "intensity": 1})"),
      "at /lights/0/look_at: look_at must differ from position");
  expect_error_containing(with_light(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, 0, 1]})"),
                          "at /lights/0: missing required key \"intensity\"");
  expect_error_containing(with_light(R"({"type": "distant", "direction": [0, 0, 0], "radiance": 1})"),
                          "at /lights/0/direction: expected a non-zero vector");
  expect_error_containing(with_light(R"({"type": "distant", "direction": [0, -1, 0]})"),
                          "at /lights/0: missing required key \"radiance\"");
  expect_error_containing(with_light(R"({"type": "distant", "direction": [0, -1, 0], "radiance": -1})"),
                          "at /lights/0/radiance: colour components must be >= 0");

  auto environment = [](const std::string& extra) {
    return textured_error_of(with_light(R"({"type": "environment", "filename": "sky.hdr")" + extra + "}"));
  };
  auto expect_environment_error = [&](const std::string& extra, const std::string& fragment) {
    std::string message = environment(extra);
    EXPECT_NE(message.find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << message;
  };
  std::string missing =
      error_of(with_light(R"({"type": "environment", "filename": "no-such-sky.exr"})"), "/tmp/candela-no-dir");
  EXPECT_NE(missing.find("at /lights/0/filename: cannot read environment map '/tmp/candela-no-dir/no-such-sky.exr': "
                         "no such file"),
            std::string::npos)
      << missing;
  expect_textured_error(with_light(R"({"type": "environment"})"), "at /lights/0: missing required key \"filename\"");
  expect_environment_error(R"(, "mapping": "cube")",
                           "at /lights/0/mapping: unknown mapping \"cube\"; expected one of: "
                           "equirectangular, equirectangular_pole_rows, equal_area");
  expect_environment_error(R"(, "scale": -1)", "at /lights/0/scale: colour components must be >= 0");
  expect_environment_error(R"(, "scale": [1, 1e39, 1])",
                           "at /lights/0/scale/1: 1e+39 is out of range for a 32-bit float");
  expect_environment_error(R"(, "up": [0, 0, 0])", "at /lights/0/up: expected a non-zero vector");
  expect_environment_error(R"(, "rotate": "left")", "at /lights/0/rotate: expected a number, got string");
  expect_environment_error(R"(, "up": [0, 1, 0], "transform": [])",
                           "at /lights/0/transform: an environment map takes either \"transform\" or "
                           "\"up\"/\"rotate\", not both");
  expect_environment_error(R"(, "transform": [{"translate": [0, 1, 0]}])",
                           "at /lights/0/transform: an environment map's transform may only rotate (or mirror) it, not "
                           "translate it");
  expect_environment_error(R"(, "transform": [{"scale": 2}])", "not scale or shear it");
  expect_environment_error(R"(, "transform": [{"rotate": {"angle": 10}}])",
                           "at /lights/0/transform/0/rotate: missing required key \"axis\"");
  expect_environment_error(R"(, "two_sided": true)", "at /lights/0/two_sided: unknown key");
}

// ---------------------------------------------------------------- instancing

TEST(JsonReader, ReadsObjectsAndInstances) {
  SceneDesc scene = read(R"({"materials": {"bark": {"type": "diffuse", "reflectance": [0.3, 0.2, 0.1]}},
    "objects": {
      "tree": {"_comment": "a trunk and a crown", "shapes": [
        {"type": "box", "min": [-0.1, 0, -0.1], "max": [0.1, 1, 0.1], "material": "bark"},
        {"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": {"type": "diffuse", "reflectance": 0.2},
         "transform": [{"translate": [0, 1.2, 0]}]}]},
      "rock": {"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.3}]}},
    "shapes": [
      {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
      {"type": "instance", "object": "tree", "transform": [{"translate": [2, 0, 0]}]},
      {"type": "instance", "object": "rock"},
      {"type": "instance", "object": "tree", "transform": [{"scale": 2}],
       "transform_end": [{"scale": 2}, {"translate": [0, 1, 0]}]}]})");
  ASSERT_EQ(scene.objects.size(), 2u);
  const ObjectDesc& tree = scene.objects[0];
  EXPECT_EQ(tree.name, "tree");
  ASSERT_EQ(tree.shapes.size(), 2u);
  EXPECT_EQ(tree.shapes[0].material, 0);
  // Inline materials are appended as usual.
  EXPECT_EQ(tree.shapes[1].material, 1);
  expect_near(tree.shapes[1].to_world.point({0, 0, 0}), {0, 1.2f, 0});  // relative to the object
  EXPECT_EQ(scene.objects[1].name, "rock");
  ASSERT_EQ(scene.shapes.size(), 1u);  // instances are not shapes
  ASSERT_EQ(scene.instances.size(), 3u);
  EXPECT_EQ(scene.instances[0].object, 0);
  expect_near(scene.instances[0].to_world.point({0, 0, 0}), {2, 0, 0});
  EXPECT_FALSE(scene.instances[0].to_world_end.has_value());
  EXPECT_EQ(scene.instances[1].object, 1);
  EXPECT_TRUE(scene.instances[1].to_world.is_identity());
  ASSERT_TRUE(scene.instances[2].to_world_end.has_value());
  expect_near(scene.instances[2].to_world_end->point({0, 1, 0}), {0, 3, 0});
}

TEST(JsonReader, BadObjectsAndInstancesAreErrors) {
  auto with_object = [](const std::string& object_shapes, const std::string& shapes = "[]") {
    return R"({"objects": {"o": {"shapes": )" + object_shapes + R"(}}, "shapes": )" + shapes + "}";
  };
  const std::string sphere = R"({"type": "sphere", "center": [0, 0, 0], "radius": 1})";
  expect_error_containing(
      with_object(R"([{"type": "sphere", "center": [0, 0, 0], "radius": 1, "emission": {"radiance": 1}}])"),
      "at /objects/o/shapes/0/emission: a shape in an object cannot emit light");
  expect_error_containing(with_object("[" + sphere + R"(, {"type": "instance", "object": "o"}])"),
                          "at /objects/o/shapes/1/type: an object cannot contain instances (objects do not nest)");
  expect_error_containing(
      with_object(R"([{"type": "sphere", "center": [0, 0, 0], "radius": 1, "transform_end": []}])"),
      "at /objects/o/shapes/0/transform_end: a shape in an object cannot move; give the instance a transform_end");
  expect_error_containing(with_object("[]"), "at /objects/o/shapes: an object needs at least one shape");
  expect_error_containing(with_object("{}"), "at /objects/o/shapes: expected an array of shapes");
  expect_error_containing(R"({"objects": {"o": {}}})", "at /objects/o: missing required key \"shapes\"");
  expect_error_containing(R"({"objects": {"o": {"shapes": [], "lights": []}}})",
                          "at /objects/o/shapes: an object needs");
  expect_error_containing(R"({"objects": {"o": {"shapes": [)" + sphere + R"(], "lights": []}}})",
                          "at /objects/o/lights: unknown key; expected one of: shapes");
  expect_error_containing(R"({"objects": []})", "at /objects: expected an object mapping object names to objects");
  expect_error_containing(with_object("[" + sphere + "]", R"([{"type": "instance", "object": "p"}])"),
                          "at /shapes/0/object: unknown object \"p\"; defined: o");
  expect_error_containing(R"({"shapes": [{"type": "instance", "object": "p"}]})",
                          "at /shapes/0/object: unknown object \"p\" (\"objects\" defines none)");
  expect_error_containing(with_object("[" + sphere + "]", R"([{"type": "instance"}])"),
                          "at /shapes/0: missing required key \"object\"");
  expect_error_containing(with_object("[" + sphere + "]", R"([{"type": "instance", "object": "o", "material": "x"}])"),
                          "at /shapes/0/material: unknown key; expected one of: type, object, transform, "
                          "transform_end");
  expect_error_containing(
      with_object(R"([{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}])",
                  R"([{"type": "instance", "object": "o", "transform_end": [{"translate": [0, 1, 0]}]}])"),
      "at /shapes/0/transform_end: an infinite plane must not move: object \"o\" contains one");
  expect_error_containing(
      with_object("[" + sphere + "]", R"([{"type": "instance", "object": "o", "transform": [{"scale": 0}]}])"),
      "at /shapes/0/transform/0/scale: scale factors must be non-zero");
}

TEST(JsonReader, EntriesRecordTheirPlaceInTheFile) {
  const std::string text = R"({
  "textures": {"checks": {"type": "checkerboard"}},
  "materials": {
    "red": {"type": "diffuse", "reflectance": [0.5, 0, 0]},
    "coat": {"type": "coated_diffuse", "reflectance": {"type": "checkerboard"}}
  },
  "objects": {"pair": {"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]}},
  "shapes": [
    {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "red"},
    {"type": "instance", "object": "pair"}
  ],
  "lights": [{"type": "point", "position": [0, 1, 0], "intensity": 1},
             {"type": "sphere", "center": [0, 2, 0], "radius": 0.1, "radiance": 1}]
})";
  const SceneDesc scene = read(text);
  auto expect_at = [](const SourceLocation& where, int line, int column, const std::string& key_path) {
    EXPECT_EQ(where.file, "test.json");
    EXPECT_EQ(where.line, line) << key_path;
    EXPECT_EQ(where.column, column) << key_path;
    EXPECT_EQ(where.key_path, key_path);
  };
  // An object member's place is its key; an array element's, its value.
  ASSERT_EQ(scene.places.textures.size(), scene.textures.size());
  ASSERT_EQ(scene.textures.size(), 2u);
  expect_at(scene.places.textures[0], 2, 16, "/textures/checks");
  expect_at(scene.places.textures[1], 5, 40, "/materials/coat/reflectance");  // inline
  ASSERT_EQ(scene.places.materials.size(), scene.materials.size());
  ASSERT_EQ(scene.materials.size(), 3u);
  expect_at(scene.places.materials[0], 4, 5, "/materials/red");
  expect_at(scene.places.materials[1], 5, 5, "/materials/coat");
  EXPECT_TRUE(scene.places.materials[2].file.empty());  // the shape light's black material
  ASSERT_EQ(scene.objects.size(), 1u);
  expect_at(scene.objects[0].where, 7, 15, "/objects/pair");
  expect_at(scene.objects[0].shapes[0].where, 7, 35, "/objects/pair/shapes/0");
  ASSERT_EQ(scene.shapes.size(), 2u);
  expect_at(scene.shapes[0].where, 9, 5, "/shapes/0");
  expect_at(scene.shapes[1].where, 13, 14, "/lights/1");  // a sphere light is an emitting shape
  ASSERT_EQ(scene.instances.size(), 1u);
  expect_at(scene.instances[0].where, 10, 5, "/shapes/1");
  ASSERT_EQ(scene.places.lights.size(), scene.lights.size());
  ASSERT_EQ(scene.lights.size(), 1u);
  expect_at(scene.places.lights[0], 12, 14, "/lights/0");
}

}  // namespace
}  // namespace candela
