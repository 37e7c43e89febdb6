// Errors found while building the render scene from a description name the place in the scene file
// where the offending entry was declared (ShapeDesc::where, SceneDesc::places), not just the file.
#include <gtest/gtest.h>

#include <string>

#include "candela/io/scene_reader.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

// The message of the SceneError that building the scene throws ("" when it builds).
std::string build_error(const SceneDesc& desc) {
  try {
    Scene scene(desc);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

std::string build_error(const std::string& json) { return build_error(read_json_scene(json, "errors.json", ".")); }

TEST(SceneErrors, AShapeErrorNamesTheShapesLineInTheFile) {
  // Line 3 declares the emissive plane, which the scene refuses (its power would be infinite).
  std::string error = build_error(R"({
  "shapes": [
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "emission": {"radiance": [1, 1, 1]}}
  ]
})");
  EXPECT_EQ(error.rfind("errors.json:3:5: at /shapes/0: shape 0: an infinite plane cannot emit light", 0), 0u) << error;
}


// What a reader's checks cannot see (a light's own checks, material references) is named by the
// places the reader recorded.
TEST(SceneErrors, LightAndMaterialErrorsNameTheirPlaces) {
  SceneDesc lights;
  lights.source_file = "scene.xml";
  lights.lights = {PointLight{}, DistantLight{Vec3(0.0f), RGB(1.0f)}};
  lights.places.lights = {SourceLocation{"scene.xml", 4, 3}, SourceLocation{"scene.xml", 7, 3}};
  std::string error = build_error(lights);
  EXPECT_EQ(error.rfind("scene.xml:7:3: distant light: the direction must be a non-zero vector", 0), 0u) << error;

  SceneDesc materials;
  materials.source_file = "scene.xml";
  MaskMaterial mask;
  mask.material = 5;
  materials.materials = {DiffuseMaterial{}, mask};
  materials.places.materials = {SourceLocation{"scene.xml", 2, 1}, SourceLocation{"scene.xml", 9, 5}};
  error = build_error(materials);
  EXPECT_EQ(error.rfind("scene.xml:9:5: material 1: wraps material 5, which is not a material before it", 0), 0u)
      << error;
}

TEST(SceneErrors, WithoutPlacesTheFileIsNamed) {
  SceneDesc desc;
  desc.source_file = "made-in-code.json";
  ShapeDesc plane;
  plane.geometry = PlaneShape{};
  plane.emission = AreaEmission{};
  desc.shapes = {plane};
  try {
    Scene scene(desc);
    FAIL() << "an emissive plane was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("made-in-code.json: shape 0: an infinite plane cannot emit light", 0), 0u)
        << e.what();
  }
}

}  // namespace
}  // namespace candela
