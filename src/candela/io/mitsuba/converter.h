#pragma once
// The second pass of the Mitsuba reader: the object tree to candela's SceneDesc, plugin by plugin,
// with Mitsuba's defaults; every property must be read by the plugin that owns it (an unknown
// parameter is an error, as in Mitsuba). What candela reads but cannot reproduce exactly is a
// warning; what would change the image materially is an error.
//
// The converter's parts: converter.cpp (the scene and property access), textures_materials.cpp,
// shapes_emitters.cpp, sensor_integrator.cpp.
#include <fmt/format.h>

#include <filesystem>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/io/mitsuba/object_tree.h"
#include "candela/io/warnings.h"
#include "candela/description/scene_desc.h"

namespace candela::mitsuba {

namespace fs = std::filesystem;

inline constexpr int kUnboundedDepth = 1024;    // candela's max_depth for Mitsuba's max_depth = -1
// Mitsuba's default focal length, 50 mm, as a field of view on the diagonal of a 36 x 24 mm film.
inline constexpr float kDefaultFovDiagonal = 46.79139f;

// How Mitsuba looks a texture up: for a colour (eval, eval_3) or for a float parameter (eval_1).
// The two differ for the checkerboard, so a texture object becomes one candela texture per lookup.
enum class TextureLookup { Color, Scalar };

class Converter {
 public:
  Converter(const ObjectTree& tree, Warnings& warnings) : tree_(tree), warnings_(warnings) {}

  SceneDesc convert(const Object& scene);

 private:
  // ------------------------------------------------ property access

  template <typename... Args>
  void warn(const Where& where, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.warn(where.loc(), fmt::format(format, std::forward<Args>(args)...));
  }

  static const Property* find(const Object& o, std::string_view name);

  [[noreturn]] static void wrong_kind(const Object& o, const Property& p, const char* expected);
  // "unknown WHAT type "x" (did you mean "y"?) (supported: ...)" at the object.
  [[noreturn]] static void unknown_type(const Object& o, std::string_view what, std::string_view type,
                                        std::initializer_list<std::string_view> supported);

  static float get_float(const Object& o, std::string_view name, float fallback);
  static int get_int(const Object& o, std::string_view name, int fallback);
  static bool get_bool(const Object& o, std::string_view name, bool fallback);
  static std::string get_string(const Object& o, std::string_view name, const std::string& fallback);
  static std::optional<Vec3> get_vector(const Object& o, std::string_view name);
  static Transform get_transform(const Object& o, std::string_view name);
  void ignore(const Object& o, std::string_view name, const char* why = nullptr);

  static void check_all_used(const Object& o);

  const Object& deref(const Property& p);

  std::vector<std::pair<const Property*, const Object*>> nested(const Object& o, std::string_view tag);

  fs::path resolve_file(const Object& o, std::string_view name_param);

  // ------------------------------------------------ colours and textures

  RGB blackbody(const Object& t);

  RGB spectrum_rgb(const Property& p, bool within_emitter);

  std::optional<ColorInput> color_input(const Object& o, std::string_view name, bool within_emitter = false,
                                        TextureLookup lookup = TextureLookup::Color);
  ColorInput color(const Object& o, std::string_view name, RGB fallback, bool within_emitter = false);

  FloatInput float_input(const Object& o, std::string_view name, float fallback);

  // Each texture, material and light is added with the place of the object it comes from (an empty
  // Where for the default material), for SceneDesc::places.
  int add_texture(TextureDesc t, const Where& where);

  int constant_texture(RGB value, const Where& where);

  UVMapping to_uv(const Object& o);

  int texture(const Object& t, TextureLookup lookup = TextureLookup::Color);

  // ------------------------------------------------ materials

  PerturbedNormalOptions perturbed_normal_options(const Object& b);

  int add_material(MaterialDesc m, const Where& where);
  int one_sided(MaterialDesc m, bool two_sided, const Where& where);
  void add_light(LightDesc l, const Where& where);

  float ior_value(const Object& o, std::string_view name, float fallback);
  float relative_ior(const Object& o, float int_default, float ext_default);

  Roughness roughness(const Object& o, float alpha_default);

  void conductor_ior(const Object& o, ConductorMaterial& c);

  int single_nested_bsdf(const Object& o, bool two_sided, int expected = 1);

  int bsdf(const Object& b, bool two_sided);

  int default_material();

  // ------------------------------------------------ shapes

  static TriangleMesh cube_mesh();

  TriangleMesh mesh_file(const Object& s);

  SdfGridShape sdf_grid(const Object& s);

  void shape(const Object& s, ObjectDesc* group);

  int shapegroup(const Object& g);

  // ------------------------------------------------ emitters

  static Vec3 origin_of(const Transform& t);

  void emitter(const Object& e);

  RGB constant_color(const Object& o, std::string_view name, RGB fallback);

  std::pair<int, int> texture_size(int index);

  // ------------------------------------------------ participating media (media.cpp)

  // The medium `m` (memoised: shapes refer to one medium by id), as an index into SceneDesc::media.
  int medium(const Object& m);
  // A medium parameter given as a colour or a float, or as a nested volume.
  VolumeDesc volume_parameter(const Object& m, std::string_view name, RGB fallback);
  float phase_g(const Object& m);
  // A shape's or the sensor's nested medium references: interior/exterior, or (sensor) the medium.
  void shape_media(const Object& s, ShapeDesc& out);

  // ------------------------------------------------ sensor, film, sampler, integrator

  static FilterDesc gaussian_filter(float stddev);

  void sensor(const Object& s);

  void film(const Object& f);

  void rfilter(const Object& r);

  void sampler(const Object& s);

  static int candela_depth(int mitsuba_depth);

  void integrator(const Object& i);

  const ObjectTree& tree_;
  Warnings& warnings_;
  SceneDesc desc_;
  // A texture once per way it is looked up (see TextureLookup).
  std::map<std::pair<const Object*, TextureLookup>, int> texture_memo_;
  std::map<std::pair<const Object*, bool>, int> bsdf_memo_;
  std::map<const Object*, int> group_memo_;
  std::map<const Object*, int> medium_memo_;
  int default_material_ = -1;
};

}  // namespace candela::mitsuba
