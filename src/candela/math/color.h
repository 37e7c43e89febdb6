#pragma once
// Radiometric quantities (radiance, reflectance, throughput) as four lanes.
//
// In an RGB render the lanes r, g, b are the colour channels and the fourth, w, is a copy of green:
// colours are made with w = g and every operation works lane by lane, so w stays equal to g and
// the reductions over four lanes (max, min, is_black) equal those over three; nothing reads w out.
// In a spectral render the four lanes are the values at a sample's four wavelengths
// (spectral/wavelengths.h). Four floats are one SIMD register, which is why the RGB render carries
// the spare lane instead of a second type.
#include <algorithm>
#include <cmath>

namespace candela {

struct RGB {
  static constexpr int kLanes = 4;
  float r = 0, g = 0, b = 0, w = 0;
  constexpr RGB() = default;
  constexpr explicit RGB(float s) : r(s), g(s), b(s), w(s) {}
  constexpr RGB(float r_, float g_, float b_) : r(r_), g(g_), b(b_), w(g_) {}
  constexpr RGB(float r_, float g_, float b_, float w_) : r(r_), g(g_), b(b_), w(w_) {}
  constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : (i == 2 ? b : w)); }
  // Values are computed lane by lane with these (there is no writable operator[], which could
  // leave w behind g): f of every lane's value, or of every lane's index.
  template <typename F>
  constexpr RGB map(F f) const { return {f(r), f(g), f(b), f(w)}; }
  template <typename F>
  static constexpr RGB from_lanes(F f) { return {f(0), f(1), f(2), f(3)}; }
  constexpr RGB operator+(const RGB& o) const { return {r + o.r, g + o.g, b + o.b, w + o.w}; }
  constexpr RGB operator-(const RGB& o) const { return {r - o.r, g - o.g, b - o.b, w - o.w}; }
  constexpr RGB operator*(const RGB& o) const { return {r * o.r, g * o.g, b * o.b, w * o.w}; }
  constexpr RGB operator*(float s) const { return {r * s, g * s, b * s, w * s}; }
  constexpr RGB operator/(float s) const { float inv = 1.0f / s; return {r * inv, g * inv, b * inv, w * inv}; }
  constexpr RGB& operator+=(const RGB& o) { r += o.r; g += o.g; b += o.b; w += o.w; return *this; }
  constexpr RGB& operator*=(const RGB& o) { r *= o.r; g *= o.g; b *= o.b; w *= o.w; return *this; }
  constexpr RGB& operator*=(float s) { r *= s; g *= s; b *= s; w *= s; return *this; }
  constexpr bool operator==(const RGB&) const = default;
  constexpr bool is_black() const { return r == 0 && g == 0 && b == 0 && w == 0; }
  constexpr float max_component() const { return std::max(std::max(r, g), std::max(b, w)); }
  constexpr float min_component() const { return std::min(std::min(r, g), std::min(b, w)); }
  // The mean of the colour channels r, g, b (a colour's grey value; a sampling weight).
  constexpr float average() const { return (r + g + b) * (1.0f / 3.0f); }
  // The mean of the first `lanes` lanes: 3 in an RGB render, 4 in a spectral one.
  constexpr float lane_average(int lanes) const { return lanes == 3 ? average() : (r + g + b + w) * 0.25f; }
  // Rec. 709 luminance: the scalar used for light power and importance.
  constexpr float luminance() const { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
  bool is_finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b) && std::isfinite(w); }
};
constexpr RGB operator*(float s, const RGB& c) { return c * s; }

}  // namespace candela
