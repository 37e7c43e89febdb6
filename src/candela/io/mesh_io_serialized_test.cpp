// Tests of load_mesh_file's reader of Mitsuba's .serialized meshes: well-formed, damaged and cut short.
#include "candela/io/mesh_io.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "candela/testing/mesh_io_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::mesh_io;
namespace fs = std::filesystem;

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
