// Reader for glTF 2.0 files (.gltf with its buffers and images, or one .glb), through Debian's shared
// tinygltf library (docs/gltf-format.md has what is supported and how it maps).
//
// tinygltf parses the JSON and loads the buffers; this file walks the default scene's node tree and
// turns meshes, materials, cameras and KHR_lights_punctual lights into a SceneDesc. Images are not
// decoded by tinygltf (a loader callback keeps the encoded bytes): candela's TextureSet reads them
// with OpenImageIO from files, so images embedded in the file, and images derived from the file's
// ones where candela has no texture operation for what glTF asks (one channel of a texture, an
// alpha mask, a colour factor times a texture, a scaled normal map), are written once to a cache
// directory. Errors name the file and the element by JSON pointer (file: at /meshes/2/primitives/0:
// ...); what candela approximates or ignores is a warning in the same form.
#include "candela/io/gltf_reader.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <unistd.h>

// tinygltf's implementation lives here (see CMakeLists.txt for why it is not linked from
// libtinygltf.so), without its stb_image decoding: images are only located, never decoded, by it.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/pbrt_reader.h"  // print_pbrt_warnings: the same one-line warnings

namespace candela {
namespace {

namespace fs = std::filesystem;
namespace tg = tinygltf;

constexpr int kMaxNodeDepth = 1024;
constexpr int kMaxResolution = 65536;

// The extensions this reader implements (or, for KHR_materials_unlit, approximates); a file that
// requires any other is refused, as the specification asks.
const std::set<std::string> kSupportedExtensions = {
    "KHR_texture_transform",       "KHR_materials_emissive_strength", "KHR_lights_punctual",
    "KHR_materials_transmission",  "KHR_materials_ior",               "KHR_mesh_quantization",
    "KHR_materials_unlit",         "EXT_mesh_gpu_instancing"};

// ---------------------------------------------------------------- small helpers

uint64_t fnv1a(std::string_view bytes, uint64_t h = 1469598103934665603ULL) {
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

// T * R * S as glTF composes a node's (or an instance's) transform; q = (x, y, z, w).
Matrix4 trs_matrix(std::array<double, 3> t, std::array<double, 4> q, std::array<double, 3> s) {
  double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n > 0)
    for (double& v : q) v /= n;
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
  Matrix4 m = Matrix4::identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.m[i][j] = r[i][j] * s[size_t(j)];
    m.m[i][3] = t[size_t(i)];
  }
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

// An accessor's elements as doubles, `components` per element (normalised integers already
// divided, sparse substitutions applied).
struct AccessorData {
  int components = 0;
  size_t count = 0;
  std::vector<double> values;
  double at(size_t element, int component) const { return values[element * size_t(components) + size_t(component)]; }
};

// One glTF material as candela materials: what a primitive using it gets.
struct MaterialInfo {
  int material = -1;
  std::optional<AreaEmission> emission;
  int uv_set = 0;
  bool uses_vertex_colors = false;
};

// A primitive converted to a triangle mesh with its material.
struct Primitive {
  TriangleMesh mesh;
  int material = -1;
  std::optional<AreaEmission> emission;
  std::string name;
};

// One placement of a mesh in the world.
struct MeshUse {
  int mesh;
  Transform to_world;
  std::string pointer;  // of the node
};

// What is done to an image before candela reads it.
struct ImageOp {
  enum Kind { Channel, Alpha, Multiply, NormalScale } kind = Channel;
  int channel = 0;        // Channel
  float alpha_factor = 1; // Alpha: alpha * alpha_factor ...
  float cutoff = -1;      // ... thresholded (1 where >= cutoff, else 0) when cutoff >= 0
  RGB factor{1.0f};       // Multiply: the linear RGB times this
  float normal_scale = 1; // NormalScale
  std::string describe() const {
    return fmt::format("{}:{}:{}:{}:{},{},{}:{}", int(kind), channel, alpha_factor, cutoff, factor.r, factor.g,
                       factor.b, normal_scale);
  }
};

class GltfReader {
 public:
  GltfReader(const fs::path& file, std::vector<std::string>& warnings, const GltfOptions& options)
      : file_(file), warnings_(warnings), options_(options) {
    base_dir_ = file.parent_path();
    cache_dir_ = options.cache_dir.empty() ? fs::temp_directory_path() / "candela-gltf" : options.cache_dir;
  }

  SceneDesc read() {
    load();
    check_extensions();
    scene_.settings.sampler.type = SamplerType::ZSobol;  // as the other readers do when a file names none
    walk_scene();
    build_meshes();
    add_camera();
    add_lights();
    return std::move(scene_);
  }

 private:
  // ------------------------------------------------------------ messages

  SourceLocation at(const std::string& pointer = {}) const { return {file_.string(), 0, 0, pointer}; }

  template <typename... Args>
  [[noreturn]] void fail(const std::string& pointer, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(at(pointer), format, std::forward<Args>(args)...);
  }

  template <typename... Args>
  void warn(const std::string& pointer, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.push_back(
        fmt::format("{}: warning: {}", at(pointer).to_string(), fmt::format(format, std::forward<Args>(args)...)));
  }

  // ------------------------------------------------------------ loading

  // Keeps the encoded bytes of embedded images (data URIs, buffer views); images in files of their
  // own are read later by OpenImageIO from the file itself.
  static bool keep_image_bytes(tg::Image* image, const int, std::string*, std::string*, int, int,
                               const unsigned char* bytes, int size, void*) {
    if (image->uri.empty()) image->image.assign(bytes, bytes + size);
    image->as_is = true;
    return true;
  }

  void load() {
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
    if (!ok || !err.empty()) {
      // tinygltf stops at a Draco primitive's missing buffer view before the extensions can be
      // checked: say what the file needs instead.
      refuse_draco_from_raw_json(ext == ".glb");
      std::vector<std::string> errors = lines(err);
      std::string message;
      for (size_t i = 0; i < errors.size(); ++i) message += (i ? "; " : "") + errors[i];
      if (message.empty()) message = "tinygltf could not load the file";
      fail("", "cannot read glTF: {}", message);
    }
  }

  // The file's JSON (a .glb's first chunk) read again with nlohmann, when tinygltf has failed: a
  // file requiring KHR_draco_mesh_compression is refused naming its first compressed mesh.
  void refuse_draco_from_raw_json(bool binary) {
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

  static std::string draco_message(const std::string& mesh) {
    return fmt::format("mesh \"{}\" is Draco-compressed (KHR_draco_mesh_compression), which candela does not "
                       "decode; convert the file to uncompressed glTF first (e.g. gltf-transform copy)", mesh);
  }

  void check_extensions() {
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

  // ------------------------------------------------------------ accessors

  AccessorData read_accessor(int index, const std::string& user) {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(user, "accessor {} does not exist (the file has {})", index, model_.accessors.size());
    const tg::Accessor& a = model_.accessors[size_t(index)];
    const std::string pointer = fmt::format("/accessors/{}", index);
    const int components = tg::GetNumComponentsInType(uint32_t(a.type));
    const int size = tg::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (components <= 0 || components > 16) fail(pointer, "unknown accessor type {}", a.type);
    if (size <= 0) fail(pointer, "unknown component type {}", a.componentType);
    if (a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3 || a.type == TINYGLTF_TYPE_MAT4)
      fail(pointer, "matrix accessors are not used by anything candela reads");
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
  void view_bytes(int view, size_t offset, const std::string& user, const std::byte*& base, size_t& available) {
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

  static void decode(const std::byte* p, int type, bool normalized, int n, double* out) {
    for (int c = 0; c < n; ++c) {
      double v = 0;
      switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
          int8_t x;
          std::memcpy(&x, p + c, 1);
          v = normalized ? std::max(x / 127.0, -1.0) : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
          uint8_t x;
          std::memcpy(&x, p + c, 1);
          v = normalized ? x / 255.0 : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          int16_t x;
          std::memcpy(&x, p + 2 * c, 2);
          v = normalized ? std::max(x / 32767.0, -1.0) : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t x;
          std::memcpy(&x, p + 2 * c, 2);
          v = normalized ? x / 65535.0 : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_INT: {
          int32_t x;
          std::memcpy(&x, p + 4 * c, 4);
          v = x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
          uint32_t x;
          std::memcpy(&x, p + 4 * c, 4);
          v = x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
          float x;
          std::memcpy(&x, p + 4 * c, 4);
          v = x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
          double x;
          std::memcpy(&x, p + 8 * c, 8);
          v = x;
          break;
        }
        default:
          break;
      }
      out[c] = v;
    }
  }

  // ------------------------------------------------------------ the node tree

  Matrix4 local_matrix(const tg::Node& node, const std::string& pointer) {
    if (node.matrix.size() == 16) return matrix_from_column_major(node.matrix);
    if (!node.matrix.empty()) fail(pointer + "/matrix", "expected 16 numbers, got {}", node.matrix.size());
    std::array<double, 3> t{0, 0, 0}, s{1, 1, 1};
    std::array<double, 4> q{0, 0, 0, 1};
    if (node.translation.size() == 3) std::copy(node.translation.begin(), node.translation.end(), t.begin());
    if (node.rotation.size() == 4) std::copy(node.rotation.begin(), node.rotation.end(), q.begin());
    if (node.scale.size() == 3) std::copy(node.scale.begin(), node.scale.end(), s.begin());
    return trs_matrix(t, q, s);
  }

  void walk_scene() {
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
    if (!model_.animations.empty()) warn("/animations", "animations are ignored (the nodes are rendered at rest)");
    on_path_.assign(model_.nodes.size(), false);
    for (int root : roots_) visit(root, Matrix4::identity(), 0, fmt::format("/scenes/{}/nodes", scene));
  }

  void visit(int index, const Matrix4& parent, int depth, const std::string& from) {
    if (index < 0 || size_t(index) >= model_.nodes.size())
      fail(from, "node {} does not exist (the file has {})", index, model_.nodes.size());
    const std::string pointer = fmt::format("/nodes/{}", index);
    if (on_path_[size_t(index)]) fail(pointer, "the node hierarchy has a cycle through this node");
    if (depth > kMaxNodeDepth) fail(pointer, "the node hierarchy is deeper than {}", kMaxNodeDepth);
    const tg::Node& node = model_.nodes[size_t(index)];
    const Matrix4 world = parent * local_matrix(node, pointer);
    std::optional<Transform> T = Transform::from_matrix(world);
    if (!T) {
      warn(pointer, "the node's world transform is singular (a zero scale); it and its children are skipped");
      return;
    }
    if (node.camera >= 0) {
      if (!camera_) camera_ = {node.camera, *T, pointer};
      else ++other_cameras_;
    }
    auto light = node.extensions.find("KHR_lights_punctual");
    if (light != node.extensions.end() && light->second.Has("light"))
      lights_.push_back({int(light->second.Get("light").GetNumberAsInt()), *T, pointer});
    if (node.skin >= 0) warn(pointer, "skinning is ignored (the mesh is rendered in its bind pose)");
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size()) fail(pointer + "/mesh", "mesh {} does not exist", node.mesh);
      auto instancing = node.extensions.find("EXT_mesh_gpu_instancing");
      if (instancing != node.extensions.end())
        add_gpu_instances(node, world, instancing->second, pointer);
      else
        uses_.push_back({node.mesh, *T, pointer});
    }
    on_path_[size_t(index)] = true;
    for (int child : node.children) visit(child, world, depth + 1, pointer + "/children");
    on_path_[size_t(index)] = false;
  }

  void add_gpu_instances(const tg::Node& node, const Matrix4& world, const tg::Value& ext, const std::string& pointer) {
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
      uses_.push_back({node.mesh, *T, fmt::format("{}[{}]", where, i)});
    }
  }

  // ------------------------------------------------------------ meshes

  void build_meshes() {
    std::map<int, int> use_count;
    for (const MeshUse& use : uses_) ++use_count[use.mesh];
    std::map<int, int> object_of_mesh;
    for (const MeshUse& use : uses_) {
      const int m = use.mesh;
      if (!converted_.count(m)) converted_[m] = convert_mesh(m);
      std::vector<Primitive>& primitives = converted_[m];
      bool emissive = std::any_of(primitives.begin(), primitives.end(), [](const Primitive& p) { return p.emission; });
      if (use_count[m] > 1 && !emissive) {
        auto found = object_of_mesh.find(m);
        if (found == object_of_mesh.end()) {
          ObjectDesc object;
          object.name = model_.meshes[size_t(m)].name.empty() ? fmt::format("mesh {}", m) : model_.meshes[size_t(m)].name;
          Bounds3 bounds;
          for (Primitive& p : primitives) {
            for (const Point3& q : p.mesh.positions) bounds.extend(q);
            ShapeDesc shape;
            shape.geometry = MeshShape{std::move(p.mesh)};
            shape.material = p.material;
            shape.name = p.name;
            object.shapes.push_back(std::move(shape));
          }
          object_bounds_.push_back(bounds);
          found = object_of_mesh.emplace(m, int(scene_.objects.size())).first;
          scene_.objects.push_back(std::move(object));
        }
        InstanceDesc instance;
        instance.object = found->second;
        instance.to_world = use.to_world;
        const Bounds3& b = object_bounds_[size_t(found->second)];
        if (!b.empty())
          for (int corner = 0; corner < 8; ++corner)
            bounds_.extend(use.to_world.point(
                {corner & 1 ? b.hi.x : b.lo.x, corner & 2 ? b.hi.y : b.lo.y, corner & 4 ? b.hi.z : b.lo.z}));
        scene_.instances.push_back(instance);
        continue;
      }
      const bool last_use = --use_count[m] == 0;
      for (Primitive& p : primitives) {
        for (const Point3& q : p.mesh.positions) bounds_.extend(use.to_world.point(q));
        ShapeDesc shape;
        shape.geometry = MeshShape{last_use ? std::move(p.mesh) : p.mesh};
        shape.to_world = use.to_world;
        shape.material = p.material;
        shape.emission = p.emission;
        shape.name = p.name;
        scene_.shapes.push_back(std::move(shape));
      }
    }
  }

  std::vector<Primitive> convert_mesh(int m) {
    const tg::Mesh& mesh = model_.meshes[size_t(m)];
    std::vector<Primitive> out;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const std::string pointer = fmt::format("/meshes/{}/primitives/{}", m, p);
      std::optional<Primitive> primitive = convert_primitive(mesh, mesh.primitives[p], pointer);
      if (primitive) {
        primitive->name = fmt::format("{}: mesh \"{}\" primitive {}", file_.filename().string(), mesh.name, p);
        out.push_back(std::move(*primitive));
      }
    }
    return out;
  }

  std::optional<Primitive> convert_primitive(const tg::Mesh& mesh, const tg::Primitive& prim, const std::string& pointer) {
    if (prim.extensions.count("KHR_draco_mesh_compression")) {
      // Not required by the file: the uncompressed accessors are there as a fallback.
    }
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP ||
        mode == TINYGLTF_MODE_LINE_STRIP) {
      warn(pointer, "mesh \"{}\": {} are not surfaces and are skipped", mesh.name, mode == 0 ? "points" : "lines");
      return std::nullopt;
    }
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
      fail(pointer + "/mode", "unknown primitive mode {}", mode);
    auto position = prim.attributes.find("POSITION");
    if (position == prim.attributes.end()) {
      warn(pointer, "mesh \"{}\": the primitive has no POSITION and is skipped", mesh.name);
      return std::nullopt;
    }
    if (!prim.targets.empty()) {
      bool weighted = false;
      for (double w : mesh.weights) weighted |= w != 0;
      if (weighted) warn(pointer, "morph targets are ignored (the base mesh is rendered)");
    }
    Primitive result;
    TriangleMesh& tm = result.mesh;
    AccessorData pos = read_accessor(position->second, pointer + "/attributes/POSITION");
    if (pos.components != 3) fail(pointer + "/attributes/POSITION", "POSITION must be VEC3");
    const size_t n = pos.count;
    tm.positions.resize(n);
    for (size_t i = 0; i < n; ++i) tm.positions[i] = Point3(float(pos.at(i, 0)), float(pos.at(i, 1)), float(pos.at(i, 2)));

    MaterialInfo material = material_info(prim.material, prim.attributes.count("COLOR_0") > 0);
    result.material = material.material;
    result.emission = material.emission;

    if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      AccessorData nor = read_accessor(it->second, pointer + "/attributes/NORMAL");
      if (nor.components != 3 || nor.count != n) fail(pointer + "/attributes/NORMAL", "NORMAL must be VEC3, one per position");
      tm.normals.resize(n);
      bool degenerate = false;
      for (size_t i = 0; i < n; ++i) {
        Normal3 v(float(nor.at(i, 0)), float(nor.at(i, 1)), float(nor.at(i, 2)));
        if (!(length_squared(v) > 1e-20f)) degenerate = true;
        tm.normals[i] = v;
      }
      if (degenerate) {
        warn(pointer + "/attributes/NORMAL", "some normals are zero; the primitive is shaded with its face normals");
        tm.normals.clear();
      }
    }
    const std::string uv_name = fmt::format("TEXCOORD_{}", material.uv_set);
    if (auto it = prim.attributes.find(uv_name); it != prim.attributes.end()) {
      AccessorData uv = read_accessor(it->second, pointer + "/attributes/" + uv_name);
      if (uv.components != 2 || uv.count != n) fail(pointer + "/attributes/" + uv_name, "{} must be VEC2, one per position", uv_name);
      tm.uvs.resize(n);
      // glTF's (0, 0) is the image's top-left corner; candela's t = 0 is its bottom row.
      for (size_t i = 0; i < n; ++i) tm.uvs[i] = Vec2(float(uv.at(i, 0)), float(1 - uv.at(i, 1)));
    } else if (material_has_textures_.count(prim.material)) {
      warn(pointer, "mesh \"{}\": the material's textures use {}, which the primitive does not have", mesh.name, uv_name);
    }
    if (material.uses_vertex_colors) {
      auto it = prim.attributes.find("COLOR_0");
      AccessorData color = read_accessor(it->second, pointer + "/attributes/COLOR_0");
      if ((color.components != 3 && color.components != 4) || color.count != n)
        fail(pointer + "/attributes/COLOR_0", "COLOR_0 must be VEC3 or VEC4, one per position");
      RGB factor = base_color_factor(prim.material);
      TriangleMesh::Attribute attribute;
      attribute.name = "color";
      attribute.channels = 3;
      attribute.values.resize(3 * n);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) attribute.values[3 * i + size_t(c)] = float(color.at(i, c)) * factor[c];
      tm.attributes.push_back(std::move(attribute));
    }

    // Indices, then strips and fans as triangles.
    std::vector<uint32_t> index;
    if (prim.indices >= 0) {
      AccessorData ind = read_accessor(prim.indices, pointer + "/indices");
      if (ind.components != 1) fail(pointer + "/indices", "indices must be SCALAR");
      index.resize(ind.count);
      for (size_t i = 0; i < ind.count; ++i) {
        double v = ind.values[i];
        if (!(v >= 0 && v < double(n))) fail(pointer + "/indices", "index {} at {} is out of range (the primitive has {} vertices)", v, i, n);
        index[i] = uint32_t(v);
      }
    } else {
      index.resize(n);
      for (size_t i = 0; i < n; ++i) index[i] = uint32_t(i);
    }
    auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
      if (a == b || b == c || a == c) return;  // degenerate
      tm.indices.insert(tm.indices.end(), {a, b, c});
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (index.size() % 3 != 0) warn(pointer, "{} indices are not a multiple of 3; the last ones are ignored", index.size());
      tm.indices.reserve(index.size());
      for (size_t i = 0; i + 2 < index.size(); i += 3) add(index[i], index[i + 1], index[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      // The specification's p_i = {v_i, v_(i + 1 + i % 2), v_(i + 2 - i % 2)}: every second one reversed.
      for (size_t i = 0; i + 2 < index.size(); ++i)
        add(index[i], index[i + 1 + i % 2], index[i + 2 - i % 2]);
    } else {
      // Fans: p_i = {v_(i + 1), v_(i + 2), v_0}.
      for (size_t i = 0; i + 2 < index.size(); ++i) add(index[i + 1], index[i + 2], index[0]);
    }
    if (tm.indices.empty()) return std::nullopt;
    return result;
  }

  // ------------------------------------------------------------ images and textures

  fs::path cache_file(uint64_t hash, const std::string& extension) {
    std::error_code ec;
    fs::create_directories(cache_dir_, ec);
    if (ec) fail("", "cannot create the image cache directory {}: {}", cache_dir_.string(), ec.message());
    return cache_dir_ / fmt::format("{:016x}{}", hash, extension);
  }

  // Writes `bytes` to `target` through a temporary name, so that concurrent readers see whole files.
  void write_file_atomically(const fs::path& target, std::string_view bytes) {
    fs::path tmp = target;
    tmp += fmt::format(".{}.tmp", getpid());
    {
      std::ofstream out(tmp, std::ios::binary);
      out.write(bytes.data(), std::streamsize(bytes.size()));
      if (!out) fail("", "cannot write {}", tmp.string());
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) fail("", "cannot write {}: {}", target.string(), ec.message());
  }

  // The file holding image `index`: its own file, or the embedded bytes written to the cache.
  std::string image_file(int index, const std::string& user) {
    if (index < 0 || size_t(index) >= model_.images.size()) fail(user, "image {} does not exist", index);
    if (auto found = image_files_.find(index); found != image_files_.end()) return found->second;
    const tg::Image& image = model_.images[size_t(index)];
    const std::string pointer = fmt::format("/images/{}", index);
    std::string result;
    if (!image.uri.empty() && !image.uri.starts_with("data:")) {
      fs::path path = base_dir_ / uri_decode(image.uri);
      std::error_code ec;
      if (!fs::is_regular_file(path, ec)) fail(pointer, "image file \"{}\" not found", path.string());
      result = path.string();
    } else {
      std::string_view bytes;
      if (image.bufferView >= 0) {
        const std::byte* base = nullptr;
        size_t available = 0;
        view_bytes(image.bufferView, 0, pointer, base, available);
        bytes = std::string_view(reinterpret_cast<const char*>(base), available);
      } else {
        bytes = std::string_view(reinterpret_cast<const char*>(image.image.data()), image.image.size());
      }
      if (bytes.empty()) fail(pointer, "the embedded image is empty");
      std::string ext = image.mimeType == "image/jpeg" ? ".jpg" : image.mimeType == "image/png" ? ".png" : "";
      if (ext.empty()) {
        if (bytes.starts_with("\x89PNG")) ext = ".png";
        else if (bytes.starts_with("\xFF\xD8")) ext = ".jpg";
        else fail(pointer, "embedded image of type \"{}\" is not supported (PNG and JPEG are)", image.mimeType);
      }
      fs::path path = cache_file(fnv1a(bytes), ext);
      std::error_code ec;
      if (!fs::exists(path, ec)) write_file_atomically(path, bytes);
      result = path.string();
    }
    image_files_[index] = result;
    return result;
  }

  struct Pixels {
    int width = 0, height = 0, channels = 0;
    bool integer = true;  // 8- or 16-bit data (sRGB-encoded where colour)
    std::vector<float> data;
  };

  Pixels read_pixels(const std::string& file, const std::string& pointer) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(file, &config);
    if (!in) fail(pointer, "cannot read image {}: {}", file, OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Pixels px;
    px.width = spec.width;
    px.height = spec.height;
    px.channels = spec.nchannels;
    px.integer = spec.format == OIIO::TypeDesc::UINT8 || spec.format == OIIO::TypeDesc::UINT16;
    if (px.width <= 0 || px.height <= 0 || px.channels <= 0 || px.width > kMaxResolution || px.height > kMaxResolution)
      fail(pointer, "image {} has an unusable size {} x {} x {}", file, px.width, px.height, px.channels);
    px.data.resize(size_t(px.width) * size_t(px.height) * size_t(px.channels));
    if (!in->read_image(0, 0, 0, px.channels, OIIO::TypeDesc::FLOAT, px.data.data()))
      fail(pointer, "cannot read image {}: {}", file, in->geterror());
    return px;
  }

  int image_channels(const std::string& file, const std::string& pointer) {
    if (auto found = channel_counts_.find(file); found != channel_counts_.end()) return found->second;
    auto in = OIIO::ImageInput::open(file);
    if (!in) fail(pointer, "cannot read image {}: {}", file, OIIO::geterror());
    int channels = in->spec().nchannels;
    channel_counts_[file] = channels;
    return channels;
  }

  // The image `source` after `op`, as a half-float EXR (linear) in the cache.
  std::string derived_image(const std::string& source, const ImageOp& op, const std::string& pointer) {
    std::error_code ec;
    auto size = fs::file_size(source, ec);
    auto time = fs::last_write_time(source, ec).time_since_epoch().count();
    std::string key = fmt::format("{}|{}|{}|{}", fs::absolute(source, ec).string(), size, time, op.describe());
    fs::path target = cache_file(fnv1a(key), ".exr");
    if (fs::exists(target, ec)) return target.string();
    Pixels px = read_pixels(source, pointer);
    const size_t count = size_t(px.width) * size_t(px.height);
    const int out_channels = op.kind == ImageOp::Multiply || op.kind == ImageOp::NormalScale ? 3 : 1;
    std::vector<float> out(count * size_t(out_channels));
    const int nc = px.channels;
    for (size_t i = 0; i < count; ++i) {
      const float* p = &px.data[i * size_t(nc)];
      auto channel = [&](int c) { return p[std::min(c, nc - 1)]; };
      switch (op.kind) {
        case ImageOp::Channel:
          out[i] = channel(nc >= 3 ? op.channel : 0);  // grey images: their one channel
          break;
        case ImageOp::Alpha: {
          float a = (nc == 4 ? p[3] : nc == 2 ? p[1] : 1.0f) * op.alpha_factor;
          out[i] = op.cutoff >= 0 ? (a >= op.cutoff ? 1.0f : 0.0f) : std::clamp(a, 0.0f, 1.0f);
          break;
        }
        case ImageOp::Multiply:
          for (int c = 0; c < 3; ++c) {
            float v = channel(nc >= 3 ? c : 0);
            out[i * 3 + size_t(c)] = (px.integer ? srgb_to_linear(v) : v) * op.factor[c];
          }
          break;
        case ImageOp::NormalScale: {
          Vec3 v(2 * channel(0) - 1, 2 * channel(1) - 1, 2 * channel(2) - 1);
          v.x *= op.normal_scale;
          v.y *= op.normal_scale;
          float len = length(v);
          if (len > 0) v = v / len;
          for (int c = 0; c < 3; ++c) out[i * 3 + size_t(c)] = 0.5f * (v[c] + 1);
          break;
        }
      }
    }
    fs::path tmp = target;
    tmp += fmt::format(".{}.tmp.exr", getpid());
    auto writer = OIIO::ImageOutput::create(tmp.string());
    OIIO::ImageSpec spec(px.width, px.height, out_channels, OIIO::TypeDesc::HALF);
    if (!writer || !writer->open(tmp.string(), spec) ||
        !writer->write_image(OIIO::TypeDesc::FLOAT, out.data()) || !writer->close())
      fail(pointer, "cannot write the derived image {}: {}", tmp.string(), writer ? writer->geterror() : OIIO::geterror());
    fs::rename(tmp, target, ec);
    if (ec) fail(pointer, "cannot write {}: {}", target.string(), ec.message());
    return target.string();
  }

  // A glTF texture reference (index, texCoord, extensions) as an ImageTexture; -1 where an Alpha
  // op finds no alpha channel. `uv_set` is the material's texture coordinate set so far (-1: none yet).
  int add_texture(int index, int tex_coord, const tg::ExtensionMap& extensions, ColorEncoding encoding,
                  std::optional<ImageOp> op, float scale, const std::string& pointer, int& uv_set) {
    if (index < 0 || size_t(index) >= model_.textures.size()) fail(pointer + "/index", "texture {} does not exist", index);
    const tg::Texture& texture = model_.textures[size_t(index)];
    const std::string tpointer = fmt::format("/textures/{}", index);
    if (texture.source < 0) {
      warn(tpointer, "the texture has no source image (or only one in an unsupported extension); it is ignored");
      return -1;
    }
    ImageTexture image;
    std::string file = image_file(texture.source, tpointer + "/source");
    image.encoding = encoding;
    image.scale = scale;
    if (op) {
      if (op->kind == ImageOp::Alpha) {
        int channels = image_channels(file, tpointer);
        if (channels != 2 && channels != 4) return -1;
      }
      file = derived_image(file, *op, tpointer);
      image.encoding = ColorEncoding::Linear;
    }
    image.filename = file;
    if (texture.sampler >= 0) {
      if (size_t(texture.sampler) >= model_.samplers.size()) fail(tpointer + "/sampler", "sampler {} does not exist", texture.sampler);
      const tg::Sampler& s = model_.samplers[size_t(texture.sampler)];
      auto wrap = [](int mode) {
        return mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? TextureWrap::Clamp
               : mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TextureWrap::Mirror
                                                               : TextureWrap::Repeat;
      };
      image.wrap = wrap(s.wrapS);
      if (s.wrapS != s.wrapT && warned_samplers_.insert(texture.sampler).second)
        warn(fmt::format("/samplers/{}", texture.sampler),
             "different wrap modes in s and t ({} and {}); candela uses wrapS ({}) for both", s.wrapS, s.wrapT, s.wrapS);
      image.bilinear = s.magFilter != TINYGLTF_TEXTURE_FILTER_NEAREST;
    }
    if (auto tt = extensions.find("KHR_texture_transform"); tt != extensions.end()) {
      const tg::Value& v = tt->second;
      double ox = 0, oy = 0, sx = 1, sy = 1;
      if (v.Has("offset") && v.Get("offset").ArrayLen() == 2) {
        ox = v.Get("offset").Get(0).GetNumberAsDouble();
        oy = v.Get("offset").Get(1).GetNumberAsDouble();
      }
      if (v.Has("scale") && v.Get("scale").ArrayLen() == 2) {
        sx = v.Get("scale").Get(0).GetNumberAsDouble();
        sy = v.Get("scale").Get(1).GetNumberAsDouble();
      }
      const double rotation = number_or(v, "rotation", 0);
      if (v.Has("texCoord")) tex_coord = v.Get("texCoord").GetNumberAsInt();
      // glTF: uv' = T(offset) R(rotation) S(scale) uv, i.e.
      //   u' = cos sx u + sin sy v + ox,   v' = -sin sx u + cos sy v + oy,
      // with v down the image; candela's t = 1 - v, so with v = 1 - t and t' = 1 - v':
      //   s' = cos sx u - sin sy t + (sin sy + ox),   t' = sin sx u + cos sy t + (1 - cos sy - oy).
      const double c = std::cos(rotation), sn = std::sin(rotation);
      image.mapping.su = float(c * sx);
      image.mapping.s_from_v = float(-sn * sy);
      image.mapping.du = float(sn * sy + ox);
      image.mapping.t_from_u = float(sn * sx);
      image.mapping.sv = float(c * sy);
      image.mapping.dv = float(1 - c * sy - oy);
    }
    if (uv_set < 0) uv_set = tex_coord;
    else if (tex_coord != uv_set)
      warn(pointer, "the texture uses TEXCOORD_{} but the material's first texture uses TEXCOORD_{}; candela meshes "
                    "have one set of texture coordinates, so TEXCOORD_{} is used", tex_coord, uv_set, uv_set);
    scene_.textures.push_back(image);
    return int(scene_.textures.size()) - 1;
  }

  // ------------------------------------------------------------ materials

  RGB base_color_factor(int m) const {
    if (m < 0) return RGB(1.0f);
    return rgb_of(model_.materials[size_t(m)].pbrMetallicRoughness.baseColorFactor, RGB(1.0f));
  }

  MaterialInfo material_info(int m, bool has_vertex_colors) {
    if (m >= 0 && size_t(m) >= model_.materials.size()) fail("", "material {} does not exist", m);
    // Vertex colours multiply the base colour; candela can use them only where there is no base
    // colour texture (the mesh attribute then carries colour x factor).
    bool vertex_colors = has_vertex_colors;
    if (m >= 0 && model_.materials[size_t(m)].pbrMetallicRoughness.baseColorTexture.index >= 0) vertex_colors = false;
    auto key = std::make_pair(m, vertex_colors);
    if (auto found = materials_.find(key); found != materials_.end()) return found->second;
    MaterialInfo info = make_material(m, vertex_colors, has_vertex_colors);
    materials_[key] = info;
    return info;
  }

  MaterialInfo make_material(int m, bool vertex_colors, bool has_vertex_colors) {
    MaterialInfo info;
    info.uses_vertex_colors = vertex_colors;
    if (m < 0) {
      // The specification's default material: white, fully metallic and rough.
      PrincipledMaterial p;
      p.base_color = RGB(1.0f);
      p.metallic = 1.0f;
      p.roughness = 1.0f;
      p.specular = 0.5f;
      if (vertex_colors) p.base_color = attribute_texture();
      scene_.materials.push_back(p);
      info.material = int(scene_.materials.size()) - 1;
      return info;
    }
    const tg::Material& mat = model_.materials[size_t(m)];
    const std::string pointer = fmt::format("/materials/{}", m);
    const tg::PbrMetallicRoughness& pbr = mat.pbrMetallicRoughness;
    int uv_set = -1;
    PrincipledMaterial p;
    p.specular = 0.5f;
    const RGB factor = rgb_of(pbr.baseColorFactor, RGB(1.0f));
    const float alpha = pbr.baseColorFactor.size() == 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
    if (has_vertex_colors && !vertex_colors)
      warn(pointer, "vertex colours (COLOR_0) are ignored where the base colour has a texture");

    // Base colour: factor x texture (sRGB), or factor x vertex colour.
    if (pbr.baseColorTexture.index >= 0) {
      const std::string where = pointer + "/pbrMetallicRoughness/baseColorTexture";
      if (factor.r == factor.g && factor.g == factor.b) {
        p.base_color.texture = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                           pbr.baseColorTexture.extensions, ColorEncoding::SRGB, std::nullopt, factor.r,
                                           where, uv_set);
      } else {
        ImageOp op;
        op.kind = ImageOp::Multiply;
        op.factor = factor;
        p.base_color.texture = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                           pbr.baseColorTexture.extensions, ColorEncoding::Linear, op, 1, where, uv_set);
      }
      if (p.base_color.texture < 0) p.base_color = factor;
    } else if (vertex_colors) {
      p.base_color = attribute_texture();
    } else {
      p.base_color = factor;
    }

    // Metallic (B) and roughness (G) of the metallicRoughness texture times their factors. glTF's
    // roughness is perceptual (alpha = roughness^2), as Mitsuba's principled reads its roughness.
    p.metallic = float(pbr.metallicFactor);
    p.roughness = float(pbr.roughnessFactor);
    if (pbr.metallicRoughnessTexture.index >= 0) {
      const std::string where = pointer + "/pbrMetallicRoughness/metallicRoughnessTexture";
      ImageOp op;
      op.channel = 2;
      if (pbr.metallicFactor != 0) {
        int t = add_texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                            pbr.metallicRoughnessTexture.extensions, ColorEncoding::Linear, op, float(pbr.metallicFactor),
                            where, uv_set);
        if (t >= 0) p.metallic.texture = t;
      }
      op.channel = 1;
      if (pbr.roughnessFactor != 0) {
        int t = add_texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                            pbr.metallicRoughnessTexture.extensions, ColorEncoding::Linear, op, float(pbr.roughnessFactor),
                            where, uv_set);
        if (t >= 0) p.roughness.texture = t;
      }
    }

    // Extensions.
    bool unlit = false, has_volume = false;
    for (const auto& [name, value] : mat.extensions) {
      const std::string where = pointer + "/extensions/" + name;
      if (name == "KHR_materials_transmission") {
        double f = number_or(value, "transmissionFactor", 0);
        p.spec_trans = float(f);
        if (value.Has("transmissionTexture") && f != 0) {
          const tg::Value& ti = value.Get("transmissionTexture");
          ImageOp op;
          op.channel = 0;
          int t = add_texture(int(number_or(ti, "index", -1)), int(number_or(ti, "texCoord", 0)), texture_extensions(ti),
                              ColorEncoding::Linear, op, float(f), where + "/transmissionTexture", uv_set);
          if (t >= 0) p.spec_trans.texture = t;
        }
      } else if (name == "KHR_materials_ior") {
        p.eta = float(number_or(value, "ior", 1.5));
        p.eta_given = true;
        if (p.eta < 1) {
          if (p.eta != 0) warn(where, "ior {} < 1 is read as 1.5", p.eta);
          p.eta = 1.5f;
        }
      } else if (name == "KHR_materials_unlit") {
        unlit = true;
      } else if (name == "KHR_materials_volume") {
        has_volume = true;
        warn(where, "KHR_materials_volume's attenuation is ignored (clear refraction)");
      } else if (name != "KHR_materials_emissive_strength") {
        warn(where, "material extension {} is not supported and is ignored", name);
      }
    }
    if (p.spec_trans.texture >= 0 || p.spec_trans.value > 0) {
      if (!has_volume)
        warn(pointer, "KHR_materials_transmission without KHR_materials_volume means a thin wall in glTF; candela "
                      "refracts into the surface as into a solid (Mitsuba's principled)");
    }

    // Emission: factor x strength x texture (sRGB), a textured area light.
    RGB emissive = rgb_of(mat.emissiveFactor, RGB(0.0f));
    if (auto it = mat.extensions.find("KHR_materials_emissive_strength"); it != mat.extensions.end())
      emissive *= float(number_or(it->second, "emissiveStrength", 1));
    int emissive_texture = -1;
    if (mat.emissiveTexture.index >= 0 && max_component(Vec3(emissive.r, emissive.g, emissive.b)) > 0)
      emissive_texture = add_texture(mat.emissiveTexture.index, mat.emissiveTexture.texCoord,
                                     mat.emissiveTexture.extensions, ColorEncoding::SRGB, std::nullopt, 1,
                                     pointer + "/emissiveTexture", uv_set);
    if (unlit) {
      // Unlit: the base colour seen whatever the lighting, which a path tracer can only show as
      // emission (base colour factor x texture).
      if (vertex_colors) warn(pointer, "KHR_materials_unlit: vertex colours are ignored");
      warn(pointer, "KHR_materials_unlit: rendered as a black surface emitting its base colour (it also lights the "
                    "rest of the scene)");
      scene_.materials.push_back(BlackMaterial{});
      info.material = int(scene_.materials.size()) - 1;
      AreaEmission e{factor, true};
      if (pbr.baseColorTexture.index >= 0)
        e.texture = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                pbr.baseColorTexture.extensions, ColorEncoding::SRGB, std::nullopt, 1,
                                pointer + "/pbrMetallicRoughness/baseColorTexture", uv_set);
      info.emission = e;
      if (uv_set >= 0) material_has_textures_.insert(m);
      info.uv_set = std::max(uv_set, 0);
      return info;
    }
    if (emissive.r > 0 || emissive.g > 0 || emissive.b > 0) {
      info.emission = AreaEmission{emissive, mat.doubleSided};
      info.emission->texture = emissive_texture;
    }

    if (mat.occlusionTexture.index >= 0) {
      // Ambient occlusion is what a path tracer computes; nothing to do (and no warning needed).
    }

    scene_.materials.push_back(p);
    int top = int(scene_.materials.size()) - 1;

    // Normal map: tangent-space, +y up the image; the frame is candela's (dp/du, dp/dv) from the uvs.
    if (mat.normalTexture.index >= 0) {
      const std::string where = pointer + "/normalTexture";
      std::optional<ImageOp> op;
      if (mat.normalTexture.scale != 1) {
        op = ImageOp{};
        op->kind = ImageOp::NormalScale;
        op->normal_scale = float(mat.normalTexture.scale);
      }
      int t = add_texture(mat.normalTexture.index, mat.normalTexture.texCoord, mat.normalTexture.extensions,
                          ColorEncoding::Linear, op, 1, where, uv_set);
      if (t >= 0) {
        scene_.materials.push_back(NormalMapMaterial{t, top});
        top = int(scene_.materials.size()) - 1;
      }
    }

    // Alpha: MASK keeps the surface where alpha >= cutoff, BLEND lets light through with probability
    // 1 - alpha (stochastic transparency, which a path tracer averages into blending).
    if (mat.alphaMode == "MASK" || mat.alphaMode == "BLEND") {
      const bool mask = mat.alphaMode == "MASK";
      const float cutoff = float(mat.alphaCutoff);
      MaskMaterial wrapper;
      wrapper.material = top;
      wrapper.opacity = mask ? (alpha >= cutoff ? 1.0f : 0.0f) : std::clamp(alpha, 0.0f, 1.0f);
      if (pbr.baseColorTexture.index >= 0) {
        ImageOp op;
        op.kind = ImageOp::Alpha;
        op.alpha_factor = mask ? alpha : 1.0f;
        op.cutoff = mask ? cutoff : -1.0f;
        int t = add_texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
                            ColorEncoding::Linear, op, mask ? 1.0f : std::clamp(alpha, 0.0f, 1.0f),
                            pointer + "/pbrMetallicRoughness/baseColorTexture", uv_set);
        if (t >= 0) wrapper.opacity.texture = t;
      }
      if (has_vertex_colors) {
        // COLOR_0's alpha would multiply too; candela's mesh attributes carry the RGB only.
      }
      if (!(wrapper.opacity.is_constant() && wrapper.opacity.value >= 1)) {
        scene_.materials.push_back(wrapper);
        top = int(scene_.materials.size()) - 1;
      }
    } else if (mat.alphaMode != "OPAQUE" && !mat.alphaMode.empty()) {
      warn(pointer + "/alphaMode", "unknown alphaMode \"{}\" is read as OPAQUE", mat.alphaMode);
    }
    // doubleSided false means back-face culling to a rasteriser; candela's surfaces are seen from both
    // sides, so only one-sided emission depends on it.
    if (uv_set >= 0) material_has_textures_.insert(m);
    info.material = top;
    info.uv_set = std::max(uv_set, 0);
    return info;
  }

  // The extensions of a textureInfo inside an extension (tinygltf parses only the core ones).
  static tg::ExtensionMap texture_extensions(const tg::Value& info) {
    tg::ExtensionMap map;
    if (info.IsObject() && info.Has("extensions")) {
      const tg::Value& ext = info.Get("extensions");
      if (ext.IsObject())
        for (const std::string& key : ext.Keys()) map[key] = ext.Get(key);
    }
    return map;
  }

  ColorInput attribute_texture() {
    if (attribute_texture_ < 0) {
      scene_.textures.push_back(MeshAttributeTexture{"color"});
      attribute_texture_ = int(scene_.textures.size()) - 1;
    }
    ColorInput in;
    in.texture = attribute_texture_;
    return in;
  }

  // ------------------------------------------------------------ camera and lights

  void add_camera() {
    CameraDesc& cam = scene_.camera;
    if (camera_) {
      const auto& [index, T, pointer] = *camera_;
      if (size_t(index) >= model_.cameras.size()) fail(pointer + "/camera", "camera {} does not exist", index);
      const tg::Camera& c = model_.cameras[size_t(index)];
      const std::string cpointer = fmt::format("/cameras/{}", index);
      if (other_cameras_ > 0)
        warn(pointer, "{} more camera node(s) in the scene are ignored; the first one is used", other_cameras_);
      // glTF cameras look down their -z with +y up; candela's camera space looks down +z.
      const Transform flip = Transform::scale({1, 1, -1});
      const int width = options_.film_width;
      if (c.type == "orthographic") {
        const double xmag = std::abs(c.orthographic.xmag), ymag = std::abs(c.orthographic.ymag);
        if (!(xmag > 0) || !(ymag > 0)) fail(cpointer + "/orthographic", "xmag and ymag must not be zero");
        cam.projection = Projection::Orthographic;
        // The film spans x in [-1, 1] and y in [-1 / aspect, 1 / aspect]: scaled by xmag, with
        // aspect xmag / ymag, that is glTF's [-xmag, xmag] x [-ymag, ymag].
        cam.world_from_camera = T * Transform::scale({float(xmag), float(xmag), -1});
        scene_.film.width = width;
        scene_.film.height = std::clamp(int(std::lround(width * ymag / xmag)), 1, kMaxResolution);
        cam.near_clip = float(c.orthographic.znear);
      } else if (c.type == "perspective") {
        if (!(c.perspective.yfov > 0) || c.perspective.yfov >= std::numbers::pi)
          fail(cpointer + "/perspective/yfov", "yfov must be in (0, pi), got {}", c.perspective.yfov);
        cam.world_from_camera = T * flip;
        cam.fov_degrees = float(c.perspective.yfov * 180 / std::numbers::pi);
        cam.fov_axis = FovAxis::Y;
        const double aspect = c.perspective.aspectRatio > 0 ? c.perspective.aspectRatio : 4.0 / 3.0;
        scene_.film.width = width;
        scene_.film.height = std::clamp(int(std::lround(width / aspect)), 1, kMaxResolution);
        cam.near_clip = float(c.perspective.znear);
      } else {
        fail(cpointer + "/type", "unknown camera type \"{}\"", c.type);
      }
      return;
    }
    // No camera: frame the bounding box from +z (glTF's front), looking down -z.
    Bounds3 b = bounds_;
    if (b.empty()) b.extend(Point3(0.0f));
    cam = camera_framing(b.lo, b.hi, 40, 1.05f);
    scene_.film.width = options_.film_width;
    scene_.film.height = std::max(1, options_.film_width * 3 / 4);
  }

  void add_lights() {
    for (const auto& [index, T, pointer] : lights_) {
      if (index < 0 || size_t(index) >= model_.lights.size())
        fail(pointer + "/extensions/KHR_lights_punctual/light", "light {} does not exist", index);
      const tg::Light& l = model_.lights[size_t(index)];
      const std::string lpointer = fmt::format("/extensions/KHR_lights_punctual/lights/{}", index);
      const RGB color = rgb_of(l.color, RGB(1.0f)) * float(l.intensity);
      if (l.range > 0)
        warn(lpointer + "/range", "range is ignored: candela's lights fall off with the inverse square everywhere");
      const Point3 position = T.point(Point3(0.0f));
      Vec3 direction = T.vector({0, 0, -1});
      direction = length(direction) > 0 ? normalize(direction) : Vec3(0, 0, -1);
      if (l.type == "point") {
        scene_.lights.push_back(PointLight{position, color});
      } else if (l.type == "spot") {
        SpotLight s;
        s.position = position;
        s.direction = direction;
        s.intensity = color;
        const double outer = std::clamp(l.spot.outerConeAngle, 1e-4, std::numbers::pi / 2);
        const double inner = std::clamp(l.spot.innerConeAngle, 0.0, outer);
        s.cone_angle = float(outer * 180 / std::numbers::pi);
        s.cone_delta = float((outer - inner) * 180 / std::numbers::pi);
        scene_.lights.push_back(s);
      } else if (l.type == "directional") {
        scene_.lights.push_back(DistantLight{direction, color});
      } else {
        fail(lpointer + "/type", "unknown light type \"{}\"", l.type);
      }
    }
    if (lights_.empty()) {
      // Without lights the model would be lit only by its own emission: a uniform white sky
      // (radiance 1) shows it as a viewer would.
      warn("", "the scene has no KHR_lights_punctual lights; a uniform white sky (radiance 1) lights it");
      scene_.lights.push_back(SkyLight{});
    }
  }

  // ------------------------------------------------------------ state

  fs::path file_, base_dir_, cache_dir_;
  std::vector<std::string>& warnings_;
  GltfOptions options_;
  tg::Model model_;
  SceneDesc scene_;

  std::vector<int> roots_;
  std::vector<bool> on_path_;
  struct NodeRef {
    int index;
    Transform to_world;
    std::string pointer;
  };
  std::optional<NodeRef> camera_;
  int other_cameras_ = 0;
  std::vector<NodeRef> lights_;
  std::vector<MeshUse> uses_;
  std::map<int, std::vector<Primitive>> converted_;
  std::map<std::pair<int, bool>, MaterialInfo> materials_;
  std::set<int> material_has_textures_;
  std::map<int, std::string> image_files_;
  std::map<std::string, int> channel_counts_;
  std::set<int> warned_samplers_;
  std::vector<Bounds3> object_bounds_;
  Bounds3 bounds_;
  int attribute_texture_ = -1;
};

}  // namespace

SceneDesc read_gltf_scene(const std::filesystem::path& file, std::vector<std::string>& warnings,
                          const GltfOptions& options) {
  SceneDesc scene = GltfReader(file, warnings, options).read();
  scene.source_file = file.string();
  return scene;
}

SceneDesc read_gltf_scene(const std::filesystem::path& file) {
  std::vector<std::string> warnings;
  try {
    SceneDesc scene = read_gltf_scene(file, warnings);
    print_pbrt_warnings(warnings);
    return scene;
  } catch (const SceneError&) {
    print_pbrt_warnings(warnings);
    throw;
  }
}

}  // namespace candela
