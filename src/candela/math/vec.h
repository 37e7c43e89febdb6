#pragma once
// Small fixed-size vectors. One 3-vector type serves for points, directions and normals: the
// distinction pbrt draws with separate types is kept here by names, not by the type system.
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace candela {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;
inline constexpr float kInv2Pi = 0.15915494309189533577f;
inline constexpr float kInv4Pi = 0.07957747154594766788f;

struct Vec2 {
  float x = 0, y = 0;
  constexpr Vec2() = default;
  constexpr Vec2(float x_, float y_) : x(x_), y(y_) {}
  constexpr Vec2 operator+(Vec2 b) const { return {x + b.x, y + b.y}; }
  constexpr Vec2 operator-(Vec2 b) const { return {x - b.x, y - b.y}; }
  constexpr Vec2 operator*(float s) const { return {x * s, y * s}; }
  constexpr float operator[](int i) const { return i == 0 ? x : y; }
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  constexpr Vec3() = default;
  constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}
  constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator+(const Vec3& b) const { return {x + b.x, y + b.y, z + b.z}; }
  constexpr Vec3 operator-(const Vec3& b) const { return {x - b.x, y - b.y, z - b.z}; }
  constexpr Vec3 operator*(const Vec3& b) const { return {x * b.x, y * b.y, z * b.z}; }
  constexpr Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(float s) const { float inv = 1.0f / s; return {x * inv, y * inv, z * inv}; }
  constexpr Vec3& operator+=(const Vec3& b) { x += b.x; y += b.y; z += b.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
  constexpr Vec3& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
  constexpr bool operator==(const Vec3&) const = default;
};
using Point3 = Vec3;
using Normal3 = Vec3;

constexpr Vec3 operator*(float s, const Vec3& v) { return v * s; }
constexpr float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float abs_dot(const Vec3& a, const Vec3& b) { return std::abs(dot(a, b)); }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length_squared(const Vec3& v) { return dot(v, v); }
inline float length(const Vec3& v) { return std::sqrt(dot(v, v)); }
inline Vec3 normalize(const Vec3& v) { return v / length(v); }
inline float distance(const Vec3& a, const Vec3& b) { return length(a - b); }
inline float max_component(const Vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline Vec3 min(const Vec3& a, const Vec3& b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3 max(const Vec3& a, const Vec3& b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool is_finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
// Flip v to lie in the hemisphere around n.
inline Vec3 face_forward(const Vec3& v, const Vec3& n) { return dot(v, n) < 0 ? -v : v; }
inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return -wo + n * (2 * dot(wo, n)); }

inline float safe_sqrt(float x) { return std::sqrt(std::max(0.0f, x)); }
inline float sqr(float x) { return x * x; }
inline float lerp(float t, float a, float b) { return (1 - t) * a + t * b; }
inline float radians(float deg) { return deg * (kPi / 180.0f); }

// Axis-aligned bounding box.
struct Bounds3 {
  Vec3 lo{INFINITY}, hi{-INFINITY};
  void extend(const Vec3& p) { lo = min(lo, p); hi = max(hi, p); }
  void extend(const Bounds3& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  Vec3 center() const { return (lo + hi) * 0.5f; }
  Vec3 diagonal() const { return hi - lo; }
};

}  // namespace candela
