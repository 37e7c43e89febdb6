// The four-lane colour type: an RGB render's fourth lane mirrors green through every operation,
// so reductions over four lanes answer as over three; map reaches every lane.
#include <gtest/gtest.h>

#include <cmath>

#include "candela/math/color.h"

namespace candela {
namespace {

TEST(RGB, AColourOfThreeChannelsCarriesGreenInItsFourthLane) {
  RGB a(0.2f, 0.7f, 0.1f), b(3.0f, 0.5f, 2.0f);
  EXPECT_EQ(a.w, a.g);
  EXPECT_EQ(RGB(0.4f).w, 0.4f);
  for (RGB c : {a + b, a - b, a * b, a * 2.0f, 2.0f * a, a / 4.0f, a.map([](float v) { return std::exp(-v); })})
    EXPECT_EQ(c.w, c.g);
  RGB c = a;
  c += b;
  c *= b;
  c *= 0.5f;
  EXPECT_EQ(c.w, c.g);
  // So the reductions over four lanes are those of the three channels.
  EXPECT_EQ(RGB(0.1f, 0.9f, 0.3f).max_component(), 0.9f);
  EXPECT_EQ(RGB(0.5f, 0.2f, 0.3f).min_component(), 0.2f);
  EXPECT_TRUE(RGB(0, 0, 0).is_black());
  EXPECT_FLOAT_EQ(RGB(0.3f, 0.6f, 0.9f).lane_average(3), 0.6f);
}

TEST(RGB, EveryLaneCountsWhenTheyHoldFourWavelengths) {
  RGB v(0, 0, 0, 2.0f);
  EXPECT_FALSE(v.is_black());
  EXPECT_EQ(v.max_component(), 2.0f);
  EXPECT_EQ(RGB(1, 1, 1, -1).min_component(), -1.0f);
  EXPECT_FLOAT_EQ(RGB(1, 2, 3, 6).lane_average(4), 3.0f);
  EXPECT_EQ(v[3], 2.0f);
  EXPECT_EQ(v.map([](float x) { return x + 1; }), RGB(1, 1, 1, 3));
  EXPECT_FALSE(RGB(0, 0, 0, NAN).is_finite());
}

}  // namespace
}  // namespace candela
