// Environment maps: the two parameterisations of the sphere (the equal-area square round trip and
// its area preservation), sample_li's directions following pdf_li (spherical chi-square) for both
// mappings under a rotation, radiance / pdf estimating the integral of the map over the sphere, and
// reading maps from files.
#include "candela/lights/environment_light.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <numbers>

#include <unistd.h>

#include "candela/film/image_io.h"
#include "candela/base/error.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/environment_maps.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

using testing::kChiSquareSamples;

// ---------------------------------------------------------------- the equal-area square

TEST(EqualAreaMapping, RoundTripsSquareToSphereToSquare) {
  Rng rng(5, 8);
  for (int i = 0; i < 100000; ++i) {
    Vec2 p{rng.next_float(), rng.next_float()};
    Vec3 w = equal_area_square_to_sphere(p);
    ASSERT_NEAR(length(w), 1.0f, 1e-5f);
    Vec2 q = equal_area_sphere_to_square(w);
    ASSERT_NEAR(q.x, p.x, 2e-5f) << p.x << " " << p.y;
    ASSERT_NEAR(q.y, p.y, 2e-5f) << p.x << " " << p.y;
  }
  // Landmarks: the centre is +z, the corners -z, the edge midpoints the horizon.
  EXPECT_NEAR(equal_area_square_to_sphere({0.5f, 0.5f}).z, 1, 1e-6f);
  EXPECT_NEAR(equal_area_square_to_sphere({0, 0}).z, -1, 1e-6f);
  EXPECT_NEAR(equal_area_square_to_sphere({1, 1}).z, -1, 1e-6f);
  Vec3 e = equal_area_square_to_sphere({1, 0.5f});
  EXPECT_NEAR(e.x, 1, 1e-6f);
  EXPECT_NEAR(e.z, 0, 1e-6f);
  // Sphere -> square -> sphere, every octant.
  for (int i = 0; i < 100000; ++i) {
    Vec3 w = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    Vec3 back = equal_area_square_to_sphere(equal_area_sphere_to_square(w));
    ASSERT_NEAR(back.x, w.x, 3e-5f);
    ASSERT_NEAR(back.y, w.y, 3e-5f);
    ASSERT_NEAR(back.z, w.z, 3e-5f);
  }
}

TEST(EqualAreaMapping, FoldedEdgesAreOneDirection) {
  for (float t : {0.1f, 0.3f, 0.45f}) {
    Vec3 a = equal_area_square_to_sphere({0, t}), b = equal_area_square_to_sphere({0, 1 - t});
    Vec3 c = equal_area_square_to_sphere({t, 1}), d = equal_area_square_to_sphere({1 - t, 1});
    EXPECT_NEAR(length(a - b), 0, 1e-5f);
    EXPECT_NEAR(length(c - d), 0, 1e-5f);
  }
}

TEST(EqualAreaMapping, IsAreaPreserving) {
  // Uniform points of the square become uniform directions.
  auto sample = [](Vec2 u) { return equal_area_square_to_sphere(u); };
  auto pdf = [](const Vec3&) { return uniform_sphere_pdf(); };
  EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 31), testing::kChiSquareAlpha);
}

// ---------------------------------------------------------------- environment lights

const Transform& test_rotation() {
  static const Transform r = Transform::rotate(40, normalize(Vec3(1, 2, -0.5f)));
  return r;
}

EnvironmentLight test_light(EnvironmentMapping mapping) {
  return EnvironmentLight(testing::environment_test_map(mapping), mapping, RGB(1.5f, 1.0f, 0.5f), test_rotation(), 3.0f);
}

constexpr EnvironmentMapping kAllMappings[] = {EnvironmentMapping::Equirectangular,
                                               EnvironmentMapping::EquirectangularPoleRows,
                                               EnvironmentMapping::EqualAreaOctahedral};
const char* name(EnvironmentMapping m) {
  switch (m) {
    case EnvironmentMapping::Equirectangular: return "equirectangular";
    case EnvironmentMapping::EquirectangularPoleRows: return "equirectangular, pole rows";
    case EnvironmentMapping::EqualAreaOctahedral: return "equal-area octahedral";
  }
  return "?";
}
// Where texel (x, y) sits in the image's (u, v).
Vec2 texel_centre(EnvironmentMapping m, int x, int y, const Image& img) {
  if (m == EnvironmentMapping::EquirectangularPoleRows) return {(x + 0.5f) / img.width, float(y) / (img.height - 1)};
  return {(x + 0.5f) / img.width, (y + 0.5f) / img.height};
}

TEST(EnvironmentLight, EquirectangularFollowsMitsubasConvention) {
  // phi = 2 pi u, theta = pi v: (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)).
  EnvironmentLight light(testing::environment_test_map(EnvironmentMapping::Equirectangular), EnvironmentMapping::Equirectangular,
                         RGB(1.0f), Transform(), 1);
  auto expect_dir = [&](Vec2 uv, Vec3 d) {
    Vec3 w = light.uv_to_direction(uv);
    EXPECT_NEAR(length(w - d), 0, 1e-6f) << uv.x << " " << uv.y;
    Vec2 back = light.direction_to_uv(d);
    EXPECT_NEAR(back.x, uv.x, 1e-6f);
    EXPECT_NEAR(back.y, uv.y, 1e-6f);
  };
  expect_dir({0.0f, 0.5f}, {0, 0, -1});
  expect_dir({0.25f, 0.5f}, {1, 0, 0});
  expect_dir({0.5f, 0.5f}, {0, 0, 1});
  expect_dir({0.75f, 0.5f}, {-1, 0, 0});
  expect_dir({0.25f, 0.25f}, {std::sqrt(0.5f), std::sqrt(0.5f), 0});
  EXPECT_NEAR(light.uv_to_direction({0.3f, 0.0f}).y, 1, 1e-6f);  // v = 0, the top row, is +y
}

TEST(EnvironmentLight, RadianceIsTheScaledImageAtPixelCentresUnderTheRotation) {
  for (EnvironmentMapping m : kAllMappings) {
    Image img = testing::environment_test_map(m);
    EnvironmentLight light = test_light(m);
    for (auto [x, y] : {std::pair{3, 2}, std::pair{img.width / 2 + 3, img.height / 4}, std::pair{10, 7}}) {
      Vec2 uv = texel_centre(m, x, y, img);
      Vec3 world = test_rotation().vector(light.uv_to_direction(uv));
      RGB expected = img.at(x, y) * RGB(1.5f, 1.0f, 0.5f);
      RGB got = light.radiance(world * 2.0f);  // need not be normalised
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1e-3f * (1 + expected[c])) << name(m);
    }
  }
}

// Mitsuba 3's envmap lookup (emitters/envmap.cpp, eval_spectrum), transcribed independently of
// environment_light.cpp: the image gets a copy of its first column appended (width + 1 columns),
// then uv.x -= 1 / (2 width), uv -= floor(uv), uv *= (width, height - 1), and the texels at
// min(floor(uv), (width - 1, height - 2)) and their +1 neighbours are blended bilinearly.
RGB mitsuba_envmap_eval(const Image& img, Vec2 uv) {
  const int w = img.width + 1, h = img.height;
  auto texel = [&](int x, int y) { return img.at(x % img.width, y); };
  double u = uv.x - 0.5 / (w - 1), v = uv.y;
  u -= std::floor(u);
  v -= std::floor(v);
  u *= w - 1;
  v *= h - 1;
  int x = std::min(int(u), w - 2), y = std::min(int(v), h - 2);
  float fx = float(u - x), fy = float(v - y);
  RGB top = texel(x, y) * (1 - fx) + texel(x + 1, y) * fx;
  RGB bottom = texel(x, y + 1) * (1 - fx) + texel(x + 1, y + 1) * fx;
  return top * (1 - fy) + bottom * fy;
}

TEST(EnvironmentLight, PoleRowsLookUpAsMitsubasEnvmap) {
  const EnvironmentMapping m = EnvironmentMapping::EquirectangularPoleRows;
  Image img = testing::environment_test_map(m);
  EnvironmentLight light(img, m, RGB(2.0f), test_rotation(), 1);
  Rng rng(7, 1);
  for (int i = 0; i < 20000; ++i) {
    Vec3 world = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    // Mitsuba's direction_to_uv of the direction in the emitter's frame.
    Vec3 d = normalize(test_rotation().inverse().vector(world));
    Vec2 uv{std::atan2(d.x, -d.z) * kInv2Pi, std::acos(std::clamp(d.y, -1.0f, 1.0f)) * kInvPi};
    RGB expected = mitsuba_envmap_eval(img, uv) * 2.0f, got = light.radiance(world);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], expected[c], 2e-4f * (1 + expected[c])) << uv.x << " " << uv.y;
  }
}

TEST(EnvironmentLight, PoleRowsDensityIsLuminanceTimesSolidAngleOfEachPatch) {
  // Mitsuba samples its envmap in proportion to luminance times sin(theta), interpolated between
  // texel centres. Here each patch between four texel centres has the density of its mean corner
  // luminance times its solid angle, uniform over the patch in (u, v): so pdf_li times the patch's
  // row Jacobian 2 pi^2 sin(theta) is the same at every point of a patch, and, divided by the mean
  // corner luminance and the row's solid angle per patch area, the same for every patch.
  const EnvironmentMapping m = EnvironmentMapping::EquirectangularPoleRows;
  Image img = testing::environment_test_map(m);
  EnvironmentLight light(img, m, RGB(1.0f), Transform(), 1);
  const int w = img.width, rows = img.height - 1;
  double ratio0 = 0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < w; ++i) {
      float lum = 0.25f * (img.at(i, j).luminance() + img.at((i + 1) % w, j).luminance() +
                           img.at(i, j + 1).luminance() + img.at((i + 1) % w, j + 1).luminance());
      if (!(lum > 0.05f)) continue;  // below the floor every pixel with radiance gets
      double row_solid_angle = 2 * std::numbers::pi / w *
                               (std::cos(std::numbers::pi * j / rows) - std::cos(std::numbers::pi * (j + 1) / rows));
      double patch_area = 1.0 / (double(w) * rows);
      for (Vec2 f : {Vec2(0.3f, 0.4f), Vec2(0.8f, 0.6f)}) {
        Vec2 uv{float((i + 0.5 + f.x) / w), float((j + f.y) / rows)};
        if (uv.x >= 1) uv.x -= 1;
        Vec3 dir = light.uv_to_direction(uv);
        double sin_theta = std::sqrt(dir.x * dir.x + dir.z * dir.z);
        double density_uv = light.pdf_li({}, dir, {}, {}) * 2 * sqr(std::numbers::pi) * sin_theta;
        double ratio = density_uv / (lum * row_solid_angle / patch_area);
        if (ratio0 == 0) ratio0 = ratio;
        ASSERT_NEAR(ratio / ratio0, 1, 2e-3) << "patch " << i << ", " << j;
      }
    }
  EXPECT_GT(ratio0, 0);
}

TEST(EnvironmentLight, RadianceIsContinuousAcrossTheImageEdges) {
  // Points just either side of where the image's edges meet on the sphere see the same radiance:
  // the equirectangular seam u = 0 ~ 1, and the octahedral square's folded edges, (eps, t) ~ (eps, 1 - t)
  // and (t, eps) ~ (1 - t, eps). The interpolation must wrap to the right neighbours for this.
  const float eps = 1e-6f;
  EnvironmentLight equirect = test_light(EnvironmentMapping::Equirectangular);
  EnvironmentLight pole_rows = test_light(EnvironmentMapping::EquirectangularPoleRows);
  EnvironmentLight octahedral = test_light(EnvironmentMapping::EqualAreaOctahedral);
  auto expect_close = [](const RGB& a, const RGB& b, const char* what, float t) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 2e-4f * (1 + a[c])) << what << " t = " << t;
  };
  for (float t : {0.05f, 0.2f, 0.33f, 0.47f, 0.6f, 0.9f}) {
    expect_close(equirect.lookup({eps, t}), equirect.lookup({1 - eps, t}), "seam", t);
    expect_close(pole_rows.lookup({eps, t}), pole_rows.lookup({1 - eps, t}), "seam (pole rows)", t);
    expect_close(octahedral.lookup({eps, t}), octahedral.lookup({eps, 1 - t}), "left edge", t);
    expect_close(octahedral.lookup({1 - eps, t}), octahedral.lookup({1 - eps, 1 - t}), "right edge", t);
    expect_close(octahedral.lookup({t, eps}), octahedral.lookup({1 - t, eps}), "top edge", t);
    expect_close(octahedral.lookup({t, 1 - eps}), octahedral.lookup({1 - t, 1 - eps}), "bottom edge", t);
  }
}

TEST(EnvironmentLight, SampledDirectionsFollowPdfLi) {
  for (EnvironmentMapping m : kAllMappings) {
    EnvironmentLight light = test_light(m);
    LightSampleContext ctx{{0.3f, -1, 2}, Normal3(0.0f)};
    auto sample = [&](Vec2 u) {
      LightSample s = light.sample_li(ctx, u);
      return s.pdf > 0 ? s.wi : Vec3(0.0f);
    };
    auto pdf = [&](const Vec3& w) { return light.pdf_li(ctx, w, {}, {}); };
    // The pdf is piecewise constant over the pixels: integrate it finely per bin.
    EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, 41, -1, 20, 40, 64),
              testing::kChiSquareAlpha)
        << name(m);
  }
}

TEST(EnvironmentLight, SamplesAreConsistentWithRadianceAndPdf) {
  for (EnvironmentMapping m : kAllMappings) {
    EnvironmentLight light = test_light(m);
    LightSampleContext ctx{{0, 0, 0}, Normal3(0, 1, 0)};
    Rng rng(2, 3);
    int valid = 0;
    for (int i = 0; i < 20000; ++i) {
      LightSample s = light.sample_li(ctx, {rng.next_float(), rng.next_float()});
      if (s.pdf == 0) continue;
      ++valid;
      ASSERT_NEAR(length(s.wi), 1, 1e-5f);
      ASSERT_TRUE(std::isinf(s.distance));
      ASSERT_FALSE(s.is_delta);
      ASSERT_NEAR(s.pdf, light.pdf_li(ctx, s.wi, s.p_light, s.n_light), 1e-3f * s.pdf) << name(m);
      RGB L = light.radiance(s.wi);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(s.radiance[c], L[c], 1e-3f * (1 + L[c])) << name(m);
    }
    EXPECT_GT(valid, 19990);
  }
}

// The integral of the map's radiance over the sphere by a midpoint rule in (cos theta, phi) of
// world directions, independent of either parameterisation.
RGB sphere_integral(const std::function<RGB(const Vec3&)>& radiance, int nz = 1200, int nphi = 2400) {
  double sum[3] = {0, 0, 0};
  for (int i = 0; i < nz; ++i) {
    double z = -1 + 2 * (i + 0.5) / nz, r = std::sqrt(std::max(0.0, 1 - z * z));
    for (int j = 0; j < nphi; ++j) {
      double phi = 2 * std::numbers::pi * (j + 0.5) / nphi;
      RGB L = radiance(Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
      for (int c = 0; c < 3; ++c) sum[c] += L[c];
    }
  }
  double cell = 4 * std::numbers::pi / (double(nz) * nphi);
  return RGB(float(sum[0] * cell), float(sum[1] * cell), float(sum[2] * cell));
}

TEST(EnvironmentLight, RadianceOverPdfEstimatesTheIntegralOfTheMap) {
  for (EnvironmentMapping m : kAllMappings) {
    EnvironmentLight light = test_light(m);
    RGB reference = sphere_integral([&](const Vec3& w) { return light.radiance(w); });
    LightSampleContext ctx{{1, 2, 3}, Normal3(0.0f)};
    Rng rng(12, 34);
    double sum[3] = {0, 0, 0}, sum_sq[3] = {0, 0, 0};
    const int n = kChiSquareSamples;
    for (int i = 0; i < n; ++i) {
      LightSample s = light.sample_li(ctx, {rng.next_float(), rng.next_float()});
      if (s.pdf == 0) continue;
      for (int c = 0; c < 3; ++c) {
        double v = s.radiance[c] / s.pdf;
        sum[c] += v;
        sum_sq[c] += v * v;
      }
    }
    for (int c = 0; c < 3; ++c) {
      double mean = sum[c] / n, se = std::sqrt(std::max(0.0, sum_sq[c] / n - mean * mean) / n);
      // 4 standard errors, plus a little for the quadrature.
      EXPECT_NEAR(mean, reference[c], 4 * se + 2e-4 * reference[c]) << name(m) << " channel " << c;
    }
    // power() is pi R^2 times the integrated luminance.
    EXPECT_NEAR(light.power(), kPi * 9 * reference.luminance(), 0.01 * light.power()) << name(m);
    EXPECT_NEAR(light.importance(ctx), reference.luminance() / 4, 0.01 * light.importance(ctx)) << name(m);
  }
}

TEST(EnvironmentLight, MisCompensationSamplesLuminanceAboveTheMeanAndStaysUnbiased) {
  // Mitsuba's mis_compensation: the density follows max(luminance - mean, 0); directions darker than
  // the mean keep only the small floor, and radiance / pdf still integrates the map.
  const EnvironmentMapping m = EnvironmentMapping::EquirectangularPoleRows;
  Image img = testing::environment_test_map(m);
  EnvironmentLight plain(img, m, RGB(1.0f), Transform(), 1), compensated(img, m, RGB(1.0f), Transform(), 1, true);
  const Vec3 bright = plain.uv_to_direction({(img.width / 2 + 4) / float(img.width), (img.height / 4 + 0.5f) / (img.height - 1)});
  const Vec3 dim = plain.uv_to_direction({0.1f, 0.8f});
  EXPECT_GT(compensated.pdf_li({}, bright, {}, {}), plain.pdf_li({}, bright, {}, {}));
  EXPECT_LT(compensated.pdf_li({}, dim, {}, {}), 0.1f * plain.pdf_li({}, dim, {}, {}));
  EXPECT_GT(compensated.pdf_li({}, dim, {}, {}), 0);
  RGB reference = sphere_integral([&](const Vec3& w) { return plain.radiance(w); }, 600, 1200);
  Rng rng(5, 6);
  double sum = 0, sum_sq = 0;
  const int n = kChiSquareSamples;
  for (int i = 0; i < n; ++i) {
    LightSample s = compensated.sample_li({}, {rng.next_float(), rng.next_float()});
    if (s.pdf == 0) continue;
    double v = s.radiance.g / s.pdf;
    sum += v;
    sum_sq += v * v;
  }
  double mean = sum / n, se = std::sqrt(std::max(0.0, sum_sq / n - mean * mean) / n);
  EXPECT_NEAR(mean, reference.g, 4 * se + 1e-3 * reference.g);
}

// pbrt-v4's lookups (filter "nearest"): the radiance anywhere in a texel is that texel's, and on an
// equal-area map the sampling density is exactly proportional to the luminance there (radiance
// luminance / pdf is the same for every sample but those of the floor under dim texels).
TEST(EnvironmentLight, NearestTexelLookupsAndExactlyProportionalSampling) {
  for (EnvironmentMapping m : {EnvironmentMapping::Equirectangular, EnvironmentMapping::EqualAreaOctahedral}) {
    const Image img = testing::environment_test_map(m);
    const EnvironmentLight light(img, m, RGB(1.5f, 1.0f, 0.5f), test_rotation(), 3.0f, false, true);
    for (auto [x, y] : {std::pair{3, 2}, std::pair{img.width / 2 + 3, img.height / 4}, std::pair{10, 7}}) {
      // Three points inside the texel, away from its centre.
      for (Vec2 offset : {Vec2(0.1f, 0.1f), Vec2(0.9f, 0.2f), Vec2(0.4f, 0.85f)}) {
        const Vec2 uv((float(x) + offset.x) / float(img.width), (float(y) + offset.y) / float(img.height));
        const RGB got = light.radiance(test_rotation().vector(light.uv_to_direction(uv)));
        const RGB expected = img.at(x, y) * RGB(1.5f, 1.0f, 0.5f);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5f * (1 + expected[c])) << name(m);
      }
    }
    // Equal-area cells have equal solid angles; a latitude-longitude cell's density follows sin(theta)
    // within it, so only the equal-area map is exactly proportional.
    if (m != EnvironmentMapping::EqualAreaOctahedral) continue;
    LightSampleContext ctx{{0, 0, 0}, Normal3(0.0f)};
    Rng rng(5, 6);
    float ratio = -1;
    for (int i = 0; i < 2000; ++i) {
      const LightSample s = light.sample_li(ctx, {rng.next_float(), rng.next_float()});
      if (s.pdf == 0 || s.radiance.luminance() < 1e-2f) continue;  // the floor under dim texels
      const float r = s.radiance.luminance() / s.pdf;
      if (ratio < 0) ratio = r;
      ASSERT_NEAR(r, ratio, 1e-3f * ratio) << name(m);
    }
  }
}

TEST(EnvironmentLight, ConstantMapIsSampledUniformly) {
  Image img(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) img.set(x, y, RGB(2.0f));
  EnvironmentLight light(img, EnvironmentMapping::EqualAreaOctahedral, RGB(1.0f), test_rotation(), 1);
  Rng rng(4, 4);
  for (int i = 0; i < 1000; ++i) {
    LightSample s = light.sample_li({}, {rng.next_float(), rng.next_float()});
    EXPECT_NEAR(s.pdf, kInv4Pi, 1e-5f);
    EXPECT_NEAR(s.radiance.g, 2.0f, 1e-5f);
  }
  EXPECT_NEAR(light.power(), kPi * 4 * kPi * 2.0f, 1e-3f);
}

TEST(EnvironmentLight, RejectsBadImages) {
  EXPECT_THROW(EnvironmentLight(Image(8, 4), EnvironmentMapping::EqualAreaOctahedral, RGB(1.0f), Transform(), 1),
               SceneError);
  EXPECT_THROW(EnvironmentLight(Image(), EnvironmentMapping::Equirectangular, RGB(1.0f), Transform(), 1), SceneError);
  EnvironmentMap desc;
  desc.filename = "/nonexistent/dir/sky-map.exr";
  try {
    make_environment_light(desc, 1);
    FAIL() << "no exception";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("sky-map.exr"), std::string::npos) << e.what();
  }
}

TEST(EnvironmentLight, ReadsItsImageFromAFile) {
  auto dir = std::filesystem::temp_directory_path() / ("candela-envmap-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  Image img = testing::environment_test_map(EnvironmentMapping::Equirectangular);
  write_image(dir / "map.exr", img);
  EnvironmentMap desc;
  desc.filename = (dir / "map.exr").string();
  desc.scale = RGB(2.0f);
  EnvironmentLight light = make_environment_light(desc, 1);
  Vec2 uv{(5 + 0.5f) / img.width, (3 + 0.5f) / img.height};
  RGB got = light.lookup(uv), expected = img.at(5, 3) * 2.0f;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1e-3f * (1 + expected[c]));
  // A non-square octahedral map is refused with the file's name.
  desc.mapping = EnvironmentMapping::EqualAreaOctahedral;
  try {
    make_environment_light(desc, 1);
    FAIL() << "no exception";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("map.exr"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace candela
