// Volume grids from OpenVDB and NanoVDB files: a grid written and read back gives the same density at
// every voxel centre, placed by the file's voxel size and index offset, and zero beyond its active
// voxels; the pbrt-v4 "nanovdb" medium and JSON grids read them; every malformed case is a SceneError
// naming the file.
#include "candela/io/grid_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "candela/io/scene_reader.h"
#include "candela/media/medium.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

class GridFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("candela-grid-files-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    values_.resize(size_t(kRes[0]) * kRes[1] * kRes[2]);
    for (size_t i = 0; i < values_.size(); ++i) values_[i] = (i % 7 == 3) ? 0.0f : 0.25f * float(i % 11) + 0.5f;
  }
  void TearDown() override { fs::remove_all(dir_); }
  static constexpr std::array<int, 3> kRes{5, 4, 3};
  static constexpr std::array<int, 3> kOffset{-2, 7, 1};
  static constexpr float kVoxel = 0.5f;
  fs::path dir_;
  std::vector<float> values_;
};

TEST_F(GridFiles, VdbAndNanoVdbReadBackAtEveryVoxelCentre) {
  for (const char* ext : {".vdb", ".nvdb"}) {
    const fs::path file = dir_ / (std::string("cloud") + ext);
    write_grid_file(file, "density", kRes, values_, kVoxel, kOffset);
    EXPECT_EQ(grid_names_in_file(file, {}), std::vector<std::string>{"density"});
    VolumeDesc v = read_grid_file(file, "density", {});
    EXPECT_EQ(v.grid_name, "density");
    EXPECT_EQ(v.border, VolumeBorder::Zero);
    EXPECT_EQ(v.to_world, v.file_to_world);
    MediumDesc desc;
    desc.density = v;
    ASSERT_EQ(medium_problem(desc), "") << ext;
    const Medium medium(desc);
    // The active voxels' box may be smaller than the grid written (zeros are inactive), so look
    // every voxel up by its world position.
    size_t k = 0;
    for (int z = 0; z < kRes[2]; ++z)
      for (int y = 0; y < kRes[1]; ++y)
        for (int x = 0; x < kRes[0]; ++x, ++k) {
          Point3 p(kVoxel * float(x + kOffset[0]), kVoxel * float(y + kOffset[1]), kVoxel * float(z + kOffset[2]));
          EXPECT_NEAR(medium.density(p), values_[k], 1e-5f) << ext << " voxel " << x << " " << y << " " << z;
        }
    // Half a voxel beyond the outermost active voxels, and further out: nothing.
    EXPECT_EQ(medium.density({kVoxel * (kOffset[0] - 3.0f), kVoxel * float(kOffset[1]), kVoxel * float(kOffset[2])}), 0.0f);
  }
}

TEST_F(GridFiles, ProblemsNameTheFile) {
  const fs::path file = dir_ / "cloud.vdb";
  write_grid_file(file, "smoke", kRes, values_, kVoxel);
  auto message = [](auto read) {
    try {
      read();
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { read_grid_file(file, "density", {}); })
                .find("cannot read volume grid '" + file.string() + "': it has no grid \"density\" (its grids: \"smoke\")"),
            std::string::npos);
  EXPECT_NE(message([&] { read_grid_file(dir_ / "missing.vdb", "density", {}); }).find("cannot read volume grid"),
            std::string::npos);
  // (Truncated and malformed .vdb files are refused by OpenVDB's reader, whose messages the error
  // carries; they are not tested here: on some truncations the library takes tens of seconds to give
  // up, too long and too variable for the suite. .nvdb files are checked by candela: next test.)
}

// Found by fuzz/nanovdb_reader_fuzz.cpp (fuzz/regressions/nanovdb_reader/): NanoVDB's own reader read
// a grid name without its NUL byte past its end (ASan: heap-buffer-overflow), allocated the sizes the
// file declared, and followed node offsets as the file gave them. candela reads the file itself and
// checks each first.
TEST_F(GridFiles, NanoVdbFilesAreCheckedBeforeTheyAreRead) {
  const fs::path file = dir_ / "cloud.nvdb";
  write_grid_file(file, "density", kRes, values_, kVoxel, kOffset);
  std::ifstream in(file, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto error_of = [&](const std::string& contents) {
    std::ofstream(file, std::ios::binary) << contents;
    try {
      read_grid_file(file, "density", {});
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto error_with = [&](size_t at, const std::string& bytes) {
    std::string patched = good;
    return error_of(patched.replace(at, bytes.size(), bytes));
  };
  const std::string prefix = "<input>: cannot read volume grid '" + file.string() + "': ";
  // The file: a 16-byte segment header, 176 bytes of the grid's metadata, its name "density\0", then
  // the grid: 672 bytes of header, then the tree, whose root node's offset is its fourth 8-byte word.
  const size_t name_end = 16 + 176 + 7, root_offset = name_end + 1 + 672 + 24;
  ASSERT_EQ(good.compare(name_end - 7, 8, std::string("density\0", 8)), 0);
  EXPECT_EQ(error_with(name_end, "x"), prefix + "a grid's name does not end in a NUL byte");
  // A name of 2^31 - 1 bytes (the metadata's nameSize at byte 136) was allocated before it was read.
  EXPECT_EQ(error_with(16 + 136, "\xff\xff\xff\x7f"), prefix + "it is cut short in a grid's name at byte 192");
  EXPECT_EQ(error_with(root_offset, std::string("\0\0\0\0\0\1\0\0", 8)),
            prefix + "grid \"density\" is corrupt: its root node lies outside it");
  EXPECT_EQ(error_of(good.substr(0, good.size() - 1)),
            prefix + "grid \"density\" of " + std::to_string(good.size() - name_end - 1) +
                " bytes runs past the end of the file");
  EXPECT_EQ(error_with(0, "NanoVDB1"), prefix + "no NanoVDB segment at byte 0");
  // (Version::c_str() mallocs the text it returns: the message leaked it until it was formatted here.)
  EXPECT_EQ(error_with(8, std::string(4, '\0')), prefix + "it is NanoVDB version 0.0.0; candela reads 32.x");
  EXPECT_EQ(error_of(good), "no error");
}

TEST_F(GridFiles, PbrtNanoVdbMediumAndJsonGridsReadThem) {
  const fs::path nvdb = dir_ / "cloud.nvdb", vdb = dir_ / "cloud.vdb";
  write_grid_file(nvdb, "density", kRes, values_, kVoxel, kOffset);
  write_grid_file(vdb, "density", kRes, values_, kVoxel, kOffset);
  // pbrt: placed by the file and then the CTM (here a translation by 10 along x).
  testing::pbrt_reader::ScratchScene scene(
      {"WorldBegin", "Translate 10 0 0",
       "MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"" + nvdb.string() + "\"",
       "  \"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 1 1 1 ] \"float scale\" 2"});
  SceneDesc pbrt = read_scene_file(scene.path());
  ASSERT_EQ(pbrt.media.size(), 1u);
  const Medium from_pbrt(pbrt.media[0]);
  // JSON: the .vdb placed by a translation by 10 along x too.
  const fs::path json = dir_ / "scene.json";
  std::ofstream(json) << R"({"media": {"smoke": {"type": "grid", "sigma_t": [3, 3, 3], "albedo": [0.5, 0.5, 0.5],
      "density": {"filename": ")" << vdb.string() << R"(", "transform": [{"translate": [10, 0, 0]}]}}},
      "materials": {"boundary": {"type": "interface"}},
      "shapes": [{"type": "sphere", "center": [10, 0, 0], "radius": 1, "material": "boundary", "interior": "smoke"}]})";
  SceneDesc from_json_desc = read_scene_file(json);
  ASSERT_EQ(from_json_desc.media.size(), 1u);
  const Medium from_json(from_json_desc.media[0]);
  EXPECT_EQ(from_pbrt.sigma_t(), RGB(3.0f));
  size_t k = 0;
  for (int z = 0; z < kRes[2]; ++z)
    for (int y = 0; y < kRes[1]; ++y)
      for (int x = 0; x < kRes[0]; ++x, ++k) {
        Point3 p(10 + kVoxel * float(x + kOffset[0]), kVoxel * float(y + kOffset[1]), kVoxel * float(z + kOffset[2]));
        EXPECT_NEAR(from_pbrt.density(p), values_[k], 1e-5f);
        EXPECT_NEAR(from_json.density(p), values_[k], 1e-5f);
      }
}

}  // namespace
}  // namespace candela
