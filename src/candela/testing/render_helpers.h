#pragma once
// Helpers for tests that render: build a scene description in code, render it, and reduce images
// to means with standard errors estimated from the render itself.
#include <cmath>
#include <functional>
#include <vector>

#include "candela/film/film.h"
#include "candela/integrators/integrator.h"
#include "candela/description/scene_desc.h"
#include "candela/scene/scene.h"

namespace candela::testing {

inline Film render_description(const SceneDesc& desc, int threads = 0) {
  Scene scene(desc);
  Film film(desc.film.width, desc.film.height);
  RenderOptions options;
  options.threads = threads;
  options.progress = false;
  render(scene, desc.settings, film, options);
  return film;
}

// The mean over the selected pixels of one channel (or the average of all three when channel < 0),
// and its standard error from the spread of the pixel values (pixels are independent estimates of
// the same value when the selection covers a uniform region).
struct MeanEstimate {
  double mean = 0, standard_error = 0;
  int pixels = 0;
};

inline MeanEstimate region_mean(const Image& img, int channel,
                                const std::function<bool(int, int)>& selected = [](int, int) { return true; }) {
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (!selected(x, y)) continue;
      RGB c = img.at(x, y);
      double v = channel < 0 ? c.average() : c[channel];
      sum += v;
      sum_sq += v * v;
      ++n;
    }
  MeanEstimate e;
  e.pixels = n;
  if (n == 0) return e;
  e.mean = sum / n;
  double var = n > 1 ? std::max(0.0, (sum_sq - n * e.mean * e.mean) / (n - 1)) : 0.0;
  e.standard_error = std::sqrt(var / n);
  return e;
}

// relMSE = mean((x - y)^2 / (y^2 + eps)) over pixels and channels, y the reference (the project's metric).
// The mean of independent estimates of one value (the image means of renders with different seeds)
// and its standard error from their spread: for estimators whose pixels are correlated (splats,
// photons), where the spread of the pixels would understate it.
inline MeanEstimate mean_of_estimates(const std::vector<double>& estimates) {
  MeanEstimate e;
  const double n = double(estimates.size());
  for (double m : estimates) e.mean += m / n;
  double v = 0;
  for (double m : estimates) v += (m - e.mean) * (m - e.mean) / (n - 1);
  e.standard_error = std::sqrt(v / n);
  e.pixels = int(estimates.size());
  return e;
}

inline double rel_mse(const Image& test, const Image& ref, double eps = 0.01) {
  double sum = 0;
  for (size_t i = 0; i < test.rgb.size(); ++i) {
    double d = double(test.rgb[i]) - ref.rgb[i];
    sum += d * d / (double(ref.rgb[i]) * ref.rgb[i] + eps);
  }
  return sum / double(test.rgb.size());
}

// Camera at `eye` looking at `target` with a vertical fov, on a small square image.
inline CameraDesc look_at_camera(const Point3& eye, const Point3& target, float fov_degrees) {
  CameraDesc c;
  Vec3 up = std::abs(normalize(target - eye).y) > 0.99f ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
  c.world_from_camera = Transform::look_at_right_handed(eye, target, up);
  c.fov_degrees = fov_degrees;
  return c;
}

// A scene with nothing in it yet but its camera, film size, samples per pixel and path depth.
inline SceneDesc empty_scene(const CameraDesc& camera, int width, int height, int spp, int max_depth) {
  SceneDesc d;
  d.film = {width, height, ""};
  d.camera = camera;
  d.settings.spp = spp;
  d.settings.max_depth = max_depth;
  return d;
}

// A closed diffuse sphere of radius 2 around the origin, seen from just off its centre on a 16 x 16
// image: the furnace scenes with analytic answers (Le / (1 - rho), rho I / (pi r^2 (1 - rho))).
// A unit sphere of `material` at the origin seen from z = -4 (it subtends asin(1/4) = 14.5 degrees)
// under a uniform sky: the furnace scene of several tests.
inline SceneDesc sphere_under_sky(const MaterialDesc& material, const RGB& sky, int size, float fov_degrees,
                                  int spp, int max_depth) {
  SceneDesc d;
  d.film = {size, size, ""};
  d.camera = look_at_camera({0, 0, -4}, {0, 0, 0}, fov_degrees);
  d.settings.spp = spp;
  d.settings.max_depth = max_depth;
  d.materials = {material};
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, 0}, 1};
  s.material = 0;
  d.shapes = {s};
  d.lights = {SkyLight{sky, sky, sky, {0, 1, 0}}};
  return d;
}

inline SceneDesc closed_diffuse_sphere(float albedo, int max_depth) {
  SceneDesc d;
  d.film = {16, 16, ""};
  d.camera = look_at_camera({0.1f, -0.2f, 0.05f}, {1, 0.3f, 0.2f}, 60);
  d.settings.max_depth = max_depth;
  d.materials = {DiffuseMaterial{RGB(albedo)}};
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, 0}, 2};
  s.material = 0;
  d.shapes = {s};
  return d;
}

}  // namespace candela::testing
