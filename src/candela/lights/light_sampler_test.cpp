// The light BVH: its choice probabilities sum to 1 and are what sample() draws (chi-square), its
// bounds hold every emitter, and no light that can light a point is ever given probability zero
// there (which would bias every estimator using it).
#include "candela/lights/light_sampler.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "candela/io/scene_reader.h"
#include "candela/sampling/rng.h"
#include "candela/testing/render_helpers.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

Vec3 random_unit(Rng& rng) {
  return square_to_uniform_sphere({rng.next_float(), rng.next_float()});
}
Point3 random_point(Rng& rng, float extent) {
  return {extent * (2 * rng.next_float() - 1), extent * (2 * rng.next_float() - 1), extent * (2 * rng.next_float() - 1)};
}

// Every kind of light the BVH bounds, scattered through a 10-unit cube, and a sky and a distant
// light beside the tree.
std::vector<Light> mixed_lights(int triangles) {
  Rng rng(7, 0);
  std::vector<Light> lights;
  for (int i = 0; i < triangles; ++i) {
    Point3 c = random_point(rng, 5);
    Point3 p0 = c + random_unit(rng) * 0.3f, p1 = c + random_unit(rng) * 0.3f, p2 = c + random_unit(rng) * 0.3f;
    Vec3 n = cross(p1 - p0, p2 - p0);
    float area = 0.5f * length(n);
    if (!(area > 1e-4f)) continue;
    RGB radiance(0.5f + 10 * rng.next_float(), 0.5f + 5 * rng.next_float(), 1.0f);
    lights.push_back(TriangleLight{p0, p1, p2, normalize(n), area, radiance, i % 5 == 0});
  }
  for (int i = 0; i < 10; ++i) lights.push_back(PointLightSource{random_point(rng, 5), RGB(1 + 10 * rng.next_float())});
  for (int i = 0; i < 5; ++i) {
    SpotLight desc;
    desc.position = random_point(rng, 5);
    desc.direction = random_unit(rng);
    desc.intensity = RGB(20.0f);
    desc.cone_angle = 20 + 40 * rng.next_float();
    desc.cone_delta = 10;
    lights.push_back(make_spot_light(desc));
  }
  for (int i = 0; i < 5; ++i)
    lights.push_back(SphereLight{random_point(rng, 5), 0.1f + 0.3f * rng.next_float(), RGB(5.0f), false, false});
  lights.push_back(RectangleLight{{-1, 6, -1}, {2, 0, 0}, {0, 0, 2}, {0, -1, 0}, 4, RGB(3.0f), false});
  lights.push_back(SkyLightSource{RGB(0.2f), RGB(0.1f), RGB(0.0f), {0, 1, 0}, 20});
  lights.push_back(DistantLightSource{normalize(Vec3(1, -2, 0.5f)), RGB(2.0f), 20});
  return lights;
}

LightSampler bvh_of(const std::vector<Light>& lights) {
  std::vector<float> power;
  for (const Light& l : lights) power.push_back(light_power(l));
  return LightSampler(lights, power, LightSampler::Mode::Bvh);
}

// Points around and among the lights, half on surfaces (a gathering normal), half in a medium.
std::vector<LightSampleContext> query_points(int n) {
  Rng rng(11, 0);
  std::vector<LightSampleContext> points;
  for (int i = 0; i < n; ++i)
    points.push_back({random_point(rng, 7), i % 2 ? random_unit(rng) : Normal3(0.0f)});
  return points;
}

TEST(LightBvh, ProbabilitiesSumToOneWithTheChanceOfNoLight) {
  std::vector<Light> lights = mixed_lights(500);
  LightSampler sampler = bvh_of(lights);
  EXPECT_GT(sampler.bvh_depth(), 8);
  EXPECT_LT(sampler.bvh_depth(), 40);
  double mean_none = 0;
  for (const LightSampleContext& ctx : query_points(200)) {
    double sum = 0;
    for (size_t i = 0; i < lights.size(); ++i) sum += sampler.pmf(ctx, i);
    // The chance that sample() finds no light, from a stratified sweep of u (exact up to the
    // strata that straddle a boundary).
    constexpr int kSweep = 100000;
    int none = 0;
    for (int k = 0; k < kSweep; ++k) none += sampler.sample(ctx, (float(k) + 0.5f) / kSweep).pmf == 0;
    EXPECT_NEAR(sum + double(none) / kSweep, 1.0, 1e-3) << "at " << ctx.p.x << " " << ctx.p.y << " " << ctx.p.z;
    EXPECT_LE(sum, 1.0 + 1e-5);
    mean_none += double(none) / kSweep / 200;
  }
  std::printf("mean chance of no light: %.4f\n", mean_none);
  EXPECT_LT(mean_none, 0.1);
  // Omnidirectional lights alone reach every point from every group: the sum is 1 exactly.
  std::vector<Light> points;
  Rng rng(2, 0);
  for (int i = 0; i < 300; ++i) points.push_back(PointLightSource{random_point(rng, 5), RGB(1 + rng.next_float())});
  LightSampler omni = bvh_of(points);
  for (const LightSampleContext& ctx : query_points(50)) {
    if (!(ctx.n == Normal3(0.0f))) continue;
    double sum = 0;
    for (size_t i = 0; i < points.size(); ++i) sum += omni.pmf(ctx, i);
    EXPECT_NEAR(sum, 1.0, 1e-4);
  }
}

// Draws `draws` lights at ctx: the frequencies match pmf() by chi-square, with one cell per light and a
// last one for "no light" (its expected count: what the pmfs leave), and every draw's pmf is pmf()'s.
void expect_frequencies_match_the_pmf(const LightSampler& sampler, size_t lights, const LightSampleContext& ctx,
                                      int draws, Rng& rng) {
  std::vector<double> observed(lights + 1, 0.0), expected(lights + 1, 0.0);
  for (int k = 0; k < draws; ++k) {
    SampledLight s = sampler.sample(ctx, rng.next_float());
    if (s.pmf == 0) {
      observed.back() += 1;
      continue;
    }
    ASSERT_NEAR(s.pmf, sampler.pmf(ctx, s.light), 1e-5f * s.pmf);  // what sample says is what pmf says
    observed[s.light] += 1;
  }
  double sum = 0;
  for (size_t i = 0; i < lights; ++i) sum += expected[i] = draws * double(sampler.pmf(ctx, i));
  expected.back() = std::max(0.0, draws - sum);
  EXPECT_GT(testing::chi_square_p_value(observed, expected), testing::kChiSquareAlpha);
}

TEST(LightBvh, SamplingFrequenciesMatchThePmf) {
  std::vector<Light> lights = mixed_lights(300);
  LightSampler sampler = bvh_of(lights);
  Rng rng(3, 0);
  for (const LightSampleContext& ctx : query_points(4))
    expect_frequencies_match_the_pmf(sampler, lights.size(), ctx, 400000, rng);
}

TEST(LightBvh, BoundsHoldEveryEmitter) {
  std::vector<Light> lights = mixed_lights(300);
  LightSampler sampler = bvh_of(lights);
  const auto& nodes = sampler.nodes();
  Rng rng(5, 0);
  auto holds = [](const Bounds3& b, const Point3& p) {
    const float eps = 1e-4f;
    return p.x >= b.lo.x - eps && p.y >= b.lo.y - eps && p.z >= b.lo.z - eps && p.x <= b.hi.x + eps &&
           p.y <= b.hi.y + eps && p.z <= b.hi.z + eps;
  };
  int leaves = 0;
  for (size_t n = 0; n < nodes.size(); ++n) {
    if (!nodes[n].leaf) continue;
    ++leaves;
    const Light& light = lights[nodes[n].child_or_light];
    for (int k = 0; k < 16; ++k) {
      LightEmission e = light_sample_le(light, {rng.next_float(), rng.next_float()}, {rng.next_float(), rng.next_float()},
                                        SceneSphere{{0, 0, 0}, 20});
      // The point and its emission direction lie in the bounds and cones of the leaf and every ancestor.
      for (size_t a = n;; a = nodes[a].parent) {
        const LightBounds& b = sampler.node_bounds(a);
        EXPECT_TRUE(holds(b.bounds, e.p)) << "light " << nodes[n].child_or_light << " node " << a;
        if (!(e.n == Normal3(0.0f))) {
          float cos_normal = b.two_sided ? std::abs(dot(b.w, e.n)) : dot(b.w, e.n);
          EXPECT_GE(cos_normal, b.cos_theta_o - 1e-4f) << "node " << a;
        }
        if (a == 0) break;
      }
    }
  }
  // Every light but those at infinity has its leaf.
  EXPECT_EQ(leaves, int(lights.size()) - 2);
}

TEST(LightBvh, NoLightThatReachesAPointHasProbabilityZeroThere) {
  std::vector<Light> lights = mixed_lights(300);
  LightSampler sampler = bvh_of(lights);
  Rng rng(9, 0);
  int reachable = 0, unreachable = 0;
  for (const LightSampleContext& ctx : query_points(400)) {
    for (size_t i = 0; i < lights.size(); ++i) {
      bool reaches = false;
      for (int k = 0; k < 8 && !reaches; ++k) {
        LightSample ls = light_sample_li(lights[i], ctx, {rng.next_float(), rng.next_float()});
        reaches = ls.pdf > 0 && !ls.radiance.is_black() && (ctx.n == Normal3(0.0f) || dot(ctx.n, ls.wi) > 0);
      }
      float pmf = sampler.pmf(ctx, i);
      if (reaches) {
        ++reachable;
        EXPECT_GT(pmf, 0) << "light " << i;
      } else if (pmf == 0) {
        ++unreachable;
      }
    }
  }
  // The bounds do prune: lights facing away and lights behind a surface get no rays.
  std::printf("reachable pairs %d, pruned %d\n", reachable, unreachable);
  EXPECT_GT(unreachable, reachable / 10);
}

TEST(LightBvh, NearLightsAndLightsFacingThePointAreFavoured) {
  // Two equal point lights, one ten times nearer; two equal panels, one facing the point.
  std::vector<Light> points{PointLightSource{{1, 0, 0}, RGB(1.0f)}, PointLightSource{{10, 0, 0}, RGB(1.0f)}};
  LightSampler s = bvh_of(points);
  LightSampleContext origin{{0, 0, 0}, Normal3(0.0f)};
  EXPECT_GT(s.pmf(origin, 0), 0.9f);
  std::vector<Light> panels{
      RectangleLight{{-1, 2, -1}, {2, 0, 0}, {0, 0, 2}, {0, -1, 0}, 4, RGB(1.0f), false},   // faces down, to the origin
      RectangleLight{{-1, -2, -1}, {2, 0, 0}, {0, 0, 2}, {0, -1, 0}, 4, RGB(1.0f), false}};  // faces down, away
  LightSampler p = bvh_of(panels);
  EXPECT_EQ(p.pmf(origin, 0), 1.0f);
  EXPECT_EQ(p.pmf(origin, 1), 0.0f);
}

TEST(LightBvh, OneLightIsAlwaysChosen) {
  // As by power, so that scenes of one light render as they did.
  std::vector<Light> one{SphereLight{{0, 3, 0}, 0.5f, RGB(4.0f), false, false}};
  LightSampler s = bvh_of(one);
  for (const LightSampleContext& ctx : query_points(50)) {
    SampledLight chosen = s.sample(ctx, 0.37f);
    EXPECT_EQ(chosen.light, 0u);
    EXPECT_EQ(chosen.pmf, 1.0f);
  }
}

TEST(LightBvh, WithoutTheTreeEveryPointUsesTheWeights) {
  std::vector<Light> lights = mixed_lights(20);
  std::vector<float> weights(lights.size(), 1.0f);
  LightSampler uniform(lights, weights, LightSampler::Mode::Weights);
  EXPECT_FALSE(uniform.uses_bvh());
  for (const LightSampleContext& ctx : query_points(5))
    for (size_t i = 0; i < lights.size(); ++i) EXPECT_FLOAT_EQ(uniform.pmf(ctx, i), 1.0f / float(lights.size()));
}

// The paper's rule through the tree: every light keeps its uniform share, the probabilities with the
// chance of no light sum to 1, sample() draws what pmf() says, and where the tree's lowest level holds
// the lights themselves the shares are the paper's estimates exactly.
TEST(LightBvh, ThePapersRuleGoesThroughTheTree) {
  std::vector<Light> lights = mixed_lights(300);
  std::vector<float> power;
  for (const Light& l : lights) power.push_back(light_power(l));
  LightSampler paper(lights, power, LightSampler::Mode::Paper);
  const float uniform_share = 0.1f / float(lights.size());
  Rng rng(4, 0);
  for (const LightSampleContext& ctx : query_points(40)) {
    double sum = 0;
    for (size_t i = 0; i < lights.size(); ++i) {
      const float pmf = paper.pmf(ctx, i);
      EXPECT_GE(pmf, uniform_share * (1 - 1e-5f)) << "light " << i;
      sum += pmf;
    }
    constexpr int kSweep = 20000;
    int none = 0;
    for (int k = 0; k < kSweep; ++k) none += paper.sample(ctx, (float(k) + 0.5f) / kSweep).pmf == 0;
    EXPECT_NEAR(sum + double(none) / kSweep, 1.0, 2e-3);
  }
  expect_frequencies_match_the_pmf(paper, lights.size(), query_points(2)[1], 300000, rng);

  // Two point lights, one ten times nearer: 0.05 + 0.9 x 100/101 of the rays go to it.
  std::vector<Light> points{PointLightSource{{1, 0, 0}, RGB(1.0f)}, PointLightSource{{10, 0, 0}, RGB(1.0f)}};
  std::vector<float> equal{1.0f, 1.0f};
  LightSampler two(points, equal, LightSampler::Mode::Paper);
  LightSampleContext origin{{0, 0, 0}, Normal3(0.0f)};
  EXPECT_NEAR(two.pmf(origin, 0), 0.05f + 0.9f * 100.0f / 101.0f, 1e-5f);
  EXPECT_NEAR(two.pmf(origin, 1), 0.05f + 0.9f * 1.0f / 101.0f, 1e-5f);
}

// A shipped many-light scene whose meshes scenes/make_city.py writes (with `make_args`), rendered small
// from `camera` with the light BVH and with power selection: the two image means, their variance, and
// the ratio of the expected relMSE (eps 0.01) of power selection's image to the BVH's.
struct ManyLightComparison {
  double mean_bvh = 0, mean_power = 0, variance = 0, relmse_ratio = 0;
};
ManyLightComparison render_by_bvh_and_by_power(const std::string& scene, const std::string& make_args,
                                                const CameraDesc& camera) {
  namespace fs = std::filesystem;
  const fs::path source = CANDELA_SOURCE_DIR;
  const fs::path dir = fs::temp_directory_path() / ("candela-many-lights-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy_file(source / "scenes" / scene, dir / scene, fs::copy_options::overwrite_existing);
  const std::string make =
      "/usr/bin/python3 " + (source / "scenes/make_city.py").string() + " " + dir.string() + " " + make_args + " > /dev/null";
  EXPECT_EQ(std::system(make.c_str()), 0) << make;
  SceneDesc bvh = read_scene_file(dir / scene);
  fs::remove_all(dir);
  EXPECT_EQ(bvh.settings.light_selection, LightSelection::Bvh);
  bvh.camera = camera;
  bvh.film.width = 64;
  bvh.film.height = 36;
  bvh.settings.spp = 32;
  SceneDesc power = bvh;
  power.settings.light_selection = LightSelection::Power;
  power.settings.seed = 1;
  {
    Scene s(bvh);
    std::printf("%s: %zu lights, light BVH depth %d\n", scene.c_str(), s.lights().size(), s.light_sampler().bvh_depth());
  }
  Film a = testing::render_description(bvh), b = testing::render_description(power);
  Image ma = a.mean_image(), mb = b.mean_image(), va = a.variance_of_mean_image(), vb = b.variance_of_mean_image();
  ManyLightComparison c;
  double rel_a = 0, rel_b = 0;
  for (size_t i = 0; i < ma.rgb.size(); ++i) {
    c.mean_bvh += ma.rgb[i], c.mean_power += mb.rgb[i], c.variance += va.rgb[i] + vb.rgb[i];
    // Each pixel's expected relMSE, against the better-converged of the two means.
    double truth = ma.rgb[i];
    rel_a += va.rgb[i] / (truth * truth + 0.01), rel_b += vb.rgb[i] / (truth * truth + 0.01);
  }
  c.relmse_ratio = rel_b / rel_a;
  std::printf("%s: expected relMSE, power / bvh: %.2f\n", scene.c_str(), c.relmse_ratio);
  return c;
}

// scenes/city-night.json on a smaller generated city (6 x 6 towers, about 4,200 emissive triangles):
// the images agree (both unbiased) within 4 standard errors, and the light BVH's noise at equal
// samples is several times lower than choosing by power.
TEST(LightBvh, TheCitySceneRendersWithLessNoiseThanPowerSelection) {
  ManyLightComparison c = render_by_bvh_and_by_power("city-night.json", "--blocks 6",
                                                     testing::look_at_camera({1.5f, 1.7f, -35}, {-1, 9, 10}, 60));
  EXPECT_NEAR(c.mean_bvh, c.mean_power, 4 * std::sqrt(c.variance));
  EXPECT_GT(c.relmse_ratio, 3.0);
}

// scenes/lamp-road.json as shipped (5,200 lamps): power selection almost never picks a lamp near the
// road the camera sees.
TEST(LightBvh, TheLampRoadRendersWithFarLessNoiseThanPowerSelection) {
  ManyLightComparison c = render_by_bvh_and_by_power("lamp-road.json", "--road",
                                                     testing::look_at_camera({-2, 1.7f, 1000}, {1, -1, 1025}, 60));
  EXPECT_NEAR(c.mean_bvh, c.mean_power, 4 * std::sqrt(c.variance));
  EXPECT_GT(c.relmse_ratio, 20.0);
}

}  // namespace
}  // namespace candela
