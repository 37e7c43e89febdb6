#pragma once
// Keyframed values and the transform hierarchy that animates a scene (glTF 2.0's animation model,
// which candela's JSON keyframes share): a value sampled at increasing times and interpolated by step,
// linear (spherical for rotations) or cubic Hermite spline, as the glTF specification defines them
// (Appendix C, "Interpolation"). Needs only math/, so the scene description can hold it.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "candela/math/transform.h"

namespace candela {

enum class Interpolation : uint8_t { Step, Linear, CubicSpline };
constexpr std::string_view enum_name(Interpolation i) {
  switch (i) {
    case Interpolation::Step: return "step";
    case Interpolation::Linear: return "linear";
    case Interpolation::CubicSpline: return "cubicspline";
  }
  return {};
}

// A value of `width` floats (1: a scalar, 3: a translation or a scale, 4: a rotation quaternion
// (x, y, z, w), N: N morph weights) at the times `times`. Before the first time it holds the first
// value, after the last the last one.
struct Keyframes {
  Interpolation interpolation = Interpolation::Linear;
  int width = 1;
  // Quaternions: linear interpolation is spherical (the shorter arc) and every result is normalised.
  bool rotation = false;
  std::vector<float> times;  // strictly increasing
  // `width` floats per time; for CubicSpline 3 x width per time: the in-tangent, the value and the
  // out-tangent (glTF's layout), tangents in units per second.
  std::vector<float> values;

  size_t size() const { return times.size(); }
  float start() const { return times.empty() ? 0 : times.front(); }
  float end() const { return times.empty() ? 0 : times.back(); }
  // The value at time t into out[0..width).
  void evaluate(float t, float* out) const;
  std::vector<float> at(float t) const;
  // What is wrong with the keyframes (sizes, times not increasing, non-finite numbers), or empty.
  std::string problem() const;
};

// A rotation (x, y, z, w) as a matrix; q need not be normalised.
Matrix4 rotation_matrix(const std::array<double, 4>& q);
// T * R * S, the order in which glTF (and candela's keyframes) compose a node's transform.
Matrix4 trs_matrix(const std::array<double, 3>& t, const std::array<double, 4>& q, const std::array<double, 3>& s);

// A node's local transform over time: translation * rotation * scale, each from its keyframes where
// it has some, else its constant value.
struct AnimatedTrs {
  std::array<float, 3> translation{0, 0, 0};
  std::array<float, 4> rotation{0, 0, 0, 1};
  std::array<float, 3> scale{1, 1, 1};
  std::optional<Keyframes> translation_keys, rotation_keys, scale_keys;
  bool animated() const { return translation_keys || rotation_keys || scale_keys; }
  Matrix4 at(float t) const;
};

// One node of the transform hierarchy: its transform relative to its parent's, constant (`matrix`)
// or keyframed (`trs`), and, for meshes with morph targets, keyframed morph weights.
struct AnimationNode {
  int parent = -1;
  std::optional<Matrix4> matrix;  // a constant local transform (then trs is unused)
  AnimatedTrs trs;
  std::optional<Keyframes> weights_keys;  // morph target weights (width = the mesh's target count)
  std::string name;
};

// Skinning (glTF's skins): each joint is a node; a vertex moves with the weighted sum of its joints'
// world transforms times their inverse bind matrices.
struct Skin {
  std::vector<int> joints;             // nodes
  std::vector<Matrix4> inverse_bind;   // one per joint
  std::string name;
};

// How a triangle mesh deforms over time (glTF skinning and morph targets): the mesh's own positions
// and normals are the rest pose, in the space of the node that places the mesh.
struct MeshDeformation {
  int skin = -1;  // SceneAnimation::skins, or -1
  // Skinning: `influences` joints per vertex (4 per JOINTS_n/WEIGHTS_n set): joint indices into the
  // skin's joints and their weights, vertex-major.
  int influences = 0;
  std::vector<uint16_t> joints;
  std::vector<float> weights;
  // Morph targets: per target the displacement of each position and normal (normals may be absent).
  std::vector<std::vector<Vec3>> target_positions, target_normals;
  std::vector<float> default_weights;  // the mesh's weights when no node animates them
  int weights_node = -1;               // the node whose keyframed weights drive the targets, or -1
};

// Everything in a scene that moves: the transform hierarchy, skins and mesh deformations; shapes,
// instances and the camera name the node that places them (-1: not animated).
struct SceneAnimation {
  std::vector<AnimationNode> nodes;
  std::vector<Skin> skins;
  std::vector<MeshDeformation> deformations;

  bool empty() const { return nodes.empty(); }
  // Node `node`'s world transform at time t: its ancestors' local transforms times its own.
  Matrix4 world_matrix(int node, float t) const;
  // Whether the node's world transform changes over time (it or an ancestor is keyframed).
  bool node_moves(int node) const;
  // The first and last keyframe time of every track (0, 0 when nothing is keyframed).
  std::array<float, 2> time_range() const;
  // A mesh's rest pose (`positions`, `normals`) deformed to time t: morphed by its targets, then,
  // with a skin, skinned. Skinned vertices come out in world space (glTF ignores the transform of a
  // skinned mesh's node: the shape's own placement must be the identity); the others stay in the
  // mesh's space. Normals are renormalised.
  void deform(const MeshDeformation& deformation, float t, std::vector<Point3>& positions,
              std::vector<Normal3>& normals) const;
  // What is wrong (node cycles, out-of-range indices, bad keyframes), or empty.
  std::string problem() const;
};

}  // namespace candela
