#pragma once
// Curves (description/shapes.h: CurveShape, pbrt-v4's Shape "curve") as Embree takes them: every
// segment a cubic Bézier segment of 4 control points of its own, each (x, y, z, radius). pbrt-v4 makes
// the same segments of its input (quadratic segments raised to cubic, B-spline segments converted to
// their Bézier control points: the same curves with the same parameter), and so does candela: the
// hit's u is then the segment's own parameter, as in pbrt-v4, and the Embree geometry has one basis
// and one layout whatever the input.
#include <array>
#include <string>
#include <vector>

#include "candela/description/shapes.h"
#include "candela/math/vec.h"

namespace candela {

// A curve's segments in its object space.
struct BezierSegments {
  std::vector<Point3> control;    // 4 per segment
  std::vector<float> width;       // 2 per segment: at its start and end (pbrt-v4's lerp of width0, width1)
  std::vector<Normal3> normals;   // ribbons: 2 per segment, unit, at its start and end; else empty
  size_t segment_count() const { return width.size() / 2; }
};

// The segments of a valid curve (curve_problem() empty).
BezierSegments curve_bezier_segments(const CurveShape& curve);

// What makes a curve impossible to build, or "" (the number of points for the basis and degree, the
// number of normals of a ribbon, finite points, widths >= 0, non-zero normals, consecutive ribbon
// normals that are not opposite).
std::string curve_problem(const CurveShape& curve);

// A cubic Bézier segment and its derivative at u.
template <typename T>
T bezier_point(const std::array<T, 4>& cp, float u) {
  const float s = 1 - u;
  return cp[0] * (s * s * s) + cp[1] * (3 * s * s * u) + cp[2] * (3 * s * u * u) + cp[3] * (u * u * u);
}
template <typename T>
T bezier_derivative(const std::array<T, 4>& cp, float u) {
  const float s = 1 - u;
  return (cp[1] - cp[0]) * (3 * s * s) + (cp[2] - cp[1]) * (6 * s * u) + (cp[3] - cp[2]) * (3 * u * u);
}

// pbrt-v4's normal of a ribbon at u between its end normals n0 and n1 (unit): their spherical
// interpolation (n0 where they are parallel).
Normal3 slerp_normal(const Normal3& n0, const Normal3& n1, float u);

// The 4 control normals of the cubic Bézier that meets slerp_normal(n0, n1, u) at u = 0, 1/3, 2/3 and
// 1 (Embree's normal-oriented curves take a normal curve in the points' basis).
std::array<Normal3, 4> bezier_normals(const Normal3& n0, const Normal3& n1);

// Embree's flat curves are ray-facing quads along a polyline of this many pieces per segment: enough
// that the polyline stays within a twentieth of the width of the curve (pbrt-v4's refinement
// criterion), for the most bent segment, in [4, 64]. `control`: 4 points per segment.
unsigned flat_curve_tessellation(const std::vector<Point3>& control, const std::vector<float>& width);

}  // namespace candela
