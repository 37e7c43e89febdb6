// Tests of read_scene_file's dispatch and errors, and that every shipped and documented JSON scene reads.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/json_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::json_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- read_scene_file

TEST(JsonReader, SceneFileWithUnknownExtensionIsAnError) {
  std::string message = scene_file_error_of(kSharedDir / "meshes/ply-tests/debian-copyright.txt");
  EXPECT_NE(message.find("debian-copyright.txt"), std::string::npos) << message;
  EXPECT_NE(message.find("unsupported scene file extension \".txt\"; supported: .json, .pbrt"), std::string::npos)
      << message;
  EXPECT_NE(scene_file_error_of(kSharedDir / "README.md").find("\".md\""), std::string::npos);
}

TEST(JsonReader, MitsubaParametersForAnotherFormatAreAnError) {
  try {
    read_scene_file(kSourceDir / "scenes/cornell-box.json", SceneReadOptions{{{"spp", "4"}}, nullptr});
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("$spp is a Mitsuba scene parameter"), std::string::npos) << e.what();
  }
}

TEST(JsonReader, MissingSceneFileIsAnError) {
  std::string message = scene_file_error_of("/tmp/candela-no-such-scene.json");
  EXPECT_NE(message.find("/tmp/candela-no-such-scene.json"), std::string::npos) << message;
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
  EXPECT_NE(scene_file_error_of(kSourceDir / "scenes").find("is a directory"), std::string::npos);
}

TEST(JsonReader, SceneFileErrorsNameTheFile) {
  // The JSON reader's messages carry the path as given to read_scene_file.
  fs::path file = fs::temp_directory_path() / "candela-json-reader-test-bad.json";
  {
    std::ofstream out(file);
    out << "{\n  \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": -1}]\n}\n";
  }
  std::string message = scene_file_error_of(file);
  fs::remove(file);
  EXPECT_EQ(message.rfind(file.string() + ":2:", 0), 0u) << message;
}

TEST(JsonReader, PbrtSceneFilesGoToThePbrtReader) {
  fs::path file = kSharedDir / "scenes/cornell-box/cornell-box.pbrt";
  SceneDesc scene = read_scene_file(file);
  EXPECT_FALSE(scene.shapes.empty());
  EXPECT_EQ(scene.source_file, file.string());
}

// ---------------------------------------------------------------- the paper's scenes

TEST(JsonReader, ReadsTheCowScene) {
  SceneDesc scene = read_scene_file(kSourceDir / "scenes/cow.json");
  bool has_cow = false, has_sphere_light = false;
  for (const ShapeDesc& shape : scene.shapes) {
    if (const auto* mesh = std::get_if<MeshShape>(&shape.geometry)) has_cow |= mesh->mesh.triangle_count() == 5856;
    if (std::holds_alternative<SphereShape>(shape.geometry) && shape.emission) has_sphere_light = true;
  }
  EXPECT_TRUE(has_cow);
  EXPECT_TRUE(has_sphere_light);
  EXPECT_EQ(scene.settings.spp, 64);
}

TEST(JsonReader, ReadsTheRoomScene) {
  SceneDesc scene = read_scene_file(kSourceDir / "scenes/room.json");
  bool has_phong = false;
  for (const MaterialDesc& material : scene.materials)
    if (const auto* phong = std::get_if<PhongMaterial>(&material)) has_phong |= phong->s > 0;
  EXPECT_TRUE(has_phong);
  bool has_light = false;
  for (const ShapeDesc& shape : scene.shapes) has_light |= shape.emission.has_value();
  EXPECT_TRUE(has_light);
  EXPECT_EQ(scene.settings.spp, 64);
}

// Every JSON scene shipped with the sources (scenes/, bench/scenes/) reads.
TEST(JsonReader, EveryShippedSceneReads) {
  int scenes = 0;
  for (const char* folder : {"scenes", "bench/scenes"})
    for (const auto& entry : fs::directory_iterator(kSourceDir / folder)) {
      if (entry.path().extension() != ".json") continue;
      // cloud.json reads the grid scenes/make_cloud.py writes (not shipped): VolPath.TheMediaExampleScenesRender
      // generates it and renders the scene.
      if (entry.path().filename() == "cloud.json") continue;
      // city-night.json and lamp-road.json likewise read the meshes scenes/make_city.py writes: LightBvh's
      // TheCityScene... and TheLampRoad... tests render them.
      if (entry.path().filename() == "city-night.json" || entry.path().filename() == "lamp-road.json") continue;
      EXPECT_NO_THROW(read_scene_file(entry.path())) << entry.path();
      ++scenes;
    }
  EXPECT_GE(scenes, 10);
}

// Keeps docs/scene-format.md honest: each of its json blocks is a complete scene that reads.
TEST(JsonReader, EveryExampleInTheFormatDocumentReads) {
  std::ifstream in(kSourceDir / "docs/scene-format.md");
  ASSERT_TRUE(in) << "docs/scene-format.md not found";
  std::string line, example;
  bool in_example = false;
  int examples = 0;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (!in_example && line == "```json") {
      in_example = true;
      example.clear();
    } else if (in_example && line == "```") {
      in_example = false;
      ++examples;
      // Mesh file examples are written as if the scene file were in scenes/.
      try {
        read_json_scene(example, "scene-format.md example ending on line " + std::to_string(line_number),
                        kSourceDir / "scenes");
      } catch (const SceneError& e) {
        ADD_FAILURE() << e.what();
      }
    } else if (in_example) {
      example += line + "\n";
    }
  }
  EXPECT_GE(examples, 20);
}

}  // namespace
}  // namespace candela
