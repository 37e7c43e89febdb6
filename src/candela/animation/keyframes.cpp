#include "candela/animation/keyframes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace candela {

namespace {

// The shorter-arc spherical interpolation of two unit quaternions (linear where they nearly agree).
void slerp(const float* a, const float* b, float s, float* out) {
  double d = 0;
  for (int i = 0; i < 4; ++i) d += double(a[i]) * b[i];
  const double sign = d < 0 ? -1 : 1;
  d = std::abs(d);
  double wa = 1 - s, wb = s;
  if (d < 0.9995) {
    const double theta = std::acos(std::min(d, 1.0));
    wa = std::sin((1 - s) * theta) / std::sin(theta);
    wb = std::sin(s * theta) / std::sin(theta);
  }
  for (int i = 0; i < 4; ++i) out[i] = float(wa * a[i] + sign * wb * b[i]);
}

void normalize_quaternion(float* q) {
  const double n = std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3]);
  if (n > 0)
    for (int i = 0; i < 4; ++i) q[i] = float(q[i] / n);
}

}  // namespace

void Keyframes::evaluate(float t, float* out) const {
  const size_t w = size_t(width);
  const bool cubic = interpolation == Interpolation::CubicSpline;
  // Value k's floats: the middle third of key k's for cubic splines.
  auto value = [&](size_t k) { return values.data() + (cubic ? 3 * w * k + w : w * k); };
  const size_t n = times.size();
  if (n == 0) {
    std::fill(out, out + w, 0.0f);
    return;
  }
  // Clamped outside the keyed range.
  if (n == 1 || t <= times.front()) {
    std::copy(value(0), value(0) + w, out);
  } else if (t >= times.back()) {
    std::copy(value(n - 1), value(n - 1) + w, out);
  } else {
    // The interval [t_k, t_k+1) holding t.
    const size_t k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    const float t0 = times[k], t1 = times[k + 1], dt = t1 - t0;
    const float s = (t - t0) / dt;
    switch (interpolation) {
      case Interpolation::Step: std::copy(value(k), value(k) + w, out); break;
      case Interpolation::Linear:
        if (rotation && w == 4) {
          slerp(value(k), value(k + 1), s, out);
        } else {
          for (size_t i = 0; i < w; ++i) out[i] = (1 - s) * value(k)[i] + s * value(k + 1)[i];
        }
        break;
      case Interpolation::CubicSpline: {
        // glTF's cubic Hermite spline: p0 = v_k, m0 = dt b_k (out-tangent), p1 = v_k+1, m1 = dt a_k+1 (in-tangent).
        const float* out_tangent = values.data() + 3 * w * k + 2 * w;
        const float* in_tangent = values.data() + 3 * w * (k + 1);
        const float s2 = s * s, s3 = s2 * s;
        const float h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
        for (size_t i = 0; i < w; ++i)
          out[i] = h00 * value(k)[i] + h10 * dt * out_tangent[i] + h01 * value(k + 1)[i] + h11 * dt * in_tangent[i];
        break;
      }
    }
  }
  if (rotation && w == 4) normalize_quaternion(out);
}

std::vector<float> Keyframes::at(float t) const {
  std::vector<float> v(size_t(std::max(width, 0)));
  evaluate(t, v.data());
  return v;
}

std::string Keyframes::problem() const {
  if (width < 1) return fmt::format("a keyframed value needs at least one component, got {}", width);
  if (rotation && width != 4) return fmt::format("a rotation is a quaternion of 4 numbers, got {}", width);
  if (times.empty()) return "keyframes need at least one time";
  const size_t per_key = size_t(width) * (interpolation == Interpolation::CubicSpline ? 3 : 1);
  if (values.size() != per_key * times.size())
    return fmt::format("{} keyframe times need {} values ({} per time{}), got {}", times.size(),
                       per_key * times.size(), per_key,
                       interpolation == Interpolation::CubicSpline ? ": in-tangent, value, out-tangent" : "",
                       values.size());
  for (size_t k = 0; k < times.size(); ++k) {
    if (!std::isfinite(times[k])) return fmt::format("keyframe time {} is not a finite number", k);
    if (k > 0 && !(times[k] > times[k - 1]))
      return fmt::format("keyframe times must increase: time {} ({}) follows {}", k, times[k], times[k - 1]);
  }
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) return fmt::format("keyframe value {} is not a finite number", i);
  return {};
}

Matrix4 rotation_matrix(const std::array<double, 4>& quaternion) {
  std::array<double, 4> q = quaternion;
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n > 0)
    for (double& v : q) v /= n;
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  Matrix4 m = Matrix4::identity();
  m.m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0};
  m.m[1] = {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0};
  m.m[2] = {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0};
  return m;
}

Matrix4 trs_matrix(const std::array<double, 3>& t, const std::array<double, 4>& q, const std::array<double, 3>& s) {
  Matrix4 m = rotation_matrix(q);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.m[i][j] *= s[size_t(j)];
    m.m[i][3] = t[size_t(i)];
  }
  return m;
}

Matrix4 AnimatedTrs::at(float t) const {
  std::array<float, 3> tr = translation, sc = scale;
  std::array<float, 4> q = rotation;
  if (translation_keys) translation_keys->evaluate(t, tr.data());
  if (rotation_keys) rotation_keys->evaluate(t, q.data());
  if (scale_keys) scale_keys->evaluate(t, sc.data());
  return trs_matrix({tr[0], tr[1], tr[2]}, {q[0], q[1], q[2], q[3]}, {sc[0], sc[1], sc[2]});
}

Matrix4 SceneAnimation::world_matrix(int node, float t) const {
  Matrix4 world = Matrix4::identity();
  // Walk up to the root, multiplying each ancestor's local transform in from the left.
  for (int n = node, depth = 0; n >= 0 && depth <= int(nodes.size()); n = nodes[size_t(n)].parent, ++depth) {
    const AnimationNode& a = nodes[size_t(n)];
    world = (a.matrix ? *a.matrix : a.trs.at(t)) * world;
  }
  return world;
}

bool SceneAnimation::node_moves(int node) const {
  for (int n = node, depth = 0; n >= 0 && depth <= int(nodes.size()); n = nodes[size_t(n)].parent, ++depth)
    if (!nodes[size_t(n)].matrix && nodes[size_t(n)].trs.animated()) return true;
  return false;
}

std::array<float, 2> SceneAnimation::time_range() const {
  bool any = false;
  float lo = 0, hi = 0;
  auto take = [&](const std::optional<Keyframes>& k) {
    if (!k || k->times.empty()) return;
    lo = any ? std::min(lo, k->start()) : k->start();
    hi = any ? std::max(hi, k->end()) : k->end();
    any = true;
  };
  for (const AnimationNode& n : nodes) {
    take(n.trs.translation_keys);
    take(n.trs.rotation_keys);
    take(n.trs.scale_keys);
    take(n.weights_keys);
  }
  return {lo, hi};
}

void SceneAnimation::deform(const MeshDeformation& d, float t, std::vector<Point3>& positions,
                            std::vector<Normal3>& normals) const {
  // Morph targets: the rest pose plus each target's displacement times its weight.
  if (!d.target_positions.empty()) {
    std::vector<float> weights = d.default_weights;
    if (d.weights_node >= 0 && nodes[size_t(d.weights_node)].weights_keys)
      weights = nodes[size_t(d.weights_node)].weights_keys->at(t);
    weights.resize(d.target_positions.size(), 0.0f);
    for (size_t target = 0; target < d.target_positions.size(); ++target) {
      const float w = weights[target];
      if (w == 0) continue;
      const std::vector<Vec3>& dp = d.target_positions[target];
      for (size_t v = 0; v < positions.size() && v < dp.size(); ++v) positions[v] += w * dp[v];
      if (target < d.target_normals.size()) {
        const std::vector<Vec3>& dn = d.target_normals[target];
        for (size_t v = 0; v < normals.size() && v < dn.size(); ++v) normals[v] += w * dn[v];
      }
    }
  }
  // Skinning: each vertex by the weighted sum of its joints' matrices, world(joint) * inverse bind.
  if (d.skin >= 0) {
    const Skin& skin = skins[size_t(d.skin)];
    std::vector<Matrix4> joint_matrices(skin.joints.size());
    for (size_t j = 0; j < skin.joints.size(); ++j)
      joint_matrices[j] = world_matrix(skin.joints[j], t) * skin.inverse_bind[j];
    const size_t k = size_t(d.influences);
    for (size_t v = 0; v < positions.size(); ++v) {
      Matrix4 m{};
      for (size_t i = 0; i < k; ++i) {
        const float w = d.weights[v * k + i];
        if (w == 0) continue;
        const Matrix4& J = joint_matrices[d.joints[v * k + i]];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 4; ++c) m.m[r][c] += w * J.m[r][c];
      }
      const Point3 p = positions[v];
      positions[v] = Point3(float(m.m[0][0] * p.x + m.m[0][1] * p.y + m.m[0][2] * p.z + m.m[0][3]),
                            float(m.m[1][0] * p.x + m.m[1][1] * p.y + m.m[1][2] * p.z + m.m[1][3]),
                            float(m.m[2][0] * p.x + m.m[2][1] * p.y + m.m[2][2] * p.z + m.m[2][3]));
      if (v < normals.size()) {
        // Normals by the inverse transpose of the blended matrix (a degenerate blend keeps them).
        m.m[3] = {0, 0, 0, 1};
        if (const std::optional<Transform> blended = Transform::from_matrix(m)) normals[v] = blended->normal(normals[v]);
      }
    }
  }
  for (Normal3& n : normals) {
    const float len = length(n);
    if (len > 0) n = n / len;
  }
}

std::string SceneAnimation::problem() const {
  const int count = int(nodes.size());
  for (int i = 0; i < count; ++i) {
    const AnimationNode& n = nodes[size_t(i)];
    if (n.parent < -1 || n.parent >= count) return fmt::format("node {} has no parent {}", i, n.parent);
    // A cycle would never reach a root.
    int steps = 0;
    for (int p = n.parent; p >= 0; p = nodes[size_t(p)].parent)
      if (++steps > count) return fmt::format("node {} is its own ancestor", i);
    for (const auto* k : {&n.trs.translation_keys, &n.trs.rotation_keys, &n.trs.scale_keys, &n.weights_keys})
      if (*k) {
        std::string p = (*k)->problem();
        if (!p.empty()) return fmt::format("node {}: {}", n.name.empty() ? std::to_string(i) : n.name, p);
      }
  }
  for (const Skin& s : skins) {
    if (s.inverse_bind.size() != s.joints.size())
      return fmt::format("skin {} has {} joints but {} inverse bind matrices", s.name, s.joints.size(),
                         s.inverse_bind.size());
    for (int j : s.joints)
      if (j < 0 || j >= count) return fmt::format("skin {} names joint node {}, which does not exist", s.name, j);
  }
  for (const MeshDeformation& d : deformations) {
    if (d.skin >= int(skins.size())) return fmt::format("a mesh names skin {}, which does not exist", d.skin);
    if (d.weights_node >= count) return fmt::format("a mesh names node {}, which does not exist", d.weights_node);
    if (d.skin >= 0) {
      const size_t joints = skins[size_t(d.skin)].joints.size();
      for (uint16_t j : d.joints)
        if (j >= joints) return fmt::format("a vertex names joint {} of a skin of {} joints", j, joints);
    }
  }
  return {};
}

}  // namespace candela
