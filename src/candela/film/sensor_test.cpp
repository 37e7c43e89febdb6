#include "candela/film/sensor.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "candela/spectral/cie.h"

namespace candela {
namespace {

cie::Xyz xyz_of_rgb(const RGB& c) { return cie::linear_srgb_to_xyz(c.r, c.g, c.b); }

TEST(FilmSensor, TheDefaultSensorPassesSamplesUnchanged) {
  const FilmSensor sensor{FilmDesc::Sensor{}};
  EXPECT_TRUE(sensor.changes_nothing());
  const RGB L(0.3f, 7.5f, 1e-6f);
  const RGB out = sensor.respond(L);
  EXPECT_EQ(out.r, L.r);
  EXPECT_EQ(out.g, L.g);
  EXPECT_EQ(out.b, L.b);
}

TEST(FilmSensor, ExposureScalesEverySample) {
  FilmDesc::Sensor desc;
  desc.exposure = 4;
  const FilmSensor sensor(desc);
  const RGB L(0.2f, 0.5f, 0.9f);
  const RGB out = sensor.respond(L);
  EXPECT_NEAR(out.r, 0.8f, 1e-5f);
  EXPECT_NEAR(out.g, 2.0f, 1e-5f);
  EXPECT_NEAR(out.b, 3.6f, 1e-5f);
}

// The daylight locus at D65's temperature (6500 K on the old radiation constant) is D65's white, and
// below 4000 K a blackbody's chromaticity is used (Illuminant A: 2856 K at x 0.4476, y 0.4074).
TEST(FilmSensor, DaylightChromaticities) {
  const Chromaticity d65 = daylight_chromaticity(6500);
  EXPECT_NEAR(d65.x, 0.3127, 3e-4);
  EXPECT_NEAR(d65.y, 0.3290, 3e-4);
  const Chromaticity d50 = daylight_chromaticity(5000);
  EXPECT_NEAR(d50.x, 0.3457, 3e-4);
  EXPECT_NEAR(d50.y, 0.3585, 3e-4);
  const Chromaticity a = daylight_chromaticity(2856 * 1.4380 / 1.4388);
  EXPECT_NEAR(a.x, 0.4476, 5e-4);
  EXPECT_NEAR(a.y, 0.4074, 5e-4);
}

// Von Kries adaptation takes the source white to the target white and keeps luminance of the white.
TEST(FilmSensor, WhiteBalanceMatrixMapsWhiteToWhite) {
  const Chromaticity from{0.4476, 0.4074}, to{0.3127, 0.3290};
  const std::array<double, 9> m = white_balance_matrix(from, to);
  const double x = from.x / from.y, y = 1, z = (1 - from.x - from.y) / from.y;
  const double X = m[0] * x + m[1] * y + m[2] * z, Y = m[3] * x + m[4] * y + m[5] * z,
               Z = m[6] * x + m[7] * y + m[8] * z;
  EXPECT_NEAR(X / (X + Y + Z), to.x, 1e-6);
  EXPECT_NEAR(Y / (X + Y + Z), to.y, 1e-6);
  EXPECT_NEAR(Y, 1, 2e-3);  // Bradford's Y row is not exactly (0 1 0): near, not equal
}

// Balanced to 4500 K, daylight of that temperature comes out grey, and D65 light comes out blue.
TEST(FilmSensor, WhiteBalancedSensorNeutralisesItsIlluminant) {
  FilmDesc::Sensor desc;
  desc.white_balance = 4500;
  const FilmSensor sensor(desc);
  const Chromaticity w = daylight_chromaticity(4500);
  const RGB warm = cie::xyz_to_linear_srgb(w.x / w.y, 1, (1 - w.x - w.y) / w.y);
  ASSERT_GT(warm.r, 1.1f * warm.b);  // the light really is warm
  const RGB out = sensor.respond(warm);
  EXPECT_NEAR(out.r / out.g, 1, 2e-3);
  EXPECT_NEAR(out.b / out.g, 1, 2e-3);
  const RGB white = sensor.respond(RGB(1.0f));
  EXPECT_GT(white.b, 1.1f * white.r);
}

// maxcomponentvalue: a sample whose largest XYZ component (times the exposure) is over the limit is
// scaled down to it, keeping its colour; one under it is untouched.
TEST(FilmSensor, LimitScalesBrightSamplesDownInSensorSpace) {
  FilmDesc::Sensor desc;
  desc.exposure = 2;
  desc.max_component = 3;
  const FilmSensor sensor(desc);
  const RGB dim(0.5f, 0.4f, 0.3f);
  const RGB dim_out = sensor.respond(dim);
  EXPECT_NEAR(dim_out.r, 1.0f, 1e-5f);
  EXPECT_NEAR(dim_out.g, 0.8f, 1e-5f);
  EXPECT_NEAR(dim_out.b, 0.6f, 1e-5f);
  const RGB bright(10.0f, 2.0f, 40.0f);
  const RGB out = sensor.respond(bright);
  const cie::Xyz s = xyz_of_rgb(out);
  EXPECT_NEAR(std::max({s.x, s.y, s.z}), 3.0, 1e-4);
  EXPECT_NEAR(out.r / out.b, bright.r / bright.b, 1e-5f);
  EXPECT_NEAR(out.g / out.b, bright.g / bright.b, 1e-5f);
}

}  // namespace
}  // namespace candela
