#include "candela/io/warnings.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "candela/base/error.h"

namespace candela {
namespace {

TEST(Warnings, LinesNameThePlaceAsEachFormatDoes) {
  Warnings warnings;
  warnings.warn(SourceLocation{"scene.pbrt", 12, 5, {}}, "sobol: using candela's zsobol sampler");
  warnings.warn(SourceLocation{"scene.xml", 7, 0, {}}, "ignored");
  warnings.warn(SourceLocation{"box.gltf", 0, 0, "/materials/0"}, "approximated");
  warnings.warn("model.obj", "material \"red\": dropped");
  warnings.add_line("material library 'x.mtl': not found; its materials are diffuse grey");
  ASSERT_EQ(warnings.size(), 5u);
  EXPECT_EQ(warnings[0], "scene.pbrt:12:5: warning: sobol: using candela's zsobol sampler");
  EXPECT_EQ(warnings[1], "scene.xml:7: warning: ignored");
  EXPECT_EQ(warnings[2], "box.gltf: at /materials/0: warning: approximated");
  EXPECT_EQ(warnings[3], "model.obj: warning: material \"red\": dropped");
  EXPECT_EQ(warnings[4], "material library 'x.mtl': not found; its materials are diffuse grey");
  EXPECT_EQ(warnings.lines().size(), 5u);
}

TEST(Warnings, PrintedWarningsAreCappedPerKind) {
  Warnings warnings;
  for (int line = 1; line <= 5; ++line) warnings.warn(SourceLocation{"a.pbrt", line, 1, {}}, "same thing");
  warnings.warn("a.pbrt:9:1", "other thing");
  ::testing::internal::CaptureStderr();
  warnings.print(stderr, 3);
  std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed,
            "a.pbrt:1:1: warning: same thing\na.pbrt:2:1: warning: same thing\na.pbrt:3:1: warning: same thing\n"
            "a.pbrt:9:1: warning: other thing\n(2 more warnings like \"same thing\")\n");
}

TEST(Warnings, LinesWithoutAPlaceAreKindsOfTheirOwn) {
  Warnings warnings;
  for (int i = 0; i < 3; ++i) warnings.add_line("no place here");
  ::testing::internal::CaptureStderr();
  warnings.print(stderr, 2);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(),
            "no place here\nno place here\n(1 more warnings like \"no place here\")\n");
}

TEST(Warnings, ReadPrintingWarningsPrintsAlsoBeforeAnError) {
  ::testing::internal::CaptureStderr();
  const int value = read_printing_warnings([](Warnings& w) {
    w.warn("a.pbrt:1:1", "first");
    return 7;
  });
  EXPECT_EQ(value, 7);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "a.pbrt:1:1: warning: first\n");

  ::testing::internal::CaptureStderr();
  EXPECT_THROW(read_printing_warnings([](Warnings& w) -> int {
                 w.warn("a.pbrt:2:1", "before the error");
                 throw SceneError("a.pbrt:3:1: broken");
               }),
               SceneError);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "a.pbrt:2:1: warning: before the error\n");
}

}  // namespace
}  // namespace candela
