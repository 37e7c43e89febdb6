// Tests of the pbrt-v4 reader: lights, shapes, the graphics state that applies to them, and the
// Bitterli scenes.
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
#include "candela/scene/scene.h"
#include "candela/spectral/cie.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;
namespace fs = std::filesystem;

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
}

// pbrt-v4's image area light: the emission is "scale" times the image at the hit's uv, clamped at the
// image's edges; "L" and "power" do not go with an image.
TEST(PbrtReader, AreaLightWithAnImageIsATexturedEmitter) {
  ScratchFile image("glow.png");
  SceneDesc scene = read_lines({"WorldBegin", "AreaLightSource \"diffuse\" \"string filename\" \"glow.png\" "
                                "\"float scale\" 4 \"bool twosided\" true",
                                "Shape \"sphere\""});
  ASSERT_EQ(scene.shapes.size(), 1u);
  const AreaEmission& emission = *scene.shapes[0].emission;
  EXPECT_TRUE(emission.two_sided);
  EXPECT_EQ(emission.radiance.r, 4);
  EXPECT_EQ(emission.radiance.b, 4);
  ASSERT_EQ(emission.texture, 0);
  const auto& texture = std::get<ImageTexture>(scene.textures[0]);
  EXPECT_EQ(fs::path(texture.filename).filename(), "glow.png");
  EXPECT_EQ(texture.wrap, TextureWrap::Clamp);
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\" \"string filename\" \"glow.png\" \"rgb L\" [1 1 1]"}, 2,
               "\"string filename\"", "cannot be given together with \"L\"");
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\" \"string filename\" \"glow.png\" \"float power\" 3"}, 2,
               "\"float power\"", "not supported with an image");
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\" \"string filename\" \"none.png\""}, 2,
               "\"string filename\"", "none.png");
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

// pbrt-v4's Loop subdivision surfaces (geometry/loop_subdivision.h): 3 levels unless "levels" says
// otherwise, points on the limit surface with its normals, which face away from the winding as
// pbrt-v4's do.
TEST(PbrtReader, LoopSubdivisionSurfaces) {
  const std::string octahedron =
      "\"point3 P\" [ 0 1 0  1 0 0  0 0 1  -1 0 0  0 0 -1  0 -1 0 ] "
      "\"integer indices\" [ 0 2 1  0 3 2  0 4 3  0 1 4  5 1 2  5 2 3  5 3 4  5 4 1 ]";
  SceneDesc scene =
      read_lines({"WorldBegin", "Shape \"loopsubdiv\" " + octahedron,
                  "Shape \"loopsubdiv\" \"integer levels\" 0 \"string scheme\" \"loop\" " + octahedron});
  ASSERT_EQ(scene.shapes.size(), 2u);
  const TriangleMesh& smooth = mesh_of(scene.shapes[0]);
  EXPECT_EQ(smooth.triangle_count(), 8u * 64);
  ASSERT_EQ(smooth.normals.size(), smooth.positions.size());
  EXPECT_TRUE(smooth.uvs.empty());
  float top = 0;
  for (size_t i = 0; i < smooth.positions.size(); ++i) {
    top = std::max(top, smooth.positions[i].y);
    EXPECT_LT(dot(smooth.normals[i], smooth.positions[i]), 0) << i;  // inwards: against the winding
  }
  // pbrt-v4's limit point of a valence-4 vertex: half of it and an eighth of each of its neighbours.
  EXPECT_NEAR(top, 0.5f, 1e-6f);
  const TriangleMesh& coarse = mesh_of(scene.shapes[1]);
  EXPECT_EQ(coarse.triangle_count(), 8u);
  for (const Point3& p : coarse.positions) EXPECT_NEAR(std::abs(p.x) + std::abs(p.y) + std::abs(p.z), 0.5f, 1e-6f);

  // One triangle with `parameters` added.
  auto triangle = [](const std::string& parameters) {
    return std::vector<std::string>{"WorldBegin",
                                    "Shape \"loopsubdiv\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] " + parameters};
  };
  expect_error(triangle(""), 2, "Shape",
               "\"indices\" is required: give the control mesh's triangles as \"integer indices\"");
  expect_error({"WorldBegin", "Shape \"loopsubdiv\" \"integer indices\" [ 0 1 2 ]"}, 2, "Shape",
               "\"P\" is required");
  expect_error(triangle("\"integer indices\" [ 0 1 2 0 ]"), 2, "\"integer indices\"",
               "has 4 values, which is not a multiple of 3");
  expect_error(triangle("\"integer indices\" [ 0 1 3 ]"), 2, "\"integer indices\"",
               "value 3 (number 3) is out of range: \"P\" has 3 points");
  expect_error(triangle("\"integer indices\" [ 0 1 1 ]"), 2, "\"integer indices\"",
               "do not make a mesh that can be subdivided: triangle 1 (0 1 1) names a point twice");
  expect_error(triangle("\"integer indices\" [ 0 1 2 ] \"integer levels\" -1"), 2, "\"integer levels\"",
               "must be at least 0, got -1");
  expect_error(triangle("\"integer indices\" [ 0 1 2 ] \"integer levels\" 20"), 2, "\"integer levels\"",
               "20 would make 1099511627776 triangles of the 1 given, more than the 4194304");
  expect_error(triangle("\"integer indices\" [ 0 1 2 ] \"normal N\" [ 0 0 1 ]"), 2, "\"normal N\"",
               "unused parameter");
  expect_warning(triangle("\"integer indices\" [ 0 1 2 ] \"string scheme\" \"catmull-clark\""), 2,
                 "\"string scheme\"", "\"scheme\" \"catmull-clark\" is ignored: pbrt-v4 subdivides with Loop's");
}

TEST(PbrtReader, AlphaAndOtherShapeParameters) {
  SceneDesc scene = read_lines({"WorldBegin", "Shape \"sphere\" \"float alpha\" 1"});
  EXPECT_EQ(scene.shapes.size(), 1u);
  EXPECT_EQ(scene.shapes[0].material, -1);  // alpha 1 is no cut-out
  // Alpha below 1 wraps the shape's material (pbrt's default diffuse where none is set) in a mask of
  // that opacity, one per material and alpha however many shapes share them.
  SceneDesc cut = read_lines({"WorldBegin", "Texture \"holes\" \"float\" \"checkerboard\"",
                              "Shape \"sphere\" \"float alpha\" 0.5", "Shape \"disk\" \"float alpha\" 0.5",
                              "Material \"conductor\"", "Shape \"sphere\" \"texture alpha\" \"holes\""});
  ASSERT_EQ(cut.shapes.size(), 3u);
  EXPECT_EQ(cut.shapes[0].material, cut.shapes[1].material);
  const auto& half = std::get<MaskMaterial>(cut.materials[size_t(cut.shapes[0].material)]);
  EXPECT_EQ(half.opacity.value, 0.5f);
  EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(cut.materials[size_t(half.material)]));
  const auto& holes = std::get<MaskMaterial>(cut.materials[size_t(cut.shapes[2].material)]);
  EXPECT_EQ(holes.opacity.texture, 0);
  EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(cut.materials[size_t(holes.material)]));
  expect_error({"WorldBegin", "Shape \"sphere\" \"float alpha\" 1.5"}, 2, "\"float alpha\"", "must be in [0, 1]");
  expect_error({"WorldBegin", "AreaLightSource \"diffuse\"", "Shape \"sphere\" \"float alpha\" 0.5"}, 3,
               "\"float alpha\"", "on an area light is not supported");
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
    EXPECT_EQ(texture.filter, TextureFilter::Bilinear);
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

// A sphere's (u, v) is pbrt-v4's: u = phi / 2 pi, v = 1 - theta / pi with theta from +z of its
// object space (0 at the bottom, 1 at the top), so textures land where pbrt-v4 puts them.
TEST(PbrtReader, SphereUvIsPbrts) {
  SceneDesc desc = read_lines({"WorldBegin", "Translate 0 0 5", "Shape \"sphere\" \"float radius\" 2"});
  EXPECT_EQ(std::get<SphereShape>(desc.shapes.at(0).geometry).uv, SphereUv::Pbrt);
  Scene scene(desc);
  auto hit_from = [&](Vec3 from, Vec3 towards) {
    SurfaceHit hit;
    EXPECT_TRUE(scene.intersect(Ray{from, normalize(towards - from), std::numeric_limits<float>::infinity(), 0}, hit));
    EXPECT_NEAR(length(hit.p - Point3(0, 0, 5)), 2, 1e-4f);
    EXPECT_GT(dot(hit.ng, hit.p - Point3(0, 0, 5)), 0) << "normals point outwards";
    return hit;
  };
  EXPECT_NEAR(hit_from({0, 0, 20}, {0, 0, 5}).uv.y, 1, 1e-3f);  // the top, theta = 0
  EXPECT_NEAR(hit_from({0, 0, -20}, {0, 0, 5}).uv.y, 0, 1e-3f);  // the bottom
  // On the equator at phi = 90 degrees: u = 1/4, v = 1/2, and dp/dv points up (+z), as pbrt-v4's.
  SurfaceHit side = hit_from({0, 20, 5}, {0, 0, 5});
  EXPECT_NEAR(side.uv.x, 0.25f, 1e-3f);
  EXPECT_NEAR(side.uv.y, 0.5f, 1e-3f);
  EXPECT_GT(side.dpdv.z, 0);
  EXPECT_LT(side.dpdu.x, 0);  // dp/du = 2 pi (-y, x, 0)
}

// A partial sphere and a cylinder (zmin, zmax, phimax) are analytic shapes with pbrt-v4's (u, v) of
// the part kept: u = phi / phimax; the sphere's v = (theta - theta(zmin)) / (theta(zmax) - theta(zmin)),
// the cylinder's v = (z - zmin) / (zmax - zmin). Through the cuts their insides show.
TEST(PbrtReader, PartialSpheresAndCylinders) {
  SceneDesc desc = read_lines({"WorldBegin", "Translate 0 0 5",
                               "Shape \"sphere\" \"float radius\" 2 \"float zmin\" -1 \"float zmax\" 1.5 \"float phimax\" 270",
                               "Translate 10 0 0",
                               "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" -1 \"float zmax\" 2 \"float phimax\" 180",
                               "Shape \"sphere\" \"float zmin\" -3 \"float zmax\" 1 \"float phimax\" 360",
                               "Shape \"cylinder\""});
  ASSERT_EQ(desc.shapes.size(), 4u);
  const auto& sphere = std::get<SphereShape>(desc.shapes[0].geometry);
  EXPECT_EQ(sphere.uv, SphereUv::Pbrt);
  EXPECT_EQ(sphere.radius, 2);
  EXPECT_TRUE(sphere.z_min_given && sphere.z_max_given);
  EXPECT_EQ(sphere.z_min, -1);
  EXPECT_EQ(sphere.z_max, 1.5f);
  EXPECT_EQ(sphere.phi_max, 270);
  const auto& cylinder = std::get<CylinderShape>(desc.shapes[1].geometry);
  EXPECT_EQ(cylinder.p0, Point3(0, 0, -1));
  EXPECT_EQ(cylinder.p1, Point3(0, 0, 2));
  EXPECT_EQ(cylinder.radius, 0.5f);
  EXPECT_EQ(cylinder.phi_max, 180);
  // Values that cut nothing off leave the whole sphere; the cylinder's defaults are pbrt-v4's.
  const auto& whole = std::get<SphereShape>(desc.shapes[2].geometry);
  EXPECT_FALSE(whole.partial());
  EXPECT_FALSE(whole.z_min_given || whole.z_max_given);
  const auto& unit = std::get<CylinderShape>(desc.shapes[3].geometry);
  EXPECT_EQ(unit.p0, Point3(0, 0, -1));
  EXPECT_EQ(unit.p1, Point3(0, 0, 1));
  EXPECT_EQ(unit.radius, 1);
  EXPECT_EQ(unit.phi_max, 360);

  desc.shapes.resize(2);
  Scene scene(desc);
  auto hit_from = [&](Vec3 from, Vec3 towards) {
    SurfaceHit hit;
    EXPECT_TRUE(scene.intersect(Ray{from, normalize(towards - from), std::numeric_limits<float>::infinity(), 0}, hit))
        << from.x << " " << from.y << " " << from.z;
    return hit;
  };
  // The sphere at phi = 90 degrees on its equator: u = 90 / 270, v = (pi/2 - acos(-1/2)) / (acos(3/4) - acos(-1/2)).
  const float v_equator = (kPi / 2 - std::acos(-0.5f)) / (std::acos(0.75f) - std::acos(-0.5f));
  SurfaceHit side = hit_from({0, 20, 5}, {0, 0, 5});
  EXPECT_NEAR(side.uv.x, 1.0f / 3, 1e-4f);
  EXPECT_NEAR(side.uv.y, v_equator, 1e-4f);
  EXPECT_GT(side.ng.y, 0.999f);
  EXPECT_LT(side.dpdu.x, 0);  // dp/du = phimax (-y, x, 0)
  EXPECT_GT(side.dpdv.z, 0);  // v grows with z
  // From phi = 315 degrees (cut away) through the centre: the inside of phi = 135 degrees.
  SurfaceHit inside = hit_from({20, -20, 5}, {0, 0, 5});
  EXPECT_NEAR(inside.p.x, -std::sqrt(2.0f), 1e-4f);
  EXPECT_NEAR(inside.uv.x, 0.5f, 1e-4f);
  EXPECT_NEAR(inside.uv.y, v_equator, 1e-4f);
  EXPECT_GT(dot(inside.ng, normalize(Vec3(-1, 1, 0))), 0.999f) << "the normal points outwards, away from the ray";
  // Down its axis, through the caps cut off above 1.5 and below -1: nothing.
  SurfaceHit hit;
  EXPECT_FALSE(scene.intersect(Ray{{0, 0, 20}, {0, 0, -1}, std::numeric_limits<float>::infinity(), 0}, hit));
  // The half cylinder (phi <= 180: y >= 0) at x = 10, z = 5 + 0.5: from +y, u = 1/2, v = 1/2; from
  // -y through the cut, the inside of the same point.
  for (float from_y : {20.0f, -20.0f}) {
    SurfaceHit c = hit_from({10, from_y, 5.5f}, {10, 0, 5.5f});
    EXPECT_NEAR(c.p.y, 0.5f, 1e-4f) << from_y;
    EXPECT_NEAR(c.uv.x, 0.5f, 1e-4f) << from_y;
    EXPECT_NEAR(c.uv.y, 0.5f, 1e-4f) << from_y;
    EXPECT_GT(c.ng.y, 0.999f) << from_y;
    EXPECT_NEAR(c.dpdu.x, -kPi * 0.5f, 1e-4f) << from_y;  // dp/du = phimax (-y, x, 0)
    EXPECT_NEAR(c.dpdv.z, 3, 1e-4f) << from_y;             // dp/dv = (0, 0, zmax - zmin)
  }
}

// pbrt-v4's "power" spreads over a partial sphere's and a cylinder's area, phimax r (zmax - zmin).
TEST(PbrtReader, PartialShapeAreaLightPower) {
  const float pi = std::numbers::pi_v<float>;
  SceneDesc scene = read_lines(
      {"WorldBegin", "AreaLightSource \"diffuse\" \"float power\" 10",
       "Shape \"sphere\" \"float radius\" 2 \"float zmin\" -1 \"float zmax\" 1.5 \"float phimax\" 270",
       "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" -1 \"float zmax\" 2 \"float phimax\" 180"});
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_NEAR(scene.shapes[0].emission->radiance.r, 10 / (pi * (1.5f * pi * 2 * 2.5f)), 1e-5f);
  EXPECT_NEAR(scene.shapes[1].emission->radiance.r, 10 / (pi * (pi * 0.5f * 3)), 1e-5f);
  Scene built(scene);
  ASSERT_EQ(built.lights().size(), 2u);
  EXPECT_NEAR(light_power(built.lights()[0]), 10, 1e-3f);  // the luminance of a grey radiance is its value
  EXPECT_NEAR(light_power(built.lights()[1]), 10, 1e-3f);
}

}  // namespace
}  // namespace candela
