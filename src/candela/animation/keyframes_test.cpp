// Keyframe interpolation against values computed by hand from glTF's definitions (step, linear,
// spherical linear, cubic Hermite spline), the transform hierarchy and mesh deformation.
#include "candela/animation/keyframes.h"

#include <gtest/gtest.h>

#include <cmath>

namespace candela {
namespace {

Keyframes scalar_keys(Interpolation interpolation, std::vector<float> times, std::vector<float> values) {
  Keyframes k;
  k.interpolation = interpolation;
  k.width = 1;
  k.times = std::move(times);
  k.values = std::move(values);
  EXPECT_EQ(k.problem(), "");
  return k;
}

TEST(Keyframes, StepHoldsEachValueUntilTheNextTime) {
  const Keyframes k = scalar_keys(Interpolation::Step, {1, 2, 4}, {10, 20, 40});
  EXPECT_EQ(k.at(0)[0], 10);     // before the first time: the first value
  EXPECT_EQ(k.at(1)[0], 10);
  EXPECT_EQ(k.at(1.99f)[0], 10);
  EXPECT_EQ(k.at(2)[0], 20);
  EXPECT_EQ(k.at(3.9f)[0], 20);
  EXPECT_EQ(k.at(4)[0], 40);
  EXPECT_EQ(k.at(100)[0], 40);   // after the last: the last value
}

TEST(Keyframes, LinearInterpolatesBetweenNeighbours) {
  const Keyframes k = scalar_keys(Interpolation::Linear, {0, 2, 3}, {0, 4, -2});
  EXPECT_FLOAT_EQ(k.at(0.5f)[0], 1);
  EXPECT_FLOAT_EQ(k.at(2.5f)[0], 1);
  EXPECT_FLOAT_EQ(k.at(-1)[0], 0);
  EXPECT_FLOAT_EQ(k.at(5)[0], -2);
}

TEST(Keyframes, CubicSplineIsGltfsHermiteSpline) {
  // Keys (in-tangent, value, out-tangent): t=0: (9, 1, 2); t=2: (-3, 5, 9).
  const Keyframes k = scalar_keys(Interpolation::CubicSpline, {0, 2}, {9, 1, 2, -3, 5, 9});
  for (float t : {0.0f, 0.3f, 1.0f, 1.7f, 2.0f}) {
    const double s = t / 2.0, dt = 2;
    const double expected = (2 * s * s * s - 3 * s * s + 1) * 1 + (s * s * s - 2 * s * s + s) * dt * 2 +
                            (-2 * s * s * s + 3 * s * s) * 5 + (s * s * s - s * s) * dt * -3;
    EXPECT_NEAR(k.at(t)[0], expected, 1e-5) << "t = " << t;
  }
  // The spline passes through its values with the tangents' slopes at the keys.
  const float h = 1e-3f;
  EXPECT_NEAR((k.at(h)[0] - k.at(0)[0]) / h, 2, 1e-2);
  EXPECT_NEAR((k.at(2)[0] - k.at(2 - h)[0]) / h, -3, 1e-2);
}

TEST(Keyframes, RotationsInterpolateAlongTheShorterArc) {
  Keyframes k;
  k.width = 4;
  k.rotation = true;
  k.times = {0, 1};
  // The identity and 90 degrees about z, the latter given as its negative (the same rotation).
  const float c = std::cos(kPi / 4), s = std::sin(kPi / 4);
  k.values = {0, 0, 0, 1, 0, 0, -s, -c};
  ASSERT_EQ(k.problem(), "");
  const std::vector<float> q = k.at(0.5f);
  // Half way: 45 degrees about z (up to sign), a unit quaternion.
  const float sign = q[3] < 0 ? -1.0f : 1.0f;
  EXPECT_NEAR(sign * q[2], std::sin(kPi / 8), 1e-6);
  EXPECT_NEAR(sign * q[3], std::cos(kPi / 8), 1e-6);
  EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1, 1e-6);
}

TEST(Keyframes, ProblemsAreNamed) {
  Keyframes k;
  k.times = {0, 1};
  k.values = {0};
  EXPECT_NE(k.problem().find("need 2 values"), std::string::npos) << k.problem();
  k.values = {0, 1};
  k.times = {1, 1};
  EXPECT_NE(k.problem().find("must increase"), std::string::npos) << k.problem();
  k.times = {0, NAN};
  EXPECT_NE(k.problem().find("finite"), std::string::npos) << k.problem();
  k.times = {0, 1};
  k.interpolation = Interpolation::CubicSpline;
  EXPECT_NE(k.problem().find("in-tangent"), std::string::npos) << k.problem();
}

TEST(SceneAnimation, ChildrenFollowTheirParents) {
  SceneAnimation a;
  AnimationNode parent;
  parent.trs.translation_keys = Keyframes{Interpolation::Linear, 3, false, {0, 1}, {0, 0, 0, 10, 0, 0}};
  AnimationNode child;
  child.parent = 0;
  child.trs.translation = {0, 1, 0};
  child.trs.rotation = {0, 0, std::sin(kPi / 4), std::cos(kPi / 4)};  // 90 degrees about z
  a.nodes = {parent, child};
  ASSERT_EQ(a.problem(), "");
  EXPECT_TRUE(a.node_moves(1));
  const auto T = Transform::from_matrix(a.world_matrix(1, 0.5f));
  ASSERT_TRUE(T);
  const Point3 p = T->point({1, 0, 0});  // rotated to (0, 1, 0), moved up 1 and along x by 5
  EXPECT_NEAR(p.x, 5, 1e-5);
  EXPECT_NEAR(p.y, 2, 1e-5);
  EXPECT_NEAR(p.z, 0, 1e-5);
  EXPECT_EQ(a.time_range()[0], 0);
  EXPECT_EQ(a.time_range()[1], 1);
  a.nodes[0].parent = 1;
  EXPECT_NE(a.problem().find("its own ancestor"), std::string::npos) << a.problem();
}

TEST(SceneAnimation, MorphsThenSkins) {
  SceneAnimation a;
  AnimationNode root;  // joint 0: static
  AnimationNode moving;  // joint 1: moves along y from 0 to 2 over [0, 1]
  moving.trs.translation_keys = Keyframes{Interpolation::Linear, 3, false, {0, 1}, {0, 0, 0, 0, 2, 0}};
  moving.weights_keys = Keyframes{Interpolation::Linear, 1, false, {0, 1}, {0, 1}};
  a.nodes = {root, moving};
  a.skins.push_back({{0, 1}, {Matrix4::identity(), Matrix4::identity()}, "skin"});
  MeshDeformation d;
  d.skin = 0;
  d.influences = 2;
  // Vertex 0 on joint 0 only, vertex 1 half on each.
  d.joints = {0, 1, 0, 1};
  d.weights = {1, 0, 0.5f, 0.5f};
  d.target_positions = {{Vec3(1, 0, 0), Vec3(0, 0, 4)}};
  d.weights_node = 1;
  a.deformations.push_back(d);
  ASSERT_EQ(a.problem(), "");
  std::vector<Point3> positions = {{0, 0, 0}, {1, 1, 1}};
  std::vector<Normal3> normals;
  a.deform(a.deformations[0], 0.5f, positions, normals);
  // Morph weight 0.5: (0.5, 0, 0) and (1, 1, 3); then vertex 1 moves by half of joint 1's (0, 1, 0).
  EXPECT_NEAR(positions[0].x, 0.5f, 1e-6);
  EXPECT_NEAR(positions[0].y, 0, 1e-6);
  EXPECT_NEAR(positions[1].x, 1, 1e-6);
  EXPECT_NEAR(positions[1].y, 1.5f, 1e-6);
  EXPECT_NEAR(positions[1].z, 3, 1e-6);
}

}  // namespace
}  // namespace candela
