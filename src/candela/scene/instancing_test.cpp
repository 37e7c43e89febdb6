// Object instancing (pbrt's ObjectBegin/ObjectInstance) through Embree instances: a scene of
// instances renders as the same scene with every instance expanded into ordinary shapes, including
// non-uniform scales, mirroring transforms, spheres inside objects, textures and a moving instance.
#include <gtest/gtest.h>

#include "candela/base/error.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

SceneDesc base_scene() {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 3, 9}, {0, 0.5f, 0}, 40), 48, 48, 16, 4);
  d.settings.seed = 7;
  d.camera.shutter_open = 0;
  d.camera.shutter_close = 1;
  d.textures.push_back(CheckerboardTexture{RGB(0.8f, 0.3f, 0.2f), RGB(0.1f, 0.6f, 0.9f), UVMapping{4, 4, 0, 0}});
  d.materials.push_back(DiffuseMaterial{RGB(0.6f)});
  DiffuseMaterial textured;
  textured.reflectance.texture = 0;
  d.materials.push_back(textured);
  ConductorMaterial metal;
  metal.roughness.u = metal.roughness.v = 0.2f;
  d.materials.push_back(metal);
  ShapeDesc floor{.geometry = RectangleShape{{-6, 0, 6}, {12, 0, 0}, {0, 0, -12}}, .material = 0};
  d.shapes.push_back(floor);
  ShapeDesc light{.geometry = SphereShape{{0, 6, 3}, 1}, .material = -1, .emission = AreaEmission{RGB(8.0f), false}};
  d.shapes.push_back(light);
  d.lights.push_back(SkyLight{RGB(0.2f), RGB(0.2f), RGB(0.2f), {0, 1, 0}});
  return d;
}

// The object: a textured box and a metal sphere, in object space.
std::vector<ShapeDesc> object_shapes() {
  ShapeDesc box{.geometry = BoxShape{{-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f}}, .material = 1};
  ShapeDesc sphere{.geometry = SphereShape{{0, 0, 0}, 0.4f}, .to_world = Transform::translate({0, 1.4f, 0}),
                   .material = 2};
  return {box, sphere};
}

struct Placement {
  Transform to_world;
  std::optional<Transform> to_world_end;
};

std::vector<Placement> placements() {
  return {{Transform::translate({-2.5f, 0, 0}), std::nullopt},
          {Transform::translate({0, 0, -1}) * Transform::rotate(30, {0, 1, 0}) * Transform::scale({1.5f, 0.7f, 1}),
           std::nullopt},
          {Transform::translate({2.5f, 0, 0}) * Transform::scale({-1, 1, 1}), std::nullopt},  // mirrored
          {Transform::translate({0, 0, 2}), Transform::translate({0.8f, 0, 2})}};               // moving
}

SceneDesc instanced_scene() {
  SceneDesc d = base_scene();
  d.objects.push_back({object_shapes(), "thing"});
  for (const auto& p : placements()) d.instances.push_back({0, p.to_world, p.to_world_end});
  return d;
}

SceneDesc expanded_scene() {
  SceneDesc d = base_scene();
  for (const auto& p : placements())
    for (ShapeDesc s : object_shapes()) {
      Transform local = s.to_world;
      s.to_world = p.to_world * local;
      if (p.to_world_end) s.to_world_end = *p.to_world_end * local;
      d.shapes.push_back(s);
    }
  return d;
}

TEST(Instancing, RendersLikeTheExpandedScene) {
  Image a = testing::render_description(instanced_scene()).mean_image();
  Image b = testing::render_description(expanded_scene()).mean_image();
  // The same rays meet the same surfaces with the same random numbers: only rounding differs (hit
  // points computed in object space and transformed), which moves a few paths' later bounces.
  double sum = 0, diff = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    sum += b.rgb[i];
    diff += std::abs(double(a.rgb[i]) - b.rgb[i]);
  }
  EXPECT_GT(sum, 0);
  EXPECT_LT(diff / sum, 0.01) << "mean absolute difference relative to the mean";
  int identical = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) identical += std::abs(a.rgb[i] - b.rgb[i]) <= 1e-4f * (1 + b.rgb[i]);
  EXPECT_GT(identical, int(0.95 * double(a.rgb.size())));
}

TEST(Instancing, EmissiveOrMovingShapesInsideObjectsAreErrors) {
  SceneDesc d = instanced_scene();
  d.objects[0].shapes[0].emission = AreaEmission{RGB(1.0f), false};
  EXPECT_THROW(Scene{d}, SceneError);
  d = instanced_scene();
  d.objects[0].shapes[1].to_world_end = Transform::translate({0, 2, 0});
  EXPECT_THROW(Scene{d}, SceneError);
  d = instanced_scene();
  d.instances[0].object = 3;
  EXPECT_THROW(Scene{d}, SceneError);
}

}  // namespace
}  // namespace candela
