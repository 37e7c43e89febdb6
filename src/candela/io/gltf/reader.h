#pragma once
// The glTF reader's parts (io/gltf/): reader.cpp (loading, accessors, the node tree),
// meshes_cameras_lights.cpp, images_materials.cpp, animation.cpp (animations, skins, morph
// targets); gltf_reader.h is the entry.
#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

// Without its stb_image decoding: images are only located, never decoded, by tinygltf (its
// implementation is compiled into gltf/reader.cpp; see CMakeLists.txt).
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

#include "candela/animation/keyframes.h"
#include "candela/base/error.h"
#include "candela/io/gltf_reader.h"

namespace candela::gltf {

namespace fs = std::filesystem;
namespace tg = tinygltf;

inline constexpr int kMaxNodeDepth = 1024;

// ---------------------------------------------------------------- small helpers

uint64_t fnv1a(std::string_view bytes, uint64_t h = 1469598103934665603ULL);
// %XX escapes of a URI reference decoded (glTF URIs are RFC 3986 references).
std::string uri_decode(const std::string& uri);
float srgb_to_linear(float v);
Matrix4 matrix_from_column_major(const std::vector<double>& a);
RGB rgb_of(const std::vector<double>& v, RGB fallback);
// A number from a tinygltf Value (ints and reals both), or `fallback`.
double number_or(const tg::Value& object, const char* key, double fallback);

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
  std::string pointer;  // /meshes/m/primitives/p
  // For MeshDeformation, per vertex in `mesh`'s vertex order (convert_primitive keeps the
  // accessors' order): skinning's JOINTS_n/WEIGHTS_n sets (`influences` = 4 per set, read only
  // when the file has skins) and each morph target's POSITION and NORMAL displacements (empty
  // where the target has none; target_normals empty when no target has normals).
  int influences = 0;
  std::vector<uint16_t> joints;
  std::vector<float> weights;
  std::vector<std::vector<Vec3>> target_positions, target_normals;
};

// One placement of a mesh in the world.
struct MeshUse {
  int mesh;
  Transform to_world;   // relative to animation_node's world transform where that is set
  std::string pointer;  // of the node
  int node = -1;
  int animation_node = -1;  // the moving node that places the mesh (SceneAnimation), or -1
  int skin = -1;            // the node's skin (model_.skins and SceneAnimation::skins), or -1
  bool deforms = false;     // skinned or with morph targets: one MeshDeformation per primitive
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
  GltfReader(const fs::path& file, Warnings& warnings, const GltfOptions& options)
      : file_(file), warnings_(warnings), options_(options) {
    base_dir_ = file.parent_path();
    cache_dir_ = options.cache_dir.empty() ? fs::temp_directory_path() / "candela-gltf" : options.cache_dir;
  }

  SceneDesc read();

 private:
  // ------------------------------------------------------------ messages

  SourceLocation at(const std::string& pointer = {}) const;

  template <typename... Args>
  [[noreturn]] void fail(const std::string& pointer, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(at(pointer), format, std::forward<Args>(args)...);
  }

  template <typename... Args>
  void warn(const std::string& pointer, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.warn(at(pointer), fmt::format(format, std::forward<Args>(args)...));
  }

  // ------------------------------------------------------------ loading

  static bool keep_image_bytes(tg::Image* image, const int, std::string*, std::string*, int, int,
                               const unsigned char* bytes, int size, void*);

  void load();

  void refuse_draco_from_raw_json(bool binary);

  static std::string draco_message(const std::string& mesh);

  void check_extensions();

  // ------------------------------------------------------------ accessors

  AccessorData read_accessor(int index, const std::string& user);

  void view_bytes(int view, size_t offset, const std::string& user, const std::byte*& base, size_t& available);

  static void decode(const std::byte* p, int type, bool normalized, int n, double* out);

  // ------------------------------------------------------------ the node tree

  Matrix4 local_matrix(const tg::Node& node, const std::string& pointer);

  void walk_scene();

  void visit(int index, const Matrix4& parent, int depth, const std::string& from);

  void add_gpu_instances(const tg::Node& node, const Matrix4& world, const tg::Value& ext, const std::string& pointer,
                         int animation_node);

  // ------------------------------------------------------------ animation (animation.cpp)

  // Whether the file has animations, skins or morph targets (else SceneDesc::animation stays empty).
  bool file_animates() const;

  // SceneDesc::animation's nodes (one per glTF node, same index), keyframes and skins; before the
  // node tree is walked, which asks it which nodes move.
  void build_animation();
  void read_channels();
  // A sampler's keyframes for a channel animating `path` ("translation", "rotation", "scale" or
  // "weights" of `width` morph targets).
  Keyframes read_keyframes(const tg::AnimationSampler& sampler, const std::string& path, int width,
                           const std::string& pointer);
  void read_skins();

  // The number of morph targets of mesh m (the same for all its primitives).
  int morph_target_count(int m);

  // A primitive's JOINTS_n/WEIGHTS_n and morph targets into `result` (convert_primitive's part).
  void read_skinning_attributes(const tg::Primitive& prim, const std::string& pointer, Primitive& result);
  void read_morph_targets(const tg::Primitive& prim, const std::string& pointer, Primitive& result);

  // The MeshDeformation of primitive p where `use` places it (index into animation.deformations),
  // or -1 when the primitive neither is skinned nor has morph targets.
  int add_deformation(const MeshUse& use, const Primitive& p);

  // The instants at which the model is framed when the file brings no camera: its animation's time
  // range in even steps; and where a use's mesh is at each of them (its one placement when static).
  std::vector<float> framing_times() const;
  std::vector<Transform> placements_over_time(const MeshUse& use) const;

  // ------------------------------------------------------------ meshes

  void build_meshes();

  std::vector<Primitive> convert_mesh(int m);

  std::optional<Primitive> convert_primitive(const tg::Mesh& mesh, const tg::Primitive& prim, const std::string& pointer);

  // ------------------------------------------------------------ images and textures

  fs::path cache_file(uint64_t hash, const std::string& extension);

  void write_file_atomically(const fs::path& target, std::string_view bytes);

  std::string image_file(int index, const std::string& user);

  struct Pixels {
    int width = 0, height = 0, channels = 0;
    bool integer = true;  // 8- or 16-bit data (sRGB-encoded where colour)
    std::vector<float> data;
  };

  Pixels read_pixels(const std::string& file, const std::string& pointer);
  void checked_exr_header(const std::string& file, const std::string& pointer) const;

  int image_channels(const std::string& file, const std::string& pointer);

  std::string derived_image(const std::string& source, const ImageOp& op, const std::string& pointer);

  int add_texture(int index, int tex_coord, const tg::ExtensionMap& extensions, ColorEncoding encoding,
                  std::optional<ImageOp> op, float scale, const std::string& pointer, int& uv_set);

  // ------------------------------------------------------------ materials

  RGB base_color_factor(int m) const;

  MaterialInfo material_info(int m, bool has_vertex_colors);

  MaterialInfo make_material(int m, bool vertex_colors, bool has_vertex_colors);

  // make_material's parts. `uv_set`: the material's texture coordinate set, -1 until its first
  // texture (add_texture); the parts are called in the order their textures are added.

  // The specification's default material (no material given); its index in scene_.materials.
  int add_default_material(bool vertex_colors);

  // pbrMetallicRoughness: the base colour (factor x texture or vertex colour), then metallic and
  // roughness (factors x texture).
  void read_base_color(const tg::PbrMetallicRoughness& pbr, RGB factor, bool vertex_colors,
                       const std::string& pointer, PrincipledMaterial& p, int& uv_set);
  void read_metallic_roughness(const tg::PbrMetallicRoughness& pbr, const std::string& pointer,
                               PrincipledMaterial& p, int& uv_set);

  // The KHR_materials_* extensions (transmission, ior, volume, unlit); whether the material is unlit.
  bool read_material_extensions(const tg::Material& mat, const std::string& pointer, PrincipledMaterial& p,
                                int& uv_set);
  void read_transmission(const tg::Value& value, const std::string& where, PrincipledMaterial& p, int& uv_set);

  // emissiveFactor x KHR_materials_emissive_strength x emissiveTexture.
  AreaEmission read_emission(const tg::Material& mat, const std::string& pointer, int& uv_set);

  // KHR_materials_unlit: a black surface emitting its base colour, into info.
  void add_unlit_material(const tg::PbrMetallicRoughness& pbr, RGB factor, bool vertex_colors,
                          const std::string& pointer, int& uv_set, MaterialInfo& info);

  // The normal map and the alpha mode as materials wrapping `top`; the new top material.
  int add_normal_map(const tg::Material& mat, const std::string& pointer, int top, int& uv_set);
  int add_alpha(const tg::Material& mat, float alpha, const std::string& pointer, int top, int& uv_set);

  static tg::ExtensionMap texture_extensions(const tg::Value& info);

  ColorInput attribute_texture();

  // ------------------------------------------------------------ camera and lights

  void add_camera();

  void add_lights();

  // ------------------------------------------------------------ state

  fs::path file_, base_dir_, cache_dir_;
  Warnings& warnings_;
  GltfOptions options_;
  tg::Model model_;
  SceneDesc scene_;

  std::vector<int> roots_;
  std::vector<bool> on_path_;
  struct NodeRef {
    int index;
    Transform to_world;  // relative to animation_node's world transform where that is set
    std::string pointer;
    int animation_node = -1;
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

}  // namespace candela::gltf
