// The JSON format's keyframed animation (docs/animation.md): tracks of each kind, node references
// from shapes, instances and the camera, skins and morph targets, the writer's round trip, the errors
// with their places, and the examples of docs/animation.md.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "candela/animation/pose.h"
#include "candela/base/error.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/json_reader_helpers.h"

namespace candela {
namespace {

using namespace candela::testing::json_reader;

// ---------------------------------------------------------------- comparing descriptions

void expect_same(const std::optional<Keyframes>& a, const std::optional<Keyframes>& b, const std::string& what) {
  ASSERT_EQ(a.has_value(), b.has_value()) << what;
  if (!a) return;
  EXPECT_EQ(a->interpolation, b->interpolation) << what;
  EXPECT_EQ(a->width, b->width) << what;
  EXPECT_EQ(a->rotation, b->rotation) << what;
  EXPECT_EQ(a->times, b->times) << what;
  EXPECT_EQ(a->values, b->values) << what;
}

void expect_same(const SceneAnimation& a, const SceneAnimation& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const AnimationNode &x = a.nodes[i], &y = b.nodes[i];
    const std::string what = "node " + std::to_string(i);
    EXPECT_EQ(x.name, y.name) << what;
    EXPECT_EQ(x.parent, y.parent) << what;
    EXPECT_EQ(x.matrix, y.matrix) << what;
    EXPECT_EQ(x.trs.translation, y.trs.translation) << what;
    EXPECT_EQ(x.trs.rotation, y.trs.rotation) << what;
    EXPECT_EQ(x.trs.scale, y.trs.scale) << what;
    expect_same(x.trs.translation_keys, y.trs.translation_keys, what + " translation");
    expect_same(x.trs.rotation_keys, y.trs.rotation_keys, what + " rotation");
    expect_same(x.trs.scale_keys, y.trs.scale_keys, what + " scale");
    expect_same(x.weights_keys, y.weights_keys, what + " weights");
  }
  ASSERT_EQ(a.skins.size(), b.skins.size());
  for (size_t i = 0; i < a.skins.size(); ++i) {
    EXPECT_EQ(a.skins[i].name, b.skins[i].name);
    EXPECT_EQ(a.skins[i].joints, b.skins[i].joints);
    EXPECT_EQ(a.skins[i].inverse_bind, b.skins[i].inverse_bind);
  }
  ASSERT_EQ(a.deformations.size(), b.deformations.size());
  for (size_t i = 0; i < a.deformations.size(); ++i) {
    const MeshDeformation &x = a.deformations[i], &y = b.deformations[i];
    EXPECT_EQ(x.skin, y.skin);
    EXPECT_EQ(x.influences, y.influences);
    EXPECT_EQ(x.joints, y.joints);
    EXPECT_EQ(x.weights, y.weights);
    EXPECT_EQ(x.target_positions, y.target_positions);
    EXPECT_EQ(x.target_normals, y.target_normals);
    EXPECT_EQ(x.default_weights, y.default_weights);
    EXPECT_EQ(x.weights_node, y.weights_node);
  }
}

Keyframes keys(Interpolation interpolation, int width, std::vector<float> times, std::vector<float> values,
               bool rotation = false) {
  Keyframes k;
  k.interpolation = interpolation;
  k.width = width;
  k.rotation = rotation;
  k.times = std::move(times);
  k.values = std::move(values);
  EXPECT_EQ(k.problem(), "");
  return k;
}

// ---------------------------------------------------------------- reading

TEST(JsonAnimationReader, ReadsEachKindOfTrack) {
  const SceneDesc scene = read(R"({"animation": {"nodes": [
      {"name": "a",
       "translation": {"interpolation": "step", "times": [0, 1], "values": [[1, 2, 3], [4, 5, 6]]},
       "rotation": {"times": [0, 2], "values": [[0, 0, 0, 1], {"axis": [0, 1, 0], "angle": 90}]},
       "scale": {"interpolation": "cubicspline", "times": [1, 3],
                 "values": [[[0, 0, 0], [1, 1, 1], [0.5, 0, 0]], [[0, 0.5, 0], [2, 2, 2], [0, 0, 0]]]},
       "weights": {"times": [0, 1, 2], "values": [[0, 1], [0.5, 0.5], [1, 0]]}},
      {"name": "b", "parent": "a", "translation": [0, 1, 0], "rotation": [0, 0, 1, 0], "scale": 2},
      {"parent": 1, "matrix": [1, 0, 0, 5,  0, 1, 0, 6,  0, 0, 1, 7,  0, 0, 0, 1]}]}})");
  const SceneAnimation& a = scene.animation;
  ASSERT_EQ(a.nodes.size(), 3u);
  const AnimatedTrs& trs = a.nodes[0].trs;
  EXPECT_EQ(a.nodes[0].name, "a");
  EXPECT_EQ(a.nodes[0].parent, -1);

  ASSERT_TRUE(trs.translation_keys);
  EXPECT_EQ(trs.translation_keys->interpolation, Interpolation::Step);
  EXPECT_EQ(trs.translation_keys->width, 3);
  EXPECT_EQ(trs.translation_keys->times, (std::vector<float>{0, 1}));
  EXPECT_EQ(trs.translation_keys->values, (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(trs.translation, (std::array<float, 3>{1, 2, 3}));  // a keyframed part's constant: its first value

  ASSERT_TRUE(trs.rotation_keys);
  EXPECT_EQ(trs.rotation_keys->interpolation, Interpolation::Linear);  // the default
  EXPECT_TRUE(trs.rotation_keys->rotation);
  EXPECT_EQ(trs.rotation_keys->width, 4);
  const float h = float(std::sqrt(0.5));
  ASSERT_EQ(trs.rotation_keys->values.size(), 8u);
  const std::vector<float> expected_rotation{0, 0, 0, 1, 0, h, 0, h};
  for (size_t i = 0; i < 8; ++i) EXPECT_NEAR(trs.rotation_keys->values[i], expected_rotation[i], 1e-7) << i;

  ASSERT_TRUE(trs.scale_keys);
  EXPECT_EQ(trs.scale_keys->interpolation, Interpolation::CubicSpline);
  EXPECT_EQ(trs.scale_keys->values,
            (std::vector<float>{0, 0, 0, 1, 1, 1, 0.5f, 0, 0, 0, 0.5f, 0, 2, 2, 2, 0, 0, 0}));
  EXPECT_EQ(trs.scale, (std::array<float, 3>{1, 1, 1}));  // the first key's value, not its in-tangent

  ASSERT_TRUE(a.nodes[0].weights_keys);
  EXPECT_EQ(a.nodes[0].weights_keys->width, 2);
  EXPECT_EQ(a.nodes[0].weights_keys->values, (std::vector<float>{0, 1, 0.5f, 0.5f, 1, 0}));

  const AnimationNode& b = a.nodes[1];
  EXPECT_EQ(b.parent, 0);  // by name
  EXPECT_FALSE(b.trs.animated());
  EXPECT_EQ(b.trs.translation, (std::array<float, 3>{0, 1, 0}));
  EXPECT_EQ(b.trs.rotation, (std::array<float, 4>{0, 0, 1, 0}));
  EXPECT_EQ(b.trs.scale, (std::array<float, 3>{2, 2, 2}));

  const AnimationNode& c = a.nodes[2];
  EXPECT_EQ(c.parent, 1);
  ASSERT_TRUE(c.matrix);
  EXPECT_EQ(c.matrix->m[0][3], 5);  // row by row, as a transform's matrix step
  EXPECT_EQ(c.matrix->m[2][3], 7);
  EXPECT_EQ(a.problem(), "");
}

// {"axis", "angle"} turns as the transform step {"rotate": {"axis", "angle"}} does.
TEST(JsonAnimationReader, AxisAngleRotatesAsTheRotateStep) {
  const SceneDesc scene =
      read(R"({"animation": {"nodes": [{"rotation": {"axis": [1, 2, -0.5], "angle": 73}}]}})");
  const std::array<float, 4> q = scene.animation.nodes[0].trs.rotation;
  const Matrix4 m = rotation_matrix({q[0], q[1], q[2], q[3]});
  const Matrix4 expected = Transform::rotate(73, {1, 2, -0.5f}).matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(m.m[r][c], expected.m[r][c], 1e-6) << r << c;
}

TEST(JsonAnimationReader, ShapesInstancesAndTheCameraRideOnNodes) {
  const SceneDesc scene = read(R"({
    "camera": {"position": [0, 0, -5], "look_at": [0, 0, 0], "animation_node": "rig"},
    "animation": {"nodes": [{"name": "rig", "translation": {"times": [0, 1], "values": [[0, 0, 0], [1, 0, 0]]}},
                            {"name": "arm", "parent": "rig"}]},
    "objects": {"o": {"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]}},
    "shapes": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 1, "animation_node": 1},
      {"type": "instance", "object": "o", "animation_node": "rig"},
      {"type": "sphere", "center": [0, 0, 0], "radius": 1,
       "animation": {"name": "spin", "parent": "arm", "rotation": {"times": [0, 1],
                     "values": [{"axis": [0, 1, 0], "angle": 0}, {"axis": [0, 1, 0], "angle": 90}]}}},
      {"type": "instance", "object": "o", "animation": {"scale": {"times": [0, 1], "values": [[1, 1, 1], [2, 2, 2]]}}},
      {"type": "sphere", "center": [0, 0, 0], "radius": 1, "animation_node": "spin"},
      {"type": "sphere", "center": [0, 0, 0], "radius": 1}]})");
  EXPECT_EQ(scene.camera.animation_node, 0);
  ASSERT_EQ(scene.shapes.size(), 4u);
  EXPECT_EQ(scene.shapes[0].animation_node, 1);
  // Inline nodes follow those of "animation", in the file's order.
  ASSERT_EQ(scene.animation.nodes.size(), 4u);
  EXPECT_EQ(scene.shapes[1].animation_node, 2);
  EXPECT_EQ(scene.animation.nodes[2].name, "spin");
  EXPECT_EQ(scene.animation.nodes[2].parent, 1);
  EXPECT_EQ(scene.shapes[2].animation_node, 2);  // a named inline node, referred to later
  EXPECT_EQ(scene.shapes[3].animation_node, -1);
  ASSERT_EQ(scene.instances.size(), 2u);
  EXPECT_EQ(scene.instances[0].animation_node, 0);
  EXPECT_EQ(scene.instances[1].animation_node, 3);
  EXPECT_TRUE(scene.animation.nodes[3].trs.scale_keys);
}

// A shape's transform is relative to its node's world transform (parent times child), at each time.
TEST(JsonAnimationReader, ThePosedSceneComposesNodeAndShapeTransforms) {
  const SceneDesc scene = read(R"({
    "animation": {"nodes": [{"translation": {"times": [0, 2], "values": [[0, 0, 0], [4, 0, 0]]}},
                            {"parent": 0, "rotation": {"times": [0, 2],
                             "values": [{"axis": [0, 0, 1], "angle": 0}, {"axis": [0, 0, 1], "angle": 90}]}}]},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "animation_node": 1,
                "transform": [{"translate": [1, 0, 0]}]}]})");
  const SceneDesc still = pose_scene(scene, {1, 1});
  // At t = 1: the parent has moved 2 along x, the child turned 45 degrees about z, the shape sits
  // 1 along the child's x.
  expect_near(still.shapes[0].to_world.point({0, 0, 0}), {2 + std::sqrt(0.5f), std::sqrt(0.5f), 0});
}

TEST(JsonAnimationReader, TheCameraKeyframesItsLens) {
  const SceneDesc scene = read(R"({"camera": {
      "fov": {"times": [0, 1], "values": [60, 30]},
      "focus_distance": {"interpolation": "cubicspline", "times": [0, 2], "values": [[0, 2, 1], [-1, 8, 0]]},
      "lens_radius": {"interpolation": "step", "times": [0], "values": [0.25]}}})");
  const CameraDesc& c = scene.camera;
  ASSERT_TRUE(c.fov_keys && c.focus_distance_keys && c.lens_radius_keys);
  EXPECT_EQ(c.fov_keys->values, (std::vector<float>{60, 30}));
  EXPECT_EQ(c.fov_keys->width, 1);
  EXPECT_EQ(c.focus_distance_keys->values, (std::vector<float>{0, 2, 1, -1, 8, 0}));
  EXPECT_EQ(c.lens_radius_keys->interpolation, Interpolation::Step);
  // The constants are the first values.
  EXPECT_EQ(c.fov_degrees, 60);
  EXPECT_EQ(c.focus_distance, 2);
  EXPECT_EQ(c.lens_radius, 0.25f);
  // Plain numbers still read as before.
  const SceneDesc plain = read(R"({"camera": {"fov": 50, "lens_radius": 0.1, "focus_distance": 3}})");
  EXPECT_FALSE(plain.camera.fov_keys || plain.camera.focus_distance_keys || plain.camera.lens_radius_keys);
  EXPECT_EQ(plain.camera.fov_degrees, 50);
}

const char* const kDeformingScene = R"({
  "animation": {
    "nodes": [{"name": "root"}, {"name": "bone", "parent": "root", "translation": [0, 1, 0]},
              {"name": "blend", "weights": {"times": [0, 1], "values": [[0, 0.5], [1, 0]]}}],
    "skins": [{"name": "arm", "joints": ["root", "bone"],
               "inverse_bind": [[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                                [1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1, 0, 0, 0, 0, 1]]},
              {"joints": [0]}],
    "deformations": [
      {"skin": "arm", "joints": [[0, 1], [0, 1], [1, 0], [1, 0]],
       "weights": [[1, 0], [0.5, 0.5], [1, 0], [0.25, 0.75]],
       "target_positions": [[[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]], []],
       "target_normals": [[], [[0, 1, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]]],
       "default_weights": [0.5, 0.25], "weights_node": "blend"},
      {"target_positions": [[[1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0]]]}]},
  "shapes": [
    {"type": "mesh", "deformation": 0, "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],
     "indices": [0, 1, 2, 2, 1, 3]},
    {"type": "mesh", "deformation": 1, "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],
     "indices": [0, 1, 2, 2, 1, 3], "animation_node": "bone", "transform": [{"translate": [0, 0, 3]}]}]})";

TEST(JsonAnimationReader, ReadsSkinsAndMorphTargets) {
  const SceneDesc scene = read(kDeformingScene);
  const SceneAnimation& a = scene.animation;
  ASSERT_EQ(a.skins.size(), 2u);
  EXPECT_EQ(a.skins[0].name, "arm");
  EXPECT_EQ(a.skins[0].joints, (std::vector<int>{0, 1}));
  EXPECT_EQ(a.skins[0].inverse_bind[1].m[1][3], -1);
  EXPECT_EQ(a.skins[1].inverse_bind, std::vector<Matrix4>{Matrix4::identity()});  // absent: identities
  ASSERT_EQ(a.deformations.size(), 2u);
  const MeshDeformation& d = a.deformations[0];
  EXPECT_EQ(d.skin, 0);
  EXPECT_EQ(d.influences, 2);
  EXPECT_EQ(d.joints, (std::vector<uint16_t>{0, 1, 0, 1, 1, 0, 1, 0}));
  EXPECT_EQ(d.weights, (std::vector<float>{1, 0, 0.5f, 0.5f, 1, 0, 0.25f, 0.75f}));
  ASSERT_EQ(d.target_positions.size(), 2u);
  EXPECT_EQ(d.target_positions[0][3], Vec3(0, 0, 1));
  EXPECT_TRUE(d.target_positions[1].empty());
  ASSERT_EQ(d.target_normals.size(), 2u);
  EXPECT_TRUE(d.target_normals[0].empty());
  EXPECT_EQ(d.target_normals[1].size(), 4u);
  EXPECT_EQ(d.default_weights, (std::vector<float>{0.5f, 0.25f}));
  EXPECT_EQ(d.weights_node, 2);
  EXPECT_EQ(a.deformations[1].skin, -1);
  EXPECT_EQ(scene.shapes[0].deformation, 0);
  EXPECT_EQ(scene.shapes[1].deformation, 1);
  EXPECT_EQ(scene.shapes[1].animation_node, 1);
  EXPECT_EQ(a.problem(), "");
  // It poses: at t = 1 the blend node weighs target 0 fully (+z), and the skin is at rest.
  const SceneDesc still = pose_scene(scene, {1, 1});
  const std::vector<Point3>& moved = std::get<MeshShape>(still.shapes[0].geometry).mesh.positions;
  expect_near(moved[0], {0, 0, 1});
  expect_near(moved[3], {1, 1, 1});
  // The second mesh has no weights: it keeps its shape and rides on its node.
  EXPECT_EQ(std::get<MeshShape>(still.shapes[1].geometry).mesh.positions[3], Vec3(1, 1, 0));
  expect_near(still.shapes[1].to_world.point({0, 0, 0}), {0, 1, 3});
}

// ---------------------------------------------------------------- writing

// A description with every part of the model: keyframes of each interpolation and width, a matrix
// node, a skin, morph targets with normals and default weights, nodes placing a shape, an instance
// and the camera, and the camera's lens keyframes. Keyframed parts' constants are their first
// values, as the reader makes them.
SceneDesc animated_description() {
  SceneDesc scene;
  SceneAnimation& a = scene.animation;
  AnimationNode root;
  root.name = "root";
  root.trs.translation_keys = keys(Interpolation::Step, 3, {0, 0.5f, 1.25f}, {1, 2, 3, 4, 5, 6, 7, 8, 9});
  root.trs.translation = {1, 2, 3};
  root.trs.rotation_keys = keys(Interpolation::Linear, 4, {0, 1}, {0, 0, 0, 1, 0, 0.70710677f, 0, 0.70710677f}, true);
  root.trs.scale = {1, 2, 0.1f};
  AnimationNode bone;
  bone.name = "bone";
  bone.parent = 0;
  bone.trs.rotation = {0.1f, 0.2f, 0.3f, 0.9f};
  bone.trs.scale_keys =
      keys(Interpolation::CubicSpline, 3, {0, 2}, {0, 0, 0, 1, 1, 1, 0.5f, 0.5f, 0.5f, -1, 0, 0, 3, 3, 3, 0, 0, 0});
  bone.trs.scale = {1, 1, 1};
  AnimationNode fixed;
  fixed.parent = 1;
  fixed.matrix = Transform::rotate(30, {1, 1, 0}).matrix();
  AnimationNode blend;
  blend.name = "root";  // a name shared: written (and read back) by index
  blend.weights_keys = keys(Interpolation::CubicSpline, 2, {0, 1},
                            {0, 0, 0.1f, 0.2f, 0, 0, 0, 0, 0.9f, 0.8f, 0, 0});
  AnimationNode single;
  single.weights_keys = keys(Interpolation::Linear, 1, {0, 1}, {0, 1});
  a.nodes = {root, bone, fixed, blend, single};
  Skin skin;
  skin.name = "skeleton";
  skin.joints = {0, 1};
  skin.inverse_bind = {Matrix4::identity(), Transform::translate({0, -1, 0.25f}).matrix()};
  a.skins = {skin};
  MeshDeformation skinned;
  skinned.skin = 0;
  skinned.influences = 2;
  skinned.joints = {0, 1, 1, 0, 0, 1, 1, 1};
  skinned.weights = {0.25f, 0.75f, 1, 0, 0.5f, 0.5f, 0.1f, 0.9f};
  skinned.target_positions = {{{0, 0, 1}, {0, 0, 1}, {0, 0, 2}, {0, 0, 2}}, {{1, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  skinned.target_normals = {{{0, 0.5f, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, {}};
  skinned.default_weights = {0.5f, 0};
  skinned.weights_node = 3;
  MeshDeformation morphed;
  morphed.target_positions = {{{0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}, {0.3f, 0.3f, 0.3f}}};
  morphed.weights_node = 4;
  a.deformations = {skinned, morphed};

  TriangleMesh quad;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  quad.indices = {0, 1, 2, 2, 1, 3};
  scene.shapes.push_back(ShapeDesc{.geometry = MeshShape{quad}, .deformation = 0});
  scene.shapes.push_back(ShapeDesc{.geometry = MeshShape{quad}, .to_world = Transform::translate({0, 0, 2}),
                                   .animation_node = 2, .deformation = 1});
  scene.shapes.push_back(ShapeDesc{.geometry = SphereShape{}, .animation_node = 0});
  scene.objects.push_back(ObjectDesc{.shapes = {ShapeDesc{.geometry = SphereShape{}}}});
  scene.instances.push_back(InstanceDesc{.object = 0, .to_world = Transform::scale({2, 2, 2}), .animation_node = 1});
  scene.camera.animation_node = 1;
  scene.camera.fov_keys = keys(Interpolation::Linear, 1, {0, 3}, {45, 20});
  scene.camera.fov_degrees = 45;
  scene.camera.focus_distance_keys = keys(Interpolation::CubicSpline, 1, {0, 3}, {0, 4, 1, -1, 9, 0});
  scene.camera.focus_distance = 4;
  scene.camera.lens_radius_keys = keys(Interpolation::Step, 1, {1}, {0.5f});
  scene.camera.lens_radius = 0.5f;
  EXPECT_EQ(a.problem(), "");
  return scene;
}

TEST(JsonAnimationWriter, WritesAndReadsBackTheWholeAnimation) {
  const SceneDesc original = animated_description();
  const std::string text = scene_to_json(original);
  SceneDesc back = read(text);
  expect_same(back.animation, original.animation);
  ASSERT_EQ(back.shapes.size(), original.shapes.size());
  for (size_t i = 0; i < back.shapes.size(); ++i) {
    EXPECT_EQ(back.shapes[i].animation_node, original.shapes[i].animation_node) << i;
    EXPECT_EQ(back.shapes[i].deformation, original.shapes[i].deformation) << i;
    EXPECT_EQ(back.shapes[i].to_world.matrix(), original.shapes[i].to_world.matrix()) << i;
  }
  ASSERT_EQ(back.instances.size(), 1u);
  EXPECT_EQ(back.instances[0].animation_node, 1);
  EXPECT_EQ(back.camera.animation_node, 1);
  expect_same(back.camera.fov_keys, original.camera.fov_keys, "fov");
  expect_same(back.camera.focus_distance_keys, original.camera.focus_distance_keys, "focus_distance");
  expect_same(back.camera.lens_radius_keys, original.camera.lens_radius_keys, "lens_radius");
  EXPECT_EQ(back.camera.fov_degrees, original.camera.fov_degrees);
  EXPECT_EQ(back.camera.focus_distance, original.camera.focus_distance);
  EXPECT_EQ(back.camera.lens_radius, original.camera.lens_radius);
  // Writing what was read gives the same text.
  back.source_file.clear();
  EXPECT_EQ(scene_to_json(back), text);
}

// Hand-written shorthands (inline nodes, names, axis-angle rotations) come back in the long form,
// which reads to the same animation.
TEST(JsonAnimationWriter, ShorthandsComeBackInTheLongForm) {
  const SceneDesc first = read(R"({
    "camera": {"animation": {"translation": {"times": [0, 1], "values": [[0, 0, 0], [0, 1, 0]]}}},
    "animation": {"nodes": [{"name": "a", "rotation": {"axis": [0, 1, 0], "angle": 30}}]},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                "animation": {"parent": "a", "rotation": {"times": [0, 1],
                              "values": [{"axis": [1, 0, 0], "angle": 0}, {"axis": [1, 0, 0], "angle": 90}]}}}]})");
  const std::string text = scene_to_json(first);
  const nlohmann::json written = nlohmann::json::parse(text);
  EXPECT_FALSE(written["shapes"][0].contains("animation"));
  EXPECT_EQ(written["shapes"][0]["animation_node"], 2);
  EXPECT_EQ(written["camera"]["animation_node"], 1);
  EXPECT_EQ(written["animation"]["nodes"][2]["parent"], 0);
  const SceneDesc second = read(text);
  expect_same(second.animation, first.animation);
}

TEST(JsonAnimationWriter, ASceneWithoutAnimationWritesNoAnimationKeys) {
  SceneDesc scene = read(R"({"camera": {"fov": 30, "lens_radius": 0.1, "focus_distance": 2},
    "objects": {"o": {"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "transform": [{"translate": [0, 1, 0]}]},
               {"type": "instance", "object": "o"}]})");
  const std::string text = scene_to_json(scene);
  for (const char* key : {"animation", "deformation", "interpolation", "\"times\""})
    EXPECT_EQ(text.find(key), std::string::npos) << key;
  const nlohmann::json written = nlohmann::json::parse(text);
  EXPECT_EQ(written["camera"]["fov"], 30);
  EXPECT_FLOAT_EQ(written["camera"]["lens_radius"].get<float>(), 0.1f);
  EXPECT_EQ(written["camera"]["focus_distance"], 2);
}

// ---------------------------------------------------------------- errors

// The message for `text` is `expected` (file:line:col: at pointer: message) exactly.
void expect_error(const std::string& text, const std::string& expected) {
  EXPECT_EQ(error_of(text), expected);
}

TEST(JsonAnimationErrors, TrackValuesMustMatchItsTimes) {
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"translation\": {\"times\": [0, 1, 2], \"values\": [[0, 0, 0], [1, 1, 1]]}}]}}",
               "test.json:2:40: at /animation/nodes/0/translation/values: 3 keyframe times need 3 values (one per "
               "time), got 2");
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"scale\": {\"interpolation\": \"cubicspline\", \"times\": [0], \"values\": [[1, 1, 1]]}}]}}",
               "test.json:2:71: at /animation/nodes/0/scale/values/0: expected [in-tangent, value, out-tangent] (a "
               "cubic spline's key), got an array of 3 numbers");
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"weights\": {\"times\": [0, 1], \"values\": [[0, 1], [1]]}}]}}",
               "test.json:2:52: at /animation/nodes/0/weights/values/1: expected 2 weights (one per morph target, as "
               "the first key has), got 1");
  expect_error("{\"camera\": {\n"
               "  \"fov\": {\"times\": [0, 1], \"values\": [40, 190]}}}",
               "test.json:2:43: at /camera/fov/values/1: expected a number in (0, 180), got 190");
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"translation\": {\"times\": [], \"values\": []}}]}}",
               "test.json:2:20: at /animation/nodes/0/translation/times: keyframes need at least one time");
}

TEST(JsonAnimationErrors, TimesMustIncrease) {
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"rotation\": {\"times\": [0, 1.5, 1],\n"
               "                \"values\": [[0, 0, 0, 1], [0, 0, 0, 1], [0, 0, 0, 1]]}}]}}",
               "test.json:2:35: at /animation/nodes/0/rotation/times/2: keyframe times must increase: time 2 (1) "
               "follows 1.5");
  expect_error(R"({"camera": {"lens_radius": {"times": [1, 1], "values": [0, 0]}}})",
               "test.json:1:42: at /camera/lens_radius/times/1: keyframe times must increase: time 1 (1) follows 1");
}

TEST(JsonAnimationErrors, UnknownInterpolationListsTheKnownOnes) {
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"scale\": {\"interpolation\": \"cubic\", \"times\": [0], \"values\": [[1, 1, 1]]}}]}}",
               "test.json:2:14: at /animation/nodes/0/scale/interpolation: unknown interpolation \"cubic\"; expected "
               "one of: step, linear, cubicspline");
}

TEST(JsonAnimationErrors, NodeReferencesMustExist) {
  expect_error("{\"animation\": {\"nodes\": [{}, {}, {}]},\n"
               " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"animation_node\": 7}]}",
               "test.json:2:66: at /shapes/0/animation_node: node 7 is out of range: there are 3 animation nodes (0 "
               "to 2)");
  expect_error("{\"camera\": {\"animation_node\": 0}}",
               "test.json:1:13: at /camera/animation_node: node 0 is out of range: there are no animation nodes");
  expect_error("{\"animation\": {\"nodes\": [{\"name\": \"arm\"},\n"
               "  {\"parent\": \"amr\"}]}}",
               "test.json:2:4: at /animation/nodes/1/parent: unknown animation node \"amr\" (did you mean \"arm\"?); "
               "named nodes: arm");
  expect_error("{\"animation\": {\"nodes\": [{\"name\": \"a\"}, {\"name\": \"a\"}]},\n"
               " \"shapes\": [{\"type\": \"instance\", \"object\": \"o\", \"animation_node\": \"a\"}],\n"
               " \"objects\": {\"o\": {\"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1}]}}}",
               "test.json:2:49: at /shapes/0/animation_node: 2 nodes are called \"a\" (nodes 0, 1): refer to one by "
               "its index");
  expect_error("{\"animation\": {\"nodes\": [{}],\n"
               "  \"skins\": [{\"joints\": [0, -1]}]}}",
               "test.json:2:28: at /animation/skins/0/joints/1: node -1 is out of range: there is 1 animation node (0 "
               "to 0)");
}

TEST(JsonAnimationErrors, ParentsMustNotFormACycle) {
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"parent\": 1},\n"
               "  {\"parent\": 2},\n"
               "  {\"parent\": 0}]}}",
               "test.json:2:4: at /animation/nodes/0/parent: node 0 is its own ancestor: its parents lead round in a "
               "cycle 0 -> 1 -> 2 -> 0");
  expect_error("{\"animation\": {\"nodes\": [{}, {}, \n"
               "  {\"name\": \"loop\", \"parent\": \"loop\"}]}}",
               "test.json:2:20: at /animation/nodes/2/parent: node 2 is its own ancestor: its parents lead round in a "
               "cycle 2 -> 2");
}

TEST(JsonAnimationErrors, NodesTakeAMatrixOrTrsNotBoth) {
  expect_error("{\"animation\": {\"nodes\": [\n"
               "  {\"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], \"scale\": 2}]}}",
               "test.json:2:64: at /animation/nodes/0/scale: a node takes either \"matrix\" or \"translation\", "
               "\"rotation\" and \"scale\", not both");
  expect_error_containing(R"({"animation": {"nodes": [{"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]}]}})",
                          "at /animation/nodes/0/matrix: the matrix must be affine");
  expect_error_containing(R"({"animation": {"nodes": [{"rotation": [0, 0, 0, 0]}]}})",
                          "at /animation/nodes/0/rotation: a rotation quaternion must not be zero");
  expect_error_containing(R"({"animation": {"nodes": [{"rotation": {"axis": [0, 1, 0], "angel": 90}}]}})",
                          "at /animation/nodes/0/rotation: missing required key \"angle\"");
  expect_error_containing(R"({"animation": {"nodes": [{"translate": [0, 1, 0]}]}})",
                          "at /animation/nodes/0/translate: unknown key (did you mean \"translation\"?)");
}

TEST(JsonAnimationErrors, DeformationsMustFitTheirMeshes) {
  auto scene = [](const std::string& deformation, const std::string& shape_keys) {
    return R"({"animation": {"nodes": [{}, {"weights": {"times": [0], "values": [[1, 0, 0]]}}],
               "skins": [{"joints": [0]}], "deformations": [)" +
           deformation + R"(]},
      "shapes": [{"type": "mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]])" + shape_keys + "}]}";
  };
  const std::string morph = R"({"target_positions": [[[0, 0, 1], [0, 0, 1], [0, 0, 1]]]})";
  EXPECT_NO_THROW(read(scene(morph, R"(, "deformation": 0)")));
  expect_error_containing(scene(R"({"target_positions": [[[0, 0, 1], [0, 0, 1]]]})", R"(, "deformation": 0)"),
                          "at /shapes/0/deformation: deformation 0 is for 2 vertices but the mesh has 3");
  expect_error_containing(scene(morph, R"(, "deformation": 1)"),
                          "at /shapes/0/deformation: deformation 1 is out of range: the scene has 1 deformation");
  expect_error_containing(scene(R"({"target_positions": [[[0, 0, 1], [0, 0, 1], [0, 0, 1]], [[0, 0, 1]]]})", ""),
                          "at /animation/deformations/0/target_positions/1: expected one entry per vertex (3, as "
                          "/animation/deformations/0/target_positions/0 has), got 1");
  expect_error_containing(scene(R"({"target_positions": [[[0, 0, 1], [0, 0, 1], [0, 0, 1]]], "weights_node": 1})", ""),
                          "at /animation/deformations/0/weights_node: node 1 keyframes 3 weights but the mesh has 1 "
                          "morph target");
  expect_error_containing(scene(R"({"skin": 0, "joints": [[0], [1], [0]], "weights": [[1], [1], [1]]})", ""),
                          "at /animation/deformations/0/joints/1/0: joint 1 is out of range: the skin has 1 joint");
  expect_error_containing(scene(R"({"skin": 0, "joints": [[0], [0], [0]], "weights": [[1], [1]]})", ""),
                          "at /animation/deformations/0/weights: expected one entry per vertex (3, as \"joints\" has)");
  expect_error_containing(scene(R"({"joints": [[0], [0], [0]], "weights": [[1], [1], [1]]})", ""),
                          "at /animation/deformations/0/joints: \"joints\" and \"weights\" skin the mesh");
  expect_error_containing(scene(R"({"default_weights": [1]})", ""),
                          "at /animation/deformations/0/default_weights: \"default_weights\" belongs to morph targets");
  expect_error_containing(scene("{}", ""), "at /animation/deformations/0: a deformation needs a \"skin\"");
  const std::string skinned = R"({"skin": 0, "joints": [[0], [0], [0]], "weights": [[1], [1], [1]]})";
  EXPECT_NO_THROW(read(scene(skinned, R"(, "deformation": 0)")));
  expect_error_containing(scene(skinned, R"(, "deformation": 0, "transform": [{"translate": [0, 1, 0]}])"),
                          "at /shapes/0/transform: a skinned mesh is placed by its skin's joints");
  expect_error_containing(scene(skinned, R"(, "deformation": 0, "animation_node": 0)"),
                          "at /shapes/0/animation_node: a skinned mesh is placed by its skin's joints");
  expect_error_containing(with_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "deformation": 0})"),
                          "at /shapes/0/deformation: deformation 0 is out of range: the scene has 0 deformations");
}

TEST(JsonAnimationErrors, AnimatedThingsCannotAlsoMoveOtherwise) {
  expect_error_containing(R"({"animation": {"nodes": [{}]}, "shapes": [{"type": "sphere", "center": [0, 0, 0],
      "radius": 1, "animation_node": 0, "transform_end": [{"translate": [0, 1, 0]}]}]})",
                          "at /shapes/0/transform_end: an animated shape is moved by its node");
  expect_error_containing(R"({"animation": {"nodes": [{}]},
      "objects": {"o": {"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "animation_node": 0}]}}})",
                          "at /objects/o/shapes/0/animation_node: a shape in an object cannot be animated");
  expect_error_containing(R"({"animation": {"nodes": [{}]}, "shapes": [{"type": "sphere", "center": [0, 0, 0],
      "radius": 1, "animation_node": 0, "animation": {}}]})",
                          "at /shapes/0/animation: give either \"animation_node\" or an inline \"animation\"");
  expect_error_containing(R"({"camera": {"animation": {"translation": {"times": [0], "values": [[0, 0, 0]]},
      "spin": 1}}})", "at /camera/animation/spin: unknown key");
}

// ---------------------------------------------------------------- docs/animation.md

// Every json block of docs/animation.md is JSON, and those marked `<!-- test: scene -->` are whole
// scenes that read.
TEST(JsonAnimationDocs, EveryExampleReads) {
  std::ifstream in(kSourceDir / "docs/animation.md");
  ASSERT_TRUE(in) << "docs/animation.md not found";
  std::string line, previous, example;
  bool in_example = false, is_scene = false;
  int blocks = 0, scenes = 0;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (!in_example && line == "```json") {
      in_example = true;
      is_scene = previous == "<!-- test: scene -->";
      example.clear();
    } else if (in_example && line == "```") {
      in_example = false;
      ++blocks;
      const std::string name = "animation.md example ending on line " + std::to_string(line_number);
      if (is_scene) {
        ++scenes;
        try {
          const SceneDesc scene = read_json_scene(example, name, kSourceDir / "scenes");
          EXPECT_NO_THROW(pose_scene(scene, {0.5f, 0.75f})) << name;
        } catch (const SceneError& e) {
          ADD_FAILURE() << e.what();
        }
      } else {
        EXPECT_TRUE(nlohmann::json::accept(example)) << name << ":\n" << example;
      }
    } else if (in_example) {
      example += line + "\n";
    }
    previous = line;
  }
  EXPECT_GE(blocks, 7);
  EXPECT_GE(scenes, 4);
}

}  // namespace
}  // namespace candela
