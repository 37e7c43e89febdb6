// The procedural textures (description/textures.h): Perlin noise's defining properties and the
// patterns built on it, each against what it must give at points where the answer is known.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "candela/textures/noise.h"
#include "candela/textures/texture.h"

namespace candela {
namespace {

RGB eval_one(const TextureDesc& desc, Point3 p, Vec2 uv = {0, 0}, Normal3 n = {0, 0, 0}) {
  const TextureSet set({desc});
  ColorInput in;
  in.texture = 0;
  return set.eval(in, TextureEvalContext{p, uv, {}, n});
}

void expect_grey(RGB c, float value, float tolerance = 1e-6f) {
  EXPECT_NEAR(c.r, value, tolerance);
  EXPECT_NEAR(c.g, value, tolerance);
  EXPECT_NEAR(c.b, value, tolerance);
}

TEST(PerlinNoise, IsZeroAtEveryLatticePoint) {
  for (int x = -3; x <= 3; ++x)
    for (int y = -3; y <= 3; ++y)
      for (int z : {-300, -1, 0, 7, 1000}) EXPECT_EQ(perlin_noise(Point3(float(x), float(y), float(z))), 0.0f);
}

TEST(PerlinNoise, IsBoundedContinuousAndHasMeanZero) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-50, 50);
  constexpr int kCount = 200000;
  double sum = 0, sum_squares = 0;
  for (int i = 0; i < kCount; ++i) {
    const Point3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    const float n = perlin_noise(p);
    // Gradient noise of unit-length-ish gradients stays within [-1, 1] (within rounding).
    ASSERT_LE(std::abs(n), 1.0001f) << p.x << " " << p.y << " " << p.z;
    // Lipschitz: its gradient is bounded, so a tiny step changes it a little.
    EXPECT_LE(std::abs(perlin_noise(p + Vec3(1e-3f, 0, 0)) - n), 1e-2f);
    sum += n;
    sum_squares += double(n) * n;
  }
  // The mean is zero: within five standard errors of the sample.
  const double mean = sum / kCount, deviation = std::sqrt(sum_squares / kCount - mean * mean);
  EXPECT_LT(std::abs(mean), 5 * deviation / std::sqrt(double(kCount)));
  EXPECT_GT(deviation, 0.1);  // and it is not flat
}

TEST(PerlinNoise, OctaveSumsStartFromNoise) {
  const Point3 p(0.3f, -1.7f, 2.2f);
  EXPECT_FLOAT_EQ(fbm(p, 0.5f, 1), perlin_noise(p));
  EXPECT_FLOAT_EQ(turbulence(p, 0.5f, 1), std::abs(perlin_noise(p)) + 0.2f * 0.5f);
  EXPECT_FLOAT_EQ(fbm(p, 0.5f, 2), perlin_noise(p) + 0.5f * perlin_noise(p * 1.99f));
  EXPECT_GE(turbulence(p, 0.7f, 6), 0.0f);
}

TEST(ProceduralTextures, BilerpGivesItsCornersAndBlendsBetween) {
  BilerpTexture bilerp{RGB(0.1f), RGB(0.2f), RGB(0.3f), RGB(0.9f), {}};
  expect_grey(eval_one(bilerp, {}, {0, 0}), 0.1f);
  expect_grey(eval_one(bilerp, {}, {0, 1}), 0.2f);
  expect_grey(eval_one(bilerp, {}, {1, 0}), 0.3f);
  expect_grey(eval_one(bilerp, {}, {1, 1}), 0.9f);
  expect_grey(eval_one(bilerp, {}, {0.5f, 0.5f}), (0.1f + 0.2f + 0.3f + 0.9f) / 4);
}

TEST(ProceduralTextures, SolidCheckerboardAlternatesOverUnitCubesInItsSpace) {
  SolidCheckerboardTexture board{ColorInput(RGB(1.0f)), ColorInput(RGB(0.0f)), Transform()};
  expect_grey(eval_one(board, {0.5f, 0.5f, 0.5f}), 1);
  expect_grey(eval_one(board, {1.5f, 0.5f, 0.5f}), 0);
  expect_grey(eval_one(board, {1.5f, 1.5f, 0.5f}), 1);
  expect_grey(eval_one(board, {-0.5f, 0.5f, 0.5f}), 0);  // floor(-0.5) = -1: odd
  expect_grey(eval_one(board, {-0.5f, -0.5f, -0.5f}), 0);
  // Its space scaled by 2 in the world: cubes of side 2.
  board.to_world = Transform::scale(Vec3(2.0f));
  expect_grey(eval_one(board, {1.5f, 0.5f, 0.5f}), 1);
  expect_grey(eval_one(board, {2.5f, 0.5f, 0.5f}), 0);
}

TEST(ProceduralTextures, NoiseTexturesReadTheirSpace) {
  const Point3 p(0.37f, 1.21f, -0.4f);
  expect_grey(eval_one(FbmTexture{6, 0.6f, Transform()}, p), fbm(p, 0.6f, 6));
  expect_grey(eval_one(WrinkledTexture{3, 0.5f, Transform()}, p), turbulence(p, 0.5f, 3));
  // A texture space scaled by 4 in the world sees the point at a quarter of its coordinates.
  expect_grey(eval_one(FbmTexture{8, 0.5f, Transform::scale(Vec3(4.0f))}, p), fbm(p * 0.25f, 0.5f, 8));
}

TEST(ProceduralTextures, MarbleFollowsItsSplineAlongTheBands) {
  // With no variation the band value is sin(scale y): at y = 0 the middle of the spline (its fourth
  // control colour, 0.5 grey, times 1.5), at sin = +-1 its ends (0.58, 0.58, 0.6 times 1.5).
  MarbleTexture marble;
  marble.variation = 0;
  expect_grey(eval_one(marble, {0.3f, 0, 0.7f}), 0.75f);
  const float quarter = std::numbers::pi_v<float> / 2;
  for (float y : {quarter, -quarter}) {
    const RGB end = eval_one(marble, {0, y, 0});
    EXPECT_NEAR(end.r, 0.87f, 1e-5f);
    EXPECT_NEAR(end.b, 0.9f, 1e-5f);
  }
  marble.scale = 2;
  const RGB scaled = eval_one(marble, {0, quarter / 2, 0}), unscaled = eval_one(MarbleTexture{.variation = 0}, {0, quarter, 0});
  EXPECT_NEAR(scaled.r, unscaled.r, 1e-5f);
  EXPECT_NEAR(scaled.b, unscaled.b, 1e-5f);
}

TEST(ProceduralTextures, DotsShowBothColoursAndOnlyThem) {
  DotsTexture dots{ColorInput(RGB(1.0f)), ColorInput(RGB(0.0f)), {}};
  int inside = 0, samples = 0;
  for (float s = -10; s < 10; s += 0.05f)
    for (float t = -10; t < 10; t += 0.05f) {
      const float v = eval_one(dots, {}, {s, t}).r;
      ASSERT_TRUE(v == 0 || v == 1);
      inside += v == 1;
      ++samples;
    }
  // About half the cells hold a dot covering pi 0.35^2 = 0.385 of it: 19% of the plane, loosely.
  EXPECT_GT(inside, samples / 10);
  EXPECT_LT(inside, samples * 3 / 10);
  // The cell around an integer point where the noise is not positive holds none.
  EXPECT_EQ(eval_one(dots, {}, {0, 0}).r, perlin_noise({0.5f, 0.5f, 0.5f}) > 0 ? 1.0f : 0.0f);
}

TEST(ProceduralTextures, DirectionMixWeighsByTheNormalsAlignment) {
  DirectionMixTexture mix{ColorInput(RGB(1.0f)), ColorInput(RGB(0.0f)), Vec3(0, 1, 0)};
  expect_grey(eval_one(mix, {}, {}, Normal3(0, 1, 0)), 1);
  expect_grey(eval_one(mix, {}, {}, Normal3(0, -1, 0)), 1);  // either side
  expect_grey(eval_one(mix, {}, {}, Normal3(1, 0, 0)), 0);
  expect_grey(eval_one(mix, {}, {}, normalize(Normal3(1, 1, 0))), std::sqrt(0.5f));
}

// A checkerboard of tex1 = 1 and tex2 = 0 seen through `mapping`: which square (s, t) falls in.
float board_at(UVMapping mapping, Point3 p) {
  return eval_one(CheckerboardTexture{ColorInput(RGB(1.0f)), ColorInput(RGB(0.0f)), mapping}, p, {0.3f, 0.3f}).r;
}

TEST(TextureProjections, SphericalCylindricalAndPlanarReadThePoint) {
  // Spherical: (theta / pi, phi / 2 pi); scaled by 4 so that the squares tell the angles apart.
  UVMapping spherical{.su = 4, .sv = 4, .projection = TextureProjection::Spherical};
  EXPECT_EQ(board_at(spherical, {0, 0, 1}), 1);       // theta 0, phi 0: square (0, 0)
  EXPECT_EQ(board_at(spherical, {1, 0.01f, 0}), 1);    // theta pi/2, phi ~0: (2.0, 0.006), square (2, 0)
  EXPECT_EQ(board_at(spherical, {-1, 0.01f, 0}), 0);   // theta pi/2, phi ~pi: (2.0, 1.99), square (2, 1)
  EXPECT_EQ(board_at(spherical, {0.3f, 0, -1}), 0);    // theta 2.85, phi 0: (3.63, 0), square (3, 0)
  // Cylindrical: ((pi + atan2(y, x)) / 2 pi, z).
  UVMapping cylindrical{.projection = TextureProjection::Cylindrical};
  EXPECT_EQ(board_at(cylindrical, {1, 0.01f, 0.5f}), 1);   // (0.5, 0.5): square (0, 0)
  EXPECT_EQ(board_at(cylindrical, {1, 0.01f, 1.5f}), 0);   // t = 1.5: square (0, 1)
  // Planar: (p . s, p . t) + offsets, in the projection's space.
  UVMapping planar{.du = 0.5f, .projection = TextureProjection::Planar};
  EXPECT_EQ(board_at(planar, {0.2f, 0.2f, 9}), 1);   // (0.7, 0.2)
  EXPECT_EQ(board_at(planar, {0.7f, 0.2f, 9}), 0);   // (1.2, 0.2)
  planar.to_world = Transform::translate(Vec3(1, 0, 0));
  EXPECT_EQ(board_at(planar, {1.2f, 0.2f, 9}), 1);   // the point at (0.2, 0.2) in the projection's space
}

}  // namespace
}  // namespace candela
