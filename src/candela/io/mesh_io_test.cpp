#include "candela/io/mesh_io.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <zlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "candela/testing/gzip_bytes.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(CANDELA_SHARED_DIR) / "meshes";
const fs::path kMeshTestData = fs::path(CANDELA_SOURCE_DIR) / "tests" / "data" / "meshes";

const SourceLocation kWhere{"scene.json", 0, 0, "/shapes/2/file"};

TriangleMesh load(const fs::path& file) { return load_mesh_file(file, kWhere); }

// The message of the SceneError that loading `file` throws; fails the test if nothing is thrown.
std::string load_error(const fs::path& file) {
  try {
    load(file);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "loading " << file << " did not throw";
  return "";
}

void expect_error_mentions(const fs::path& file, const std::vector<std::string>& parts) {
  const std::string message = load_error(file);
  EXPECT_EQ(message.rfind("scene.json: at /shapes/2/file: cannot read mesh '" + file.string() + "'", 0), 0u)
      << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

Bounds3 bounds_of(const TriangleMesh& mesh) {
  Bounds3 bounds;
  for (const Point3& p : mesh.positions) bounds.extend(p);
  return bounds;
}

void expect_bounds_near(const TriangleMesh& mesh, Vec3 lo, Vec3 hi, float tolerance = 1e-4f) {
  const Bounds3 bounds = bounds_of(mesh);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(bounds.lo[axis], lo[axis], tolerance) << "axis " << axis;
    EXPECT_NEAR(bounds.hi[axis], hi[axis], tolerance) << "axis " << axis;
  }
}

double surface_area(const TriangleMesh& mesh) {
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
std::vector<PositionTriangle> triangle_set(const TriangleMesh& mesh) {
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
void expect_well_formed(const TriangleMesh& mesh) {
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

const std::string kPlyTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

// ---------------------------------------------------------------- OBJ files of the shared meshes

TEST_F(MeshIo, SpotObjHasAllTrianglesWithUvs) {
  const TriangleMesh spot = load(kMeshes / "spot" / "spot.obj");
  expect_well_formed(spot);
  EXPECT_EQ(spot.triangle_count(), 5856u);
  EXPECT_EQ(spot.uvs.size(), spot.positions.size());
  EXPECT_TRUE(spot.normals.empty());
  // 2,930 positions and 3,225 uvs: vertices on uv seams are split, the rest stay shared.
  EXPECT_EQ(spot.positions.size(), 3225u);
  // The uv range of the file's 'vt' lines (the texture atlas overhangs [0,1] a little).
  Vec2 uv_lo{1e9f, 1e9f}, uv_hi{-1e9f, -1e9f};
  for (const Vec2& uv : spot.uvs) {
    uv_lo = {std::min(uv_lo.x, uv.x), std::min(uv_lo.y, uv.y)};
    uv_hi = {std::max(uv_hi.x, uv.x), std::max(uv_hi.y, uv.y)};
  }
  EXPECT_FLOAT_EQ(uv_lo.x, -0.0522421f);
  EXPECT_FLOAT_EQ(uv_hi.x, 0.989055f);
  EXPECT_FLOAT_EQ(uv_lo.y, 0.111175f);
  EXPECT_FLOAT_EQ(uv_hi.y, 1.00065f);
  expect_bounds_near(spot, {-0.471552f, -0.736784f, -0.668909f}, {0.471552f, 0.953646f, 1.049f});
}

TEST_F(MeshIo, SpotQuadrangulatedObjGivesTheSameTriangleCount) {
  const TriangleMesh quads = load(kMeshes / "spot" / "spot" / "spot_quadrangulated.obj");
  const TriangleMesh triangles = load(kMeshes / "spot" / "spot" / "spot_triangulated.obj");
  EXPECT_EQ(quads.triangle_count(), 5856u);
  EXPECT_EQ(triangles.triangle_count(), 5856u);
  EXPECT_NEAR(surface_area(quads), surface_area(triangles), 1e-3 * surface_area(triangles));
}

TEST_F(MeshIo, TeapotObjKeepsSharedVertices) {
  const TriangleMesh teapot = load(kMeshes / "teapot" / "teapot.obj");
  expect_well_formed(teapot);
  EXPECT_EQ(teapot.triangle_count(), 6320u);
  EXPECT_EQ(teapot.positions.size(), 3644u);  // one vertex per 'v' line: nothing duplicated
  EXPECT_TRUE(teapot.normals.empty());
  EXPECT_TRUE(teapot.uvs.empty());
  expect_bounds_near(teapot, {-3, 0, -2}, {3.434f, 3.15f, 2});
}

// ---------------------------------------------------------------- PLY files of the shared meshes

TEST_F(MeshIo, StanfordBunnyPly) {
  const TriangleMesh bunny = load(kMeshes / "bunny" / "stanford-original" / "bun_zipper.ply");
  expect_well_formed(bunny);
  EXPECT_EQ(bunny.triangle_count(), 69451u);
  EXPECT_EQ(bunny.positions.size(), 35947u);
  EXPECT_TRUE(bunny.normals.empty());  // none in the file, and none are made up
  EXPECT_TRUE(bunny.uvs.empty());
  expect_bounds_near(bunny, {-0.0946899f, 0.0329874f, -0.0618736f}, {0.0610091f, 0.187321f, 0.0587997f}, 1e-6f);
}

TEST_F(MeshIo, StanfordBunnyLowResolutionPly) {
  const TriangleMesh bunny = load(kMeshes / "bunny" / "stanford-original" / "bun_zipper_res4.ply");
  expect_well_formed(bunny);
  EXPECT_EQ(bunny.triangle_count(), 948u);
  EXPECT_EQ(bunny.positions.size(), 453u);
  expect_bounds_near(bunny, {-0.0931466f, 0.0336204f, -0.056644f}, {0.0581591f, 0.181897f, 0.0578008f}, 1e-6f);
}

TEST_F(MeshIo, BunnyObjAndPlyHoldTheSameSurface) {
  const TriangleMesh ply = load(kMeshes / "bunny" / "stanford-original" / "bun_zipper.ply");
  const TriangleMesh obj = load(kMeshes / "bunny" / "stanford-bunny.obj");
  EXPECT_EQ(obj.triangle_count(), ply.triangle_count());
  EXPECT_NEAR(surface_area(obj), surface_area(ply), 1e-4 * surface_area(ply));
  const Bounds3 a = bounds_of(obj), b = bounds_of(ply);
  EXPECT_LT(length(a.lo - b.lo) + length(a.hi - b.hi), 1e-5f);
}

TEST_F(MeshIo, DragonPlyHasNormals) {
  const TriangleMesh dragon = load(kMeshes / "dragon" / "dragon_100k.ply");
  expect_well_formed(dragon);
  EXPECT_EQ(dragon.triangle_count(), 100000u);
  EXPECT_EQ(dragon.positions.size(), 50000u);
  ASSERT_EQ(dragon.normals.size(), dragon.positions.size());
  for (const Normal3& n : dragon.normals) ASSERT_NEAR(length(n), 1.0f, 1e-3f);
  EXPECT_TRUE(dragon.uvs.empty());
  expect_bounds_near(dragon, {-1.35294f, -0.954207f, -0.605046f}, {1.35294f, 0.954207f, 0.605046f});
}

// ---------------------------------------------------------------- Assimp's PLY test files

TEST_F(MeshIo, AsciiAndBinaryPlyGiveTheSameTriangles) {
  const TriangleMesh ascii = load(kMeshes / "ply-tests" / "cube.ply");  // quads
  const TriangleMesh binary = load(kMeshes / "ply-tests" / "cube_binary.ply");  // triangles
  expect_well_formed(ascii);
  expect_well_formed(binary);
  EXPECT_EQ(ascii.triangle_count(), 12u);
  EXPECT_EQ(binary.triangle_count(), 12u);
  EXPECT_EQ(triangle_set(ascii), triangle_set(binary));
}

TEST_F(MeshIo, PlyQuadsBecomeTwoTrianglesEach) {
  const TriangleMesh cube = load(kMeshes / "ply-tests" / "cube.ply");
  EXPECT_EQ(cube.triangle_count(), 2u * 6u);
  EXPECT_EQ(cube.positions.size(), 8u);
  EXPECT_NEAR(surface_area(cube), 6.0, 1e-6);
  expect_bounds_near(cube, {0, 0, 0}, {1, 1, 1}, 0);
}

TEST_F(MeshIo, PlyUvsAndNormalsAreRead) {
  const TriangleMesh cube = load(kMeshes / "ply-tests" / "cube_uv.ply");
  expect_well_formed(cube);
  EXPECT_EQ(cube.triangle_count(), 12u);
  ASSERT_EQ(cube.positions.size(), 24u);
  ASSERT_EQ(cube.uvs.size(), 24u);
  ASSERT_EQ(cube.normals.size(), 24u);
  // The first vertices as written in the file: u, v = s, t, not flipped.
  EXPECT_EQ(cube.positions[0], Vec3(1, 1, -1));
  EXPECT_EQ(cube.normals[0], Vec3(0, 0, -1));
  EXPECT_EQ(cube.uvs[0].x, 0.0f);
  EXPECT_EQ(cube.uvs[0].y, 0.0f);
  EXPECT_EQ(cube.uvs[2].x, 1.0f);
  EXPECT_EQ(cube.uvs[2].y, 1.0f);
  EXPECT_NEAR(surface_area(cube), 24.0, 1e-4);

  const TriangleMesh wuson = load(kMeshes / "ply-tests" / "Wuson.ply");
  expect_well_formed(wuson);
  EXPECT_EQ(wuson.triangle_count(), 3732u);
  EXPECT_EQ(wuson.uvs.size(), wuson.positions.size());
  EXPECT_EQ(wuson.normals.size(), wuson.positions.size());
}

TEST_F(MeshIo, PlyColoursBecomeAColorAttribute) {
  const TriangleMesh triangle = load(kMeshes / "ply-tests" / "float-color.ply");
  ASSERT_EQ(triangle.triangle_count(), 1u);
  ASSERT_EQ(triangle.positions.size(), 3u);
  EXPECT_EQ(triangle.positions[triangle.indices[0]], Vec3(0, 0, 0));
  EXPECT_EQ(triangle.positions[triangle.indices[1]], Vec3(100, 0, 0));
  EXPECT_EQ(triangle.positions[triangle.indices[2]], Vec3(200, 200, 0));
  EXPECT_TRUE(triangle.normals.empty());
  EXPECT_TRUE(triangle.uvs.empty());
  ASSERT_EQ(triangle.attributes.size(), 2u);  // red green blue, and alpha on its own
  EXPECT_EQ(triangle.attributes[0].name, "color");
  EXPECT_FALSE(triangle.attributes[0].per_face);
  EXPECT_EQ(triangle.attributes[0].channels, 3);
  EXPECT_EQ(triangle.attributes[0].values, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}));
  EXPECT_EQ(triangle.attributes[1].name, "alpha");
  EXPECT_EQ(triangle.attributes[1].channels, 1);
}

TEST_F(MeshIo, PlyExtraPropertiesBecomeAttributesInFileOrder) {
  // Vertex and face properties beyond the geometry, ASCII and big-endian binary alike: name_0..2
  // group into 3 channels, a lone property is one channel, a quad's value goes to both triangles.
  const std::string header_tail =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\n"
      "property float weight\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face 1\nproperty list uchar int vertex_indices\nproperty float tint_0\nproperty float tint_1\n"
      "property float tint_2\nproperty short id\nend_header\n";
  const std::string ascii = "ply\nformat ascii 1.0\n" + header_tail +
                            "0 0 0 0 0 0.5 255 0 0\n1 0 0 1 0 1.5 0 255 0\n\n1 1 0 1 1 2.5 0 0 255 7\n"
                            "0 1 0 0 1 3.5 1 2 3\n4 0 1 2 3 0.25 0.5 0.75 -12\n";
  std::string binary = "ply\nformat binary_big_endian 1.0\n" + header_tail;
  auto put = [&](auto value) {
    auto bits = std::bit_cast<std::array<char, sizeof value>>(value);
    std::reverse(bits.begin(), bits.end());
    binary.append(bits.data(), bits.size());
  };
  const float positions[4][6] = {{0, 0, 0, 0, 0, 0.5f}, {1, 0, 0, 1, 0, 1.5f}, {1, 1, 0, 1, 1, 2.5f}, {0, 1, 0, 0, 1, 3.5f}};
  const uint8_t colours[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {1, 2, 3}};
  for (int i = 0; i < 4; ++i) {
    for (float f : positions[i]) put(f);
    for (uint8_t c : colours[i]) put(c);
  }
  put(uint8_t(4));
  for (int32_t i : {0, 1, 2, 3}) put(i);
  for (float f : {0.25f, 0.5f, 0.75f}) put(f);
  put(int16_t(-12));
  for (const std::string& contents : {ascii, binary}) {
    const TriangleMesh mesh = load(write("attributes.ply", contents));
    ASSERT_EQ(mesh.triangle_count(), 2u);
    EXPECT_EQ(mesh.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(mesh.positions[2], Vec3(1, 1, 0));
    ASSERT_EQ(mesh.uvs.size(), 4u);
    EXPECT_EQ(mesh.uvs[3].y, 1.0f);
    ASSERT_EQ(mesh.attributes.size(), 4u);
    EXPECT_EQ(mesh.attributes[0].name, "weight");
    EXPECT_EQ(mesh.attributes[0].values, (std::vector<float>{0.5f, 1.5f, 2.5f, 3.5f}));
    EXPECT_EQ(mesh.attributes[1].name, "color");
    EXPECT_EQ(mesh.attributes[1].channels, 3);
    EXPECT_EQ(mesh.attributes[1].values[11], 3.0f);
    EXPECT_EQ(mesh.attributes[2].name, "tint");
    EXPECT_TRUE(mesh.attributes[2].per_face);
    EXPECT_EQ(mesh.attributes[2].values, (std::vector<float>{0.25f, 0.5f, 0.75f, 0.25f, 0.5f, 0.75f}));
    EXPECT_EQ(mesh.attributes[3].name, "id");
    EXPECT_EQ(mesh.attributes[3].values, (std::vector<float>{-12, -12}));
  }
}

TEST_F(MeshIo, PlyPointCloudHasNoTriangles) {
  expect_error_mentions(kMeshes / "ply-tests" / "points.ply", {"no triangles", "4 'vertex'"});
}

TEST_F(MeshIo, TruncatedPlyIsAnError) {
  // pond.0.ply declares 70,051 vertices of 31 bytes but holds 69 bytes less than that.
  expect_error_mentions(kMeshes / "ply-tests" / "pond.0.ply", {"truncated PLY", "70048 of the 70051 'vertex'"});
}

TEST_F(MeshIo, MalformedPlyIsAnError) {
  // issue623.ply declares a list property on its vertices that the vertex lines do not hold.
  expect_error_mentions(kMeshes / "ply-tests" / "issue623.ply", {"malformed PLY", "line 13", "'vertex'"});
}

// ---------------------------------------------------------------- OBJ test data of this repository

TEST_F(MeshIo, ObjQuadsWithNormalsAndUvs) {
  const TriangleMesh cube = load(kMeshTestData / "cube_quads_normals.obj");  // its .mtl is missing
  expect_well_formed(cube);
  EXPECT_EQ(cube.triangle_count(), 12u);  // both objects of the file, in one mesh
  // Each corner differs from the others in normal or uv: 6 faces x 4 corners.
  ASSERT_EQ(cube.positions.size(), 24u);
  ASSERT_EQ(cube.normals.size(), 24u);
  ASSERT_EQ(cube.uvs.size(), 24u);
  EXPECT_NEAR(surface_area(cube), 6.0, 1e-6);
  expect_bounds_near(cube, {0, 0, 0}, {1, 1, 1}, 0);
  // Winding and normals agree: counter-clockwise seen from outside.
  for (size_t i = 0; i < cube.indices.size(); i += 3) {
    const Point3& a = cube.positions[cube.indices[i]];
    const Vec3 geometric = normalize(cross(cube.positions[cube.indices[i + 1]] - a, cube.positions[cube.indices[i + 2]] - a));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(dot(geometric, cube.normals[cube.indices[i + k]]), 1.0f, 1e-6f);
  }
}

TEST_F(MeshIo, MalformedObjIsAnError) {
  expect_error_mentions(kMeshTestData / "malformed.obj", {"malformed OBJ", "line 5"});
}

TEST_F(MeshIo, ObjIndexOutOfRangeIsAnError) {
  expect_error_mentions(kMeshTestData / "index_out_of_range.obj", {"malformed OBJ", "face 2", "vertex 9", "4 of them"});
}

// ---------------------------------------------------------------- OBJ cases written on the fly

TEST_F(MeshIo, ObjPolygonsAreTriangulated) {
  const TriangleMesh pentagon = load(write("pentagon.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\nf 1 2 3 4 5\n"));
  EXPECT_EQ(pentagon.triangle_count(), 3u);
  EXPECT_EQ(pentagon.positions.size(), 5u);
  EXPECT_NEAR(surface_area(pentagon), 1.25, 1e-6);
}

TEST_F(MeshIo, ObjNormalsOnSomeCornersOnlyAreDropped) {
  const TriangleMesh mesh =
      load(write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n"));
  EXPECT_EQ(mesh.triangle_count(), 2u);
  EXPECT_TRUE(mesh.normals.empty());
  EXPECT_EQ(mesh.positions.size(), 4u);  // dropped normals do not split the shared vertices
}

TEST_F(MeshIo, ObjRelativeIndicesWork) {
  const TriangleMesh mesh = load(write("relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"));
  ASSERT_EQ(mesh.triangle_count(), 1u);
  EXPECT_EQ(mesh.positions[mesh.indices[1]], Vec3(1, 0, 0));
}

TEST_F(MeshIo, ObjIndicesOutOfRangeAreAnError) {
  expect_error_mentions(write("before_first.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -5 1 2\n"),
                        {"malformed OBJ", "before the first one"});
  // tinyobjloader drops such a quad with only a warning.
  expect_error_mentions(write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 7\n"),
                        {"malformed OBJ", "out of bounds"});
  expect_error_mentions(write("uv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n"),
                        {"texture coordinate 2"});
  expect_error_mentions(write("normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//3\n"),
                        {"normal 3"});
}

// Indices near and beyond 2^31 (docs/reliability.md, "Hostile inputs"): tinyobjloader would wrap them
// around, 2^31 to an index before the first vertex and 10^20 to a valid one.
TEST_F(MeshIo, ObjFaceIndicesNearTwoToThe31AreAnError) {
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n";
  expect_error_mentions(write("max.obj", vertices + "f 1 2 2147483647\n"),
                        {"malformed OBJ", "face 1 refers to vertex 2147483647 but the file has 3 of them"});
  for (const char* index : {"2147483648", "-2147483648", "99999999999999999999", "-99999999999999999999"})
    expect_error_mentions(write("beyond.obj", vertices + "f 1 2 " + index + "\n"),
                          {"malformed OBJ: line 5: face index '" + std::string(index) +
                           "' is out of range (at most 2147483647 in size)"});
  expect_error_mentions(write("uv.obj", vertices + "f 1/1 2/1 3/4294967296\n"), {"line 5", "'4294967296'"});
  expect_error_mentions(write("normal.obj", vertices + "f 1//1 2//1 3//2147483648\n"), {"line 5", "'2147483648'"});
}

TEST_F(MeshIo, ObjNonFiniteCoordinatesAreAnError) {
  expect_error_mentions(write("nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"), {"line 2", "'nan'"});
  expect_error_mentions(write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"), {"line 3", "'-inf'"});
  expect_error_mentions(write("overflow.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n"),
                        {"non-finite position"});
  expect_error_mentions(write("normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 NaN\nf 1//1 2//1 3//1\n"),
                        {"'NaN'"});
}

TEST_F(MeshIo, ObjVertexWithMissingCoordinatesIsAnError) {
  expect_error_mentions(write("short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"),
                        {"line 2", "a 'v' line needs 3 numbers, it has 2"});
}

TEST_F(MeshIo, ObjWithoutFacesIsAnError) {
  expect_error_mentions(write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\nl 1 2\n"), {"no triangles"});
  expect_error_mentions(write("empty.obj", ""), {"no triangles"});
  expect_error_mentions(write("binary.obj", std::string("\x7f" "ELF\x02\x01\x01\0\0\0", 10)), {"no triangles"});
}

// ---------------------------------------------------------------- PLY cases written on the fly

TEST_F(MeshIo, BigEndianPlyGivesTheSameTriangles) {
  // cube_binary.ply rewritten big-endian: 8 vertices of 3 floats, 12 faces of a uchar and 3 ints.
  const std::string little = read(kMeshes / "ply-tests" / "cube_binary.ply");
  const size_t data = little.find("end_header\n") + 11;
  std::string big = little.substr(0, data);
  big.replace(big.find("binary_little_endian"), 20, "binary_big_endian");
  const auto append_reversed = [&](size_t at, size_t bytes) {
    for (size_t k = bytes; k-- > 0;) big += little[at + k];
  };
  for (size_t v = 0; v < 24; ++v) append_reversed(data + 4 * v, 4);
  for (size_t f = 0; f < 12; ++f) {
    const size_t at = data + 96 + 13 * f;
    big += little[at];
    for (size_t k = 0; k < 3; ++k) append_reversed(at + 1 + 4 * k, 4);
  }
  ASSERT_EQ(big.size(), little.size() - 3);  // "little" -> "big" in the format line
  EXPECT_EQ(triangle_set(load(write("cube_be.ply", big))),
            triangle_set(load(kMeshes / "ply-tests" / "cube_binary.ply")));
}

TEST_F(MeshIo, PlyHeaderClaimingBillionsOfElementsFailsFast) {
  const auto start = std::chrono::steady_clock::now();
  expect_error_mentions(write("huge_binary.ply",
                              "ply\nformat binary_little_endian 1.0\nelement vertex 3000000000\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 1\n"
                              "property list uchar int vertex_indices\nend_header\n" +
                                  std::string(100, '\0')),
                        {"corrupt PLY header", "3000000000 'vertex'", "100 bytes"});
  expect_error_mentions(write("huge_faces.ply",
                              "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 4294967295\n"
                              "property list uchar int vertex_indices\nend_header\n" +
                                  std::string(36, '\0') + std::string(13 * 2, '\3')),
                        {"4294967295 'face'"});
  expect_error_mentions(write("huge_ascii.ply",
                              "ply\nformat ascii 1.0\nelement vertex 18446744073709551615\nproperty float x\n"
                              "property float y\nproperty float z\nend_header\n0 0 0\n"),
                        {"18446744073709551615 'vertex'"});
  expect_error_mentions(write("overflow.ply",
                              "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\n"
                              "end_header\n0\n"),
                        {"invalid count"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

// Resource limits (docs/reliability.md): a header claiming 2^32 - 1 vertices in a small file is refused
// before anything is allocated for them, with a message naming the file and the element, in ASCII
// and binary files and when the count is only too big for the data that follows the earlier elements.
// Run in a child process whose address space is capped at 256 MiB more than it uses: an attempt to
// allocate for the declared counts would fail there with "out of memory" instead.
TEST_F(MeshIo, PlyHeaderClaimingFourBillionVerticesIsRefusedWithoutAllocating) {
  const std::string vertices = "element vertex 4294967295\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const fs::path ascii = write("four_billion_ascii.ply", "ply\nformat ascii 1.0\n" + vertices + faces +
                                                             "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const fs::path binary = write("four_billion_binary.ply", "ply\nformat binary_little_endian 1.0\n" + vertices +
                                                               faces + std::string(36 + 13, '\0'));
  // The 3 vertices fit, but 4 million faces do not fit in the 26 bytes of data.
  const fs::path cumulative =
      write("cumulative.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 4000000\nproperty list uchar int vertex_indices\n"
                              "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const auto start = std::chrono::steady_clock::now();
  expect_error_mentions(ascii, {"corrupt PLY header", "4294967295 'vertex'", "ASCII"});
  expect_error_mentions(binary, {"corrupt PLY header", "4294967295 'vertex'", "49 bytes"});
  expect_error_mentions(cumulative, {"corrupt PLY header", "4000000 'face'"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));

  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    long vm_kb = 0;
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmSize:", 0) == 0) vm_kb = std::stol(line.substr(7));
    const rlimit cap{rlim_t(vm_kb) * 1024 + (rlim_t(256) << 20), rlim_t(vm_kb) * 1024 + (rlim_t(256) << 20)};
    if (vm_kb == 0 || setrlimit(RLIMIT_AS, &cap) != 0) _exit(3);
    for (const fs::path& file : {ascii, binary}) {
      try {
        load_mesh_file(file, kWhere);
        _exit(1);
      } catch (const SceneError& e) {
        if (std::string(e.what()).find("corrupt PLY header") == std::string::npos) _exit(2);
      }
    }
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: loaded; 2: another error (out of memory?); 3: no rlimit";
}

TEST_F(MeshIo, PlyCutShortAnywhereIsAnErrorNotACrash) {
  // Assimp alone loops forever on a header without "end_header" and reads past the end of (or
  // asserts on) data cut short; every prefix must either load completely or fail with a SceneError.
  for (const char* name : {"cube_binary.ply", "cube_uv.ply", "cube.ply"}) {
    const std::string whole = read(kMeshes / "ply-tests" / name);
    const TriangleMesh complete = load(kMeshes / "ply-tests" / name);
    for (size_t cut = 0; cut < whole.size(); ++cut) {
      const fs::path file = write("cut.ply", whole.substr(0, cut));
      try {
        const TriangleMesh mesh = load(file);
        EXPECT_EQ(triangle_set(mesh), triangle_set(complete)) << name << " cut at " << cut;
      } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("PLY"), std::string::npos) << e.what();
      }
    }
  }
}

TEST_F(MeshIo, PlyBadFaceIndexIsAnError) {
  expect_error_mentions(write("index.ply", kPlyTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
                        {"malformed PLY", "refers to vertex 3", "3 vertices"});
  // Out of range in a polygon: triangulating it would read outside the vertices.
  expect_error_mentions(write("polygon.ply", kPlyTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n5 0 1 2 1000000 2000000\n"),
                        {"refers to vertex 1000000"});
}

TEST_F(MeshIo, PlyNonFiniteCoordinatesAreAnError) {
  expect_error_mentions(write("nan.ply", kPlyTriangleHeader + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
                        {"line 11", "'nan' is not a finite number"});
  expect_error_mentions(write("inf.ply", kPlyTriangleHeader + "0 0 0\n1 0 0\n0 1e999 0\n3 0 1 2\n"),
                        {"vertex 2", "non-finite position"});
}

TEST_F(MeshIo, PlyGarbageInPlaceOfANumberIsShownPrintably) {
  expect_error_mentions(write("garbage.ply", kPlyTriangleHeader + "0 0 0\n1 \x01\xff 0\n0 1 0\n3 0 1 2\n"),
                        {"line 11", "'\?\?' is not a finite number"});
}

TEST_F(MeshIo, PlyWithoutUsableFacesOrCoordinatesIsAnError) {
  const std::string vertices = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n";
  const std::string data = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
  expect_error_mentions(write("no_z.ply", vertices + "element face 1\nproperty list uchar int vertex_indices\n"
                                                     "end_header\n0 0\n1 0\n0 1\n1 1\n3 0 1 2\n"),
                        {"lacks an x, y or z"});
  expect_error_mentions(write("no_indices.ply", vertices + "property float z\nelement face 1\nproperty uchar n\n"
                                                           "end_header\n" + data + "3\n"),
                        {"no triangles", "4 'vertex', 1 'face'"});
  expect_error_mentions(write("strips.ply", vertices + "property float z\nelement tristrips 1\n"
                                                       "property list int int vertex_indices\nproperty int id\n"
                                                       "end_header\n" + data + "5 0 1 2 3 -1 7\n"),
                        {"'tristrips' element must hold one list"});
}

// Triangle strips (the Igea scan's layout): -1 ends a strip; every other triangle is reversed so that
// all keep the strip's orientation (the normals of a planar strip agree); degenerate joints are dropped.
TEST_F(MeshIo, PlyTriangleStripsBecomeConsistentlyWoundTriangles) {
  const std::string vertices = "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
                               "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n"
                               "0 0 0\n0 1 0\n1 0 0\n1 1 0\n2 0 0\n2 1 0\n";
  // Strip 0 1 2 3 4 (three triangles), strip 5 4 3 (one), and 2 2 3: degenerate, dropped.
  const TriangleMesh ascii = load(write("strips.ply", vertices + "14 0 1 2 3 4 -1 5 4 3 -1 2 2 3 -1\n"));
  ASSERT_EQ(ascii.triangle_count(), 4u);
  for (size_t t = 0; t < ascii.triangle_count(); ++t) {
    const Point3 &a = ascii.positions[ascii.indices[3 * t]], &b = ascii.positions[ascii.indices[3 * t + 1]],
                 &c = ascii.positions[ascii.indices[3 * t + 2]];
    EXPECT_LT(cross(b - a, c - a).z, 0) << "triangle " << t << " is wound against the strip";
  }
  // The same strips in a big-endian binary file give the same triangles.
  std::string binary = "ply\nformat binary_big_endian 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
                       "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  auto put_u32 = [&](uint32_t u) {
    for (int k = 3; k >= 0; --k) binary += char((u >> (8 * k)) & 0xff);
  };
  const float xyz[6][3] = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  for (const auto& v : xyz)
    for (float f : v) {
      uint32_t u;
      std::memcpy(&u, &f, 4);
      put_u32(u);
    }
  const int list[] = {0, 1, 2, 3, 4, -1, 5, 4, 3, -1, 2, 2, 3, -1};
  put_u32(14);
  for (int i : list) put_u32(uint32_t(i));
  const TriangleMesh big = load(write("strips_be.ply", binary));
  EXPECT_EQ(big.indices, ascii.indices);
}

TEST_F(MeshIo, IgeaScanReadsAllItsStripTriangles) {
  const TriangleMesh igea = load(kMeshes / "igea/igea.ply");
  EXPECT_EQ(igea.triangle_count(), 268686u);  // as the shared README counts them
  EXPECT_EQ(igea.positions.size(), 134345u);
}

TEST_F(MeshIo, PlyMalformedHeaderIsAnError) {
  expect_error_mentions(write("magic.ply", "solid cube\nfacet normal 0 0 1\n"), {"does not start with 'ply'"});
  expect_error_mentions(write("format.ply", "ply\nformat json 1.0\nend_header\n"), {"unknown format"});
  expect_error_mentions(write("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion q\nend_header\n1\n"),
                        {"unknown property type 'quaternion'"});
  expect_error_mentions(write("no_end.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
                        {"no 'end_header'"});
  // An empty element without properties is harmless; a non-empty one is not.
  const std::string cube = read(kMeshes / "ply-tests" / "cube_binary.ply");
  const size_t first_element = cube.find("element");
  const std::string with_empty_element =
      cube.substr(0, first_element) + "element nothing 0\n" + cube.substr(first_element);
  EXPECT_EQ(load(write("empty_element.ply", with_empty_element)).triangle_count(), 12u);
  expect_error_mentions(write("bare_element.ply", "ply\nformat ascii 1.0\nelement nothing 5\nend_header\n"),
                        {"element 'nothing' has no properties"});
}

// Found by fuzz/ply_reader_fuzz.cpp (docs/reliability.md): headers that Assimp reads differently
// from the checks here, which made it leak. The fuzzer's inputs are in fuzz/regressions/ply_reader/.
TEST_F(MeshIo, PlyWithTwoFormatLinesIsAnError) {
  expect_error_mentions(write("two_formats.ply", "ply\nformat ascii 1.0\nformat binary_little_endian 1.0\n" +
                                                     kPlyTriangleHeader.substr(kPlyTriangleHeader.find("element")) +
                                                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                        {"more than one format line"});
  expect_error_mentions(fuzzed("leak-second-format-line.ply"), {"malformed PLY"});
}

TEST_F(MeshIo, PlyElementDeclaredTwiceIsAnError) {
  expect_error_mentions(write("two_faces.ply", kPlyTriangleHeader.substr(0, kPlyTriangleHeader.find("end_header")) +
                                                   "element face 1\nproperty list uchar int vertex_indices\n"
                                                   "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n"),
                        {"element 'face' is declared twice"});
  // (This file also has a stray "endian 1.0" line, now refused first.)
  expect_error_mentions(fuzzed("leak-duplicate-elements.ply"), {"malformed PLY"});
}

TEST_F(MeshIo, PlyElementNameMustStartWithALetter) {
  expect_error_mentions(write("digits.ply", "ply\nformat ascii 1.0\nelement 22222222222222222222 1\n"
                                            "property float x\nend_header\n0\n"),
                        {"element name '22222222222222222222' does not start with a letter"});
  expect_error_mentions(fuzzed("oom-numeric-element-name.ply"),
                        {"does not start with a letter"});
}

TEST_F(MeshIo, PlyWithoutAVertexElementIsAnError) {
  expect_error_mentions(write("novertex.ply", "ply\nformat ascii 1.0\nelement point 1\nproperty float x\n"
                                              "property float y\nproperty float z\nend_header\n0 0 0\n"),
                        {"declares no 'vertex' element"});
  expect_error_mentions(fuzzed("oom-no-vertex-element.ply"),
                        {"declares no 'vertex' element"});
}

TEST_F(MeshIo, PlyControlBytesInTheHeaderAreAnError) {
  expect_error_mentions(write("cr.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                        "property float y\nproperty float z\n\r\r\rend_header\n0 0 0\n"),
                        {"header line 7 has a carriage return inside it"});
  expect_error_mentions(fuzzed("segv-carriage-returns-before-end-header.ply"),
                        {"carriage return"});
  using namespace std::string_literals;
  expect_error_mentions(write("nul.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\0y\n"
                                         "property float y\nproperty float z\nend_header\n0 0 0\n"s),
                        {"header line 4 has a control byte (0x00) in it"});
  expect_error_mentions(fuzzed("oom-nul-in-header.ply"), {"control byte"});
  // CRLF line ends are fine.
  EXPECT_EQ(load(write("crlf.ply", "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\n"
                                   "property float y\r\nproperty float z\r\nelement face 1\r\n"
                                   "property list uchar int vertex_indices\r\nend_header\r\n"
                                   "0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n"))
                .triangle_count(),
            1u);
}

TEST_F(MeshIo, PlyCarriageReturnInsideADataLineIsAnError) {
  // Assimp would end the record there and read the rest as the next one (found by the fuzzer: a
  // 30-digit "list length" and a 14 GB allocation).
  expect_error_mentions(write("cr.ply", kPlyTriangleHeader + "0 0 0\n1 0 0\r0666666666666666 1 0\n0 1 0\n3 0 1 2\n"),
                        {"malformed PLY: line 11 has a carriage return inside it"});
  // At the end of a line (CRLF files) it is fine.
  EXPECT_EQ(load(write("crlf.ply", kPlyTriangleHeader + "0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n")).triangle_count(), 1u);
}

TEST_F(MeshIo, PlyUnrecognisedLineInsideAnElementIsAnError) {
  expect_error_mentions(write("garbled.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                             "propeofy ltrat ny\nproperty float y\nproperty float z\n"
                                             "end_header\n0 0 0\n"),
                        {"unrecognised header line 'propeofy ltrat ny' after element 'vertex'"});
  expect_error_mentions(fuzzed("oom-unrecognised-header-line.ply"),
                        {"unrecognised header line"});
  // Before the first element, a stray line (Blender 2.4's broken comment) is still skipped.
  const fs::path wuson = kMeshes / "ply-tests" / "Wuson.ply";
  if (fs::exists(wuson)) {
    EXPECT_GT(load(wuson).triangle_count(), 0u);
  }
}

// ---------------------------------------------------------------- file names and places

// pbrt-v4's "mesh.ply.gz": decompressed whole (io/gzip.h, whose tests hold the limit), then read by its
// format's reader; a damaged one is an error naming the mesh.
TEST_F(MeshIo, GzippedMeshesAreDecompressedFirst) {
  const std::string ply = kPlyTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(triangle_set(load(write("triangle.ply.gz", testing::gzip_bytes(ply)))),
            triangle_set(load(write("triangle.ply", ply))));
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  EXPECT_EQ(load(write("triangle.OBJ.GZ", testing::gzip_bytes(obj))).triangle_count(), 1u);
  const std::string gzipped = testing::gzip_bytes(ply);
  expect_error_mentions(write("cut.ply.gz", gzipped.substr(0, gzipped.size() / 2)),
                        {"cut.ply.gz': gzip: the compressed data is cut short"});
  expect_error_mentions(write("bomb.ply.gz", testing::gzip_bomb(1025)),
                        {"bomb.ply.gz': gzip: it decompresses to more than 1.0 GiB, the limit for a gzipped file"});
}

TEST_F(MeshIo, MissingFileNamesBothPlaces) {
  const fs::path missing = kMeshTestData / "no_such_mesh.obj";
  EXPECT_EQ(load_error(missing), "scene.json: at /shapes/2/file: cannot read mesh '" + missing.string() + "': no such file");
  const SourceLocation pbrt{"scene.pbrt", 12, 5, ""};
  try {
    load_mesh_file("meshes/cow.ply", pbrt);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(), "scene.pbrt:12:5: cannot read mesh 'meshes/cow.ply': no such file");
  }
}

TEST_F(MeshIo, UnsupportedExtensionListsTheSupportedOnes) {
  expect_error_mentions(kMeshTestData / "cow.stl", {"unsupported mesh format '.stl'", ".obj", ".ply"});
  expect_error_mentions(kMeshTestData / "cow", {"no extension", ".obj", ".ply"});
}

TEST_F(MeshIo, DirectoryNamedLikeAMeshIsAnError) {
  fs::create_directory(dir_ / "folder.obj");
  expect_error_mentions(dir_ / "folder.obj", {"directory"});
}

TEST_F(MeshIo, ExtensionIsMatchedIgnoringCase) {
  EXPECT_EQ(load(write("TRIANGLE.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).triangle_count(), 1u);
  EXPECT_EQ(load(write("Cube.Ply", read(kMeshes / "ply-tests" / "cube.ply"))).triangle_count(), 12u);
}

// ---------------------------------------------------------------- Mitsuba .serialized

const fs::path kMatpreview = fs::path(CANDELA_SHARED_DIR) / "scenes/mitsuba-tests/common/meshes/matpreview.serialized";

TEST_F(MeshIo, SerializedMeshesOfMitsubasMatpreview) {
  // The file holds three meshes (version 3, single precision, normals and uvs); their counts, as a
  // independent reading with Python's zlib gives them.
  const size_t vertices[] = {289, 2078, 29439}, triangles[] = {512, 3936, 57152};
  for (int index = 0; index < 3; ++index) {
    TriangleMesh mesh = load_mesh_file(kMatpreview, kWhere, index);
    expect_well_formed(mesh);
    EXPECT_EQ(mesh.positions.size(), vertices[index]) << index;
    EXPECT_EQ(mesh.triangle_count(), triangles[index]) << index;
    EXPECT_EQ(mesh.normals.size(), vertices[index]);
    EXPECT_EQ(mesh.uvs.size(), vertices[index]);
    for (const Normal3& n : mesh.normals) ASSERT_NEAR(length(n), 1.0f, 1e-3f);
  }
  EXPECT_EQ(load(kMatpreview).triangle_count(), 512u);  // shape 0 when the scene names none
}

// A .serialized file written here: the given meshes' zlib streams, then the table of offsets.
std::string serialized_file(const std::vector<std::string>& raw_meshes, uint16_t version) {
  std::string file;
  std::vector<uint64_t> offsets;
  for (const std::string& raw : raw_meshes) {
    offsets.push_back(file.size());
    file += std::string("\x1c\x04", 2);
    file += char(version & 0xff);
    file += char(version >> 8);
    uLongf size = compressBound(uLong(raw.size()));
    std::string packed(size, '\0');
    EXPECT_EQ(compress(reinterpret_cast<Bytef*>(packed.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                       uLong(raw.size())),
              Z_OK);
    file += packed.substr(0, size);
  }
  auto put = [&](uint64_t v, int bytes) {
    for (int k = 0; k < bytes; ++k) file += char((v >> (8 * k)) & 0xff);
  };
  for (uint64_t o : offsets) put(o, version == 3 ? 4 : 8);
  put(raw_meshes.size(), 4);
  return file;
}

template <typename T>
void append(std::string& raw, T value) {
  raw.append(reinterpret_cast<const char*>(&value), sizeof value);  // little-endian machine
}

TEST_F(MeshIo, SerializedVersion4WithNameDoublesColoursAndFaceNormals) {
  std::string raw;
  append<uint32_t>(raw, 0x1 | 0x2 | 0x8 | 0x10 | 0x2000);  // normals, uvs, colours, face normals, doubles
  raw += std::string("triangle\0", 9);
  append<uint64_t>(raw, 3);
  append<uint64_t>(raw, 1);
  for (double v : {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 2.0, 0.0}) append(raw, v);       // positions
  for (int i = 0; i < 3; ++i) for (double v : {0.0, 0.0, 1.0}) append(raw, v);        // normals
  for (double v : {0.0, 0.0, 1.0, 0.0, 0.0, 1.0}) append(raw, v);                      // uvs
  for (double v : {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}) append(raw, v);       // colours
  for (uint32_t i : {0u, 1u, 2u}) append(raw, i);
  std::string empty_first;  // a first mesh, so that index 1 has to be found through the table
  append<uint32_t>(empty_first, 0x1000);
  empty_first += std::string("\0", 1);
  append<uint64_t>(empty_first, 3);
  append<uint64_t>(empty_first, 1);
  for (float v : {0.f, 0.f, 0.f, 5.f, 0.f, 0.f, 0.f, 5.f, 0.f}) append(empty_first, v);
  for (uint32_t i : {0u, 2u, 1u}) append(empty_first, i);
  const fs::path file = write("two.serialized", serialized_file({empty_first, raw}, 4));

  TriangleMesh first = load_mesh_file(file, kWhere, 0);
  EXPECT_EQ(first.positions[1], Point3(5, 0, 0));
  EXPECT_EQ(first.indices, (std::vector<uint32_t>{0, 2, 1}));
  TriangleMesh mesh = load_mesh_file(file, kWhere, 1);
  ASSERT_EQ(mesh.positions.size(), 3u);
  EXPECT_EQ(mesh.positions[2], Point3(0, 2, 0));
  EXPECT_TRUE(mesh.normals.empty());  // face normals asked for: flat shading
  ASSERT_EQ(mesh.uvs.size(), 3u);
  EXPECT_EQ(mesh.uvs[1].x, 1.0f);
  EXPECT_EQ(mesh.uvs[1].y, 0.0f);
  ASSERT_EQ(mesh.attributes.size(), 1u);
  EXPECT_EQ(mesh.attributes[0].name, "color");
  EXPECT_EQ(mesh.attributes[0].channels, 3);
  EXPECT_FLOAT_EQ(mesh.attributes[0].values[4], 0.5f);
  EXPECT_EQ(mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST_F(MeshIo, SerializedErrorsAreClear) {
  auto error = [&](const fs::path& file, int index) -> std::string {
    try {
      load_mesh_file(file, kWhere, index);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(error(kMatpreview, 3).find("shape_index 3 is out of range: the file holds 3 meshes"), std::string::npos);
  EXPECT_NE(error(kMatpreview, -1).find("out of range"), std::string::npos);
  EXPECT_NE(error(write("x.serialized", "ply\nformat ascii 1.0\n"), 0).find("not a Mitsuba .serialized file"),
            std::string::npos);
  // Cut short anywhere: the table, the stream or the data end early; never a crash.
  const std::string whole = read(kMatpreview);
  for (size_t cut : {size_t(6), size_t(5000), size_t(60000), whole.size() / 2, whole.size() - 3}) {
    const std::string message = error(write("cut.serialized", whole.substr(0, cut)), 0);
    EXPECT_NE(message.find("cannot read mesh"), std::string::npos) << cut << ": " << message;
  }
  // The table intact but a stream damaged.
  std::string damaged = whole;
  for (size_t i = 100; i < 200; ++i) damaged[i] = char(~damaged[i]);
  EXPECT_NE(error(write("damaged.serialized", damaged), 0).find("cannot read mesh"), std::string::npos);
  // Counts that promise more than the stream holds.
  std::string raw;
  append<uint32_t>(raw, 0x1000);
  append<uint64_t>(raw, 3);
  append<uint64_t>(raw, uint64_t(1) << 40);
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(raw, v);
  EXPECT_NE(error(write("huge.serialized", serialized_file({raw}, 3)), 0).find("more than this machine's memory"),
            std::string::npos);
  std::string short_raw;
  append<uint32_t>(short_raw, 0x1000);
  append<uint64_t>(short_raw, 3);
  append<uint64_t>(short_raw, 2);
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(short_raw, v);
  for (uint32_t i : {0u, 1u, 2u}) append(short_raw, i);  // one of the two triangles
  EXPECT_NE(error(write("short.serialized", serialized_file({short_raw}, 3)), 0).find("truncated .serialized"),
            std::string::npos);
  // A shape index is for .serialized files only.
  EXPECT_NE(error(kMeshes / "ply-tests" / "cube.ply", 1).find("only meaningful for a .serialized file"),
            std::string::npos);
}

}  // namespace
}  // namespace candela
