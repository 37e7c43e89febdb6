// One frame of an animated description: placements at the shutter's opening and closing, deformed
// meshes, the camera and its lens at the middle, and two-transform motion held outside its times.
#include "candela/animation/pose.h"

#include <gtest/gtest.h>

#include <cmath>

namespace candela {
namespace {

Keyframes linear_track(int width, std::vector<float> times, std::vector<float> values) {
  Keyframes k;
  k.width = width;
  k.times = std::move(times);
  k.values = std::move(values);
  return k;
}

SceneDesc animated_scene() {
  SceneDesc desc;
  AnimationNode slider;  // moves along +x by 10 per second over [0, 1]
  slider.trs.translation_keys = linear_track(3, {0, 1}, {0, 0, 0, 10, 0, 0});
  AnimationNode fixed;
  fixed.trs.translation = {0, 5, 0};
  desc.animation.nodes = {slider, fixed};
  ShapeDesc sphere;
  sphere.geometry = SphereShape{};
  sphere.to_world = Transform::translate({0, 0, 1});  // relative to its node
  sphere.animation_node = 0;
  ShapeDesc resting;
  resting.geometry = SphereShape{};
  resting.animation_node = 1;
  desc.shapes = {sphere, resting};
  desc.camera.animation_node = 0;
  desc.camera.fov_keys = linear_track(1, {0, 1}, {20, 60});
  return desc;
}

TEST(PoseScene, PlacesShapesAtTheShutterOpeningAndClosing) {
  const SceneDesc still = pose_scene(animated_scene(), {0.25f, 0.5f});
  EXPECT_TRUE(still.animation.empty());
  EXPECT_EQ(still.transform_start_time, 0.25f);
  EXPECT_EQ(still.transform_end_time, 0.5f);
  EXPECT_EQ(still.camera.shutter_open, 0.25f);
  EXPECT_EQ(still.camera.shutter_close, 0.5f);
  const Point3 start = still.shapes[0].to_world.point({0, 0, 0});
  EXPECT_NEAR(start.x, 2.5f, 1e-5);
  EXPECT_NEAR(start.z, 1, 1e-5);
  ASSERT_TRUE(still.shapes[0].to_world_end);
  EXPECT_NEAR(still.shapes[0].to_world_end->point({0, 0, 0}).x, 5, 1e-5);
  EXPECT_EQ(still.shapes[0].animation_node, -1);
  // A node that does not move gives a still shape.
  EXPECT_FALSE(still.shapes[1].to_world_end);
  EXPECT_NEAR(still.shapes[1].to_world.point({0, 0, 0}).y, 5, 1e-6);
  // The camera and its fov at the middle of the interval, 0.375 s.
  EXPECT_NEAR(still.camera.world_from_camera.point({0, 0, 0}).x, 3.75f, 1e-5);
  EXPECT_NEAR(still.camera.fov_degrees, 35, 1e-4);
  EXPECT_FALSE(still.camera.fov_keys);
}

TEST(PoseScene, AClosedShutterStopsTheMotion) {
  const SceneDesc still = pose_scene(animated_scene(), {0.5f, 0.5f});
  EXPECT_NEAR(still.shapes[0].to_world.point({0, 0, 0}).x, 5, 1e-5);
  EXPECT_FALSE(still.shapes[0].to_world_end);
}

TEST(PoseScene, DeformsMeshesAtBothEnds) {
  SceneDesc desc;
  AnimationNode weights_node;
  weights_node.weights_keys = linear_track(1, {0, 1}, {0, 1});
  desc.animation.nodes = {weights_node};
  MeshDeformation morph;
  morph.target_positions = {{Vec3(0, 0, 2), Vec3(0, 0, 2), Vec3(0, 0, 2)}};
  morph.weights_node = 0;
  desc.animation.deformations = {morph};
  MeshShape mesh;
  mesh.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.mesh.indices = {0, 1, 2};
  ShapeDesc shape;
  shape.geometry = mesh;
  shape.deformation = 0;
  desc.shapes = {shape};
  const SceneDesc still = pose_scene(desc, {0.25f, 0.75f});
  const auto& posed = std::get<MeshShape>(still.shapes[0].geometry);
  EXPECT_NEAR(posed.mesh.positions[1].z, 0.5f, 1e-6);
  ASSERT_EQ(posed.positions_end.size(), 3u);
  EXPECT_NEAR(posed.positions_end[2].z, 1.5f, 1e-6);
  EXPECT_EQ(still.shapes[0].deformation, -1);
}

TEST(PoseScene, TwoTransformMotionIsHeldOutsideItsTimes) {
  SceneDesc desc;
  desc.animation.nodes.resize(1);  // animated, though this shape moves by its own two transforms
  ShapeDesc shape;
  shape.geometry = SphereShape{};
  shape.to_world_end = Transform::translate({4, 0, 0});
  desc.shapes = {shape};
  desc.transform_start_time = 0;
  desc.transform_end_time = 1;
  const SceneDesc during = pose_scene(desc, {0.25f, 0.5f});
  EXPECT_NEAR(during.shapes[0].to_world.point({0, 0, 0}).x, 1, 1e-5);
  ASSERT_TRUE(during.shapes[0].to_world_end);
  EXPECT_NEAR(during.shapes[0].to_world_end->point({0, 0, 0}).x, 2, 1e-5);
  const SceneDesc after = pose_scene(desc, {3, 4});
  EXPECT_NEAR(after.shapes[0].to_world.point({0, 0, 0}).x, 4, 1e-5);
  EXPECT_FALSE(after.shapes[0].to_world_end);
}

TEST(PoseScene, FrameTimesCentreTheShutterOnTheFrame) {
  const FrameTime t = frame_time(12, 24, 0.5);
  EXPECT_NEAR(t.open, 0.5 - 0.25 / 24, 1e-6);
  EXPECT_NEAR(t.close, 0.5 + 0.25 / 24, 1e-6);
  EXPECT_EQ(frame_time(3, 30, 0).open, frame_time(3, 30, 0).close);
}

}  // namespace
}  // namespace candela
