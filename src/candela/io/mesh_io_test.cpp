// Tests of load_mesh_file: OBJ files, gzipped meshes, and errors for missing files and unsupported extensions.
#include "candela/io/mesh_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "candela/testing/gzip_bytes.h"
#include "candela/testing/mesh_io_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::mesh_io;
namespace fs = std::filesystem;

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

}  // namespace
}  // namespace candela
