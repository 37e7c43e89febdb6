#pragma once
// Helpers shared by the tests of load_mesh_file (mesh_io_test.cpp, mesh_io_ply_test.cpp,
// mesh_io_serialized_test.cpp): loading meshes and expecting errors, measures of a mesh, and the MeshIo
// fixture, whose scratch directory holds the files that tests write on the fly.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mesh_io.h"

// In a namespace of their own, like the JSON and pbrt reader tests' helpers.
namespace candela::testing::mesh_io {

namespace fs = std::filesystem;

inline const fs::path kMeshes = fs::path(CANDELA_SHARED_DIR) / "meshes";
inline const fs::path kMeshTestData = fs::path(CANDELA_SOURCE_DIR) / "tests" / "data" / "meshes";

inline const SourceLocation kWhere{"scene.json", 0, 0, "/shapes/2/file"};

inline TriangleMesh load(const fs::path& file) { return load_mesh_file(file, kWhere); }

// The message of the SceneError that loading `file` throws; fails the test if nothing is thrown.
inline std::string load_error(const fs::path& file) {
  try {
    load(file);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "loading " << file << " did not throw";
  return "";
}

inline void expect_error_mentions(const fs::path& file, const std::vector<std::string>& parts) {
  const std::string message = load_error(file);
  EXPECT_EQ(message.rfind("scene.json: at /shapes/2/file: cannot read mesh '" + file.string() + "'", 0), 0u)
      << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

inline Bounds3 bounds_of(const TriangleMesh& mesh) {
  Bounds3 bounds;
  for (const Point3& p : mesh.positions) bounds.extend(p);
  return bounds;
}

inline void expect_bounds_near(const TriangleMesh& mesh, Vec3 lo, Vec3 hi, float tolerance = 1e-4f) {
  const Bounds3 bounds = bounds_of(mesh);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(bounds.lo[axis], lo[axis], tolerance) << "axis " << axis;
    EXPECT_NEAR(bounds.hi[axis], hi[axis], tolerance) << "axis " << axis;
  }
}

inline double surface_area(const TriangleMesh& mesh) {
  double area = 0;
  for (size_t i = 0; i < mesh.indices.size(); i += 3) {
    const Point3& a = mesh.positions[mesh.indices[i]];
    const Point3& b = mesh.positions[mesh.indices[i + 1]];
    const Point3& c = mesh.positions[mesh.indices[i + 2]];
    area += 0.5 * length(cross(b - a, c - a));
  }
  return area;
}

// The triangles as position triples, each rotated to start at its smallest corner (winding kept) and
// sorted, so meshes that index the same triangles differently compare equal.
using PositionTriangle = std::array<std::array<float, 3>, 3>;
inline std::vector<PositionTriangle> triangle_set(const TriangleMesh& mesh) {
  std::vector<PositionTriangle> triangles;
  for (size_t i = 0; i < mesh.indices.size(); i += 3) {
    PositionTriangle t;
    for (int k = 0; k < 3; ++k) {
      const Point3& p = mesh.positions[mesh.indices[i + k]];
      t[k] = {p.x, p.y, p.z};
    }
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    triangles.push_back(t);
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

// What every loaded mesh must satisfy, whatever the file.
inline void expect_well_formed(const TriangleMesh& mesh) {
  ASSERT_EQ(mesh.indices.size() % 3, 0u);
  EXPECT_GT(mesh.triangle_count(), 0u);
  EXPECT_TRUE(mesh.normals.empty() || mesh.normals.size() == mesh.positions.size());
  EXPECT_TRUE(mesh.uvs.empty() || mesh.uvs.size() == mesh.positions.size());
  for (uint32_t index : mesh.indices) ASSERT_LT(index, mesh.positions.size());
  for (const Point3& p : mesh.positions) ASSERT_TRUE(is_finite(p));
}

// A scratch directory per test for files written on the fly.
class MeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("candela_mesh_io_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& contents) const {
    const fs::path file = dir_ / name;
    std::ofstream(file, std::ios::binary) << contents;
    return file;
  }
  static std::string read(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  // A fuzzer's input from fuzz/regressions/ply_reader/, copied into the scratch directory.
  fs::path fuzzed(const std::string& name) const {
    return write(name, read(fs::path(CANDELA_SOURCE_DIR) / "fuzz" / "regressions" / "ply_reader" / name));
  }

  fs::path dir_;
};

inline const std::string kPlyTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

}  // namespace candela::testing::mesh_io
