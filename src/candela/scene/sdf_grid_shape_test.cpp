// SDF grid shapes through the whole renderer: a sphere's signed distance sampled on a grid, written
// as a Mitsuba .vol file, read back and traced through Scene and Embree, against the analytic sphere;
// rays from inside, along voxel faces and edges; transformed, instanced and moving grids; smooth and
// analytic normals; the JSON and Mitsuba readers, the JSON writer, and the scenes that are refused.
//
// Tolerances come from the grid spacing h = 1 / (n - 1). The sphere's distance |p - c| - r has the
// Hessian (I - n n^T) / |p - c|, so near the surface its second derivatives are at most
// kappa = 1 / (r - sqrt(3) h) (the nearest a voxel holding surface comes to the centre). Linear
// interpolation along an axis is off by at most h^2 / 8 times the second derivative, so the trilinear
// interpolant is within 3 h^2 kappa / 8 of the distance: the surface found lies within that of the
// sphere (the distance has unit gradient). Each partial derivative of the interpolant is a difference
// quotient across a voxel, off by at most h kappa / 2 per component, sqrt(3) h kappa / 2 in all: the
// bound on the normals' error (twice that for the smooth normal, whose differences reach into the
// neighbouring voxels).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "candela/geometry/sdf_grid.h"
#include "candela/base/error.h"
#include "candela/io/json_writer.h"
#include "candela/io/mitsuba_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/math/frame.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

constexpr int kSamples = 33;  // h = 1/32: sample planes fall on exact binary fractions
constexpr double kRadius = 0.3;
const Point3 kCenter(0.5f);

struct Tolerances {
  double h, kappa, position, normal, smooth_normal;
};

Tolerances tolerances(int n, double radius) {
  Tolerances t;
  t.h = 1.0 / (n - 1);
  t.kappa = 1 / (radius - std::sqrt(3.0) * t.h);
  t.position = 3 * t.h * t.h * t.kappa / 8;
  t.normal = std::sqrt(3.0) * t.h * t.kappa / 2;
  t.smooth_normal = 2 * t.normal;
  return t;
}

// One folder per test process: ctest runs these tests in parallel processes, which would otherwise
// write and read the same files at once.
fs::path temp_dir() {
  fs::path dir = fs::temp_directory_path() / ("candela_sdf_shape_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// The sphere (kCenter, radius) as a .vol file of n^3 samples over [0,1]^3.
fs::path sphere_vol(int n, double radius) {
  VolumeGrid grid;
  grid.resolution = {n, n, n};
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double dx = double(x) / (n - 1) - 0.5, dy = double(y) / (n - 1) - 0.5, dz = double(z) / (n - 1) - 0.5;
        grid.values.push_back(float(std::sqrt(dx * dx + dy * dy + dz * dz) - radius));
      }
  const fs::path file = temp_dir() / fmt::format("sphere_{}_{}.vol", n, radius);
  write_volume_grid(file, grid);
  return file;
}

SdfGridShape sphere_grid(SdfNormals normals = SdfNormals::Analytic) {
  return read_sdf_grid_file(sphere_vol(kSamples, kRadius), {"test", 0, 0, {}}, normals);
}

SceneDesc single_shape(const SdfGridShape& grid, const Transform& to_world = {}) {
  SceneDesc d;
  ShapeDesc s;
  s.geometry = grid;
  s.to_world = to_world;
  d.shapes = {s};
  return d;
}

double angle_error(const Vec3& a, const Vec3& b) { return length(a - b); }

// A ray towards the sphere along a random direction, passing the centre at `impact` (object space).
struct AimedRay {
  Ray ray;
  double impact;  // distance of the line from the centre
  double t_enter;  // where it enters the sphere (impact < radius)
};

AimedRay aimed_ray(Rng& rng, double max_impact) {
  const Vec3 w = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
  const Frame frame(w);
  const double impact = max_impact * std::sqrt(rng.next_float());
  const double phi = 2 * kPi * rng.next_float();
  const Vec3 offset = (frame.s * float(std::cos(phi)) + frame.t * float(std::sin(phi))) * float(impact);
  const float back = 2;
  AimedRay a{Ray{kCenter + offset - w * back, w}, impact, 0};
  a.t_enter = impact < kRadius ? back - std::sqrt(kRadius * kRadius - impact * impact) : 0;
  return a;
}

TEST(SdfGridShape, SphereGridMatchesTheAnalyticSphere) {
  const Tolerances tol = tolerances(kSamples, kRadius);
  Scene scene(single_shape(sphere_grid()));
  Rng rng(11, 12);
  double worst_radius = 0, worst_t = 0, worst_normal = 0;
  int hits = 0, misses = 0;
  for (int i = 0; i < 20000; ++i) {
    const AimedRay a = aimed_ray(rng, 1.2 * kRadius);
    SurfaceHit hit;
    const bool found = scene.intersect(a.ray, hit);
    const std::string what = fmt::format("ray {} (impact {:.5f})", i, a.impact);
    if (a.impact < kRadius - tol.position) {
      ASSERT_TRUE(found) << what;
    } else if (a.impact > kRadius + tol.position) {
      ASSERT_FALSE(found) << what << " hit at " << hit.t;
    }
    if (!found) {
      ++misses;
      continue;
    }
    ++hits;
    // On the sphere to within the interpolation error (and float rounding of the point).
    const Vec3 from_center = hit.p - kCenter;
    const double radius_error = std::abs(length(from_center) - kRadius);
    EXPECT_LE(radius_error, tol.position + 1e-6) << what;
    worst_radius = std::max(worst_radius, radius_error);
    const Normal3 exact = normalize(from_center);
    // The distance along the ray is off by the surface error over the cosine of incidence.
    const double cosine = -dot(exact, a.ray.direction);
    if (cosine > 0.2) {
      const double t_error = std::abs(hit.t - a.t_enter);
      EXPECT_LE(t_error, tol.position / cosine + 1e-5) << what;
      worst_t = std::max(worst_t, t_error * cosine);
    }
    const double normal_error = angle_error(hit.ng, exact);
    EXPECT_LE(normal_error, tol.normal) << what;
    worst_normal = std::max(worst_normal, normal_error);
    EXPECT_EQ(hit.ns, hit.ng) << what;  // analytic shading normals
    EXPECT_EQ(hit.uv.x, 0);
    EXPECT_EQ(hit.uv.y, 0);
    EXPECT_NEAR(dot(hit.dpdu, hit.ns), 0, 1e-5);
    EXPECT_NEAR(dot(hit.dpdv, hit.ns), 0, 1e-5);
  }
  std::printf("h %.4f: %d hits, %d misses; off the sphere by at most %.2e (bound %.2e), along rays %.2e x cos, "
              "normals by %.3f (bound %.3f)\n",
              tol.h, hits, misses, worst_radius, tol.position, worst_t, worst_normal, tol.normal);
  EXPECT_GT(hits, 10000);
  EXPECT_GT(misses, 2000);
}

TEST(SdfGridShape, SmoothAndAnalyticNormalsAreBothCloseToTheSpheres) {
  const Tolerances tol = tolerances(kSamples, kRadius);
  for (SdfNormals mode : {SdfNormals::Analytic, SdfNormals::Smooth}) {
    Scene scene(single_shape(sphere_grid(mode)));
    Rng rng(13, 14);
    double worst = 0, total = 0;
    int count = 0;
    for (int i = 0; i < 5000; ++i) {
      const AimedRay a = aimed_ray(rng, 0.95 * kRadius);
      SurfaceHit hit;
      ASSERT_TRUE(scene.intersect(a.ray, hit)) << i;
      const double error = angle_error(hit.ns, normalize(hit.p - kCenter));
      worst = std::max(worst, error);
      total += error;
      ++count;
      EXPECT_GT(dot(hit.ns, hit.ng), 0) << i;
    }
    const bool smooth = mode == SdfNormals::Smooth;
    std::printf("%s normals: mean error %.4f, worst %.4f (bound %.4f)\n", smooth ? "smooth" : "analytic",
                total / count, worst, smooth ? tol.smooth_normal : tol.normal);
    EXPECT_LE(worst, smooth ? tol.smooth_normal : tol.normal);
  }
}

TEST(SdfGridShape, RaysFromInsideFindTheSurfaceOnTheWayOut) {
  const Tolerances tol = tolerances(kSamples, kRadius);
  Scene scene(single_shape(sphere_grid()));
  Rng rng(15, 16);
  for (int i = 0; i < 3000; ++i) {
    // A start well inside (beyond the surface error), any direction.
    const Vec3 w = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3 u = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    const double depth = (kRadius - 2 * tol.position) * std::cbrt(rng.next_float());
    const Point3 origin = kCenter + u * float(depth);
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(Ray{origin, w}, hit)) << i;
    // The exit of the line from the sphere.
    const double b = dot(origin - kCenter, w), c = length_squared(origin - kCenter) - kRadius * kRadius;
    const double t_exit = -b + std::sqrt(b * b - c);
    const double cosine = dot(normalize(hit.p - kCenter), w);
    EXPECT_NEAR(hit.t, t_exit, tol.position / cosine + 1e-5) << i;
    EXPECT_GT(dot(hit.ng, w), 0) << i << ": the normal points out, along the leaving ray";
  }
}

TEST(SdfGridShape, RaysAlongVoxelFacesAndEdgesLeaveNoHoles) {
  const Tolerances tol = tolerances(kSamples, kRadius);
  Scene scene(single_shape(sphere_grid()));
  const float h = 1.0f / (kSamples - 1);  // exact: sample planes are at multiples of h
  int checked = 0;
  const auto check = [&](const Ray& ray, const std::string& what) {
    const Vec3 d = normalize(ray.direction);
    const Vec3 to_center = kCenter - ray.origin;
    const double impact = length(to_center - d * dot(to_center, d));
    SurfaceHit hit;
    const bool found = scene.intersect(ray, hit);
    if (impact < kRadius - tol.position) {
      EXPECT_TRUE(found) << what << " (impact " << impact << ")";
    } else if (impact > kRadius + tol.position) {
      EXPECT_FALSE(found) << what << " (impact " << impact << ")";
    }
    ++checked;
  };
  // Along every voxel edge parallel to each axis (both coordinates on sample planes), both ways.
  for (int axis = 0; axis < 3; ++axis)
    for (int j = 4; j <= 28; ++j)
      for (int k = 4; k <= 28; ++k)
        for (float sign : {1.0f, -1.0f}) {
          Point3 origin(0.0f);
          Vec3 d(0.0f);
          origin[(axis + 1) % 3] = float(j) * h;
          origin[(axis + 2) % 3] = float(k) * h;
          origin[axis] = sign > 0 ? -0.5f : 1.5f;
          d[axis] = sign;
          check(Ray{origin, d}, fmt::format("along the edge axis {} at ({}, {}) sign {}", axis, j, k, sign));
        }
  // Fans lying in a sample plane (on voxel faces all the way), from a point on a voxel edge.
  for (int plane = 10; plane <= 22; plane += 3) {
    const Point3 origin(-0.5f, 0.5f + 3 * h, float(plane) * h);
    for (int i = 0; i <= 4000; ++i) {
      const float angle = -0.6f + 1.2f * float(i) / 4000;
      check(Ray{origin, {std::cos(angle), std::sin(angle), 0}}, fmt::format("fan in plane z {} ray {}", plane, i));
    }
  }
  // A fan across the faces, from a voxel corner, through a slanted plane.
  const Point3 corner(-0.25f, 0.5f - 2 * h, 0.5f + 5 * h);
  for (int i = 0; i <= 20000; ++i) {
    const float a = -0.7f + 1.4f * float(i) / 20000;
    check(Ray{corner, normalize(Vec3(std::cos(a), std::sin(a), 0.37f * std::sin(a) - 0.2f))},
          fmt::format("slanted fan ray {}", i));
  }
  EXPECT_GT(checked, 40000);
}

TEST(SdfGridShape, ASurfaceLyingOnAVoxelFaceIsHitByEveryRayCrossingIt) {
  // f = x - 1/2 sampled at x = 0, 1/2, 1: the surface is exactly the face the two voxels share,
  // where each finds the value zero at its end or its start.
  SdfGridShape plane;
  plane.resolution = {3, 2, 2};
  plane.values = std::make_shared<const std::vector<float>>(
      std::vector<float>{-0.5f, 0, 0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f});
  const Transform to_world = Transform::rotate(20, normalize(Vec3(1, 1, 1)));
  Scene scene(single_shape(plane, to_world));
  Rng rng(19, 20);
  for (int i = 0; i < 20000; ++i) {
    const Point3 target = to_world.point({0.5f, 0.02f + 0.96f * rng.next_float(), 0.02f + 0.96f * rng.next_float()});
    Vec3 w = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    const Normal3 n = to_world.normal({1, 0, 0});
    if (std::abs(dot(w, n)) < 0.1f) continue;
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(Ray{target - w * 3, w}, hit)) << i;
    EXPECT_NEAR(hit.t, 3, 1e-4f) << i;
    EXPECT_NEAR(dot(hit.ng, n), 1, 1e-5f) << i;
  }
}

// A rotation, a non-uniform scale and a shear, then a translation.
Transform skewed_transform() {
  Matrix4 shear = Matrix4::identity();
  shear.m[0][1] = 0.2;
  shear.m[2][0] = -0.15;
  return Transform::translate({1, -2, 0.5f}) * Transform::rotate(35, normalize(Vec3(1, 2, -0.5f))) *
         *Transform::from_matrix(shear) * Transform::scale({1.6f, 0.8f, 1.2f});
}

// Rays at the sphere placed by `to_world` land on it and see its normal, within the grid's error
// (mapped by the transform: normals are compared in object space after the inverse transpose).
void expect_transformed_sphere(const Scene& scene, const Transform& to_world, uint64_t seed) {
  const Tolerances tol = tolerances(kSamples, kRadius);
  const Transform to_object = to_world.inverse();
  Rng rng(seed, 17);
  for (int i = 0; i < 3000; ++i) {
    const Vec3 u = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    const Point3 target = to_world.point(kCenter + u * float(kRadius * 0.9 * std::sqrt(rng.next_float())));
    const Vec3 w = normalize(square_to_uniform_sphere({rng.next_float(), rng.next_float()}));
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(Ray{target - w * 6, w}, hit)) << i;
    const Vec3 q = to_object.point(hit.p) - kCenter;
    EXPECT_NEAR(length(q), kRadius, tol.position + 1e-5) << i;
    // The world normal back in object space (as a normal) is the sphere's there.
    const Normal3 back = normalize(to_object.normal(hit.ng));
    EXPECT_LE(angle_error(back, normalize(q)), 2 * tol.normal) << i;
    EXPECT_NEAR(length(hit.ng), 1, 1e-5);
  }
}

TEST(SdfGridShape, TransformedAndInstancedGridsAreWhereTheirTransformsPutThem) {
  const SdfGridShape grid = sphere_grid();
  const Transform T = skewed_transform();
  expect_transformed_sphere(Scene(single_shape(grid, T)), T, 1);

  // In an object (its own transform inside), placed twice by instances.
  SceneDesc d;
  ObjectDesc object;
  ShapeDesc shape;
  shape.geometry = grid;
  shape.to_world = Transform::scale({2, 1, 1});
  object.shapes = {shape};
  d.objects = {object};
  const Transform first = Transform::translate({-5, 0, 0}) * T, second = Transform::translate({20, 0, 0}) * Transform::rotate(90, {0, 1, 0});
  d.instances = {InstanceDesc{0, first, std::nullopt}, InstanceDesc{0, second, std::nullopt}};
  Scene scene(d);
  expect_transformed_sphere(scene, first * shape.to_world, 2);
  expect_transformed_sphere(scene, second * shape.to_world, 3);
}

TEST(SdfGridShape, ReverseOrientationFlipsBothNormals) {
  SceneDesc d = single_shape(sphere_grid(SdfNormals::Smooth));
  d.shapes[0].reverse_orientation = true;
  Scene scene(d);
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(Ray{{0.5f, 0.5f, -1}, {0, 0, 1}}, hit));
  EXPECT_NEAR(hit.t, 1.2f, 2e-3f);
  // The outward normal there is -z; reversed, both point into the sphere.
  EXPECT_GT(hit.ng.z, 0.99f);
  EXPECT_GT(hit.ns.z, 0.99f);
}

TEST(SdfGridShape, AMovingGridIsWhereItIsAtTheRaysTime) {
  SceneDesc d = single_shape(sphere_grid());
  d.shapes[0].to_world_end = Transform::translate({3, 0, 0});
  Scene scene(d);
  EXPECT_TRUE(scene.has_motion());
  for (float time : {0.0f, 0.5f, 1.0f}) {
    SurfaceHit hit;
    const float x = 0.5f + 3 * time;
    ASSERT_TRUE(scene.intersect(Ray{{x, 0.5f, -2}, {0, 0, 1}, std::numeric_limits<float>::infinity(), time}, hit))
        << time;
    EXPECT_NEAR(hit.t, 2.2f, 2e-3f) << time;
    EXPECT_NEAR(hit.p.x, x, 1e-4f) << time;
    EXPECT_LT(hit.ng.z, -0.99f) << time;
  }
}

TEST(SdfGridShape, TheSceneRefusesEmissiveAndMalformedGrids) {
  SceneDesc emissive = single_shape(sphere_grid());
  emissive.shapes[0].emission = AreaEmission{RGB(1.0f), false};
  try {
    Scene scene(emissive);
    ADD_FAILURE() << "an emissive SDF grid was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot emit light"), std::string::npos) << e.what();
  }
  SdfGridShape broken = sphere_grid();
  broken.resolution = {kSamples, kSamples, kSamples - 1};
  EXPECT_THROW(Scene{single_shape(broken)}, SceneError);
}

// ---------------------------------------------------------------- readers and writer

std::string write_text(const std::string& name, const std::string& text) {
  const fs::path file = temp_dir() / name;
  std::ofstream(file) << text;
  return file.string();
}

std::string json_error(const std::string& shape) {
  try {
    read_json_scene(R"({"shapes": [)" + shape + "]}", "scene.json", temp_dir());
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SdfGridShape, JsonReadsAFileOrInlineSamplesAndRefusesWhatCannotBe) {
  const fs::path vol = sphere_vol(9, kRadius);
  SceneDesc d = read_json_scene(R"({"shapes": [
      {"type": "sdfgrid", "filename": ")" + vol.filename().string() + R"(", "normals": "analytic",
       "transform": [{"scale": 2}]},
      {"type": "sdfgrid", "resolution": [2, 2, 3], "values": [-1, 1, -1, 1, -1, 1, -1, 1, 1, 1, 1, 1]}]})",
                                "scene.json", temp_dir());
  ASSERT_EQ(d.shapes.size(), 2u);
  const auto& from_file = std::get<SdfGridShape>(d.shapes[0].geometry);
  EXPECT_EQ(from_file.resolution, (std::array<int, 3>{9, 9, 9}));
  EXPECT_EQ(from_file.normals, SdfNormals::Analytic);
  EXPECT_EQ(fs::path(from_file.filename), temp_dir() / vol.filename());
  EXPECT_EQ(d.shapes[0].to_world.point({1, 1, 1}), Vec3(2, 2, 2));
  const auto& inline_grid = std::get<SdfGridShape>(d.shapes[1].geometry);
  EXPECT_EQ(inline_grid.resolution, (std::array<int, 3>{2, 2, 3}));
  EXPECT_EQ(inline_grid.normals, SdfNormals::Smooth);
  EXPECT_EQ(inline_grid.values->size(), 12u);
  EXPECT_TRUE(inline_grid.filename.empty());

  const std::string file = R"("filename": ")" + vol.filename().string() + R"(")";
  EXPECT_NE(json_error(R"({"type": "sdfgrid", )" + file + R"(, "emission": {"radiance": 1}})").find("cannot emit light"),
            std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid", )" + file + R"(, "normals": "flat"})").find("unknown normals \"flat\"; expected one of: smooth, analytic"),
            std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid", )" + file + R"(, "values": [1]})").find("not both"), std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid"})").find("has neither"), std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid", "filename": "missing.vol"})").find("no such file"), std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid", "resolution": [2, 2, 2], "values": [1, -1]})").find("expected 8 values"),
            std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid", "resolution": [2, 1, 2], "values": [1, -1, 1, -1]})").find(">= 2"),
            std::string::npos);
  EXPECT_NE(json_error(R"({"type": "sdfgrid", "resolution": [2, 2, 2], "values": [1, 1, 1, 1, 1, 1, 1, 1]})")
                .find("no voxel holds a surface"),
            std::string::npos);
}

TEST(SdfGridShape, JsonWriterWritesTheFileOrTheSamplesBack) {
  SceneDesc scene;
  ShapeDesc from_file;
  from_file.geometry = sphere_grid(SdfNormals::Analytic);
  ShapeDesc in_memory;
  SdfGridShape grid;
  grid.resolution = {2, 3, 2};
  grid.values = std::make_shared<const std::vector<float>>(
      std::vector<float>{-0.1f, 0.25f, -1.5f, 2, 1e-7f, -3, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f});
  in_memory.geometry = grid;
  in_memory.to_world = Transform::translate({1, 2, 3});
  scene.shapes = {from_file, in_memory};
  // Written from another directory than the .vol file's: the file name is absolute.
  const SceneDesc back = read_json_scene(scene_to_json(scene), "converted.json", fs::current_path());
  ASSERT_EQ(back.shapes.size(), 2u);
  const auto& a = std::get<SdfGridShape>(back.shapes[0].geometry);
  const auto& original = std::get<SdfGridShape>(from_file.geometry);
  EXPECT_EQ(a.normals, SdfNormals::Analytic);
  EXPECT_EQ(a.resolution, original.resolution);
  EXPECT_EQ(*a.values, *original.values);
  EXPECT_TRUE(fs::path(a.filename).is_absolute());
  const auto& b = std::get<SdfGridShape>(back.shapes[1].geometry);
  EXPECT_EQ(b.resolution, grid.resolution);
  EXPECT_EQ(*b.values, *grid.values);  // every float round-trips
  EXPECT_EQ(b.normals, SdfNormals::Smooth);
  EXPECT_EQ(back.shapes[1].to_world, in_memory.to_world);
}

std::string mitsuba_error(const std::string& body) {
  Warnings warnings;
  try {
    read_mitsuba_scene_text("<scene version=\"3.0.0\">\n" + body + "\n</scene>", "test.xml", temp_dir(), warnings);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SdfGridShape, MitsubaReadsAnSdfgridInAShapegroupAndRefusesAnEmittingOne) {
  const std::string vol = sphere_vol(9, kRadius).filename().string();
  Warnings warnings;
  const SceneDesc d = read_mitsuba_scene_text(R"(<scene version="3.0.0">
      <shape type="shapegroup" id="group">
        <shape type="sdfgrid"><string name="filename" value=")" + vol + R"("/>
          <string name="normals" value="analytic"/><bsdf type="diffuse"/></shape>
      </shape>
      <shape type="instance"><ref id="group"/><transform name="to_world"><translate x="1"/></transform></shape>
      <shape type="sdfgrid"><string name="filename" value=")" + vol + R"("/></shape>
    </scene>)",
                                              "test.xml", temp_dir(), warnings);
  ASSERT_EQ(d.objects.size(), 1u);
  ASSERT_EQ(d.instances.size(), 1u);
  const auto& grouped = std::get<SdfGridShape>(d.objects[0].shapes[0].geometry);
  EXPECT_EQ(grouped.normals, SdfNormals::Analytic);
  EXPECT_EQ(grouped.resolution, (std::array<int, 3>{9, 9, 9}));
  ASSERT_EQ(d.shapes.size(), 1u);
  EXPECT_EQ(std::get<SdfGridShape>(d.shapes[0].geometry).normals, SdfNormals::Smooth);  // Mitsuba's default
  EXPECT_NO_THROW(Scene{d});

  const std::string shape = R"(<shape type="sdfgrid"><string name="filename" value=")" + vol + "\"/>";
  EXPECT_NE(mitsuba_error(shape + R"(<emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>)")
                .find("cannot be an area emitter"),
            std::string::npos);
  EXPECT_NE(mitsuba_error(shape + R"(<string name="normals" value="flat"/></shape>)").find("\"smooth\" or \"analytic\""),
            std::string::npos);
  EXPECT_NE(mitsuba_error(R"(<shape type="sdfgrid"><string name="filename" value="missing.vol"/></shape>)")
                .find("not found"),
            std::string::npos);
  const std::string bad = write_text("bad.vol", "VOL\x02 not really");
  EXPECT_NE(mitsuba_error(R"(<shape type="sdfgrid"><string name="filename" value="bad.vol"/></shape>)").find(bad),
            std::string::npos);
}

}  // namespace
}  // namespace candela
