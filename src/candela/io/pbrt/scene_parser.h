#pragma once
// The third layer of the pbrt-v4 reader (docs/pbrt-format.md): the directives, read in order with
// pbrt's graphics state (graphics_state.h), build a SceneDesc. One class, its members defined by
// subject in several files:
//   scene_parser.cpp    files, Include/Import, the directive table, transforms, attribute blocks
//   render_directives.cpp  Camera, Film, Sampler, Integrator, PixelFilter and the other options
//   textures.cpp        spectra, textured parameters and Texture
//   materials.cpp       Material, MakeNamedMaterial, NamedMaterial
//   lights.cpp          LightSource, AreaLightSource
//   shapes.cpp          Shape and object instancing
//   media.cpp           MakeNamedMedium, MediumInterface
// Every problem is one SceneError naming file:line:column. What candela reads but cannot reproduce
// exactly (a sampler or integrator it replaces, a parameter it ignores) is a warning naming
// file:line:column; what would change the image materially is an error.
#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <tuple>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "candela/io/named_spectra.h"
#include "candela/io/pbrt/graphics_state.h"
#include "candela/io/pbrt/parameters.h"
#include "candela/io/pbrt/tokenizer.h"
#include "candela/io/warnings.h"
#include "candela/description/scene_desc.h"

namespace candela::pbrt {

namespace fs = std::filesystem;
constexpr float kPi = std::numbers::pi_v<float>;

struct ObjectDefinition {
  std::string name;
  SourceLocation where;
  std::vector<ShapeDesc> shapes;
  int index = -1;  // into SceneDesc::objects, once it is first instanced
};

// A shape's geometry with what "power" needs to know about its area: pbrt-v4 makes one area light
// per primitive (each triangle of a mesh, each patch of a bilinear mesh, the whole sphere or disk)
// and gives each the radiance that makes *that primitive* emit "power".
struct BuiltGeometry {
  ShapeGeometry geometry;
  // Meshes: the pbrt primitive each triangle belongs to (empty: each triangle is its own).
  std::vector<uint32_t> primitive_of_triangle;
  // Spheres, cylinders and disks: pbrt's object-space area (pbrt ignores the CTM's scale here).
  float object_area = 0;
};

// A medium name as MediumInterface and MakeNamedMedium use it. Its slot in SceneDesc::media is
// reserved when it is first named, so that (as in pbrt-v4) an interface may name a medium that is
// defined further on.
struct NamedMedium {
  int index = -1;  // into SceneDesc::media
  bool defined = false;
  SourceLocation first_reference;  // for the error when the scene never defines it
};

struct NamedTexture {
  int index = -1;  // into SceneDesc::textures; -1 for a "constant" texture
  ColorInput color;
  FloatInput value;
  SourceLocation where;
};

// What the Sampler, Integrator and PixelFilter directives chose, starting from pbrt-v4's defaults
// for a scene that leaves them out. write_render_settings copies it into SceneDesc::settings: the
// one place that writes RenderSettings.
struct RenderDirectives {
  SamplerDesc sampler{SamplerType::ZSobol};
  int spp = 16;  // pixel samples, or an "mlt" integrator's mutations per pixel
  std::optional<uint64_t> seed;
  std::string integrator = "path";
  bool integrator_given = false;  // else pbrt-v4's default, volpath, which is path without media
  int max_depth = 5;
  FilterDesc filter = default_filter(FilterType::Gaussian);
  std::optional<LightSelection> light_sampler;  // an integrator that reads "lightsampler" was named
  struct Metropolis {
    int bootstrap = 0, chains = 0;
    float large_step = 0, sigma = 0;
  };
  std::optional<Metropolis> mlt;
  AmbientOcclusionSettings ambient_occlusion;  // "ambientocclusion"'s "maxdistance" and "cossample"
  SppmSettings sppm;                           // "sppm"'s "photonsperiteration" and "radius"
};

enum class Section { Options, World };

class SceneParser {
 public:
  explicit SceneParser(Warnings& warnings) : warnings_(warnings) {}
  SceneDesc parse(const fs::path& file);
  // pbrt text not read from a file: `name` stands for the file in messages, and relative file
  // names (Include, Import, meshes, images) are looked up in `base_dir`.
  SceneDesc parse(std::string text, const std::string& name, const fs::path& base_dir);

 private:
  using Handler = void (SceneParser::*)(const Token&);
  static const std::unordered_map<std::string_view, Handler>& handlers();

  template <typename... Args>
  void warn(const SourceLocation& where, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.warn(where, fmt::format(format, std::forward<Args>(args)...));
  }
  // Accepts the parameter `name` if given and warns that it is ignored (silently for one an
  // Attribute set, which applies to many directives).
  void ignore_param(ParamList& params, std::string_view name, std::string_view why);

  // files
  void start(const std::string& source, const fs::path& top_directory);
  SceneDesc finish(const SourceLocation& end);
  SourceLocation parse_file(const fs::path& file, const SourceLocation* included_from);
  SourceLocation parse_tokens(Tokenizer& tokens, const fs::path& directory, const fs::path& canonical_file,
                              const SourceLocation* included_from);
  void parse_directives();
  std::string describe_include_places() const;
  fs::path resolve_path(const std::string& name, const SourceLocation& where, std::string_view what) const;
  void check_end_of_scene(const SourceLocation& end) const;

  // reading arguments
  Token expect_string(const Token& directive, std::string_view what);
  double expect_number(const Token& directive, int index, int count);
  Vec3 read_vec3(const Token& directive, int first_index = 0, int count = 3);
  Matrix4 read_bracketed_matrix(const Token& directive);
  ParamList read_params(const Token& directive, std::string owner, AttributeTarget target = kAttributeTargets);

  // state checks
  void require_world(const Token& directive) const;
  void require_options(const Token& directive) const;
  void push_block(const Token& directive, BlockKind kind);
  void pop_block(const Token& directive, BlockKind kind);

  // the CTMs that ActiveTransform selects become f(CTM)
  template <typename F>
  void update_active_ctms(F f) {
    if (state_.active_transforms & kStartTransform) state_.ctm.start = f(state_.ctm.start);
    if (state_.active_transforms & kEndTransform) state_.ctm.end = f(state_.ctm.end);
  }
  void post_multiply_ctm(const Transform& t) {
    update_active_ctms([&](const Transform& ctm) { return ctm * t; });
  }

  // directives
  void identity(const Token&) {
    update_active_ctms([](const Transform&) { return Transform(); });
  }
  void translate(const Token& d) { post_multiply_ctm(Transform::translate(read_vec3(d))); }
  void scale(const Token& d);
  void rotate(const Token& d);
  void look_at(const Token& d);
  void transform(const Token& d);
  void concat_transform(const Token& d);
  void coordinate_system(const Token& d);
  void coord_sys_transform(const Token& d);
  void active_transform(const Token& d);
  void transform_times(const Token& d);
  void attribute_begin(const Token& d);
  void attribute_end(const Token& d);
  void attribute(const Token& d);
  void reverse_orientation(const Token& d);
  void camera(const Token& d);
  void film(const Token& d);
  void sampler(const Token& d);
  void integrator(const Token& d);
  void pixel_filter(const Token& d);
  void accelerator(const Token& d);
  void read_light_sampler(ParamList& params, const char* default_sampler);
  void option(const Token& d);
  void color_space(const Token& d);
  void world_begin(const Token& d);
  void texture(const Token& d);
  void material(const Token& d);
  void make_named_material(const Token& d);
  void named_material(const Token& d);
  void light_source(const Token& d);
  void area_light_source(const Token& d);
  void shape(const Token& d);
  void object_begin(const Token& d);
  void object_end(const Token& d);
  void object_instance(const Token& d);
  void make_named_medium(const Token& d);
  void medium_interface(const Token& d);
  void include(const Token& d);
  void import(const Token& d);
  void world_end(const Token& d);

  // the rendering options, once read
  void write_render_settings(RenderSettings& settings) const;
  // The Film's pixelbounds or cropwindow as pixels [x0, x1) x [y0, y1) of the full image, if given.
  std::optional<std::array<int, 4>> pixel_bounds_;
  // The Film's "iso" (100 by default).
  float film_iso_ = 100;
  // Makes the film that part of the full image: the camera's screen window narrowed to it.
  void crop_film(const std::array<int, 4>& bounds);

  // spectra and textured parameters
  std::optional<ColorInput> read_color(ParamList& params, std::string_view name, pbrt_spectra::Role role);
  std::optional<FloatInput> read_float_texture(ParamList& params, std::string_view name);
  std::optional<RGB> read_emission(ParamList& params, std::string_view name);
  std::optional<RGB> read_spectrum(ParamList& params, std::string_view name, pbrt_spectra::Role role);
  std::optional<float> read_ior(ParamList& params, std::string_view name);
  // A "spectrum" parameter's value as RGB: a named spectrum, a spectrum file or (wavelength, value) pairs.
  RGB spectrum_rgb(const Param& p, const ParamList& params, pbrt_spectra::Role role);
  // The pairs of the spectrum file a "spectrum" parameter's string names, read once per file.
  const std::vector<double>& spectrum_file_pairs(const Param& p, const ParamList& params);
  std::map<fs::path, std::vector<double>> spectrum_files_;
  Roughness read_roughness(ParamList& params, std::string_view prefix = {});
  // The slab of pbrt-v4's layered materials: thickness, albedo, g, maxdepth, nsamples.
  LayerSlab read_layer_slab(ParamList& params);
  // pbrt-v4's "hair" material (io/pbrt/materials.cpp).
  MaterialDesc make_hair_material(ParamList& params);
  // A material's shading-normal parameters (every pbrt-v4 material but "mix" and "interface"):
  // read_shading_normals reads them into shading_normals_, wrap_shading_normals wraps the material
  // added after it.
  struct ShadingNormals {
    int normal_map = -1;                    // an image texture of tangent-space normals
    std::optional<FloatInput> displacement;  // a height texture (bump mapping)
  };
  void read_shading_normals(ParamList& params);
  int wrap_shading_normals(int material, const SourceLocation& where);
  ShadingNormals shading_normals_;
  int add_texture(TextureDesc texture, const SourceLocation& where);

  // textures
  UVMapping read_uv_mapping(ParamList& params);
  ImageTexture make_image_texture(ParamList& params);
  RGB read_constant_input(ParamList& params, std::string_view name, bool is_float, RGB fallback);
  static int read_octaves(ParamList& params);
  ColorInput read_texture_input(ParamList& params, std::string_view name, bool is_float, RGB fallback);

  // scene objects from parameter lists
  MaterialDesc make_material(const std::string& type, const SourceLocation& type_where, ParamList& params);
  ColorInput scaled(ColorInput c, float scale, const SourceLocation& where);
  int add_material(MaterialDesc material, const SourceLocation& where);
  int masked_material(int material, const FloatInput& alpha, const SourceLocation& where);
  // The mask materials made for "alpha": (material, alpha texture, constant alpha) -> material.
  std::map<std::tuple<int, int, float>, int> masked_materials_;
  void add_light(LightDesc light, const SourceLocation& where);
  BuiltGeometry make_sphere(ParamList& params);
  BuiltGeometry make_cylinder(ParamList& params);
  BuiltGeometry make_triangle_mesh(ParamList& params);
  BuiltGeometry make_ply_mesh(ParamList& params);
  BuiltGeometry make_disk(ParamList& params);
  BuiltGeometry make_bilinear_mesh(ParamList& params);
  BuiltGeometry make_loop_subdivision(ParamList& params);
  BuiltGeometry make_curve(ParamList& params);
  RGB read_light_scale(ParamList& params, RGB emitted);
  void require_static_light(const Token& directive, const Token& type) const;
  void add_emissive_shape(ShapeDesc shape, const BuiltGeometry& built, const Token& directive);
  void add_shape(ShapeDesc shape, const Token& directive);

  // participating media
  int medium_index(const Token& name);
  void check_media_defined() const;
  void read_scattering(ParamList& params, MediumDesc& medium, std::optional<RGB> sigma_a, std::optional<RGB> sigma_s);
  RGB read_medium_emission(ParamList& params, float scale);
  MediumDesc make_homogeneous_medium(ParamList& params);
  MediumDesc make_grid_medium(ParamList& params);
  MediumDesc make_nanovdb_medium(ParamList& params);
  // pbrt-v4's "subsurface" material: its dielectric boundary; and, where the integrator renders
  // subsurface scattering (volpath), the medium its shapes are filled with, left in
  // pending_subsurface_medium_ for claim_subsurface_medium.
  MaterialDesc make_subsurface_material(ParamList& params);
  // Records that material `material` (as shapes get it) is the subsurface material just made, if it is one.
  void claim_subsurface_medium(int material);
  std::map<int, int> subsurface_media_;  // material index -> the subsurface medium of its shapes
  int pending_subsurface_medium_ = -1;
  void read_temperature_mapping(ParamList& params, MediumDesc& medium);

  Warnings& warnings_;
  SceneDesc scene_;
  RenderDirectives options_;
  GraphicsState state_;
  Section section_ = Section::Options;
  SourceLocation world_begin_;
  std::vector<OpenBlock> blocks_;
  size_t block_floor_ = 0;  // blocks below this belong to the file that Imported the current one
  std::map<std::string, TransformSet> coordinate_systems_;
  std::map<std::string, std::pair<int, SourceLocation>> named_materials_;
  std::map<std::string, NamedTexture> spectrum_textures_, float_textures_;
  std::optional<ObjectDefinition> open_object_;
  std::map<std::string, ObjectDefinition> objects_;
  std::map<std::string, NamedMedium> media_;
  Tokenizer* tokens_ = nullptr;
  fs::path directory_;  // of the file being read: relative names are looked up there first
  // Canonical paths of the files being read, to catch include cycles (empty for text not read from
  // a file).
  std::vector<fs::path> open_files_;
  std::vector<SourceLocation> include_places_;  // where each of them was included, for messages
  int files_read_ = 0;  // every Include and Import so far, against a file including others many times over
  fs::path top_directory_;
};

}  // namespace candela::pbrt
