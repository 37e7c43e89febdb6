#pragma once
// Helpers shared by the tests of the pbrt-v4 reader (pbrt_reader_test.cpp, pbrt_materials_test.cpp,
// pbrt_shapes_lights_test.cpp): scratch scene files, reading scenes from lines of text, and expecting
// errors and warnings at a file:line:column.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/pbrt_reader.h"
#include "candela/description/scene_desc.h"

// In a namespace of their own, since the JSON reader tests have helpers of the same names.
namespace candela::testing::pbrt_reader {

namespace fs = std::filesystem;

inline const fs::path kSharedCornellBox = fs::path(CANDELA_SHARED_DIR) / "scenes/cornell-box/cornell-box.pbrt";
inline const fs::path kRepoCornellBox = fs::path(CANDELA_SOURCE_DIR) / "scenes/cornell-box.pbrt";
inline const fs::path kTestData = fs::path(CANDELA_SOURCE_DIR) / "tests/data/pbrt";

// The directory of the scratch scenes and files of this test process.
inline fs::path scratch_dir() { return fs::temp_directory_path() / fmt::format("candela_pbrt_reader_{}", getpid()); }

// A scene written to its own file, for the tests whose point is reading files; named after the test
// so that tests can run in parallel processes; the file is removed again when the object goes out of
// scope.
class ScratchScene {
 public:
  explicit ScratchScene(const std::vector<std::string>& lines) {
    static int counter = 0;
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path dir = scratch_dir();
    fs::create_directories(dir);
    path_ = dir / fmt::format("{}_{}.pbrt", test->name(), counter++);
    std::ofstream out(path_);
    for (const std::string& line : lines) out << line << '\n';
  }
  ScratchScene(const ScratchScene&) = delete;
  ScratchScene& operator=(const ScratchScene&) = delete;
  ~ScratchScene() {
    std::error_code ignored;
    fs::remove(path_, ignored);
    fs::remove(path_.parent_path(), ignored);  // only succeeds once the directory is empty
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// An empty file beside the scratch scenes, for parameters that name files the reader only looks up
// (images); removed again when the object goes out of scope.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& name) : path_(scratch_dir() / name) {
    fs::create_directories(path_.parent_path());
    std::ofstream out(path_);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() {
    std::error_code ignored;
    fs::remove(path_, ignored);
    fs::remove(path_.parent_path(), ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}
inline std::string joined(const Warnings& warnings) { return joined(warnings.lines()); }

// The scenes of most tests are text, read with read_pbrt_string: this is their name in messages,
// and the files they name (ScratchFile) are looked up in scratch_dir().
inline const std::string kSceneName = "scene.pbrt";

inline SceneDesc read_lines(const std::vector<std::string>& lines) {
  Warnings warnings;
  return read_pbrt_string(joined(lines), kSceneName, scratch_dir(), warnings);
}

struct Warned {
  SceneDesc scene;
  Warnings warnings;
};

inline Warned read_warned(const std::vector<std::string>& lines) {
  Warned result;
  result.scene = read_pbrt_string(joined(lines), kSceneName, scratch_dir(), result.warnings);
  return result;
}

// The message of the error `read` throws, or "" when it reads without one.
template <typename Read>
inline std::string error_of(Read read) {
  try {
    Warnings warnings;
    read(warnings);
  } catch (const SceneError& error) {
    return error.what();
  }
  return "";
}

inline std::string error_reading(const fs::path& file) {
  return error_of([&](Warnings& warnings) { read_pbrt_scene(file, warnings); });
}

inline std::string error_reading_text(const std::vector<std::string>& lines) {
  return error_of([&](Warnings& warnings) {
    read_pbrt_string(joined(lines), kSceneName, scratch_dir(), warnings);
  });
}

// Expects the scene to fail with a message that starts "<file>:<line>:<column>: ", where the column
// is that of `marker` in the line, and that contains `fragment`.
inline void expect_error(const std::vector<std::string>& lines, int line, std::string_view marker, std::string_view fragment) {
  size_t column = lines.at(line - 1).find(marker);
  ASSERT_NE(column, std::string::npos) << "marker " << marker << " is not in line " << line;
  std::string message = error_reading_text(lines);
  std::string place = fmt::format("{}:{}:{}: ", kSceneName, line, column + 1);
  EXPECT_TRUE(message.starts_with(place)) << "expected the error at " << place << "\ngot: " << message;
  EXPECT_NE(message.find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << message;
}

// Expects the scene to read with exactly one warning, "<file>:<line>:<column>: warning: ...", where
// the column is that of `marker` in the line, containing `fragment`.
inline void expect_warning(const std::vector<std::string>& lines, int line, std::string_view marker,
                    std::string_view fragment) {
  size_t column = lines.at(line - 1).find(marker);
  ASSERT_NE(column, std::string::npos) << "marker " << marker << " is not in line " << line;
  const std::vector<std::string> warnings = read_warned(lines).warnings.lines();
  ASSERT_EQ(warnings.size(), 1u) << joined(warnings);
  std::string place = fmt::format("{}:{}:{}: warning: ", kSceneName, line, column + 1);
  EXPECT_TRUE(warnings[0].starts_with(place)) << "expected the warning at " << place << "\ngot: " << warnings[0];
  EXPECT_NE(warnings[0].find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << warnings[0];
}

inline void expect_near(const Vec3& actual, const Vec3& expected, float tolerance = 1e-4f) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

inline const TriangleMesh& mesh_of(const ShapeDesc& shape) { return std::get<MeshShape>(shape.geometry).mesh; }

inline RGB reflectance_of(const SceneDesc& scene, const ShapeDesc& shape) {
  return std::get<DiffuseMaterial>(scene.materials.at(shape.material)).reflectance.value;
}

}  // namespace candela::testing::pbrt_reader
