// The path integrator's strategies estimate the same image: uniform, cosine and BSDF direction
// sampling, with and without MIS, one or several shadow rays, lights chosen by power or by the
// paper's rule. Only the noise differs. Each comparison checks the difference of image means
// against the standard error computed from the renders, and the per-pixel differences against
// their own variances (a chi-square-like statistic that must be about 1 per pixel).
#include <gtest/gtest.h>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

// A soft-shadow test scene: a glossy sphere (the paper's material) over a diffuse floor, lit by a
// rectangular area light, a sphere light, a point light and a dim sky.
SceneDesc soft_shadow_scene(int spp) {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 2.5f, -6}, {0, 0.5f, 0}, 40), 48, 36, spp, 5);
  PhongMaterial glossy;
  glossy.diffuse = RGB(0.6f, 0.3f, 0.2f);
  glossy.specular = RGB(0.9f);
  glossy.exponent = 20;
  glossy.d = 0.5f;
  glossy.s = 0.4f;
  glossy.t = 0;
  d.materials = {DiffuseMaterial{RGB(0.7f)}, glossy, BlackMaterial{}};
  ShapeDesc floor{.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}}, .material = 0};
  ShapeDesc sphere{.geometry = SphereShape{{0, 1, 0}, 1}, .material = 1};
  ShapeDesc panel;
  panel.geometry = RectangleShape{{-1, 4, -1}, {2, 0, 0}, {0, 0, 2}};  // normal cross(u, v) = -y: faces down
  panel.material = 2;
  panel.emission = AreaEmission{RGB(3.0f), false};
  ShapeDesc bulb{.geometry = SphereShape{{2.5f, 2.5f, -1}, 0.3f}, .material = 2,
                 .emission = AreaEmission{RGB(8.0f, 6.0f, 4.0f), false}};
  d.shapes = {floor, sphere, panel, bulb};
  d.lights = {PointLight{{-3, 3, -2}, RGB(4.0f)}, SkyLight{RGB(0.1f), RGB(0.1f), RGB(0.1f), {0, 1, 0}}};
  return d;
}

struct Comparison {
  double mean_difference_in_se;  // |mean A - mean B| / standard error of the difference
  double per_pixel_chi2;         // mean over pixels of (A - B)^2 / (var A + var B); about 1 if equal
};

Comparison compare(const Film& a, const Film& b) {
  Image ma = a.mean_image(), mb = b.mean_image(), va = a.variance_of_mean_image(), vb = b.variance_of_mean_image();
  double diff = 0, var = 0, chi2 = 0;
  int n = 0;
  for (size_t i = 0; i < ma.rgb.size(); ++i) {
    diff += double(ma.rgb[i]) - mb.rgb[i];
    var += double(va.rgb[i]) + vb.rgb[i];
    double v = double(va.rgb[i]) + vb.rgb[i];
    if (v > 0) {
      chi2 += (double(ma.rgb[i]) - mb.rgb[i]) * (double(ma.rgb[i]) - mb.rgb[i]) / v;
      ++n;
    }
  }
  return {std::abs(diff) / std::sqrt(var), chi2 / std::max(n, 1)};
}

void expect_same_image(const SceneDesc& a, const SceneDesc& b, const char* what) {
  SceneDesc b2 = b;
  b2.settings.seed = a.settings.seed + 1;  // independent noise
  Comparison c = compare(testing::render_description(a), testing::render_description(b2));
  EXPECT_LT(c.mean_difference_in_se, 4.0) << what;
  // Heavy-tailed pixels make the per-pixel statistic noisy; a biased strategy shows as >> 1.
  EXPECT_LT(c.per_pixel_chi2, 1.6) << what;
  EXPECT_GT(c.per_pixel_chi2, 0.5) << what;
}

TEST(PathIntegratorStrategies, DirectionSamplingDoesNotChangeTheImage) {
  SceneDesc bsdf = soft_shadow_scene(256), cosine = bsdf, uniform = bsdf;
  cosine.settings.path.direction_sampling = DirectionSampling::Cosine;
  uniform.settings.path.direction_sampling = DirectionSampling::Uniform;
  expect_same_image(bsdf, cosine, "bsdf vs cosine");
  expect_same_image(bsdf, uniform, "bsdf vs uniform");
}

TEST(PathIntegratorStrategies, MisOnAndOffAgree) {
  SceneDesc mis = soft_shadow_scene(256), no_mis = mis;
  no_mis.settings.path.mis = false;
  expect_same_image(mis, no_mis, "MIS vs no MIS");
  no_mis.settings.path.direction_sampling = DirectionSampling::Uniform;
  expect_same_image(mis, no_mis, "MIS vs the paper's uniform sampling without MIS");
}

TEST(PathIntegratorStrategies, ShadowRayCountAndLightSelectionAgree) {
  SceneDesc one = soft_shadow_scene(256), four = one, paper = one;
  four.settings.path.shadow_rays = 4;
  paper.settings.light_selection = LightSelection::Paper;
  paper.settings.path.shadow_rays = 4;
  expect_same_image(one, four, "1 vs 4 shadow rays");
  expect_same_image(one, paper, "power vs paper's rule");
  paper.settings.path.mis = false;
  expect_same_image(one, paper, "paper's rule without MIS");
  SceneDesc bvh = one;
  bvh.settings.light_selection = LightSelection::Bvh;
  expect_same_image(one, bvh, "power vs light BVH");
  bvh.settings.path.shadow_rays = 3;
  expect_same_image(one, bvh, "light BVH, 3 shadow rays");
  bvh.settings.path.mis = false;
  expect_same_image(one, bvh, "light BVH without MIS");
}

TEST(PathIntegratorStrategies, ComparisonDetectsABiasedRender) {
  // The same check must fail when one image is wrong by a little: the panel light 3% brighter.
  SceneDesc a = soft_shadow_scene(256), b = a;
  b.shapes[2].emission->radiance = RGB(3.0f * 1.03f);
  b.settings.seed = 9;
  Comparison c = compare(testing::render_description(a), testing::render_description(b));
  EXPECT_GT(c.mean_difference_in_se, 4.0);
}

TEST(PathIntegratorStrategies, MoreShadowRaysLowerTheNoise) {
  // Direct light only, without MIS: the noise left is that of the shadow rays and the pixel jitter.
  SceneDesc one = soft_shadow_scene(16), eight = one;
  one.settings.max_depth = eight.settings.max_depth = 1;
  one.settings.path.mis = eight.settings.path.mis = false;
  eight.settings.path.shadow_rays = 8;
  auto noise = [](const Film& f) {
    double v = 0;
    for (float x : f.variance_of_mean_image().rgb) v += x;
    return v;
  };
  double ratio = noise(testing::render_description(one)) / noise(testing::render_description(eight));
  std::printf("variance ratio, 1 vs 8 shadow rays: %.2f\n", ratio);
  EXPECT_GT(ratio, 1.5);
}

}  // namespace
}  // namespace candela
