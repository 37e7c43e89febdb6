// An orthographic camera with the path tracer, bidirectional path tracing and Metropolis light
// transport: no light path can connect to an orthographic camera (t = 1 contributes nothing), so
// BDPT's MIS weights must leave that strategy out for the others to sum to one, and MLT's chains
// choosing it must find nothing. The scene also has Mitsuba's new emitters: a disk area light, a
// Mitsuba spot light and a projector, plus a diffuse cylinder, all out of the camera's direct view.
// Images agree when the mean of their difference over the image and each quadrant is within 4
// standard errors (BDPT: estimated from the pixels' spread; MLT: from the spread over seeds).
#include <gtest/gtest.h>

#include <cmath>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

SceneDesc orthographic_scene() {
  SceneDesc d;
  d.film = {24, 24, ""};
  // Looking along +z at a wall at z = 0; the film spans [-1.5, 1.5]^2 (a scaled camera).
  d.camera.projection = Projection::Orthographic;
  d.camera.world_from_camera = Transform::look_at_right_handed({0, 0, -5}, {0, 0, 0}, {0, 1, 0}) *
                               Transform::scale({1.5f, 1.5f, 1});
  d.camera.near_clip = 1;
  d.settings.max_depth = 3;
  d.textures = {CheckerboardTexture{RGB(1.0f), RGB(0.2f), UVMapping{3, 3, 0, 0}}};
  d.materials = {DiffuseMaterial{RGB(0.7f, 0.6f, 0.5f)}, DiffuseMaterial{RGB(0.3f, 0.6f, 0.8f)}};
  ShapeDesc wall;
  wall.geometry = RectangleShape{{-4, -4, 0}, {0, 8, 0}, {8, 0, 0}};  // normal -z, towards the camera
  wall.material = 0;
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-4, -1.8f, -4}, {0, 0, 4}, {8, 0, 0}};  // normal +y
  floor.material = 0;
  ShapeDesc tube;
  tube.geometry = CylinderShape{{0.5f, -1.8f, -1}, {0.5f, 1, -1}, 0.3f};
  tube.material = 1;
  ShapeDesc lamp;  // above the view, tilted towards the wall and the floor
  lamp.geometry = DiskShape{};
  lamp.to_world = Transform::translate({-0.5f, 2.2f, -1.5f}) * Transform::rotate(60, {1, 0, 0}) *
                  Transform::scale({0.5f, 0.5f, 1});
  lamp.material = 0;
  lamp.emission = AreaEmission{RGB(6.0f), false};
  d.shapes = {wall, floor, tube, lamp};
  SpotLight spot;
  spot.position = {-1, 0.3f, -3};
  spot.direction = normalize(Vec3(0.2f, -0.1f, 1));
  spot.intensity = RGB(3.0f, 2.5f, 2.0f);
  spot.cone_angle = 25;
  spot.cone_delta = 10;
  spot.falloff = SpotFalloff::Linear;
  ProjectorLight projector;
  projector.to_world = Transform::look_at_right_handed({1, 0.5f, -3}, {0.8f, 0, 0}, {0, 1, 0});
  projector.fov_degrees = 30;
  projector.irradiance = 0;
  projector.scale = RGB(0.5f);
  d.lights = {spot, projector};
  return d;
}

// An emissive tube standing on a diffuse floor, seen straight from above (the tube's wall edge-on):
// the floor right beside the wall is lit from very near, where the strategies' densities differ
// most, so a weight that kept the impossible t = 1 strategy would show.
SceneDesc tube_on_floor() {
  SceneDesc d;
  d.film = {24, 24, ""};
  d.camera.projection = Projection::Orthographic;
  d.camera.world_from_camera = Transform::look_at_right_handed({0, 3, 0}, {0, 0, 0}, {0, 0, 1}) *
                               Transform::scale({1.2f, 1.2f, 1});
  d.settings.max_depth = 2;
  d.materials = {DiffuseMaterial{RGB(0.7f)}};
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-3, 0, -3}, {0, 0, 6}, {6, 0, 0}};  // normal +y
  floor.material = 0;
  ShapeDesc tube;
  tube.geometry = CylinderShape{{0, 0, 0}, {0, 1, 0}, 0.3f};
  tube.material = 0;
  tube.emission = AreaEmission{RGB(2.0f), false};
  d.shapes = {floor, tube};
  return d;
}

Image render_image(SceneDesc d, const std::string& integrator, int spp, uint64_t seed) {
  d.settings.integrator = integrator;
  d.settings.spp = spp;
  d.settings.seed = seed;
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 128;
  return testing::render_description(d).mean_image();
}

struct Region {
  int x0, y0, x1, y1;
};
const Region kRegions[] = {{0, 0, 24, 24}, {0, 0, 12, 12}, {12, 0, 24, 12}, {0, 12, 12, 24}, {12, 12, 24, 24}};

double region_average(const Image& img, const Region& r) {
  double s = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) s += img.at(x, y).average();
  return s / double((r.x1 - r.x0) * (r.y1 - r.y0));
}

// The difference's mean per region within 4 standard errors of its pixels' spread.
void expect_agree(const Image& a, const Image& b, const std::string& what) {
  for (const Region& r : kRegions) {
    double sum = 0, sum_sq = 0;
    int n = 0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        double v = (a.at(x, y) - b.at(x, y)).average();
        sum += v;
        sum_sq += v * v;
        ++n;
      }
    double mean = sum / n, se = std::sqrt(std::max(0.0, (sum_sq - n * mean * mean) / (n - 1)) / n);
    EXPECT_LE(std::abs(mean), 4 * se + 1e-6) << what << ": mean difference " << mean << " +- " << se << " over ["
                                             << r.x0 << "," << r.x1 << ")x[" << r.y0 << "," << r.y1 << ")";
  }
}

// Metropolis: region means over 4 seeds against the path tracer's (whose own error is small).
void expect_metropolis_agrees(const SceneDesc& d, const Image& path, const char* what) {
  const int seeds = 4;
  std::vector<Image> mlt;
  for (int s = 1; s <= seeds; ++s) mlt.push_back(render_image(d, "mlt", 64, uint64_t(10 + s)));
  for (const Region& r : kRegions) {
    double m = 0, m2 = 0;
    for (const Image& img : mlt) {
      double v = region_average(img, r);
      m += v / seeds;
      m2 += v * v / seeds;
    }
    double se = std::sqrt(std::max(0.0, m2 - m * m) / (seeds - 1));
    double ref = region_average(path, r);
    EXPECT_NEAR(m, ref, 4 * se + 0.02 * ref) << what << ": mlt vs path over [" << r.x0 << "," << r.x1 << ")x[" << r.y0 << ","
                                             << r.y1 << "), seed spread " << se;
  }
}

TEST(OrthographicIntegrators, PathBidirectionalAndMetropolisAgree) {
  const SceneDesc d = orthographic_scene();
  Image path = render_image(d, "path", 256, 1);
  Image bdpt = render_image(d, "bdpt", 128, 2);
  // The image is far from black.
  EXPECT_GT(region_average(path, kRegions[0]), 0.05);
  expect_agree(bdpt, path, "bdpt vs path");
  expect_metropolis_agrees(d, path, "orthographic scene");
}

TEST(OrthographicIntegrators, BidirectionalAndMetropolisAgreeWhereLightIsNear) {
  const SceneDesc d = tube_on_floor();
  Image path = render_image(d, "path", 512, 3);
  Image bdpt = render_image(d, "bdpt", 256, 4);
  expect_agree(bdpt, path, "bdpt vs path, tube on a floor");
  expect_metropolis_agrees(d, path, "tube on a floor");
}

}  // namespace
}  // namespace candela
