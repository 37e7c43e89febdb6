// Tests of the pbrt-v4 reader's errors and warnings at file:line:column, and pbrt options mapped onto candela's.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/film/aov_film.h"
#include "candela/io/pbrt_reader.h"
#include "candela/description/scene_desc.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- bad input: syntax

TEST(PbrtReader, UnknownDirective) {
  expect_error({"WorldBegin", "", "  Sphere \"x\""}, 3, "Sphere", "unknown directive \"Sphere\"");
}

TEST(PbrtReader, UnknownTextureTypeIsNamed) {
  expect_error({"WorldBegin", "Texture \"t\" \"spectrum\" \"windy\""}, 2, "\"windy\"",
               "texture type \"windy\" is not supported: candela has no such texture (supported: \"imagemap\", "
               "\"checkerboard\", \"scale\", \"mix\", \"constant\", \"bilerp\", \"directionmix\", \"dots\", "
               "\"fbm\", \"marble\", \"wrinkled\")");
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
               "unused parameter \"float radiu\" (did you mean \"radius\"?) (parameters read here: radius, zmin, zmax, phimax, alpha)");
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
               "\"glass-XY\" is neither a named spectrum");
  expect_error({"WorldBegin", "Material \"conductor\" \"spectrum eta\" \"metal-Xx-eta\""}, 2, "\"spectrum eta\"",
               "\"metal-Xx-eta\" is neither a named spectrum (\"metal-Ag-eta\"");
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

// Partial spheres and cylinders: zmin below zmax (pbrt-v4 would swap them), phimax in (0, 360]
// (pbrt-v4 clamps it), something of the sphere left between zmin and zmax.
TEST(PbrtReader, BadPartialSphereAndCylinder) {
  for (std::string shape : {"sphere", "cylinder"}) {
    const std::string owner = "Shape \"" + shape + "\": ";
    expect_error({"WorldBegin", "Shape \"" + shape + "\" \"float zmin\" 0.5 \"float zmax\" -0.5"}, 2, "\"float zmax\"",
                 owner + "\"zmax\" must exceed \"zmin\" (0.5), got -0.5");
    expect_error({"WorldBegin", "Shape \"" + shape + "\" \"float zmin\" 0.25 \"float zmax\" 0.25"}, 2, "\"float zmax\"",
                 "must exceed \"zmin\" (0.25), got 0.25");
    for (std::string phi_max : {"0", "-90", "400"})
      expect_error({"WorldBegin", "Shape \"" + shape + "\" \"float phimax\" " + phi_max}, 2, "\"float phimax\"",
                   owner + "\"phimax\" must be in (0, 360] degrees, got " + phi_max);
    expect_error({"WorldBegin", "Shape \"" + shape + "\" \"float radius\" 0"}, 2, "\"float radius\"",
                 owner + "\"radius\" must be positive, got 0");
  }
  expect_error({"WorldBegin", "Shape \"sphere\" \"float zmin\" 1"}, 2, "\"float zmin\"",
               "\"zmin\" must be below the radius (1) or nothing is left, got 1");
  expect_error({"WorldBegin", "Shape \"sphere\" \"float radius\" 2 \"float zmax\" -2.5"}, 2, "\"float zmax\"",
               "\"zmax\" must be above minus the radius (-2) or nothing is left, got -2.5");
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
               "unknown shape type \"spere\" (did you mean \"sphere\"?) (supported: \"sphere\", \"cylinder\", "
               "\"trianglemesh\", \"plymesh\", \"disk\", \"bilinearmesh\", \"loopsubdiv\", \"curve\")");
  expect_error({"WorldBegin", "Material \"plastic\""}, 2, "\"plastic\"", "unknown material type \"plastic\"");
  expect_error({"WorldBegin", "Material \"measured\""}, 2, "\"measured\"",
               "material type \"measured\" is not supported: candela has no BSDF for it");
  expect_error({"WorldBegin", "MakeNamedMaterial \"m\" \"string type\" \"measured\""}, 2, "\"string type\"",
               "not supported");
  expect_error({"WorldBegin", "LightSource \"sun\""}, 2, "\"sun\"", "unknown light type \"sun\"");
  expect_error({"Integrator \"whitted\"", "WorldBegin"}, 1, "\"whitted\"", "unknown integrator type \"whitted\"");
  expect_error({"Accelerator \"octree\"", "WorldBegin"}, 1, "\"octree\"", "unknown accelerator type");
  expect_error({"WorldBegin", "AreaLightSource \"glow\""}, 2, "\"glow\"", "unknown area light type");
  expect_error({"Camera \"realistic\"", "WorldBegin"}, 1, "\"realistic\"", "not supported yet");
  expect_error({"Film \"photographic\"", "WorldBegin"}, 1, "\"photographic\"", "unknown film type");
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
  for (std::string type : {"randomwalk", "simplepath"}) {
    SCOPED_TRACE(type);
    std::vector<std::string> lines = {"Integrator \"" + type + "\" \"integer maxdepth\" 9", "WorldBegin"};
    expect_warning(lines, 1, "\"" + type + "\"",
                   "Integrator \"" + type + "\": using candela's path integrator with maxdepth 9");
    SceneDesc scene = read_lines(lines);
    EXPECT_EQ(scene.settings.integrator, "path");
    EXPECT_EQ(scene.settings.max_depth, 9);
  }
  // pbrt-v4's light tracer is candela's light_path, with its maxdepth, without a warning.
  Warned lightpath = read_warned({"Integrator \"lightpath\" \"integer maxdepth\" 4", "WorldBegin"});
  EXPECT_TRUE(lightpath.warnings.empty()) << joined(lightpath.warnings);
  EXPECT_EQ(lightpath.scene.settings.integrator, "light_path");
  EXPECT_EQ(lightpath.scene.settings.max_depth, 4);
  EXPECT_EQ(read_lines({"Integrator \"lightpath\"", "WorldBegin"}).settings.max_depth, 5);  // pbrt's default
  Warned volpath = read_warned({"Integrator \"volpath\" \"integer maxdepth\" 7", "WorldBegin"});
  EXPECT_TRUE(volpath.warnings.empty()) << joined(volpath.warnings);
  EXPECT_EQ(volpath.scene.settings.integrator, "volpath");
  EXPECT_EQ(volpath.scene.settings.max_depth, 7);
  expect_warning({"Integrator \"simplevolpath\"", "WorldBegin"}, 1, "\"simplevolpath\"",
                 "Integrator \"simplevolpath\": using candela's volpath integrator with maxdepth 5");
  EXPECT_EQ(read_lines({"Integrator \"simplevolpath\"", "WorldBegin"}).settings.integrator, "volpath");
  // ambientocclusion is candela's ambient_occlusion with pbrt-v4's two parameters, without a warning.
  Warned ao = read_warned({"Integrator \"ambientocclusion\" \"bool cossample\" false \"float maxdistance\" 0.5",
                           "WorldBegin"});
  EXPECT_TRUE(ao.warnings.empty()) << joined(ao.warnings);
  EXPECT_EQ(ao.scene.settings.integrator, "ambient_occlusion");
  EXPECT_FALSE(ao.scene.settings.ambient_occlusion.cosine_sampling);
  EXPECT_EQ(ao.scene.settings.ambient_occlusion.max_distance, 0.5f);
  const SceneDesc ao_defaults = read_lines({"Integrator \"ambientocclusion\"", "WorldBegin"});
  EXPECT_EQ(ao_defaults.settings.integrator, "ambient_occlusion");
  EXPECT_TRUE(ao_defaults.settings.ambient_occlusion.cosine_sampling);
  EXPECT_TRUE(std::isinf(ao_defaults.settings.ambient_occlusion.max_distance));
  expect_error({"Integrator \"ambientocclusion\" \"float maxdistance\" 0", "WorldBegin"}, 1,
               "\"float maxdistance\"", "must be positive");
  // It has no depth: pbrt-v4 refuses "maxdepth" as an unused parameter, and so does candela.
  expect_error({"Integrator \"ambientocclusion\" \"integer maxdepth\" 5", "WorldBegin"}, 1,
               "\"integer maxdepth\"", "unused parameter");
  // sppm is candela's sppm with pbrt-v4's parameters, without a warning; -1 photons (the default)
  // are one per pixel (candela's 0), and its seed is the render's.
  Warned sppm = read_warned({"Integrator \"sppm\" \"integer photonsperiteration\" 1000 \"float radius\" 0.1 "
                             "\"integer seed\" 7 \"integer maxdepth\" 6",
                             "WorldBegin"});
  EXPECT_TRUE(sppm.warnings.empty()) << joined(sppm.warnings);
  EXPECT_EQ(sppm.scene.settings.integrator, "sppm");
  EXPECT_EQ(sppm.scene.settings.sppm.photons_per_iteration, 1000);
  EXPECT_EQ(sppm.scene.settings.sppm.radius, 0.1f);
  EXPECT_EQ(sppm.scene.settings.seed, 7u);
  EXPECT_EQ(sppm.scene.settings.max_depth, 6);
  const SceneDesc sppm_defaults = read_lines({"Integrator \"sppm\"", "WorldBegin"});
  EXPECT_EQ(sppm_defaults.settings.sppm, SppmSettings{});
  EXPECT_EQ(sppm_defaults.settings.max_depth, 5);
  expect_error({"Integrator \"sppm\" \"float radius\" 0", "WorldBegin"}, 1, "\"float radius\"", "must be positive");
  expect_error({"Integrator \"sppm\" \"integer photonsperiteration\" 0", "WorldBegin"}, 1,
               "\"integer photonsperiteration\"", "must be positive or -1");
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
  expect_error({"WorldBegin", "Accelerator \"bvh\""}, 2, "Accelerator", "not allowed after WorldBegin");
}

// pbrt-v4's PixelSensor: the exposure is the shutter interval x ISO / 100, a camera sensor becomes
// the CIE 1931 one white-balanced to 6500 K (with a warning), maxcomponentvalue limits the sensor.
TEST(PbrtReader, FilmSensorIsoWhiteBalanceAndLimit) {
  const SceneDesc plain = read_lines({"WorldBegin"});
  EXPECT_TRUE(plain.film.sensor.changes_nothing());
  const SceneDesc iso = read_lines({"Camera \"perspective\" \"float shutteropen\" 0.25 \"float shutterclose\" 0.75",
                                    "Film \"rgb\" \"float iso\" 400 \"float whitebalance\" 5000 "
                                    "\"float maxcomponentvalue\" 2",
                                    "WorldBegin"});
  EXPECT_FLOAT_EQ(iso.film.sensor.exposure, 2);
  EXPECT_FLOAT_EQ(iso.film.sensor.white_balance, 5000);
  EXPECT_FLOAT_EQ(iso.film.sensor.max_component, 2);
  // The Film may come before the Camera: the exposure is settled at WorldBegin.
  EXPECT_FLOAT_EQ(read_lines({"Film \"rgb\" \"float iso\" 200", "Camera \"perspective\" \"float shutterclose\" 0.5",
                              "WorldBegin"}).film.sensor.exposure, 1);
  EXPECT_FLOAT_EQ(read_lines({"Film \"rgb\" \"string sensor\" \"cie1931\"", "WorldBegin"}).film.sensor.white_balance, 0);
  expect_warning({"Film \"rgb\" \"string sensor\" \"canon_eos_5d_mkiv\"", "WorldBegin"}, 1,
                 "\"string sensor\"", "using the CIE 1931 sensor white-balanced to 6500 K");
  EXPECT_FLOAT_EQ(read_warned({"Film \"rgb\" \"string sensor\" \"nikon_d850\"", "WorldBegin"})
                      .scene.film.sensor.white_balance, 6500);
  expect_error({"Film \"rgb\" \"string sensor\" \"leica_m11\"", "WorldBegin"}, 1, "\"string sensor\"",
               "unknown sensor \"leica_m11\" (pbrt-v4 has \"cie1931\" and the cameras \"canon_eos_100d\"");
  expect_error({"Film \"rgb\" \"float iso\" 0", "WorldBegin"}, 1, "\"float iso\"", "must be positive");
  expect_error({"Film \"rgb\" \"float whitebalance\" 500", "WorldBegin"}, 1, "\"float whitebalance\"",
               "[1000, 100000] kelvin");
  expect_error({"Film \"rgb\" \"float maxcomponentvalue\" -1", "WorldBegin"}, 1, "\"float maxcomponentvalue\"",
               "must be positive");
  expect_error({"Camera \"perspective\" \"float shutteropen\" 0.5 \"float shutterclose\" 0.5", "WorldBegin"}, 1,
               "\"float shutterclose\"", "the shutter does not open");
}


// pbrt-v4's gbuffer film: the rgb film's parameters (sensor included) plus its coordinate system,
// read as pbrt's gbuffer AOVs (film/aov_film.h).
TEST(PbrtReader, GbufferFilmSelectsPbrtsLayers) {
  const SceneDesc camera_space = read_lines({"Film \"gbuffer\" \"integer xresolution\" 32 \"float iso\" 200 "
                                             "\"string filename\" \"out.EXR\"",
                                             "WorldBegin"});
  EXPECT_EQ(camera_space.film.aovs, "gbuffer");
  EXPECT_EQ(camera_space.film.width, 32);
  EXPECT_EQ(parse_aov_selection(camera_space.film.aovs).space, AovSpace::Camera);
  const SceneDesc world = read_lines({"Film \"gbuffer\" \"string coordinatesystem\" \"world\"", "WorldBegin"});
  EXPECT_EQ(world.film.aovs, "gbuffer,world_space");
  EXPECT_EQ(parse_aov_selection(world.film.aovs).space, AovSpace::World);
  EXPECT_EQ(read_lines({"Film \"rgb\"", "WorldBegin"}).film.aovs, "");
  expect_error({"Film \"gbuffer\"", "  \"string coordinatesystem\" \"screen\"", "WorldBegin"}, 2,
               "\"string coordinatesystem\"", "Film \"gbuffer\": unknown \"coordinatesystem\" \"screen\"");
  expect_error({"Film \"rgb\" \"string coordinatesystem\" \"camera\"", "WorldBegin"}, 1,
               "\"string coordinatesystem\"", "");
  expect_error({"Film \"gbuffer\" \"string filename\" \"out.png\"", "WorldBegin"}, 1, "\"string filename\"",
               "the gbuffer film writes EXR files only");
  expect_error({"Film \"gbuffer\" \"float iso\" 0", "WorldBegin"}, 1, "\"float iso\"", "Film \"gbuffer\"");
}

// pbrt-v4's spectral film: the rgb film's parameters plus its buckets, read as candela's spectral
// AOV layer (film/aov_film.h).
TEST(PbrtReader, SpectralFilmSelectsTheSpectralLayer) {
  const SceneDesc defaults = read_lines({"Film \"spectral\" \"string filename\" \"out.exr\"", "WorldBegin"});
  EXPECT_EQ(defaults.film.aovs, "spectral:16:360:830");  // pbrt-v4's nbuckets, Lambda_min, Lambda_max
  const AovSelection selection = parse_aov_selection(defaults.film.aovs);
  EXPECT_EQ(selection.spectral.count, 16);
  EXPECT_EQ(selection.layers, std::vector<Aov>{Aov::Spectral});
  const SceneDesc narrow = read_lines({"Film \"spectral\" \"integer nbuckets\" 8 \"float lambdamin\" 400 "
                                       "\"float lambdamax\" 700.5 \"float iso\" 200",
                                       "WorldBegin"});
  const SpectralBuckets b = parse_aov_selection(narrow.film.aovs).spectral;
  EXPECT_EQ(b.count, 8);
  EXPECT_EQ(b.lambda_min, 400.0f);
  EXPECT_EQ(b.lambda_max, 700.5f);
  expect_error({"Film \"spectral\" \"integer nbuckets\" 0", "WorldBegin"}, 1, "\"integer nbuckets\"",
               "must be between 1 and 1000");
  expect_error({"Film \"spectral\" \"float lambdamin\" 300", "WorldBegin"}, 1, "\"float lambdamin\"",
               "must be at least 360 nm");
  expect_error({"Film \"spectral\" \"float lambdamax\" 900", "WorldBegin"}, 1, "\"float lambdamax\"",
               "must be at most 830 nm");
  expect_error({"Film \"spectral\" \"string filename\" \"out.png\"", "WorldBegin"}, 1, "\"string filename\"",
               "the spectral film writes EXR files only");
  expect_error({"Film \"rgb\" \"integer nbuckets\" 4", "WorldBegin"}, 1, "\"integer nbuckets\"", "");
}
}  // namespace
}  // namespace candela
