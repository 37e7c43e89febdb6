// Tests of the JSON scene reader's errors for bad input, each naming its line, column and JSON pointer.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>

#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/json_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::json_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- bad input

TEST(JsonReader, MalformedJsonReportsLineAndColumn) {
  std::string message = error_of("{\n  \"camera\": {\n    \"fov\": 40,\n  }\n}");
  EXPECT_EQ(message.rfind("test.json:4:3: malformed JSON", 0), 0u) << message;
  EXPECT_NE(message.find("unexpected '}'"), std::string::npos) << message;
  EXPECT_EQ(error_of("").rfind("test.json:1:1: malformed JSON", 0), 0u);
  EXPECT_EQ(error_of("{\"shapes\": [\n").rfind("test.json:2:", 0), 0u) << error_of("{\"shapes\": [\n");
}

TEST(JsonReader, NumberBeyondDoubleRangeIsAnError) {
  std::string message = error_of("{\"camera\": {\n\"fov\": 1e999}}");
  EXPECT_EQ(message.rfind("test.json:2:8:", 0), 0u) << message;
  EXPECT_NE(message.find("1e999 is out of range"), std::string::npos) << message;
  expect_error_containing(R"({"camera": {"fov": 1e300}})", "out of range for a 32-bit float");
}

TEST(JsonReader, UnknownKeyNamesItsJsonPointer) {
  std::string message = error_of(
      "{\"shapes\": [\n"
      "  {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1},\n"
      "  {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"radiuss\": 2}]}");
  EXPECT_EQ(message,
            "test.json:3:56: at /shapes/1/radiuss: unknown key (did you mean \"radius\"?); expected one of: type, center, radius, uv, "
            "z_min, z_max, phi_max, material, emission, transform, transform_end, name, reverse_orientation, interior, "
            "exterior, animation_node, animation, deformation");
  expect_error_containing(R"({"camera": {"fov": 40, "zoom": 2}})", "at /camera/zoom: unknown key");
  expect_error_containing(R"({"scene": {}})", "at /scene: unknown key");
  expect_error_containing(R"({"render": {"samples": 4}})", "at /render/samples: unknown key");
  expect_error_containing(with_material(R"({"type": "diffuse", "albedo": 0.5})"),
                          "at /materials/m/albedo: unknown key");
  expect_error_containing(with_light(R"({"type": "point", "position": [0, 0, 0], "intensity": 1, "radius": 1})"),
                          "at /lights/0/radius: unknown key");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                    "emission": {"radiance": 1, "power": 3}})"),
                          "at /shapes/0/emission/power: unknown key");
}

TEST(JsonReader, PointerEscapesSlashAndTildeInMaterialNames) {
  std::string message = error_of(with_material(R"({"type": "diffuse"}, "a/b~c": {"type": "diffuse", "x": 1})"));
  EXPECT_NE(message.find("at /materials/a~1b~0c/x: unknown key"), std::string::npos) << message;
  EXPECT_EQ(message.rfind("test.json:1:", 0), 0u) << message;  // found again in the text despite the escapes
}

TEST(JsonReader, DuplicateKeyIsAnError) {
  std::string message =
      error_of("{\"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0],\n \"radius\": 1, \"radius\": 2}]}");
  EXPECT_NE(message.find("test.json:2:15: at /shapes/0/radius: duplicate key"), std::string::npos) << message;
}

TEST(JsonReader, WrongTypeIsAnError) {
  std::string radius_message = error_of(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": "big"})"));
  EXPECT_NE(radius_message.find("at /shapes/0/radius: expected a number, got string"), std::string::npos)
      << radius_message;
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0], "radius": 1})"),
                          "at /shapes/0/center: expected an array of 3 numbers, got an array of 2 elements");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, null, 0], "radius": 1})"),
                          "at /shapes/0/center/1: expected a number, got null");
  expect_error_containing(R"({"render": {"spp": 2.5}})", "at /render/spp: expected an integer, got 2.5");
  expect_error_containing(R"({"render": {"output": 3}})", "expected a string, got number");
  expect_error_containing(R"({"shapes": {}})", "at /shapes: expected an array of shapes, got object");
  expect_error_containing(R"({"materials": []})", "at /materials: expected an object");
  expect_error_containing(R"({"camera": 5})", "at /camera: expected an object, got number");
  expect_error_containing("[]", "expected an object, got an array of 0 elements");
  expect_error_containing(
      with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "reverse_orientation": 1})"),
      "expected true or false, got number");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": 3})"),
                          "expected a material name or a material object, got number");
  expect_error_containing(with_material(R"({"type": "diffuse", "reflectance": true})"),
                          "at /materials/m/reflectance: expected a colour, [r, g, b] or a single number, or a "
                          "texture (a name or an object), got boolean");
  // A string names a texture.
  expect_error_containing(with_material(R"({"type": "diffuse", "reflectance": "red"})"),
                          "at /materials/m/reflectance: unknown texture \"red\" (\"textures\" defines none)");
}

TEST(JsonReader, MissingRequiredKeyIsAnError) {
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0]})"),
                          "at /shapes/0: missing required key \"radius\"");
  expect_error_containing(with_shape(R"({"center": [0, 0, 0], "radius": 1})"), "missing required key \"type\"");
  expect_error_containing(with_light(R"({"type": "point", "position": [0, 0, 0]})"),
                          "missing required key \"intensity\"");
  expect_error_containing(with_shape(R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]})"),
                          "missing required key \"indices\"");
  expect_error_containing(with_shape(R"({"type": "mesh"})"), "a mesh needs either \"file\" or inline \"positions\"");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "emission": {}})"),
                          "at /shapes/0/emission: missing required key \"radiance\"");
  expect_error_containing(with_light(R"({"type": "sky", "ground": 1})"), "a sky needs \"radiance\"");
}

TEST(JsonReader, NonPositiveSizesAreErrors) {
  std::string message = error_of(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": -1})"));
  EXPECT_NE(message.find("test.json:1:"), std::string::npos) << message;
  EXPECT_NE(message.find("at /shapes/0/radius: expected a positive number, got -1"), std::string::npos) << message;
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0})"), "positive");
  expect_error_containing(with_shape(R"({"type": "box", "min": [0, 0, 0], "max": [1, 0, 1]})"),
                          "at /shapes/0/max: max must exceed min on every axis; on axis y");
  expect_error_containing(with_shape(R"({"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 0]})"),
                          "at /shapes/0/normal: expected a non-zero vector");
  expect_error_containing(
      with_shape(R"({"type": "rectangle", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [2, 0, 0]})"),
      "edge_u and edge_v are parallel");
  expect_error_containing(with_light(R"({"type": "sphere", "center": [0, 0, 0], "radius": -2, "radiance": 1})"),
                          "at /lights/0/radius: expected a positive number, got -2");
}

TEST(JsonReader, BadResolutionIsAnError) {
  expect_error_containing(R"({"camera": {"width": 0}})", "at /camera/width: expected an integer in [1, 65536], got 0");
  expect_error_containing(R"({"camera": {"height": -5}})", "at /camera/height: expected an integer in [1, 65536]");
  expect_error_containing(R"({"camera": {"width": 100000}})", "expected an integer in [1, 65536], got 100000");
  expect_error_containing(R"({"camera": {"width": 65536, "height": 65536}})", "exceeds the limit of 2^28 pixels");
  expect_error_containing(R"({"camera": {"width": 1e30}})", "too large");
}

TEST(JsonReader, BadRenderSettingsAreErrors) {
  expect_error_containing(R"({"render": {"spp": 0}})", "at /render/spp: expected an integer in [1, 16777216], got 0");
  expect_error_containing(R"({"render": {"max_depth": 0}})", "expected an integer in [1, 100000]");
  expect_error_containing(R"({"render": {"rr_start_depth": -1}})", "expected an integer >= 0");
  expect_error_containing(R"({"render": {"seed": -1}})", "expected a non-negative integer, got -1");
  expect_error_containing(R"({"render": {"spp": 3000000000}})", "expected an integer in [1, 16777216], got 3000000000");
  expect_error_containing(R"({"render": {"integrator": ""}})", "the integrator name is empty");
}


TEST(JsonReader, BadScreenWindowsAreErrors) {
  expect_error_containing(R"({"camera": {"screen_window": [0, 1, 0]}})",
                          "at /camera/screen_window: expected [x0, x1, y0, y1]");
  expect_error_containing(R"({"camera": {"screen_window": [1, 0, 0, 1]}})",
                          "at /camera/screen_window: the window must have x0 < x1 and y0 < y1, got [1, 0, 0, 1]");
  expect_error_containing(R"({"camera": {"screen_window": [0, 1, "a", 1]}})", "at /camera/screen_window/2");
}

TEST(JsonReader, BadLensShutterAndMotionAreErrors) {
  expect_error_containing(R"({"camera": {"lens_radius": -1}})", "at /camera/lens_radius: expected a number >= 0");
  expect_error_containing(R"({"camera": {"focus_distance": 0}})", "at /camera/focus_distance: expected a positive");
  expect_error_containing(R"({"camera": {"shutter": [1, 0]}})",
                          "at /camera/shutter: the shutter must not close before it opens, got [1, 0]");
  expect_error_containing(R"({"camera": {"shutter": 1}})", "at /camera/shutter: expected an array of 2 numbers");
  expect_error_containing(R"({"render": {"transform_times": [1, 1]}})",
                          "at /render/transform_times: the start time must be less than the end time");
  expect_error_containing(R"({"render": {"transform_times": [0, 1, 2]}})", "expected an array of 2 numbers");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                         "emission": {"radiance": 1}, "transform_end": []})"),
                          "at /shapes/0/transform_end: area lights must not move");
  expect_error_containing(with_shape(R"({"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                                         "transform_end": [{"translate": [0, 1, 0]}]})"),
                          "at /shapes/0/transform_end: an infinite plane must not move");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                         "transform_end": [{"scale": 0}]})"),
                          "at /shapes/0/transform_end/0/scale: scale factors must be non-zero");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                         "transform_end": {"scale": 2}})"),
                          "at /shapes/0/transform_end: expected an array of transform steps");
  // Lights are not shapes that can be given an end transform.
  expect_error_containing(with_light(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "radiance": 1,
                                         "transform_end": []})"),
                          "at /lights/0/transform_end: unknown key");
}

TEST(JsonReader, BadSamplerAndFilterAreErrors) {
  expect_error_containing(R"({"render": {"sampler": {"type": "halton"}}})",
                          "at /render/sampler/type: unknown sampler \"halton\"; expected one of: random, independent, "
                          "stratified, poisson, zsobol");
  expect_error_containing(R"({"render": {"sampler": {}}})", "at /render/sampler: missing required key \"type\"");
  expect_error_containing(R"({"render": {"sampler": "zsobol"}})", "at /render/sampler: expected an object");
  expect_error_containing(R"({"render": {"sampler": {"type": "zsobol", "jitter": false}}})",
                          "at /render/sampler/jitter: unknown key");
  expect_error_containing(R"({"render": {"sampler": {"type": "stratified", "jitter": 0}}})",
                          "at /render/sampler/jitter: expected true or false");
  expect_error_containing(R"({"render": {"filter": {"type": "triangle"}}})",
                          "at /render/filter/type: unknown filter \"triangle\"; expected one of: box, tent, "
                          "gaussian, mitchell");
  expect_error_containing(R"({"render": {"filter": {"type": "box", "radius": 0}}})",
                          "at /render/filter/radius: a filter radius must be in (0, 64] pixels, got 0");
  expect_error_containing(R"({"render": {"filter": {"type": "tent", "radius": [1, 100]}}})",
                          "a filter radius must be in (0, 64] pixels, got 100");
  expect_error_containing(R"({"render": {"filter": {"type": "tent", "radius": [1]}}})", "expected an array of 2");
  expect_error_containing(R"({"render": {"filter": {"type": "gaussian", "sigma": 0}}})",
                          "at /render/filter/sigma: expected a positive number");
  expect_error_containing(R"({"render": {"filter": {"type": "box", "sigma": 1}}})",
                          "at /render/filter/sigma: unknown key");
  expect_error_containing(R"({"render": {"filter": {"type": "gaussian", "b": 1}}})",
                          "at /render/filter/b: unknown key");
  expect_error_containing(R"({"render": {"filter": {"type": "mitchell", "c": "half"}}})",
                          "at /render/filter/c: expected a number");
}

TEST(JsonReader, BadStrategiesAndAdaptiveSettingsAreErrors) {
  expect_error_containing(R"({"render": {"direction_sampling": "cos"}})",
                          "at /render/direction_sampling: unknown direction sampling \"cos\"; expected one of: bsdf, "
                          "cosine, uniform");
  expect_error_containing(R"({"render": {"light_selection": "random"}})",
                          "unknown light selection \"random\"; expected one of: power, paper, uniform, bvh");
  EXPECT_EQ(read(R"({"render": {"light_selection": "uniform"}})").settings.light_selection, LightSelection::Uniform);
  expect_error_containing(R"({"render": {"bvh": "small"}})",
                          "at /render/bvh: unknown bvh \"small\"; expected one of: fast, compact");
  expect_error_containing(R"({"render": {"mis": "yes"}})", "at /render/mis: expected true or false");
  expect_error_containing(R"({"render": {"shadow_rays": 0}})", "at /render/shadow_rays: expected an integer in [1, 1024]");
  expect_error_containing(R"({"render": {"adaptive": {}}})",
                          "at /render/adaptive: expected \"threshold\", \"spp\" or both");
  expect_error_containing(R"({"render": {"adaptive": {"spp": 8}}})",
                          "at /render/adaptive/spp: must be at least the batch size (16), got 8");
  expect_error_containing(R"({"render": {"adaptive": {"spp": 64, "max_spp": 32}}})",
                          "at /render/adaptive/max_spp: must be at least the mean spp (64), got 32");
  expect_error_containing(R"({"render": {"adaptive": {"threshold": 0}}})",
                          "at /render/adaptive/threshold: expected a positive number");
  expect_error_containing(R"({"render": {"adaptive": {"threshold": 0.1, "batch": 12}}})",
                          "at /render/adaptive/batch: must be a power of two, got 12");
  expect_error_containing(R"({"render": {"adaptive": {"threshold": 0.1, "batch": 0}}})", "expected an integer in [1, 65536]");
  expect_error_containing(R"({"render": {"adaptive": {"threshold": 0.1, "batch": 32, "max_spp": 16}}})",
                          "at /render/adaptive/max_spp: must be at least the batch size (32), got 16");
  expect_error_containing(R"({"render": {"adaptive": {"threshold": 0.1, "batches": 2}}})",
                          "at /render/adaptive/batches: unknown key");
}

TEST(JsonReader, DegenerateCameraIsAnError) {
  expect_error_containing(R"({"camera": {"position": [1, 1, 1], "look_at": [1, 1, 1]}})",
                          "at /camera/look_at: look_at must differ from position");
  expect_error_containing(R"({"camera": {"position": [0, 0, 0], "look_at": [0, 5, 0]}})",
                          "at /camera/up: up is parallel to the view direction");
  expect_error_containing(R"({"camera": {"up": [0, 0, 0]}})", "at /camera/up: expected a non-zero vector");
  expect_error_containing(R"({"camera": {"fov": 180}})", "field of view must be in (0, 180) degrees, got 180");
  expect_error_containing(R"({"camera": {"fov": 0}})", "field of view");
}

TEST(JsonReader, UnknownMaterialNameIsAnError) {
  std::string message =
      error_of(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "gold"})",
                          R"({"red": {"type": "diffuse"}, "blue": {"type": "diffuse"}})"));
  EXPECT_NE(message.find("at /shapes/0/material: unknown material \"gold\"; defined: blue, red"), std::string::npos)
      << message;
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "gold"})"),
                          "defines none");
}

TEST(JsonReader, UnknownTypesAreErrors) {
  expect_error_containing(with_shape(R"({"type": "torus"})"),
                          "at /shapes/0/type: unknown shape type \"torus\"; expected one of: sphere, plane, box, "
                          "rectangle, mesh, disk, cylinder, sdfgrid, curve, instance");
  expect_error_containing(with_material(R"({"type": "velvet"})"),
                          "at /materials/m/type: unknown material type \"velvet\"");
  expect_error_containing(with_light(R"({"type": "laser"})"),
                          "at /lights/0/type: unknown light type \"laser\"; expected one of: point, sky, spot, "
                          "distant, environment, projector, goniometric, sphere, rectangle");
}

TEST(JsonReader, BadMaterialValuesAreErrors) {
  std::string message = error_of(with_material(R"({"type": "phong", "d": 0.6, "s": 0.3, "t": 0.2})"));
  EXPECT_NE(message.find("at /materials/m: d + s + t must be <= 1"), std::string::npos) << message;
  EXPECT_NO_THROW(read(with_material(R"({"type": "phong", "d": 0.6, "s": 0.3, "t": 0.1})")));
  expect_error_containing(with_material(R"({"type": "phong", "d": 1.5})"), "expected a number in [0, 1], got 1.5");
  expect_error_containing(with_material(R"({"type": "phong", "exponent": -1})"), "expected a number >= 0");
  expect_error_containing(with_material(R"({"type": "glass", "ior": 0})"), "at /materials/m/ior: expected a positive");
  expect_error_containing(with_material(R"({"type": "diffuse", "reflectance": [0.5, 1.2, 0.5]})"),
                          "at /materials/m/reflectance/1: a reflectance must be <= 1");
  expect_error_containing(with_material(R"({"type": "mirror", "reflectance": -0.1})"), "must be >= 0, got -0.1");
  expect_error_containing(with_light(R"({"type": "point", "position": [0, 0, 0], "intensity": [1, -1, 1]})"),
                          "at /lights/0/intensity/1: colour components must be >= 0");
  EXPECT_NO_THROW(read(with_light(R"({"type": "point", "position": [0, 0, 0], "intensity": 1000})")));
}

TEST(JsonReader, BadMeshDataIsAnError) {
  std::string out_of_range =
      error_of(with_shape(R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, 1, 3]})"));
  EXPECT_NE(out_of_range.find("at /shapes/0/indices/2: index 3 is out of range: the mesh has 3 positions"),
            std::string::npos)
      << out_of_range;
  expect_error_containing(
      with_shape(R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, -1, 2]})"),
      "index -1 is out of range");
  expect_error_containing(
      with_shape(R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, 1]})"),
      "expected a non-zero multiple of 3 indices");
  expect_error_containing(with_shape(R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0]]})"),
                          "a mesh needs at least 3 positions");
  expect_error_containing(with_shape(
                         R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "normals": [[0, 0, 1]]})"),
                          "at /shapes/0/normals: expected one entry per position (3), got 1");
  expect_error_containing(with_shape(
                   R"({"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "uvs": [[0, 0], [1, 0], [0]]})"),
                          "at /shapes/0/uvs/2: expected an array of 2 numbers");
  expect_error_containing(
      with_shape(R"({"type": "mesh", "file": "a.obj", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]})"),
      "either \"file\" or inline \"positions\", not both");
  expect_error_containing(with_shape(R"({"type": "mesh", "file": "a.obj", "indices": [0, 1, 2]})"),
                          "at /shapes/0/indices: inline mesh data cannot be combined with \"file\"");
}

TEST(JsonReader, MissingMeshFileNamesTheFile) {
  std::string message = error_of(with_shape(R"({"type": "mesh", "file": "no-such-cow.obj"})"), "/tmp/candela-no-dir");
  EXPECT_NE(message.find("no-such-cow.obj"), std::string::npos) << message;
  EXPECT_NE(message.find("/shapes/0/file"), std::string::npos) << message;
}

TEST(JsonReader, BadTransformsAreErrors) {
  auto transform_error = [](const std::string& steps) {
    return error_of(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "transform": )" + steps + "}"));
  };
  EXPECT_NE(transform_error(R"([{"scale": [1, 0, 1]}])")
                .find("at /shapes/0/transform/0/scale: scale factors must be non-zero"),
            std::string::npos);
  EXPECT_NE(
      transform_error(R"([{"translate": [1, 0, 0], "scale": 2}])")
          .find("at /shapes/0/transform/0: a transform step needs exactly one of: translate, rotate, scale, matrix; "
                "got translate, scale"),
      std::string::npos);
  EXPECT_NE(transform_error(R"([{"translat": [1, 0, 0]}])").find("at /shapes/0/transform/0/translat: unknown key"),
            std::string::npos);
  EXPECT_NE(transform_error(R"([{}])").find("needs exactly one of"), std::string::npos);
  EXPECT_NE(transform_error(R"([{"rotate": {"angle": 10, "axis": [0, 0, 0]}}])").find("expected a non-zero vector"),
            std::string::npos);
  EXPECT_NE(transform_error(R"([{"rotate": {"axis": [0, 1, 0]}}])").find("missing required key \"angle\""),
            std::string::npos);
  EXPECT_NE(transform_error(R"([{"matrix": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 0, 0,  0, 0, 0, 1]}])")
                .find("the matrix is singular"),
            std::string::npos);
  EXPECT_NE(transform_error(R"([{"matrix": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 1, 1]}])")
                .find("last row must be [0, 0, 0, 1]"),
            std::string::npos);
  EXPECT_NE(transform_error(R"([{"matrix": [1, 0, 0]}])").find("expected 16 numbers"), std::string::npos);
  EXPECT_NE(transform_error(R"({"translate": [1, 0, 0]})").find("expected an array of transform steps"),
            std::string::npos);
}

TEST(JsonReader, BadSkyIsAnError) {
  expect_error_containing(with_light(R"({"type": "sky", "radiance": 1, "zenith": 2})"), "not both");
}

}  // namespace
}  // namespace candela
