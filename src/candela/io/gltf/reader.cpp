// The glTF reader: loading (tinygltf), accessors and the node tree.
// tinygltf's implementation lives here (see CMakeLists.txt for why it is not linked from
// libtinygltf.so).
#define TINYGLTF_IMPLEMENTATION
#include "candela/io/gltf/reader.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <system_error>
#include <type_traits>

namespace candela::gltf {
namespace {

// The extensions this reader implements (or, for KHR_materials_unlit, approximates); a file that
// requires any other is refused, as the specification asks.
const std::set<std::string> kSupportedExtensions = {
    "KHR_texture_transform",       "KHR_materials_emissive_strength", "KHR_lights_punctual",
    "KHR_materials_transmission",  "KHR_materials_ior",               "KHR_mesh_quantization",
    "KHR_materials_unlit",         "EXT_mesh_gpu_instancing"};


}  // namespace

// ---------------------------------------------------------------- small helpers

uint64_t fnv1a(std::string_view bytes, uint64_t h) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

// %XX escapes of a URI reference decoded (glTF URIs are RFC 3986 references).
std::string uri_decode(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) &&
        std::isxdigit((unsigned char)uri[i + 2])) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

Matrix4 matrix_from_column_major(const std::vector<double>& a) {
  Matrix4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.m[r][c] = a[size_t(c * 4 + r)];
  return m;
}

RGB rgb_of(const std::vector<double>& v, RGB fallback) {
  if (v.size() < 3) return fallback;
  return RGB(float(v[0]), float(v[1]), float(v[2]));
}

// A number from a tinygltf Value (ints and reals both), or `fallback`.
double number_or(const tg::Value& object, const char* key, double fallback) {
  if (!object.IsObject() || !object.Has(key)) return fallback;
  const tg::Value& v = object.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

SceneDesc GltfReader::read() {
  load();
  check_extensions();
  scene_.settings.sampler.type = SamplerType::ZSobol;  // as the other readers do when a file names none
  build_animation();
  walk_scene();
  build_meshes();
  add_camera();
  add_lights();
  return std::move(scene_);
}

// ---------------------------------------------------------------- messages

SourceLocation GltfReader::at(const std::string& pointer) const { return {file_.string(), 0, 0, pointer}; }
                              
                              // ---------------------------------------------------------------- loading
                              
// Keeps the encoded bytes of embedded images (data URIs, buffer views); images in files of their
                              // own are read later by OpenImageIO from the file itself.
bool GltfReader::keep_image_bytes(tg::Image* image, const int, std::string*, std::string*, int, int,
                              const unsigned char* bytes, int size, void*) {
  if (image->uri.empty()) image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

void GltfReader::load() {
  tg::TinyGLTF loader;
  loader.SetImageLoader(&GltfReader::keep_image_bytes, nullptr);
  std::string err, warn_text;
  std::string ext = file_.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  bool ok;
  // tinygltf throws nothing but may report through both strings.
  if (ext == ".glb")
    ok = loader.LoadBinaryFromFile(&model_, &err, &warn_text, file_.string());
  else
    ok = loader.LoadASCIIFromFile(&model_, &err, &warn_text, file_.string());
  auto lines = [](const std::string& text) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start < text.size()) {
      size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      std::string line = text.substr(start, end - start);
      if (!line.empty()) out.push_back(line);
      start = end + 1;
    }
    return out;
  };
  for (const std::string& line : lines(warn_text)) {
    if (line.starts_with("Failed to load external 'uri' for image")) continue;  // checked where used
    warn("", "{}", line);
  }
  std::vector<std::string> errors = lines(err);
  // tinygltf wants every skin to have inverseBindMatrices; the specification makes them optional
  // (identity matrices when absent), and the skin is read as it says.
  std::erase_if(errors, [](const std::string& line) {
    return line.starts_with("'inverseBindMatrices' property is missing");
  });
  if (!ok || !errors.empty()) {
    // tinygltf stops at a Draco primitive's missing buffer view before the extensions can be
    // checked: say what the file needs instead.
    refuse_draco_from_raw_json(ext == ".glb");
    std::string message;
    for (size_t i = 0; i < errors.size(); ++i) message += (i ? "; " : "") + errors[i];
    if (message.empty()) message = "tinygltf could not load the file";
    fail("", "cannot read glTF: {}", message);
  }
}

// The file's JSON (a .glb's first chunk) read again with nlohmann, when tinygltf has failed: a
// file requiring KHR_draco_mesh_compression is refused naming its first compressed mesh.
void GltfReader::refuse_draco_from_raw_json(bool binary) {
  std::ifstream in(file_, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string text = bytes;
  if (binary) {
    if (bytes.size() < 20) return;
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    if (bytes.compare(16, 4, "JSON") != 0 || size_t(length) > bytes.size() - 20) return;
    text = bytes.substr(20, length);
  }
  nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("extensionsRequired")) return;
  const nlohmann::json& required = j["extensionsRequired"];
  if (!required.is_array() || std::find(required.begin(), required.end(), "KHR_draco_mesh_compression") == required.end())
    return;
  if (j.contains("meshes") && j["meshes"].is_array())
    for (size_t m = 0; m < j["meshes"].size(); ++m) {
      const nlohmann::json& mesh = j["meshes"][m];
      if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
      for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
        const nlohmann::json& prim = mesh["primitives"][p];
        if (prim.is_object() && prim.contains("extensions") && prim["extensions"].is_object() &&
            prim["extensions"].contains("KHR_draco_mesh_compression"))
          fail(fmt::format("/meshes/{}/primitives/{}", m, p), "{}", draco_message(mesh.value("name", std::string())));
      }
    }
  fail("/extensionsRequired", "the file requires KHR_draco_mesh_compression, which candela does not decode");
}

std::string GltfReader::draco_message(const std::string& mesh) {
  return fmt::format("mesh \"{}\" is Draco-compressed (KHR_draco_mesh_compression), which candela does not "
                     "decode; convert the file to uncompressed glTF first (e.g. gltf-transform copy)", mesh);
}

void GltfReader::check_extensions() {
  for (const std::string& name : model_.extensionsRequired) {
    if (name == "KHR_draco_mesh_compression") {
      for (size_t m = 0; m < model_.meshes.size(); ++m)
        for (size_t p = 0; p < model_.meshes[m].primitives.size(); ++p)
          if (model_.meshes[m].primitives[p].extensions.count(name))
            fail(fmt::format("/meshes/{}/primitives/{}", m, p), "{}", draco_message(model_.meshes[m].name));
      fail("/extensionsRequired", "the file requires KHR_draco_mesh_compression, which candela does not decode");
    }
    if (!kSupportedExtensions.count(name))
      fail("/extensionsRequired", "the file requires the extension {}, which candela does not support", name);
  }
  for (const std::string& name : model_.extensionsUsed)
    if (!kSupportedExtensions.count(name) && name != "KHR_draco_mesh_compression")
      warn("/extensionsUsed", "extension {} is not supported and is ignored", name);
}

// ---------------------------------------------------------------- accessors

AccessorData GltfReader::read_accessor(int index, const std::string& user) {
  if (index < 0 || size_t(index) >= model_.accessors.size())
    fail(user, "accessor {} does not exist (the file has {})", index, model_.accessors.size());
  const tg::Accessor& a = model_.accessors[size_t(index)];
  const std::string pointer = fmt::format("/accessors/{}", index);
  const int components = tg::GetNumComponentsInType(uint32_t(a.type));
  const int size = tg::GetComponentSizeInBytes(uint32_t(a.componentType));
  if (components <= 0 || components > 16) fail(pointer, "unknown accessor type {}", a.type);
  if (size <= 0) fail(pointer, "unknown component type {}", a.componentType);
  // MAT4 (a skin's inverse bind matrices) has no column padding; MAT2 and MAT3 of small components
  // would, and nothing candela reads uses them.
  if (a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3)
    fail(pointer, "MAT2 and MAT3 accessors are not used by anything candela reads");
  AccessorData data;
  data.components = components;
  data.count = a.count;
  data.values.assign(a.count * size_t(components), 0.0);
  if (a.bufferView >= 0) {
    const std::byte* base = nullptr;
    size_t stride = 0, available = 0;
    view_bytes(a.bufferView, a.byteOffset, pointer, base, available);
    stride = model_.bufferViews[size_t(a.bufferView)].byteStride;
    const size_t element = size_t(components) * size_t(size);
    if (stride == 0) stride = element;
    if (stride < element) fail(pointer, "byteStride {} is smaller than an element ({} bytes)", stride, element);
    if (a.count > 0 && (a.count - 1) * stride + element > available)
      fail(pointer, "{} elements of {} bytes with stride {} run past the end of buffer view {}", a.count, element,
           stride, a.bufferView);
    for (size_t i = 0; i < a.count; ++i)
      decode(base + i * stride, a.componentType, a.normalized, components, &data.values[i * size_t(components)]);
  }
  if (a.sparse.isSparse) {
    const size_t count = size_t(std::max(a.sparse.count, 0));
    const int index_size = tg::GetComponentSizeInBytes(uint32_t(a.sparse.indices.componentType));
    if (index_size <= 0) fail(pointer + "/sparse/indices", "unknown component type");
    const std::byte* ib = nullptr;
    const std::byte* vb = nullptr;
    size_t iavail = 0, vavail = 0;
    view_bytes(a.sparse.indices.bufferView, size_t(a.sparse.indices.byteOffset), pointer + "/sparse/indices", ib,
               iavail);
    view_bytes(a.sparse.values.bufferView, size_t(a.sparse.values.byteOffset), pointer + "/sparse/values", vb,
               vavail);
    const size_t element = size_t(components) * size_t(size);
    if (count * size_t(index_size) > iavail || count * element > vavail)
      fail(pointer + "/sparse", "{} sparse elements run past the end of their buffer views", count);
    for (size_t i = 0; i < count; ++i) {
      double target = 0;
      decode(ib + i * size_t(index_size), a.sparse.indices.componentType, false, 1, &target);
      if (target < 0 || size_t(target) >= a.count)
        fail(pointer + "/sparse/indices", "sparse index {} is out of range (count {})", target, a.count);
      decode(vb + i * element, a.componentType, a.normalized, components,
             &data.values[size_t(target) * size_t(components)]);
    }
  }
  return data;
}

// The bytes of buffer view `view` from `offset` on, checked against the view and its buffer.
void GltfReader::view_bytes(int view, size_t offset, const std::string& user, const std::byte*& base, size_t& available) {
  if (view < 0 || size_t(view) >= model_.bufferViews.size())
    fail(user, "buffer view {} does not exist (the file has {})", view, model_.bufferViews.size());
  const tg::BufferView& v = model_.bufferViews[size_t(view)];
  if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size())
    fail(fmt::format("/bufferViews/{}", view), "buffer {} does not exist", v.buffer);
  const tg::Buffer& b = model_.buffers[size_t(v.buffer)];
  if (v.byteOffset + v.byteLength > b.data.size() || v.byteOffset + v.byteLength < v.byteOffset)
    fail(fmt::format("/bufferViews/{}", view), "bytes {}..{} lie outside buffer {} ({} bytes)", v.byteOffset,
         v.byteOffset + v.byteLength, v.buffer, b.data.size());
  if (offset > v.byteLength) fail(user, "byteOffset {} lies outside buffer view {}", offset, view);
  base = reinterpret_cast<const std::byte*>(b.data.data()) + v.byteOffset + offset;
  available = v.byteLength - offset;
}

namespace {
// Component c of an array of T's (unaligned), mapped to [0, 1] or [-1, 1] where `normalized`
// applies (8- and 16-bit integers; glTF's normalized signed ints clamp -max - 1 to -1).
template <class T>
double component(const std::byte* p, int c, bool normalized) {
  T x;
  std::memcpy(&x, p + sizeof(T) * c, sizeof(T));
  double v = x;
  if constexpr (std::is_integral_v<T> && sizeof(T) <= 2) {
    constexpr double max = std::numeric_limits<T>::max();
    if (normalized) v = std::is_signed_v<T> ? std::max(v / max, -1.0) : v / max;
  }
  return v;
}
}  // namespace

void GltfReader::decode(const std::byte* p, int type, bool normalized, int n, double* out) {
  for (int c = 0; c < n; ++c) {
    double v = 0;
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_BYTE: v = component<int8_t>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = component<uint8_t>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_SHORT: v = component<int16_t>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: v = component<uint16_t>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_INT: v = component<int32_t>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: v = component<uint32_t>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_FLOAT: v = component<float>(p, c, normalized); break;
      case TINYGLTF_COMPONENT_TYPE_DOUBLE: v = component<double>(p, c, normalized); break;
      default: break;
    }
    out[c] = v;
  }
}

// ---------------------------------------------------------------- the node tree

Matrix4 GltfReader::local_matrix(const tg::Node& node, const std::string& pointer) {
  if (node.matrix.size() == 16) return matrix_from_column_major(node.matrix);
  if (!node.matrix.empty()) fail(pointer + "/matrix", "expected 16 numbers, got {}", node.matrix.size());
  std::array<double, 3> t{0, 0, 0}, s{1, 1, 1};
  std::array<double, 4> q{0, 0, 0, 1};
  if (node.translation.size() == 3) std::copy(node.translation.begin(), node.translation.end(), t.begin());
  if (node.rotation.size() == 4) std::copy(node.rotation.begin(), node.rotation.end(), q.begin());
  if (node.scale.size() == 3) std::copy(node.scale.begin(), node.scale.end(), s.begin());
  return trs_matrix(t, q, s);
}

void GltfReader::walk_scene() {
  int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
  if (model_.scenes.empty()) {
    // A file without scenes is a library of assets; render its root nodes as a scene would.
    warn("", "the file has no scenes; rendering every root node");
    std::vector<bool> child(model_.nodes.size(), false);
    for (const tg::Node& n : model_.nodes)
      for (int c : n.children)
        if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = true;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (!child[i]) roots_.push_back(int(i));
  } else {
    if (size_t(scene) >= model_.scenes.size()) fail("/scene", "scene {} does not exist", scene);
    roots_ = model_.scenes[size_t(scene)].nodes;
  }
  on_path_.assign(model_.nodes.size(), false);
  for (int root : roots_) visit(root, Matrix4::identity(), 0, fmt::format("/scenes/{}/nodes", scene));
}

void GltfReader::visit(int index, const Matrix4& parent, int depth, const std::string& from) {
  if (index < 0 || size_t(index) >= model_.nodes.size())
    fail(from, "node {} does not exist (the file has {})", index, model_.nodes.size());
  const std::string pointer = fmt::format("/nodes/{}", index);
  if (on_path_[size_t(index)]) fail(pointer, "the node hierarchy has a cycle through this node");
  if (depth > kMaxNodeDepth) fail(pointer, "the node hierarchy is deeper than {}", kMaxNodeDepth);
  const tg::Node& node = model_.nodes[size_t(index)];
  const Matrix4 world = parent * local_matrix(node, pointer);
  // A node whose world transform is keyframed (it or an ancestor) places what it holds through
  // SceneAnimation: what it holds gets the node and a transform relative to it. Its rest transform
  // may then be singular (a scale keyed from 0 to make it appear).
  const bool moves = !scene_.animation.empty() && scene_.animation.node_moves(index);
  std::optional<Transform> T = Transform::from_matrix(world);
  if (!T && !moves) {
    warn(pointer, "the node's world transform is singular (a zero scale); it and its children are skipped");
    return;
  }
  if (node.camera >= 0) {
    if (!camera_) camera_ = moves ? NodeRef{node.camera, Transform(), pointer, index} : NodeRef{node.camera, *T, pointer};
    else ++other_cameras_;
  }
  auto light = node.extensions.find("KHR_lights_punctual");
  if (light != node.extensions.end() && light->second.Has("light")) {
    if (moves)
      warn(pointer, "animated lights are not supported yet: the light stays where its node is at rest");
    if (T)
      lights_.push_back({int(light->second.Get("light").GetNumberAsInt()), *T, pointer});
    else
      warn(pointer, "the light's node has a singular rest transform (a zero scale); the light is skipped");
  }
  if (node.mesh >= 0) {
    if (size_t(node.mesh) >= model_.meshes.size()) fail(pointer + "/mesh", "mesh {} does not exist", node.mesh);
    MeshUse use{node.mesh, moves ? Transform() : T.value_or(Transform()), pointer, index, moves ? index : -1};
    if (!scene_.animation.empty()) {
      if (node.skin >= 0) {
        if (size_t(node.skin) >= model_.skins.size()) fail(pointer + "/skin", "skin {} does not exist", node.skin);
        // glTF ignores a skinned mesh's node transform: the joints place the vertices in the world.
        use.skin = node.skin;
        use.to_world = Transform();
        use.animation_node = -1;
      }
      use.deforms = use.skin >= 0 || morph_target_count(node.mesh) > 0;
    }
    auto instancing = node.extensions.find("EXT_mesh_gpu_instancing");
    if (instancing != node.extensions.end() && use.deforms)
      warn(pointer + "/extensions/EXT_mesh_gpu_instancing",
           "a skinned or morphing mesh is not instanced: one copy is placed where its node is");
    if (instancing != node.extensions.end() && !use.deforms)
      add_gpu_instances(node, moves ? Matrix4::identity() : world, instancing->second, pointer, use.animation_node);
    else
      uses_.push_back(std::move(use));
  }
  on_path_[size_t(index)] = true;
  for (int child : node.children) visit(child, world, depth + 1, pointer + "/children");
  on_path_[size_t(index)] = false;
}

// `world`: the node's world transform, or the identity when animation_node places the instances.
void GltfReader::add_gpu_instances(const tg::Node& node, const Matrix4& world, const tg::Value& ext, const std::string& pointer,
                                   int animation_node) {
  const std::string where = pointer + "/extensions/EXT_mesh_gpu_instancing";
  const tg::Value& attributes = ext.Get("attributes");
  std::optional<AccessorData> t, r, s;
  size_t count = 0;
  bool any = false;
  auto get = [&](const char* name, std::optional<AccessorData>& out, int components) {
    if (!attributes.IsObject() || !attributes.Has(name)) return;
    out = read_accessor(int(attributes.Get(name).GetNumberAsInt()), where + "/attributes/" + name);
    if (out->components != components) fail(where + "/attributes/" + name, "expected {} components", components);
    if (any && out->count != count) fail(where, "the instance attributes have different counts");
    count = out->count;
    any = true;
  };
  get("TRANSLATION", t, 3);
  get("ROTATION", r, 4);
  get("SCALE", s, 3);
  for (const auto& [name, _] : attributes.IsObject() ? attributes.Get<tg::Value::Object>() : tg::Value::Object())
    if (name != "TRANSLATION" && name != "ROTATION" && name != "SCALE")
      warn(where + "/attributes/" + name, "instance attribute {} is ignored", name);
  for (size_t i = 0; i < count; ++i) {
    std::array<double, 3> tt{0, 0, 0}, ss{1, 1, 1};
    std::array<double, 4> qq{0, 0, 0, 1};
    for (int c = 0; c < 3; ++c) {
      if (t) tt[size_t(c)] = t->at(i, c);
      if (s) ss[size_t(c)] = s->at(i, c);
    }
    if (r)
      for (int c = 0; c < 4; ++c) qq[size_t(c)] = r->at(i, c);
    std::optional<Transform> T = Transform::from_matrix(world * trs_matrix(tt, qq, ss));
    if (!T) continue;  // a zero-scaled instance is hidden
    uses_.push_back({node.mesh, *T, fmt::format("{}[{}]", where, i), -1, animation_node});
  }
}

}  // namespace candela::gltf
