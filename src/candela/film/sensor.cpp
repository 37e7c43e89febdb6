#include "candela/film/sensor.h"

#include <algorithm>
#include <cmath>

#include "candela/spectral/blackbody.h"
#include "candela/spectral/cie.h"

namespace candela {
namespace {

using Matrix3 = std::array<double, 9>;

Matrix3 multiply(const Matrix3& a, const Matrix3& b) {
  Matrix3 m{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) m[size_t(3 * r + c)] += a[size_t(3 * r + k)] * b[size_t(3 * k + c)];
  return m;
}

std::array<double, 3> multiply_vector(const Matrix3& m, const std::array<double, 3>& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

// Bradford's cone responses from CIE XYZ, and back (the published pair).
constexpr Matrix3 kLmsFromXyz = {0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296};
constexpr Matrix3 kXyzFromLms = {0.9869929, -0.1470543, 0.1599627, 0.4323053, 0.5183603,
                                 0.0492912, -0.0085287, 0.0400428, 0.9684867};

// XYZ (Y = 1) of chromaticity c.
std::array<double, 3> white_xyz(Chromaticity c) { return {c.x / c.y, 1.0, (1 - c.x - c.y) / c.y}; }

// sRGB's white, D65, as its standard gives it.
constexpr Chromaticity kSrgbWhite{0.3127, 0.3290};

Matrix3 xyz_from_linear_srgb() {
  Matrix3 m{};
  for (int c = 0; c < 3; ++c) {
    const cie::Xyz column = cie::linear_srgb_to_xyz(c == 0, c == 1, c == 2);
    m[size_t(c)] = column.x;
    m[size_t(3 + c)] = column.y;
    m[size_t(6 + c)] = column.z;
  }
  return m;
}

Matrix3 linear_srgb_from_xyz() {
  Matrix3 m{};
  for (int c = 0; c < 3; ++c) {
    const RGB column = cie::xyz_to_linear_srgb(c == 0, c == 1, c == 2);
    m[size_t(c)] = column.r;
    m[size_t(3 + c)] = column.g;
    m[size_t(6 + c)] = column.b;
  }
  return m;
}

std::array<float, 9> to_float(const Matrix3& m) {
  std::array<float, 9> f;
  for (size_t i = 0; i < 9; ++i) f[i] = float(m[i]);
  return f;
}

}  // namespace

Chromaticity daylight_chromaticity(double kelvin) {
  const double cct = kelvin * 1.4388 / 1.4380;
  if (cct < 4000) {
    // A blackbody's chromaticity: its spectrum integrated against the matching functions.
    double x = 0, y = 0, z = 0;
    for (double lambda = cie::kLambdaMin; lambda <= cie::kLambdaMax; lambda += 1) {
      const double b = planck(lambda, cct, kPbrtPlanck);
      const cie::Xyz m = cie::matching(lambda);
      x += b * m.x;
      y += b * m.y;
      z += b * m.z;
    }
    return {x / (x + y + z), y / (x + y + z)};
  }
  // The CIE daylight locus: x from the temperature (two ranges), y from x.
  const double t = cct, t2 = t * t, t3 = t2 * t;
  const double x = t <= 7000 ? -4.6070e9 / t3 + 2.9678e6 / t2 + 0.09911e3 / t + 0.244063
                             : -2.0064e9 / t3 + 1.9018e6 / t2 + 0.24748e3 / t + 0.237040;
  return {x, -3.0 * x * x + 2.870 * x - 0.275};
}

std::array<double, 9> white_balance_matrix(Chromaticity from, Chromaticity to) {
  const std::array<double, 3> lms_from = multiply_vector(kLmsFromXyz, white_xyz(from));
  const std::array<double, 3> lms_to = multiply_vector(kLmsFromXyz, white_xyz(to));
  const Matrix3 scale = {lms_to[0] / lms_from[0], 0, 0, 0, lms_to[1] / lms_from[1], 0, 0, 0, lms_to[2] / lms_from[2]};
  return multiply(kXyzFromLms, multiply(scale, kLmsFromXyz));
}

FilmSensor::FilmSensor(const FilmDesc::Sensor& desc) : changes_nothing_(desc.changes_nothing()) {
  max_component_ = desc.max_component;
  const Matrix3 to_xyz = xyz_from_linear_srgb();
  Matrix3 sensor_from_rgb = to_xyz;
  for (double& v : sensor_from_rgb) v *= desc.exposure;
  sensor_from_rgb_ = to_float(sensor_from_rgb);
  const Matrix3 balance = desc.white_balance > 0
                              ? white_balance_matrix(daylight_chromaticity(desc.white_balance), kSrgbWhite)
                              : Matrix3{1, 0, 0, 0, 1, 0, 0, 0, 1};
  rgb_from_sensor_ = to_float(multiply(linear_srgb_from_xyz(), balance));
}

RGB FilmSensor::respond_slow(const RGB& L) const {
  const auto& s = sensor_from_rgb_;
  float x = s[0] * L.r + s[1] * L.g + s[2] * L.b;
  float y = s[3] * L.r + s[4] * L.g + s[5] * L.b;
  float z = s[6] * L.r + s[7] * L.g + s[8] * L.b;
  // Possibly scale the response down to the sensor's limit (pbrt-v4's maxcomponentvalue).
  if (max_component_ > 0) {
    const float m = std::max({x, y, z});
    if (m > max_component_) {
      const float k = max_component_ / m;
      x *= k;
      y *= k;
      z *= k;
    }
  }
  const auto& o = rgb_from_sensor_;
  return RGB(o[0] * x + o[1] * y + o[2] * z, o[3] * x + o[4] * y + o[5] * z, o[6] * x + o[7] * y + o[8] * z);
}

}  // namespace candela
