// Curves (pbrt-v4's Shape "curve") through the whole Scene on Embree's curve primitives: a flat curve
// and a tube are hit at the points and with the (u, v), tangent and normal that pbrt-v4's geometry
// gives them (computed here from the curve itself); their silhouettes are their width, tapered where
// the width is; rays leaving a tube do not meet it again; ribbons turn with their normals; transforms,
// motion and instancing move them; what cannot be a curve is refused; the JSON reader and writer keep
// every curve.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "candela/base/error.h"
#include "candela/geometry/curves.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

constexpr float kCurveInf = std::numeric_limits<float>::infinity();

// A straight cubic segment along x from (-1, 0, 0) to (1, 0, 0), its control points evenly spaced (so
// u = (x + 1) / 2).
CurveShape straight_curve(CurveType type, float width0 = 0.2f, float width1 = 0.2f) {
  CurveShape c;
  c.points = {{-1, 0, 0}, {-1.0f / 3, 0, 0}, {1.0f / 3, 0, 0}, {1, 0, 0}};
  c.type = type;
  c.width0 = width0;
  c.width1 = width1;
  if (type == CurveType::Ribbon) c.normals = {{0, 0, 1}, {0, 0, 1}};
  return c;
}

SceneDesc curve_scene(const CurveShape& c, const Transform& to_world = Transform(), bool reverse = false) {
  SceneDesc d;
  ShapeDesc s;
  s.geometry = c;
  s.to_world = to_world;
  s.reverse_orientation = reverse;
  d.shapes = {s};
  return d;
}

void expect_curve_vec_near(const Vec3& a, const Vec3& b, float tolerance, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tolerance) << what;
  EXPECT_NEAR(a.y, b.y, tolerance) << what;
  EXPECT_NEAR(a.z, b.z, tolerance) << what;
}

// A ray down -z through (x, y) from z = 5.
Ray curve_probe_ray(float x, float y, float time = 0) { return Ray{{x, y, 5}, {0, 0, -1}, kCurveInf, time}; }

TEST(CurveShape, FlatCurveFacesTheRayWithPbrtsParameterisation) {
  for (bool reverse : {false, true}) {
    Scene scene(curve_scene(straight_curve(CurveType::Flat), Transform(), reverse));
    for (float y : {-0.09f, -0.05f, 0.0f, 0.05f, 0.09f}) {
      const std::string what = "y = " + std::to_string(y) + (reverse ? " reversed" : "");
      SurfaceHit hit;
      ASSERT_TRUE(scene.intersect(curve_probe_ray(0.3f, y), hit)) << what;
      EXPECT_NEAR(hit.t, 5, 1e-4f) << what;
      expect_curve_vec_near(hit.p, Point3(0.3f, y, 0), 1e-4f, what);
      EXPECT_NEAR(hit.uv.x, 0.65f, 1e-3f) << what;
      // v grows along cross(d, tangent) = (0, -1, 0): 0.5 - y / width.
      EXPECT_NEAR(hit.uv.y, 0.5f - y / 0.2f, 2e-3f) << what;
      expect_curve_vec_near(hit.dpdu, Vec3(2, 0, 0), 1e-4f, what);
      expect_curve_vec_near(hit.dpdv, Vec3(0, -0.2f, 0), 1e-4f, what);
      // Facing back along the ray, flipped by reverse orientation.
      expect_curve_vec_near(hit.ng, Normal3(0, 0, reverse ? -1.0f : 1.0f), 1e-5f, what);
      EXPECT_EQ(hit.ns, hit.ng) << what;
    }
    SurfaceHit miss;
    EXPECT_FALSE(scene.intersect(curve_probe_ray(0.3f, 0.11f), miss));
    EXPECT_FALSE(scene.intersect(curve_probe_ray(0.3f, -0.11f), miss));
    EXPECT_FALSE(scene.intersect(curve_probe_ray(1.05f, 0), miss));  // beyond its end
    EXPECT_TRUE(scene.occluded(curve_probe_ray(0.3f, 0)));
  }
}

TEST(CurveShape, TubeIsRoundWithItsSilhouetteTheWidth) {
  Scene scene(curve_scene(straight_curve(CurveType::Cylinder)));
  for (float y : {-0.099f, -0.06f, 0.0f, 0.05f, 0.099f}) {
    const std::string what = "y = " + std::to_string(y);
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(curve_probe_ray(-0.4f, y), hit)) << what;
    const float z = std::sqrt(0.01f - y * y);
    EXPECT_NEAR(hit.t, 5 - z, 2e-3f) << what;
    expect_curve_vec_near(hit.ng, Normal3(0, y, z) / 0.1f, 2e-2f, what);
    EXPECT_NEAR(hit.uv.x, 0.3f, 1e-3f) << what;
    EXPECT_NEAR(hit.uv.y, 0.5f - y / 0.2f, 2e-3f) << what;  // pbrt-v4's v: h = 2 v - 1 across the fibre
    expect_curve_vec_near(hit.dpdu, Vec3(2, 0, 0), 1e-4f, what);
    EXPECT_NEAR(dot(hit.dpdv, hit.ng), 0, 1e-4f) << what;  // around the tube, towards growing v
    EXPECT_LT(hit.dpdv.y, 0) << what;
  }
  SurfaceHit miss;
  EXPECT_FALSE(scene.intersect(curve_probe_ray(-0.4f, 0.101f), miss));
  EXPECT_FALSE(scene.intersect(curve_probe_ray(-0.4f, -0.101f), miss));
  // Seen along y, it is as wide in z.
  SurfaceHit side;
  ASSERT_TRUE(scene.intersect(Ray{{0, -5, 0.095f}, {0, 1, 0}, kCurveInf, 0}, side));
  EXPECT_FALSE(scene.intersect(Ray{{0, -5, 0.105f}, {0, 1, 0}, kCurveInf, 0}, miss));
}

TEST(CurveShape, WidthTapersFromWidth0ToWidth1) {
  for (CurveType type : {CurveType::Flat, CurveType::Cylinder}) {
    Scene scene(curve_scene(straight_curve(type, 0.25f, 0.05f)));
    for (float u : {0.1f, 0.5f, 0.9f}) {
      const float half = 0.5f * (0.25f + u * (0.05f - 0.25f)), x = 2 * u - 1;
      SurfaceHit hit;
      EXPECT_TRUE(scene.intersect(curve_probe_ray(x, 0.97f * half), hit)) << u;
      EXPECT_FALSE(scene.intersect(curve_probe_ray(x, 1.03f * half), hit)) << u;
    }
  }
}

TEST(CurveShape, RaysLeavingATubeDoNotMeetItAgain) {
  Scene scene(curve_scene(straight_curve(CurveType::Cylinder)));
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(curve_probe_ray(0.2f, 0.03f), hit));
  // Outwards, inwards (through the fibre) and grazing.
  for (Vec3 dir : {Vec3(0, 0.2f, 1), Vec3(0.1f, -0.3f, -1), hit.ng * -1.0f, normalize(cross(hit.ng, Vec3(1, 0, 0)))}) {
    const Ray leaving{offset_ray_origin(hit.p, hit.ng, dir), normalize(dir), kCurveInf, 0};
    SurfaceHit again;
    EXPECT_FALSE(scene.intersect(leaving, again)) << dir.x << " " << dir.y << " " << dir.z;
    EXPECT_FALSE(scene.occluded(leaving));
  }
  // A ray from outside still meets it, from either side.
  EXPECT_TRUE(scene.occluded(Ray{{0.2f, 0, -5}, {0, 0, 1}, kCurveInf, 0}));
  ASSERT_TRUE(scene.intersect(Ray{{0.2f, 0, -5}, {0, 0, 1}, kCurveInf, 0}, hit));
  expect_curve_vec_near(hit.ng, Normal3(0, 0, -1), 1e-3f, "underside");
}

TEST(CurveShape, RaysLeavingAFlatCurveOrRibbonDoNotMeetItAgain) {
  for (CurveType type : {CurveType::Flat, CurveType::Ribbon}) {
    Scene scene(curve_scene(straight_curve(type)));
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(curve_probe_ray(0.2f, 0.03f), hit));
    for (Vec3 dir : {Vec3(0, 0.2f, 1), Vec3(0.1f, -0.3f, -1), Vec3(0.3f, 1, 0.05f), Vec3(-0.5f, -1, -0.02f)}) {
      const Ray leaving{offset_ray_origin(hit.p, hit.ng, dir), normalize(dir), kCurveInf, 0};
      SurfaceHit again;
      EXPECT_FALSE(scene.intersect(leaving, again)) << int(type) << ": " << dir.x << " " << dir.y << " " << dir.z;
    }
  }
}

TEST(CurveShape, RibbonTurnsWithItsNormals) {
  // Flat in the xy plane: seen from above and below with the normal +z.
  Scene flat(curve_scene(straight_curve(CurveType::Ribbon)));
  for (float dir : {-1.0f, 1.0f}) {
    SurfaceHit hit;
    ASSERT_TRUE(flat.intersect(Ray{{0.3f, 0.05f, -5 * dir}, {0, 0, dir}, kCurveInf, 0}, hit)) << dir;
    EXPECT_NEAR(hit.t, 5, 1e-3f);
    expect_curve_vec_near(hit.ng, Normal3(0, 0, 1), 1e-4f, "ribbon normal");
    EXPECT_NEAR(hit.uv.x, 0.65f, 1e-3f);
    // v grows along cross(d, tangent): towards -y seen from above, +y from below.
    EXPECT_NEAR(hit.uv.y, 0.5f + dir * 0.25f, 1e-2f) << dir;
    SurfaceHit miss;
    EXPECT_FALSE(flat.intersect(Ray{{0.3f, 0.11f, -5 * dir}, {0, 0, dir}, kCurveInf, 0}, miss));
  }
  // Turned from +z at its start to +y at its end: at u = 0.5 the band is tilted by 45 degrees, so a
  // ray down -z sees it cos 45 as wide.
  CurveShape turned = straight_curve(CurveType::Ribbon);
  turned.normals = {{0, 0, 1}, {0, 1, 0}};
  Scene scene(curve_scene(turned));
  const float half = 0.1f * std::sqrt(0.5f);
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(curve_probe_ray(0, 0.9f * half), hit));
  // The band's own normal, tilted along the tangent where the band twists (a helicoid's: by about the
  // offset 0.09 times the twist rate pi / 4 per unit length).
  EXPECT_NEAR(std::abs(hit.ng.x), 0.09f * kPi / 4, 2e-2f);
  EXPECT_NEAR(dot(hit.ng, normalize(Normal3(0, 1, 1))), std::sqrt(1 - sqr(0.09f * kPi / 4)), 1e-2f);
  EXPECT_NEAR(hit.uv.y, 0.05f, 3e-2f);
  EXPECT_FALSE(scene.intersect(curve_probe_ray(0, 1.1f * half), hit));
}

TEST(CurveShape, BsplinesAndQuadraticsAreTheirBezierSegments) {
  CurveShape c;
  c.points = {{-1, 0, 0}, {-0.5f, 1, 0}, {0, -1, 0}, {0.5f, 1, 0}, {1, 0, 0}};
  c.basis = CurveBasis::BSpline;
  c.type = CurveType::Cylinder;
  c.width0 = c.width1 = 0.05f;
  const BezierSegments segments = curve_bezier_segments(c);
  Scene scene(curve_scene(c));
  for (size_t k = 0; k < 2; ++k) {
    const std::array<Point3, 4> cp = {segments.control[4 * k], segments.control[4 * k + 1],
                                      segments.control[4 * k + 2], segments.control[4 * k + 3]};
    const Point3 on = bezier_point(cp, 0.5f);
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(curve_probe_ray(on.x, on.y), hit)) << k;
    EXPECT_EQ(hit.primitive, k);
    EXPECT_NEAR(hit.uv.x, 0.5f, 1e-2f) << k;
    EXPECT_NEAR(hit.p.z, 0.025f, 1e-3f) << k;
  }
}

TEST(CurveShape, TransformsPlaceTheCurveAndScaleItsWidth) {
  const Transform T = Transform::translate({0, 1, 0}) * Transform::rotate(90, {0, 0, 1}) * Transform::scale(Vec3(2));
  Scene scene(curve_scene(straight_curve(CurveType::Cylinder), T));
  // Now along y from (0, -1, 0) to (0, 3, 0), radius 0.2.
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(curve_probe_ray(0.19f, 2), hit));
  EXPECT_NEAR(hit.uv.x, 0.75f, 2e-3f);
  expect_curve_vec_near(hit.dpdu, Vec3(0, 4, 0), 1e-3f, "tangent");
  EXPECT_FALSE(scene.intersect(curve_probe_ray(0.21f, 2), hit));
}

TEST(CurveShape, MovingCurvesAreWhereTheyAreAtTheRaysTime) {
  SceneDesc d = curve_scene(straight_curve(CurveType::Flat));
  d.shapes[0].to_world_end = Transform::translate({0, 1, 0});
  Scene scene(d);
  for (float time : {0.0f, 0.5f, 1.0f}) {
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(curve_probe_ray(0.3f, time + 0.05f, time), hit)) << time;
    EXPECT_NEAR(hit.uv.y, 0.25f, 1e-2f) << time;
    EXPECT_FALSE(scene.intersect(curve_probe_ray(0.3f, time + 0.15f, time), hit)) << time;
  }
}

TEST(CurveShape, InstancedCurvesAreHitInTheirInstancesPlace) {
  SceneDesc d;
  ObjectDesc object;
  ShapeDesc s;
  s.geometry = straight_curve(CurveType::Cylinder);
  object.shapes = {s};
  d.objects = {object};
  for (float x : {-3.0f, 3.0f}) {
    InstanceDesc instance;
    instance.to_world = Transform::translate({x, 0, 0});
    d.instances.push_back(instance);
  }
  Scene scene(d);
  for (float x : {-3.3f, 2.7f}) {
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(curve_probe_ray(x, 0.05f), hit)) << x;
    EXPECT_NEAR(hit.uv.x, 0.35f, 2e-3f) << x;
    EXPECT_NEAR(hit.uv.y, 0.25f, 2e-3f) << x;
    expect_curve_vec_near(hit.ng, normalize(Normal3(0, 0.05f, std::sqrt(0.0075f))), 2e-2f, "instanced normal");
  }
}

TEST(CurveShape, EmittersAndMediumBoundariesAreRefused) {
  SceneDesc emitting = curve_scene(straight_curve(CurveType::Flat));
  emitting.shapes[0].emission = AreaEmission{};
  try {
    Scene scene(emitting);
    ADD_FAILURE() << "an emissive curve was built";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("a curve cannot emit light"), std::string::npos) << e.what();
  }
  SceneDesc bad = curve_scene(straight_curve(CurveType::Flat));
  std::get<CurveShape>(bad.shapes[0].geometry).points.pop_back();
  try {
    Scene scene(bad);
    ADD_FAILURE() << "a curve of 3 points was built";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("needs 3k + 1 (4, 7, 10, ...) points, got 3"), std::string::npos) << e.what();
  }
}

std::string curve_json_error(const std::string& shape) {
  try {
    read_json_scene(R"({"shapes": [)" + shape + "]}", "scene.json", ".");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(CurveShape, JsonReaderReadsEveryKey) {
  const SceneDesc d = read_json_scene(R"({"shapes": [
      {"type": "curve", "points": [[0, 0, 0], [1, 1, 0], [2, 0, 0]], "basis": "bspline", "degree": 2,
       "curve_type": "ribbon", "width0": 0.5, "width1": 0.25, "normals": [[0, 0, 1], [0, 1, 1]]},
      {"type": "curve", "points": [[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 0, 0]], "width": 0.1}]})",
                                      "scene.json", ".");
  ASSERT_EQ(d.shapes.size(), 2u);
  const auto& ribbon = std::get<CurveShape>(d.shapes[0].geometry);
  EXPECT_EQ(ribbon.points.size(), 3u);
  EXPECT_EQ(ribbon.basis, CurveBasis::BSpline);
  EXPECT_EQ(ribbon.degree, 2);
  EXPECT_EQ(ribbon.type, CurveType::Ribbon);
  EXPECT_EQ(ribbon.width0, 0.5f);
  EXPECT_EQ(ribbon.width1, 0.25f);
  EXPECT_EQ(ribbon.normals.size(), 2u);
  const auto& plain = std::get<CurveShape>(d.shapes[1].geometry);
  EXPECT_EQ(plain.basis, CurveBasis::Bezier);
  EXPECT_EQ(plain.degree, 3);
  EXPECT_EQ(plain.type, CurveType::Flat);
  EXPECT_EQ(plain.width0, 0.1f);
  EXPECT_EQ(plain.width1, 0.1f);

  const std::string four = R"("points": [[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 0, 0]])";
  EXPECT_NE(curve_json_error(R"({"type": "curve", "points": [[0, 0, 0], [1, 1, 0]]})")
                .find("a degree 3 Bézier curve needs 3k + 1 (4, 7, 10, ...) points, got 2"),
            std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "curve_type": "ribbon"})").find("needs 2 normals"),
            std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "normals": [[0, 0, 1], [0, 0, 1]]})")
                .find("only a ribbon has normals"),
            std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "curve_type": "tube"})")
                .find("expected one of: flat, cylinder, ribbon"),
            std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "basis": "catmullrom"})").find("bezier, bspline"),
            std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "degree": 4})").find("[2, 3]"), std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "width": 1, "width0": 2})").find("not both"),
            std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve", )" + four + R"(, "width1": -1})").find(">= 0"), std::string::npos);
  EXPECT_NE(curve_json_error(R"({"type": "curve"})").find("\"points\""), std::string::npos);
}

TEST(CurveShape, JsonWriterRoundTripsEveryCurve) {
  SceneDesc scene;
  CurveShape ribbon;
  ribbon.points = {{0.1f, 0.2f, 0.3f}, {1, 1.5f, -0.25f}, {2, 0, 1e-7f}, {3.25f, 0, 0}, {4, 1, 1}};
  ribbon.basis = CurveBasis::BSpline;
  ribbon.degree = 3;
  ribbon.type = CurveType::Ribbon;
  ribbon.width0 = 0.3f;
  ribbon.width1 = 0.01f;
  ribbon.normals = {{0, 0, 1}, {0, 0.6f, 0.8f}, {1, 0, 0}};
  CurveShape tube = straight_curve(CurveType::Cylinder, 0.25f, 0.05f);
  tube.degree = 3;
  for (const CurveShape& c : {ribbon, tube}) {
    ShapeDesc s;
    s.geometry = c;
    s.to_world = Transform::translate({1, 2, 3});
    s.reverse_orientation = true;
    scene.shapes.push_back(s);
  }
  const SceneDesc back = read_json_scene(scene_to_json(scene), "converted.json", ".");
  ASSERT_EQ(back.shapes.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const auto& a = std::get<CurveShape>(scene.shapes[i].geometry);
    const auto& b = std::get<CurveShape>(back.shapes[i].geometry);
    EXPECT_EQ(b.points, a.points) << i;
    EXPECT_EQ(b.normals, a.normals) << i;
    EXPECT_EQ(b.basis, a.basis) << i;
    EXPECT_EQ(b.degree, a.degree) << i;
    EXPECT_EQ(b.type, a.type) << i;
    EXPECT_EQ(b.width0, a.width0) << i;
    EXPECT_EQ(b.width1, a.width1) << i;
    EXPECT_EQ(back.shapes[i].to_world, scene.shapes[i].to_world) << i;
    EXPECT_TRUE(back.shapes[i].reverse_orientation) << i;
  }
}

}  // namespace
}  // namespace candela
