// The media building blocks: Henyey-Greenstein sampling against its density (chi-square), grid
// lookups (voxel-centred samples, the two border rules), the majorant grid bounding the density
// along rays, and the checks that refuse media that cannot be rendered.
#include "candela/media/medium.h"

#include <gtest/gtest.h>

#include "candela/sampling/rng.h"
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

}  // namespace
}  // namespace candela
