// Every input that once crashed a fuzz target (fuzz/regressions/<target>/, docs/reliability.md) is
// read again by the same reader, the way the fuzz target reads it: the reader must either succeed
// or throw its documented error (SceneError; FileContentError for render parts and checkpoints).
// Under the ASan+UBSan build in CI a memory error fails the test as well.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "../fuzz/checkpoint_input.h"
#include "../fuzz/grid_input.h"
#include "candela/base/error.h"
#include "candela/geometry/sdf_grid.h"
#include "candela/io/gltf_reader.h"
#include "candela/io/grid_files.h"
#include "candela/io/mesh_io.h"
#include "candela/io/mitsuba_reader.h"
#include "candela/io/pbrt_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/render/checkpoint.h"
#include "candela/render/film_part.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

const fs::path kRegressions = fs::path(CANDELA_SOURCE_DIR) / "fuzz" / "regressions";

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<fs::path> inputs_of(const std::string& target) {
  std::vector<fs::path> files;
  const fs::path dir = kRegressions / target;
  if (fs::is_directory(dir))
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file() && entry.path().filename().string()[0] != '.') files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// A scratch directory like the fuzz targets' one (fuzz/fuzz_common.h): the input plus the two
// meshes that fuzzed scenes may name.
class FuzzRegression : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("candela_fuzz_regression_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    write(dir_ / "mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    write(dir_ / "mesh.ply",
          "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
          "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static void write(const fs::path& file, const std::string& bytes) {
    std::ofstream out(file, std::ios::binary);
    out << bytes;
  }
  fs::path copy_in(const fs::path& input, const std::string& name) {
    write(dir_ / name, read_bytes(input));
    return dir_ / name;
  }
  fs::path dir_;
};

// Runs `read` on each input; the reader's documented error (SceneError unless said otherwise) is
// fine, another exception fails the test.
template <typename DocumentedError = SceneError, typename Read>
void expect_no_crash(const std::string& target, Read read) {
  for (const fs::path& input : inputs_of(target)) {
    SCOPED_TRACE(input.string());
    try {
      read(input);
    } catch (const DocumentedError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not the reader's documented error: " << e.what();
    }
  }
}

TEST_F(FuzzRegression, JsonReader) {
  expect_no_crash("json_reader", [&](const fs::path& input) {
    (void)read_json_scene(read_bytes(input), input.filename().string(), dir_);
  });
}

TEST_F(FuzzRegression, PbrtReader) {
  expect_no_crash("pbrt_reader", [&](const fs::path& input) {
    Warnings warnings;
    (void)read_pbrt_scene(copy_in(input, "input.pbrt"), warnings);
  });
}

TEST_F(FuzzRegression, ObjReader) {
  expect_no_crash("obj_reader", [&](const fs::path& input) {
    (void)load_mesh_file(copy_in(input, "input.obj"), SourceLocation{"fuzz", 1, 1, {}});
  });
}

TEST_F(FuzzRegression, PlyReader) {
  expect_no_crash("ply_reader", [&](const fs::path& input) {
    (void)load_mesh_file(copy_in(input, "input.ply"), SourceLocation{"fuzz", 1, 1, {}});
  });
}

TEST_F(FuzzRegression, SerializedReader) {
  // As fuzz/serialized_reader_fuzz.cpp reads its input: an odd first byte, the rest is the whole
  // file; an even one, the rest is one mesh's stream, compressed and wrapped (version 3 or 4 by bit 1).
  expect_no_crash("serialized_reader", [&](const fs::path& input) {
    const std::string data = read_bytes(input);
    if (data.empty()) return;
    std::string file = data.substr(1);
    if (!(data[0] & 1)) {
      const char version = data[0] & 2 ? 4 : 3;
      uLongf size = compressBound(uLong(file.size()));
      std::string packed(size, '\0');
      ASSERT_EQ(compress(reinterpret_cast<Bytef*>(packed.data()), &size, reinterpret_cast<const Bytef*>(file.data()),
                         uLong(file.size())),
                Z_OK);
      file = std::string{'\x1c', '\x04', version, '\0'} + packed.substr(0, size) +
             std::string(version == 3 ? 4 : 8, '\0') + std::string{'\x01', '\0', '\0', '\0'};
    }
    write(dir_ / "input.serialized", file);
    for (int shape_index : {0, 1}) {
      try {
        (void)load_mesh_file(dir_ / "input.serialized", SourceLocation{"fuzz", 1, 1, {}}, shape_index);
      } catch (const SceneError&) {
      }
    }
  });
}

TEST_F(FuzzRegression, MitsubaReader) {
  expect_no_crash("mitsuba_reader", [&](const fs::path& input) {
    Warnings warnings;
    (void)read_mitsuba_scene_text(read_bytes(input), input.filename().string(), dir_, warnings);
  });
}

TEST_F(FuzzRegression, GltfReader) {
  // As fuzz/gltf_reader_fuzz.cpp: a .glb when the input starts with "glTF", else a .gltf.
  expect_no_crash("gltf_reader", [&](const fs::path& input) {
    const std::string name = read_bytes(input).starts_with("glTF") ? "input.glb" : "input.gltf";
    Warnings warnings;
    (void)read_gltf_scene(copy_in(input, name), warnings, GltfOptions{dir_ / "gltf-cache", 64});
  });
}

TEST_F(FuzzRegression, VolReader) {
  expect_no_crash("vol_reader", [&](const fs::path& input) {
    const fs::path file = copy_in(input, "input.vol");
    try {
      (void)read_grid_file(file, "density", SourceLocation{"fuzz", 1, 1, {}});
    } catch (const SceneError&) {
    }
    (void)read_sdf_grid_file(file, SourceLocation{"fuzz", 1, 1, {}}, SdfNormals::Smooth);
  });
}

TEST_F(FuzzRegression, NanovdbReader) {
  // As fuzz/nanovdb_reader_fuzz.cpp: the file fuzz/grid_input.h makes, its grids listed, the first read.
  expect_no_crash("nanovdb_reader", [&](const fs::path& input) {
    write(dir_ / "input.nvdb", candela_fuzz::nanovdb_file_of(read_bytes(input), dir_));
    std::vector<std::string> names;
    try {
      names = grid_names_in_file(dir_ / "input.nvdb", SourceLocation{"fuzz", 1, 1, {}});
    } catch (const SceneError&) {
    }
    (void)read_grid_file(dir_ / "input.nvdb", names.empty() ? "density" : names.front(), SourceLocation{"fuzz", 1, 1, {}},
                         candela_fuzz::kMaxFuzzedDenseSamples);
  });
}

TEST_F(FuzzRegression, PartReader) {
  expect_no_crash<FileContentError>("part_reader",
                                    [&](const fs::path& input) { (void)merge_parts({copy_in(input, "input.exr")}); });
}

TEST_F(FuzzRegression, CheckpointReader) {
  // As fuzz/checkpoint_reader_fuzz.cpp: the input made into a checkpoint by fuzz/checkpoint_input.h.
  expect_no_crash<FileContentError>("checkpoint_reader", [&](const fs::path& input) {
    (void)parse_checkpoint(candela_fuzz::checkpoint_bytes_of(read_bytes(input)), "fuzz.ckpt");
  });
}

}  // namespace
}  // namespace candela
