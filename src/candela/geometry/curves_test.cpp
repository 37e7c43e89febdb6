// A curve's segments as Embree's cubic Bézier segments (geometry/curves.h): the basis changes keep the
// curve and its parameter (checked against the B-spline and quadratic bases evaluated directly), the
// widths are pbrt-v4's per segment, a ribbon's normal turns as pbrt-v4's slerp, and the checks refuse
// what cannot be built.
#include "candela/geometry/curves.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace candela {
namespace {

void expect_curve_points_near(const Vec3& a, const Vec3& b, float tolerance, const char* what) {
  EXPECT_NEAR(a.x, b.x, tolerance) << what;
  EXPECT_NEAR(a.y, b.y, tolerance) << what;
  EXPECT_NEAR(a.z, b.z, tolerance) << what;
}

std::array<Point3, 4> curve_segment(const BezierSegments& s, size_t k) {
  return {s.control[4 * k], s.control[4 * k + 1], s.control[4 * k + 2], s.control[4 * k + 3]};
}

const std::vector<Point3> kCurvePoints = {{0, 0, 0}, {1, 2, 0}, {2, -1, 1}, {3, 0, 2}, {4, 3, -1}, {5, 1, 0}, {6, 0, 0}};

TEST(Curves, SegmentCountFollowsTheBasisAndDegree) {
  CurveShape c;
  c.points = kCurvePoints;  // 7 points
  EXPECT_EQ(c.segment_count(), 2u);  // cubic Bézier: 4 + 3
  c.degree = 2;
  EXPECT_EQ(c.segment_count(), 3u);  // quadratic Bézier: 3 + 2 + 2
  c.basis = CurveBasis::BSpline;
  EXPECT_EQ(c.segment_count(), 5u);
  c.degree = 3;
  EXPECT_EQ(c.segment_count(), 4u);
  c.basis = CurveBasis::Bezier;
  c.points.resize(6);
  EXPECT_EQ(c.segment_count(), 0u);
  EXPECT_EQ(c.expected_point_count(), "3k + 1 (4, 7, 10, ...)");
  c.points.resize(3);
  c.basis = CurveBasis::BSpline;
  EXPECT_EQ(c.segment_count(), 0u);
  EXPECT_EQ(c.expected_point_count(), "at least 4");
  c.degree = 4;
  c.points = kCurvePoints;
  EXPECT_EQ(c.segment_count(), 0u);
}

TEST(Curves, CubicBsplineSegmentsAreTheSameCurve) {
  CurveShape c;
  c.points = kCurvePoints;
  c.basis = CurveBasis::BSpline;
  const BezierSegments s = curve_bezier_segments(c);
  ASSERT_EQ(s.segment_count(), 4u);
  for (size_t k = 0; k < 4; ++k)
    for (float u : {0.0f, 0.2f, 0.5f, 0.9f, 1.0f}) {
      // The uniform cubic B-spline's basis functions on segment k.
      const float v = 1 - u;
      const Point3 expected = c.points[k] * (v * v * v / 6) + c.points[k + 1] * ((3 * u * u * u - 6 * u * u + 4) / 6) +
                              c.points[k + 2] * ((-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6) +
                              c.points[k + 3] * (u * u * u / 6);
      expect_curve_points_near(bezier_point(curve_segment(s, k), u), expected, 1e-5f, "cubic B-spline");
    }
}

TEST(Curves, QuadraticSegmentsAreTheSameCurve) {
  CurveShape c;
  c.points = kCurvePoints;
  c.degree = 2;
  const BezierSegments bezier = curve_bezier_segments(c);
  ASSERT_EQ(bezier.segment_count(), 3u);
  for (size_t k = 0; k < 3; ++k)
    for (float u : {0.0f, 0.3f, 0.75f, 1.0f}) {
      const Point3* p = &c.points[2 * k];
      const Point3 expected = p[0] * ((1 - u) * (1 - u)) + p[1] * (2 * u * (1 - u)) + p[2] * (u * u);
      expect_curve_points_near(bezier_point(curve_segment(bezier, k), u), expected, 1e-5f, "quadratic Bézier");
    }
  c.basis = CurveBasis::BSpline;
  const BezierSegments spline = curve_bezier_segments(c);
  ASSERT_EQ(spline.segment_count(), 5u);
  for (size_t k = 0; k < 5; ++k)
    for (float u : {0.0f, 0.4f, 1.0f}) {
      const Point3* p = &c.points[k];
      const Point3 expected =
          p[0] * ((1 - u) * (1 - u) / 2) + p[1] * ((-2 * u * u + 2 * u + 1) / 2) + p[2] * (u * u / 2);
      expect_curve_points_near(bezier_point(curve_segment(spline, k), u), expected, 1e-5f, "quadratic B-spline");
    }
}

TEST(Curves, DerivativeIsTheTangent) {
  const std::array<Point3, 4> cp = {Point3(0, 0, 0), Point3(1, 2, 0), Point3(2, -1, 1), Point3(3, 0, 2)};
  for (float u : {0.1f, 0.5f, 0.8f}) {
    const float h = 1e-3f;
    const Vec3 numeric = (bezier_point(cp, u + h) - bezier_point(cp, u - h)) / (2 * h);
    expect_curve_points_near(bezier_derivative(cp, u), numeric, 2e-2f, "tangent");
  }
}

TEST(Curves, WidthsArePbrtsLerpPerSegment) {
  CurveShape c;
  c.points = kCurvePoints;
  c.basis = CurveBasis::BSpline;  // 4 segments
  c.width0 = 0.4f;
  c.width1 = 0.2f;
  const BezierSegments s = curve_bezier_segments(c);
  const std::vector<float> expected = {0.4f, 0.35f, 0.35f, 0.3f, 0.3f, 0.25f, 0.25f, 0.2f};
  ASSERT_EQ(s.width.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(s.width[i], expected[i], 1e-6f) << i;
  EXPECT_TRUE(s.normals.empty());
}

TEST(Curves, RibbonNormalsTurnByTheirSphericalInterpolation) {
  const Normal3 n0(0, 0, 1), n1(0, 1, 0);
  for (float u : {0.0f, 0.25f, 0.5f, 1.0f}) {
    const float angle = u * kPi / 2;
    expect_curve_points_near(slerp_normal(n0, n1, u), Normal3(0, std::sin(angle), std::cos(angle)), 1e-5f, "slerp");
  }
  expect_curve_points_near(slerp_normal(n0, n0, 0.3f), n0, 0, "parallel normals");
  // The Bézier normal curve meets the slerp at u = 0, 1/3, 2/3, 1 and stays close in between.
  const std::array<Normal3, 4> b = bezier_normals(n0, n1);
  for (float u : {0.0f, 1.0f / 3, 2.0f / 3, 1.0f})
    expect_curve_points_near(bezier_point(b, u), slerp_normal(n0, n1, u), 1e-5f, "control normals");
  expect_curve_points_near(normalize(bezier_point(b, 0.5f)), slerp_normal(n0, n1, 0.5f), 2e-3f, "between");

  CurveShape ribbon;
  ribbon.points = kCurvePoints;
  ribbon.type = CurveType::Ribbon;
  ribbon.normals = {{0, 0, 2}, {0, 1, 1}, {1, 0, 0}};
  const BezierSegments s = curve_bezier_segments(ribbon);
  ASSERT_EQ(s.normals.size(), 4u);  // the ends of each segment, unit
  expect_curve_points_near(s.normals[0], Normal3(0, 0, 1), 1e-6f, "first");
  expect_curve_points_near(s.normals[1], normalize(Normal3(0, 1, 1)), 1e-6f, "shared end");
  expect_curve_points_near(s.normals[2], normalize(Normal3(0, 1, 1)), 1e-6f, "shared start");
  expect_curve_points_near(s.normals[3], Normal3(1, 0, 0), 1e-6f, "last");
}

TEST(Curves, ProblemsAreNamed) {
  CurveShape c;
  c.points = kCurvePoints;
  EXPECT_EQ(curve_problem(c), "");
  c.points.resize(5);
  EXPECT_EQ(curve_problem(c), "a degree 3 Bézier curve needs 3k + 1 (4, 7, 10, ...) points, got 5");
  c.points = kCurvePoints;
  c.width1 = -1;
  EXPECT_NE(curve_problem(c).find("widths must be finite and >= 0"), std::string::npos);
  c.width1 = 1;
  c.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  EXPECT_EQ(curve_problem(c), "only a ribbon has normals");
  c.type = CurveType::Ribbon;
  EXPECT_EQ(curve_problem(c), "");
  c.normals.pop_back();
  EXPECT_EQ(curve_problem(c), "a ribbon of 2 segments needs 3 normals (one at each end of each segment), got 2");
  c.normals = {{0, 0, 1}, {0, 0, 0}, {0, 0, 1}};
  EXPECT_EQ(curve_problem(c), "normal 1 must be finite and non-zero");
  c.normals = {{0, 0, 1}, {0, 0, -1}, {0, 0, 1}};
  EXPECT_NE(curve_problem(c).find("opposite directions"), std::string::npos);
  c.degree = 5;
  EXPECT_EQ(curve_problem(c), "the degree must be 2 or 3, got 5");
}

TEST(Curves, FlatTessellationFollowsTheBendAndTheWidth) {
  const std::vector<Point3> straight = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_EQ(flat_curve_tessellation(straight, {0.1f, 0.1f}), 4u);
  // The probes' curve: bent by 2 across a width of 0.15 needs sqrt(0.75 * |p0 - 2 p1 + p2| / (0.05 w)) pieces.
  const std::vector<Point3> bent = {{-1.5f, 0.3f, 0}, {-0.5f, 1.8f, 0}, {0.5f, -0.2f, 0}, {1.5f, 1.2f, 0}};
  const float bend = std::max(length(bent[0] - bent[1] * 2 + bent[2]), length(bent[1] - bent[2] * 2 + bent[3]));
  EXPECT_EQ(flat_curve_tessellation(bent, {0.15f, 0.15f}),
            unsigned(std::ceil(std::sqrt(0.75 * bend / (0.05 * 0.15)))));
  EXPECT_EQ(flat_curve_tessellation(bent, {1e-6f, 1e-6f}), 64u);
  EXPECT_EQ(flat_curve_tessellation(bent, {0, 0}), 4u);  // invisible: nothing to follow
}

}  // namespace
}  // namespace candela
