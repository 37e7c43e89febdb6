// Disks and cylinders as analytic Embree user geometry, through the whole Scene: hit points, uv,
// normals and dp/du against Mitsuba's parameterisation, computed independently here from the
// object-space point each ray is aimed at, under non-uniform scales, rotations and shears; misses
// just outside; reverse orientation; objects placed by instances; motion blur.
#include <gtest/gtest.h>

#include <cmath>

#include "candela/geometry/embree_scene.h"
#include "candela/base/error.h"
#include "candela/math/frame.h"
#include "candela/sampling/rng.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

// A rotation, a non-uniform scale and a shear, then a translation.
Transform skewed_transform() {
  Matrix4 shear = Matrix4::identity();
  shear.m[0][1] = 0.3;  // x += 0.3 y
  shear.m[2][0] = -0.2;  // z -= 0.2 x
  return Transform::translate({1, -2, 0.5f}) * Transform::rotate(35, normalize(Vec3(1, 2, -0.5f))) *
         *Transform::from_matrix(shear) * Transform::scale({2, 0.5f, 1.5f});
}

SceneDesc single_shape(ShapeGeometry g, const Transform& to_world, bool reverse = false) {
  SceneDesc d;
  ShapeDesc s;
  s.geometry = std::move(g);
  s.to_world = to_world;
  s.reverse_orientation = reverse;
  d.shapes = {s};
  return d;
}

void expect_vec_near(const Vec3& a, const Vec3& b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

// A ray towards world point `target` from `distance` away along -dir (dir unit).
Ray ray_to(const Point3& target, const Vec3& dir, float distance, float time = 0) {
  return Ray{target - dir * distance, dir, std::numeric_limits<float>::infinity(), time};
}

TEST(QuadricShapes, DiskHitsUvNormalAndTangentUnderASkewedTransform) {
  for (bool reverse : {false, true}) {
    const Transform T = skewed_transform();
    Scene scene(single_shape(DiskShape{}, T, reverse));
    const Normal3 n = normalize(T.normal({0, 0, 1})) * (reverse ? -1.0f : 1.0f);
    Rng rng(3, 4);
    for (int i = 0; i < 2000; ++i) {
      float r = std::sqrt(rng.next_float()) * 0.999f, phi = 2 * kPi * rng.next_float();
      Point3 local(r * std::cos(phi), r * std::sin(phi), 0);
      Point3 target = T.point(local);
      // From either side, at a direction well away from the plane.
      Vec3 dir = normalize(square_to_uniform_sphere({rng.next_float(), rng.next_float()}));
      if (std::abs(dot(dir, n)) < 0.2f) dir = normalize(dir + n * (rng.next_float() < 0.5f ? 1.0f : -1.0f));
      SurfaceHit hit;
      ASSERT_TRUE(scene.intersect(ray_to(target, dir, 5), hit)) << i;
      std::string what = "disk sample " + std::to_string(i) + (reverse ? " (reversed)" : "");
      EXPECT_NEAR(hit.t, 5, 1e-4f) << what;
      expect_vec_near(hit.p, target, 1e-4f, what + " p");
      EXPECT_NEAR(hit.uv.x, r, 1e-4f) << what;  // Mitsuba: (u, v) = (r, phi / 2 pi)
      EXPECT_NEAR(hit.uv.y, phi * kInv2Pi, 1e-4f) << what;
      expect_vec_near(hit.ng, n, 1e-5f, what + " ng");
      expect_vec_near(hit.ns, n, 1e-5f, what + " ns");
      expect_vec_near(hit.dpdu, T.vector({std::cos(phi), std::sin(phi), 0}), 1e-4f, what + " dpdu");
    }
    // Just outside the rim (r = 1.01 in object space) and parallel rays miss.
    for (int i = 0; i < 500; ++i) {
      float phi = 2 * kPi * rng.next_float();
      Point3 target = T.point({1.01f * std::cos(phi), 1.01f * std::sin(phi), 0});
      SurfaceHit hit;
      ASSERT_FALSE(scene.intersect(ray_to(target, n, 5), hit)) << "outside the rim, phi " << phi;
    }
  }
}

TEST(QuadricShapes, CylinderHitsUvNormalAndTangentUnderASkewedTransform) {
  const Transform T = skewed_transform();
  const CylinderShape c{{0.2f, -0.1f, 0.3f}, {-0.4f, 0.5f, 1.8f}, 0.7f};
  const Vec3 axis = c.p1 - c.p0;
  const Frame f(normalize(axis));  // Mitsuba's to_frame: phi = 0 along f.s
  for (bool reverse : {false, true}) {
    Scene scene(single_shape(c, T, reverse));
    Rng rng(5, 6);
    for (int i = 0; i < 2000; ++i) {
      float h = 0.001f + 0.998f * rng.next_float(), phi = 2 * kPi * rng.next_float();
      Vec3 radial = f.s * std::cos(phi) + f.t * std::sin(phi);
      Point3 target = T.point(c.p0 + radial * c.radius + axis * h);
      Normal3 outward = normalize(T.normal(radial));
      std::string what = "cylinder sample " + std::to_string(i) + (reverse ? " (reversed)" : "");
      // From outside along the outward normal (a convex section: nothing else in the way), and from
      // the axis point at the same height (the tube seen from inside).
      Point3 inside = T.point(c.p0 + axis * h);
      for (int from_inside = 0; from_inside < 2; ++from_inside) {
        Ray ray = from_inside ? Ray{inside, normalize(target - inside), std::numeric_limits<float>::infinity(), 0}
                              : ray_to(target, -outward, 3);
        float expected_t = from_inside ? length(target - inside) : 3.0f;
        SurfaceHit hit;
        ASSERT_TRUE(scene.intersect(ray, hit)) << what << (from_inside ? " inside" : " outside");
        EXPECT_NEAR(hit.t, expected_t, 2e-4f) << what;
        expect_vec_near(hit.p, target, 2e-4f, what + " p");
        // Mitsuba: (u, v) = (phi / 2 pi, height / length), dp/du = 2 pi r (-sin, cos) in the frame.
        EXPECT_NEAR(hit.uv.x, phi * kInv2Pi, 1e-4f) << what;
        EXPECT_NEAR(hit.uv.y, h, 1e-4f) << what;
        Normal3 n = reverse ? -outward : outward;
        expect_vec_near(hit.ng, n, 1e-4f, what + " ng");
        expect_vec_near(hit.dpdu, T.vector((f.t * std::cos(phi) - f.s * std::sin(phi)) * (2 * kPi * c.radius)), 2e-4f,
                        what + " dpdu");
      }
    }
    // Just above and below the ends, at a constant height in the tube's space: no hit.
    for (float h : {-0.01f, 1.01f}) {
      Point3 target = T.point(c.p0 + f.s * c.radius + axis * h);
      SurfaceHit hit;
      EXPECT_FALSE(scene.intersect(ray_to(target, -normalize(T.vector(f.s)), 3), hit)) << "height " << h;
    }
    SurfaceHit hit;
    Point3 below = T.point(c.p0 - axis * 0.5f), above = T.point(c.p0 + axis * 1.5f);
    EXPECT_FALSE(scene.intersect(Ray{below, normalize(above - below), std::numeric_limits<float>::infinity(), 0}, hit))
        << "along the axis";
  }
}

TEST(QuadricShapes, UnitQuadricIntersectionIsExactForDistantRays) {
  // Far away (1e4 units) the cancellation-free quadratic still lands on the surface.
  double t;
  ASSERT_TRUE(intersect_unit_quadric(QuadricGeometry::Kind::Cylinder, {1e4f, 0.3f, 0.5f}, {-1, 0, 0}, 0, 1e30, t));
  EXPECT_NEAR(t, 1e4 - std::sqrt(1 - 0.09), 1e-3);
  ASSERT_TRUE(intersect_unit_quadric(QuadricGeometry::Kind::Disk, {0.5f, 0.5f, 1e4f}, {0, 0, -1}, 0, 1e30, t));
  EXPECT_NEAR(t, 1e4, 1e-3);
  EXPECT_FALSE(intersect_unit_quadric(QuadricGeometry::Kind::Disk, {0.5f, 0.5f, 1}, {0, 0, -1}, 0, 0.5, t));
}

TEST(QuadricShapes, InstancedDisksAndCylindersAreReconstructedInTheWorld) {
  SceneDesc d;
  ObjectDesc obj;
  ShapeDesc disk;
  disk.geometry = DiskShape{};
  disk.to_world = Transform::scale({2, 1, 1});
  ShapeDesc tube;
  tube.geometry = CylinderShape{{0, 0, 1}, {0, 0, 3}, 0.5f};
  obj.shapes = {disk, tube};
  d.objects = {obj};
  const Transform place = Transform::translate({10, 0, 0}) * Transform::rotate(90, {1, 0, 0});  // object z -> world -y
  d.instances = {InstanceDesc{0, place, std::nullopt}};
  Scene scene(d);
  // The disk's point (0.6, 0.4, 0) of its own space is (1.2, 0.4, 0) in the object, placed in the world.
  float r = std::sqrt(0.36f + 0.16f), phi = std::atan2(0.4f, 0.6f);
  Point3 target = place.point({1.2f, 0.4f, 0});
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(ray_to(target, {0, 1, 0}, 4), hit));
  expect_vec_near(hit.p, target, 1e-4f, "instanced disk p");
  EXPECT_NEAR(hit.uv.x, r, 1e-4f);
  EXPECT_NEAR(hit.uv.y, phi * kInv2Pi, 1e-4f);
  expect_vec_near(hit.ng, {0, -1, 0}, 1e-5f, "instanced disk ng");
  // The tube at height 2 (v = 0.5), seen from the world +z side.
  Point3 side = place.point({0, 0.5f, 2});
  ASSERT_TRUE(scene.intersect(ray_to(side, {0, 0, -1}, 4), hit));
  expect_vec_near(hit.p, side, 1e-4f, "instanced tube p");
  EXPECT_NEAR(hit.uv.y, 0.5f, 1e-4f);
  expect_vec_near(hit.ng, normalize(place.normal({0, 1, 0})), 1e-5f, "instanced tube ng");
}

TEST(QuadricShapes, MovingDiskAndCylinderAreWhereTheyAreAtTheRaysTime) {
  for (int kind = 0; kind < 2; ++kind) {
    SceneDesc d;
    ShapeDesc s;
    if (kind == 0) s.geometry = DiskShape{};
    else s.geometry = CylinderShape{{0, 0, -1}, {0, 0, 1}, 1};
    s.to_world = Transform::translate({0, 0, 0});
    s.to_world_end = Transform::translate({4, 0, 0});
    d.shapes = {s};
    Scene scene(d);
    for (float time : {0.0f, 0.25f, 1.0f}) {
      float x = 4 * time;
      SurfaceHit hit;
      // Disk: straight down onto its centre; tube: from +y onto its top line.
      Ray ray = kind == 0 ? Ray{{x, 0, 3}, {0, 0, -1}, std::numeric_limits<float>::infinity(), time}
                          : Ray{{x, 3, 0}, {0, -1, 0}, std::numeric_limits<float>::infinity(), time};
      ASSERT_TRUE(scene.intersect(ray, hit)) << "kind " << kind << " time " << time;
      EXPECT_NEAR(hit.p.x, x, 1e-4f);
      EXPECT_NEAR(hit.t, kind == 0 ? 3.0f : 2.0f, 1e-4f);
      // Where it was at time 0 there is nothing at time 1.
      if (time == 1.0f) {
        Ray old = ray;
        old.origin.x = 0;
        EXPECT_FALSE(scene.intersect(old, hit)) << "kind " << kind;
      }
    }
  }
}

TEST(QuadricShapes, EmissiveCylinderMustStayCircular) {
  SceneDesc d = single_shape(CylinderShape{}, Transform::scale({2, 1, 1}));
  d.shapes[0].emission = AreaEmission{RGB(1.0f), false};
  EXPECT_THROW(Scene{d}, SceneError);
  d.shapes[0].to_world = Transform::scale({2, 2, 5});  // uniform across the axis: a circular tube
  EXPECT_NO_THROW(Scene{d});
}

}  // namespace
}  // namespace candela
