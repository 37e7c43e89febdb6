// Tests of the Mitsuba 3 XML reader: each parses small scenes and checks the SceneDesc.
#include "candela/io/mitsuba_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include "candela/film/image_io.h"
#include "candela/base/error.h"
#include "candela/io/named_spectra.h"
#include "candela/lights/light.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  fs::path dir = fs::temp_directory_path() / "candela_mitsuba_test";
  fs::create_directories(dir);
  return dir;
}

SceneDesc read_text(const std::string& body, const MitsubaReadOptions& options = {}) {
  Warnings warnings;
  return read_mitsuba_scene_text("<scene version=\"3.0.0\">\n" + body + "\n</scene>", "test.xml", temp_dir(),
                                 warnings, options);
}

// The material wrapped in the one-sided material of shape `shape` (Mitsuba's BSDFs are one-sided).
template <typename M>
const M& inside_one_sided(const SceneDesc& s, size_t shape) {
  return std::get<M>(s.materials[std::get<OneSidedMaterial>(s.materials[s.shapes[shape].material]).material]);
}

std::string mitsuba_error_of(const std::string& body) {
  try {
    read_text(body);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MitsubaReader, CameraLooksAtTargetWithImageRightToTheRight) {
  SceneDesc s = read_text(R"(<sensor type="perspective"><float name="fov" value="45"/>
      <transform name="to_world"><lookat origin="0,0,-5" target="0,0,0" up="0,1,0"/></transform>
      <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/></film></sensor>)");
  const Transform& cam = s.camera.world_from_camera;
  Vec3 eye = cam.point({0, 0, 0}), forward = normalize(cam.vector({0, 0, 1}));
  EXPECT_NEAR(eye.z, -5, 1e-5);
  EXPECT_NEAR(forward.z, 1, 1e-5);
  // Looking along +z with +y up, the image's right is world -x (Mitsuba's camera +x is the left).
  Vec3 right = cam.vector({1, 0, 0}), up = cam.vector({0, 1, 0});
  EXPECT_NEAR(right.x, -1, 1e-5);
  EXPECT_NEAR(up.y, 1, 1e-5);
  EXPECT_EQ(s.camera.fov_axis, FovAxis::X);
  EXPECT_FLOAT_EQ(s.camera.fov_degrees, 45);
  EXPECT_EQ(s.film.width, 32);
  EXPECT_EQ(s.film.height, 16);
  EXPECT_FLOAT_EQ(s.camera.near_clip, 0.01f);
}

TEST(MitsubaReader, TransformsComposeInOrder) {
  SceneDesc s = read_text(R"(<shape type="sphere"><transform name="to_world">
      <scale value="2"/><translate x="1"/><rotate y="1" angle="90"/></transform></shape>)");
  ASSERT_EQ(s.shapes.size(), 1u);
  Vec3 p = s.shapes[0].to_world.point({1, 0, 0});  // scale -> (2,0,0), translate -> (3,0,0), rotate -> (0,0,-3)
  EXPECT_NEAR(p.x, 0, 1e-5);
  EXPECT_NEAR(p.z, -3, 1e-5);
}

TEST(MitsubaReader, DefaultsParametersAndOverrides) {
  std::string body = R"(<default name="spp" value="7"/>
      <integrator type="moment"><integrator type="path"><integer name="max_depth" value="2"/></integrator></integrator>
      <sensor type="perspective"><sampler type="independent"><integer name="sample_count" value="$spp"/></sampler></sensor>)";
  SceneDesc s = read_text(body);
  EXPECT_EQ(s.settings.spp, 7);
  EXPECT_EQ(s.settings.max_depth, 1);  // Mitsuba's depth 2 = direct lighting
  EXPECT_EQ(s.settings.sampler.type, SamplerType::Independent);
  MitsubaReadOptions o;
  o.parameters["spp"] = "64";
  EXPECT_EQ(read_text(body, o).settings.spp, 64);
  EXPECT_NE(mitsuba_error_of("<integer name=\"x\" value=\"$nope\"/>").find("undefined parameter"), std::string::npos);
}

TEST(MitsubaReader, MaxDepthMapping) {
  EXPECT_EQ(read_text(R"(<integrator type="path"/>)").settings.max_depth, 1024);
  EXPECT_EQ(read_text(R"(<integrator type="path"><integer name="max_depth" value="5"/></integrator>)")
                .settings.max_depth, 4);
  EXPECT_EQ(read_text(R"(<integrator type="direct"/>)").settings.max_depth, 1);
  EXPECT_FALSE(read_text(R"(<integrator type="path"/>)").settings.hide_emitters);
  EXPECT_TRUE(read_text(R"(<integrator type="path"><boolean name="hide_emitters" value="true"/></integrator>)")
                  .settings.hide_emitters);
  EXPECT_TRUE(read_text(R"(<integrator type="direct"><boolean name="hide_emitters" value="true"/></integrator>)")
                  .settings.hide_emitters);
}

// Found by fuzz/mitsuba_reader_fuzz.cpp (fuzz/regressions/mitsuba_reader/ub-integer-beyond-int.xml): the
// value was cast to int, undefined behaviour that UBSan reported.
TEST(MitsubaReader, IntegerBeyondIntIsAnError) {
  EXPECT_EQ(mitsuba_error_of(R"(<sensor type="perspective"><sampler type="independent">
                        <integer name="sample_count" value="5e123"/></sampler></sensor>)"),
            "test.xml:3: sampler \"independent\": \"sample_count\" is 5e+123, beyond the integers candela takes "
            "(-2147483648 to 2147483647)");
  EXPECT_EQ(read_text(R"(<integrator type="path"><integer name="max_depth" value="2147483647"/></integrator>)")
                .settings.max_depth, 2147483646);
  EXPECT_EQ(read_text(R"(<integrator type="path"><integer name="rr_depth" value="-2147483648"/></integrator>)")
                .settings.rr_start_depth, 1);
}

TEST(MitsubaReader, RefsIncludeAndOneSidedWrapping) {
  {
    std::ofstream f(temp_dir() / "inc.xml");
    f << R"(<scene version="3.0.0"><bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.8"/></bsdf></scene>)";
  }
  SceneDesc s = read_text(R"(<include filename="inc.xml"/>
      <shape type="rectangle"><ref id="white"/></shape>
      <shape type="rectangle"><bsdf type="twosided"><ref id="white"/></bsdf></shape>
      <shape type="disk"/>)");
  ASSERT_EQ(s.shapes.size(), 3u);
  const auto* one = std::get_if<OneSidedMaterial>(&s.materials[s.shapes[0].material]);
  ASSERT_NE(one, nullptr);
  EXPECT_LT(one->material, s.shapes[0].material);
  const auto* d = std::get_if<DiffuseMaterial>(&s.materials[one->material]);
  ASSERT_NE(d, nullptr);
  EXPECT_FLOAT_EQ(d->reflectance.value.g, 0.8f);
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(s.materials[s.shapes[1].material]));  // twosided
  const auto* def = std::get_if<OneSidedMaterial>(&s.materials[s.shapes[2].material]);  // Mitsuba's default bsdf
  ASSERT_NE(def, nullptr);
  EXPECT_FLOAT_EQ(std::get<DiffuseMaterial>(s.materials[def->material]).reflectance.value.r, 0.5f);
  EXPECT_TRUE(std::holds_alternative<DiskShape>(s.shapes[2].geometry));
}

// Recursion a hostile file could make deep (docs/reliability.md, "Hostile inputs"): each is refused at
// a limit, with the place, rather than overflowing the stack or reading files without end.
TEST(MitsubaReader, DeepNestingAndIncludesAreRefusedAtTheirLimits) {
  std::string deep;
  for (int k = 0; k < 100000; ++k) deep += "<bsdf type=\"twosided\">";
  deep += "<bsdf type=\"diffuse\"/>";
  for (int k = 0; k < 100000; ++k) deep += "</bsdf>";
  EXPECT_EQ(mitsuba_error_of(deep), "test.xml:2: <bsdf> is nested more than 100 objects deep");

  std::ofstream(temp_dir() / "self.xml") << R"(<scene version="3.0.0"><include filename="self.xml"/></scene>)";
  EXPECT_NE(mitsuba_error_of(R"(<include filename="self.xml"/>)").find("self.xml:1: more than 15 nested <include>s"),
            std::string::npos)
      << mitsuba_error_of(R"(<include filename="self.xml"/>)");
  // Files that each include the next ten times, 15 levels: 10^15 includes.
  for (int k = 1; k <= 15; ++k) {
    std::ofstream file(temp_dir() / ("tenfold" + std::to_string(k) + ".xml"));
    file << "<scene version=\"3.0.0\">";
    for (int copy = 0; copy < 10 && k < 15; ++copy) file << "<include filename=\"tenfold" << k + 1 << ".xml\"/>";
    file << "</scene>";
  }
  EXPECT_NE(mitsuba_error_of(R"(<include filename="tenfold1.xml"/>)").find("more than 100000 <include>s in all"),
            std::string::npos);

  // Instancing cannot recurse: a shapegroup holds neither shapegroups nor instances.
  EXPECT_NE(mitsuba_error_of(R"(<shape type="shapegroup" id="a"><shape type="shapegroup" id="b"><shape type="sphere"/></shape>
      </shape><shape type="instance"><ref id="a"/></shape>)")
                .find("a shapegroup cannot hold another shapegroup (instancing does not nest)"),
            std::string::npos);
  EXPECT_NE(mitsuba_error_of(R"(<shape type="shapegroup" id="a"><shape type="sphere"/></shape>
      <shape type="shapegroup" id="b"><shape type="instance"><ref id="a"/></shape></shape>
      <shape type="instance"><ref id="b"/></shape>)")
                .find("a shapegroup cannot hold an instance (instancing does not nest)"),
            std::string::npos);
}

TEST(MitsubaReader, Bsdfs) {
  SceneDesc s = read_text(R"(
    <shape type="sphere"><bsdf type="dielectric"><string name="int_ior" value="diamond"/></bsdf></shape>
    <shape type="sphere"><bsdf type="roughconductor"><string name="material" value="Al"/>
      <string name="distribution" value="ggx"/><float name="alpha_u" value="0.25"/><float name="alpha_v" value="0.05"/></bsdf></shape>
    <shape type="sphere"><bsdf type="roughplastic"><float name="alpha" value="0.1"/><boolean name="nonlinear" value="true"/></bsdf></shape>
    <shape type="sphere"><bsdf type="thindielectric"/></shape>
    <shape type="sphere"><bsdf type="null"/></shape>)");
  const auto& d = std::get<DielectricMaterial>(s.materials[s.shapes[0].material]);
  EXPECT_NEAR(d.ior, 2.419f / 1.000277f, 1e-5);
  const auto& c = inside_one_sided<ConductorMaterial>(s, 1);
  EXPECT_EQ(c.roughness.distribution, MicrofacetDistribution::GGXSeparable);  // Mitsuba's G1(wo) G1(wi)
  EXPECT_FLOAT_EQ(c.roughness.u.value, 0.25f);
  EXPECT_FLOAT_EQ(c.roughness.v.value, 0.05f);
  EXPECT_NEAR(c.eta.value.r, 1.6575f, 1e-3);
  const auto& p = inside_one_sided<CoatedDiffuseMaterial>(s, 2);
  EXPECT_EQ(p.roughness.distribution, MicrofacetDistribution::Beckmann);  // Mitsuba's default
  EXPECT_TRUE(p.nonlinear);
  EXPECT_TRUE(p.tabulated_coat);  // Mitsuba's roughplastic integrates its rough coat into tables
  EXPECT_NEAR(p.ior, 1.49f / 1.000277f, 1e-5);
  EXPECT_TRUE(std::get<DielectricMaterial>(s.materials[s.shapes[3].material]).thin);
  EXPECT_TRUE(std::holds_alternative<InterfaceMaterial>(s.materials[s.shapes[4].material]));
}

TEST(MitsubaReader, TwosidedWithTwoBsdfs) {
  SceneDesc s = read_text(R"(<shape type="rectangle"><bsdf type="twosided">
      <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.1, 0.1"/></bsdf>
      <bsdf type="roughconductor"/></bsdf></shape>)");
  const auto& sides = std::get<TwoSidedMaterial>(s.materials[s.shapes[0].material]);
  EXPECT_FLOAT_EQ(std::get<DiffuseMaterial>(s.materials[size_t(sides.front)]).reflectance.value.r, 0.8f);
  EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(s.materials[size_t(sides.back)]));
}

TEST(MitsubaReader, CheckerboardMapsToCandelasSquares) {
  SceneDesc s = read_text(R"(<bsdf type="diffuse" id="b"><texture name="reflectance" type="checkerboard">
      <transform name="to_uv"><scale x="5" y="3"/></transform><rgb name="color0" value="0.8"/><float name="color1" value="0.1"/>
      </texture></bsdf><shape type="rectangle"><ref id="b"/></shape>)");
  ASSERT_EQ(s.textures.size(), 1u);
  const auto& c = std::get<CheckerboardTexture>(s.textures[0]);
  EXPECT_FLOAT_EQ(c.tex1.value.r, 0.8f);
  EXPECT_FLOAT_EQ(c.tex2.value.r, 0.1f);
  EXPECT_FLOAT_EQ(c.mapping.su, 10);
  EXPECT_FLOAT_EQ(c.mapping.sv, 6);
}

TEST(MitsubaReader, CheckerboardLookedUpAsAFloatSwapsItsColours) {
  // Mitsuba's checkerboard gives color0 where (u mod 1 < 0.5) == (v mod 1 < 0.5) to colour lookups
  // (eval, eval_3) but color1 there to float lookups (eval_1: roughness and other float parameters).
  SceneDesc s = read_text(R"(<texture type="checkerboard" id="check"><float name="color0" value="0.05"/>
      <float name="color1" value="0.3"/></texture>
    <shape type="sphere"><bsdf type="roughconductor"><string name="distribution" value="ggx"/>
      <ref name="alpha" id="check"/></bsdf></shape>
    <shape type="sphere"><bsdf type="diffuse"><ref name="reflectance" id="check"/></bsdf></shape>)");
  ASSERT_EQ(s.textures.size(), 2u);
  const auto& conductor = inside_one_sided<ConductorMaterial>(s, 0);
  const auto& diffuse = inside_one_sided<DiffuseMaterial>(s, 1);
  const auto& as_float = std::get<CheckerboardTexture>(s.textures[size_t(conductor.roughness.u.texture)]);
  const auto& as_colour = std::get<CheckerboardTexture>(s.textures[size_t(diffuse.reflectance.texture)]);
  EXPECT_FLOAT_EQ(as_colour.tex1.value.r, 0.05f);  // candela's tex1: where floor(2u) + floor(2v) is even
  EXPECT_FLOAT_EQ(as_colour.tex2.value.r, 0.3f);
  EXPECT_FLOAT_EQ(as_float.tex1.value.r, 0.3f);
  EXPECT_FLOAT_EQ(as_float.tex2.value.r, 0.05f);
  EXPECT_EQ(conductor.roughness.u.texture, conductor.roughness.v.texture);  // one texture per lookup kind
}

TEST(MitsubaReader, BitmapLookedUpAsAFloatIsItsLuminance) {
  write_image(temp_dir() / "roughness-test.exr", Image(4, 4));
  SceneDesc s = read_text(R"(<texture type="bitmap" id="map"><string name="filename" value="roughness-test.exr"/></texture>
    <shape type="sphere"><bsdf type="roughconductor"><ref name="alpha" id="map"/></bsdf></shape>
    <shape type="sphere"><bsdf type="diffuse"><ref name="reflectance" id="map"/></bsdf></shape>)");
  ASSERT_EQ(s.textures.size(), 2u);
  const auto& conductor = inside_one_sided<ConductorMaterial>(s, 0);
  const auto& diffuse = inside_one_sided<DiffuseMaterial>(s, 1);
  EXPECT_TRUE(std::get<ImageTexture>(s.textures[size_t(conductor.roughness.u.texture)]).luminance);
  EXPECT_FALSE(std::get<ImageTexture>(s.textures[size_t(diffuse.reflectance.texture)]).luminance);
}

TEST(MitsubaReader, NormalAndBumpMapsTakeMitsubasFlipAndShadowingDefaults) {
  SceneDesc s = read_text(R"(
    <shape type="sphere"><bsdf type="normalmap"><texture name="normalmap" type="rawconstant">
      <vector name="value" value="0.5, 0.5, 1"/></texture><bsdf type="diffuse"/></bsdf></shape>
    <shape type="sphere"><bsdf type="normalmap"><boolean name="flip_invalid_normals" value="false"/>
      <boolean name="use_shadowing_function" value="false"/><texture name="normalmap" type="rawconstant">
      <vector name="value" value="0.5, 0.5, 1"/></texture><bsdf type="diffuse"/></bsdf></shape>
    <shape type="sphere"><bsdf type="bumpmap"><texture type="checkerboard"/><bsdf type="diffuse"/></bsdf></shape>)");
  auto options = [&](int shape) {
    const MaterialDesc& m = s.materials[s.shapes[size_t(shape)].material];
    if (const auto* n = std::get_if<NormalMapMaterial>(&m)) return n->options;
    return std::get<BumpMapMaterial>(m).options;
  };
  EXPECT_TRUE(options(0).flip_invalid_normals);
  EXPECT_TRUE(options(0).shadowing_function);
  EXPECT_FALSE(options(1).flip_invalid_normals);
  EXPECT_FALSE(options(1).shadowing_function);
  EXPECT_TRUE(options(2).flip_invalid_normals);
  EXPECT_TRUE(options(2).shadowing_function);
}

TEST(MitsubaReader, RotatedToUvOfABitmap) {
  // A quarter turn: Mitsuba's uv' = (-v, u); candela looks images up with t = 1 - v', so
  // s = -v and t = 1 - u.
  const std::string image = (fs::path(CANDELA_SOURCE_DIR) / "tests/data/textures/checker.ppm").string();
  SceneDesc s = read_text(R"(<bsdf type="diffuse" id="b"><texture name="reflectance" type="bitmap">
      <string name="filename" value=")" + image + R"("/><transform name="to_uv"><rotate z="1" angle="90"/></transform>
      </texture></bsdf><shape type="rectangle"><ref id="b"/></shape>)");
  const auto& t = std::get<ImageTexture>(s.textures[0]);
  EXPECT_NEAR(t.mapping.su, 0, 1e-6);
  EXPECT_NEAR(t.mapping.s_from_v, -1, 1e-6);
  EXPECT_NEAR(t.mapping.du, 0, 1e-6);
  EXPECT_NEAR(t.mapping.t_from_u, -1, 1e-6);
  EXPECT_NEAR(t.mapping.sv, 0, 1e-6);
  EXPECT_NEAR(t.mapping.dv, 1, 1e-6);
}

TEST(MitsubaReader, SpectraAsMitsubasRgbVariant) {
  // A flat reflectance of 0.78 given on 400..700 nm only (zero outside, as Mitsuba integrates it).
  SceneDesc s = read_text(R"(<shape type="rectangle"><bsdf type="diffuse">
      <spectrum name="reflectance" value="400:0.78, 500:0.78, 600:0.78, 700:0.78"/></bsdf>
      <emitter type="area"><spectrum name="radiance" value="400:0, 500:8, 600:15.6, 700:18.4"/></emitter></shape>)");
  const auto& one = std::get<OneSidedMaterial>(s.materials[s.shapes[0].material]);
  RGB r = std::get<DiffuseMaterial>(s.materials[one.material]).reflectance.value;
  EXPECT_NEAR(r.r, 0.935761f, 1e-4);
  EXPECT_NEAR(r.g, 0.740626f, 1e-4);
  EXPECT_NEAR(r.b, 0.704686f, 1e-4);
  ASSERT_TRUE(s.shapes[0].emission);
  EXPECT_NEAR(s.shapes[0].emission->radiance.r, 20.7108f, 2e-3);
  EXPECT_NEAR(s.shapes[0].emission->radiance.g, 10.8546f, 2e-3);
  EXPECT_NEAR(s.shapes[0].emission->radiance.b, 2.77115f, 2e-3);
  // Mitsuba 3's own silver: eta = (0.155276, 0.116728, 0.138388).
  auto ag = mitsuba_spectra::named_conductor("Ag");
  ASSERT_TRUE(ag);
  EXPECT_NEAR(ag->eta.g, 0.116728f, 1e-5);
}

TEST(MitsubaReader, SpectrumFilesReadAsInlinePairs) {
  const fs::path file = temp_dir() / "flat.spd";
  std::ofstream(file) << "# a flat reflectance\n400 0.78\n500 0.78\n\n600\t0.78  # comment\n700 0.78\n";
  SceneDesc s = read_text(R"(<shape type="rectangle"><bsdf type="diffuse">
      <spectrum name="reflectance" filename=")" + file.string() + R"("/></bsdf></shape>)");
  const auto& one = std::get<OneSidedMaterial>(s.materials[s.shapes[0].material]);
  RGB r = std::get<DiffuseMaterial>(s.materials[one.material]).reflectance.value;
  EXPECT_NEAR(r.r, 0.935761f, 1e-4);  // the inline pairs' value (SpectraAsMitsubasRgbVariant)
  EXPECT_NEAR(r.b, 0.704686f, 1e-4);
  std::ofstream(file) << "400 0.5\n380 0.5\n";
  std::string message = mitsuba_error_of(R"(<shape type="rectangle"><bsdf type="diffuse">
      <spectrum name="reflectance" filename=")" + file.string() + R"("/></bsdf></shape>)");
  EXPECT_NE(message.find(file.string() + ":2:1: wavelengths must increase"), std::string::npos) << message;
  std::ofstream(file) << "400 0.5\n500 x\n";
  message = mitsuba_error_of(R"(<shape type="rectangle"><bsdf type="diffuse">
      <spectrum name="reflectance" filename=")" + file.string() + R"("/></bsdf></shape>)");
  EXPECT_NE(message.find(":2:1: expected \"wavelength value\""), std::string::npos) << message;
  EXPECT_NE(mitsuba_error_of(R"(<shape type="rectangle"><bsdf type="diffuse">
      <spectrum name="reflectance" filename="no-such.spd"/></bsdf></shape>)")
                .find("\"no-such.spd\" not found"),
            std::string::npos);
}

TEST(MitsubaReader, BlackbodyAsASpectralVariantRecordsIt) {
  auto radiance = [](double kelvin) {
    SceneDesc s = read_text(R"(<shape type="rectangle"><emitter type="area"><spectrum type="blackbody" name="radiance">
        <float name="temperature" value=")" + std::to_string(kelvin) + R"("/></spectrum></emitter></shape>)");
    EXPECT_TRUE(s.shapes[0].emission);
    return s.shapes[0].emission->radiance;
  };
  for (double kelvin : {2000.0, 5000.0, 6504.0, 10000.0}) {
    RGB c = radiance(kelvin);
    // Chromaticity: pbrt-v4's normalised blackbody, an independent integration (against Wyman et
    // al.'s fit of the CIE curves instead of Mitsuba's table), up to scale. At 2000 K blue is 3% of
    // green and the fit's error in the far blue shows (10%), so that one is compared by order only.
    RGB ref = pbrt_spectra::blackbody_rgb(float(kelvin));
    if (kelvin >= 5000) {
      EXPECT_NEAR(c.r / c.g, ref.r / ref.g, 0.01 * ref.r / ref.g) << kelvin;
      EXPECT_NEAR(c.b / c.g, ref.b / ref.g, 0.01 * ref.b / ref.g) << kelvin;
    } else {
      EXPECT_GT(c.r, c.g);
      EXPECT_GT(c.g, c.b);
    }
    // Luminance in physical units: Y = integral of Planck x ybar / integral of ybar, with ybar from
    // Wyman, Sloan and Shirley's two-Gaussian fit (about 1% accurate).
    double num = 0, den = 0;
    for (double nm = 360; nm <= 830; nm += 0.5) {
      auto lobe = [&](double mu, double below, double above) {
        double t = (nm - mu) / (nm < mu ? below : above);
        return std::exp(-0.5 * t * t);
      };
      double ybar = 0.821 * lobe(568.8, 46.9, 40.5) + 0.286 * lobe(530.9, 16.3, 31.1);
      double l = nm * 1e-9;
      double planck = 1e-9 * 2 * 6.62607004e-34 * 2.99792458e8 * 2.99792458e8 /
                      (std::pow(l, 5) * std::expm1(6.62607004e-34 * 2.99792458e8 / (l * 1.38064852e-23 * kelvin)));
      num += planck * ybar;
      den += ybar;
    }
    EXPECT_NEAR(c.luminance(), num / den, 0.02 * num / den) << kelvin;
  }
  EXPECT_GT(radiance(2000).r, radiance(2000).b);    // red hot
  EXPECT_LT(radiance(10000).r, radiance(10000).b);  // blue white
  EXPECT_NE(mitsuba_error_of(R"(<shape type="rectangle"><emitter type="area"><spectrum type="blackbody" name="radiance">
      <float name="temperature" value="-5"/></spectrum></emitter></shape>)")
                .find("the temperature must be positive"),
            std::string::npos);
}

TEST(MitsubaReader, Emitters) {
  SceneDesc s = read_text(R"(
    <emitter type="point"><point name="position" x="1" y="2" z="3"/><rgb name="intensity" value="300"/></emitter>
    <emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
    <emitter type="directional"><vector name="direction" value="0,0,1"/><rgb name="irradiance" value="2"/></emitter>
    <emitter type="spot"><float name="cutoff_angle" value="30"/>
      <transform name="to_world"><lookat origin="0,3,0" target="0,0,0" up="0,0,1"/></transform></emitter>)");
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_FLOAT_EQ(std::get<PointLight>(s.lights[0]).position.z, 3);
  EXPECT_TRUE(std::get<SkyLight>(s.lights[1]).is_constant());
  EXPECT_FLOAT_EQ(std::get<DistantLight>(s.lights[2]).radiance.g, 2);
  const auto& spot = std::get<SpotLight>(s.lights[3]);
  EXPECT_EQ(spot.falloff, SpotFalloff::Linear);
  EXPECT_FLOAT_EQ(spot.cone_angle, 30);
  EXPECT_FLOAT_EQ(spot.cone_delta, 30 - 22.5f);  // beam_width defaults to 3/4 of the cutoff
  EXPECT_NEAR(spot.direction.y, -1, 1e-5);
  EXPECT_NEAR(spot.up.z, 1, 1e-5);
}

TEST(MitsubaReader, EnvmapUsesMitsubasTexelPlacement) {
  write_image(temp_dir() / "envmap-test.exr", Image(8, 4));
  SceneDesc s = read_text(R"(<emitter type="envmap"><string name="filename" value="envmap-test.exr"/>
      <float name="scale" value="2"/><transform name="to_world"><rotate y="1" angle="90"/></transform></emitter>)");
  ASSERT_EQ(s.lights.size(), 1u);
  const auto& map = std::get<EnvironmentMap>(s.lights[0]);
  EXPECT_EQ(map.mapping, EnvironmentMapping::EquirectangularPoleRows);
  EXPECT_FLOAT_EQ(map.scale.g, 2);
  EXPECT_NEAR(map.to_world.vector({1, 0, 0}).z, -1, 1e-5f);
}

TEST(MitsubaReader, TexturedAreaEmittersOnAnalyticShapes) {
  // The lights of spheres, disks and cylinders read the texture at their samples' (u, v)
  // (TexturedEmission.AnalyticEmittersCarryTheTextureRaysFindAtTheirSamples checks the values).
  for (std::string shape : {"sphere", "disk", "cylinder"}) {
    SceneDesc s = read_text("<shape type=\"" + shape + "\"><emitter type=\"area\">"
                            "<texture type=\"checkerboard\" name=\"radiance\"/></emitter></shape>");
    ASSERT_EQ(s.shapes.size(), 1u) << shape;
    ASSERT_TRUE(s.shapes[0].emission && s.shapes[0].emission->texture >= 0) << shape;
    Scene scene(s);
    ASSERT_EQ(scene.lights().size(), 1u) << shape;
    float lo = 1e30f, hi = 0;
    for (int i = 0; i < 64; ++i) {
      LightEmission le = light_sample_le(scene.lights()[0], {(i % 8 + 0.5f) / 8, (i / 8 + 0.5f) / 8}, {0.5f, 0.5f},
                                         scene.bounding_sphere());
      lo = std::min(lo, le.radiance.g);
      hi = std::max(hi, le.radiance.g);
    }
    EXPECT_LT(lo, hi) << shape << ": the checkerboard's two colours";
  }
}

TEST(MitsubaReader, SerializedShapesPickTheirMeshByIndex) {
  const std::string file = (fs::path(CANDELA_SHARED_DIR) / "scenes/mitsuba-tests/common/meshes/matpreview.serialized").string();
  SceneDesc s = read_text(R"(<shape type="serialized"><string name="filename" value=")" + file + R"("/>
      <integer name="shape_index" value="2"/></shape>
    <shape type="serialized"><string name="filename" value=")" + file + R"("/><boolean name="face_normals" value="true"/></shape>)");
  ASSERT_EQ(s.shapes.size(), 2u);
  const TriangleMesh& big = std::get<MeshShape>(s.shapes[0].geometry).mesh;
  EXPECT_EQ(big.triangle_count(), 57152u);
  EXPECT_EQ(big.normals.size(), big.positions.size());
  const TriangleMesh& first = std::get<MeshShape>(s.shapes[1].geometry).mesh;
  EXPECT_EQ(first.triangle_count(), 512u);
  EXPECT_TRUE(first.normals.empty());
  EXPECT_NE(mitsuba_error_of(R"(<shape type="serialized"><string name="filename" value=")" + file +
                     R"("/><integer name="shape_index" value="7"/></shape>)")
                .find("shape_index 7 is out of range"),
            std::string::npos);
}

TEST(MitsubaReader, ErrorsNameFileAndLine) {
  EXPECT_NE(mitsuba_error_of("<shape type=\"sphere\">\n<float name=\"radiuss\" value=\"1\"/></shape>").find("test.xml:3"),
            std::string::npos);
  EXPECT_NE(mitsuba_error_of("<shape type=\"sphere\"><float name=\"radiuss\" value=\"1\"/></shape>").find("unknown parameter"),
            std::string::npos);
  EXPECT_NE(mitsuba_error_of("<shape type=\"teapot\"/>").find("unknown shape type"), std::string::npos);
  // A likely typo gets the nearest name the plugin reads, or the nearest type.
  EXPECT_NE(mitsuba_error_of("<shape type=\"sphere\"><float name=\"radiuss\" value=\"1\"/></shape>")
                .find("unknown parameter \"radiuss\" (did you mean \"radius\"?)"),
            std::string::npos);
  EXPECT_NE(mitsuba_error_of("<shape type=\"spehre\"/>").find("unknown shape type \"spehre\" (did you mean \"sphere\"?)"),
            std::string::npos)
      << mitsuba_error_of("<shape type=\"spehre\"/>");
  EXPECT_NE(mitsuba_error_of("<shape type=\"sphere\"><ref id=\"nothing\"/></shape>").find("undefined id \"nothing\""),
            std::string::npos);
  EXPECT_NE(mitsuba_error_of("<shape type=\"obj\"><string name=\"filename\" value=\"missing.obj\"/></shape>")
                .find("\"missing.obj\" not found"),
            std::string::npos);
  EXPECT_NE(mitsuba_error_of("<shape type=\"sphere\">").find("malformed XML"), std::string::npos);
}

// The text entry point: the name given is the file in messages, and relative paths resolve
// against the folder given (as if the text were a file there).
TEST(MitsubaReader, TextEntryPointNamesItsTextAndResolvesAgainstItsFolder) {
  const fs::path dir = temp_dir() / "text_entry";
  fs::create_directories(dir);
  {
    std::ofstream f(dir / "grey.xml");
    f << R"(<bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.25"/></bsdf>)";
  }
  Warnings warnings;
  SceneDesc s = read_mitsuba_scene_text(R"(<scene version="3.0.0"><include filename="grey.xml"/>
      <shape type="sphere"><ref id="grey"/></shape></scene>)",
                                        "in-memory.xml", dir, warnings);
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_EQ(s.source_file, "in-memory.xml");
  const auto& one = std::get<OneSidedMaterial>(s.materials[s.shapes[0].material]);
  EXPECT_FLOAT_EQ(std::get<DiffuseMaterial>(s.materials[one.material]).reflectance.value.g, 0.25f);
  try {
    read_mitsuba_scene_text("<scene version=\"3.0.0\">\n<shape type=\"teapot\"/></scene>", "in-memory.xml", dir,
                            warnings);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("in-memory.xml:2: unknown shape type", 0), 0u) << e.what();
  }
}

// Shapes, shapegroups, instances, textures, materials and lights carry the file:line:column of
// the element they come from (SceneDesc::places for the last three, parallel to their vectors).
TEST(MitsubaReader, DescriptionsKnowTheirPlaces) {
  SceneDesc s = read_text(R"(<texture type="checkerboard" id="checks"/>
<shape type="sphere">
  <bsdf type="diffuse"><ref name="reflectance" id="checks"/></bsdf>
</shape>
<shape type="shapegroup" id="group">
    <shape type="disk"/>
</shape>
  <shape type="instance"><ref id="group"/></shape>
<emitter type="point"/>)");
  // Line 1 is the <scene> that read_text adds.
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_EQ(s.shapes[0].where.to_string(), "test.xml:3:1");
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].where.to_string(), "test.xml:6:1");
  EXPECT_EQ(s.objects[0].shapes[0].where.to_string(), "test.xml:7:5");
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].where.to_string(), "test.xml:9:3");
  ASSERT_EQ(s.places.textures.size(), s.textures.size());
  EXPECT_EQ(s.places.textures.at(0).to_string(), "test.xml:2:1");
  ASSERT_EQ(s.places.materials.size(), s.materials.size());
  EXPECT_EQ(s.places.materials[std::size_t(s.shapes[0].material)].to_string(), "test.xml:4:3");
  ASSERT_EQ(s.places.lights.size(), 1u);
  EXPECT_EQ(s.places.lights[0].to_string(), "test.xml:10:1");
}

// Every scene of Mitsuba's render tests reads.
TEST(MitsubaReader, RenderTestScenes) {
  fs::path root = fs::path(CANDELA_SHARED_DIR) / "scenes/mitsuba-tests/tests/scenes";
  if (!fs::exists(root)) GTEST_SKIP() << "no shared Mitsuba test scenes";
  // Every scene of the suite reads; the participating-media ones (but test_surf_area_light of that
  // folder) have media, and every shape that refers to one is a medium boundary.
  int read = 0;
  for (const auto& dir : fs::directory_iterator(root))
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      if (entry.path().extension() != ".xml") continue;
      const bool media = dir.path().filename() == "participating_media" &&
                         entry.path().filename() != "test_surf_area_light_volpath.xml";
      Warnings warnings;
      SceneDesc s = read_mitsuba_scene(entry.path(), warnings);
      EXPECT_FALSE(s.shapes.empty() && s.instances.empty()) << entry.path();
      EXPECT_EQ(!s.media.empty(), media) << entry.path();
      if (dir.path().filename() == "participating_media") EXPECT_EQ(s.settings.integrator, "volpath") << entry.path();
      ++read;
    }
  EXPECT_EQ(read, 33);
}

}  // namespace
}  // namespace candela
