// AOV layers (film/aov_film.h, render/first_hit_aovs.h): analytic albedo, normals and depth, the
// film's sample counts and variance, the colour unchanged by them, and the command line's EXR layers.
#include "candela/film/aov_film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <stdexcept>

#include "candela/base/error.h"
#include "candela/camera/camera.h"
#include "candela/film/image_io.h"
#include "candela/integrators/integrator.h"
#include "candela/render/first_hit_aovs.h"
#include "candela/spectral/cie.h"
#include "candela/testing/command_line.h"
#include "candela/testing/render_helpers.h"

namespace fs = std::filesystem;

namespace candela {
namespace {

const std::vector<Aov> kGeometric = {Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Position};

struct AovRender {
  Film film;
  AovFilm aovs;
  std::vector<AovLayer> layers;
};

AovRender render_with_aovs(const SceneDesc& desc, const std::vector<Aov>& layers, int threads = 2) {
  Scene scene(desc);
  AovRender r{Film(desc.film.width, desc.film.height), AovFilm(desc.film.width, desc.film.height, layers), {}};
  RenderOptions options;
  options.threads = threads;
  options.progress = false;
  options.aovs = &r.aovs;
  render(scene, desc.settings, r.film, options);
  r.layers = r.aovs.images(r.film);
  return r;
}

const AovLayer& layer(const std::vector<AovLayer>& layers, Aov aov) {
  for (const AovLayer& l : layers)
    if (l.aov == aov) return l;
  throw std::logic_error("no such layer");
}

// The camera at the origin looking along +z at an infinite plane z = distance facing it.
SceneDesc plane_facing_camera(float distance, const MaterialDesc& material, float fov_degrees) {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 0, 0}, {0, 0, 1}, fov_degrees), 12, 10, 8, 2);
  d.materials = {material};
  ShapeDesc plane;
  plane.geometry = PlaneShape{{0, 0, distance}, {0, 0, -1}};
  plane.material = 0;
  d.shapes = {plane};
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  return d;
}

TEST(Aovs, ParsesNamesAndRefusesUnknownOnes) {
  EXPECT_EQ(parse_aovs("depth, albedo,depth"), (std::vector<Aov>{Aov::Albedo, Aov::Depth}));
  EXPECT_EQ(parse_aovs("all").size(), std::size(kAllAovs));
  EXPECT_EQ(describe_aovs(parse_aovs("variance,spp,normal")), "normal,spp,variance");
  try {
    parse_aovs("albedo,colour");
    FAIL() << "an unknown name was accepted";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(),
                 "unknown AOV 'colour' (valid: albedo, normal, depth, position, spp, variance, geometric_normal, uv, "
                 "depth_derivatives, relative_variance, halves, spectral[:N[:MIN:MAX]], all, gbuffer, camera_space, world_space)");
  }
  EXPECT_THROW(parse_aovs("albedo,,normal"), UsageError);
}

// One BSDF sample of a cosine-sampled Lambertian weighs f cos / pdf = R exactly.
TEST(Aovs, AlbedoOfADiffusePlaneIsItsReflectance) {
  const RGB reflectance(0.2f, 0.5f, 0.8f);
  AovRender r = render_with_aovs(plane_facing_camera(3, DiffuseMaterial{reflectance}, 60), kGeometric);
  const AovLayer& albedo = layer(r.layers, Aov::Albedo);
  const AovLayer& normal = layer(r.layers, Aov::Normal);
  for (int y = 0; y < albedo.height; ++y)
    for (int x = 0; x < albedo.width; ++x)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(albedo.at(x, y, c), reflectance[c], 1e-6f) << x << "," << y << " channel " << c;
        EXPECT_EQ(normal.at(x, y, c), c == 2 ? -1.0f : 0.0f) << x << "," << y;  // facing the camera
      }
}

// Planar depth: the same in every pixel of a plane facing the camera, though the distance along the
// rays grows towards the corners (by 1 / cos of up to 45 degrees here).
TEST(Aovs, DepthOfAPlaneFacingTheCameraIsItsDistance) {
  const float d = 3.25f;
  AovRender r = render_with_aovs(plane_facing_camera(d, DiffuseMaterial{RGB(0.5f)}, 90), kGeometric);
  const AovLayer& depth = layer(r.layers, Aov::Depth);
  const AovLayer& position = layer(r.layers, Aov::Position);
  float widest = 0;
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      EXPECT_NEAR(depth.at(x, y, 0), d, 2e-5f * d) << x << "," << y;
      EXPECT_NEAR(position.at(x, y, 2), d, 2e-5f * d) << x << "," << y;
      widest = std::max(widest, std::hypot(position.at(x, y, 0), position.at(x, y, 1)));
    }
  EXPECT_GT(widest, 0.8f * d);  // the corners are far off axis: the depth is not the ray distance
}

// A unit sphere filling the image: each pixel's normal is the mean over its samples of p / |p|.
// The reference is the pixel's mean of the analytic normal over a fine grid of positions; the
// tolerance is 5 standard errors of a mean of spp independent uniform positions in the pixel.
TEST(Aovs, NormalsOfASphereAreTheAnalyticNormals) {
  constexpr int kSize = 16, kSpp = 64, kGrid = 16;
  SceneDesc desc = testing::sphere_under_sky(DiffuseMaterial{RGB(0.5f)}, RGB(1.0f), kSize, 20, kSpp, 1);
  desc.settings.sampler.type = SamplerType::Independent;
  desc.settings.seed = 7;
  AovRender r = render_with_aovs(desc, {Aov::Normal, Aov::Depth});
  const AovLayer& normal = layer(r.layers, Aov::Normal);
  const AovLayer& depth = layer(r.layers, Aov::Depth);
  const Camera camera(desc.camera, kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      double sum[3] = {0, 0, 0}, sum_sq[3] = {0, 0, 0}, depth_sum = 0;
      for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
          Ray ray = camera.generate_ray({float(x) + (float(i) + 0.5f) / kGrid, float(y) + (float(j) + 0.5f) / kGrid},
                                        {0.5f, 0.5f}, 0);
          // |o + t d| = 1, the nearer root.
          const Vec3 o = ray.origin, dir = normalize(ray.direction);
          const double b = dot(o, dir), c = dot(o, o) - 1.0, disc = b * b - c;
          ASSERT_GT(disc, 0) << "the sphere must fill the image";
          const double t = -b - std::sqrt(disc);
          const double n[3] = {o.x + t * dir.x, o.y + t * dir.y, o.z + t * dir.z};
          for (int k = 0; k < 3; ++k) {
            sum[k] += n[k];
            sum_sq[k] += n[k] * n[k];
          }
          depth_sum += t * dot(dir, camera.forward());
        }
      const double count = double(kGrid) * kGrid;
      for (int k = 0; k < 3; ++k) {
        const double mean = sum[k] / count, sd = std::sqrt(std::max(0.0, sum_sq[k] / count - mean * mean));
        EXPECT_NEAR(normal.at(x, y, k), mean, 5 * sd / std::sqrt(double(kSpp)) + 1e-5)
            << "pixel " << x << "," << y << " component " << k;
      }
      EXPECT_NEAR(depth.at(x, y, 0), depth_sum / count, 0.01) << "pixel " << x << "," << y;
    }
}

// A mirror is followed to the first non-delta surface: a mirror of reflectance 0.8 facing the
// camera shows a diffuse plane of 0.5 behind the camera, so the albedo is 0.4 and the normal the
// plane's; depth and position stay at the mirror.
TEST(Aovs, MirrorsAreFollowedToTheDiffuseSurfaceTheyShow) {
  SceneDesc desc = plane_facing_camera(2, MirrorMaterial{RGB(0.8f)}, 40);
  desc.materials.push_back(DiffuseMaterial{RGB(0.5f)});
  ShapeDesc back;
  back.geometry = PlaneShape{{0, 0, -3}, {0, 0, 1}};
  back.material = 1;
  desc.shapes.push_back(back);
  AovRender r = render_with_aovs(desc, kGeometric);
  const AovLayer& albedo = layer(r.layers, Aov::Albedo);
  const AovLayer& normal = layer(r.layers, Aov::Normal);
  const AovLayer& depth = layer(r.layers, Aov::Depth);
  for (int y = 0; y < albedo.height; ++y)
    for (int x = 0; x < albedo.width; ++x) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(albedo.at(x, y, c), 0.4f, 1e-6f) << x << "," << y;
      EXPECT_NEAR(normal.at(x, y, 2), 1.0f, 1e-6f) << x << "," << y;
      EXPECT_NEAR(depth.at(x, y, 0), 2.0f, 1e-4f) << x << "," << y;
    }
}

// Pixels that see only the sky: albedo 0, normal 0 (OIDN's "no surface"), Blender's background depth.
TEST(Aovs, MissesHaveNoSurface) {
  SceneDesc desc = testing::sphere_under_sky(DiffuseMaterial{RGB(0.5f)}, RGB(1.0f), 16, 60, 4, 1);
  AovRender r = render_with_aovs(desc, kGeometric);
  for (Aov aov : kGeometric)
    for (int c = 0; c < int(layer(r.layers, aov).channels.size()); ++c)
      EXPECT_EQ(layer(r.layers, aov).at(0, 0, c), aov == Aov::Depth ? kAovMissDepth : 0.0f) << aov_name(aov);
}

TEST(Aovs, SampleCountLayerIsTheAdaptiveSppMap) {
  SceneDesc desc = testing::sphere_under_sky(DiffuseMaterial{RGB(0.5f)}, RGB(1.0f), 16, 40, 1, 3);
  desc.settings.adaptive_spp = 32;
  desc.settings.adaptive_batch = 8;
  AovRender r = render_with_aovs(desc, {Aov::Depth, Aov::SampleCount});
  const AovLayer& spp = layer(r.layers, Aov::SampleCount);
  const Image counts = r.film.sample_count_image();
  float least = 1e30f, most = 0;
  for (int y = 0; y < spp.height; ++y)
    for (int x = 0; x < spp.width; ++x) {
      EXPECT_EQ(spp.at(x, y, 0), counts.at(x, y).r) << x << "," << y;
      least = std::min(least, spp.at(x, y, 0));
      most = std::max(most, spp.at(x, y, 0));
    }
  EXPECT_LT(least, most) << "the render should have been adaptive";
  EXPECT_NEAR(layer(r.layers, Aov::Depth).at(8, 8, 0), 3.0f, 0.01f);  // the sphere's front at the centre
}

// The variance layer (each pixel's variance of its mean, from its own samples) against the spread of
// the pixel values over independent renders: over the pixels, the mean of the across-seed sample
// variances and the mean of the layer agree within 4 standard errors, those of a chi-square variance
// estimate with seeds - 1 degrees of freedom (2 sigma^4 / (seeds - 1)) and of the layer's own spread.
TEST(Aovs, VarianceLayerAgreesWithTheSpreadOfIndependentRenders) {
  constexpr int kSize = 16, kSeeds = 16, kSpp = 16;
  SceneDesc desc = testing::sphere_under_sky(DiffuseMaterial{RGB(0.5f)}, RGB(1.0f), kSize, 30, kSpp, 3);
  desc.settings.sampler.type = SamplerType::Independent;
  const int pixels = kSize * kSize;
  std::vector<double> value_sum(pixels, 0), value_sq(pixels, 0), layer_sum(pixels, 0), layer_sq(pixels, 0);
  for (int seed = 0; seed < kSeeds; ++seed) {
    desc.settings.seed = uint64_t(1000 + seed);
    AovRender r = render_with_aovs(desc, {Aov::Variance});
    const Image mean = r.film.mean_image();
    const AovLayer& variance = layer(r.layers, Aov::Variance);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const int p = y * kSize + x;
        const double v = mean.at(x, y).g, l = variance.at(x, y, 1);
        value_sum[p] += v;
        value_sq[p] += v * v;
        layer_sum[p] += l;
        layer_sq[p] += l * l;
      }
  }
  double across = 0, layer_mean = 0, across_var = 0, layer_var = 0;
  for (int p = 0; p < pixels; ++p) {
    const double m = value_sum[p] / kSeeds;
    const double s2 = std::max(0.0, (value_sq[p] - kSeeds * m * m) / (kSeeds - 1));
    const double lm = layer_sum[p] / kSeeds;
    const double l_spread = std::max(0.0, (layer_sq[p] - kSeeds * lm * lm) / (kSeeds - 1));
    across += s2;
    layer_mean += lm;
    across_var += 2 * lm * lm / (kSeeds - 1);
    layer_var += l_spread / kSeeds;
  }
  across /= pixels;
  layer_mean /= pixels;
  const double se = std::sqrt(across_var + layer_var) / pixels;
  ASSERT_GT(layer_mean, 0);
  EXPECT_NEAR(across, layer_mean, 4 * se) << "across seeds " << across << ", layer " << layer_mean << ", se " << se;
  RecordProperty("across_seed_variance", std::to_string(across));
  RecordProperty("variance_layer_mean", std::to_string(layer_mean));
  RecordProperty("standard_error", std::to_string(se));
}

// A diffuse floor, a mirror ball and a glass ball under a sky: the colour is bitwise the same with
// and without every AOV, for the integrators that trace camera samples.
SceneDesc mixed_scene() {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 1, -5}, {0, 0.5f, 0}, 40), 24, 16, 8, 4);
  d.settings.sampler.type = SamplerType::ZSobol;
  d.materials = {DiffuseMaterial{RGB(0.6f, 0.5f, 0.4f)}, MirrorMaterial{RGB(0.9f)}, DielectricMaterial{}};
  ShapeDesc floor;
  floor.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}};
  floor.material = 0;
  ShapeDesc mirror;
  mirror.geometry = SphereShape{{-1.1f, 1, 0}, 1};
  mirror.material = 1;
  ShapeDesc glass;
  glass.geometry = SphereShape{{1.1f, 1, 0}, 1};
  glass.material = 2;
  d.shapes = {floor, mirror, glass};
  d.lights = {SkyLight{RGB(1.0f), RGB(0.6f), RGB(0.2f), {0, 1, 0}}};
  return d;
}

TEST(Aovs, TheColourIsBitwiseTheSameWithAndWithoutThem) {
  for (const char* integrator : {"path", "bdpt"}) {
    SceneDesc desc = mixed_scene();
    desc.settings.integrator = integrator;
    const Film plain = testing::render_description(desc, 2);
    AovRender with = render_with_aovs(desc, std::vector<Aov>(std::begin(kAllAovs), std::end(kAllAovs)));
    ASSERT_EQ(plain.pixels().size(), with.film.pixels().size());
    EXPECT_EQ(std::memcmp(plain.pixels().data(), with.film.pixels().data(), plain.pixels().size() * sizeof(PixelSums)), 0)
        << integrator;
    EXPECT_EQ(plain.mean_image().rgb, with.film.mean_image().rgb) << integrator;
  }
}

TEST(Aovs, AreTheSameForAnyThreadCount) {
  SceneDesc desc = mixed_scene();
  AovRender one = render_with_aovs(desc, kGeometric, 1);
  AovRender three = render_with_aovs(desc, kGeometric, 3);
  for (size_t i = 0; i < one.layers.size(); ++i) EXPECT_EQ(one.layers[i].values, three.layers[i].values) << one.layers[i].name;
}

// The pass of their own (render_aovs, for integrators without camera samples) is the same code as
// the camera samples': with the same samples per pixel the layers are identical. MLT adds its AOVs
// through its depth-0 pass (spp / 16 camera samples per pixel, here 16).
TEST(Aovs, SeparatePassAndMltAgreeWithCameraSamples) {
  SceneDesc desc = mixed_scene();
  desc.settings.spp = 16;
  AovRender path = render_with_aovs(desc, kGeometric);
  Scene scene(desc);
  AovFilm separate(desc.film.width, desc.film.height, kGeometric);
  RenderOptions options;
  options.threads = 2;
  options.progress = false;
  render_aovs(scene, desc.settings, separate, options, 16);
  const std::vector<AovLayer> separate_layers = separate.images(path.film);
  desc.settings.integrator = "mlt";
  desc.settings.spp = 256;
  desc.settings.mlt.bootstrap = 1000;
  desc.settings.mlt.chains = 16;
  AovRender mlt = render_with_aovs(desc, kGeometric);
  for (size_t i = 0; i < path.layers.size(); ++i) {
    EXPECT_EQ(path.layers[i].values, separate_layers[i].values) << path.layers[i].name;
    EXPECT_EQ(path.layers[i].values, mlt.layers[i].values) << path.layers[i].name;
  }
}

// ---- the command line

std::string run_cli(const std::string& args) { return std::string(CANDELA_CLI_PATH) + " " + args; }

const char* kSphereJson = R"({
  "camera": {"position": [0, 0, -3], "look_at": [0, 0, 0], "fov": 40, "width": 16, "height": 12},
  "render": {"spp": 4},
  "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}],
  "lights": [{"type": "sky", "radiance": 1}]
})";

TEST(Aovs, CommandLineWritesNamedExrLayers) {
  const fs::path dir = testing::fresh_test_directory("candela_aov_cli");
  const std::string scene = (dir / "sphere.json").string(), out = (dir / "out.exr").string();
  std::ofstream(scene) << kSphereJson;
  testing::CommandResult r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov all -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> names = read_channel_names(out);
  for (const char* expected : {"R", "G", "B", "Albedo.R", "Albedo.G", "Albedo.B", "Normal.X", "Normal.Y", "Normal.Z",
                               "Depth.Z", "Position.X", "Position.Y", "Position.Z", "SampleCount.X", "Variance.R",
                               "Variance.G", "Variance.B", "GeometricNormal.X", "GeometricNormal.Y",
                               "GeometricNormal.Z", "UV.U", "UV.V", "DepthDerivatives.X", "DepthDerivatives.Y",
                               "RelativeVariance.R", "RelativeVariance.G", "RelativeVariance.B"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  EXPECT_EQ(names.size(), 27u);
  const FloatChannels depth = read_float_channels(out, "Depth.");
  ASSERT_EQ(depth.values.size(), 16u * 12u);
  EXPECT_NEAR(depth.values[6 * 16 + 8], 2.0f, 0.01f);  // the sphere's front, 2 from the camera
  EXPECT_EQ(depth.values[0], kAovMissDepth);           // the sky in the corner
  for (float n : read_float_channels(out, "SampleCount.").values) EXPECT_EQ(n, 4.0f);
  // The colour is as a render without AOVs writes it.
  const std::string plain = (dir / "plain.exr").string();
  ASSERT_EQ(testing::run_command(run_cli("render " + scene + " -o " + plain + " -q")).exit_code, 0);
  EXPECT_EQ(read_image(out).rgb, read_image(plain).rgb);
  fs::remove_all(dir);
}

TEST(Aovs, CommandLineRefusesUnknownNamesAndUnkeptCombinations) {
  const fs::path dir = testing::fresh_test_directory("candela_aov_cli");
  const std::string scene = (dir / "sphere.json").string(), out = (dir / "out.exr").string();
  std::ofstream(scene) << kSphereJson;
  testing::CommandResult r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov albedo,colour -q"));
  EXPECT_EQ(r.exit_code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("--aov: unknown AOV 'colour' (valid: albedo, normal, depth, position, spp, variance, "
                          "geometric_normal, uv, depth_derivatives, relative_variance, halves, spectral[:N[:MIN:MAX]], all, gbuffer"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out));
  r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov depth --part 1/2 -q"));
  EXPECT_EQ(r.exit_code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("--aov cannot be combined with --part"), std::string::npos) << r.output;
  // A PNG gets the colour alone, with one note.
  const std::string png = (dir / "out.png").string();
  r = testing::run_command(run_cli("render " + scene + " -o " + png + " --aov normal"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("note: AOVs are written into .exr outputs only"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(png));
  fs::remove_all(dir);
}

// The scene's own list (render.aovs), checked where it is read.
TEST(Aovs, SceneSettingNamesTheLayers) {
  const fs::path dir = testing::fresh_test_directory("candela_aov_cli");
  std::string json = kSphereJson;
  const std::string with = std::regex_replace(json, std::regex(R"("spp": 4)"), R"("spp": 4, "aovs": "depth, normal")");
  const std::string scene = (dir / "sphere.json").string(), out = (dir / "out.exr").string();
  std::ofstream(scene) << with;
  testing::CommandResult r = testing::run_command(run_cli("render " + scene + " -o " + out + " -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> names = read_channel_names(out);
  EXPECT_EQ(names.size(), 7u);
  EXPECT_NE(std::find(names.begin(), names.end(), "Depth.Z"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "Normal.X"), names.end());
  std::ofstream(scene) << std::regex_replace(json, std::regex(R"("spp": 4)"), R"("spp": 4, "aovs": "dept")");
  r = testing::run_command(run_cli("render " + scene + " -o " + out + " -q"));
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("/render/aovs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("unknown AOV 'dept'"), std::string::npos) << r.output;
  fs::remove_all(dir);
}


TEST(Aovs, GbufferSelectsPbrtsLayersInCameraSpace) {
  const AovSelection gbuffer = parse_aov_selection("gbuffer");
  EXPECT_EQ(gbuffer.layers, std::vector<Aov>(std::begin(kPbrtGbufferAovs), std::end(kPbrtGbufferAovs)));
  EXPECT_EQ(gbuffer.naming, AovNaming::PbrtGbuffer);
  EXPECT_EQ(gbuffer.space, AovSpace::Camera);
  EXPECT_EQ(parse_aov_selection(" gbuffer , world_space").space, AovSpace::World);
  const AovSelection own = parse_aov_selection("position, camera_space, uv");
  EXPECT_EQ(own.layers, (std::vector<Aov>{Aov::Position, Aov::Uv}));
  EXPECT_EQ(own.naming, AovNaming::Candela);
  EXPECT_EQ(own.space, AovSpace::Camera);
  EXPECT_EQ(parse_aov_selection("normal").space, AovSpace::World);
  EXPECT_THROW(parse_aov_selection("gbuffer,albedo"), UsageError);           // a fixed set
  EXPECT_THROW(parse_aov_selection("albedo,camera_space,world_space"), UsageError);
  EXPECT_THROW(parse_aov_selection("camera_space"), UsageError);             // no layer
}

// A plane tilted towards the camera, z = 4 + y / 2 in camera space, seen by a pinhole camera at
// (1, 2, 3) looking along world -z (camera x = world x, y = world y, z = world -z): one sample
// through each pixel's centre gives the analytic position, normals and dz/dx, dz/dy (the plane is its
// own tangent plane, so the neighbouring pixels' rays meet it where the differentials say).
struct TiltedPlaneGbuffer {
  static constexpr int kWidth = 8, kHeight = 6;
};

SceneDesc tilted_plane_gbuffer_scene() {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({1, 2, 3}, {1, 2, 0}, 50), TiltedPlaneGbuffer::kWidth,
                                     TiltedPlaneGbuffer::kHeight, 1, 2);
  d.materials = {DiffuseMaterial{RGB(0.5f)}};
  ShapeDesc plane;
  // Camera-space normal (0, -1/2, 1) at camera-space (0, 0, 4) = world (1, 2, -1): world (0, -1/2, -1).
  plane.geometry = PlaneShape{{1, 2, -1}, normalize(Vec3(0, -0.5f, -1))};
  plane.material = 0;
  d.shapes = {plane};
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  return d;
}

// Where the camera ray through film position `film` meets the tilted plane, in camera space.
Point3 tilted_plane_hit_in_camera_space(const Camera& camera, Vec2 film) {
  const Ray ray = camera.generate_ray(film, {0.5f, 0.5f}, 0);
  const Vec3 d(ray.direction.x, ray.direction.y, -ray.direction.z);  // camera space
  const float t = 4 / (d.z - 0.5f * d.y);
  return {t * d.x, t * d.y, t * d.z};
}

std::vector<AovLayer> tilted_plane_gbuffer_layers(const AovSelection& selection, int samples_per_pixel) {
  const SceneDesc desc = tilted_plane_gbuffer_scene();
  Scene scene(desc);
  const int w = TiltedPlaneGbuffer::kWidth, h = TiltedPlaneGbuffer::kHeight;
  Film film(w, h);
  AovFilm aovs(w, h, selection, aov_camera_frame(scene.camera()));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Ray ray = scene.camera().generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}, 0);
      const AovSample s = first_hit_aovs(scene, ray, true, x, y, 0, 7);
      for (int k = 0; k < samples_per_pixel; ++k) {
        film.add_sample(x, y, RGB(1.0f));
        aovs.add_sample(x, y, s, 1);
      }
    }
  return aovs.images(film);
}

TEST(Aovs, TiltedPlaneGivesAnalyticCameraSpaceGbuffer) {
  const SceneDesc desc = tilted_plane_gbuffer_scene();
  const Camera camera(desc.camera, desc.film.width, desc.film.height);
  const AovCameraFrame frame = aov_camera_frame(camera);
  EXPECT_NEAR(frame.x.x, 1, 1e-5f);
  EXPECT_NEAR(frame.y.y, 1, 1e-5f);
  EXPECT_NEAR(frame.z.z, -1, 1e-5f);
  // pbrt-v4's layout; 64 samples per pixel scale the differentials by max(1/8, 1/sqrt(64)) = 1/8.
  const std::vector<AovLayer> layers = tilted_plane_gbuffer_layers(parse_aov_selection("gbuffer"), 64);
  const AovLayer& p = layer(layers, Aov::Position);
  const AovLayer& n = layer(layers, Aov::GeometricNormal);
  const AovLayer& ns = layer(layers, Aov::Normal);
  const AovLayer& dz = layer(layers, Aov::DepthDerivatives);
  EXPECT_EQ(p.name, "P");
  EXPECT_EQ(n.name, "N");
  EXPECT_EQ(ns.name, "Ns");
  EXPECT_EQ(dz.name, "");
  const Vec3 normal = normalize(Vec3(0, 0.5f, -1));  // facing the camera
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const Point3 expected = tilted_plane_hit_in_camera_space(camera, {x + 0.5f, y + 0.5f});
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(p.at(x, y, c), expected[c], 1e-4f) << x << "," << y << " channel " << c;
        EXPECT_NEAR(n.at(x, y, c), normal[c], 1e-5f) << x << "," << y;
        EXPECT_NEAR(ns.at(x, y, c), normal[c], 1e-5f) << x << "," << y;
      }
      const float dzdx = tilted_plane_hit_in_camera_space(camera, {x + 1.5f, y + 0.5f}).z - expected.z;
      const float dzdy = tilted_plane_hit_in_camera_space(camera, {x + 0.5f, y + 1.5f}).z - expected.z;
      EXPECT_NEAR(dz.at(x, y, 0), std::abs(dzdx) / 8, 1e-4f) << x << "," << y;
      EXPECT_NEAR(dz.at(x, y, 1), std::abs(dzdy) / 8, 1e-4f) << x << "," << y;
      EXPECT_GT(dz.at(x, y, 1), 0.002f);  // the tilt is about x: z changes down the image
    }
}

TEST(Aovs, TiltedPlaneGivesWorldSpaceGbufferOnRequest) {
  const SceneDesc desc = tilted_plane_gbuffer_scene();
  const Camera camera(desc.camera, desc.film.width, desc.film.height);
  const std::vector<AovLayer> layers = tilted_plane_gbuffer_layers(parse_aov_selection("gbuffer,world_space"), 1);
  const AovLayer& p = layer(layers, Aov::Position);
  const AovLayer& n = layer(layers, Aov::GeometricNormal);
  const AovLayer& dz = layer(layers, Aov::DepthDerivatives);
  const Vec3 normal = normalize(Vec3(0, 0.5f, 1));  // camera-space (0, 1/2, -1) in world space
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const Point3 c = tilted_plane_hit_in_camera_space(camera, {x + 0.5f, y + 0.5f});
      const Point3 world(1 + c.x, 2 + c.y, 3 - c.z);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(p.at(x, y, k), world[k], 1e-4f) << x << "," << y;
        EXPECT_NEAR(n.at(x, y, k), normal[k], 1e-5f) << x << "," << y;
      }
      // World z runs against camera z here: the same magnitudes, unscaled with one sample per pixel.
      const float dzdx = tilted_plane_hit_in_camera_space(camera, {x + 1.5f, y + 0.5f}).z - c.z;
      EXPECT_NEAR(dz.at(x, y, 0), std::abs(dzdx), 1e-4f) << x << "," << y;
    }
}

TEST(Aovs, GbufferMissesAreZeroAndUvIsTheHits) {
  // The sky fills the image: every pixel is 0 in every geometric layer.
  SceneDesc empty = testing::empty_scene(testing::look_at_camera({0, 0, 0}, {0, 0, 1}, 50), 4, 3, 2, 2);
  empty.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  AovRender r = render_with_aovs(empty, parse_aovs("all"));
  for (Aov aov : {Aov::Position, Aov::GeometricNormal, Aov::Uv, Aov::DepthDerivatives, Aov::Normal})
    for (float v : layer(r.layers, aov).values) EXPECT_EQ(v, 0.0f) << aov_name(aov);
  // uv: the hit's own parameterisation, averaged over the one sample through each pixel centre.
  const SceneDesc desc = tilted_plane_gbuffer_scene();
  Scene scene(desc);
  const std::vector<AovLayer> layers = tilted_plane_gbuffer_layers(parse_aov_selection("uv"), 1);
  const AovLayer& uv = layer(layers, Aov::Uv);
  EXPECT_EQ(uv.name, "UV");
  for (int y = 0; y < uv.height; ++y)
    for (int x = 0; x < uv.width; ++x) {
      SurfaceHit hit;
      Ray ray = scene.camera().generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}, 0);
      ASSERT_TRUE(scene.intersect(ray, hit));
      EXPECT_FLOAT_EQ(uv.at(x, y, 0), hit.uv.x);
      EXPECT_FLOAT_EQ(uv.at(x, y, 1), hit.uv.y);
    }
}

// pbrt-v4's gbuffer EXR: its channel names (an empty layer name leaves the channels alone).
TEST(Aovs, GbufferExrChannelsArePbrtsNames) {
  const std::vector<AovLayer> layers = tilted_plane_gbuffer_layers(parse_aov_selection("gbuffer"), 4);
  const FloatChannels channels = exr_channels(layers);
  EXPECT_EQ(channels.names,
            (std::vector<std::string>{"Albedo.R", "Albedo.G", "Albedo.B", "P.X", "P.Y", "P.Z", "dzdx", "dzdy", "N.X",
                                      "N.Y", "N.Z", "Ns.X", "Ns.Y", "Ns.Z", "u", "v", "Variance.R", "Variance.G",
                                      "Variance.B", "RelativeVariance.R", "RelativeVariance.G",
                                      "RelativeVariance.B"}));
}

TEST(Aovs, CommandLineWritesPbrtGbufferExr) {
  const fs::path dir = testing::fresh_test_directory("candela_aov_cli");
  const std::string scene = (dir / "sphere.json").string(), out = (dir / "out.exr").string();
  std::ofstream(scene) << kSphereJson;
  testing::CommandResult r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov gbuffer -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> names = read_channel_names(out);
  EXPECT_EQ(names.size(), 25u);
  for (const char* expected : {"R", "G", "B", "P.Z", "dzdx", "N.X", "Ns.Z", "u", "v", "RelativeVariance.B"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  const FloatChannels p = read_float_channels(out, "P.");
  ASSERT_EQ(p.values.size(), 16u * 12u * 3u);
  EXPECT_NEAR(p.values[(6 * 16 + 8) * 3 + 2], 2.0f, 0.02f);  // the sphere's front, 2 along the view
  EXPECT_EQ(p.values[2], 0.0f);                               // the sky in the corner
  fs::remove_all(dir);
}

// pbrt-v4's spectral film as an AOV layer: "spectral", "spectral:N", "spectral:N:MIN:MAX".
TEST(Aovs, SpectralLayerParsesBucketsAndRefusesBadOnes) {
  const AovSelection plain = parse_aov_selection("spectral");
  EXPECT_EQ(plain.layers, std::vector<Aov>{Aov::Spectral});
  EXPECT_EQ(plain.spectral.count, 16);
  EXPECT_EQ(plain.spectral.lambda_min, 360.0f);
  EXPECT_EQ(plain.spectral.lambda_max, 830.0f);
  const AovSelection mixed = parse_aov_selection("albedo, spectral:8:400:700");
  EXPECT_EQ(mixed.layers, (std::vector<Aov>{Aov::Albedo, Aov::Spectral}));
  EXPECT_EQ(mixed.spectral.count, 8);
  EXPECT_EQ(mixed.spectral.lambda_min, 400.0f);
  // "all" leaves it out: it needs spectral transport.
  EXPECT_FALSE(parse_aov_selection("all").wants_spectral());
  for (const char* bad : {"spectral:0", "spectral:2.5", "spectral:8:400", "spectral:8:300:700", "spectral:8:700:400",
                          "spectral:x", "spectral,spectral:4", "gbuffer,spectral", "spectrals"})
    EXPECT_THROW(parse_aov_selection(bad), UsageError) << bad;
}

TEST(Aovs, SpectralBucketsAreNamedByTheirCentresAsPbrtNamesThem) {
  SpectralBuckets b{8, 360, 830};
  EXPECT_EQ(b.channel_name(0), "389,375nm");
  EXPECT_EQ(b.channel_name(7), "800,625nm");
  EXPECT_EQ(b.bucket_of(360), 0);
  EXPECT_EQ(b.bucket_of(830), 7);
  EXPECT_EQ(b.bucket_of(418.75f + 0.01f), 1);
  EXPECT_EQ(b.bucket_of(359), -1);
  const AovFilm film(1, 1, parse_aov_selection("spectral:8"), AovCameraFrame{});
  Film colour(1, 1);
  const std::vector<AovLayer> layers = film.images(colour);
  ASSERT_EQ(layers.size(), 1u);
  EXPECT_EQ(exr_channels(layers).names[0], "S0.389,375nm");  // the OpenEXR spectral layout's names, as pbrt-v4's
}

// Each bucket is the mean of the spectrum over it, although candela's wavelengths are importance
// sampled (not uniform, as pbrt-v4's spectral film draws them): the 1 / pdf weights make it so.
TEST(Aovs, SpectralBucketsAreTheSpectrumsMeanOverEachBucket) {
  const SpectralBuckets buckets{6, 360, 830};
  AovFilm film(1, 1, parse_aov_selection("spectral:6"), AovCameraFrame{});
  auto spectrum = [](float lambda) { return 2.0f + std::sin(lambda / 40.0f); };
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Wavelengths wl = sample_visible_wavelengths(uniform(rng));
    const RGB values = RGB::from_lanes([&](int k) { return spectrum(wl.lambda[k]); });
    film.add_spectral_sample(0, 0, values, wl, 0.5f + uniform(rng), 0);
  }
  const AovLayer layer = film.images(Film(1, 1))[0];
  for (int b = 0; b < buckets.count; ++b) {
    const double lo = 360 + b * (470.0 / 6), hi = lo + 470.0 / 6;
    double mean = 0;  // the exact mean over the bucket, by the midpoint rule
    for (int k = 0; k < 1000; ++k) mean += spectrum(float(lo + (k + 0.5) * (hi - lo) / 1000)) / 1000;
    // The ratio estimator's error: the spectrum varies by at most 1 within a bucket, and the
    // outermost buckets get the fewest wavelengths (about 1% of 80000): 5 standard errors.
    EXPECT_NEAR(layer.values[size_t(b)], mean, 5 * 0.5 / std::sqrt(800.0)) << "bucket " << b;
  }
}

TEST(Aovs, SpectralMaxComponentScalesAsPbrtsSpectralFilm) {
  AovFilm film(1, 1, parse_aov_selection("spectral:1"), AovCameraFrame{});
  Wavelengths wl;
  for (int k = 0; k < Wavelengths::kCount; ++k) wl.lambda[k] = 500, wl.pdf[k] = 1;
  // The limit applies to the largest lane in pbrt-v4's units (over the CIE Y integral).
  const float y = float(cie::y_integral());
  EXPECT_TRUE(film.empty());
  film.add_spectral_sample(0, 0, RGB(4 * y, 2 * y, 2 * y, 2 * y), wl, 1, 2);
  EXPECT_FALSE(film.empty());  // (no separate AOV pass then doubles its weights)
  EXPECT_NEAR(film.images(Film(1, 1))[0].values[0], (2 * y + 3 * y) / 4, 1e-3 * y);  // scaled by 1/2
}

// A sky of radiance 1 seen everywhere: every bucket is D65 (normalised to luminance 1) averaged over
// the bucket, as pbrt-v4's spectral film records an RGB illuminant; the EXR says it is spectral.
TEST(Aovs, CommandLineWritesTheSpectralLayout) {
  const fs::path dir = testing::fresh_test_directory("candela_aov_spectral");
  const std::string scene = (dir / "sky.json").string(), out = (dir / "out.exr").string();
  std::ofstream(scene) << R"({
  "camera": {"position": [0, 0, -3], "look_at": [0, 0, 0], "fov": 40, "width": 16, "height": 12},
  "render": {"spp": 16, "spectral": true},
  "lights": [{"type": "sky", "radiance": 1}]
})";
  testing::CommandResult r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov spectral:4 -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_channel_names(out),
            (std::vector<std::string>{"R", "G", "B", "S0.418,750nm", "S0.536,250nm", "S0.653,750nm", "S0.771,250nm"}));
  const FloatChannels s = read_float_channels(out, "S0.");
  ASSERT_EQ(s.values.size(), 16u * 12u * 4u);
  for (int b = 0; b < 4; ++b) {
    double measured = 0;
    for (size_t p = 0; p < 16 * 12; ++p) measured += s.values[p * 4 + size_t(b)] / (16.0 * 12.0);
    double expected = 0;
    for (int k = 0; k < 1000; ++k) expected += cie::d65(360 + 117.5 * (b + (k + 0.5) / 1000)) / 1000;
    // 3072 wavelengths per bucket; D65 varies by under 40% within one: well inside 3%.
    EXPECT_NEAR(measured, expected, 0.03 * expected) << "bucket " << b;
  }
  // Refused without spectral transport, and with an integrator that splats.
  r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov spectral --transport rgb -q"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("needs spectral transport"), std::string::npos) << r.output;
  r = testing::run_command(run_cli("render " + scene + " -o " + out + " --aov spectral --integrator bdpt -q"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("not kept by the bdpt integrator"), std::string::npos) << r.output;
  fs::remove_all(dir);
}
}  // namespace
}  // namespace candela

namespace candela {
namespace {

// The halves layer: each half's colour mean and share from the film, and each half's own features,
// kept apart by the sample's half (a pixel's first sample in half A, its other two in half B).
TEST(Aovs, HalvesLayerKeepsEachHalfsColourAndFeatures) {
  Film film(1, 1);
  AovFilm aovs(1, 1, parse_aov_selection("halves"), AovCameraFrame{});
  EXPECT_TRUE(aovs.needs_shading());  // the features need the first hit's BSDF
  AovSample hit_a, hit_b;
  hit_a.hit = hit_b.hit = true;
  hit_a.albedo = RGB(0.2f, 0.4f, 0.6f);
  hit_b.albedo = RGB(0.8f, 0.8f, 0.8f);
  hit_a.normal = {0, 1, 0};
  hit_b.normal = {1, 0, 0};
  hit_a.depth = 2;
  hit_b.depth = 5;
  film.add_sample(0, 0, RGB(1.0f), 1, true);
  aovs.add_sample(0, 0, hit_a, 1, true);
  for (int k = 0; k < 2; ++k) {
    film.add_sample(0, 0, RGB(4.0f), 1, false);
    aovs.add_sample(0, 0, hit_b, 1, false);
  }
  const std::vector<AovLayer> layers = aovs.images(film);
  ASSERT_EQ(layers.size(), 1u);
  const AovLayer& halves = layers[0];
  ASSERT_EQ(halves.channels.size(), 21u);
  EXPECT_EQ(halves.name, "Halves");
  const std::vector<float> expected = {1, 1, 1, 4, 4, 4, 1.0f / 3,                     // A, B, ShareA
                                       0.2f, 0.4f, 0.6f, 0, 1, 0, 2,                   // A's albedo, normal, depth
                                       0.8f, 0.8f, 0.8f, 1, 0, 0, 5};                  // B's
  for (size_t c = 0; c < expected.size(); ++c)
    EXPECT_NEAR(halves.values[c], expected[c], 1e-6f) << halves.channels[c];
  EXPECT_EQ(exr_channels(layers).names[7], "Halves.A.Albedo.R");
}

}  // namespace
}  // namespace candela
