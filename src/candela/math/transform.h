#pragma once
// 4x4 affine transforms, stored with their inverse (pbrt style) so normals and inverse maps are cheap.
#include <array>
#include <optional>

#include "candela/math/vec.h"

namespace candela {

struct Matrix4 {
  std::array<std::array<double, 4>, 4> m{};  // row-major; m[row][col]
  static Matrix4 identity();
  Matrix4 operator*(const Matrix4& b) const;
  Matrix4 transposed() const;
  std::optional<Matrix4> inverse() const;  // nullopt when singular
  double determinant() const;
  bool operator==(const Matrix4&) const = default;
};

class Transform {
 public:
  Transform() : m_(Matrix4::identity()), inv_(Matrix4::identity()) {}
  Transform(const Matrix4& m, const Matrix4& inv) : m_(m), inv_(inv) {}
  // Returns nullopt for a singular matrix.
  static std::optional<Transform> from_matrix(const Matrix4& m);

  static Transform translate(const Vec3& d);
  static Transform scale(const Vec3& s);   // caller checks for zero factors
  static Transform rotate(float degrees, const Vec3& axis);
  // Right-handed look-at for the JSON format: camera +x = image right = cross(forward, up).
  static Transform look_at_right_handed(const Point3& eye, const Point3& target, const Vec3& up);
  // pbrt-v4's LookAt: returns camera-from-world (left-handed camera space, +x = cross(up, forward)).
  static Transform look_at_pbrt(const Point3& eye, const Point3& target, const Vec3& up);

  Transform operator*(const Transform& b) const { return {m_ * b.m_, b.inv_ * inv_}; }
  Transform inverse() const { return {inv_, m_}; }
  const Matrix4& matrix() const { return m_; }
  const Matrix4& inverse_matrix() const { return inv_; }
  bool is_identity() const { return m_ == Matrix4::identity(); }
  bool swaps_handedness() const { return m_.determinant() < 0; }

  Point3 point(const Point3& p) const;
  Vec3 vector(const Vec3& v) const;
  Normal3 normal(const Normal3& n) const;  // transforms by the inverse transpose; not normalised
  bool operator==(const Transform&) const = default;

 private:
  Matrix4 m_, inv_;
};

// The transform (1-t) start + t end, t in [0,1]; nullopt where the interpolated matrix is singular.
// For affine maps this moves every point linearly, exactly as Embree's vertex motion blur does.
std::optional<Transform> interpolate_transform(const Transform& start, const Transform& end, float t);

}  // namespace candela
