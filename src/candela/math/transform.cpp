#include "candela/math/transform.h"

#include <cmath>

namespace candela {

Matrix4 Matrix4::identity() {
  Matrix4 r;
  for (int i = 0; i < 4; ++i) r.m[i][i] = 1;
  return r;
}

Matrix4 Matrix4::operator*(const Matrix4& b) const {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Matrix4 Matrix4::transposed() const {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
  return r;
}

double Matrix4::determinant() const {
  // Laplace expansion along the first row with 3x3 minors.
  auto minor3 = [&](int col) {
    int c[3], k = 0;
    for (int j = 0; j < 4; ++j)
      if (j != col) c[k++] = j;
    return m[1][c[0]] * (m[2][c[1]] * m[3][c[2]] - m[2][c[2]] * m[3][c[1]]) -
           m[1][c[1]] * (m[2][c[0]] * m[3][c[2]] - m[2][c[2]] * m[3][c[0]]) +
           m[1][c[2]] * (m[2][c[0]] * m[3][c[1]] - m[2][c[1]] * m[3][c[0]]);
  };
  double d = 0;
  for (int j = 0; j < 4; ++j) d += (j % 2 ? -1 : 1) * m[0][j] * minor3(j);
  return d;
}

std::optional<Matrix4> Matrix4::inverse() const {
  // Gauss-Jordan elimination with partial pivoting.
  Matrix4 a = *this, inv = identity();
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::abs(a.m[r][col]) > std::abs(a.m[pivot][col])) pivot = r;
    if (std::abs(a.m[pivot][col]) < 1e-300 || !std::isfinite(a.m[pivot][col])) return std::nullopt;
    std::swap(a.m[col], a.m[pivot]);
    std::swap(inv.m[col], inv.m[pivot]);
    double s = 1.0 / a.m[col][col];
    for (int j = 0; j < 4; ++j) { a.m[col][j] *= s; inv.m[col][j] *= s; }
    for (int r = 0; r < 4; ++r) {
      if (r == col) continue;
      double f = a.m[r][col];
      if (f == 0) continue;
      for (int j = 0; j < 4; ++j) { a.m[r][j] -= f * a.m[col][j]; inv.m[r][j] -= f * inv.m[col][j]; }
    }
  }
  return inv;
}

std::optional<Transform> Transform::from_matrix(const Matrix4& m) {
  auto inv = m.inverse();
  if (!inv) return std::nullopt;
  return Transform(m, *inv);
}

Transform Transform::translate(const Vec3& d) {
  Matrix4 m = Matrix4::identity(), inv = Matrix4::identity();
  for (int i = 0; i < 3; ++i) { m.m[i][3] = d[i]; inv.m[i][3] = -d[i]; }
  return {m, inv};
}

Transform Transform::scale(const Vec3& s) {
  Matrix4 m = Matrix4::identity(), inv = Matrix4::identity();
  for (int i = 0; i < 3; ++i) { m.m[i][i] = s[i]; inv.m[i][i] = 1.0 / s[i]; }
  return {m, inv};
}

Transform Transform::rotate(float degrees, const Vec3& axis_in) {
  // Rodrigues' rotation about a normalised axis; the inverse of a rotation is its transpose.
  double ax = axis_in.x, ay = axis_in.y, az = axis_in.z;
  double len = std::sqrt(ax * ax + ay * ay + az * az);
  ax /= len; ay /= len; az /= len;
  double theta = degrees * 3.14159265358979323846 / 180.0;
  double s = std::sin(theta), c = std::cos(theta);
  Matrix4 m = Matrix4::identity();
  m.m[0][0] = ax * ax + (1 - ax * ax) * c;
  m.m[0][1] = ax * ay * (1 - c) - az * s;
  m.m[0][2] = ax * az * (1 - c) + ay * s;
  m.m[1][0] = ax * ay * (1 - c) + az * s;
  m.m[1][1] = ay * ay + (1 - ay * ay) * c;
  m.m[1][2] = ay * az * (1 - c) - ax * s;
  m.m[2][0] = ax * az * (1 - c) - ay * s;
  m.m[2][1] = ay * az * (1 - c) + ax * s;
  m.m[2][2] = az * az + (1 - az * az) * c;
  return {m, m.transposed()};
}

static Transform frame_transform(const Vec3& x, const Vec3& y, const Vec3& z, const Point3& origin) {
  // Columns are the camera axes in world space: this maps camera space to world space.
  Matrix4 m = Matrix4::identity();
  for (int i = 0; i < 3; ++i) {
    m.m[i][0] = x[i];
    m.m[i][1] = y[i];
    m.m[i][2] = z[i];
    m.m[i][3] = origin[i];
  }
  return *Transform::from_matrix(m);
}

Transform Transform::look_at_right_handed(const Point3& eye, const Point3& target, const Vec3& up) {
  Vec3 forward = normalize(target - eye);
  Vec3 right = normalize(cross(forward, normalize(up)));
  Vec3 true_up = cross(right, forward);
  return frame_transform(right, true_up, forward, eye);  // world-from-camera
}

Transform Transform::look_at_pbrt(const Point3& eye, const Point3& target, const Vec3& up) {
  Vec3 dir = normalize(target - eye);
  Vec3 right = normalize(cross(normalize(up), dir));
  Vec3 new_up = cross(dir, right);
  return frame_transform(right, new_up, dir, eye).inverse();  // camera-from-world, as pbrt's CTM wants
}

Point3 Transform::point(const Point3& p) const {
  const auto& a = m_.m;
  double x = a[0][0] * p.x + a[0][1] * p.y + a[0][2] * p.z + a[0][3];
  double y = a[1][0] * p.x + a[1][1] * p.y + a[1][2] * p.z + a[1][3];
  double z = a[2][0] * p.x + a[2][1] * p.y + a[2][2] * p.z + a[2][3];
  double w = a[3][0] * p.x + a[3][1] * p.y + a[3][2] * p.z + a[3][3];
  if (w == 1) return {float(x), float(y), float(z)};
  return {float(x / w), float(y / w), float(z / w)};
}

Vec3 Transform::vector(const Vec3& v) const {
  const auto& a = m_.m;
  return {float(a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z),
          float(a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z),
          float(a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z)};
}

Normal3 Transform::normal(const Normal3& n) const {
  const auto& a = inv_.m;  // (M^-1)^T n
  return {float(a[0][0] * n.x + a[1][0] * n.y + a[2][0] * n.z),
          float(a[0][1] * n.x + a[1][1] * n.y + a[2][1] * n.z),
          float(a[0][2] * n.x + a[1][2] * n.y + a[2][2] * n.z)};
}

std::optional<Transform> interpolate_transform(const Transform& start, const Transform& end, float t) {
  Matrix4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.m[r][c] = (1 - double(t)) * start.matrix().m[r][c] + double(t) * end.matrix().m[r][c];
  return Transform::from_matrix(m);
}

}  // namespace candela
