// Tests of the pbrt-v4 reader's "subsurface" material: a dielectric boundary filling its shapes with a
// subsurface medium (random-walked by volpath), given by a named preset, by sigma_a and sigma_s, by
// reflectance and mfp, or by pbrt-v4's default; the media around it; the integrators that render only
// the boundary; the errors; and the round trip through candela's JSON.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "candela/description/scene_desc.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/media/subsurface_albedo.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;

void expect_rgb_close(const RGB& actual, const RGB& expected, float relative = 1e-5f) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(actual[c], expected[c], relative * std::max(1.0f, std::abs(expected[c]))) << "channel " << c;
}

RGB sigma_a_of(const MediumDesc& m) { return m.sigma_t * (RGB(1.0f) - m.albedo.constant); }
RGB sigma_s_of(const MediumDesc& m) { return m.sigma_t * m.albedo.constant; }

const DielectricMaterial& boundary_of(const SceneDesc& scene, const ShapeDesc& shape) {
  return std::get<DielectricMaterial>(scene.materials.at(shape.material));
}

TEST(PbrtSubsurface, NamedPresetFillsTheShapeWithItsScaledCoefficients) {
  Warned read = read_warned({"WorldBegin",
                             "Material \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 10 \"float eta\" 1.4",
                             "Shape \"sphere\" \"float radius\" 0.8"});
  EXPECT_TRUE(read.warnings.empty()) << joined(read.warnings);
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(scene.shapes.size(), 1u);
  ASSERT_EQ(scene.media.size(), 1u);
  const ShapeDesc& sphere = scene.shapes[0];
  const DielectricMaterial& boundary = boundary_of(scene, sphere);
  EXPECT_FLOAT_EQ(boundary.ior, 1.4f);
  EXPECT_FALSE(boundary.thin);
  EXPECT_EQ(sphere.interior_medium, 0);
  EXPECT_EQ(sphere.exterior_medium, -1);
  const MediumDesc& skin = scene.media[0];
  // Jensen et al. 2001's skin 1 per mm, times 10, in the scene's units (as pbrt-v4 takes them).
  expect_rgb_close(sigma_s_of(skin), RGB(7.4f, 8.8f, 10.1f));
  expect_rgb_close(sigma_a_of(skin), RGB(0.32f, 1.7f, 4.8f));
  EXPECT_FLOAT_EQ(skin.scale, 1);
  EXPECT_FLOAT_EQ(skin.g, 0);
  EXPECT_TRUE(skin.subsurface);
  EXPECT_TRUE(skin.is_homogeneous());
  EXPECT_EQ(skin.where.line, 2);
  EXPECT_EQ(scene.settings.integrator, "volpath");  // pbrt-v4's default integrator renders the BSSRDF
}

TEST(PbrtSubsurface, SigmaAndSigmaSWithRoughnessAndG) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "MakeNamedMaterial \"jade\" \"string type\" \"subsurface\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ]",
                                "  \"rgb sigma_s\" [ 3 2 1 ] \"float scale\" 2 \"float g\" 0.3 \"float roughness\" 0.2",
                                "NamedMaterial \"jade\"", "Shape \"sphere\"", "Translate 3 0 0", "Shape \"sphere\""});
  ASSERT_EQ(scene.media.size(), 1u);
  const MediumDesc& jade = scene.media[0];
  expect_rgb_close(sigma_a_of(jade), RGB(0.2f, 0.4f, 0.6f));
  expect_rgb_close(sigma_s_of(jade), RGB(6, 4, 2));
  EXPECT_FLOAT_EQ(jade.g, 0.3f);
  ASSERT_EQ(scene.shapes.size(), 2u);
  for (const ShapeDesc& shape : scene.shapes) {  // one medium for every shape of the material
    EXPECT_EQ(shape.interior_medium, 0);
    const DielectricMaterial& boundary = boundary_of(scene, shape);
    EXPECT_FLOAT_EQ(boundary.ior, 1.33f);  // pbrt-v4's default eta
    EXPECT_FLOAT_EQ(boundary.roughness.u.value, 0.2f);
    EXPECT_FLOAT_EQ(boundary.roughness.v.value, 0.2f);
    EXPECT_TRUE(boundary.roughness.remap);
  }
}

TEST(PbrtSubsurface, ReflectanceAndMfpInvertTheEffectiveAlbedo) {
  SceneDesc scene = read_lines({"WorldBegin",
                                "Material \"subsurface\" \"rgb reflectance\" [ 0.2 0.5 0.8 ] \"rgb mfp\" [ 1 2 0.5 ]",
                                "  \"float scale\" 0.5 \"float eta\" 1.5 \"float g\" 0.2",
                                "Shape \"sphere\""});
  ASSERT_EQ(scene.media.size(), 1u);
  const MediumDesc& m = scene.media[0];
  // pbrt-v4 scales the mean free path: sigma_t = 1 / (scale mfp).
  expect_rgb_close(m.sigma_t, RGB(2, 1, 4));
  const float reflectance[3] = {0.2f, 0.5f, 0.8f};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(m.albedo.constant[c], subsurface_albedo_from_effective(reflectance[c], 0.2, 1.5), 1e-6);
    // The medium gives back the reflectance asked for.
    EXPECT_NEAR(subsurface_effective_albedo(m.albedo.constant[c], 0.2, 1.5), reflectance[c], 1e-4);
  }
  EXPECT_FLOAT_EQ(m.g, 0.2f);
  // Without "mfp", it is 1.
  SceneDesc unit = read_lines({"WorldBegin", "Material \"subsurface\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]", "Shape \"sphere\""});
  expect_rgb_close(unit.media.at(0).sigma_t, RGB(1.0f));
}

TEST(PbrtSubsurface, DefaultsAreWholeMilk) {
  SceneDesc scene = read_lines({"WorldBegin", "Material \"subsurface\"", "Shape \"sphere\""});
  const MediumDesc& milk = scene.media.at(0);
  expect_rgb_close(sigma_a_of(milk), RGB(0.0011f, 0.0024f, 0.014f));
  expect_rgb_close(sigma_s_of(milk), RGB(2.55f, 3.21f, 3.77f));
  EXPECT_FLOAT_EQ(boundary_of(scene, scene.shapes.at(0)).ior, 1.33f);
}

TEST(PbrtSubsurface, TheShapeStaysInTheMediumAroundIt) {
  const std::vector<std::string> lines = {
      "WorldBegin",
      "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"",
      "MakeNamedMedium \"water\" \"string type\" \"homogeneous\"",
      "Material \"subsurface\" \"string name\" \"Marble\"",
      "MediumInterface \"\" \"fog\"",
      "Shape \"sphere\"",
      "MediumInterface \"fog\"",
      "Shape \"sphere\"",
      "MediumInterface \"water\" \"fog\"",
      "Shape \"sphere\""};
  Warned read = read_warned(lines);
  const SceneDesc& scene = read.scene;
  ASSERT_EQ(scene.media.size(), 3u);
  EXPECT_TRUE(scene.media[2].subsurface);
  ASSERT_EQ(scene.shapes.size(), 3u);
  for (const ShapeDesc& shape : scene.shapes) {
    EXPECT_EQ(shape.interior_medium, 2);
    EXPECT_EQ(shape.exterior_medium, 0);  // the fog
  }
  // An inside medium the interface names is not used (pbrt-v4's BSSRDF never enters it): a warning.
  ASSERT_EQ(read.warnings.lines().size(), 1u) << joined(read.warnings);
  expect_warning(lines, 10, "Shape", "the MediumInterface's inside medium \"water\" is not used");
}

TEST(PbrtSubsurface, OtherIntegratorsRenderTheBoundaryAloneAsPbrtV4Does) {
  const std::vector<std::string> lines = {"Integrator \"path\"", "WorldBegin",
                                          "Material \"subsurface\" \"string name\" \"Skin1\"", "Shape \"sphere\""};
  Warned read = read_warned(lines);
  EXPECT_TRUE(read.scene.media.empty());
  EXPECT_EQ(read.scene.shapes.at(0).interior_medium, -1);
  EXPECT_FLOAT_EQ(boundary_of(read.scene, read.scene.shapes[0]).ior, 1.33f);
  EXPECT_EQ(read.scene.settings.integrator, "path");
  expect_warning(lines, 3, "Material", "the path integrator does not render subsurface scattering");
  // volpath (and simplevolpath, which candela renders with volpath) fill the shape.
  for (const char* integrator : {"volpath", "simplevolpath"}) {
    SceneDesc scene = read_lines({fmt::format("Integrator \"{}\"", integrator), "WorldBegin",
                                  "Material \"subsurface\"", "Shape \"sphere\""});
    EXPECT_EQ(scene.shapes.at(0).interior_medium, 0) << integrator;
  }
}

TEST(PbrtSubsurface, MixPicksASubsurfaceMaterialWholeOrNotAtAll) {
  const std::string named = "MakeNamedMaterial \"skin\" \"string type\" \"subsurface\" \"string name\" \"Skin2\"";
  const std::string plain = "MakeNamedMaterial \"plain\" \"string type\" \"diffuse\"";
  SceneDesc picked = read_lines({"WorldBegin", named, plain,
                                 "Material \"mix\" \"string materials\" [ \"plain\" \"skin\" ] \"float amount\" 1",
                                 "Shape \"sphere\""});
  EXPECT_EQ(picked.shapes.at(0).interior_medium, 0);
  EXPECT_TRUE(std::holds_alternative<DielectricMaterial>(picked.materials.at(picked.shapes[0].material)));
  SceneDesc other = read_lines({"WorldBegin", named, plain,
                                "Material \"mix\" \"string materials\" [ \"plain\" \"skin\" ] \"float amount\" 0",
                                "Shape \"sphere\""});
  EXPECT_EQ(other.shapes.at(0).interior_medium, -1);
  expect_error({"WorldBegin", named, plain, "Material \"mix\" \"string materials\" [ \"plain\" \"skin\" ]"}, 4,
               "\"string materials\"", "mixes the subsurface material \"skin\" with another");
}

TEST(PbrtSubsurface, Errors) {
  const std::vector<std::string> unknown = {"WorldBegin", "Material \"subsurface\" \"string name\" \"Skin3\""};
  expect_error(unknown, 2, "\"string name\"", "names no scattering preset: \"Skin3\" (the presets are \"Apple\", ");
  EXPECT_NE(error_reading_text(unknown).find("\"Skin1\", \"Skin2\""), std::string::npos);
  expect_error({"WorldBegin", "Material \"subsurface\" \"rgb sigma_a\" [ 1 1 1 ]"}, 2, "Material",
               "\"sigma_s\" is required with \"sigma_a\"");
  // The preset replaces the coefficients, and coefficients replace the reflectance: unused parameters.
  expect_error({"WorldBegin", "Material \"subsurface\" \"string name\" \"Apple\" \"rgb sigma_a\" [ 1 1 1 ]"}, 2,
               "\"rgb sigma_a\"", "unused parameter \"rgb sigma_a\"");
  expect_error({"WorldBegin",
                "Material \"subsurface\" \"rgb sigma_a\" [ 1 1 1 ] \"rgb sigma_s\" [ 1 1 1 ] \"rgb reflectance\" [ .5 .5 .5 ]"},
               2, "\"rgb reflectance\"", "unused parameter \"rgb reflectance\"");
  expect_error({"WorldBegin", "Material \"subsurface\" \"float g\" 1"}, 2, "\"float g\"",
               "must be between -1 and 1, exclusive");
  expect_error({"WorldBegin", "Material \"subsurface\" \"float scale\" -1"}, 2, "\"float scale\"",
               "must not be negative");
  expect_error({"WorldBegin", "Material \"subsurface\" \"rgb reflectance\" [ .5 .5 .5 ] \"rgb mfp\" [ 1 0 1 ]"}, 2,
               "\"rgb mfp\"", "must be positive");
  // A non-zero g with a preset is ignored, as pbrt-v4 does, with a warning.
  expect_warning({"WorldBegin", "Material \"subsurface\" \"string name\" \"Apple\" \"float g\" 0.5"}, 2, "\"float g\"",
                 "\"g\" 0.5 is ignored with a named medium");
}

TEST(PbrtSubsurface, ConvertsToJsonAndBack) {
  SceneDesc original = read_lines({"WorldBegin", "Material \"subsurface\" \"string name\" \"Ketchup\" \"float g\" 0",
                                   "  \"float roughness\" 0.1", "Shape \"sphere\""});
  SceneDesc back = read_json_scene(scene_to_json(original), "converted.json", scratch_dir());
  ASSERT_EQ(back.media.size(), 1u);
  const MediumDesc &b = back.media[0], &o = original.media[0];
  EXPECT_TRUE(b.subsurface);
  EXPECT_EQ(b.sigma_t, o.sigma_t);
  EXPECT_EQ(b.albedo.constant, o.albedo.constant);
  EXPECT_EQ(b.g, o.g);
  ASSERT_EQ(back.shapes.size(), 1u);
  EXPECT_EQ(back.shapes[0].interior_medium, 0);
  EXPECT_EQ(back.shapes[0].exterior_medium, -1);
  EXPECT_FLOAT_EQ(boundary_of(back, back.shapes[0]).ior, 1.33f);
  EXPECT_EQ(back.settings.integrator, "volpath");
}

}  // namespace
}  // namespace candela
