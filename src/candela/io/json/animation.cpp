// The "animation" section (docs/animation.md): the transform hierarchy's nodes with their keyframed
// translation, rotation, scale and morph weights, skins and mesh deformations; and the references to
// nodes from shapes, instances and the camera, with the camera's keyframed lens values.
#include <algorithm>
#include <cmath>

#include "candela/io/json/reader.h"

namespace candela::json {

namespace {

constexpr size_t kMaxJoints = 65536;  // MeshDeformation::joints are 16-bit

// The floats of a track's first value (the middle of a cubic spline's first key).
const float* first_value(const Keyframes& keys) {
  return keys.values.data() + (keys.interpolation == Interpolation::CubicSpline ? keys.width : 0);
}

// Where a track's k-th value is: values/k, or values/k/1 inside a cubic spline's [in, value, out].
std::string value_pointer(const std::string& track, const Keyframes& keys, size_t k) {
  const std::string entry = child_pointer(child_pointer(track, "values"), k);
  return keys.interpolation == Interpolation::CubicSpline ? child_pointer(entry, size_t(1)) : entry;
}

// "1 node", "3 nodes": counts in messages.
std::string count_of(size_t n, std::string_view thing) { return fmt::format("{} {}{}", n, thing, n == 1 ? "" : "s"); }

template <typename Names>
std::vector<std::string_view> name_list(const Names& names) {
  std::vector<std::string_view> list;
  for (const auto& entry : names) list.push_back(entry.first);
  return list;
}

}  // namespace

// ---- the section

void JsonSceneReader::read_animation(const Json& value, const std::string& pointer) {
  CheckedObject a(report_, value, pointer);
  SceneAnimation& animation = scene_.animation;
  if (const Json* nodes = a.find("nodes")) {
    const std::string nodes_pointer = a.pointer_of("nodes");
    check_is_array(report_, *nodes, nodes_pointer, "animation nodes");
    // Nodes may name parents (and skins joints) further down the list.
    collect_node_names(*nodes);
    node_count_ = int(nodes->size());
    for (size_t i = 0; i < nodes->size(); ++i) {
      node_pointers_.push_back(child_pointer(nodes_pointer, i));
      animation.nodes.push_back(read_animation_node((*nodes)[i], node_pointers_.back()));
    }
    check_node_cycles();
  }
  if (const Json* skins = a.find("skins")) {
    const std::string skins_pointer = a.pointer_of("skins");
    check_is_array(report_, *skins, skins_pointer, "skins");
    for (size_t i = 0; i < skins->size(); ++i)
      animation.skins.push_back(read_skin((*skins)[i], child_pointer(skins_pointer, i)));
  }
  if (const Json* deformations = a.find("deformations")) {
    const std::string deformations_pointer = a.pointer_of("deformations");
    check_is_array(report_, *deformations, deformations_pointer, "mesh deformations");
    for (size_t i = 0; i < deformations->size(); ++i)
      animation.deformations.push_back(read_deformation((*deformations)[i], child_pointer(deformations_pointer, i)));
  }
  a.finish();
}

void JsonSceneReader::collect_node_names(const Json& nodes) {
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].is_object())
      if (auto name = nodes[i].find("name"); name != nodes[i].end() && name->is_string() && !name->get<std::string>().empty())
        node_names_[name->get<std::string>()].push_back(int(i));
}

// ---- nodes

AnimationNode JsonSceneReader::read_animation_node(const Json& value, const std::string& pointer) const {
  CheckedObject n(report_, value, pointer);
  AnimationNode node;
  node.name = n.string_or("name", "");
  if (const Json* parent = n.find("parent")) node.parent = node_reference(*parent, n.pointer_of("parent"));
  if (const Json* matrix = n.find("matrix")) {
    for (std::string_view key : {"translation", "rotation", "scale"})
      if (n.has(key))
        report_.fail(n.pointer_of(key), "a node takes either \"matrix\" or \"translation\", \"rotation\" and \"scale\", "
                                        "not both");
    node.matrix = read_node_matrix(*matrix, n.pointer_of("matrix"));
  } else {
    read_node_trs(n, node.trs);
  }
  if (const Json* weights = n.find("weights"))
    node.weights_keys = read_keyframes(*weights, n.pointer_of("weights"), TrackValue::Weights);
  n.finish();
  return node;
}

// Each of translation, rotation and scale: a constant, or keyframes (an object with "times"; a
// rotation's {"axis", "angle"} is a constant). A keyframed one's constant is its first value.
void JsonSceneReader::read_node_trs(CheckedObject& n, AnimatedTrs& trs) const {
  if (const Json* t = n.find("translation")) {
    const std::string pointer = n.pointer_of("translation");
    if (t->is_object()) {
      trs.translation_keys = read_keyframes(*t, pointer, TrackValue::Vec3);
      std::copy_n(first_value(*trs.translation_keys), 3, trs.translation.begin());
    } else {
      const Vec3 v = read_vec3(report_, *t, pointer);
      trs.translation = {v.x, v.y, v.z};
    }
  }
  if (const Json* r = n.find("rotation")) {
    const std::string pointer = n.pointer_of("rotation");
    if (r->is_object() && !r->contains("axis") && !r->contains("angle")) {
      trs.rotation_keys = read_keyframes(*r, pointer, TrackValue::Rotation);
      std::copy_n(first_value(*trs.rotation_keys), 4, trs.rotation.begin());
    } else {
      trs.rotation = read_rotation_value(*r, pointer);
    }
  }
  if (const Json* s = n.find("scale")) {
    const std::string pointer = n.pointer_of("scale");
    if (s->is_object()) {
      trs.scale_keys = read_keyframes(*s, pointer, TrackValue::Vec3);
      std::copy_n(first_value(*trs.scale_keys), 3, trs.scale.begin());
    } else {
      const Vec3 v = s->is_number() ? Vec3(read_float(report_, *s, pointer)) : read_vec3(report_, *s, pointer);
      trs.scale = {v.x, v.y, v.z};
    }
  }
}

// 16 numbers row by row, as a transform's "matrix" step; affine, but it may be singular (a node
// scaled to nothing hides what it carries).
Matrix4 JsonSceneReader::read_node_matrix(const Json& value, const std::string& pointer) const {
  if (!value.is_array() || value.size() != 16)
    report_.fail(pointer, "expected 16 numbers (a 4x4 matrix, row by row), got {}", describe(value));
  Matrix4 m;
  for (size_t i = 0; i < 16; ++i) m.m[i / 4][i % 4] = read_double(report_, value[i], child_pointer(pointer, i));
  if (m.m[3][0] != 0 || m.m[3][1] != 0 || m.m[3][2] != 0 || m.m[3][3] != 1)
    report_.fail(pointer, "the matrix must be affine: its last row must be [0, 0, 0, 1]");
  return m;
}

// Every node must reach a root: a parent chain that comes back to a node on it is reported at the
// "parent" of the node where it closes.
void JsonSceneReader::check_node_cycles() const {
  const std::vector<AnimationNode>& nodes = scene_.animation.nodes;
  enum : char { Unseen, OnPath, Done };
  std::vector<char> state(nodes.size(), Unseen);
  for (size_t i = 0; i < nodes.size(); ++i) {
    std::vector<int> path;
    int n = int(i);
    while (n >= 0 && state[size_t(n)] == Unseen) {
      state[size_t(n)] = OnPath;
      path.push_back(n);
      n = nodes[size_t(n)].parent;
    }
    if (n >= 0 && state[size_t(n)] == OnPath) {
      std::vector<int> cycle(std::find(path.begin(), path.end(), n), path.end());
      cycle.push_back(n);
      report_.fail(child_pointer(node_pointers_[size_t(n)], "parent"),
                   "node {} is its own ancestor: its parents lead round in a cycle {}", n, fmt::join(cycle, " -> "));
    }
    for (int p : path) state[size_t(p)] = Done;
  }
}

int JsonSceneReader::node_reference(const Json& value, const std::string& pointer) const {
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    auto it = node_names_.find(name);
    if (it == node_names_.end()) {
      if (node_names_.empty()) report_.fail(pointer, "unknown animation node \"{}\" (no node has a name)", name);
      const std::vector<std::string_view> names = name_list(node_names_);
      report_.fail(pointer, "unknown animation node \"{}\"{}; named nodes: {}", name, did_you_mean(name, names),
                   fmt::join(names, ", "));
    }
    if (it->second.size() > 1)
      report_.fail(pointer, "{} nodes are called \"{}\" (nodes {}): refer to one by its index", it->second.size(),
                   name, fmt::join(it->second, ", "));
    return it->second.front();
  }
  if (!value.is_number()) report_.fail(pointer, "expected a node index or name, got {}", describe(value));
  const int64_t index = read_int64(report_, value, pointer);
  if (index < 0 || index >= node_count_) {
    if (node_count_ == 0) report_.fail(pointer, "node {} is out of range: there are no animation nodes", index);
    report_.fail(pointer, "node {} is out of range: there {} {} (0 to {})", index, node_count_ == 1 ? "is" : "are",
                 count_of(size_t(node_count_), "animation node"), node_count_ - 1);
  }
  return int(index);
}

// ---- skins and deformations

Skin JsonSceneReader::read_skin(const Json& value, const std::string& pointer) const {
  CheckedObject s(report_, value, pointer);
  Skin skin;
  skin.name = s.string_or("name", "");
  const Json& joints = s.require("joints");
  const std::string joints_pointer = s.pointer_of("joints");
  check_is_array(report_, joints, joints_pointer, "joint nodes");
  if (joints.empty() || joints.size() > kMaxJoints)
    report_.fail(joints_pointer, "a skin has 1 to {} joints, got {}", kMaxJoints, joints.size());
  for (size_t j = 0; j < joints.size(); ++j)
    skin.joints.push_back(node_reference(joints[j], child_pointer(joints_pointer, j)));
  if (const Json* inverse = s.find("inverse_bind")) {
    const std::string inverse_pointer = s.pointer_of("inverse_bind");
    check_is_array(report_, *inverse, inverse_pointer, "inverse bind matrices (16 numbers each, row by row)");
    if (inverse->size() != joints.size())
      report_.fail(inverse_pointer, "expected one inverse bind matrix per joint ({}), got {}", joints.size(),
                   inverse->size());
    // Only their first three rows count (skinning blends affine maps), so any 16 numbers will do.
    for (size_t j = 0; j < inverse->size(); ++j) {
      const Json& m = (*inverse)[j];
      const std::string m_pointer = child_pointer(inverse_pointer, j);
      if (!m.is_array() || m.size() != 16)
        report_.fail(m_pointer, "expected 16 numbers (a 4x4 matrix, row by row), got {}", describe(m));
      Matrix4 matrix;
      for (size_t i = 0; i < 16; ++i) matrix.m[i / 4][i % 4] = read_double(report_, m[i], child_pointer(m_pointer, i));
      skin.inverse_bind.push_back(matrix);
    }
  } else {
    skin.inverse_bind.assign(skin.joints.size(), Matrix4::identity());
  }
  s.finish();
  return skin;
}

int JsonSceneReader::skin_reference(const Json& value, const std::string& pointer) const {
  const std::vector<Skin>& skins = scene_.animation.skins;
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    std::vector<int> found;
    for (size_t i = 0; i < skins.size(); ++i)
      if (skins[i].name == name) found.push_back(int(i));
    if (found.empty()) report_.fail(pointer, "unknown skin \"{}\"", name);
    if (found.size() > 1)
      report_.fail(pointer, "{} skins are called \"{}\" (skins {}): refer to one by its index", found.size(), name,
                   fmt::join(found, ", "));
    return found.front();
  }
  if (!value.is_number()) report_.fail(pointer, "expected a skin index or name, got {}", describe(value));
  const int64_t index = read_int64(report_, value, pointer);
  if (index < 0 || uint64_t(index) >= skins.size())
    report_.fail(pointer, "skin {} is out of range: the scene has {}", index, count_of(skins.size(), "skin"));
  return int(index);
}

// Per-vertex arrays, inline: each vertex's joints and weights as arrays of the same length (the
// influences per vertex), each morph target's displacements as [x, y, z] per vertex.
MeshDeformation JsonSceneReader::read_deformation(const Json& value, const std::string& pointer) {
  CheckedObject d(report_, value, pointer);
  MeshDeformation deformation;
  size_t vertices = 0;  // how many vertices the arrays are for, from the first non-empty one
  std::string vertices_from;
  auto match_vertices = [&](size_t count, const std::string& array_pointer) {
    if (count == 0) return;
    if (vertices == 0) {
      vertices = count;
      vertices_from = array_pointer;
    } else if (count != vertices) {
      report_.fail(array_pointer, "expected one entry per vertex ({}, as {} has), got {}", vertices, vertices_from,
                   count);
    }
  };

  if (const Json* skin = d.find("skin")) deformation.skin = skin_reference(*skin, d.pointer_of("skin"));
  const Json* joints = d.find("joints");
  const Json* weights = d.find("weights");
  if (deformation.skin < 0 && (joints || weights))
    report_.fail(d.pointer_of(joints ? "joints" : "weights"),
                 "\"joints\" and \"weights\" skin the mesh: they need the \"skin\" whose joints they name");
  if (deformation.skin >= 0) {
    if (!joints || !weights)
      report_.fail(d.pointer(), "a skinned deformation needs per-vertex \"joints\" and \"weights\"");
    const size_t joint_count = scene_.animation.skins[size_t(deformation.skin)].joints.size();
    const std::string joints_pointer = d.pointer_of("joints"), weights_pointer = d.pointer_of("weights");
    check_is_array(report_, *joints, joints_pointer, "each vertex's joints [j0, j1, ...]");
    check_is_array(report_, *weights, weights_pointer, "each vertex's weights [w0, w1, ...]");
    if (joints->empty()) report_.fail(joints_pointer, "expected the joints of at least one vertex");
    if (weights->size() != joints->size())
      report_.fail(weights_pointer, "expected one entry per vertex ({}, as \"joints\" has), got {}", joints->size(),
                   weights->size());
    const Json& first = (*joints)[0];
    if (!first.is_array() || first.empty())
      report_.fail(child_pointer(joints_pointer, size_t(0)), "expected a vertex's joints [j0, j1, ...], got {}",
                   describe(first));
    deformation.influences = int(first.size());
    const size_t k = first.size();
    deformation.joints.reserve(joints->size() * k);
    deformation.weights.reserve(joints->size() * k);
    for (size_t v = 0; v < joints->size(); ++v) {
      for (const auto& [array, array_pointer] : {std::pair{joints, joints_pointer}, std::pair{weights, weights_pointer}}) {
        const Json& entry = (*array)[v];
        if (!entry.is_array() || entry.size() != k)
          report_.fail(child_pointer(array_pointer, v),
                       "expected {} numbers (every vertex has as many joints and weights as the first), got {}", k,
                       describe(entry));
      }
      const std::string vertex_joints = child_pointer(joints_pointer, v);
      for (size_t i = 0; i < k; ++i) {
        const int64_t j = read_int64(report_, (*joints)[v][i], child_pointer(vertex_joints, i));
        if (j < 0 || uint64_t(j) >= joint_count)
          report_.fail(child_pointer(vertex_joints, i), "joint {} is out of range: the skin has {} (0 to {})", j,
                       count_of(joint_count, "joint"), joint_count - 1);
        deformation.joints.push_back(uint16_t(j));
        const float w = read_float_element(report_, (*weights)[v], i, child_pointer(weights_pointer, v));
        if (w < 0) report_.fail(child_pointer(child_pointer(weights_pointer, v), i), "a joint weight must be >= 0, got {}", w);
        deformation.weights.push_back(w);
      }
    }
    match_vertices(joints->size(), joints_pointer);
  }

  if (const Json* targets = d.find("target_positions")) {
    const std::string targets_pointer = d.pointer_of("target_positions");
    deformation.target_positions = read_morph_targets(*targets, targets_pointer);
    if (deformation.target_positions.empty()) report_.fail(targets_pointer, "expected at least one morph target");
    for (size_t t = 0; t < deformation.target_positions.size(); ++t)
      match_vertices(deformation.target_positions[t].size(), child_pointer(targets_pointer, t));
  }
  const size_t target_count = deformation.target_positions.size();
  auto require_targets = [&](std::string_view key) {
    if (target_count == 0)
      report_.fail(d.pointer_of(key), "\"{}\" belongs to morph targets: give \"target_positions\"", key);
  };
  if (const Json* normals = d.find("target_normals")) {
    require_targets("target_normals");
    const std::string normals_pointer = d.pointer_of("target_normals");
    deformation.target_normals = read_morph_targets(*normals, normals_pointer);
    if (deformation.target_normals.size() != target_count)
      report_.fail(normals_pointer, "expected one entry per morph target ({}), got {}", target_count,
                   deformation.target_normals.size());
    for (size_t t = 0; t < target_count; ++t)
      match_vertices(deformation.target_normals[t].size(), child_pointer(normals_pointer, t));
  }
  if (const Json* defaults = d.find("default_weights")) {
    require_targets("default_weights");
    const std::string defaults_pointer = d.pointer_of("default_weights");
    check_is_array(report_, *defaults, defaults_pointer, "morph target weights");
    if (defaults->size() != target_count)
      report_.fail(defaults_pointer, "expected one weight per morph target ({}), got {}", target_count, defaults->size());
    for (size_t t = 0; t < defaults->size(); ++t)
      deformation.default_weights.push_back(read_float_element(report_, *defaults, t, defaults_pointer));
  }
  if (const Json* node = d.find("weights_node")) {
    require_targets("weights_node");
    deformation.weights_node = node_reference(*node, d.pointer_of("weights_node"));
    const AnimationNode& n = scene_.animation.nodes[size_t(deformation.weights_node)];
    if (n.weights_keys && size_t(n.weights_keys->width) != target_count)
      report_.fail(d.pointer_of("weights_node"), "node {} keyframes {} but the mesh has {}", deformation.weights_node,
                   count_of(size_t(n.weights_keys->width), "weight"), count_of(target_count, "morph target"));
  }
  if (deformation.skin < 0 && target_count == 0)
    report_.fail(d.pointer(), "a deformation needs a \"skin\" (with per-vertex \"joints\" and \"weights\") or morph "
                              "targets (\"target_positions\")");
  d.finish();
  deformation_vertices_.push_back(vertices);
  return deformation;
}

// [[[x, y, z] per vertex] per target]; a target without displacements of this kind is [].
std::vector<std::vector<Vec3>> JsonSceneReader::read_morph_targets(const Json& value,
                                                                   const std::string& pointer) const {
  check_is_array(report_, value, pointer, "morph targets (each [[x, y, z] per vertex])");
  std::vector<std::vector<Vec3>> targets;
  for (size_t t = 0; t < value.size(); ++t)
    targets.push_back(read_vec3_list(value[t], child_pointer(pointer, t), "displacements [x, y, z] per vertex"));
  return targets;
}

// ---- keyframes

// {"interpolation": "step" | "linear" | "cubicspline" (default "linear"), "times": [...],
//  "values": [one per time]}; a cubic spline's value is [in-tangent, value, out-tangent].
Keyframes JsonSceneReader::read_keyframes(const Json& value, const std::string& pointer, TrackValue kind) const {
  CheckedObject t(report_, value, pointer);
  Keyframes keys;
  keys.rotation = kind == TrackValue::Rotation;
  keys.width = kind == TrackValue::Number ? 1 : kind == TrackValue::Vec3 ? 3 : kind == TrackValue::Rotation ? 4 : 0;
  if (const Json* interpolation = t.find("interpolation"))
    keys.interpolation = read_enum<Interpolation>(report_, *interpolation, t.pointer_of("interpolation"), "interpolation");
  const bool cubic = keys.interpolation == Interpolation::CubicSpline;

  const Json& times = t.require("times");
  const std::string times_pointer = t.pointer_of("times");
  check_is_array(report_, times, times_pointer, "keyframe times");
  if (times.empty()) report_.fail(times_pointer, "keyframes need at least one time");
  for (size_t k = 0; k < times.size(); ++k) {
    const float time = read_float_element(report_, times, k, times_pointer);
    if (k > 0 && !(time > keys.times.back()))
      report_.fail(child_pointer(times_pointer, k), "keyframe times must increase: time {} ({}) follows {}", k, time,
                   keys.times.back());
    keys.times.push_back(time);
  }

  const Json& values = t.require("values");
  const std::string values_pointer = t.pointer_of("values");
  check_is_array(report_, values, values_pointer, "keyframe values");
  if (values.size() != times.size())
    report_.fail(values_pointer, "{} keyframe times need {} values (one {}per time), got {}", times.size(), times.size(),
                 cubic ? "[in-tangent, value, out-tangent] " : "", values.size());
  for (size_t k = 0; k < values.size(); ++k) {
    const std::string entry_pointer = child_pointer(values_pointer, k);
    if (!cubic) {
      read_track_value(values[k], entry_pointer, kind, false, keys);
      continue;
    }
    // A plain value where a key was expected is an array of numbers too: tell the two apart.
    const bool triple = values[k].is_array() && values[k].size() == 3 &&
                        (kind == TrackValue::Number || std::none_of(values[k].begin(), values[k].end(),
                                                                    [](const Json& v) { return v.is_number(); }));
    if (!triple)
      report_.fail(entry_pointer, "expected [in-tangent, value, out-tangent] (a cubic spline's key), got {}",
                   values[k].is_array() && values[k].size() == 3 ? "an array of 3 numbers" : describe(values[k]));
    for (size_t part = 0; part < 3; ++part)
      read_track_value(values[k][part], child_pointer(entry_pointer, part), kind, part != 1, keys);
  }
  t.finish();
  // The reads above check what they can point at; this catches anything left.
  if (std::string problem = keys.problem(); !problem.empty()) report_.fail(pointer, "{}", problem);
  return keys;
}

// One value (or tangent) of a track appended to keys.values; a weights track takes its width from
// its first value.
void JsonSceneReader::read_track_value(const Json& value, const std::string& pointer, TrackValue kind, bool tangent,
                                       Keyframes& keys) const {
  switch (kind) {
    case TrackValue::Number: keys.values.push_back(read_float(report_, value, pointer)); return;
    case TrackValue::Vec3: {
      const Vec3 v = read_vec3(report_, value, pointer);
      keys.values.insert(keys.values.end(), {v.x, v.y, v.z});
      return;
    }
    case TrackValue::Rotation: {
      // Tangents are rates of change of the quaternion's four numbers, not rotations.
      if (tangent) {
        if (!value.is_array() || value.size() != 4)
          report_.fail(pointer, "expected a quaternion tangent [x, y, z, w], got {}", describe(value));
        for (size_t i = 0; i < 4; ++i) keys.values.push_back(read_float_element(report_, value, i, pointer));
        return;
      }
      const std::array<float, 4> q = read_rotation_value(value, pointer);
      keys.values.insert(keys.values.end(), q.begin(), q.end());
      return;
    }
    case TrackValue::Weights: {
      check_is_array(report_, value, pointer, "morph target weights [w0, w1, ...]");
      if (keys.width == 0) {
        if (value.empty()) report_.fail(pointer, "expected at least one weight (one per morph target)");
        keys.width = int(value.size());
      } else if (value.size() != size_t(keys.width)) {
        report_.fail(pointer, "expected {} weights (one per morph target, as the first key has), got {}", keys.width,
                     value.size());
      }
      for (size_t i = 0; i < value.size(); ++i) keys.values.push_back(read_float_element(report_, value, i, pointer));
      return;
    }
  }
}

// A quaternion [x, y, z, w] (glTF's order), or {"axis": direction, "angle": degrees} about it
// (right-hand rule, as a transform's "rotate" step).
std::array<float, 4> JsonSceneReader::read_rotation_value(const Json& value, const std::string& pointer) const {
  if (value.is_array() && value.size() == 4) {
    std::array<float, 4> q;
    for (size_t i = 0; i < 4; ++i) q[i] = read_float_element(report_, value, i, pointer);
    if (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0)
      report_.fail(pointer, "a rotation quaternion must not be zero ([0, 0, 0, 1] is no rotation)");
    return q;
  }
  if (!value.is_object())
    report_.fail(pointer, "expected a rotation: a quaternion [x, y, z, w] or {{\"axis\": [x, y, z], \"angle\": "
                          "degrees}}, got {}", describe(value));
  CheckedObject r(report_, value, pointer);
  const double degrees = r.number("angle");
  const Vec3 axis = normalize(r.direction("axis"));
  r.finish();
  const double half = degrees * 3.14159265358979323846 / 360;
  const double s = std::sin(half);
  return {float(axis.x * s), float(axis.y * s), float(axis.z * s), float(std::cos(half))};
}

// ---- references from shapes, instances and the camera

int JsonSceneReader::animation_node_of(CheckedObject& object) {
  const Json* node = object.find("animation_node");
  const Json* inline_node = object.find("animation");
  if (node && inline_node)
    report_.fail(object.pointer_of("animation"), "give either \"animation_node\" or an inline \"animation\", not both");
  if (node) return node_reference(*node, object.pointer_of("animation_node"));
  if (!inline_node) return -1;
  // An inline node of its own, after those of "animation": its parent, if any, is one of those.
  const std::string pointer = object.pointer_of("animation");
  AnimationNode n = read_animation_node(*inline_node, pointer);
  const int index = int(scene_.animation.nodes.size());
  if (!n.name.empty()) node_names_[n.name].push_back(index);
  scene_.animation.nodes.push_back(std::move(n));
  node_pointers_.push_back(pointer);
  node_count_ = index + 1;
  return index;
}

int JsonSceneReader::read_deformation_use(const Json& value, CheckedObject& s, const ShapeDesc& shape) const {
  const std::string pointer = s.pointer_of("deformation");
  const std::vector<MeshDeformation>& deformations = scene_.animation.deformations;
  const int64_t index = read_int64(report_, value, pointer);
  if (index < 0 || uint64_t(index) >= deformations.size())
    report_.fail(pointer, "deformation {} is out of range: the scene has {}", index,
                 count_of(deformations.size(), "deformation"));
  const auto* mesh = std::get_if<MeshShape>(&shape.geometry);
  if (!mesh) report_.fail(pointer, "only a triangle mesh deforms");
  const size_t vertices = deformation_vertices_[size_t(index)];
  if (vertices != 0 && vertices != mesh->mesh.positions.size())
    report_.fail(pointer, "deformation {} is for {} vertices but the mesh has {}", index, vertices,
                 mesh->mesh.positions.size());
  // Skinning puts the vertices in world space: nothing else may place them.
  if (deformations[size_t(index)].skin >= 0) {
    auto refuse = [&](std::string_view key) {
      report_.fail(s.pointer_of(key), "a skinned mesh is placed by its skin's joints (its vertices are skinned into "
                                      "world space): it cannot have \"{}\"", key);
    };
    if (!shape.to_world.is_identity()) refuse("transform");
    if (shape.to_world_end) refuse("transform_end");
    if (shape.animation_node >= 0) refuse(s.has("animation") ? "animation" : "animation_node");
  }
  return int(index);
}

std::optional<Keyframes> JsonSceneReader::camera_track(CheckedObject& camera, std::string_view key,
                                                       const ValueRange& bound, float& constant) const {
  const Json* value = camera.find(key);
  if (!value || !value->is_object()) return std::nullopt;
  const std::string pointer = camera.pointer_of(key);
  Keyframes keys = read_keyframes(*value, pointer, TrackValue::Number);
  const size_t stride = keys.interpolation == Interpolation::CubicSpline ? 3 : 1;
  for (size_t k = 0; k < keys.size(); ++k) {
    const float v = keys.values[k * stride + (stride == 3 ? 1 : 0)];
    if (!bound.contains(v)) report_.fail(value_pointer(pointer, keys, k), "expected {}, got {}", bound.expected(), v);
  }
  constant = *first_value(keys);
  return keys;
}

}  // namespace candela::json
