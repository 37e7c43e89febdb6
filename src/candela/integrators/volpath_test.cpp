// The volumetric path tracer against analytic answers: transmittance through a chromatic slab,
// furnaces of media in closed enclosures (albedo 1 inside an emitter; an emitting, absorbing medium;
// Kirchhoff's equilibrium of emitting walls and an emitting, scattering medium), a heterogeneous
// grid's transmittance by ratio tracking and by delta tracking against quadrature, a subsurface
// slab's reflectance against the exact transport (adding-doubling), equiangular sampling on against
// off and BDPT (and its determinism), and the refusal of scenes with media by integrators that do not
// render them. Each render is repeated over seeds;
// tolerances are 5 standard errors of the mean over seeds (Student's t, 7 degrees of freedom).
#include "candela/integrators/volpath.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <unistd.h>

#include "candela/base/error.h"
#include "candela/integrators/integrator.h"
#include "candela/io/scene_reader.h"
#include "candela/media/subsurface_albedo.h"
#include "candela/sampling/rng.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using testing::look_at_camera;

constexpr int kSeedsPerCase = 8;

// Mean over seeds of each channel's image mean, and its standard error.
struct ChannelMeans {
  RGB mean, standard_error;
};

ChannelMeans render_means(const SceneDesc& desc) {
  const Scene scene(desc);
  double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
  for (uint64_t seed = 1; seed <= kSeedsPerCase; ++seed) {
    RenderSettings settings = desc.settings;
    settings.seed = seed;
    Film film(desc.film.width, desc.film.height);
    RenderOptions options;
    options.progress = false;
    render(scene, settings, film, options);
    Image image = film.mean_image();
    for (int c = 0; c < 3; ++c) {
      double m = testing::region_mean(image, c, [](int, int) { return true; }).mean;
      sum[c] += m;
      sum2[c] += m * m;
    }
  }
  auto mean = [&](int c) { return sum[c] / kSeedsPerCase; };
  auto standard_error = [&](int c) {
    double m = mean(c), v = std::max(0.0, (sum2[c] - kSeedsPerCase * m * m) / (kSeedsPerCase - 1));
    return float(std::sqrt(v / kSeedsPerCase));
  };
  return {RGB(float(mean(0)), float(mean(1)), float(mean(2))),
          RGB(standard_error(0), standard_error(1), standard_error(2))};
}

void expect_channels(const ChannelMeans& got, const RGB& expected, const char* what, float floor = 1e-4f) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(got.mean[c], expected[c], 5 * got.standard_error[c] + floor * expected[c])
        << what << ", channel " << c << ": standard error " << got.standard_error[c];
}

SceneDesc volpath_scene(int size, int spp) {
  SceneDesc d;
  d.film = {size, size, ""};
  d.settings.integrator = "volpath";
  d.settings.spp = spp;
  d.settings.max_depth = 1000;
  return d;
}

// A sphere of radius 2 at the origin bounding `medium` (the medium inside, vacuum outside), black,
// optionally emitting `wall` on both sides; the camera at its centre, in the medium.
SceneDesc medium_in_sphere(const MediumDesc& medium, const RGB& wall) {
  SceneDesc d = volpath_scene(8, 16);
  d.camera = look_at_camera({0, 0, 0}, {0.3f, 0.2f, 1}, 90);
  d.camera.medium = 0;
  d.media = {medium};
  d.materials = {BlackMaterial{}};
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, 0}, 2};
  s.material = 0;
  s.interior_medium = 0;
  if (!wall.is_black()) s.emission = AreaEmission{wall, true};
  d.shapes = {s};
  return d;
}

// A slab of `medium` between z = -half and z = half (10 x 10 wide, bounded by an interface), seen
// along z by an orthographic camera from z = -3; no lights.
SceneDesc slab_scene(const MediumDesc& medium, float half) {
  SceneDesc d = volpath_scene(8, 64);
  d.camera.projection = Projection::Orthographic;
  d.camera.world_from_camera = Transform::look_at_right_handed({0, 0, -3}, {0, 0, 0}, {0, 1, 0});
  d.media = {medium};
  d.materials = {InterfaceMaterial{}};
  ShapeDesc slab;
  slab.geometry = BoxShape{{-5, -5, -half}, {5, 5, half}};
  slab.material = 0;
  slab.interior_medium = 0;
  d.shapes = {slab};
  return d;
}

TEST(VolPath, ChromaticSlabTransmitsExpOfMinusSigmaTTimesThickness) {
  // An absorbing slab 0.8 thick between an orthographic camera and a white sky: exp(-sigma_t d)
  // per channel, however unlike the channels' coefficients are (the hero channel drives sampling).
  MediumDesc fog;
  fog.sigma_t = {0.2f, 1.0f, 4.0f};
  fog.albedo.constant = RGB(0.0f);
  SceneDesc d = slab_scene(fog, 0.4f);
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  expect_channels(render_means(d), {std::exp(-0.16f), std::exp(-0.8f), std::exp(-3.2f)}, "slab");
}

TEST(VolPath, AnEnclosureThatEmitsLeFilledWithAnAlbedoOneMediumRendersLe) {
  for (float sigma : {0.3f, 4.0f}) {
    MediumDesc medium;
    medium.sigma_t = RGB(sigma);
    medium.albedo.constant = RGB(1.0f);
    medium.g = 0.4f;
    expect_channels(render_means(medium_in_sphere(medium, {1.0f, 2.0f, 0.5f})), {1.0f, 2.0f, 0.5f}, "albedo 1");
  }
}

TEST(VolPath, AnEmittingAbsorbingMediumGivesLeTimesOneMinusItsTransmittance) {
  // From the centre every ray travels 2 to the black wall: L = Le (1 - exp(-2 sigma_t)).
  MediumDesc medium;
  medium.sigma_t = {0.1f, 0.5f, 2.0f};
  medium.albedo.constant = RGB(0.0f);
  medium.emission = {3.0f, 1.0f, 2.0f};
  const RGB expected = RGB::from_lanes(
      [&](int c) { return medium.emission[c] * (1 - std::exp(-2 * medium.sigma_t[c])); });
  expect_channels(render_means(medium_in_sphere(medium, RGB(0.0f))), expected, "emitting absorber");
}

TEST(VolPath, AGlowingTemperatureGridGivesTheQuadratureOfItsEmission) {
  // An absorbing slab whose density, temperature and emission scale vary with depth (pbrt-v4's
  // blackbody emission from a temperature grid), seen along its depth by an orthographic camera
  // against black: L = integral of sigma_a(z) Le(z) exp(-optical depth to z) dz, by quadrature.
  MediumDesc fire;
  fire.sigma_t = {1.0f, 1.5f, 0.7f};
  fire.albedo.constant = RGB(0.0f);
  const Transform box = Transform::translate({-5, -5, -0.5f}) * Transform::scale({10, 10, 1});
  auto column = [&](std::vector<float> v) {
    VolumeDesc g;
    g.resolution = {1, 1, int(v.size())};
    g.values = std::make_shared<const std::vector<float>>(std::move(v));
    g.to_world = box;
    return g;
  };
  fire.density = column({0.5f, 1.0f, 2.0f, 0.7f});
  fire.temperature = column({1500, 3000, 6000, 2500});
  fire.temperature_offset = 200;
  fire.temperature_scale = 1.2f;
  fire.emission_scale = column({2.0f, 1.0f, 0.5f, 3.0f});
  SceneDesc d = slab_scene(fire, 0.5f);
  const Medium medium(fire);
  ASSERT_TRUE(medium.is_emissive());
  double expected_sum[3] = {0, 0, 0}, depth[3] = {0, 0, 0};
  const int steps = 100000;
  for (int i = 0; i < steps; ++i) {
    const float z = -0.5f + (float(i) + 0.5f) / steps;
    const Point3 p(0.1f, -0.2f, z);
    const RGB le = medium.emission(p);
    for (int c = 0; c < 3; ++c) {
      const double sigma_a = double(medium.sigma_t()[c]) * medium.density(p), dz = 1.0 / steps;
      expected_sum[c] += sigma_a * le[c] * std::exp(-(depth[c] + 0.5 * sigma_a * dz)) * dz;
      depth[c] += sigma_a * dz;
    }
  }
  const RGB expected = RGB(float(expected_sum[0]), float(expected_sum[1]), float(expected_sum[2]));
  ASSERT_GT(expected.min_component(), 0.01f);
  expect_channels(render_means(d), expected, "temperature grid, volpath", 1e-3f);
  // BDPT takes the medium's light where its camera subpaths collide (the collision estimator).
  d.settings.integrator = "bdpt";
  expect_channels(render_means(d), expected, "temperature grid, bdpt", 1e-3f);
}

TEST(VolPath, EmittingWallsAndAnEmittingScatteringMediumAreInEquilibrium) {
  // Kirchhoff: walls and medium at the same "temperature" (both emit Le where they absorb) give Le
  // everywhere, whatever the albedo, the extinction's colour and the phase function.
  MediumDesc medium;
  medium.sigma_t = {0.4f, 1.5f, 3.0f};
  medium.albedo.constant = {0.6f, 0.3f, 0.9f};
  medium.g = -0.3f;
  medium.emission = {0.7f, 1.2f, 2.0f};
  expect_channels(render_means(medium_in_sphere(medium, medium.emission)), medium.emission, "equilibrium");
}

// A scene of one heterogeneous medium (a random 6^3 grid over [-1, 1]^3) bounded by an interface box.
SceneDesc grid_scene() {
  SceneDesc d = volpath_scene(4, 1);
  MediumDesc m;
  m.sigma_t = {0.5f, 1.0f, 2.0f};
  m.scale = 1.5f;
  m.density.resolution = {6, 6, 6};
  std::vector<float> values(216);
  Rng rng(5, 6);
  for (float& v : values) v = rng.next_float() < 0.3f ? 0.0f : 3 * rng.next_float();
  m.density.values = std::make_shared<const std::vector<float>>(values);
  m.density.to_world = Transform::translate({-1, -1, -1}) * Transform::scale({2, 2, 2});
  d.media = {m};
  d.materials = {InterfaceMaterial{}};
  ShapeDesc box;
  box.geometry = BoxShape{{-1.5f, -1.5f, -1.5f}, {1.5f, 1.5f, 1.5f}};
  box.material = 0;
  box.interior_medium = 0;
  d.shapes = {box};
  return d;
}

TEST(VolPath, GridTransmittanceByRatioAndDeltaTrackingMatchesQuadrature) {
  const SceneDesc desc = grid_scene();
  const Scene scene(desc);
  const Medium& medium = scene.media()[0];
  const VolPathIntegrator volpath(scene, desc.settings);
  const Point3 from(-1.3f, -0.4f, 0.2f), to(1.2f, 0.5f, -0.3f);
  const Vec3 dir = normalize(to - from);
  const float length_ = length(to - from);
  // The optical depth by the midpoint rule.
  double depth = 0;
  const int steps = 200000;
  for (int i = 0; i < steps; ++i)
    depth += double(medium.density(from + dir * (length_ * (float(i) + 0.5f) / float(steps)))) * length_ / steps;
  ASSERT_GT(depth, 0.5);  // the segment does cross the medium
  const int n = 40000;
  Rng rng(11, 12);
  for (int c = 0; c < 3; ++c) {
    const double expected = std::exp(-double(medium.sigma_t()[c]) * depth);
    // Ratio tracking, as the integrator's shadow rays do it (the hero channel chosen uniformly).
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
      double t = volpath.transmittance(from, to, 0, int(rng.next_u32() % 3), rng.next_u32(), 0)[c];
      sum += t;
      sum2 += t * t;
    }
    double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, expected, 5 * se + 1e-4) << "ratio tracking, channel " << c;
    // Delta tracking (media/medium.h, as BDPT walks): the fraction of walks that reach the end.
    const float sigma = medium.sigma_t()[c];
    int reached = 0;
    for (int i = 0; i < n; ++i) reached += std::isinf(sample_collision(medium, sigma, Ray{from, dir}, length_, rng));
    // The scalar ratio tracking BDPT's connections use.
    double ratio_sum = 0, ratio_sum2 = 0;
    for (int i = 0; i < n; ++i) {
      double t = estimate_transmittance(medium, sigma, Ray{from, dir}, length_, rng);
      ratio_sum += t;
      ratio_sum2 += t * t;
    }
    double ratio_mean = ratio_sum / n, ratio_se = std::sqrt((ratio_sum2 / n - ratio_mean * ratio_mean) / n);
    EXPECT_NEAR(ratio_mean, expected, 5 * ratio_se + 1e-4) << "scalar ratio tracking, channel " << c;
    double p = double(reached) / n;
    EXPECT_NEAR(p, expected, 5 * std::sqrt(expected * (1 - expected) / n) + 1e-4) << "delta tracking, channel " << c;
  }
}

TEST(VolPath, WithoutMediaItAgreesWithThePathTracer) {
  // A diffuse sphere under a sky, and a thin dielectric sheet in front of it.
  SceneDesc d = testing::sphere_under_sky(DiffuseMaterial{RGB(0.7f, 0.5f, 0.3f)}, RGB(1.0f), 8, 20, 32, 8);
  DielectricMaterial sheet;
  sheet.thin = true;
  sheet.ior = 1.5f;
  d.materials.push_back(sheet);
  ShapeDesc s;
  s.geometry = RectangleShape{{-1.5f, -1.5f, -2}, {3, 0, 0}, {0, 3, 0}};
  s.material = 1;
  d.shapes.push_back(s);
  ChannelMeans path = render_means(d);
  d.settings.integrator = "volpath";
  ChannelMeans volpath = render_means(d);
  for (int c = 0; c < 3; ++c) {
    float se = std::hypot(path.standard_error[c], volpath.standard_error[c]);
    EXPECT_NEAR(volpath.mean[c], path.mean[c], 5 * se + 1e-4f) << "channel " << c;
  }
}

TEST(VolPath, ThePathTracerRefusesScenesWithMedia) {
  MediumDesc medium;
  SceneDesc d = medium_in_sphere(medium, RGB(1.0f));
  auto message = [&](const SceneDesc& desc, const char* name) {
    const Scene scene(desc);
    RenderSettings settings = desc.settings;
    settings.integrator = name;
    Film film(desc.film.width, desc.film.height);
    RenderOptions options;
    options.progress = false;
    try {
      render(scene, settings, film, options);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("rendered");
  };
  EXPECT_NE(message(d, "path").find("use --integrator volpath"), std::string::npos);
}

TEST(VolPath, AShapeOrCameraReferringToAMissingMediumIsASceneError) {
  MediumDesc medium;
  SceneDesc d = medium_in_sphere(medium, RGB(1.0f));
  d.shapes[0].interior_medium = 3;
  EXPECT_THROW(Scene{d}, SceneError);
  d = medium_in_sphere(medium, RGB(1.0f));
  d.camera.medium = 1;
  EXPECT_THROW(Scene{d}, SceneError);
  d = medium_in_sphere(medium, RGB(1.0f));
  d.media[0].g = -1.5f;
  try {
    Scene scene(d);
    ADD_FAILURE() << "accepted g = -1.5";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("g = -1.5 must be within (-1, 1)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

// The media examples of scenes/ read and render (tiny, a few samples): finite, not black. The cloud's
// density grid is generated by scenes/make_cloud.py, as a user would (at a low resolution here).
TEST(VolPath, TheMediaExampleScenesRender) {
  namespace fs = std::filesystem;
  const fs::path source = CANDELA_SOURCE_DIR;
  const fs::path dir = fs::temp_directory_path() / ("candela-media-examples-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy_file(source / "scenes/cloud.json", dir / "cloud.json", fs::copy_options::overwrite_existing);
  const std::string make = "/usr/bin/python3 " + (source / "scenes/make_cloud.py").string() + " " +
                           (dir / "cloud.vol").string() + " --resolution 24 > /dev/null";
  ASSERT_EQ(std::system(make.c_str()), 0) << make;
  for (const fs::path& file : {source / "scenes/fog-room.json", source / "scenes/subsurface.json", dir / "cloud.json"}) {
    SceneDesc desc = read_scene_file(file);
    ASSERT_FALSE(desc.media.empty()) << file;
    EXPECT_EQ(desc.settings.integrator, "volpath") << file;
    desc.film.width = 24;
    desc.film.height = 16;
    desc.settings.spp = 4;
    Image image = testing::render_description(desc).mean_image();
    double sum = 0;
    for (float v : image.rgb) {
      ASSERT_TRUE(std::isfinite(v)) << file;
      sum += v;
    }
    EXPECT_GT(sum, 0) << file;
  }
  fs::remove_all(dir);
}

// ---------------------------------------------------------------- subsurface media

// A slab 60 mean free paths deep and 120 wide of a subsurface medium (sigma_t = 1, the albedo per
// channel, Henyey-Greenstein g) inside a smooth dielectric of index eta, its top face at z = 0, seen
// along its normal by an orthographic camera under a uniform white sky. By reciprocity it reflects the
// albedo for light arriving along the normal: F0 + (1 - F0) rho_eff, the boundary's Fresnel
// reflectance and the light it lets in that comes back out (media/subsurface_albedo.h's effective
// albedo, the exact transport by adding-doubling).
void expect_subsurface_slab_reflectance(const RGB& albedo, float g, float eta, int max_depth) {
  SceneDesc d = volpath_scene(4, 128);
  d.settings.max_depth = max_depth;
  d.camera.projection = Projection::Orthographic;
  d.camera.world_from_camera = Transform::look_at_right_handed({0, 0, -3}, {0, 0, 0}, {0, 1, 0});
  MediumDesc medium;
  medium.sigma_t = RGB(1.0f);
  medium.albedo.constant = albedo;
  medium.g = g;
  medium.subsurface = true;
  d.media = {medium};
  DielectricMaterial boundary;
  boundary.ior = eta;
  d.materials = {boundary};
  ShapeDesc slab;
  slab.geometry = BoxShape{{-60, -60, 0}, {60, 60, 60}};
  slab.material = 0;
  slab.interior_medium = 0;
  d.shapes = {slab};
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  const float f0 = ((eta - 1) / (eta + 1)) * ((eta - 1) / (eta + 1));
  auto reflectance = [&](int c) { return f0 + (1 - f0) * float(subsurface_effective_albedo(albedo[c], g, eta)); };
  expect_channels(render_means(d), RGB(reflectance(0), reflectance(1), reflectance(2)), "subsurface slab", 2e-3f);
}

TEST(VolPath, IsotropicSubsurfaceSlabReflectsTheExactTransportsEffectiveAlbedo) {
  expect_subsurface_slab_reflectance({0.3f, 0.8f, 0.97f}, 0, 1.33f, 5);
}

TEST(VolPath, ForwardScatteringSubsurfaceSlabReflectsTheExactTransportsEffectiveAlbedo) {
  expect_subsurface_slab_reflectance({0.5f, 0.9f, 0.95f}, 0.5f, 1.5f, 5);
}

// Dozens of scattering events inside, yet max_depth 1 (the bounce that entered) renders all of them.
TEST(VolPath, ASubsurfaceExcursionIsOneBounce) {
  expect_subsurface_slab_reflectance({0.6f, 0.9f, 0.97f}, 0.2f, 1.33f, 1);
}

// ---------------------------------------------------------------- equiangular sampling

// Equiangular sampling (integrators/volpath.h) takes a light's point for a 2D sample as the light
// samples it from any point that sees it, and as its emitted rays start: for the area-sampled lights
// the two are the same mapping.
TEST(VolPath, AreaSampledLightsSampleTheSamePointForLightAndEmissionSampling) {
  SceneDesc d = volpath_scene(4, 1);
  d.materials = {DiffuseMaterial{RGB(0.5f)}};
  auto emitter = [&](ShapeGeometry geometry, const Transform& to_world = {}) {
    ShapeDesc s;
    s.geometry = std::move(geometry);
    s.to_world = to_world;
    s.material = 0;
    s.emission = AreaEmission{RGB(1.0f), true};
    d.shapes.push_back(s);
  };
  emitter(RectangleShape{{-1, 2, -1}, {2, 0, 0}, {0, 0, 2}});
  emitter(DiskShape{}, Transform::translate({0, 3, 0}) * Transform::scale({0.5f, 0.5f, 0.5f}));
  emitter(CylinderShape{{2, 0, 0}, {2, 1, 0}, 0.3f, 360});
  emitter(BoxShape{{-3, -3, -3}, {-2, -2, -2}});
  const Scene scene(d);
  ASSERT_GE(scene.lights().size(), 4u);
  Rng rng(31, 32);
  int compared = 0;
  for (const Light& light : scene.lights())
    for (int i = 0; i < 100; ++i) {
      const Vec2 u(rng.next_float(), rng.next_float());
      const LightSampleContext ctx{Point3(4 * rng.next_float() - 2, 4 * rng.next_float() - 2, 4 * rng.next_float() - 2),
                                   Normal3(0.0f)};
      const LightSample ls = light_sample_li(light, ctx, u);
      if (!(ls.pdf > 0)) continue;
      const Point3 p = light_sample_le(light, u, Vec2(0.5f, 0.5f), SceneSphere{}).p;
      EXPECT_LT(length(p - ls.p_light), 1e-5f * (1 + length(p)));
      ++compared;
    }
  EXPECT_GT(compared, 100 * int(scene.lights().size()) / 4);
}

// A chromatic homogeneous fog lit by a point light and a small one-sided rectangle light, over a
// diffuse floor: bounded by an interface sphere with the camera outside, or (unbounded) around the
// camera under a sky (segments to infinity, and a light equiangular sampling leaves out).
SceneDesc lit_fog(bool bounded) {
  SceneDesc d = volpath_scene(12, 16);
  d.settings.max_depth = 4;
  MediumDesc fog;
  fog.sigma_t = {0.3f, 0.6f, 1.2f};
  fog.albedo.constant = {0.9f, 0.7f, 0.8f};
  fog.g = 0.3f;
  d.media = {fog};
  d.materials = {InterfaceMaterial{}, DiffuseMaterial{RGB(0.6f, 0.5f, 0.4f)}, BlackMaterial{}};
  ShapeDesc floor;
  floor.geometry = RectangleShape{{-1.2f, -1, -1.2f}, {0, 0, 2.4f}, {2.4f, 0, 0}};
  floor.material = 1;
  if (bounded) {
    d.camera = look_at_camera({0, 0.2f, -4}, {0, 0, 0}, 50);
    ShapeDesc ball;
    ball.geometry = SphereShape{{0, 0, 0}, 2};
    ball.material = 0;
    ball.interior_medium = 0;
    d.shapes.push_back(ball);
  } else {
    d.camera = look_at_camera({0, 0.2f, -1.8f}, {0, 0, 0}, 60);
    d.camera.medium = 0;
    d.lights.push_back(SkyLight{RGB(0.3f), RGB(0.2f), RGB(0.1f), {0, 1, 0}});
  }
  d.shapes.push_back(floor);
  ShapeDesc lamp;
  lamp.geometry = RectangleShape{{-0.6f, 1.2f, -0.2f}, {0.4f, 0, 0}, {0, 0, 0.4f}};  // facing down
  lamp.material = 2;
  lamp.emission = AreaEmission{RGB(6.0f, 5.0f, 3.0f), false};
  d.shapes.push_back(lamp);
  d.lights.push_back(PointLight{{0.5f, 0.3f, 0.4f}, RGB(1.0f, 2.0f, 1.5f)});
  return d;
}

// Equiangular sampling on and off estimate the same image: the means over seeds agree within 5
// standard errors of their difference, in RGB and spectral transport, with lights chosen by power and
// through the light BVH (a choice that depends on the point); and with BDPT's.
TEST(VolPath, EquiangularSamplingOnAndOffAgree) {
  for (bool bounded : {true, false})
    for (bool spectral : {false, true}) {
      SceneDesc d = lit_fog(bounded);
      d.settings.spectral = spectral;
      d.settings.spp = 128;
      if (spectral) d.settings.light_selection = LightSelection::Bvh;
      d.settings.volpath.equiangular = false;
      const ChannelMeans off = render_means(d);
      d.settings.volpath.equiangular = true;
      const ChannelMeans on = render_means(d);
      for (int c = 0; c < 3; ++c) {
        ASSERT_GT(on.mean[c], 0.01f);
        const float se = std::hypot(on.standard_error[c], off.standard_error[c]);
        EXPECT_NEAR(on.mean[c], off.mean[c], 5 * se + 1e-4f * off.mean[c])
            << (bounded ? "bounded" : "unbounded") << (spectral ? ", spectral" : ", rgb") << ", channel " << c
            << ": standard errors " << on.standard_error[c] << " (on), " << off.standard_error[c] << " (off)";
      }
      // Distance sampling alone has heavy tails near the point light (its 1 / d^2 at scattering points
      // close to it), so its standard error over 8 seeds is itself uncertain: BDPT, which reaches the
      // point light from light subpaths too, is a second opinion with light tails.
      if (bounded && !spectral) {
        d.settings.integrator = "bdpt";
        const ChannelMeans bdpt = render_means(d);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(on.mean[c], bdpt.mean[c], 5 * std::hypot(on.standard_error[c], bdpt.standard_error[c]))
              << "against bdpt, channel " << c;
      }
    }
}

// Equiangular sampling draws its sample dimensions in a fixed order: 1 and 2 threads give the same
// image, bit for bit; and it changes the image (it runs).
TEST(VolPath, EquiangularSamplingIsTheSameForOneAndTwoThreads) {
  SceneDesc d = lit_fog(true);
  d.settings.seed = 3;
  const Image one = testing::render_description(d, 1).mean_image();
  const Image two = testing::render_description(d, 2).mean_image();
  ASSERT_EQ(one.rgb.size(), two.rgb.size());
  EXPECT_TRUE(one.rgb == two.rgb);
  d.settings.volpath.equiangular = false;
  EXPECT_FALSE(testing::render_description(d, 1).mean_image().rgb == one.rgb);
}

}  // namespace
}  // namespace candela
