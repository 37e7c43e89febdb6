// The pbrt-v4 reader's Shape "curve": pbrt-v4's parameters and defaults (Curve::Create), the CTM and
// graphics state applied, and every curve pbrt-v4 reports an error for refused at its file:line:column.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "candela/description/scene_desc.h"
#include "candela/scene/scene.h"
#include "candela/testing/pbrt_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;

const std::string kCurveP = "\"point3 P\" [ -1 0 0  -0.5 1 0  0.5 -1 0  1 0 0 ]";

const CurveShape& curve_of(const ShapeDesc& shape) { return std::get<CurveShape>(shape.geometry); }

TEST(PbrtCurves, DefaultsAreFlatCubicBezierOfWidthOne) {
  const SceneDesc scene = read_lines({"WorldBegin", "Translate 0 2 0", "Shape \"curve\" " + kCurveP});
  ASSERT_EQ(scene.shapes.size(), 1u);
  const CurveShape& c = curve_of(scene.shapes[0]);
  EXPECT_EQ(c.points.size(), 4u);
  EXPECT_EQ(c.points[1], Point3(-0.5f, 1, 0));
  EXPECT_EQ(c.basis, CurveBasis::Bezier);
  EXPECT_EQ(c.degree, 3);
  EXPECT_EQ(c.type, CurveType::Flat);
  EXPECT_EQ(c.width0, 1);
  EXPECT_EQ(c.width1, 1);
  EXPECT_TRUE(c.normals.empty());
  expect_near(scene.shapes[0].to_world.point(Point3(0.0f)), Point3(0, 2, 0));
}

TEST(PbrtCurves, EveryParameterIsRead) {
  const SceneDesc scene = read_lines(
      {"WorldBegin", "ReverseOrientation",
       "Shape \"curve\" \"point3 P\" [ 0 0 0  1 1 0  2 0 0  3 1 0  4 0 0 ] \"string basis\" \"bspline\" "
       "\"integer degree\" 2 \"string type\" \"ribbon\" \"normal N\" [ 0 0 1  0 1 1  0 1 0  1 0 0 ] "
       "\"float width\" 0.5 \"float width1\" 0.1 \"integer splitdepth\" 5",
       "Shape \"curve\" " + kCurveP + " \"string type\" \"cylinder\" \"float width0\" 0.3"});
  ASSERT_EQ(scene.shapes.size(), 2u);
  const CurveShape& ribbon = curve_of(scene.shapes[0]);
  EXPECT_EQ(ribbon.basis, CurveBasis::BSpline);
  EXPECT_EQ(ribbon.degree, 2);
  EXPECT_EQ(ribbon.type, CurveType::Ribbon);
  EXPECT_EQ(ribbon.segment_count(), 3u);
  EXPECT_EQ(ribbon.normals.size(), 4u);
  EXPECT_EQ(ribbon.width0, 0.5f);  // "width" where "width0" is not given
  EXPECT_EQ(ribbon.width1, 0.1f);
  EXPECT_TRUE(scene.shapes[0].reverse_orientation);
  const CurveShape& tube = curve_of(scene.shapes[1]);
  EXPECT_EQ(tube.type, CurveType::Cylinder);
  EXPECT_EQ(tube.width0, 0.3f);
  EXPECT_EQ(tube.width1, 1);
  Scene built(scene);  // and they build
}

TEST(PbrtCurves, BadCurvesAreRefusedWhereTheyAreGiven) {
  const std::string owner = "Shape \"curve\": ";
  expect_error({"WorldBegin", "Shape \"curve\" \"point3 P\" [ 0 0 0  1 1 0  2 0 0  3 1 0  4 0 0 ]"}, 2, "\"point3 P\"",
               owner + "\"P\" has 5 points, but a degree 3 Bézier curve needs 3k + 1 (4, 7, 10, ...)");
  expect_error({"WorldBegin", "Shape \"curve\" \"point3 P\" [ 0 0 0  1 1 0 ] \"string basis\" \"bspline\""}, 2,
               "\"point3 P\"", "a degree 3 B-spline curve needs at least 4");
  expect_error({"WorldBegin", "Shape \"curve\" \"float width\" 1"}, 2, "Shape", owner + "\"P\" is required");
  expect_error({"WorldBegin", "Shape \"curve\" " + kCurveP + " \"string type\" \"tube\""}, 2, "\"string type\"",
               owner + "\"type\" must be \"flat\", \"cylinder\" or \"ribbon\", got \"tube\"");
  expect_error({"WorldBegin", "Shape \"curve\" " + kCurveP + " \"string basis\" \"hermite\""}, 2, "\"string basis\"",
               owner + "\"basis\" must be \"bezier\" or \"bspline\", got \"hermite\"");
  expect_error({"WorldBegin", "Shape \"curve\" " + kCurveP + " \"integer degree\" 4"}, 2, "\"integer degree\"",
               owner + "\"degree\" must be 2 or 3");
  expect_error({"WorldBegin", "Shape \"curve\" " + kCurveP + " \"string type\" \"ribbon\""}, 2, "Shape",
               owner + "\"N\" is required for \"ribbon\" curves");
  expect_error({"WorldBegin", "Shape \"curve\" " + kCurveP + " \"string type\" \"ribbon\" \"normal N\" [ 0 0 1 ]"}, 2,
               "\"normal N\"", "has 1 normals, but a ribbon of 1 segments needs 2");
  expect_error({"WorldBegin", "Shape \"curve\" " + kCurveP + " \"float width1\" -0.5"}, 2, "\"float width1\"",
               owner + "\"width1\" must be >= 0, got -0.5");
  expect_error({"WorldBegin", "AttributeBegin", "AreaLightSource \"diffuse\"", "Shape \"curve\" " + kCurveP,
                "AttributeEnd"},
               4, "Shape", "a curve cannot be an area light");
}

TEST(PbrtCurves, NormalsOfCurvesThatAreNoRibbonsAreIgnoredWithAWarning) {
  const std::vector<std::string> lines = {"WorldBegin",
                                          "Shape \"curve\" " + kCurveP + " \"normal N\" [ 0 0 1  0 0 1 ]"};
  expect_warning(lines, 2, "\"normal N\"", "\"N\" is ignored: curve normals are only used with \"ribbon\" curves");
  EXPECT_TRUE(curve_of(read_lines(lines).shapes[0]).normals.empty());
}

TEST(PbrtCurves, CurvesStayInTheOutsideMedium) {
  const std::vector<std::string> lines = {
      "WorldBegin", "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"", "MediumInterface \"fog\" \"\"",
      "Shape \"curve\" " + kCurveP};
  expect_warning(lines, 4, "Shape", "a curve has no inside");
  const SceneDesc scene = read_lines(lines);
  EXPECT_EQ(scene.shapes[0].interior_medium, scene.shapes[0].exterior_medium);
}

}  // namespace
}  // namespace candela
