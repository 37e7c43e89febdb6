// The media building blocks: Henyey-Greenstein sampling against its density (chi-square), grid
// lookups (voxel-centred samples, the two border rules), the majorant grid bounding the density
// along rays, pbrt-v4's procedural cloud (its density against pbrt-v4's definition, its bound), and
// the checks that refuse media that cannot be rendered.
#include "candela/media/medium.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

#include "candela/sampling/rng.h"
#include "candela/textures/noise.h"
#include "candela/testing/bsdf_chi_square.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

TEST(HenyeyGreenstein, IntegratesToOneAndSamplesItsDensity) {
  for (float g : {0.0f, 0.3f, -0.6f, 0.9f}) {
    HenyeyGreenstein hg{g};
    const Vec3 wo = normalize(Vec3(0.3f, -0.5f, 0.8f));
    // The density integrates to 1 over the sphere (midpoint rule in cos theta about -wo).
    Frame frame(-wo);
    double integral = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      float c = -1 + 2 * (float(i) + 0.5f) / float(n);
      Vec3 wi = frame.to_world({std::sqrt(1 - c * c), 0, c});
      integral += double(hg.p(wo, wi)) * 2 * 3.14159265358979 * 2 / n;
    }
    EXPECT_NEAR(integral, 1.0, 1e-3) << "g = " << g;
    // Forward scattering for g > 0: wi near -wo is likelier.
    if (g > 0) EXPECT_GT(hg.p(wo, -wo), hg.p(wo, wo));
    // sample() draws from p, and reports p as its pdf.
    testing::Binning binning;
    binning.axis = -wo;
    binning.zoom = g > 0.5f ? 4.0f : 1.0f;
    double p = testing::zoomed_chi_square([&](Vec2 u) { return hg.sample(wo, u).wi; },
                                          [&](const Vec3& wi) { return hg.pdf(wo, wi); }, binning);
    EXPECT_GT(p, testing::kChiSquareAlpha) << "g = " << g;
    Rng rng(3, 4);
    for (int i = 0; i < 100; ++i) {
      PhaseSample s = hg.sample(wo, {rng.next_float(), rng.next_float()});
      EXPECT_NEAR(s.pdf, hg.p(wo, s.wi), 1e-4f * s.pdf);
      EXPECT_NEAR(length(s.wi), 1.0f, 1e-5f);
    }
  }
}

// A 2 x 1 x 1 grid over [0,1]^3: samples at x = 1/4 and 3/4.
VolumeDesc two_sample_grid(VolumeBorder border) {
  VolumeDesc v;
  v.resolution = {2, 1, 1};
  v.values = std::make_shared<const std::vector<float>>(std::vector<float>{2.0f, 4.0f});
  v.border = border;
  return v;
}

TEST(Volume, SamplesSitAtVoxelCentresAndTheBorderClampsOrFades) {
  Volume clamp(two_sample_grid(VolumeBorder::Clamp)), zero(two_sample_grid(VolumeBorder::Zero));
  EXPECT_FLOAT_EQ(clamp.scalar_at({0.25f, 0.5f, 0.5f}), 2.0f);
  EXPECT_FLOAT_EQ(clamp.scalar_at({0.75f, 0.5f, 0.5f}), 4.0f);
  EXPECT_FLOAT_EQ(clamp.scalar_at({0.5f, 0.5f, 0.5f}), 3.0f);
  // Between the outermost centre and the face: Mitsuba clamps, pbrt-v4 fades to zero.
  EXPECT_FLOAT_EQ(clamp.scalar_at({0.0f, 0.5f, 0.5f}), 2.0f);
  EXPECT_FLOAT_EQ(clamp.scalar_at({1.0f, 0.5f, 0.5f}), 4.0f);
  EXPECT_FLOAT_EQ(zero.scalar_at({0.0f, 0.5f, 0.5f}), 1.0f);  // halfway between sample 0 (2) and 0
  EXPECT_FLOAT_EQ(zero.scalar_at({1.0f, 0.5f, 0.5f}), 2.0f);
  // y and z have one sample: clamped, or faded towards the faces.
  EXPECT_FLOAT_EQ(clamp.scalar_at({0.25f, 0.0f, 1.0f}), 2.0f);
  EXPECT_FLOAT_EQ(zero.scalar_at({0.25f, 0.5f, 0.0f}), 1.0f);
}

TEST(Medium, HasNoDensityOutsideItsGridAndTheMajorantBoundsItAlongRays) {
  MediumDesc desc;
  desc.sigma_t = {1, 2, 3};
  desc.scale = 2;
  desc.density.resolution = {20, 12, 9};
  std::vector<float> values(20 * 12 * 9);
  Rng rng(7, 9);
  // Sparse: mostly empty, a few dense voxels.
  for (float& v : values) v = rng.next_float() < 0.1f ? 10 * rng.next_float() : 0.0f;
  desc.density.values = std::make_shared<const std::vector<float>>(values);
  desc.density.to_world = Transform::translate({-1, -2, 0.5f}) * Transform::rotate(30, {1, 1, 0}) *
                          Transform::scale({2, 3, 1.5f});
  ASSERT_EQ(medium_problem(desc), "");
  const Medium m(desc);
  EXPECT_EQ(m.sigma_t(), RGB(2, 4, 6));
  EXPECT_EQ(m.density(desc.density.to_world.point({1.2f, 0.5f, 0.5f})), 0.0f);
  EXPECT_EQ(m.density(desc.density.to_world.point({0.5f, -0.01f, 0.5f})), 0.0f);
  EXPECT_GT(m.majorant_resolution()[0], 1);
  // Along random rays, every point's density is within the majorant of the piece holding it, the
  // pieces are in order and do not overlap, and the density is zero outside them.
  int checked = 0, inside = 0;
  for (int r = 0; r < 200; ++r) {
    Point3 o = desc.density.to_world.point({2 * rng.next_float() - 0.5f, 2 * rng.next_float() - 0.5f,
                                            2 * rng.next_float() - 0.5f});
    Vec3 d(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
    Ray ray{o, d};
    std::vector<std::array<float, 3>> pieces;
    m.for_each_majorant(ray, 0, 20, [&](float t0, float t1, float bound) {
      pieces.push_back({t0, t1, bound});
      return true;
    });
    for (size_t i = 1; i < pieces.size(); ++i) EXPECT_GE(pieces[i][0], pieces[i - 1][1] - 1e-4f);
    for (int k = 0; k < 400; ++k) {
      float t = 20 * (float(k) + 0.5f) / 400;
      float density = m.density(ray.at(t));
      float bound = 0;
      for (const auto& p : pieces)
        if (t >= p[0] && t <= p[1]) bound = std::max(bound, p[2]);
      ++checked;
      if (density > 0) ++inside;
      EXPECT_LE(density, bound * (1 + 1e-5f) + 1e-6f) << "ray " << r << ", t " << t;
    }
  }
  EXPECT_GT(inside, checked / 200);  // the rays did pass through the (sparse) medium
}

TEST(Medium, ProblemsAreNamed) {
  auto problem = [](auto edit) {
    MediumDesc m;
    edit(m);
    return medium_problem(m);
  };
  EXPECT_EQ(problem([](MediumDesc&) {}), "");
  EXPECT_NE(problem([](MediumDesc& m) { m.sigma_t = {1, -1, 1}; }).find("sigma_t"), std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) { m.scale = std::nanf(""); }).find("scale"), std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) { m.g = 1; }).find("g = 1 must be within (-1, 1)"), std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) { m.albedo.constant = {0.5f, 1.2f, 0}; }).find("albedo"), std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) { m.emission = {0, -1, 0}; }).find("emission"), std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) {
              m.density.resolution = {2, 2, 2};
              m.density.values = std::make_shared<const std::vector<float>>(7, 1.0f);
              m.density.filename = "smoke.vol";
            }).find("density grid \"smoke.vol\" has 7 values; 2 x 2 x 2 x 1 channel(s) needs 8"),
            std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) {
              m.density.resolution = {1, 1, 1};
              m.density.values = std::make_shared<const std::vector<float>>(1, -1.0f);
            }).find("value -1"),
            std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) {
              m.density.resolution = {1, 1, 1};
              m.density.channels = 3;
              m.density.values = std::make_shared<const std::vector<float>>(3, 1.0f);
            }).find("has 3 channels; it must have 1"),
            std::string::npos);
}

// ---------------------------------------------------------------- pbrt-v4's procedural cloud

// pbrt-v4's CloudMedium::Density written out as pbrt-v4 states it (pbrt's Noise is perlin_noise, DNoise
// the forward differences over 0.01 divided by 0.01), independently of cloud_density's use of fbm.
float pbrt_v4_cloud_density_as_written(float density, float wispiness, float frequency, Point3 p) {
  Point3 pp(frequency * p.x, frequency * p.y, frequency * p.z);
  if (wispiness > 0) {
    float vomega = 0.05f * wispiness, vlambda = 10;
    for (int i = 0; i < 2; ++i) {
      const Point3 at(vlambda * pp.x, vlambda * pp.y, vlambda * pp.z);
      const float n = perlin_noise(at);
      const float dx = (perlin_noise({at.x + 0.01f, at.y, at.z}) - n) / 0.01f;
      const float dy = (perlin_noise({at.x, at.y + 0.01f, at.z}) - n) / 0.01f;
      const float dz = (perlin_noise({at.x, at.y, at.z + 0.01f}) - n) / 0.01f;
      pp = Point3(pp.x + vomega * dx, pp.y + vomega * dy, pp.z + vomega * dz);
      vomega *= 0.5f;
      vlambda *= 1.99f;
    }
  }
  float d = 0, omega = 0.5f, lambda = 1;
  for (int i = 0; i < 5; ++i) {
    d += omega * perlin_noise({lambda * pp.x, lambda * pp.y, lambda * pp.z});
    omega *= 0.5f;
    lambda *= 1.99f;
  }
  d = std::clamp((1 - p.y) * 4.5f * density * d, 0.0f, 1.0f);
  d += 2 * std::max(0.0f, 0.5f - p.y);
  return std::clamp(d, 0.0f, 1.0f);
}

TEST(CloudDensity, IsPbrtV4sDefinition) {
  Rng rng(3, 5);
  int partial = 0;  // points strictly between empty and full: where the noise decides
  for (int i = 0; i < 500; ++i) {
    CloudDensity c;
    c.density = 4 * rng.next_float() - 1;
    c.wispiness = i % 3 == 0 ? 0.0f : 2 * rng.next_float();
    c.frequency = 1 + 8 * rng.next_float();
    const Point3 p(4 * rng.next_float() - 2, 2.5f * rng.next_float() - 0.5f, 4 * rng.next_float() - 2);
    const float expected = pbrt_v4_cloud_density_as_written(c.density, c.wispiness, c.frequency, p);
    const float got = cloud_density(c, p);
    // The displacement divides by 0.01 where Vec3 multiplies by its reciprocal: rounding only.
    EXPECT_NEAR(got, expected, 1e-4f) << "point " << i;
    EXPECT_GE(got, 0.0f);
    EXPECT_LE(got, 1.0f);
    partial += got > 0 && got < 1;
  }
  EXPECT_GT(partial, 100);

  // The altitude falloff's fixed points: full at and below p.y = 0, half at p.y = 0.25 where the noise
  // adds nothing (density 0), none at p.y = 1 whatever the noise.
  CloudDensity c;
  EXPECT_EQ(cloud_density(c, {0.3f, 0, 0.7f}), 1.0f);
  EXPECT_EQ(cloud_density(c, {0.3f, -2, 0.7f}), 1.0f);
  EXPECT_EQ(cloud_density(c, {0.3f, 1, 0.7f}), 0.0f);
  c.density = 0;
  EXPECT_EQ(cloud_density(c, {0.3f, 0.25f, 0.7f}), 0.5f);
  EXPECT_EQ(cloud_density(c, {0.3f, 0.75f, 0.7f}), 0.0f);
}

TEST(CloudDensity, ThinsWithAltitudeAndReappearsAboveOneWhereTheNoiseIsNegative) {
  CloudDensity c;
  c.density = 2;
  Rng rng(11, 13);
  auto mean_at = [&](float y) {
    double sum = 0;
    for (int i = 0; i < 2000; ++i) sum += cloud_density(c, {4 * rng.next_float(), y, 4 * rng.next_float()});
    return sum / 2000;
  };
  const double low = mean_at(0.55f), middle = mean_at(0.8f), high = mean_at(0.95f), above = mean_at(1.5f);
  EXPECT_GT(low, middle + 0.05);
  EXPECT_GT(middle, high + 0.02);
  // (1 - p.y) turns negative above 1: pbrt-v4's cloud has density there where the noise is negative,
  // which a bound has to allow for.
  EXPECT_GT(above, 0.05);
}

TEST(CloudDensity, BoundHoldsOverEverySlabOfAltitude) {
  Rng rng(17, 19);
  int tight = 0;
  for (int cell = 0; cell < 400; ++cell) {
    CloudDensity c;
    c.density = cell % 4 == 0 ? 0.05f * rng.next_float() : 6 * rng.next_float() - 2;
    c.wispiness = 2 * rng.next_float();
    c.frequency = 1 + 6 * rng.next_float();
    // Random slabs, some thin ones around p.y = 1 where the bound is below 1.
    const float y_lo = cell % 2 == 0 ? 0.9f + 0.1f * rng.next_float() : 3 * rng.next_float() - 1;
    const float y_hi = y_lo + (cell % 2 == 0 ? 0.05f : 0.5f) * rng.next_float();
    const float bound = cloud_density_bound(c, y_lo, y_hi);
    EXPECT_LE(bound, 1.0f);
    tight += bound < 0.5f;
    for (int k = 0; k < 200; ++k) {
      const Point3 p(8 * rng.next_float() - 4, y_lo + (y_hi - y_lo) * rng.next_float(), 8 * rng.next_float() - 4);
      ASSERT_LE(cloud_density(c, p), bound) << "cell " << cell << ", y in [" << y_lo << ", " << y_hi << "]";
    }
  }
  EXPECT_GT(tight, 40);  // the bound is not merely pbrt-v4's 1
}

// A cloud placed in the world: nothing outside its box, the cloud's density at the point of the cloud's
// space inside it, and the majorant (altitude slabs) above the density along random rays.
TEST(Medium, CloudFillsItsBoxAndItsMajorantBoundsItAlongRays) {
  MediumDesc desc;
  desc.sigma_t = RGB(1.1f);
  CloudDensity cloud;
  cloud.density = 0.3f;  // thin enough that the slabs near p.y = 1 bound it below 1
  cloud.box_min = {-0.8f, 0, -0.8f};
  cloud.box_max = {0.8f, 1.6f, 0.8f};
  const Transform placement = Transform::translate({0.5f, 0.8f, -1}) * Transform::rotate(20, {0, 0, 1});
  desc.density.cloud = cloud;
  desc.density.to_world = placement * cloud.unit_cube_to_cloud();
  ASSERT_EQ(medium_problem(desc), "");
  const Medium m(desc);
  EXPECT_FALSE(m.has_constant_density());
  EXPECT_EQ(m.majorant_resolution(), (std::array<int, 3>{1, 32, 1}));
  EXPECT_EQ(m.density(placement.point({0.9f, 0.5f, 0})), 0.0f);  // beyond the box in x
  EXPECT_EQ(m.density(placement.point({0, -0.1f, 0})), 0.0f);    // below it (where the cloud would be full)
  EXPECT_GE(m.density(placement.point({0, 0.01f, 0})), 0.97f);    // just inside: nearly full
  Rng rng(23, 29);
  for (int i = 0; i < 50; ++i) {
    const Point3 p(1.6f * rng.next_float() - 0.8f, 1.6f * rng.next_float(), 1.6f * rng.next_float() - 0.8f);
    EXPECT_NEAR(m.density(placement.point(p)), cloud_density(cloud, p), 1e-4f);
  }
  int checked = 0, inside = 0, below_one = 0;
  for (int r = 0; r < 200; ++r) {
    const Point3 o = placement.point({3 * rng.next_float() - 1.5f, 3 * rng.next_float() - 0.7f,
                                      3 * rng.next_float() - 1.5f});
    const Ray ray{o, Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f)};
    std::vector<std::array<float, 3>> pieces;
    m.for_each_majorant(ray, 0, 10, [&](float t0, float t1, float bound) {
      pieces.push_back({t0, t1, bound});
      below_one += bound < 1;
      return true;
    });
    for (int k = 0; k < 400; ++k) {
      const float t = 10 * (float(k) + 0.5f) / 400;
      const float density = m.density(ray.at(t));
      float bound = 0;
      for (const auto& piece : pieces)
        if (t >= piece[0] && t <= piece[1]) bound = std::max(bound, piece[2]);
      ++checked;
      inside += density > 0;
      EXPECT_LE(density, bound) << "ray " << r << ", t " << t;
    }
  }
  EXPECT_GT(inside, checked / 50);  // the rays did pass through the cloud
  EXPECT_GT(below_one, 0);
  // majorant_cell_samples 0: one bound, as pbrt-v4 has; so too where every slab's bound is 1.
  desc.majorant_cell_samples = 0;
  EXPECT_EQ(Medium(desc).majorant_resolution(), (std::array<int, 3>{1, 1, 1}));
  desc.majorant_cell_samples = 4;
  desc.density.cloud->density = 3;
  EXPECT_EQ(Medium(desc).majorant_resolution(), (std::array<int, 3>{1, 1, 1}));
}

TEST(Medium, CloudProblemsAreNamed) {
  auto problem = [](auto edit) {
    MediumDesc m;
    m.density.cloud = CloudDensity{};
    edit(m);
    return medium_problem(m);
  };
  EXPECT_EQ(problem([](MediumDesc&) {}), "");
  EXPECT_NE(problem([](MediumDesc& m) { m.density.cloud->frequency = std::numeric_limits<float>::infinity(); })
                .find("the cloud's frequency inf must be finite"),
            std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) { m.density.cloud->box_max.y = 0; }).find("must be finite and have volume"),
            std::string::npos);
  EXPECT_NE(problem([](MediumDesc& m) { m.albedo.cloud = CloudDensity{}; })
                .find("albedo is a procedural cloud; only a density may be one"),
            std::string::npos);
}

}  // namespace
}  // namespace candela
