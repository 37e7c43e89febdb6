// Tests of the pbrt-v4 reader's files: Include and Import, gzipped files, text read without a file, missing files.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/pbrt_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/description/scene_desc.h"
#include "candela/testing/command_line.h"
#include "candela/testing/gzip_bytes.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- Include and Import

TEST(PbrtReader, IncludeResolvesNamesBesideTheNamingFile) {
  SceneDesc scene = read_pbrt_scene(kTestData / "include/main.pbrt");
  EXPECT_EQ(scene.film.width, 64);
  ASSERT_EQ(scene.shapes.size(), 3u);
  expect_near(scene.shapes[0].to_world.point(Point3(0, 0, 0)), Point3(0, 0, 5));
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[0].geometry).radius, 2);
  for (const ShapeDesc& shape : scene.shapes) EXPECT_EQ(reflectance_of(scene, shape), RGB(0.1f, 0.2f, 0.9f));
  // The same .ply named relative to the including file and relative to the top-level file.
  EXPECT_EQ(mesh_of(scene.shapes[1]).triangle_count(), 1u);
  EXPECT_EQ(mesh_of(scene.shapes[2]).positions, mesh_of(scene.shapes[1]).positions);
  // A shape declared in an included file is placed in that file.
  EXPECT_EQ(scene.shapes[0].where.to_string(), (kTestData / "include/parts/spheres.pbrt").string() + ":3:5");
}

TEST(PbrtReader, ErrorInAnIncludedFileNamesThatFileAndLine) {
  fs::path main = kTestData / "include/bad_main.pbrt";
  std::string message = error_reading(main);
  std::string included = (kTestData / "include/parts/bad.pbrt").string();
  EXPECT_TRUE(message.starts_with(included + ":3:1: unknown directive \"Shap\"")) << message;
  EXPECT_NE(message.find(main.string() + ":3:9"), std::string::npos) << message;
}

TEST(PbrtReader, IncludeCycleIsAnError) {
  std::string message = error_reading(kTestData / "include/cycle_a.pbrt");
  EXPECT_NE(message.find("cycle_b.pbrt:1:9: \"" + (kTestData / "include/cycle_a.pbrt").string() + "\" includes itself"),
            std::string::npos)
      << message;
}

// Files for the tests below, in a directory of their own.
class PbrtFiles {
 public:
  PbrtFiles() : dir_(testing::fresh_test_directory("candela_pbrt_files")) {}
  ~PbrtFiles() { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }

 private:
  fs::path dir_;
};

TEST(PbrtReader, IncludeChainsDeeperThan64FilesAreRefused) {
  PbrtFiles files;
  for (int k = 1; k < 100; ++k) files.write(fmt::format("f{}.pbrt", k), fmt::format("Include \"f{}.pbrt\"\n", k + 1));
  files.write("f100.pbrt", "Shape \"sphere\"\n");
  const fs::path main = files.write("main.pbrt", "WorldBegin\nInclude \"f1.pbrt\"\n");
  const std::string message = error_reading(main);
  // The innermost places first, the top-level file's last; the 60 between them counted, not listed.
  EXPECT_EQ(message, fmt::format("{0}f63.pbrt:1:9: files are included more than 64 deep (in the file included at "
                                 "{0}f62.pbrt:1:9, included at {0}f61.pbrt:1:9, ... 60 more Includes ..., included at "
                                 "{1}:2:9)",
                                 (main.parent_path() / "").string(), main.string()));
}

TEST(PbrtReader, AFileIncludedManyTimesOverIsRefused) {
  // 20 levels of files that each include the next twice: 2^20 files to read.
  PbrtFiles files;
  for (int k = 1; k < 20; ++k)
    files.write(fmt::format("f{}.pbrt", k), fmt::format("Include \"f{0}.pbrt\"\nInclude \"f{0}.pbrt\"\n", k + 1));
  files.write("f20.pbrt", "");
  const fs::path main = files.write("main.pbrt", "WorldBegin\nInclude \"f1.pbrt\"\n");
  const std::string message = error_reading(main);
  EXPECT_NE(message.find(": more than 100000 files are included in all (a file included many times over?)"),
            std::string::npos)
      << message;
}

TEST(PbrtReader, GzippedIncludesImportsMeshesAndScenesAreRead) {
  PbrtFiles files;
  files.write("geometry.pbrt.gz", testing::gzip_bytes("Shape \"sphere\" \"float radius\" 2\n"));
  files.write("imported.pbrt.gz", testing::gzip_bytes("Material \"conductor\"\nShape \"sphere\"\n"));
  files.write("triangle.ply.gz", testing::gzip_bytes("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                                     "property float y\nproperty float z\nelement face 1\n"
                                                     "property list uchar int vertex_indices\nend_header\n"
                                                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  const std::string text = "WorldBegin\nInclude \"geometry.pbrt.gz\"\nImport \"imported.pbrt.gz\"\n"
                           "Shape \"plymesh\" \"string filename\" \"triangle.ply.gz\"\n";
  const fs::path main = files.write("main.pbrt", text);
  const SceneDesc scene = read_pbrt_scene(main);
  ASSERT_EQ(scene.shapes.size(), 3u);
  EXPECT_FLOAT_EQ(std::get<SphereShape>(scene.shapes[0].geometry).radius, 2);
  EXPECT_EQ(scene.shapes[0].where.to_string(), (main.parent_path() / "geometry.pbrt.gz").string() + ":1:1");
  EXPECT_EQ(mesh_of(scene.shapes[2]).triangle_count(), 1u);
  // The whole scene gzipped, as pbrt-v4 reads it.
  const SceneDesc gzipped = read_scene_file(files.write("main.pbrt.gz", testing::gzip_bytes(text)));
  EXPECT_EQ(gzipped.shapes.size(), 3u);

  // A damaged one is an error at the Include that names it.
  const std::string whole = testing::gzip_bytes("Shape \"sphere\"\n");
  files.write("cut.pbrt.gz", whole.substr(0, whole.size() - 3));
  const fs::path cut = files.write("cut.pbrt", "WorldBegin\nInclude \"cut.pbrt.gz\"\n");
  EXPECT_EQ(error_reading(cut), fmt::format("{}:2:9: cannot read \"{}\": gzip: the compressed data is cut short",
                                            cut.string(), (cut.parent_path() / "cut.pbrt.gz").string()));
}

TEST(PbrtReader, ImportedGraphicsStateDoesNotLeak) {
  SceneDesc scene = read_pbrt_scene(kTestData / "include/import_main.pbrt");
  ASSERT_EQ(scene.shapes.size(), 2u);
  expect_near(scene.shapes[0].to_world.point(Point3(0, 0, 0)), Point3(10, 0, 0));
  EXPECT_TRUE(std::holds_alternative<DielectricMaterial>(scene.materials.at(scene.shapes[0].material)));
  EXPECT_TRUE(scene.shapes[1].to_world.is_identity());
  EXPECT_EQ(reflectance_of(scene, scene.shapes[1]), RGB(0.5f));
}

// ---------------------------------------------------------------- text not read from a file

TEST(PbrtReader, TextReadsAsItsFileWouldWithNamesResolvedInTheBaseDirectory) {
  const fs::path file = kTestData / "include/main.pbrt";
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  SceneDesc from_file = read_pbrt_scene(file);
  SceneDesc from_text = read_pbrt_string(text.str(), "main (as text)", file.parent_path());
  EXPECT_EQ(from_text.source_file, "main (as text)");
  EXPECT_EQ(from_text.film.width, from_file.film.width);
  ASSERT_EQ(from_text.shapes.size(), 3u);
  ASSERT_EQ(from_text.shapes.size(), from_file.shapes.size());
  for (size_t i = 0; i < from_file.shapes.size(); ++i) {
    EXPECT_EQ(from_text.shapes[i].to_world, from_file.shapes[i].to_world);
    EXPECT_EQ(from_text.shapes[i].where.to_string(), from_file.shapes[i].where.to_string());
    EXPECT_EQ(reflectance_of(from_text, from_text.shapes[i]), reflectance_of(from_file, from_file.shapes[i]));
  }
  EXPECT_EQ(mesh_of(from_text.shapes[1]).positions, mesh_of(from_file.shapes[1]).positions);

  // Messages name the text by the name given, and the files it includes by their paths.
  std::string message = error_of([&](Warnings& warnings) {
    read_pbrt_string("WorldBegin\nInclude \"parts/bad.pbrt\"\n", "inline", kTestData / "include", warnings);
  });
  EXPECT_TRUE(message.starts_with((kTestData / "include/parts/bad.pbrt").string() + ":3:1: unknown directive"))
      << message;
  EXPECT_NE(message.find("(in the file included at inline:2:9)"), std::string::npos) << message;
}

TEST(PbrtReader, RecordsWhereEachEntityIsDeclared) {
  ScratchFile png("wood.png");
  SceneDesc scene = read_lines({
      "WorldBegin",
      "Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"",
      "MakeNamedMaterial \"m\" \"string type\" \"diffuse\" \"texture reflectance\" \"wood\"",
      // "scale" makes a scale texture of "wood", which this directive declares
      "  Material \"diffusetransmission\" \"texture transmittance\" \"wood\" \"float scale\" 0.5",
      "LightSource \"point\"",
      "  Shape \"sphere\"",
      "ObjectBegin \"pair\"",
      "Shape \"sphere\"",
      "ObjectEnd",
      "  ObjectInstance \"pair\"",
  });
  auto places = [](const std::vector<SourceLocation>& where) {
    std::vector<std::string> text;
    for (const SourceLocation& w : where) text.push_back(w.to_string());
    return text;
  };
  ASSERT_EQ(scene.textures.size(), 2u);
  EXPECT_EQ(places(scene.places.textures), (std::vector<std::string>{"scene.pbrt:2:1", "scene.pbrt:4:3"}));
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_EQ(places(scene.places.materials), (std::vector<std::string>{"scene.pbrt:3:1", "scene.pbrt:4:3"}));
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(places(scene.places.lights), (std::vector<std::string>{"scene.pbrt:5:1"}));
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_EQ(scene.shapes[0].where.to_string(), "scene.pbrt:6:3");
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].where.to_string(), "scene.pbrt:7:1");
  EXPECT_EQ(scene.objects[0].shapes.at(0).where.to_string(), "scene.pbrt:8:1");
  ASSERT_EQ(scene.instances.size(), 1u);
  EXPECT_EQ(scene.instances[0].where.to_string(), "scene.pbrt:10:3");
}

TEST(PbrtReader, MissingIncludeFile) {
  ScratchScene scene({"WorldBegin", "Include \"no/such/file.pbrt\""});
  std::string message = error_reading(scene.path());
  EXPECT_TRUE(message.starts_with(scene.path().string() + ":2:9: Include: cannot find \"no/such/file.pbrt\""))
      << message;
}

TEST(PbrtReader, MissingPlyFile) {
  ScratchScene scene({"WorldBegin", "Shape \"plymesh\" \"string filename\" \"missing.ply\""});
  std::string message = error_reading(scene.path());
  EXPECT_TRUE(message.starts_with(scene.path().string() + ":2:17: Shape \"plymesh\": \"filename\": cannot find "
                                  "\"missing.ply\""))
      << message;
}

TEST(PbrtReader, MissingSceneFile) {
  fs::path file = kTestData / "no-such-scene.pbrt";
  EXPECT_EQ(error_reading(file), file.string() + ": no such scene file");
}

TEST(PbrtReader, ImportBeforeWorldBegin) {
  expect_error({"Import \"x.pbrt\""}, 1, "Import", "Import is not allowed before WorldBegin");
}

}  // namespace
}  // namespace candela
