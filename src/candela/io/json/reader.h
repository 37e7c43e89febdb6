#pragma once
// The reader of candela's JSON scene format (docs/scene-format.md): one JsonSceneReader per file,
// its sections read by the functions of reader.cpp (the document), settings.cpp (camera and render
// settings), textures.cpp, materials.cpp, shapes.cpp (shapes, objects and instances, meshes,
// transforms), lights.cpp, media.cpp and animation.cpp (keyframes, skins, morph targets:
// docs/animation.md). Each reader of a kind of entry (texture, material, shape,
// light) dispatches on a table of type names, from which its "unknown ... type" message lists the names.
#include <fmt/ranges.h>

#include <array>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "candela/io/json/checked_object.h"
#include "candela/io/json/source_position.h"
#include "candela/io/named_spectra.h"
#include "candela/description/scene_desc.h"

namespace candela {
struct RenderOption;
struct RenderRequest;
}  // namespace candela

namespace candela::json {

namespace fs = std::filesystem;

constexpr int kMaxTextureDepth = 64;    // textures using textures

// The "type" of an entry of "shapes" that places an object.
constexpr std::string_view kInstanceType = "instance";

// What one keyframe of a track holds: a number (the camera's fov, focus_distance, lens_radius), a
// translation or scale [x, y, z], a rotation (a quaternion [x, y, z, w] or {"axis", "angle"}), or
// morph target weights (an array of as many numbers as the mesh has targets).
enum class TrackValue { Number, Vec3, Rotation, Weights };

class JsonSceneReader {
 public:
  JsonSceneReader(std::string_view text, const std::string& file_name, const fs::path& base_dir)
      : text_(text), report_(text, file_name), base_dir_(base_dir) {}

  SceneDesc read();

 private:
  // ---- the document (reader.cpp)
  Json parse_document() const;
  [[noreturn]] void throw_number_overflow(std::string_view what) const;
  static std::string parse_error_reason(std::string_view what);
  void reject_duplicate_keys() const;
  SourceLocation place(const std::string& pointer) const;  // file and key path; line and column later
  void locate_places();

  // ---- camera and render settings (settings.cpp)
  void read_camera(const Json& value, const std::string& pointer);
  void read_lens_and_shutter(CheckedObject& camera);
  std::array<float, 4> read_screen_window(const Json& value, const std::string& pointer) const;
  void read_crop(const Json& value, const std::string& pointer);
  void read_sensor(const Json& value, const std::string& pointer);
  void check_view_direction(const CheckedObject& camera, Point3 position, Point3 look_at, Vec3 up) const;
  void read_render(const Json& value, const std::string& pointer);
  void read_render_option(const RenderOption& option, const Json& value, const std::string& pointer,
                          RenderRequest& request) const;
  void read_film_outputs(CheckedObject& render);
  void check_integrator_reads(const Json& value, const CheckedObject& render, const RenderSettings& settings) const;
  void read_transform_times(const Json& value, const std::string& pointer);
  void read_filter_shape(CheckedObject& object, FilterDesc& filter) const;
  Vec2 read_filter_radius(const Json& value, const std::string& pointer) const;
  void check_adaptive(const CheckedObject& adaptive, const RenderSettings& settings) const;

  // ---- named textures and materials (textures.cpp)
  // They may refer to each other in any order. Each is read when first needed, so that
  // SceneDesc::textures (materials) lists every one after those it refers to.
  struct NamedEntry {
    const Json* value = nullptr;
    std::string pointer;
    bool reading = false;  // being read: meeting it again is a cycle
    int index = -1;        // in SceneDesc::textures (materials), once read
  };
  using NamedEntries = std::map<std::string, NamedEntry>;
  // Records the entries of the object mapping names to `kind`s ("texture", "material"); returns
  // their names in the file's order.
  std::vector<std::string> collect_named(const Json& value, const std::string& pointer, std::string_view kind,
                                         NamedEntries& entries);
  // The entry called `name` (given at pointer); an unknown name fails, listing those defined.
  NamedEntry& find_named(NamedEntries& entries, const std::string& name, const std::string& pointer,
                         std::string_view kind);

  // ---- textures (textures.cpp)
  void read_textures(const Json& value, const std::string& pointer);
  int named_texture(const std::string& name, const std::string& pointer);
  int add_texture(TextureDesc texture, SourceLocation where);
  TextureDesc read_texture(const Json& value, const std::string& pointer);
  UVMapping read_uv_mapping(CheckedObject& t) const;
  void read_projection(CheckedObject& t, UVMapping& mapping) const;
  std::string existing_file(CheckedObject& object, std::string_view key, std::string_view what) const;

  // ---- material and texture parameters: a constant, a texture name, or an inline texture object
  // The texture a parameter names (a string) or writes inline (an object); nothing for a constant.
  std::optional<int> texture_reference(const Json& value, const std::string& pointer);
  ColorInput read_color_input(const Json& value, const std::string& pointer, ColorKind kind);
  ColorInput color_input_or(CheckedObject& object, std::string_view key, ColorKind kind, ColorInput fallback);
  FloatInput read_float_input(const Json& value, const std::string& pointer, const ValueRange& bound);
  FloatInput float_input_or(CheckedObject& object, std::string_view key, const ValueRange& bound, FloatInput fallback);

  // ---- materials (materials.cpp)
  void read_materials(const Json& value, const std::string& pointer);
  int add_material(MaterialDesc material, SourceLocation where);
  MaterialDesc read_material(const Json& value, const std::string& pointer);
  // ---- any type with a schema (description/schema.h; schema_fields.cpp): its fields from `m` into
  // `object`, then, once the format's shorthands have filled in the rest, its cross-field check.
  void read_fields(CheckedObject& m, const TypeSchema& schema, void* object);
  void check_fields(CheckedObject& m, const TypeSchema& schema, const void* object) const;
  // The alternative of Variant that the object's "type" names, default-constructed; an unknown type
  // is an error at /type naming the known ones (and `also_known`: types told apart elsewhere).
  template <typename Variant>
  Variant default_of_named_type(CheckedObject& m, std::string_view kind,
                                std::initializer_list<std::string_view> also_known = {}) const {
    const std::string type = m.string("type");
    std::optional<Variant> value = default_of_type<Variant>(type);
    if (!value) {
      std::vector<std::string_view> names = type_names_of<Variant>();
      names.insert(names.end(), also_known.begin(), also_known.end());
      report_.fail(m.pointer_of("type"), "unknown {} type \"{}\"{}; expected one of: {}", kind, type,
                   did_you_mean(type, names), fmt::join(names, ", "));
    }
    return *value;
  }
  // Every field of the value's schema read from the object, and the schema's rule checked.
  template <typename Variant>
  void read_schema_fields(CheckedObject& m, Variant& value) {
    std::visit(
        [&](auto& desc) {
          const TypeSchema& schema = SchemaOf<std::decay_t<decltype(desc)>>::schema;
          read_fields(m, schema, &desc);
          check_fields(m, schema, &desc);
        },
        value);
  }
  Roughness read_roughness(CheckedObject& m, std::string_view prefix = {});
  void read_conductor_preset(CheckedObject& m, ColorInput& eta, ColorInput& k) const;
  int material_by_name(const std::string& name, const std::string& pointer);
  int wrapped_material(CheckedObject& m, std::string_view key);
  std::array<int, 2> material_pair(CheckedObject& m, std::string_view key);
  int texture_reference(CheckedObject& m, std::string_view key);
  int black_material();

  // ---- shapes (shapes.cpp)
  void read_shapes(const Json& value, const std::string& pointer);
  ShapeDesc read_shape(const Json& value, const std::string& pointer);
  ShapeGeometry read_geometry(CheckedObject& s);
  SdfGridShape read_sdf_grid(CheckedObject& s) const;
  CurveShape read_curve(CheckedObject& s) const;
  int read_shape_material(CheckedObject& s);
  AreaEmission read_emission(const Json& value, const std::string& pointer);

  // ---- objects and instances
  static bool is_instance(const Json& shape);
  void read_objects(const Json& value, const std::string& pointer);
  ObjectDesc read_object(const Json& value, const std::string& pointer);
  InstanceDesc read_instance(const Json& value, const std::string& pointer);
  int object_by_name(const std::string& name, const std::string& pointer) const;

  // ---- meshes
  MeshShape read_mesh(CheckedObject& s) const;
  TriangleMesh read_mesh_file(CheckedObject& s) const;
  TriangleMesh read_inline_mesh(CheckedObject& s) const;
  void read_mesh_attributes(const Json& value, const std::string& pointer, TriangleMesh& mesh) const;
  std::vector<Vec3> read_vec3_list(const Json& value, const std::string& pointer, std::string_view of_what) const;
  std::vector<Vec2> read_vec2_list(const Json& value, const std::string& pointer) const;
  std::vector<uint32_t> read_indices(const Json& value, const std::string& pointer, size_t vertex_count) const;
  void check_per_vertex_count(size_t count, size_t vertex_count, const std::string& pointer) const;
  void check_nonzero_normals(const std::vector<Normal3>& normals, const std::string& pointer) const;

  // ---- transforms
  Transform read_moving_transform(const Json& value, CheckedObject& s, const ShapeDesc& shape) const;
  Transform read_transform_key(CheckedObject& object) const;
  Transform read_transform(const Json& value, const std::string& pointer) const;
  Transform read_transform_step(const Json& value, const std::string& pointer) const;
  Transform read_rotation(const Json& value, const std::string& pointer) const;
  Transform read_scale(const Json& value, const std::string& pointer) const;
  Transform read_matrix(const Json& value, const std::string& pointer) const;

  // ---- lights (lights.cpp)
  void read_lights(const Json& value, const std::string& pointer);
  void read_light(const Json& value, const std::string& pointer);
  ShapeDesc read_shape_light(CheckedObject& light, ShapeGeometry geometry);
  void read_sky_shorthands(CheckedObject& light, SkyLight& sky) const;
  void read_spot_shorthands(CheckedObject& light, SpotLight& spot) const;
  void read_environment_orientation(CheckedObject& light, EnvironmentMap& environment) const;
  static Transform rotation_between(Vec3 from, Vec3 to);
  void check_rotation(const Transform& transform, const std::string& pointer) const;

  // ---- animation (animation.cpp): read before the camera and the shapes that refer to its nodes
  void read_animation(const Json& value, const std::string& pointer);
  void collect_node_names(const Json& nodes);
  AnimationNode read_animation_node(const Json& value, const std::string& pointer) const;
  void read_node_trs(CheckedObject& n, AnimatedTrs& trs) const;
  Matrix4 read_node_matrix(const Json& value, const std::string& pointer) const;
  void check_node_cycles() const;
  Skin read_skin(const Json& value, const std::string& pointer) const;
  MeshDeformation read_deformation(const Json& value, const std::string& pointer);
  std::vector<std::vector<Vec3>> read_morph_targets(const Json& value, const std::string& pointer) const;
  Keyframes read_keyframes(const Json& value, const std::string& pointer, TrackValue kind) const;
  void read_track_value(const Json& value, const std::string& pointer, TrackValue kind, bool tangent,
                        Keyframes& keys) const;
  std::array<float, 4> read_rotation_value(const Json& value, const std::string& pointer) const;
  // A reference to a node, skin or deformation: an index, or a name for nodes and skins.
  int node_reference(const Json& value, const std::string& pointer) const;
  int skin_reference(const Json& value, const std::string& pointer) const;
  // The node an object (shape, instance, camera) is placed by: its "animation_node", or the node its
  // inline "animation" adds; -1 for neither.
  int animation_node_of(CheckedObject& object);
  // The deformation a shape names (`value`, its "deformation"), checked against the shape.
  int read_deformation_use(const Json& value, CheckedObject& s, const ShapeDesc& shape) const;
  // The camera's `key` where it is keyframed (an object), its values checked against `bound` and
  // `constant` set to its first; nothing where the key is absent or a plain number.
  std::optional<Keyframes> camera_track(CheckedObject& camera, std::string_view key, const ValueRange& bound,
                                        float& constant) const;

  // ---- participating media (media.cpp): read before the camera and the shapes that name them
  void read_media(const Json& value, const std::string& pointer);
  MediumDesc read_medium(const Json& value, const std::string& pointer);
  VolumeDesc read_volume_or_constant(CheckedObject& m, const Field& f) const;
  VolumeDesc read_volume(const Json& value, const std::string& pointer, std::string_view what) const;
  int medium_by_name(const std::string& name, const std::string& pointer) const;
  int medium_reference(CheckedObject& object, std::string_view key) const;

  std::string_view text_;
  ErrorReporter report_;
  fs::path base_dir_;
  SceneDesc scene_;
  NamedEntries named_textures_;
  std::vector<std::string> texture_stack_;  // the named textures being read, outermost first
  int texture_depth_ = 0;                   // textures being read, named or inline
  NamedEntries named_materials_;
  std::map<std::string, int> object_index_;
  std::map<std::string, int> medium_index_;
  std::optional<int> black_material_;
  // Animation: the nodes by name (several nodes may share one: such a name cannot be referred to),
  // the number of nodes references may name (forward references within "nodes" included), where
  // each node is declared, and the number of vertices each deformation is for (0: any).
  std::map<std::string, std::vector<int>, std::less<>> node_names_;
  int node_count_ = 0;
  std::vector<std::string> node_pointers_;
  std::vector<size_t> deformation_vertices_;
};

}  // namespace candela::json
