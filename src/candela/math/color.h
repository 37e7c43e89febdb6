#pragma once
// Linear RGB radiometric quantities (radiance, reflectance, throughput).
#include <algorithm>
#include <cmath>

namespace candela {

struct RGB {
  float r = 0, g = 0, b = 0;
  constexpr RGB() = default;
  constexpr explicit RGB(float s) : r(s), g(s), b(s) {}
  constexpr RGB(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
  constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr RGB operator+(const RGB& o) const { return {r + o.r, g + o.g, b + o.b}; }
  constexpr RGB operator-(const RGB& o) const { return {r - o.r, g - o.g, b - o.b}; }
  constexpr RGB operator*(const RGB& o) const { return {r * o.r, g * o.g, b * o.b}; }
  constexpr RGB operator*(float s) const { return {r * s, g * s, b * s}; }
  constexpr RGB operator/(float s) const { float inv = 1.0f / s; return {r * inv, g * inv, b * inv}; }
  constexpr RGB& operator+=(const RGB& o) { r += o.r; g += o.g; b += o.b; return *this; }
  constexpr RGB& operator*=(const RGB& o) { r *= o.r; g *= o.g; b *= o.b; return *this; }
  constexpr RGB& operator*=(float s) { r *= s; g *= s; b *= s; return *this; }
  constexpr bool operator==(const RGB&) const = default;
  constexpr bool is_black() const { return r == 0 && g == 0 && b == 0; }
  constexpr float max_component() const { return std::max(r, std::max(g, b)); }
  constexpr float min_component() const { return std::min(r, std::min(g, b)); }
  constexpr float average() const { return (r + g + b) * (1.0f / 3.0f); }
  // Rec. 709 luminance: the scalar used for light power and importance.
  constexpr float luminance() const { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
  bool is_finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
};
constexpr RGB operator*(float s, const RGB& c) { return c * s; }

}  // namespace candela
