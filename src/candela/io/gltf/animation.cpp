// The glTF reader: animations (node translation, rotation, scale and morph weight channels), skins
// and morph targets, into SceneDesc::animation (animation/keyframes.h), which shares glTF's model:
// one AnimationNode per glTF node (same index), a Skin per skin and a MeshDeformation per skinned
// or morphing primitive where a node places it.
#include <algorithm>
#include <cmath>

#include "candela/io/gltf/reader.h"

namespace candela::gltf {

bool GltfReader::file_animates() const {
  if (!model_.animations.empty() || !model_.skins.empty()) return true;
  for (const tg::Mesh& mesh : model_.meshes)
    for (const tg::Primitive& prim : mesh.primitives)
      if (!prim.targets.empty()) return true;
  return false;
}

void GltfReader::build_animation() {
  if (!file_animates()) return;
  SceneAnimation& animation = scene_.animation;
  const size_t count = model_.nodes.size();
  animation.nodes.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const tg::Node& node = model_.nodes[i];
    const std::string pointer = fmt::format("/nodes/{}", i);
    AnimationNode& a = animation.nodes[i];
    a.name = node.name.empty() ? pointer : node.name;
    if (node.matrix.size() == 16) {
      a.matrix = matrix_from_column_major(node.matrix);
    } else {
      if (!node.matrix.empty()) fail(pointer + "/matrix", "expected 16 numbers, got {}", node.matrix.size());
      // As local_matrix reads them: wrongly sized properties keep their defaults.
      if (node.translation.size() == 3)
        for (size_t c = 0; c < 3; ++c) a.trs.translation[c] = float(node.translation[c]);
      if (node.rotation.size() == 4)
        for (size_t c = 0; c < 4; ++c) a.trs.rotation[c] = float(node.rotation[c]);
      if (node.scale.size() == 3)
        for (size_t c = 0; c < 3; ++c) a.trs.scale[c] = float(node.scale[c]);
    }
  }
  // Parents from the children lists: the nodes form a forest (a node has one parent at most).
  for (size_t i = 0; i < count; ++i) {
    const std::vector<int>& children = model_.nodes[i].children;
    for (size_t c = 0; c < children.size(); ++c) {
      const std::string pointer = fmt::format("/nodes/{}/children/{}", i, c);
      const int child = children[c];
      if (child < 0 || size_t(child) >= count) fail(pointer, "node {} does not exist (the file has {})", child, count);
      int& parent = animation.nodes[size_t(child)].parent;
      if (parent >= 0) fail(pointer, "node {} is a child of both node {} and node {} (glTF's nodes form trees)", child, parent, i);
      parent = int(i);
    }
  }
  for (size_t i = 0; i < count; ++i) {
    size_t steps = 0;
    for (int p = animation.nodes[i].parent; p >= 0; p = animation.nodes[size_t(p)].parent)
      if (++steps > count) fail(fmt::format("/nodes/{}", i), "the node hierarchy has a cycle through this node");
  }
  read_channels();
  read_skins();
  if (const std::string problem = animation.problem(); !problem.empty()) fail("", "animation: {}", problem);
}

// Every animation of the file plays at once, each from its own keyframe times (a renderer has no
// way to pick a clip yet). A target (node and property) keyed by more than one channel keeps the
// first channel's keyframes, with a warning.
void GltfReader::read_channels() {
  SceneAnimation& animation = scene_.animation;
  const size_t count = model_.nodes.size();
  std::map<std::pair<int, std::string>, std::string> keyed_by;  // target -> the channel's pointer
  for (size_t a = 0; a < model_.animations.size(); ++a) {
    const tg::Animation& anim = model_.animations[a];
    for (size_t c = 0; c < anim.channels.size(); ++c) {
      const tg::AnimationChannel& channel = anim.channels[c];
      const std::string where = fmt::format("/animations/{}/channels/{}", a, c);
      const std::string& path = channel.target_path;
      if (path != "translation" && path != "rotation" && path != "scale" && path != "weights") {
        warn(where + "/target/path", "animating \"{}\" is not supported; the channel is ignored", path);
        continue;
      }
      const int n = channel.target_node;
      if (n < 0 || size_t(n) >= count) fail(where + "/target/node", "node {} does not exist (the file has {})", n, count);
      if (channel.sampler < 0 || size_t(channel.sampler) >= anim.samplers.size())
        fail(where + "/sampler", "sampler {} does not exist (the animation has {})", channel.sampler, anim.samplers.size());
      AnimationNode& target = animation.nodes[size_t(n)];
      if (target.matrix)
        fail(where + "/target/node", "node {} has a matrix, which animations cannot target (only translation, rotation "
             "and scale)", n);
      int width = path == "rotation" ? 4 : 3;
      if (path == "weights") {
        const int mesh = model_.nodes[size_t(n)].mesh;
        width = mesh >= 0 && size_t(mesh) < model_.meshes.size() ? morph_target_count(mesh) : 0;
        if (width == 0) fail(where + "/target", "node {} has no mesh with morph targets to weight", n);
      }
      auto [first, fresh] = keyed_by.emplace(std::pair(n, path), where);
      if (!fresh) {
        warn(where, "node {}'s {} is also animated by {}; that channel's keyframes are used", n, path, first->second);
        continue;
      }
      Keyframes keys = read_keyframes(anim.samplers[size_t(channel.sampler)], path, width,
                                      fmt::format("/animations/{}/samplers/{}", a, channel.sampler));
      if (path == "translation") target.trs.translation_keys = std::move(keys);
      else if (path == "rotation") target.trs.rotation_keys = std::move(keys);
      else if (path == "scale") target.trs.scale_keys = std::move(keys);
      else target.weights_keys = std::move(keys);
    }
  }
}

Keyframes GltfReader::read_keyframes(const tg::AnimationSampler& sampler, const std::string& path, int width,
                                     const std::string& pointer) {
  Keyframes keys;
  keys.width = width;
  keys.rotation = path == "rotation";
  const std::string& how = sampler.interpolation;
  if (how.empty() || how == "LINEAR") keys.interpolation = Interpolation::Linear;
  else if (how == "STEP") keys.interpolation = Interpolation::Step;
  else if (how == "CUBICSPLINE") keys.interpolation = Interpolation::CubicSpline;
  else fail(pointer + "/interpolation", "unknown interpolation \"{}\" (LINEAR, STEP or CUBICSPLINE)", how);
  const AccessorData input = read_accessor(sampler.input, pointer + "/input");
  if (input.components != 1) fail(pointer + "/input", "keyframe times must be SCALAR, got {} components", input.components);
  // Morph weights come as scalars, `width` per key; the others as one VEC3 or VEC4 per key.
  const bool weights = path == "weights";
  const int components = weights ? 1 : width;
  const AccessorData output = read_accessor(sampler.output, pointer + "/output");
  if (output.components != components)
    fail(pointer + "/output", "the target needs {} values, got {} components", components == 1 ? "SCALAR"
         : components == 3 ? "VEC3" : "VEC4", output.components);
  const size_t per_key = (weights ? size_t(width) : 1) * (keys.interpolation == Interpolation::CubicSpline ? 3 : 1);
  if (output.count != input.count * per_key)
    fail(pointer, "{} keyframe times need {} output elements ({} per time{}), got {}", input.count,
         input.count * per_key, per_key,
         keys.interpolation == Interpolation::CubicSpline ? ": in-tangent, value, out-tangent" : "", output.count);
  keys.times.reserve(input.values.size());
  for (double t : input.values) keys.times.push_back(float(t));
  keys.values.reserve(output.values.size());
  for (double v : output.values) keys.values.push_back(float(v));
  if (const std::string problem = keys.problem(); !problem.empty()) fail(pointer, "{}", problem);
  return keys;
}

void GltfReader::read_skins() {
  SceneAnimation& animation = scene_.animation;
  for (size_t s = 0; s < model_.skins.size(); ++s) {
    const tg::Skin& skin = model_.skins[s];
    const std::string pointer = fmt::format("/skins/{}", s);
    Skin out;
    out.name = skin.name.empty() ? std::to_string(s) : skin.name;
    // Vertices name joints by 16-bit indices at most.
    if (skin.joints.size() > 65536) fail(pointer + "/joints", "{} joints are more than 65536", skin.joints.size());
    for (size_t j = 0; j < skin.joints.size(); ++j)
      if (skin.joints[j] < 0 || size_t(skin.joints[j]) >= model_.nodes.size())
        fail(fmt::format("{}/joints/{}", pointer, j), "node {} does not exist (the file has {})", skin.joints[j],
             model_.nodes.size());
    out.joints = skin.joints;
    if (skin.inverseBindMatrices >= 0) {
      const std::string where = pointer + "/inverseBindMatrices";
      const AccessorData ibm = read_accessor(skin.inverseBindMatrices, where);
      if (ibm.components != 16) fail(where, "inverse bind matrices must be MAT4, got {} components", ibm.components);
      if (ibm.count < skin.joints.size())
        fail(where, "the skin has {} joints but only {} inverse bind matrices", skin.joints.size(), ibm.count);
      for (size_t j = 0; j < skin.joints.size(); ++j)
        out.inverse_bind.push_back(matrix_from_column_major(
            std::vector<double>(ibm.values.begin() + std::ptrdiff_t(16 * j), ibm.values.begin() + std::ptrdiff_t(16 * j + 16))));
    } else {
      out.inverse_bind.assign(skin.joints.size(), Matrix4::identity());  // the specification's default
    }
    animation.skins.push_back(std::move(out));
  }
}

int GltfReader::morph_target_count(int m) {
  const tg::Mesh& mesh = model_.meshes[size_t(m)];
  if (mesh.primitives.empty()) return 0;
  const size_t targets = mesh.primitives[0].targets.size();
  for (size_t p = 1; p < mesh.primitives.size(); ++p)
    if (mesh.primitives[p].targets.size() != targets)
      fail(fmt::format("/meshes/{}/primitives/{}/targets", m, p),
           "the primitive has {} morph targets but primitive 0 has {} (they must have the same number)",
           mesh.primitives[p].targets.size(), targets);
  return int(targets);
}

void GltfReader::read_skinning_attributes(const tg::Primitive& prim, const std::string& pointer, Primitive& result) {
  const size_t n = result.mesh.positions.size();
  std::vector<AccessorData> joint_sets, weight_sets;
  for (int set = 0;; ++set) {
    const std::string joints_name = fmt::format("JOINTS_{}", set), weights_name = fmt::format("WEIGHTS_{}", set);
    auto joints = prim.attributes.find(joints_name);
    auto weights = prim.attributes.find(weights_name);
    if (joints == prim.attributes.end() && weights == prim.attributes.end()) break;
    if (joints == prim.attributes.end() || weights == prim.attributes.end())
      fail(pointer + "/attributes", "{} needs {} beside it", joints == prim.attributes.end() ? weights_name : joints_name,
           joints == prim.attributes.end() ? joints_name : weights_name);
    joint_sets.push_back(read_accessor(joints->second, pointer + "/attributes/" + joints_name));
    weight_sets.push_back(read_accessor(weights->second, pointer + "/attributes/" + weights_name));
    auto check = [&](const AccessorData& data, const std::string& name) {
      if (data.components != 4 || data.count != n)
        fail(pointer + "/attributes/" + name, "{} must be VEC4, one per position ({}), got {} of {} components", name,
             n, data.count, data.components);
    };
    check(joint_sets.back(), joints_name);
    check(weight_sets.back(), weights_name);
  }
  if (joint_sets.empty()) return;
  const size_t k = 4 * joint_sets.size();
  result.influences = int(k);
  result.joints.assign(n * k, 0);
  result.weights.assign(n * k, 0.0f);
  for (size_t set = 0; set < joint_sets.size(); ++set)
    for (size_t v = 0; v < n; ++v)
      for (int c = 0; c < 4; ++c) {
        const double joint = joint_sets[set].at(v, c), weight = weight_sets[set].at(v, c);
        if (!(joint >= 0 && joint <= 65535 && joint == std::floor(joint)))
          fail(fmt::format("{}/attributes/JOINTS_{}", pointer, set), "vertex {} names joint {}", v, joint);
        if (!std::isfinite(weight))
          fail(fmt::format("{}/attributes/WEIGHTS_{}", pointer, set), "vertex {} has weight {}", v, weight);
        const size_t i = v * k + 4 * set + size_t(c);
        // An unused influence (weight 0) may name any joint: keep it in range.
        result.joints[i] = weight == 0 ? 0 : uint16_t(joint);
        result.weights[i] = float(weight);
      }
}

void GltfReader::read_morph_targets(const tg::Primitive& prim, const std::string& pointer, Primitive& result) {
  const size_t n = result.mesh.positions.size();
  bool any_normals = false;
  for (size_t t = 0; t < prim.targets.size(); ++t) {
    const std::map<std::string, int>& target = prim.targets[t];
    auto displacements = [&](const char* name) {
      std::vector<Vec3> out;
      auto it = target.find(name);
      if (it == target.end()) return out;
      const std::string where = fmt::format("{}/targets/{}/{}", pointer, t, name);
      const AccessorData data = read_accessor(it->second, where);
      if (data.components != 3 || data.count != n)
        fail(where, "{} must be VEC3, one per position ({}), got {} of {} components", name, n, data.count,
             data.components);
      out.resize(n);
      for (size_t v = 0; v < n; ++v) out[v] = Vec3(float(data.at(v, 0)), float(data.at(v, 1)), float(data.at(v, 2)));
      return out;
    };
    // Tangent displacements are not read: candela derives tangents itself.
    result.target_positions.push_back(displacements("POSITION"));
    result.target_normals.push_back(displacements("NORMAL"));
    any_normals |= !result.target_normals.back().empty();
  }
  if (!any_normals) result.target_normals.clear();
}

int GltfReader::add_deformation(const MeshUse& use, const Primitive& p) {
  SceneAnimation& animation = scene_.animation;
  MeshDeformation d;
  if (use.skin >= 0) {
    if (p.influences == 0)
      fail(p.pointer + "/attributes", "the mesh is skinned (by {}/skin) but the primitive has no JOINTS_0 and WEIGHTS_0",
           use.pointer);
    const size_t joints = animation.skins[size_t(use.skin)].joints.size();
    const size_t k = size_t(p.influences);
    for (size_t i = 0; i < p.joints.size(); ++i)
      if (p.joints[i] >= joints)
        fail(fmt::format("{}/attributes/JOINTS_{}", p.pointer, (i % k) / 4),
             "vertex {} names joint {}, but skin {} (of {}/skin) has {} joints", i / k, p.joints[i], use.skin,
             use.pointer, joints);
    d.skin = use.skin;
    d.influences = p.influences;
    d.joints = p.joints;
    d.weights = p.weights;
  }
  if (!p.target_positions.empty()) {
    const tg::Node& node = model_.nodes[size_t(use.node)];
    const tg::Mesh& mesh = model_.meshes[size_t(use.mesh)];
    const size_t targets = p.target_positions.size();
    // The node's weights override the mesh's; none: every target at weight 0.
    const bool from_node = !node.weights.empty();
    const std::vector<double>& weights = from_node ? node.weights : mesh.weights;
    if (!weights.empty() && weights.size() != targets)
      fail(from_node ? use.pointer + "/weights" : fmt::format("/meshes/{}/weights", use.mesh),
           "{} weights for {} morph targets", weights.size(), targets);
    d.default_weights.assign(targets, 0.0f);
    for (size_t t = 0; t < weights.size(); ++t) d.default_weights[t] = float(weights[t]);
    d.target_positions = p.target_positions;
    d.target_normals = p.target_normals;
    d.weights_node = use.node;
  }
  if (d.skin < 0 && d.target_positions.empty()) return -1;
  animation.deformations.push_back(std::move(d));
  return int(animation.deformations.size()) - 1;
}

std::vector<float> GltfReader::framing_times() const {
  // Enough instants over the animation for the framing to hold the whole motion (the keyframed
  // paths between them are smooth at this scale).
  const auto [start, end] = scene_.animation.time_range();
  std::vector<float> times;
  constexpr int kSteps = 32;
  for (int i = 0; i <= kSteps; ++i) times.push_back(start + (end - start) * float(i) / kSteps);
  return times;
}

std::vector<Transform> GltfReader::placements_over_time(const MeshUse& use) const {
  if (use.animation_node < 0) return {use.to_world};
  std::vector<Transform> placements;
  for (float t : framing_times())
    if (auto T = Transform::from_matrix(scene_.animation.world_matrix(use.animation_node, t) * use.to_world.matrix()))
      placements.push_back(*T);
  return placements;
}

}  // namespace candela::gltf
