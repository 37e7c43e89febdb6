// Bidirectional path tracing and Metropolis light transport against analytic answers and against
// the path tracer.
//
// Two images A and B of the same scene "agree" when (1) the mean of A - B over the image and over
// each quadrant is within 4 standard errors of zero, the standard error estimated from the spread of
// A - B over the pixels (pixels are independent renders of one pixel each, so the spread of their
// differences measures the noise of both), and (2) relMSE(A, B) is below a bound derived from the
// noise: each renderer's own relMSE noise level is measured as half the relMSE between two of its
// renders with different seeds, and relMSE(A, B) may be at most twice the sum of both levels
// (a bias adds its square on top of the noise, whatever the spp). The integrator comparisons leave out
// the pixels that see a light source directly: that light is the same strategy in every integrator
// (s = 0 of depth 0), and the binomial noise of how many camera samples hit a small light would
// dominate every statistic; and they compare 2x2 block means.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>

#include "candela/integrators/bdpt.h"
#include "candela/integrators/mlt.h"
#include "candela/film/image_io.h"
#include "candela/io/scene_reader.h"
#include "candela/sampling/rng.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using testing::look_at_camera;
using testing::region_mean;
using testing::rel_mse;

const std::string kSharedDir = CANDELA_SHARED_DIR;
const std::string kScenes = std::string(CANDELA_SOURCE_DIR) + "/scenes/";

Film render_film(SceneDesc d, const std::string& integrator, int spp, uint64_t seed, int threads = 0,
                 RenderOptions options = {}) {
  d.settings.integrator = integrator;
  d.settings.spp = spp;
  d.settings.seed = seed;
  Scene scene(d);
  Film film(d.film.width, d.film.height);
  options.threads = threads;
  options.progress = false;
  render(scene, d.settings, film, options);
  return film;
}

Image render_image(const SceneDesc& d, const std::string& integrator, int spp, uint64_t seed, int threads = 0) {
  return render_film(d, integrator, spp, seed, threads).mean_image();
}

double image_mean(const Image& img) {
  double s = 0;
  for (float v : img.rgb) s += v;
  return s / double(img.rgb.size());
}

// Condition (1) of the file comment, on the pixels of [x0, x1) x [y0, y1), all channels.
void expect_zero_mean_difference(const Image& a, const Image& b, int x0, int y0, int x1, int y1, const char* what) {
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      RGB d = a.at(x, y) - b.at(x, y);
      double v = d.average();
      sum += v;
      sum_sq += v * v;
      ++n;
    }
  double mean = sum / n, se = std::sqrt(std::max(0.0, (sum_sq - n * mean * mean) / (n - 1)) / n);
  double scale = std::max(1e-3, std::abs(image_mean(b)));
  EXPECT_LE(std::abs(mean), 4 * se + 1e-6 * scale)
      << what << ": mean difference " << mean << " over [" << x0 << "," << x1 << ")x[" << y0 << "," << y1
      << "), standard error " << se;
}

void expect_agree(const Image& a, const Image& b, const char* what) {
  int w = a.width, h = a.height;
  expect_zero_mean_difference(a, b, 0, 0, w, h, what);
  expect_zero_mean_difference(a, b, 0, 0, w / 2, h / 2, what);
  expect_zero_mean_difference(a, b, w / 2, 0, w, h / 2, what);
  expect_zero_mean_difference(a, b, 0, h / 2, w / 2, h, what);
  expect_zero_mean_difference(a, b, w / 2, h / 2, w, h, what);
}

// Renders the scene twice (seeds 1, 2) with each integrator; checks condition (2) of the file
// comment for every pair, and that image means agree within `mean_tolerance` (relative).
struct IntegratorRun {
  std::string integrator;
  int spp;
};

// 2x2 block means: Metropolis chains clump their deposits, and caustics come as rare bright
// samples; block means make both noises closer to Gaussian, which the seed-to-seed noise estimate assumes.
Image block_means(const Image& img) {
  Image out(img.width / 2, img.height / 2);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      out.set(x, y, (img.at(2 * x, 2 * y) + img.at(2 * x + 1, 2 * y) + img.at(2 * x, 2 * y + 1) + img.at(2 * x + 1, 2 * y + 1)) * 0.25f);
  return out;
}

// Zeroes the pixels that see emission directly (at depth 0), and their neighbours, in the images.
void mask_visible_lights(const SceneDesc& d, std::vector<Image*> images) {
  SceneDesc emission_only = d;
  emission_only.settings.max_depth = 0;
  for (MediumDesc& m : emission_only.media) m.emission = RGB(0.0f);  // glowing fog is seen everywhere
  Image lights = render_image(emission_only, d.media.empty() ? "path" : "volpath", 256, 99);
  const int w = lights.width, h = lights.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (lights.at(x, y).is_black()) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          for (Image* img : images) img->set(nx, ny, RGB(0.0f));
        }
    }
}

void expect_integrators_agree(const SceneDesc& d, const std::vector<IntegratorRun>& runs, double mean_tolerance,
                              const char* scene) {
  std::vector<Image> first, second;
  std::vector<double> noise;
  for (const auto& r : runs) {
    first.push_back(render_image(d, r.integrator, r.spp, 1));
    second.push_back(render_image(d, r.integrator, r.spp, 2));
    mask_visible_lights(d, {&first.back(), &second.back()});
    first.back() = block_means(first.back());
    second.back() = block_means(second.back());
    noise.push_back(0.5 * rel_mse(first.back(), second.back()));
    std::printf("%s %s at %d spp: mean %.5f, relMSE noise level %.5f\n", scene, r.integrator.c_str(), r.spp,
                image_mean(first.back()), noise.back());
  }
  for (size_t i = 0; i < runs.size(); ++i)
    for (size_t j = i + 1; j < runs.size(); ++j) {
      double e = rel_mse(first[i], first[j]);
      double bound = 2 * (noise[i] + noise[j]);
      std::string what = std::string(scene) + ": " + runs[i].integrator + " vs " + runs[j].integrator;
      std::printf("%s: relMSE %.5f (bound %.5f)\n", what.c_str(), e, bound);
      EXPECT_LT(e, bound) << what;
      // Means of both seeds together: within mean_tolerance, or within 4 standard errors where the
      // noise of the means (half the difference between the two seeds of each) is larger than that.
      double mi = 0.5 * (image_mean(first[i]) + image_mean(second[i]));
      double mj = 0.5 * (image_mean(first[j]) + image_mean(second[j]));
      double se_i = 0.5 * std::abs(image_mean(first[i]) - image_mean(second[i])) / mi;
      double se_j = 0.5 * std::abs(image_mean(first[j]) - image_mean(second[j])) / mj;
      double tolerance = std::max(mean_tolerance, 4 * std::sqrt(se_i * se_i + se_j * se_j));
      std::printf("%s: means %.5f vs %.5f, ratio %.4f (tolerance %.4f)\n", what.c_str(), mi, mj, mi / mj, tolerance);
      EXPECT_NEAR(mi / mj, 1.0, tolerance) << what << ": image means " << mi << " vs " << mj;
    }
}

SceneDesc scene_at(const std::string& file, int width, int height) {
  SceneDesc d = read_scene_file(file);
  d.film.width = width;
  d.film.height = height;
  return d;
}

// ---------------------------------------------------------------------------------------- furnaces

SceneDesc closed_sphere(float albedo) { return testing::closed_diffuse_sphere(albedo, 1000); }

// A sphere under a uniform sky, as in the path tracer's furnace tests: light paths start on the
// scene disk of the light at infinity.
SceneDesc sphere_under_sky(const MaterialDesc& m) {
  return testing::sphere_under_sky(m, RGB(1.0f), 24, 20, RenderSettings{}.spp, 100);  // the sphere fills the image
}

bool inside_disk(int x, int y) {
  // The sphere subtends 14.5 degrees of the 20-degree fov; keep pixels well inside.
  float sx = (2 * (x + 0.5f) / 24 - 1), sy = (2 * (y + 0.5f) / 24 - 1);
  return sx * sx + sy * sy < 0.5f;
}

// The emissive closed sphere under MLT. Its pixels are correlated (chains wander), so the error is
// measured over independent seeds; `floor` is the relative error allowed beyond 5 standard errors.
void expect_metropolis_closed_sphere(bool spectral, double floor) {
  const float albedo = 0.6f, Le = 0.5f;
  SceneDesc d = closed_sphere(albedo);
  d.shapes[0].emission = AreaEmission{RGB(Le), true};
  d.settings.spectral = spectral;
  d.settings.max_depth = 30;  // what is left beyond depth 30 is 0.6^31 of the light
  d.settings.mlt.bootstrap = 4000;
  d.settings.mlt.chains = 64;
  std::vector<double> means;
  for (uint64_t seed = 1; seed <= 4; ++seed) means.push_back(image_mean(render_image(d, "mlt", 64, seed)));
  double m = 0, v = 0;
  for (double x : means) m += x / means.size();
  for (double x : means) v += (x - m) * (x - m) / (means.size() - 1);
  double expected = Le * (1 - std::pow(albedo, 31)) / (1 - albedo);
  EXPECT_NEAR(m, expected, 5 * std::sqrt(v / means.size()) + floor * expected) << "seed-to-seed deviation " << std::sqrt(v);
}

TEST(BidirectionalFurnace, MetropolisClosedSphereUnderATimeLimit) {
  // Under a time limit the normalisation takes further batches until a ninth of the time is spent:
  // its error then falls as 1/sqrt(batches) from one batch's, and the image still has the analytic
  // mean. How many batches fit depends on the machine (one under the sanitizers), so the test checks
  // the time spent and the error per batch count, and the gain only where several batches ran.
  const float albedo = 0.6f, Le = 0.5f;
  SceneDesc d = closed_sphere(albedo);
  d.shapes[0].emission = AreaEmission{RGB(Le), true};
  d.settings.integrator = "mlt";
  d.settings.max_depth = 30;
  d.settings.mlt.bootstrap = 4000;
  d.settings.mlt.chains = 64;
  d.settings.spp = 1 << 20;  // more than fits in the time
  const Scene scene(d);
  RenderOptions options;
  options.progress = false;
  std::vector<double> means;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    d.settings.seed = seed;
    RenderSettings one_batch = d.settings;
    one_batch.spp = 64;  // 64 x 16 x 12 / 8 mutations < mlt_bootstrap: one batch
    Film reference_film(d.film.width, d.film.height);
    RenderStats single = render(scene, one_batch, reference_film, options);
    options.time_limit_seconds = 1.5;
    Film film(d.film.width, d.film.height);
    RenderStats limited = render(scene, d.settings, film, options);
    options.time_limit_seconds = 0;
    EXPECT_TRUE(limited.time_limited);
    ASSERT_TRUE(mlt_stats(single) && mlt_stats(limited));
    const MltStats& one = *mlt_stats(single);
    const MltStats& more = *mlt_stats(limited);
    EXPECT_GE(more.normalization_seconds, 1.5 / 9);
    ASSERT_EQ(one.normalization_samples, uint64_t(d.settings.mlt.bootstrap));
    ASSERT_EQ(more.normalization_samples % one.normalization_samples, 0u);
    const double batches = double(more.normalization_samples / one.normalization_samples);
    EXPECT_NEAR(limited.splat_scale_relative_error * std::sqrt(batches), single.splat_scale_relative_error,
                0.35 * single.splat_scale_relative_error)
        << batches << " batches";
    if (batches >= 4) {
      EXPECT_LT(limited.splat_scale_relative_error, 0.7 * single.splat_scale_relative_error);
    }
    means.push_back(image_mean(film.mean_image()));
  }
  double m = 0, v = 0;
  for (double x : means) m += x / means.size();
  for (double x : means) v += (x - m) * (x - m) / (means.size() - 1);
  double expected = Le * (1 - std::pow(albedo, 31)) / (1 - albedo);
  EXPECT_NEAR(m, expected, 5 * std::sqrt(v / means.size()) + 1e-4 * expected) << "seed-to-seed deviation " << std::sqrt(v);
}

// --------------------------------------------------------------------------- strategies of one bounce

// A diffuse floor under a rectangular light that the camera does not see: every path has exactly
// one scattering vertex at max depth 1.
SceneDesc floor_under_light() {
  SceneDesc d;
  d.film = {32, 32, ""};
  d.camera = look_at_camera({0, 2, -3}, {0, 0, 0}, 40);
  d.settings.max_depth = 1;
  d.materials = {DiffuseMaterial{RGB(0.6f, 0.5f, 0.4f)}};
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-3, 0, -3}, {0, 0, 6}, {6, 0, 0}};  // normal +y
  floor.material = 0;
  ShapeDesc light;
  light.geometry = RectangleShape{{-0.5f, 1.5f, -0.5f}, {1, 0, 0}, {0, 0, 1}};  // normal -y
  light.material = 0;
  light.emission = AreaEmission{RGB(4.0f), false};
  d.shapes = {floor, light};
  return d;
}

// Every strategy's image, scaled like the light image (index BdptIntegrator::strategy_index).
std::vector<Image> strategy_images(const SceneDesc& d, bool unweighted, int spp, uint64_t seed, Image* full) {
  // (Depths up to 5: every depth of this scene's.)
  BdptStrategyImages images(d.settings, d.film.width, d.film.height, "", unweighted);
  RenderOptions options;
  options.integrator_outputs = &images;
  Film film = render_film(d, "bdpt", spp, seed, 0, options);
  if (full) *full = film.mean_image();
  std::vector<Image> scaled;
  for (const auto& img : images.images()) scaled.push_back(img.image(film.splat_scale()));
  return scaled;
}

TEST(BidirectionalStrategies, EachUnweightedStrategyOfOneBounceIsUnbiased) {
  SceneDesc d = floor_under_light();
  Image path = render_image(d, "path", 256, 11);
  std::vector<Image> strategies = strategy_images(d, true, 256, 12, nullptr);
  // Depth 1: (s, t) = (0, 3) the camera path hits the light, (1, 2) next-event estimation, (2, 1)
  // light tracing; the light is out of view, so depth 0 is black.
  for (int s = 0; s <= 2; ++s) {
    const Image& img = strategies[size_t(BdptIntegrator::strategy_index(s, 3 - s))];
    std::string what = "unweighted strategy s=" + std::to_string(s) + ", t=" + std::to_string(3 - s);
    expect_agree(img, path, what.c_str());
  }
}

TEST(BidirectionalStrategies, WeightedStrategiesSumToTheImageAndThePathTracer) {
  SceneDesc d = floor_under_light();
  Image full;
  std::vector<Image> strategies = strategy_images(d, false, 64, 13, &full);
  Image sum(d.film.width, d.film.height);
  for (int s = 0; s <= 2; ++s) {
    const Image& img = strategies[size_t(BdptIntegrator::strategy_index(s, 3 - s))];
    for (size_t i = 0; i < sum.rgb.size(); ++i) sum.rgb[i] += img.rgb[i];
  }
  // The strategy images are the film's contributions split up (up to the filter's normalisation of
  // the camera part, exact for the box filter used by default).
  ASSERT_EQ(d.settings.filter.type, FilterType::Box);
  for (size_t i = 0; i < sum.rgb.size(); ++i) EXPECT_NEAR(sum.rgb[i], full.rgb[i], 1e-4 + 1e-4 * full.rgb[i]);
  expect_agree(full, render_image(d, "path", 64, 14), "bdpt vs path");
}

// Under the light BVH, BDPT's next-event strategy chooses lights by what they give at the camera
// vertex while light paths start by power; the MIS weights carry the ratio of the two. Lights of
// very different power, distance and orientation (one facing away from most of the scene) make
// that ratio range widely: a wrong weight shows as a biased image against the path tracer's and
// against BDPT choosing by power.
TEST(BidirectionalStrategies, LightBvhKeepsTheEstimateUnbiased) {
  SceneDesc d = floor_under_light();
  d.settings.max_depth = 3;
  d.materials.push_back(DiffuseMaterial{RGB(0.3f, 0.6f, 0.8f)});
  ShapeDesc up_light;  // faces up, lighting only the ceiling-less sky side: most vertices cannot see it
  up_light.geometry = RectangleShape{{1.0f, 0.8f, -1.0f}, {0, 0, 0.6f}, {0.6f, 0, 0}};  // normal +y
  up_light.material = 1;
  up_light.emission = AreaEmission{RGB(30.0f, 20.0f, 10.0f), false};
  ShapeDesc wall;  // a wall above the up-facing light, so its light does reach the floor
  wall.geometry = RectangleShape{{0.5f, 2.5f, -2}, {2, 0, 0}, {0, 0, 4}};  // normal -y
  wall.material = 1;
  ShapeDesc bulb{.geometry = SphereShape{{-1.2f, 0.4f, 0.6f}, 0.15f}, .material = 0,
                 .emission = AreaEmission{RGB(2.0f, 6.0f, 3.0f), false}};
  d.shapes.push_back(up_light);
  d.shapes.push_back(wall);
  d.shapes.push_back(bulb);
  d.lights = {PointLight{{-1, 1, -1.5f}, RGB(0.5f)}, SkyLight{RGB(0.05f), RGB(0.05f), RGB(0.05f), {0, 1, 0}}};
  SceneDesc bvh = d, power = d;
  bvh.settings.light_selection = LightSelection::Bvh;
  power.settings.light_selection = LightSelection::Power;
  Image bdpt_bvh = render_image(bvh, "bdpt", 256, 31);
  expect_agree(bdpt_bvh, render_image(power, "bdpt", 256, 32), "bdpt: light BVH vs power");
  expect_agree(bdpt_bvh, render_image(bvh, "path", 512, 33), "light BVH: bdpt vs path");
}

TEST(BidirectionalStrategies, LightTracingAloneReproducesThePathTracer) {
  // The t = 1 strategies alone (unweighted) render every path of depth >= 1 of a diffuse scene;
  // directly seen emission (depth 0) is the (0, 2) strategy's.
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 32, 32);
  d.settings.max_depth = 3;
  std::vector<Image> strategies = strategy_images(d, true, 128, 21, nullptr);
  Image light_tracing = strategies[size_t(BdptIntegrator::strategy_index(0, 2))];
  for (int depth = 1; depth <= 3; ++depth) {
    const Image& img = strategies[size_t(BdptIntegrator::strategy_index(depth + 1, 1))];
    for (size_t i = 0; i < img.rgb.size(); ++i) light_tracing.rgb[i] += img.rgb[i];
  }
  expect_agree(light_tracing, render_image(d, "path", 128, 22), "light tracing vs path");
}

// ------------------------------------------------------------------------------------- agreement

TEST(BidirectionalAgreement, CornellBox) {
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 48, 48);
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 256;
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}, {"mlt", 256}}, 0.005, "cornell-box");
}

// The Cornell box filled with chromatic fog (the fog's box an interface just inside the walls; the
// camera outside in vacuum, the light inside the fog): the volumetric path tracer, BDPT and MLT agree
// image-wide and by quadrant, as they do without fog.
SceneDesc foggy_cornell_box(int width, int height) {
  SceneDesc d = scene_at(kScenes + "cornell-box.json", width, height);
  MediumDesc fog;
  fog.name = "fog";
  fog.sigma_t = {0.0015f, 0.0025f, 0.0035f};
  fog.albedo.constant = {0.9f, 0.8f, 0.7f};
  fog.g = 0.3f;
  d.media = {fog};
  d.materials.push_back(InterfaceMaterial{});
  ShapeDesc box;
  box.geometry = BoxShape{{1, 1, 1}, {555, 547, 558}};
  box.material = int(d.materials.size()) - 1;
  box.interior_medium = 0;
  d.shapes.push_back(box);
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 256;
  return d;
}

TEST(BidirectionalAgreement, FoggyCornellBox) {
  expect_integrators_agree(foggy_cornell_box(48, 48), {{"volpath", 256}, {"bdpt", 64}, {"mlt", 256}}, 0.01,
                           "foggy cornell-box");
}

// The fog glows (about as bright as the lit walls): BDPT and MLT take the emission where camera
// subpaths scatter, volpath at every tentative collision; the light is still on.
TEST(BidirectionalAgreement, GlowingFogCornellBox) {
  SceneDesc d = foggy_cornell_box(32, 32);
  d.media[0].emission = {6.0f, 3.0f, 2.0f};
  expect_integrators_agree(d, {{"volpath", 256}, {"bdpt", 64}, {"mlt", 256}}, 0.01, "glowing foggy cornell-box");
}

// The same with a heterogeneous medium: a random 8^3 density grid (a third of it empty) filling the
// box, grey, with ratio tracking on connections and the majorant grid in every walk.
TEST(BidirectionalAgreement, SmokyCornellBox) {
  SceneDesc d = foggy_cornell_box(48, 48);
  MediumDesc& smoke = d.media[0];
  smoke.sigma_t = RGB(0.004f);
  smoke.albedo.constant = RGB(0.85f);
  smoke.density.resolution = {8, 8, 8};
  smoke.majorant_cell_samples = 2;
  std::vector<float> values(512);
  Rng rng(21, 22);
  for (float& v : values) v = rng.next_float() < 0.33f ? 0.0f : 2 * rng.next_float();
  smoke.density.values = std::make_shared<const std::vector<float>>(values);
  smoke.density.to_world = Transform::scale({556, 548, 559});
  expect_integrators_agree(d, {{"volpath", 256}, {"bdpt", 64}}, 0.01, "smoky cornell-box");
}

// Metropolis light transport's noise is correlated over whole regions (chains clump), so two seeds
// say little about it: here it is judged over 6 seeds, region by region (the image, its halves and
// quadrants, lights masked), each region's mean within 4 standard errors of the seeds' spread of a
// high-spp bidirectional render.
void expect_metropolis_agrees(const SceneDesc& d, int mutations, int bdpt_spp, const char* scene, bool regions = true) {
  Image reference = render_image(d, "bdpt", bdpt_spp, 1);
  std::vector<Image> runs;
  for (uint64_t seed = 1; seed <= 6; ++seed) runs.push_back(render_image(d, "mlt", mutations, seed));
  std::vector<Image*> masked{&reference};
  for (Image& r : runs) masked.push_back(&r);
  mask_visible_lights(d, masked);
  const int w = reference.width, h = reference.height;
  struct Region {
    const char* name;
    int x0, y0, x1, y1;
  };
  for (const Region& r : {Region{"image", 0, 0, w, h}, Region{"top", 0, 0, w, h / 2}, Region{"bottom", 0, h / 2, w, h},
                          Region{"top left", 0, 0, w / 2, h / 2}, Region{"top right", w / 2, 0, w, h / 2},
                          Region{"bottom left", 0, h / 2, w / 2, h}, Region{"bottom right", w / 2, h / 2, w, h}}) {
    if (!regions && std::string(r.name) != "image") continue;
    auto region_mean_of = [&](const Image& img) {
      double sum = 0;
      for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) sum += img.at(x, y).average();
      return sum / double((r.x1 - r.x0) * (r.y1 - r.y0));
    };
    double m = 0, v = 0;
    std::vector<double> means;
    for (const Image& run : runs) means.push_back(region_mean_of(run));
    for (double x : means) m += x / double(means.size());
    for (double x : means) v += (x - m) * (x - m) / double(means.size() - 1);
    double se = std::sqrt(v / double(means.size())), ref = region_mean_of(reference);
    std::printf("%s %s: mlt %.5f +- %.5f, bdpt %.5f\n", scene, r.name, m, se, ref);
    EXPECT_NEAR(m, ref, 4 * se + 1e-4 * ref) << scene << " " << r.name;
  }
}

TEST(BidirectionalAgreement, VeachMis) {
  SceneDesc d = scene_at(kSharedDir + "/scenes/bitterli/veach-mis/scene-v4.pbrt", 64, 36);
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}}, 0.005, "veach-mis");
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 256;
  expect_metropolis_agrees(d, 256, 256, "veach-mis");
}

TEST(BidirectionalAgreement, MetropolisWithLensAndCausticPerturbations) {
  // The perturbations, and the small steps that stand in for them where they would move nothing
  // (accepted with Hastings' ratio, MltSampler::small_step_probability), keep the chains' target.
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 48, 48);
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 256;
  d.settings.mlt.lens = 0.3f;
  d.settings.mlt.caustic = 0.2f;
  expect_metropolis_agrees(d, 256, 256, "cornell-box with perturbations");
}

TEST(BidirectionalAgreement, GlassSphereCaustic) {
  // The path tracer finds the caustic only by hitting the small light through the glass: rare,
  // bright samples, hence its high spp.
  SceneDesc d = scene_at(kScenes + "caustic.json", 32, 24);
  expect_integrators_agree(d, {{"path", 8192}, {"bdpt", 512}}, 0.005, "caustic");
  // The caustic's focus is a narrow peak of the Metropolis target: at this budget the chains share
  // their deposits between it and the rest unevenly (4-5 standard errors by region, in both
  // directions, docs/bidirectional.md), so only the whole image is judged here.
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 64;
  expect_metropolis_agrees(d, 512, 2048, "caustic", false);
}

TEST(BidirectionalAgreement, PaperRoom) {
  SceneDesc d = scene_at(kScenes + "room.json", 48, 36);
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 256;
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}, {"mlt", 256}}, 0.005, "room");
}

TEST(BidirectionalAgreement, ThinLensAndMotionBlur) {
  // The Cornell box through a thin lens focused on the tall block, with the short block moving
  // during the shutter: the lens point is the camera vertex, and every ray of a path (light paths
  // too) sees the scene at the path's time.
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 40, 40);
  d.camera.lens_radius = 25;
  d.camera.focus_distance = 1100;
  bool moved = false;
  for (ShapeDesc& shape : d.shapes)
    if (shape.name == "short block") {
      shape.to_world_end = Transform::translate({0, 60, 40}) * shape.to_world;
      moved = true;
    }
  ASSERT_TRUE(moved);
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}}, 0.005, "lens and motion");
}

TEST(BidirectionalAgreement, EmitterWithoutASurface) {
  // An emissive sphere of material "interface" (as pbrt's area lights often are): camera rays pass
  // through it, collecting its light on the way (the s = 0 strategy weighed at the crossing), and
  // light it sends to the floor arrives by every other strategy.
  SceneDesc d;
  d.film = {40, 30, ""};
  d.camera = look_at_camera({0, 1.2f, -3}, {0, 0.5f, 0}, 45);
  d.settings.max_depth = 4;
  d.materials = {DiffuseMaterial{RGB(0.6f)}, InterfaceMaterial{}};
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-3, 0, -3}, {0, 0, 6}, {6, 0, 0}};
  floor.material = 0;
  ShapeDesc lamp;
  lamp.geometry = SphereShape{{0.3f, 0.8f, 0.2f}, 0.25f};
  lamp.material = 1;
  lamp.emission = AreaEmission{RGB(3.0f), false};
  d.shapes = {floor, lamp};
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}}, 0.005, "interface emitter");
  // The lamp is seen: the masked comparison above leaves its pixels out, so check them here.
  SceneDesc direct = d;
  direct.settings.max_depth = 0;
  Image p = render_image(direct, "path", 64, 1), b = render_image(direct, "bdpt", 64, 1);
  EXPECT_GT(image_mean(p), 0);
  EXPECT_NEAR(image_mean(b) / image_mean(p), 1.0, 1e-6);
}

TEST(BidirectionalAgreement, EnvironmentMap) {
  // A diffuse sphere and a floor under an importance-sampled environment map: light paths start
  // on the scene disk in directions drawn from the map.
  const std::filesystem::path map = std::filesystem::temp_directory_path() /
                                    ("candela_bidirectional_env_" + std::to_string(getpid()) + ".exr");
  Image env(32, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      env.set(x, y, (x >= 20 && x < 23 && y >= 3 && y < 5) ? RGB(60, 50, 40) : RGB(0.2f, 0.3f, 0.5f) * (y < 8 ? 1.0f : 0.2f));
  write_image(map, env, {});
  SceneDesc d;
  d.film = {40, 30, ""};
  d.camera = look_at_camera({0, 1.5f, -4}, {0, 0.6f, 0}, 45);
  d.settings.max_depth = 6;
  d.materials = {DiffuseMaterial{RGB(0.7f, 0.6f, 0.5f)}, DiffuseMaterial{RGB(0.5f)}};
  ShapeDesc ball;
  ball.geometry = SphereShape{{0, 0.8f, 0}, 0.8f};
  ball.material = 0;
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-4, 0, -4}, {0, 0, 8}, {8, 0, 0}};
  floor.material = 1;
  d.shapes = {ball, floor};
  EnvironmentMap light;
  light.filename = map.string();
  d.lights = {light};
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}}, 0.005, "environment map");
  std::filesystem::remove(map);
}

// -------------------------------------------------------------------------------- spectral transport

// Spectral transport (spectral/wavelengths.h) in every integrator: grey materials under a white sky
// keep their analytic answers (the constant spectra of grey reflectances, and D65 for white light,
// whose colour through the CIE tables is white within 2e-3: Cie.TablesGiveTheStandardIntegrals...).
TEST(SpectralTransport, FurnacesKeepTheirAnalyticAnswers) {
  for (const char* integrator : {"path", "bdpt"}) {
    for (auto [material, expected] : {std::pair<MaterialDesc, double>{DiffuseMaterial{RGB(0.7f)}, 0.7},
                                      std::pair<MaterialDesc, double>{DielectricMaterial{1.5f, RGB(1.0f), RGB(1.0f)}, 1.0}}) {
      SceneDesc d = sphere_under_sky(material);
      d.settings.spectral = true;
      Image img = render_image(d, integrator, 32, 5);
      for (int c = 0; c < 3; ++c) {
        testing::MeanEstimate e = region_mean(img, c, inside_disk);
        EXPECT_NEAR(e.mean, expected, 4 * e.standard_error + 2e-3)
            << integrator << " channel " << c << ": standard error " << e.standard_error;
      }
    }
  }
  // Metropolis: the closed emissive sphere.
  expect_metropolis_closed_sphere(true, 2e-3);
}

TEST(BidirectionalAgreement, SpectralCornellBox) {
  // Spectral transport with saturated walls: the path tracer, BDPT and MLT sample the same spectra.
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 32, 32);
  d.settings.spectral = true;
  d.settings.mlt.bootstrap = 20000;
  d.settings.mlt.chains = 256;
  expect_integrators_agree(d, {{"path", 256}, {"bdpt", 64}, {"mlt", 256}}, 0.005, "spectral cornell-box");
}

TEST(SpectralTransport, OneAndTwoThreadsGiveBitwiseIdenticalImages) {
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 24, 16);
  d.settings.spectral = true;
  d.settings.mlt.bootstrap = 2000;
  d.settings.mlt.chains = 16;
  for (const char* integrator : {"path", "bdpt", "mlt"}) {
    Image one = render_image(d, integrator, 8, 7, 1), two = render_image(d, integrator, 8, 7, 2);
    EXPECT_TRUE(std::memcmp(one.rgb.data(), two.rgb.data(), one.rgb.size() * sizeof(float)) == 0) << integrator;
  }
}

// ----------------------------------------------------------------------------------- determinism

bool bitwise_equal(const Image& a, const Image& b) {
  return a.rgb.size() == b.rgb.size() && std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

TEST(BidirectionalDeterminism, OneAndTwoThreadsGiveBitwiseIdenticalImages) {
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 40, 24);
  d.settings.mlt.bootstrap = 2000;
  d.settings.mlt.chains = 16;
  for (const char* integrator : {"bdpt", "mlt"}) {
    Image one = render_image(d, integrator, 8, 7, 1), two = render_image(d, integrator, 8, 7, 2);
    EXPECT_TRUE(bitwise_equal(one, two)) << integrator;
    EXPECT_FALSE(bitwise_equal(one, render_image(d, integrator, 8, 8, 2))) << integrator << ": the seed must matter";
  }
}

TEST(BidirectionalDeterminism, ContinuedRenderEqualsUninterruptedOne) {
  // The film as it stood after the first pass (what a checkpoint restores), continued to the end,
  // equals the uninterrupted render bit for bit: the splats are integer sums, whatever order they
  // arrive in.
  SceneDesc d = scene_at(kScenes + "cornell-box.json", 24, 24);
  d.settings.integrator = "bdpt";
  d.settings.seed = 5;
  d.settings.spp = 40;  // more than one pass (16 samples per pixel)
  Scene scene(d);
  Film whole(24, 24), part(24, 24);
  RenderOptions options;
  options.progress = false;
  bool copied = false;
  options.after_pass = [&](const Film& f, uint64_t) {
    if (copied) return;
    part.pixels() = f.pixels();
    part.enable_splats();
    part.splats().sums() = f.splats().sums();
    copied = true;
  };
  render(scene, d.settings, whole, options);
  ASSERT_TRUE(copied);
  ASSERT_LT(part.total_samples(), whole.total_samples());
  options.after_pass = nullptr;
  render(scene, d.settings, part, options);
  EXPECT_TRUE(bitwise_equal(whole.mean_image(), part.mean_image()));
}

}  // namespace
}  // namespace candela
