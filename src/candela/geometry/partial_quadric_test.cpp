// pbrt-v4's partial spheres and cylinders (zmin, zmax, phimax) as analytic Embree user geometry,
// through the whole Scene: points of the part kept are hit with pbrt-v4's (u, v) and tangents
// (computed here independently, from the parameterisation itself); a ray through the cut goes on
// to the far side and sees its inside; a ray that meets the surface only where it is cut away
// misses; moving partial spheres are cut where they are at the ray's time.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "candela/geometry/embree_scene.h"
#include "candela/math/frame.h"
#include "candela/sampling/rng.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

SceneDesc single_partial_shape(ShapeGeometry g, const Transform& to_world, bool reverse = false) {
  SceneDesc d;
  ShapeDesc s;
  s.geometry = std::move(g);
  s.to_world = to_world;
  s.reverse_orientation = reverse;
  d.shapes = {s};
  return d;
}

void expect_partial_vec_near(const Vec3& a, const Vec3& b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

float azimuth_of(float x, float y) {
  float phi = std::atan2(y, x);
  return phi < 0 ? phi + 2 * kPi : phi;
}

// ---------------------------------------------------------------- partial spheres

// Radius 1.5 around (0.2, -0.1, 0.3), kept for -0.9 <= z <= 1.2 and phi <= 270 degrees, with
// pbrt-v4's (u, v); turned, scaled uniformly (by 1.3) and moved.
struct PartialSphereCase {
  SphereShape sphere{{0.2f, -0.1f, 0.3f}, 1.5f, SphereUv::Pbrt};
  Transform T = Transform::translate({1, -2, 0.5f}) * Transform::rotate(35, normalize(Vec3(1, 2, -0.5f))) *
                Transform::scale(Vec3(1.3f));
  float phi_max = 1.5f * kPi;
  float theta_lo = std::acos(-0.9f / 1.5f), theta_hi = std::acos(1.2f / 1.5f);  // theta at z_min and z_max
  PartialSphereCase() {
    sphere.z_min = -0.9f;
    sphere.z_max = 1.2f;
    sphere.z_min_given = sphere.z_max_given = true;
    sphere.phi_max = 270;
  }
  // The point of (u, v), by pbrt-v4's parameterisation: phi = u phi_max, theta from theta(z_min) at
  // v = 0 to theta(z_max) at v = 1 (object space, from the centre).
  Vec3 offset(float u, float v) const {
    float phi = u * phi_max, theta = theta_lo + v * (theta_hi - theta_lo);
    return Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)) * sphere.radius;
  }
  Point3 world(const Vec3& offset) const { return T.point(sphere.center + offset); }
};

TEST(PartialSphere, KeptPointsHaveThePbrtParameterisation) {
  const PartialSphereCase c;
  for (bool reverse : {false, true}) {
    Scene scene(single_partial_shape(c.sphere, c.T, reverse));
    Rng rng(3, 4);
    for (int i = 0; i < 2000; ++i) {
      float u = 0.002f + 0.996f * rng.next_float(), v = 0.002f + 0.996f * rng.next_float();
      Vec3 local = c.offset(u, v);
      Point3 target = c.world(local);
      Normal3 outward = normalize(c.T.normal(local));
      SurfaceHit hit;
      std::string what = "sphere sample " + std::to_string(i) + (reverse ? " (reversed)" : "");
      ASSERT_TRUE(scene.intersect(Ray{target + outward * 3.0f, -outward, kInf, 0}, hit)) << what;
      EXPECT_NEAR(hit.t, 3, 2e-4f) << what;
      expect_partial_vec_near(hit.p, target, 2e-4f, what + " p");
      EXPECT_NEAR(hit.uv.x, u, 2e-4f) << what;
      EXPECT_NEAR(hit.uv.y, v, 2e-4f) << what;
      expect_partial_vec_near(hit.ng, reverse ? -outward : outward, 1e-4f, what + " ng");
      // dp/du and dp/dv: central differences of the parameterisation (where both sides are on it).
      const float h = 1e-3f;
      if (u > h && u < 1 - h && v > h && v < 1 - h) {
        Vec3 dpdu = (c.world(c.offset(u + h, v)) - c.world(c.offset(u - h, v))) / (2 * h);
        Vec3 dpdv = (c.world(c.offset(u, v + h)) - c.world(c.offset(u, v - h))) / (2 * h);
        expect_partial_vec_near(hit.dpdu, dpdu, 2e-3f * length(dpdu), what + " dpdu");
        expect_partial_vec_near(hit.dpdv, dpdv, 2e-3f * length(dpdv) + 1e-4f, what + " dpdv");
      }
    }
  }
}

TEST(PartialSphere, ARayThroughTheCutSeesTheInsideOfTheFarSide) {
  const PartialSphereCase c;
  Scene scene(single_partial_shape(c.sphere, c.T));
  Rng rng(5, 6);
  for (int i = 0; i < 1000; ++i) {
    // Aimed along the normal at a point of the cut-away azimuths (270 to 360 degrees), height within
    // +-0.8: the ray crosses the centre and meets the sphere again at the opposite point, whose
    // azimuth (90 to 180 degrees) and height are kept.
    float phi = kPi * (1.505f + 0.49f * rng.next_float()), z = 0.8f * (2 * rng.next_float() - 1);
    float rho = std::sqrt(c.sphere.radius * c.sphere.radius - z * z);
    Vec3 local(rho * std::cos(phi), rho * std::sin(phi), z);
    Normal3 outward = normalize(c.T.normal(local));
    Point3 start = c.world(local) + outward * 3.0f;
    Point3 far = c.world(-local);
    SurfaceHit hit;
    std::string what = "through the cut " + std::to_string(i);
    ASSERT_TRUE(scene.intersect(Ray{start, -outward, kInf, 0}, hit)) << what;
    EXPECT_NEAR(hit.t, length(far - start), 3e-4f) << what;
    expect_partial_vec_near(hit.p, far, 3e-4f, what + " p");
    // The normal still points outwards, away from the ray: its inside is what the ray sees.
    expect_partial_vec_near(hit.ng, normalize(c.T.normal(-local)), 1e-4f, what + " ng");
    EXPECT_GT(dot(hit.ng, -outward), 0.99f) << what;
    Vec3 far_local = -local;
    float theta = std::acos(far_local.z / c.sphere.radius);
    EXPECT_NEAR(hit.uv.x, azimuth_of(far_local.x, far_local.y) / c.phi_max, 2e-4f) << what;
    EXPECT_NEAR(hit.uv.y, (theta - c.theta_lo) / (c.theta_hi - c.theta_lo), 2e-4f) << what;
  }
}

TEST(PartialSphere, RaysThatMeetOnlyTheCutAwayPartMiss) {
  const PartialSphereCase c;
  Scene scene(single_partial_shape(c.sphere, c.T));
  SurfaceHit hit;
  // Down the sphere's own z axis: through the cap above z_max and the cap below z_min.
  Point3 above = c.world({0, 0, 3}), below = c.world({0, 0, -3});
  EXPECT_FALSE(scene.intersect(Ray{above, normalize(below - above), kInf, 0}, hit)) << "down the axis";
  EXPECT_FALSE(scene.intersect(Ray{below, normalize(above - below), kInf, 0}, hit)) << "up the axis";
  // Chords between two cut-away azimuths (280 and 350 degrees), at several heights.
  for (float z : {-0.5f, 0.0f, 0.7f}) {
    float rho = std::sqrt(c.sphere.radius * c.sphere.radius - z * z);
    auto at = [&](float degrees) {
      float phi = radians(degrees);
      return c.world({rho * std::cos(phi), rho * std::sin(phi), z});
    };
    Point3 a = at(280), b = at(350);
    EXPECT_FALSE(scene.intersect(Ray{a + (a - b), normalize(b - a), kInf, 0}, hit)) << "chord at z " << z;
    // The same chord turned by 180 degrees lies in the kept azimuths.
    Point3 a2 = at(100), b2 = at(170);
    EXPECT_TRUE(scene.intersect(Ray{a2 + (a2 - b2), normalize(b2 - a2), kInf, 0}, hit)) << "kept chord at z " << z;
    expect_partial_vec_near(hit.p, a2, 3e-4f, "kept chord");
  }
}

TEST(PartialSphere, AWholeRangeLeavesTheWholeSphere) {
  SphereShape s{{0, 0, 0}, 2, SphereUv::Pbrt};
  EXPECT_FALSE(s.partial());
  s.z_min = -5;  // clamped to -radius: no cut
  s.z_min_given = true;
  EXPECT_FALSE(s.partial());
  s.z_max = 1.9f;
  s.z_max_given = true;
  EXPECT_TRUE(s.partial());
  EXPECT_EQ(s.z_hi(), 1.9f);
  EXPECT_EQ(s.z_lo(), -2);
  SphereShape p{{0, 0, 0}, 2, SphereUv::Pbrt};
  p.phi_max = 359;
  EXPECT_TRUE(p.partial());
}

TEST(PartialSphere, MovingPartialSphereIsCutWhereItIsAtTheRaysTime) {
  SceneDesc d;
  ShapeDesc s;
  SphereShape sphere{{0, 0, 0}, 1, SphereUv::Pbrt};
  sphere.phi_max = 180;  // the half y >= 0
  s.geometry = sphere;
  s.to_world = Transform();
  s.to_world_end = Transform::translate({4, 0, 0});
  d.shapes = {s};
  Scene scene(d);
  for (float time : {0.0f, 0.5f, 1.0f}) {
    float x = 4 * time;
    SurfaceHit hit;
    // From -y: through the cut-away half, onto the inside of the kept half at y = 1.
    ASSERT_TRUE(scene.intersect(Ray{{x, -3, 0}, {0, 1, 0}, kInf, time}, hit)) << time;
    EXPECT_NEAR(hit.t, 4, 1e-4f) << time;
    EXPECT_NEAR(hit.p.x, x, 1e-4f) << time;
    EXPECT_GT(hit.ng.y, 0.999f) << time;
    EXPECT_NEAR(hit.uv.x, 0.5f, 1e-4f) << time;  // phi = 90 degrees of 180
    // From +y: the outside of the kept half.
    ASSERT_TRUE(scene.intersect(Ray{{x, 3, 0}, {0, -1, 0}, kInf, time}, hit)) << time;
    EXPECT_NEAR(hit.t, 2, 1e-4f) << time;
  }
}

TEST(PartialSphere, EmptyOrInvalidCutsAreSceneErrors) {
  SphereShape s{{0, 0, 0}, 1, SphereUv::Pbrt};
  s.z_min = 1.5f;  // above the sphere: nothing left
  s.z_min_given = true;
  EXPECT_THROW(Scene{single_partial_shape(s, Transform())}, SceneError);
  s.z_min = 0.5f;
  s.z_max = 0.25f;
  s.z_max_given = true;
  EXPECT_THROW(Scene{single_partial_shape(s, Transform())}, SceneError);
  s.z_max = 0.75f;
  EXPECT_NO_THROW(Scene{single_partial_shape(s, Transform())});
  for (float phi_max : {0.0f, -10.0f, 361.0f, std::nanf("")}) {
    SphereShape p{{0, 0, 0}, 1, SphereUv::Pbrt};
    p.phi_max = phi_max;
    EXPECT_THROW(Scene{single_partial_shape(p, Transform())}, SceneError) << phi_max;
    CylinderShape cyl;
    cyl.phi_max = phi_max;
    EXPECT_THROW(Scene{single_partial_shape(cyl, Transform())}, SceneError) << phi_max;
  }
}

// ---------------------------------------------------------------- partial cylinders

// A shear, a non-uniform scale and a turn, as the whole cylinders' tests use.
Transform partial_skewed_transform() {
  Matrix4 shear = Matrix4::identity();
  shear.m[0][1] = 0.3;
  shear.m[2][0] = -0.2;
  return Transform::translate({1, -2, 0.5f}) * Transform::rotate(35, normalize(Vec3(1, 2, -0.5f))) *
         *Transform::from_matrix(shear) * Transform::scale({2, 0.5f, 1.5f});
}

TEST(PartialCylinder, KeptPointsHaveThePbrtParameterisation) {
  const Transform T = partial_skewed_transform();
  const CylinderShape c{{0.2f, -0.1f, 0.3f}, {-0.4f, 0.5f, 1.8f}, 0.7f, 270};
  const float phi_max = 1.5f * kPi;
  const Vec3 axis = c.p1 - c.p0;
  const Frame f(normalize(axis));  // phi = 0 along f.s
  Scene scene(single_partial_shape(c, T));
  Rng rng(7, 8);
  for (int i = 0; i < 2000; ++i) {
    float h = 0.001f + 0.998f * rng.next_float(), u = 0.001f + 0.998f * rng.next_float(), phi = u * phi_max;
    Vec3 radial = f.s * std::cos(phi) + f.t * std::sin(phi);
    Point3 target = T.point(c.p0 + radial * c.radius + axis * h);
    Normal3 outward = normalize(T.normal(radial));
    std::string what = "cylinder sample " + std::to_string(i);
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(Ray{target + outward * 3.0f, -outward, kInf, 0}, hit)) << what;
    EXPECT_NEAR(hit.t, 3, 2e-4f) << what;
    expect_partial_vec_near(hit.p, target, 2e-4f, what + " p");
    EXPECT_NEAR(hit.uv.x, u, 1e-4f) << what;  // pbrt-v4: u = phi / phimax, v = (z - zmin) / (zmax - zmin)
    EXPECT_NEAR(hit.uv.y, h, 1e-4f) << what;
    expect_partial_vec_near(hit.ng, outward, 1e-4f, what + " ng");
    expect_partial_vec_near(hit.dpdu, T.vector((f.t * std::cos(phi) - f.s * std::sin(phi)) * (phi_max * c.radius)), 3e-4f,
                    what + " dpdu");
  }
}

TEST(PartialCylinder, ARayThroughTheCutSeesTheInsideAndOneOutsidePhiMaxMisses) {
  const Transform T = partial_skewed_transform();
  const CylinderShape c{{0.2f, -0.1f, 0.3f}, {-0.4f, 0.5f, 1.8f}, 0.7f, 270};
  const Vec3 axis = c.p1 - c.p0;
  const Frame f(normalize(axis));
  Scene scene(single_partial_shape(c, T));
  auto point = [&](float degrees, float r, float h) {
    float phi = radians(degrees);
    return T.point(c.p0 + (f.s * std::cos(phi) + f.t * std::sin(phi)) * (r * c.radius) + axis * h);
  };
  Rng rng(9, 10);
  for (int i = 0; i < 500; ++i) {
    // From outside the cut-away azimuths (270 to 360 degrees) across the axis at a constant height
    // of the tube: the wall is met first at the cut, then at the opposite azimuth, which is kept.
    float degrees = 271 + 88 * rng.next_float(), h = 0.02f + 0.96f * rng.next_float();
    Point3 start = point(degrees, 2, h), far = point(degrees + 180, 1, h);
    SurfaceHit hit;
    std::string what = "through the cut " + std::to_string(i);
    ASSERT_TRUE(scene.intersect(Ray{start, normalize(far - start), kInf, 0}, hit)) << what;
    EXPECT_NEAR(hit.t, length(far - start), 3e-4f) << what;
    expect_partial_vec_near(hit.p, far, 3e-4f, what + " p");
    EXPECT_GT(dot(hit.ng, normalize(far - start)), 0) << what << ": the inside faces the ray";
    EXPECT_NEAR(hit.uv.x, (degrees - 180) / 270, 1e-4f) << what;
    EXPECT_NEAR(hit.uv.y, h, 1e-4f) << what;
    // A chord between two cut-away azimuths meets nothing.
    Point3 a = point(280, 1, h), b = point(350, 1, h);
    EXPECT_FALSE(scene.intersect(Ray{a + (a - b), normalize(b - a), kInf, 0}, hit)) << what << " chord";
  }
}

TEST(PartialCylinder, UnitTubeTakesTheFarRootWhereTheNearOneIsCut) {
  double t;
  // Half a tube (phi <= 180 degrees: y >= 0). Along -x at y = 0.3: the near root (x > 0, y > 0) is kept.
  ASSERT_TRUE(intersect_unit_quadric(QuadricGeometry::Kind::Cylinder, {5, 0.3f, 0.5f}, {-1, 0, 0}, 0, 1e30, t, kPi));
  EXPECT_NEAR(t, 5 - std::sqrt(1 - 0.09), 1e-5);
  // Along +y at x = 0.3 from below: the near root (y < 0) is cut, the far one (y > 0) kept.
  ASSERT_TRUE(intersect_unit_quadric(QuadricGeometry::Kind::Cylinder, {0.3f, -5, 0.5f}, {0, 1, 0}, 0, 1e30, t, kPi));
  EXPECT_NEAR(t, 5 + std::sqrt(1 - 0.09), 1e-5);
  // Along +x at y = -0.3: both roots are in the cut-away half.
  EXPECT_FALSE(intersect_unit_quadric(QuadricGeometry::Kind::Cylinder, {-5, -0.3f, 0.5f}, {1, 0, 0}, 0, 1e30, t, kPi));
  // The whole tube meets it.
  EXPECT_TRUE(intersect_unit_quadric(QuadricGeometry::Kind::Cylinder, {-5, -0.3f, 0.5f}, {1, 0, 0}, 0, 1e30, t));
}

}  // namespace
}  // namespace candela
