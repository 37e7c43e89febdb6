#pragma once
// Helpers shared by the tests of the JSON scene reader (json_reader_test.cpp,
// json_materials_lights_test.cpp): reading scenes from text and the messages of their errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "candela/description/scene_desc.h"

// In a namespace of their own, since the pbrt reader tests have helpers of the same names.
namespace candela::testing::json_reader {

namespace fs = std::filesystem;

inline const fs::path kSourceDir = CANDELA_SOURCE_DIR;
inline const fs::path kSharedDir = CANDELA_SHARED_DIR;

inline SceneDesc read(const std::string& text, const fs::path& base_dir = fs::current_path()) {
  return read_json_scene(text, "test.json", base_dir);
}

// The message of the SceneError that reading `text` throws; fails the test if none is thrown.
inline std::string error_of(const std::string& text, const fs::path& base_dir = fs::current_path()) {
  try {
    read(text, base_dir);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for: " << text;
  return {};
}

inline std::string scene_file_error_of(const fs::path& file) {
  try {
    read_scene_file(file);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for: " << file;
  return {};
}

// One shape in an otherwise empty scene.
inline std::string with_shape(const std::string& shape, const std::string& materials = "{}") {
  return R"({"materials": )" + materials + R"(, "shapes": [)" + shape + "]}";
}

inline std::string with_material(const std::string& material) {
  return with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"})",
                    R"({"m": )" + material + "}");
}

inline std::string with_light(const std::string& light) { return R"({"lights": [)" + light + "]}"; }

inline void expect_near(const Vec3& a, const Vec3& b, float tolerance = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

// The message for `text` contains `fragment`.
inline void expect_error_containing(const std::string& text, const std::string& fragment) {
  std::string message = error_of(text);
  EXPECT_NE(message.find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << message;
}

}  // namespace candela::testing::json_reader
