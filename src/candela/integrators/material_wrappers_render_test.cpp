// Renders of the material wrappers with analytic answers: a mask against a flat sky (the opacity-
// weighted mix, and Mitsuba's depth rule: what is seen through a mask at the last bounce gets no
// direct light), one-sided surfaces seen from the back, identity normal and bump maps, a tilted
// normal map's cosine, and a white furnace of every wrapper. Path tracing and BDPT (whose vertex
// code MLT shares).
#include <gtest/gtest.h>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using namespace testing;  // the render helpers: render_description, region_mean, look_at_camera, ...

void expect_mean(const testing::MeanEstimate& e, double expected, const std::string& what) {
  EXPECT_NEAR(e.mean, expected, 4 * e.standard_error + 1e-4 * std::max(1.0, std::abs(expected)))
      << what << " (standard error " << e.standard_error << ")";
}

// A large rectangle in the z = 0 plane facing +z (or -z), seen from z = 3 looking down, under a
// constant white sky.
SceneDesc plane_scene(const std::vector<MaterialDesc>& materials, bool facing_up = true) {
  SceneDesc d;
  d.film = {16, 16, ""};
  d.camera = look_at_camera({0, 0, 3}, {0, 0, 0}, 20);
  d.settings.spp = 64;
  d.settings.max_depth = 1;
  d.materials = materials;
  ShapeDesc s;
  s.geometry = facing_up ? RectangleShape{{-5, -5, 0}, {10, 0, 0}, {0, 10, 0}} : RectangleShape{{-5, -5, 0}, {0, 10, 0}, {10, 0, 0}};
  s.material = int(materials.size()) - 1;
  d.shapes = {s};
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 0, 1}}};
  return d;
}

MaskMaterial mask_of(int material, float opacity) {
  MaskMaterial m{.opacity = opacity, .material = material};
  return m;
}

TEST(MaterialWrappersRender, MaskIsTheOpacityWeightedMix) {
  // Front: o R L (direct sky light) + (1 - o) L (the sky through the passage).
  for (const char* integrator : {"path", "bdpt"}) {
    SceneDesc d = plane_scene({DiffuseMaterial{RGB(0.6f)}, mask_of(0, 0.3f)});
    d.settings.integrator = integrator;
    Image img = render_description(d).mean_image();
    expect_mean(region_mean(img, -1), 0.3 * 0.6 + 0.7, std::string("mask, ") + integrator);
  }
}

TEST(MaterialWrappersRender, WhatAMaskShowsAtTheLastBounceGetsNoDirectLight) {
  // A second, opaque plane below the mask: with max_depth 1 (Mitsuba's 2) the passage through the mask
  // is the last bounce, so the plane behind contributes nothing (it does not emit).
  for (const char* integrator : {"path", "bdpt"}) {
    SceneDesc d = plane_scene({DiffuseMaterial{RGB(0.6f)}, mask_of(0, 0.3f)});
    d.settings.integrator = integrator;
    ShapeDesc floor;
    floor.geometry = RectangleShape{{-50, -50, -1}, {100, 0, 0}, {0, 100, 0}};
    floor.material = 0;
    d.shapes.push_back(floor);
    Image img = render_description(d).mean_image();
    expect_mean(region_mean(img, -1), 0.3 * 0.6, std::string("mask over a floor, ") + integrator);
  }
}

TEST(MaterialWrappersRender, TwoSidedShowsEachSideItsOwnMaterial) {
  // Front albedo 0.6, back 0.2 (each lit by the sky on its side): the camera sees the side it faces.
  for (const char* integrator : {"path", "bdpt", "mlt"}) {
    for (bool facing_up : {true, false}) {
      SceneDesc d = plane_scene({DiffuseMaterial{RGB(0.6f)}, DiffuseMaterial{RGB(0.2f)}, TwoSidedMaterial{0, 1}},
                                facing_up);
      d.settings.integrator = integrator;
      expect_mean(region_mean(render_description(d).mean_image(), -1), facing_up ? 0.6 : 0.2,
                  std::string(facing_up ? "front, " : "back, ") + integrator);
    }
  }
  // Wrapping it is refused: the side is chosen per hit, before any other wrapper.
  SceneDesc wrapped = plane_scene({DiffuseMaterial{RGB(0.6f)}, DiffuseMaterial{RGB(0.2f)}, TwoSidedMaterial{0, 1},
                                   mask_of(2, 0.5f)});
  EXPECT_THROW(render_description(wrapped), SceneError);
}

TEST(MaterialWrappersRender, HiddenEmittersStillLightTheScene) {
  // A black emissive square (radiance 4) between the camera and the plane, facing the camera, over
  // the plane lit by the sky: with hide_emitters the square the camera sees is black, and every
  // other pixel is bitwise what it was (the same random numbers, the same light).
  for (const char* integrator : {"path", "bdpt", "mlt"}) {
    SceneDesc d = plane_scene({BlackMaterial{}, DiffuseMaterial{RGB(0.6f)}});
    ShapeDesc seen;
    seen.geometry = RectangleShape{{-0.2f, -0.2f, 1}, {0.4f, 0, 0}, {0, 0.4f, 0}};
    seen.material = 0;
    seen.emission = AreaEmission{RGB(4.0f)};
    d.shapes.push_back(seen);
    d.settings.integrator = integrator;
    d.settings.max_depth = 2;
    SceneDesc hidden = d;
    hidden.settings.hide_emitters = true;
    Image shown = render_description(d).mean_image(), dark = render_description(hidden).mean_image();
    auto in_square = [](int x, int y) { return x >= 6 && x < 10 && y >= 6 && y < 10; };  // inside the seen square
    expect_mean(region_mean(shown, -1, in_square), 4.0, std::string("emitter shown, ") + integrator);
    expect_mean(region_mean(dark, -1, in_square), 0.0, std::string("emitter hidden, ") + integrator);
    auto outside = [](int x, int y) { return x < 3 || x >= 13 || y < 3 || y >= 13; };  // clear of the square
    MeanEstimate lit = region_mean(shown, -1, outside);
    EXPECT_GT(lit.mean, 0.01) << integrator;  // the lamp lights the plane
    if (std::string(integrator) != "mlt") {
      size_t differing = 0;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          if (outside(x, y))
            for (int c = 0; c < 3; ++c) differing += shown.at(x, y)[c] != dark.at(x, y)[c];
      EXPECT_EQ(differing, 0u) << integrator;
    } else {
      expect_mean(region_mean(dark, -1, outside), lit.mean, std::string("plane, emitters hidden, ") + integrator);
    }
  }
}

TEST(MaterialWrappersRender, OneSidedSurfaceIsBlackFromTheBack) {
  for (const char* integrator : {"path", "bdpt"}) {
    // The plane faces away from the camera; the sky lights the side the camera sees.
    SceneDesc two = plane_scene({DiffuseMaterial{RGB(0.6f)}}, false);
    SceneDesc one = plane_scene({DiffuseMaterial{RGB(0.6f)}, OneSidedMaterial{0}}, false);
    two.settings.integrator = one.settings.integrator = integrator;
    expect_mean(region_mean(render_description(two).mean_image(), -1), 0.6, std::string("two-sided, ") + integrator);
    expect_mean(region_mean(render_description(one).mean_image(), -1), 0.0, std::string("one-sided, ") + integrator);
    // Seen from the front it is the material itself.
    SceneDesc front = plane_scene({DiffuseMaterial{RGB(0.6f)}, OneSidedMaterial{0}}, true);
    front.settings.integrator = integrator;
    expect_mean(region_mean(render_description(front).mean_image(), -1), 0.6, std::string("front, ") + integrator);
  }
}

// A sphere with an anisotropic rough conductor under a point light and a sky: the scene in which
// identity normal and bump maps must change nothing.
SceneDesc conductor_sphere(int wrapper) {
  SceneDesc d;
  d.film = {24, 24, ""};
  d.camera = look_at_camera({0, 0, -4}, {0, 0, 0}, 35);
  d.settings.spp = 8;
  d.settings.max_depth = 3;
  ConductorMaterial metal;
  metal.roughness.u = 0.25f;
  metal.roughness.v = 0.05f;
  d.materials = {metal};
  d.textures = {ScaleTexture{ColorInput(RGB(0.5f, 0.5f, 1.0f)), FloatInput(1.0f)}};
  if (wrapper == 1) d.materials.push_back(NormalMapMaterial{0, 0});
  if (wrapper == 2) d.materials.push_back(BumpMapMaterial{0, 0.5f, 0});
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, 0}, 1};
  s.to_world = Transform::rotate(30, {1, 1, 0});
  s.material = int(d.materials.size()) - 1;
  d.shapes = {s};
  d.lights = {PointLight{{-2, 3, -3}, RGB(20.0f)}, SkyLight{RGB(0.3f), RGB(0.3f), RGB(0.3f), {0, 1, 0}}};
  return d;
}

TEST(MaterialWrappersRender, IdentityNormalAndBumpMapsChangeNothing) {
  Image plain = render_description(conductor_sphere(0)).mean_image();
  double total = 0;
  for (float v : plain.rgb) total += v;
  ASSERT_GT(total, 0);
  for (int wrapper : {1, 2}) {
    Image mapped = render_description(conductor_sphere(wrapper)).mean_image();
    double diff = 0;
    for (size_t i = 0; i < plain.rgb.size(); ++i) diff += std::abs(double(mapped.rgb[i]) - plain.rgb[i]);
    EXPECT_LT(diff / total, 1e-3) << (wrapper == 1 ? "normal map" : "bump map");
  }
}

TEST(MaterialWrappersRender, TiltedNormalMapShadesWithTheTiltedCosine) {
  // A diffuse plane (normal +z, dp/du = +x) under a distant light from (sin 45, 0, cos 45): the
  // reflected radiance is R E cos(n', d) / pi with n' the mapped normal in the frame (dp/du, n x dp/du, n).
  const float R = 0.5f;
  const Vec3 d = normalize(Vec3(1, 0, 1));
  struct Case {
    RGB rgb;
    Vec3 n;
  } cases[] = {{RGB(0.5f, 0.5f, 1.0f), Vec3(0, 0, 1)},
               {RGB(0.75f, 0.5f, 0.5f + 0.5f * std::sqrt(0.75f)), Vec3(0.5f, 0, std::sqrt(0.75f))},
               {RGB(0.5f, 0.75f, 0.5f + 0.5f * std::sqrt(0.75f)), Vec3(0, 0.5f, std::sqrt(0.75f))}};
  for (const char* integrator : {"path", "bdpt"})
    for (const Case& c : cases) {
      SceneDesc s;
      s.film = {8, 8, ""};
      s.camera = look_at_camera({0, 0, 3}, {0, 0, 0}, 10);
      s.settings.spp = 4;
      s.settings.max_depth = 1;
      s.settings.integrator = integrator;
      s.textures = {ScaleTexture{ColorInput(c.rgb), FloatInput(1.0f)}};
      s.materials = {DiffuseMaterial{RGB(R)}, NormalMapMaterial{0, 0}};
      ShapeDesc plane;
      plane.geometry = RectangleShape{{-2, -2, 0}, {4, 0, 0}, {0, 4, 0}};
      plane.material = 1;
      s.shapes = {plane};
      s.lights = {DistantLight{-d, RGB(1.0f)}};
      Image img = render_description(s).mean_image();
      double expected = R * kInvPi * std::max(0.0f, dot(normalize(c.n), d));
      expect_mean(region_mean(img, -1), expected, std::string("normal ") + std::to_string(c.n.x) + "," +
                                                      std::to_string(c.n.y) + ", " + integrator);
    }
}

TEST(MaterialWrappersRender, WhiteFurnaceNeverGainsEnergy) {
  // A sphere of each wrapper over white materials under a white sky: no pixel brighter than the sky.
  ConductorMaterial white_metal;
  white_metal.reflectance = ColorInput(RGB(0.9999f));
  white_metal.roughness.u = white_metal.roughness.v = 0.3f;
  white_metal.roughness.distribution = MicrofacetDistribution::Beckmann;
  BlendMaterial blend{.weight = 0.5f, .material0 = 0, .material1 = 1};
  DielectricMaterial beckmann_glass;
  beckmann_glass.roughness.u = beckmann_glass.roughness.v = 0.2f;
  beckmann_glass.roughness.distribution = MicrofacetDistribution::Beckmann;
  CoatedDiffuseMaterial plastic;
  plastic.reflectance = RGB(1.0f);
  plastic.roughness.u = plastic.roughness.v = 0.2f;
  plastic.roughness.distribution = MicrofacetDistribution::Beckmann;
  const std::vector<std::pair<MaterialDesc, std::string>> wrappers = {
      {mask_of(0, 0.4f), "mask"},
      {blend, "blend"},
      {OneSidedMaterial{0}, "one-sided"},
      {NormalMapMaterial{0, 0}, "normal map"},
      {BumpMapMaterial{1, 0.3f, 1}, "bump map"},
      {beckmann_glass, "Beckmann glass"},
      {plastic, "Beckmann plastic"},
  };
  for (const auto& [wrapper, name] : wrappers) {
    SceneDesc d;
    d.film = {16, 16, ""};
    d.camera = look_at_camera({0, 0, -4}, {0, 0, 0}, 30);
    d.settings.spp = 32;
    d.settings.max_depth = 50;
    d.textures = {ScaleTexture{ColorInput(RGB(0.7f, 0.55f, 0.9f)), FloatInput(1.0f)},
                  CheckerboardTexture{ColorInput(RGB(0.0f)), ColorInput(RGB(1.0f)), {8, 8, 0, 0}}};
    d.materials = {DiffuseMaterial{RGB(1.0f)}, white_metal, wrapper};
    ShapeDesc s;
    s.geometry = SphereShape{{0, 0, 0}, 1};
    s.material = 2;
    d.shapes = {s};
    d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
    Image img = render_description(d).mean_image();
    testing::MeanEstimate e = region_mean(img, -1);
    EXPECT_LE(e.mean, 1.0 + 4 * e.standard_error + 1e-3) << name;
    EXPECT_GT(e.mean, 0.3) << name;
  }
}

}  // namespace
}  // namespace candela
