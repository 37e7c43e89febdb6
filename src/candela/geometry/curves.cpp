#include "candela/geometry/curves.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace candela {
namespace {

using CubicSegment = std::array<Point3, 4>;

// The standard basis changes (each the same curve with the same parameter).
CubicSegment raise_quadratic(const Point3& p0, const Point3& p1, const Point3& p2) {
  return {p0, p0 + (p1 - p0) * (2.0f / 3), p2 + (p1 - p2) * (2.0f / 3), p2};
}
CubicSegment quadratic_bspline_to_bezier(const Point3& p0, const Point3& p1, const Point3& p2) {
  return raise_quadratic((p0 + p1) * 0.5f, p1, (p1 + p2) * 0.5f);
}
CubicSegment cubic_bspline_to_bezier(const Point3& p0, const Point3& p1, const Point3& p2, const Point3& p3) {
  return {(p0 + p1 * 4 + p2) / 6, (p1 * 2 + p2) / 3, (p1 + p2 * 2) / 3, (p1 + p2 * 4 + p3) / 6};
}

float curve_normal_angle(const Normal3& a, const Normal3& b) {
  // Stable for nearly parallel and nearly opposite vectors (pbrt-v4's AngleBetween).
  if (dot(a, b) < 0) return std::numbers::pi_v<float> - 2 * std::asin(std::min(1.0f, length(a + b) / 2));
  return 2 * std::asin(std::min(1.0f, length(b - a) / 2));
}

}  // namespace

std::string curve_problem(const CurveShape& c) {
  if (c.degree != 2 && c.degree != 3) return fmt::format("the degree must be 2 or 3, got {}", c.degree);
  const size_t segments = c.segment_count();
  if (segments == 0)
    return fmt::format("a degree {} {} curve needs {} points, got {}", c.degree,
                       c.basis == CurveBasis::BSpline ? "B-spline" : "Bézier", c.expected_point_count(),
                       c.points.size());
  for (size_t i = 0; i < c.points.size(); ++i)
    if (!is_finite(c.points[i])) return fmt::format("point {} is not finite", i);
  if (!(c.width0 >= 0 && c.width1 >= 0) || !std::isfinite(c.width0) || !std::isfinite(c.width1))
    return fmt::format("the widths must be finite and >= 0, got {} and {}", c.width0, c.width1);
  if (c.type != CurveType::Ribbon) {
    if (!c.normals.empty()) return "only a ribbon has normals";
    return {};
  }
  if (c.normals.size() != segments + 1)
    return fmt::format("a ribbon of {} segments needs {} normals (one at each end of each segment), got {}", segments,
                       segments + 1, c.normals.size());
  for (size_t i = 0; i < c.normals.size(); ++i)
    if (!is_finite(c.normals[i]) || !(length_squared(c.normals[i]) > 0))
      return fmt::format("normal {} must be finite and non-zero", i);
  for (size_t i = 0; i + 1 < c.normals.size(); ++i)
    if (curve_normal_angle(normalize(c.normals[i]), normalize(c.normals[i + 1])) > std::numbers::pi_v<float> - 1e-3f)
      return fmt::format("normals {} and {} point in opposite directions: the ribbon cannot turn from one to the other",
                         i, i + 1);
  return {};
}

BezierSegments curve_bezier_segments(const CurveShape& c) {
  BezierSegments out;
  const size_t n = c.segment_count();
  out.control.reserve(4 * n);
  out.width.reserve(2 * n);
  const auto& p = c.points;
  for (size_t k = 0; k < n; ++k) {
    CubicSegment cubic;
    if (c.basis == CurveBasis::Bezier) {
      const size_t i = k * size_t(c.degree);
      cubic = c.degree == 2 ? raise_quadratic(p[i], p[i + 1], p[i + 2]) : CubicSegment{p[i], p[i + 1], p[i + 2], p[i + 3]};
    } else {
      cubic = c.degree == 2 ? quadratic_bspline_to_bezier(p[k], p[k + 1], p[k + 2])
                            : cubic_bspline_to_bezier(p[k], p[k + 1], p[k + 2], p[k + 3]);
    }
    out.control.insert(out.control.end(), cubic.begin(), cubic.end());
    // pbrt-v4's Lerp(k / n, width0, width1), in float as pbrt-v4 computes it.
    auto width_at = [&](size_t j) {
      const float t = float(j) / float(n);
      return (1 - t) * c.width0 + t * c.width1;
    };
    out.width.push_back(width_at(k));
    out.width.push_back(width_at(k + 1));
    if (c.type == CurveType::Ribbon) {
      out.normals.push_back(normalize(c.normals[k]));
      out.normals.push_back(normalize(c.normals[k + 1]));
    }
  }
  return out;
}

Normal3 slerp_normal(const Normal3& n0, const Normal3& n1, float u) {
  const float angle = curve_normal_angle(n0, n1);
  if (angle == 0) return n0;
  const float inv_sin = 1 / std::sin(angle);
  return n0 * (std::sin((1 - u) * angle) * inv_sin) + n1 * (std::sin(u * angle) * inv_sin);
}

std::array<Normal3, 4> bezier_normals(const Normal3& n0, const Normal3& n1) {
  // f(1/3) = (8 b0 + 12 b1 + 6 b2 + b3) / 27 and f(2/3) = (b0 + 6 b1 + 12 b2 + 8 b3) / 27, solved for
  // b1 and b2 with b0 = f(0) and b3 = f(1).
  const Normal3 f1 = slerp_normal(n0, n1, 1.0f / 3), f2 = slerp_normal(n0, n1, 2.0f / 3);
  const Normal3 a = f1 * 27 - n0 * 8 - n1, b = f2 * 27 - n0 - n1 * 8;
  return {n0, (a * 2 - b) / 18, (b * 2 - a) / 18, n1};
}

unsigned flat_curve_tessellation(const std::vector<Point3>& control, const std::vector<float>& width) {
  // A polyline of N pieces strays from a cubic Bézier segment by at most max |B''| / (8 N^2), and
  // |B''| <= 6 max_i |p_i - 2 p_(i+1) + p_(i+2)|.
  double pieces = 4;
  for (size_t s = 0; 4 * s + 3 < control.size() && 2 * s + 1 < width.size(); ++s) {
    const Point3* p = &control[4 * s];
    const double bend = std::max(length(p[0] - p[1] * 2 + p[2]), length(p[1] - p[2] * 2 + p[3]));
    const double tolerance = 0.05 * std::max(width[2 * s], width[2 * s + 1]);
    if (tolerance > 0) pieces = std::max(pieces, std::sqrt(0.75 * bend / tolerance));
  }
  return unsigned(std::clamp(std::ceil(pieces), 4.0, 64.0));
}

}  // namespace candela
