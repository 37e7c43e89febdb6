// Motion blur (the paper's sec. 4.2): a black shape moving in front of a white sky, seen by a
// pinhole camera, blurs into the time average of its silhouettes. The renders are compared per image
// column with the analytic time-averaged coverage, within 4 standard errors estimated from the
// render; direct ray queries check the hit reconstruction of moving triangles and spheres.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "candela/base/error.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

// The camera sits at the origin looking down -z with a 90 degree vertical fov on a 64x16 film: at
// depth kDepth one world unit is one pixel, and world x = X is film column 32 + X.
constexpr int kWidth = 64, kHeight = 16;
constexpr float kDepth = 8;
constexpr int kSpp = 256;

SceneDesc sky_scene() {
  SceneDesc d;
  d.film = {kWidth, kHeight, ""};
  d.camera = testing::look_at_camera({0, 0, 0}, {0, 0, -1}, 90);
  d.settings.spp = kSpp;
  d.settings.max_depth = 1;
  d.settings.seed = 7;
  d.materials = {BlackMaterial{}};
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  return d;
}

// A black rectangle at depth kDepth covering every row and the film left of column `edge_column`.
ShapeDesc black_square(float edge_column) {
  ShapeDesc s;
  float right = edge_column - kWidth / 2;
  s.geometry = RectangleShape{{-100, -20, -kDepth}, {right + 100, 0, 0}, {0, 40, 0}};
  s.material = 0;
  s.name = "square";
  return s;
}

// Per column: the mean over its rows of the rendered value and the standard error of that mean.
struct ColumnProfile {
  std::vector<double> mean, standard_error;
};

ColumnProfile column_profile(const Film& film) {
  Image mean = film.mean_image(), variance = film.variance_of_mean_image();
  ColumnProfile p;
  for (int x = 0; x < mean.width; ++x) {
    double sum = 0, var = 0;
    for (int y = 0; y < mean.height; ++y) {
      sum += mean.at(x, y).r;
      var += variance.at(x, y).r;
    }
    p.mean.push_back(sum / mean.height);
    p.standard_error.push_back(std::sqrt(var) / mean.height);
  }
  return p;
}

// The time average over [open, close] of `covered(time)`, by the midpoint rule (or the value at
// `open` for a zero-length shutter).
double time_average(const std::function<double(double)>& covered, double open, double close) {
  if (close <= open) return covered(open);
  const int steps = 20000;
  double sum = 0;
  for (int i = 0; i < steps; ++i) sum += covered(open + (close - open) * (i + 0.5) / steps);
  return sum / steps;
}

// Expected white fraction of column `column` while a black region covers the film left of
// edge(time): one minus the part of the pixel left of the edge, averaged over the shutter.
double expected_edge_column(int column, const std::function<double(double)>& edge, double open, double close) {
  return 1 - time_average([&](double t) { return std::clamp(edge(t) - column, 0.0, 1.0); }, open, close);
}

void expect_profile(const ColumnProfile& rendered, const std::function<double(int)>& expected) {
  for (int x = 0; x < kWidth; ++x) {
    // Columns never or always covered are exact; the others are within 4 standard errors.
    EXPECT_NEAR(rendered.mean[x], expected(x), 4 * rendered.standard_error[x] + 1e-5) << "column " << x;
  }
}

TEST(MotionBlur, MovingSquareGivesBoxFilteredStep) {
  // The square's edge moves D = 16 pixels during the shutter: a linear ramp over 16 columns,
  // rounded by the pixel's box over the one column at each end.
  const float start = 24, D = 16;
  SceneDesc d = sky_scene();
  ShapeDesc square = black_square(start);
  square.to_world_end = Transform::translate({D, 0, 0});
  d.shapes = {square};
  ColumnProfile p = column_profile(testing::render_description(d));
  expect_profile(p, [&](int x) { return expected_edge_column(x, [&](double t) { return start + D * t; }, 0, 1); });
  // The expectation itself, in closed form for column 28: the pixel is covered for a fraction
  // (integral of clamp(x, 0, 1) over x in [-4, 12]) / 16 = 11.5 / 16 of the shutter.
  EXPECT_NEAR(expected_edge_column(28, [&](double t) { return start + D * t; }, 0, 1), 1 - 11.5 / 16, 1e-6);
}

TEST(MotionBlur, AbsoluteTimesMapToTransformTimesAndClamp) {
  // The square moves between times 1 and 2 only; the shutter [0, 2] sees it standing at its start
  // position for the first half.
  const float start = 24, D = 16;
  SceneDesc d = sky_scene();
  d.transform_start_time = 1;
  d.transform_end_time = 2;
  d.camera.shutter_open = 0;
  d.camera.shutter_close = 2;
  ShapeDesc square = black_square(start);
  square.to_world_end = Transform::translate({D, 0, 0});
  d.shapes = {square};
  ColumnProfile p = column_profile(testing::render_description(d));
  auto edge = [&](double t) { return start + D * std::clamp(t - 1, 0.0, 1.0); };
  expect_profile(p, [&](int x) { return expected_edge_column(x, edge, 0, 2); });
}

TEST(MotionBlur, ZeroLengthShutterRendersSharpAtThatTime) {
  const float start = 24, D = 16, time = 0.3f;  // the edge at column 28.8
  SceneDesc d = sky_scene();
  d.camera.shutter_open = d.camera.shutter_close = time;
  ShapeDesc square = black_square(start);
  square.to_world_end = Transform::translate({D, 0, 0});
  d.shapes = {square};
  ColumnProfile p = column_profile(testing::render_description(d));
  for (int x = 0; x < kWidth; ++x) {
    if (x == 28) EXPECT_NEAR(p.mean[x], 0.2, 4 * p.standard_error[x] + 1e-5);
    else EXPECT_EQ(p.mean[x], x < 28 ? 0.0 : 1.0) << "column " << x;
  }
}

TEST(MotionBlur, StaticSceneIsUnchangedByTheShutter) {
  SceneDesc d;
  d.film = {32, 24, ""};
  d.camera = testing::look_at_camera({0, 2, -6}, {0, 0.5f, 0}, 40);
  d.settings.spp = 16;
  d.settings.max_depth = 4;
  d.materials = {DiffuseMaterial{RGB(0.6f)}};
  ShapeDesc floor, ball, box;
  floor.geometry = PlaneShape{};
  ball.geometry = SphereShape{{0, 1, 0}, 1};
  box.geometry = BoxShape{{1.5f, 0, -0.5f}, {2.5f, 1, 0.5f}};
  box.to_world_end = box.to_world;  // an end transform equal to the start is no motion
  floor.material = ball.material = box.material = 0;
  d.shapes = {floor, ball, box};
  d.lights = {PointLight{{2, 4, -3}, RGB(20.0f)}, SkyLight{RGB(0.2f), RGB(0.2f), RGB(0.2f), {0, 1, 0}}};
  Image open_shutter = testing::render_description(d).mean_image();
  d.camera.shutter_open = d.camera.shutter_close = 0.5f;
  Image instant = testing::render_description(d).mean_image();
  // The same samples are drawn either way and static geometry ignores the ray's time.
  EXPECT_EQ(open_shutter.rgb, instant.rgb);
}

// Area of the part of an ellipse (centre xc, semi-axis a along x, b along y) between x0 and x1.
double ellipse_strip_area(double xc, double a, double b, double x0, double x1) {
  auto F = [](double u) {
    u = std::clamp(u, -1.0, 1.0);
    return u * std::sqrt(1 - u * u) + std::asin(u);
  };
  return a * b * (F((x1 - xc) / a) - F((x0 - xc) / a));
}

TEST(MotionBlur, MovingSphereCoverageMatchesTimeAveragedSilhouette) {
  // A sphere of radius R moves along x at depth kDepth. Its silhouette on the image plane z = 1 is
  // the ellipse cut from the cone of half-angle alpha = asin(R / distance) around the direction to
  // its centre (at angle theta to the view axis): with A = cos^2 theta - sin^2 alpha, the centre is
  // at x = sin theta cos theta / A and the semi-axes are sin alpha cos alpha / A and sin alpha / sqrt(A).
  const double R = 2, x_start = -6, x_end = 6;
  SceneDesc d = sky_scene();
  d.settings.spp = 64;
  ShapeDesc ball{.geometry = SphereShape{{float(x_start), 0, -kDepth}, float(R)}, .material = 0,
                 .to_world_end = Transform::translate({float(x_end - x_start), 0, 0})};
  d.shapes = {ball};
  ColumnProfile p = column_profile(testing::render_description(d));

  const double pixel = 1.0 / 8;  // on the image plane: tan(45 degrees) over 8 rows
  auto strip_area = [&](int column, double t) {
    double x = x_start + (x_end - x_start) * t;
    double distance = std::sqrt(x * x + kDepth * kDepth);
    double sin_a = R / distance, cos_a = std::sqrt(1 - sin_a * sin_a);
    double sin_t = x / distance, cos_t = kDepth / distance;
    double A = cos_t * cos_t - sin_a * sin_a;
    double x0 = column * pixel - 4;
    return ellipse_strip_area(sin_t * cos_t / A, sin_a * cos_a / A, sin_a / std::sqrt(A), x0, x0 + pixel);
  };
  double total_rendered = 0, total_expected = 0, total_variance = 0;
  for (int x = 0; x < kWidth; ++x) {
    // A column spans the image plane's full height 2: its white fraction is one minus the
    // time-averaged silhouette area inside it over the column's area.
    double covered = time_average([&](double t) { return strip_area(x, t); }, 0, 1) / (pixel * 2);
    EXPECT_NEAR(p.mean[x], 1 - covered, 4 * p.standard_error[x] + 1e-5) << "column " << x;
    total_rendered += p.mean[x];
    total_expected += 1 - covered;
    total_variance += p.standard_error[x] * p.standard_error[x];
  }
  EXPECT_NEAR(total_rendered, total_expected, 4 * std::sqrt(total_variance));
}

// ------------------------------------------------------------------ direct ray queries

Ray ray_at(const Point3& o, const Vec3& d, float time) {
  return Ray{o, d, std::numeric_limits<float>::infinity(), time};
}

TEST(MotionBlurHits, MovingTrianglesAreInterpolatedAtTheRayTime) {
  // A quad with shading normals turning a quarter about y between times 2 and 4: at time 3 the
  // matrix is the average of the two, mapping the plane z = 0 to the plane with normal (1, 0, 1).
  SceneDesc d;
  d.transform_start_time = 2;
  d.transform_end_time = 4;
  TriangleMesh quad;
  quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  quad.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  ShapeDesc shape{.geometry = MeshShape{quad}, .to_world_end = Transform::rotate(90, {0, 1, 0})};
  d.shapes = {shape};
  Scene scene(d);

  Normal3 end_normal = normalize(shape.to_world_end->normal({0, 0, 1}));
  Normal3 expected = normalize(Normal3(0, 0, 1) + end_normal);
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(ray_at({0.2f, 0.1f, 5}, {0, 0, -1}, 3), hit));
  // The plane through the origin with normal `expected`: z = -x * n.x / n.z.
  EXPECT_NEAR(hit.p.x, 0.2f, 1e-5f);
  EXPECT_NEAR(hit.p.z, -0.2f * expected.x / expected.z, 1e-5f);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(hit.ng[i], expected[i], 1e-5f);
    EXPECT_NEAR(hit.ns[i], expected[i], 1e-5f);
  }
  // Before the start time the quad is at its start transform.
  ASSERT_TRUE(scene.intersect(ray_at({0.2f, 0.1f, 5}, {0, 0, -1}, 0), hit));
  EXPECT_NEAR(hit.p.z, 0, 1e-6f);
  EXPECT_NEAR(hit.ns.z, 1, 1e-6f);
}

// The unit sphere at the origin at the shutter's opening, transformed by `end` at its close.
Scene unit_sphere_moving_to(const Transform& end) {
  ShapeDesc ball{.geometry = SphereShape{{0, 0, 0}, 1}, .to_world_end = end};
  SceneDesc d;
  d.shapes = {ball};
  return Scene(d);
}

TEST(MotionBlurHits, MovingSphereIsIntersectedAtTheRayTime) {
  Scene scene = unit_sphere_moving_to(Transform::translate({4, 0, 0}));
  const Point3 o(2, 0.5f, 10);
  const Vec3 down(0, 0, -1);
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(ray_at(o, down, 0.5f), hit));  // centre at x = 2
  EXPECT_NEAR(hit.p.z, std::sqrt(0.75f), 1e-5f);
  EXPECT_NEAR(hit.ng.y, 0.5f, 1e-5f);
  EXPECT_NEAR(hit.t, 10 - std::sqrt(0.75f), 1e-5f);
  EXPECT_FALSE(scene.intersect(ray_at(o, down, 0), hit));
  EXPECT_FALSE(scene.intersect(ray_at(o, down, 1), hit));
  EXPECT_TRUE(scene.occluded(ray_at(o, down, 0.5f)));
  EXPECT_FALSE(scene.occluded(ray_at(o, down, 0.1f)));
}

TEST(MotionBlurHits, SphereGrowingNonUniformlyStaysInsideItsBounds) {
  // Scaled by 1 to 3 along x: at time 0.5 an ellipsoid with x semi-axis 2.
  Scene scene = unit_sphere_moving_to(Transform::scale({3, 1, 1}));
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(ray_at({1.9f, 0, 10}, {0, 0, -1}, 0.5f), hit));
  EXPECT_NEAR(hit.p.z, std::sqrt(1 - 0.95f * 0.95f), 1e-4f);
  EXPECT_FALSE(scene.intersect(ray_at({2.1f, 0, 10}, {0, 0, -1}, 0.5f), hit));
  EXPECT_FALSE(scene.intersect(ray_at({1.9f, 0, 10}, {0, 0, -1}, 0), hit));
}

void expect_scene_error(const SceneDesc& d, const std::string& fragment) {
  try {
    Scene scene(d);
    FAIL() << "expected a SceneError containing '" << fragment << "'";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(MotionBlurErrors, MovingLightsAndPlanesAreRejected) {
  SceneDesc d;
  ShapeDesc lamp{.geometry = RectangleShape{}, .emission = AreaEmission{},
                 .to_world_end = Transform::translate({1, 0, 0}), .name = "lamp"};
  d.shapes = {lamp};
  expect_scene_error(d, "(\"lamp\"): area lights must not move");
  lamp.geometry = SphereShape{};
  d.shapes = {lamp};
  expect_scene_error(d, "(\"lamp\"): area lights must not move");

  ShapeDesc floor{.geometry = PlaneShape{}, .to_world_end = Transform::translate({0, 1, 0}), .name = "floor"};
  d.shapes = {floor};
  expect_scene_error(d, "(\"floor\"): an infinite plane must not move");

  ShapeDesc box{.geometry = BoxShape{}, .to_world_end = Transform::scale({-1, 1, 1}), .name = "box"};
  d.shapes = {box};
  expect_scene_error(d, "(\"box\"): the end transform mirrors the shape");
}

}  // namespace
}  // namespace candela
