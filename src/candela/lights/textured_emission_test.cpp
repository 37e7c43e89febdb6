// Textured area emitters (AreaEmission::texture): a rectangle light whose radiance is a 2 x 2
// checkerboard must light a diffuse floor exactly as four untextured quarter rectangles of the two
// radiances do. Shadow rays (sample_li), emission seen by bounces (Scene::emitted, MIS) and light
// paths (sample_le, BDPT) all read the texture at the sampled point, so any of them reading it wrong
// changes the floor's brightness pattern. On spheres, disks and cylinders, whose lights compute the
// (u, v) of a sampled point themselves, every sample's radiance must be what a ray finds there.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>

#include "candela/lights/light.h"
#include "candela/sampling/rng.h"
#include "candela/scene/scene.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

constexpr float kBright = 4, kDim = 1;

SceneDesc floor_scene() {
  SceneDesc d;
  d.film = {32, 32, ""};
  d.camera = testing::look_at_camera({0, 3, -0.01f}, {0, 0, 0}, 70);
  d.settings.max_depth = 1;
  d.settings.spp = 256;
  d.settings.seed = 3;
  d.materials = {DiffuseMaterial{RGB(0.8f)}, BlackMaterial{}};
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-2, 0, -2}, {0, 0, 4}, {4, 0, 0}};  // normal +y
  floor.material = 0;
  d.shapes = {floor};
  return d;
}

// The light: 1 x 1 at height 1 above the floor's centre, facing down; (s, t) along +x and +z.
ShapeDesc light_rect(Point3 corner, float size_x, float size_z, float radiance, int texture) {
  ShapeDesc l;
  l.geometry = RectangleShape{corner, {size_x, 0, 0}, {0, 0, size_z}};  // cross(x, z) = -y: down
  l.material = 1;
  l.emission = AreaEmission{RGB(radiance), false, texture};
  return l;
}

SceneDesc textured() {
  SceneDesc d = floor_scene();
  CheckerboardTexture c;
  c.tex1 = RGB(1.0f);
  c.tex2 = RGB(kDim / kBright);
  c.mapping = {2, 2, 0, 0};  // four cells; (s, t) in [0, 0.5)^2 is "even": bright
  d.textures = {c};
  d.shapes.push_back(light_rect({-0.5f, 1, -0.5f}, 1, 1, kBright, 0));
  return d;
}

SceneDesc quarters() {
  SceneDesc d = floor_scene();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      d.shapes.push_back(
          light_rect({-0.5f + 0.5f * i, 1, -0.5f + 0.5f * j}, 0.5f, 0.5f, (i + j) % 2 == 0 ? kBright : kDim, -1));
  return d;
}

// Per quadrant of the image (which sees the floor under one cell), the mean of the pixel-wise
// difference: zero in expectation, its standard error from the spread of the differences (noise only,
// as the two images have the same expectation in every pixel).
void expect_same_quadrants(const Image& a, const Image& b, const char* what) {
  Image difference(a.width, a.height);
  for (size_t i = 0; i < a.rgb.size(); ++i) difference.rgb[i] = a.rgb[i] - b.rgb[i];
  for (int q = 0; q < 4; ++q) {
    auto in_quadrant = [q](int x, int y) { return (x < 16) == (q % 2 == 0) && (y < 16) == (q < 2); };
    testing::MeanEstimate d = testing::region_mean(difference, -1, in_quadrant);
    double mean = testing::region_mean(b, -1, in_quadrant).mean;
    EXPECT_NEAR(d.mean, 0, 5 * d.standard_error) << what << " quadrant " << q << " (mean " << mean << ")";
    std::printf("%s quadrant %d: mean %.5f, difference %.5f +- %.5f\n", what, q, mean, d.mean, d.standard_error);
  }
}

TEST(TexturedEmission, CheckerboardLightEqualsFourUntexturedQuartersOnTheFloor) {
  for (const char* integrator : {"path", "bdpt"}) {
    SceneDesc a = textured(), b = quarters();
    a.settings.integrator = b.settings.integrator = integrator;
    expect_same_quadrants(testing::render_description(a).mean_image(), testing::render_description(b).mean_image(),
                          integrator);
  }
}

TEST(TexturedEmission, SeenDirectlyTheLightShowsItsTexture) {
  // Looking up at the light from below its centre: each quarter of the image sees one cell.
  SceneDesc d = textured();
  d.shapes.erase(d.shapes.begin());  // no floor
  d.camera = testing::look_at_camera({0, 0, 0}, {0, 1, 0}, 40);
  d.settings.spp = 4;
  Image image = testing::render_description(d).mean_image();
  float lo = 1e30f, hi = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      if (x == 15 || x == 16 || y == 15 || y == 16) continue;  // pixels on the cells' edges
      float v = image.at(x, y).r;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  EXPECT_NEAR(lo, kDim, 1e-4f);
  EXPECT_NEAR(hi, kBright, 1e-4f);
}

// A textured sphere, disk or cylinder emitter: the radiance each light sample carries (shadow rays,
// sample_li; light paths, sample_le) must equal what Scene::emitted gives where a ray meets that
// point, so the light's (u, v) is the hit's. The texture is an 8 x 4 checkerboard: a wrong
// convention (u and v swapped, phi from another axis, the object frame ignored) disagrees on about
// half the samples.
struct AnalyticEmitter {
  const char* name;
  ShapeGeometry geometry;
  Transform to_world;
  Point3 viewpoint;  // a point outside that sees much of the emitting side
};

TEST(TexturedEmission, AnalyticEmittersCarryTheTextureRaysFindAtTheirSamples) {
  const Transform turn = Transform::rotate(35, normalize(Vec3(1, 2, -1)));
  const AnalyticEmitter cases[] = {
      {"sphere", SphereShape{{0.2f, 0, 0}, 0.8f}, Transform::translate({1, 0.5f, 2}) * turn * Transform::scale(Vec3(1.5f)),
       {4, 3, -2}},
      {"mirrored sphere", SphereShape{{0, 0, 0}, 1}, turn * Transform::scale({-1, 1, 1}), {-3, 2, 2}},
      {"skewed disk", DiskShape{}, turn * Transform::scale({1.5f, 0.7f, 1}), turn.point({0.3f, 0.2f, 2})},
      {"cylinder", CylinderShape{{0, 0, -1}, {0.5f, 0, 1}, 0.6f}, Transform::translate({0, 1, 0}) * turn,
       turn.point({3, 1, 0.5f}) + Vec3(0, 1, 0)},
  };
  for (const AnalyticEmitter& c : cases) {
    SceneDesc d;
    CheckerboardTexture board;
    board.tex1 = RGB(1.0f);
    board.tex2 = RGB(0.25f);
    board.mapping = {8, 4, 0, 0};
    d.textures = {board};
    d.materials = {BlackMaterial{}};
    ShapeDesc shape;
    shape.geometry = c.geometry;
    shape.to_world = c.to_world;
    shape.material = 0;
    shape.emission = AreaEmission{RGB(2.0f), true, 0};
    d.shapes = {shape};
    Scene scene(d);
    ASSERT_EQ(scene.lights().size(), 1u) << c.name;
    const Light& light = scene.lights()[0];
    const float far = std::numeric_limits<float>::infinity();
    Rng rng(7, 11);
    int checked = 0, disagree = 0, bright = 0;
    // Only where the ray meets the sampled point itself (on a tube, the far side's samples are hidden).
    auto compare = [&](const RGB& carried, const Ray& ray, float distance, const Vec3& towards) {
      SurfaceHit hit;
      if (!scene.intersect(ray, hit) || std::abs(hit.t - distance) > 1e-3f * distance) return;
      ++checked;
      RGB found = scene.emitted(hit, towards);
      disagree += std::abs(found.r - carried.r) > 1e-4f;
      bright += carried.r > 1;
    };
    for (int i = 0; i < 4000; ++i) {
      Vec2 u{rng.next_float(), rng.next_float()}, v{rng.next_float(), rng.next_float()};
      LightSample ls = light_sample_li(light, {c.viewpoint, Normal3(0.0f)}, u);
      if (ls.pdf > 0) compare(ls.radiance, Ray{c.viewpoint, ls.wi, far, 0}, ls.distance, -ls.wi);
      // Back along an emitted ray, from just off the surface, to the point it left.
      LightEmission le = light_sample_le(light, u, v, scene.bounding_sphere());
      if (le.pdf_pos > 0 && le.pdf_dir > 0) compare(le.radiance, Ray{le.p + le.w * 1e-3f, -le.w, far, 0}, 1e-3f, le.w);
    }
    EXPECT_GT(checked, 5000) << c.name;
    EXPECT_LE(disagree, checked / 1000) << c.name << ": " << disagree << " of " << checked << " samples";
    EXPECT_GT(bright, checked / 4) << c.name << ": the texture's bright cells must show";
    EXPECT_LT(bright, 3 * checked / 4) << c.name << ": the texture's dim cells must show";
  }
}

}  // namespace
}  // namespace candela
