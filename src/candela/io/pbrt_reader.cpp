// Reader for pbrt-v4 scene files (the subset in docs/pbrt-format.md).
//
// Three layers: a tokenizer that knows line:column, a parameter-list reader that checks types and
// counts, and a parser that keeps pbrt's graphics state (CTM, material, area light, orientation,
// Attribute defaults) and fills a SceneDesc. Every problem is one SceneError naming
// file:line:column; like pbrt itself, a parameter that nothing reads is an error rather than being
// silently ignored. What candela reads but cannot reproduce exactly (a sampler or integrator it
// replaces, a parameter it ignores) is a warning naming file:line:column; what would change the
// image materially is an error.
#include "candela/io/pbrt_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mesh_io.h"
#include "candela/io/named_spectra.h"
#include "candela/io/scene_reader.h"

namespace candela {
namespace {

namespace fs = std::filesystem;
constexpr float kPi = std::numbers::pi_v<float>;

SourceLocation location(const std::string& file, int line, int column) {
  SourceLocation where;
  where.file = file;
  where.line = line;
  where.column = column;
  return where;
}

// pbrt's limits on what a scene may ask for, beyond which the request is surely a mistake.
constexpr int kMaxResolutionPerSide = 65536;
constexpr int64_t kMaxPixels = int64_t{1} << 28;
constexpr int kMaxIncludeDepth = 64;
constexpr float kMaxFilterRadius = 64;  // pixels; the filter is tabulated per unit of radius

// Tessellation of the shapes candela has no primitive for.
constexpr int kDiskSegmentsPerTurn = 128;  // with the rings scaled to keep the area exact
constexpr int kBilinearPatchTessellation = 16;  // a non-planar bilinear patch becomes 16 x 16 quads

// ---------------------------------------------------------------- tokens

enum class TokenKind { Word, String, OpenBracket, CloseBracket, End };

struct Token {
  TokenKind kind = TokenKind::End;
  std::string text;  // a word as written; a string without its quotes and with escapes decoded
  const std::string* file = nullptr;
  int line = 0;
  int column = 0;
};

SourceLocation at(const Token& token) { return location(*token.file, token.line, token.column); }

// How a token reads in an error message.
std::string describe(const Token& token) {
  switch (token.kind) {
    case TokenKind::Word: return token.text;
    case TokenKind::String: return fmt::format("\"{}\"", token.text);
    case TokenKind::OpenBracket: return "\"[\"";
    case TokenKind::CloseBracket: return "\"]\"";
    case TokenKind::End: break;
  }
  return "the end of the file";
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Splits pbrt text into words, quoted strings and brackets; '#' starts a comment to the end of the line.
class Tokenizer {
 public:
  Tokenizer(std::string text, std::string file_name) : text_(std::move(text)), file_name_(std::move(file_name)) {
    if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;  // a UTF-8 byte-order mark some editors write
  }

  const std::string& file_name() const { return file_name_; }

  Token next() {
    if (!lookahead_) return scan();
    Token token = std::move(*lookahead_);
    lookahead_.reset();
    return token;
  }

  const Token& peek() {
    if (!lookahead_) lookahead_ = scan();
    return *lookahead_;
  }

 private:
  bool at_end() const { return pos_ >= text_.size(); }

  char advance() {
    char c = text_[pos_++];
    if (c == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
    return c;
  }

  void skip_space_and_comments() {
    while (!at_end()) {
      char c = text_[pos_];
      if (is_space(c)) {
        advance();
      } else if (c == '#') {
        while (!at_end() && text_[pos_] != '\n') advance();
      } else {
        return;
      }
    }
  }

  Token scan() {
    skip_space_and_comments();
    Token token;
    token.file = &file_name_;
    token.line = line_;
    token.column = column_;
    if (at_end()) return token;
    char c = text_[pos_];
    if (c == '[' || c == ']') {
      advance();
      token.kind = c == '[' ? TokenKind::OpenBracket : TokenKind::CloseBracket;
      token.text = c;
    } else if (c == '"') {
      scan_string(token);
    } else {
      size_t start = pos_;
      while (!at_end() && !is_space(text_[pos_]) && text_[pos_] != '"' && text_[pos_] != '[' &&
             text_[pos_] != ']')
        advance();
      token.kind = TokenKind::Word;
      token.text.assign(text_, start, pos_ - start);
    }
    return token;
  }

  // A string must close on the line it opens, as in pbrt: that catches a missing quote early.
  void scan_string(Token& token) {
    token.kind = TokenKind::String;
    advance();  // the opening quote
    while (true) {
      if (at_end() || text_[pos_] == '\n')
        throw_scene_error(at(token), "unterminated string: a string must end with '\"' on the line it starts");
      int escape_line = line_, escape_column = column_;
      char c = advance();
      if (c == '"') return;
      if (c != '\\') {
        token.text += c;
        continue;
      }
      if (at_end() || text_[pos_] == '\n')
        throw_scene_error(at(token), "unterminated string: a string must end with '\"' on the line it starts");
      token.text += decode_escape(advance(), location(file_name_, escape_line, escape_column));
    }
  }

  static char decode_escape(char c, const SourceLocation& where) {
    switch (c) {
      case 'b': return '\b';
      case 'f': return '\f';
      case 'n': return '\n';
      case 'r': return '\r';
      case 't': return '\t';
      case '\\': return '\\';
      case '\'': return '\'';
      case '"': return '"';
      default: break;
    }
    throw_scene_error(where, "unknown escape sequence '\\{}' in a string", c);
  }

  std::string text_;
  std::string file_name_;
  size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
  std::optional<Token> lookahead_;
};

// Numbers as pbrt writes them; rejects nan, inf and values beyond float range, which would only
// poison the renderer later.
std::optional<double> parse_number(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  if (text.empty() || text[0] == '+') return std::nullopt;
  double value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if (!std::isfinite(value) || std::abs(value) > FLT_MAX) return std::nullopt;
  return value;
}

std::optional<int> parse_integer(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  if (text.empty() || text[0] == '+') return std::nullopt;
  int64_t value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if (value < INT_MIN || value > INT_MAX) return std::nullopt;
  return static_cast<int>(value);
}


// ---------------------------------------------------------------- parameter lists

enum class ValueKind { Number, Integer, Bool, String, Spectrum };

// pbrt-v4's parameter types, with the older spellings mapped to the canonical ones.
std::string canonical_type(std::string_view type) {
  if (type == "point") return "point3";
  if (type == "vector") return "vector3";
  if (type == "normal3") return "normal";
  if (type == "color") return "rgb";
  return std::string(type);
}

std::optional<ValueKind> value_kind_of(std::string_view type) {
  if (type == "integer") return ValueKind::Integer;
  if (type == "float" || type == "point2" || type == "vector2" || type == "point3" || type == "vector3" ||
      type == "normal" || type == "rgb" || type == "blackbody")
    return ValueKind::Number;
  if (type == "bool") return ValueKind::Bool;
  if (type == "string" || type == "texture") return ValueKind::String;
  if (type == "spectrum") return ValueKind::Spectrum;  // a name or (wavelength, value) pairs
  return std::nullopt;
}

// One "type name" [ values ] entry of a directive's parameter list.
struct Param {
  std::string type;  // canonical spelling
  std::string name;
  SourceLocation where;  // the "type name" string
  ValueKind kind = ValueKind::Number;
  std::vector<double> numbers;  // Number and Integer values, and a spectrum's pairs
  std::vector<std::string> strings;
  std::vector<bool> bools;
  bool used = false;

  size_t count() const { return numbers.size() + strings.size() + bools.size(); }
  std::string declaration() const { return fmt::format("\"{} {}\"", type, name); }
};

std::string join_quoted(std::initializer_list<std::string_view> names, std::string_view last_separator = " or ") {
  std::string list;
  size_t i = 0;
  for (std::string_view name : names) {
    if (i > 0) list += i + 1 == names.size() ? std::string(last_separator) : std::string(", ");
    list += fmt::format("\"{}\"", name);
    ++i;
  }
  return list;
}

// Lookups check a parameter's type and number of values and mark it used; reject_unused() then
// reports the first parameter nothing asked for, listing the ones this directive does read.
// `defaults` are the parameters an Attribute directive set for this kind of directive: they are
// found when the directive itself does not give the parameter, and are never reported as unused
// (they apply to every directive of the kind, and only some read each one), as in pbrt-v4.
class ParamList {
 public:
  ParamList(std::string owner, SourceLocation directive, std::vector<Param> params, std::vector<Param> defaults = {})
      : owner_(std::move(owner)),
        directive_(std::move(directive)),
        params_(std::move(params)),
        defaults_(std::move(defaults)) {}

  const std::string& owner() const { return owner_; }
  const SourceLocation& directive() const { return directive_; }

  bool has(std::string_view name) const { return find_in(params_, name) || find_in(defaults_, name); }
  bool has_own(std::string_view name) const { return find_in(params_, name) != nullptr; }

  // The parameter's place in the file, or the directive's when it was not given.
  SourceLocation where(std::string_view name) const {
    if (const Param* p = find_in(params_, name)) return p->where;
    if (const Param* p = find_in(defaults_, name)) return p->where;
    return directive_;
  }

  template <typename... Args>
  [[noreturn]] void fail(std::string_view name, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(where(name), "{}: \"{}\" {}", owner_, name, fmt::format(format, std::forward<Args>(args)...));
  }

  // The parameter `name` if given (by the directive or an Attribute), after checking that its type
  // is one of `types`; marks it used. nullptr when it is not given.
  Param* take(std::string_view name, std::initializer_list<std::string_view> types) {
    if (std::find(queried_.begin(), queried_.end(), name) == queried_.end()) queried_.emplace_back(name);
    Param* p = find_in(params_, name);
    if (!p) p = find_in(defaults_, name);
    if (!p) return nullptr;
    if (std::find(types.begin(), types.end(), p->type) == types.end()) {
      if (p->type == "texture")
        throw_scene_error(p->where, "{}: {}: a texture is not accepted here; give {}", owner_, p->declaration(),
                          join_quoted(types));
      throw_scene_error(p->where, "{}: parameter \"{}\" must be of type {}, not \"{}\"", owner_, name,
                        join_quoted(types), p->type);
    }
    p->used = true;
    return p;
  }

  // Marks `name` read whatever its type (for parameters that are accepted and ignored).
  Param* take_any(std::string_view name) {
    if (std::find(queried_.begin(), queried_.end(), name) == queried_.end()) queried_.emplace_back(name);
    Param* p = find_in(params_, name);
    if (!p) p = find_in(defaults_, name);
    if (p) p->used = true;
    return p;
  }

  void expect_count(const Param& p, size_t count) const {
    if (p.count() != count)
      throw_scene_error(p.where, "{}: {} takes exactly {} value{}, got {}", owner_, p.declaration(), count,
                        count == 1 ? "" : "s", p.count());
  }

  void expect_multiple(const Param& p, size_t per_item) const {
    if (p.count() % per_item != 0)
      throw_scene_error(p.where, "{}: {} needs a multiple of {} values, got {}", owner_, p.declaration(), per_item,
                        p.count());
  }

  float get_float(std::string_view name, float fallback) {
    const Param* p = take_single(name, "float", 1);
    return p ? static_cast<float>(p->numbers[0]) : fallback;
  }

  int get_int(std::string_view name, int fallback) {
    const Param* p = take_single(name, "integer", 1);
    return p ? static_cast<int>(p->numbers[0]) : fallback;
  }

  bool get_bool(std::string_view name, bool fallback) {
    const Param* p = take_single(name, "bool", 1);
    return p ? p->bools[0] : fallback;
  }

  std::string get_string(std::string_view name, std::string fallback) {
    const Param* p = take_single(name, "string", 1);
    return p ? p->strings[0] : std::move(fallback);
  }

  std::vector<std::string> get_strings(std::string_view name) {
    const Param* p = take(name, {"string"});
    return p ? p->strings : std::vector<std::string>{};
  }

  Point3 get_point3(std::string_view name, Point3 fallback) {
    const Param* p = take_single(name, "point3", 3);
    return p ? to_vec3(p->numbers, 0) : fallback;
  }

  std::vector<double> get_floats(std::string_view name) {
    const Param* p = take(name, {"float"});
    return p ? p->numbers : std::vector<double>{};
  }

  // Colours are never negative; reflectances (albedos) are at most 1, as pbrt-v4 requires.
  RGB get_rgb(std::string_view name, RGB fallback, bool is_reflectance) {
    const Param* p = take_single(name, "rgb", 3);
    return p ? checked_rgb(*p, is_reflectance) : fallback;
  }

  RGB checked_rgb(const Param& p, bool is_reflectance) const {
    expect_count(p, 3);
    RGB rgb(static_cast<float>(p.numbers[0]), static_cast<float>(p.numbers[1]), static_cast<float>(p.numbers[2]));
    if (rgb.min_component() < 0)
      throw_scene_error(p.where, "{}: \"{}\" has a negative component ({} {} {})", owner_, p.name, rgb.r, rgb.g,
                        rgb.b);
    if (is_reflectance && rgb.max_component() > 1)
      throw_scene_error(p.where, "{}: \"{}\" is a reflectance and must not exceed 1 ({} {} {})", owner_, p.name,
                        rgb.r, rgb.g, rgb.b);
    return rgb;
  }

  std::vector<Vec3> get_vec3_array(std::string_view name, std::string_view type) {
    const Param* p = take(name, {type});
    std::vector<Vec3> values;
    if (!p) return values;
    expect_multiple(*p, 3);
    values.reserve(p->numbers.size() / 3);
    for (size_t i = 0; i < p->numbers.size(); i += 3) values.push_back(to_vec3(p->numbers, i));
    return values;
  }

  std::vector<Vec2> get_point2_array(std::string_view name) {
    const Param* p = take(name, {"point2"});
    std::vector<Vec2> values;
    if (!p) return values;
    expect_multiple(*p, 2);
    values.reserve(p->numbers.size() / 2);
    for (size_t i = 0; i < p->numbers.size(); i += 2)
      values.emplace_back(static_cast<float>(p->numbers[i]), static_cast<float>(p->numbers[i + 1]));
    return values;
  }

  std::vector<int> get_int_array(std::string_view name) {
    const Param* p = take(name, {"integer"});
    std::vector<int> values;
    if (p)
      for (double v : p->numbers) values.push_back(static_cast<int>(v));
    return values;
  }

  void reject_unused() const {
    for (const Param& p : params_) {
      if (p.used) continue;
      std::string known;
      for (const std::string& name : queried_) known += (known.empty() ? "" : ", ") + name;
      if (known.empty())
        throw_scene_error(p.where, "{}: unused parameter {} (it takes no parameters)", owner_, p.declaration());
      throw_scene_error(p.where, "{}: unused parameter {} (parameters read here: {})", owner_, p.declaration(),
                        known);
    }
  }

 private:
  static Vec3 to_vec3(const std::vector<double>& numbers, size_t i) {
    return {static_cast<float>(numbers[i]), static_cast<float>(numbers[i + 1]), static_cast<float>(numbers[i + 2])};
  }

  static Param* find_in(std::vector<Param>& params, std::string_view name) {
    for (Param& p : params)
      if (p.name == name) return &p;
    return nullptr;
  }
  static const Param* find_in(const std::vector<Param>& params, std::string_view name) {
    for (const Param& p : params)
      if (p.name == name) return &p;
    return nullptr;
  }

  const Param* take_single(std::string_view name, std::string_view type, size_t count) {
    const Param* p = take(name, {type});
    if (p) expect_count(*p, count);
    return p;
  }

  std::string owner_;
  SourceLocation directive_;
  std::vector<Param> params_;
  std::vector<Param> defaults_;
  std::vector<std::string> queried_;
};

// "unknown shape type" for a misspelling, "not supported" for a pbrt-v4 type candela lacks;
// both list the types that are supported.
[[noreturn]] void reject_type(const SourceLocation& where, std::string_view what, std::string_view type,
                              std::initializer_list<std::string_view> supported,
                              std::initializer_list<std::string_view> known_unsupported,
                              std::string_view why = "") {
  std::string list = join_quoted(supported, ", ");
  if (std::find(known_unsupported.begin(), known_unsupported.end(), type) != known_unsupported.end())
    throw_scene_error(where, "{} type \"{}\" is not supported{} (supported: {})", what, type,
                      why.empty() ? std::string(" yet") : fmt::format(": {}", why), list);
  throw_scene_error(where, "unknown {} type \"{}\" (supported: {})", what, type, list);
}

// ---------------------------------------------------------------- the parser

// pbrt keeps two CTMs: the transform at TransformTimes' start time and at its end time. They differ
// only where ActiveTransform made the transform directives change one of them: an animated shape.
struct TransformSet {
  Transform start, end;
  bool is_animated() const { return start != end; }
};

// Which of the two CTMs the transform directives change (ActiveTransform StartTime / EndTime / All).
enum ActiveTransforms : uint8_t { kStartTransform = 1, kEndTransform = 2, kAllTransforms = 3 };

// The current AreaLightSource. With "power", the radiance depends on the area of each shape, so
// it is computed per shape.
struct AreaLightSpec {
  RGB radiance{1.0f};  // L * scale
  bool two_sided = false;
  std::optional<float> power;
  SourceLocation where;
};

// Attribute "shape" | "light" | "material" | "medium" | "texture": default parameters.
enum AttributeTarget { kShapeAttributes, kLightAttributes, kMaterialAttributes, kMediumAttributes,
                       kTextureAttributes, kAttributeTargets };

// pbrt's per-attribute-block state.
struct GraphicsState {
  TransformSet ctm;
  uint8_t active_transforms = kAllTransforms;
  int material = -1;  // -1: pbrt's default material, diffuse 0.5
  std::optional<AreaLightSpec> area_light;
  bool reverse_orientation = false;
  std::vector<Param> attributes[kAttributeTargets];
};

enum class BlockKind { Attribute, Object };

struct OpenBlock {
  BlockKind kind;
  std::string opener;  // the directive that opened it, for messages
  SourceLocation where;
  GraphicsState saved;
};

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
  // Spheres and disks: pbrt's object-space area (pbrt ignores the CTM's scale here).
  float object_area = 0;
};

struct NamedTexture {
  int index = -1;  // into SceneDesc::textures; -1 for a "constant" texture
  ColorInput color;
  FloatInput value;
  SourceLocation where;
};

enum class Section { Options, World };

class PbrtParser {
 public:
  explicit PbrtParser(std::vector<std::string>& warnings) : warnings_(warnings) {}
  SceneDesc parse(const fs::path& file);

 private:
  using Handler = void (PbrtParser::*)(const Token&);
  static const std::unordered_map<std::string_view, Handler>& handlers();

  template <typename... Args>
  void warn(const SourceLocation& where, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.push_back(
        fmt::format("{}: warning: {}", where.to_string(), fmt::format(format, std::forward<Args>(args)...)));
  }
  // Accepts the parameter `name` if given and warns that it is ignored (silently for one an
  // Attribute set, which applies to many directives).
  void ignore_param(ParamList& params, std::string_view name, std::string_view why);

  // files
  SourceLocation parse_file(const fs::path& file, const SourceLocation* included_from);
  void parse_directives();
  fs::path resolve_path(const std::string& name, const SourceLocation& where, std::string_view what) const;
  void check_end_of_scene(const SourceLocation& end) const;

  // reading arguments
  Token expect_string(const Token& directive, std::string_view what);
  double expect_number(const Token& directive, int index, int count);
  Vec3 read_vec3(const Token& directive, int first_index = 0, int count = 3);
  Matrix4 read_bracketed_matrix(const Token& directive);
  std::vector<Param> read_param_vector(const std::string& owner);
  ParamList read_params(const Token& directive, std::string owner, AttributeTarget target = kAttributeTargets);
  Param read_param(const Token& declaration, const std::string& owner);
  void add_value(Param& param, const Token& value, const std::string& owner);

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
  void read_light_sampler(ParamList& params);
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

  // spectra and textured parameters
  std::optional<ColorInput> read_color(ParamList& params, std::string_view name, pbrt_spectra::Role role);
  std::optional<FloatInput> read_float_texture(ParamList& params, std::string_view name);
  std::optional<RGB> read_emission(ParamList& params, std::string_view name);
  std::optional<float> read_ior(ParamList& params, std::string_view name);
  RGB named_spectrum(const Param& p, const ParamList& params, pbrt_spectra::Role role);
  Roughness read_roughness(ParamList& params);
  void ignore_shading_params(ParamList& params);
  int add_texture(TextureDesc texture);

  // textures
  UVMapping read_uv_mapping(ParamList& params);
  ImageTexture make_image_texture(ParamList& params);
  ColorInput read_texture_input(ParamList& params, std::string_view name, bool is_float, RGB fallback);

  // scene objects from parameter lists
  MaterialDesc make_material(const std::string& type, const SourceLocation& type_where, ParamList& params);
  int add_material(MaterialDesc material) {
    scene_.materials.push_back(std::move(material));
    return static_cast<int>(scene_.materials.size()) - 1;
  }
  BuiltGeometry make_sphere(ParamList& params);
  BuiltGeometry make_triangle_mesh(ParamList& params);
  BuiltGeometry make_ply_mesh(ParamList& params);
  BuiltGeometry make_disk(ParamList& params);
  BuiltGeometry make_bilinear_mesh(ParamList& params);
  RGB read_light_scale(ParamList& params, RGB emitted);
  void add_emissive_shape(ShapeDesc shape, const BuiltGeometry& built, const Token& directive);
  void add_shape(ShapeDesc shape, const Token& directive);

  std::vector<std::string>& warnings_;
  SceneDesc scene_;
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
  Tokenizer* tokens_ = nullptr;
  std::vector<fs::path> open_files_;  // canonical paths of the files being read, to catch include cycles
  fs::path top_directory_;
};

const std::unordered_map<std::string_view, PbrtParser::Handler>& PbrtParser::handlers() {
  static const std::unordered_map<std::string_view, Handler> table = {
      {"Identity", &PbrtParser::identity},
      {"Translate", &PbrtParser::translate},
      {"Scale", &PbrtParser::scale},
      {"Rotate", &PbrtParser::rotate},
      {"LookAt", &PbrtParser::look_at},
      {"Transform", &PbrtParser::transform},
      {"ConcatTransform", &PbrtParser::concat_transform},
      {"CoordinateSystem", &PbrtParser::coordinate_system},
      {"CoordSysTransform", &PbrtParser::coord_sys_transform},
      {"AttributeBegin", &PbrtParser::attribute_begin},
      {"AttributeEnd", &PbrtParser::attribute_end},
      {"TransformBegin", &PbrtParser::attribute_begin},  // deprecated; pbrt-v4 treats it as AttributeBegin
      {"TransformEnd", &PbrtParser::attribute_end},
      {"Attribute", &PbrtParser::attribute},
      {"ReverseOrientation", &PbrtParser::reverse_orientation},
      {"Camera", &PbrtParser::camera},
      {"Film", &PbrtParser::film},
      {"Sampler", &PbrtParser::sampler},
      {"Integrator", &PbrtParser::integrator},
      {"PixelFilter", &PbrtParser::pixel_filter},
      {"Accelerator", &PbrtParser::accelerator},
      {"Option", &PbrtParser::option},
      {"ColorSpace", &PbrtParser::color_space},
      {"WorldBegin", &PbrtParser::world_begin},
      {"Texture", &PbrtParser::texture},
      {"Material", &PbrtParser::material},
      {"MakeNamedMaterial", &PbrtParser::make_named_material},
      {"NamedMaterial", &PbrtParser::named_material},
      {"LightSource", &PbrtParser::light_source},
      {"AreaLightSource", &PbrtParser::area_light_source},
      {"Shape", &PbrtParser::shape},
      {"ObjectBegin", &PbrtParser::object_begin},
      {"ObjectEnd", &PbrtParser::object_end},
      {"ObjectInstance", &PbrtParser::object_instance},
      {"MakeNamedMedium", &PbrtParser::make_named_medium},
      {"MediumInterface", &PbrtParser::medium_interface},
      {"Include", &PbrtParser::include},
      {"Import", &PbrtParser::import},
      {"ActiveTransform", &PbrtParser::active_transform},
      {"TransformTimes", &PbrtParser::transform_times},
      {"WorldEnd", &PbrtParser::world_end},
  };
  return table;
}

void PbrtParser::ignore_param(ParamList& params, std::string_view name, std::string_view why) {
  bool own = params.has_own(name);
  Param* p = params.take_any(name);
  if (p && own) warn(p->where, "{}: \"{}\" is ignored: {}", params.owner(), name, why);
}

// ---------------------------------------------------------------- files

SceneDesc PbrtParser::parse(const fs::path& file) {
  // pbrt-v4's defaults for a scene that leaves out a directive.
  scene_.source_file = file.string();
  scene_.camera.fov_degrees = 90;
  scene_.camera.fov_axis = FovAxis::Smaller;
  scene_.film.width = 1280;
  scene_.film.height = 720;
  scene_.settings.spp = 16;
  scene_.settings.sampler.type = SamplerType::ZSobol;
  scene_.settings.filter = default_filter(FilterType::Gaussian);
  scene_.settings.max_depth = 5;
  scene_.settings.integrator = "path";
  scene_.settings.spectral = true;  // pbrt-v4 renders spectrally; RGB parameters become spectra as there

  top_directory_ = file.parent_path();
  SourceLocation end = parse_file(file, nullptr);
  check_end_of_scene(end);
  return std::move(scene_);
}

std::string read_file_text(const fs::path& file, const SourceLocation& where) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_scene_error(where, "cannot open \"{}\"", file.string());
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw_scene_error(where, "cannot read \"{}\"", file.string());
  return std::move(text).str();
}

// Reads one file's directives with the current state; returns where the file ended.
SourceLocation PbrtParser::parse_file(const fs::path& file, const SourceLocation* included_from) {
  SourceLocation blame = included_from ? *included_from : location(file.string(), 0, 0);
  if (!included_from && !fs::is_regular_file(file)) throw_scene_error(blame, "no such scene file");
  if (open_files_.size() >= kMaxIncludeDepth)
    throw_scene_error(blame, "files are included more than {} deep", kMaxIncludeDepth);
  std::error_code error;
  fs::path canonical = fs::weakly_canonical(file, error);
  if (error) canonical = fs::absolute(file).lexically_normal();
  if (std::find(open_files_.begin(), open_files_.end(), canonical) != open_files_.end())
    throw_scene_error(blame, "\"{}\" includes itself (directly or through other files)", file.string());

  Tokenizer tokens(read_file_text(file, blame), file.string());
  Tokenizer* outer = std::exchange(tokens_, &tokens);
  open_files_.push_back(canonical);
  try {
    parse_directives();
  } catch (const SceneError& error) {
    tokens_ = outer;
    open_files_.pop_back();
    if (!included_from) throw;
    // Errors inside an included file name that file; add where it was included from.
    throw SceneError(fmt::format("{} (in the file included at {})", error.what(), included_from->to_string()));
  }
  SourceLocation end = at(tokens.peek());
  tokens_ = outer;
  open_files_.pop_back();
  return end;
}

void PbrtParser::parse_directives() {
  while (true) {
    Token directive = tokens_->next();
    if (directive.kind == TokenKind::End) return;
    if (directive.kind != TokenKind::Word)
      throw_scene_error(at(directive), "expected a directive (such as Shape or AttributeBegin), got {}",
                        describe(directive));
    auto handler = handlers().find(directive.text);
    if (handler == handlers().end()) throw_scene_error(at(directive), "unknown directive \"{}\"", directive.text);
    (this->*handler->second)(directive);
  }
}

// Relative names are looked up beside the file that names them, then (as pbrt-v4 does for every
// relative name) beside the top-level scene file.
fs::path PbrtParser::resolve_path(const std::string& name, const SourceLocation& where, std::string_view what) const {
  if (name.empty()) throw_scene_error(where, "{}: the file name is empty", what);
  fs::path path(name);
  if (path.is_absolute()) {
    if (!fs::is_regular_file(path)) throw_scene_error(where, "{}: cannot find \"{}\"", what, name);
    return path;
  }
  fs::path beside_this = fs::path(tokens_->file_name()).parent_path() / path;
  if (fs::is_regular_file(beside_this)) return beside_this;
  fs::path beside_top = top_directory_ / path;
  if (beside_top != beside_this && fs::is_regular_file(beside_top)) return beside_top;
  if (beside_top != beside_this)
    throw_scene_error(where, "{}: cannot find \"{}\" (looked for \"{}\" and \"{}\")", what, name,
                      beside_this.string(), beside_top.string());
  throw_scene_error(where, "{}: cannot find \"{}\" (looked for \"{}\")", what, name, beside_this.string());
}

void PbrtParser::check_end_of_scene(const SourceLocation& end) const {
  if (section_ != Section::World)
    throw_scene_error(end, "the scene ends before WorldBegin; the shapes and lights must follow a WorldBegin");
  if (!blocks_.empty()) {
    const OpenBlock& block = blocks_.back();
    throw_scene_error(block.where, "{} is never closed by {} before the end of the scene", block.opener,
                      block.kind == BlockKind::Object ? "ObjectEnd" : "AttributeEnd");
  }
}

// ---------------------------------------------------------------- reading arguments

Token PbrtParser::expect_string(const Token& directive, std::string_view what) {
  Token token = tokens_->next();
  if (token.kind != TokenKind::String)
    throw_scene_error(at(token), "{}: expected {} as a quoted string, got {}", directive.text, what, describe(token));
  return token;
}

double PbrtParser::expect_number(const Token& directive, int index, int count) {
  Token token = tokens_->next();
  std::optional<double> value = token.kind == TokenKind::Word ? parse_number(token.text) : std::nullopt;
  if (!value)
    throw_scene_error(at(token), "{}: expected {} numbers, got {} as number {}", directive.text, count,
                      describe(token), index + 1);
  return *value;
}

Vec3 PbrtParser::read_vec3(const Token& directive, int first_index, int count) {
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = static_cast<float>(expect_number(directive, first_index + i, count));
  return v;
}

// pbrt writes matrices column by column (the translation is in elements 13 to 15).
Matrix4 PbrtParser::read_bracketed_matrix(const Token& directive) {
  Token open = tokens_->next();
  if (open.kind != TokenKind::OpenBracket)
    throw_scene_error(at(open), "{}: expected \"[\" and 16 numbers, got {}", directive.text, describe(open));
  Matrix4 m;
  for (int i = 0; i < 16; ++i) m.m[i % 4][i / 4] = expect_number(directive, i, 16);
  Token close = tokens_->next();
  if (close.kind != TokenKind::CloseBracket)
    throw_scene_error(at(close), "{}: expected \"]\" after 16 numbers, got {}", directive.text, describe(close));
  return m;
}

std::vector<Param> PbrtParser::read_param_vector(const std::string& owner) {
  std::vector<Param> params;
  while (tokens_->peek().kind == TokenKind::String) {
    Token declaration = tokens_->next();
    Param param = read_param(declaration, owner);
    for (const Param& earlier : params)
      if (earlier.name == param.name)
        throw_scene_error(param.where, "{}: parameter \"{}\" is given twice (first at {})", owner, param.name,
                          earlier.where.to_string());
    params.push_back(std::move(param));
  }
  return params;
}

// `target` names the Attribute defaults that apply to this directive.
ParamList PbrtParser::read_params(const Token& directive, std::string owner, AttributeTarget target) {
  std::vector<Param> params = read_param_vector(owner);
  std::vector<Param> defaults;
  if (target < kAttributeTargets) defaults = state_.attributes[target];
  return ParamList(std::move(owner), at(directive), std::move(params), std::move(defaults));
}

Param PbrtParser::read_param(const Token& declaration, const std::string& owner) {
  std::istringstream words(declaration.text);
  std::string type, name, extra;
  words >> type >> name >> extra;
  if (name.empty() || !extra.empty())
    throw_scene_error(at(declaration), "{}: expected a parameter declared as \"type name\", got {}", owner,
                      describe(declaration));
  Param param;
  param.type = canonical_type(type);
  param.name = name;
  param.where = at(declaration);
  std::optional<ValueKind> kind = value_kind_of(param.type);
  if (!kind)
    throw_scene_error(param.where,
                      "{}: unknown parameter type \"{}\" (expected integer, float, point2, vector2, point3, vector3, "
                      "normal, rgb, spectrum, blackbody, bool, string or texture)",
                      owner, type);
  param.kind = *kind;

  Token first = tokens_->next();
  if (first.kind == TokenKind::OpenBracket) {
    while (true) {
      Token value = tokens_->next();
      if (value.kind == TokenKind::CloseBracket) break;
      if (value.kind == TokenKind::End)
        throw_scene_error(at(first), "{}: the \"[\" of {} is never closed by \"]\"", owner, param.declaration());
      add_value(param, value, owner);
    }
  } else {
    add_value(param, first, owner);  // a single value may be written without brackets
  }
  if (param.count() == 0) throw_scene_error(param.where, "{}: {} has no values", owner, param.declaration());
  return param;
}

void PbrtParser::add_value(Param& param, const Token& value, const std::string& owner) {
  bool is_word = value.kind == TokenKind::Word;
  switch (param.kind) {
    case ValueKind::Number:
      if (std::optional<double> number = is_word ? parse_number(value.text) : std::nullopt) {
        param.numbers.push_back(*number);
        return;
      }
      throw_scene_error(at(value), "{}: {} expects numbers, got {}", owner, param.declaration(), describe(value));
    case ValueKind::Integer:
      if (std::optional<int> integer = is_word ? parse_integer(value.text) : std::nullopt) {
        param.numbers.push_back(*integer);
        return;
      }
      throw_scene_error(at(value), "{}: {} expects integers, got {}", owner, param.declaration(), describe(value));
    case ValueKind::Bool:
      // pbrt-v4 writes true/false bare; pbrt-v3 wrote them quoted. Both are read.
      if ((is_word || value.kind == TokenKind::String) && (value.text == "true" || value.text == "false")) {
        param.bools.push_back(value.text == "true");
        return;
      }
      throw_scene_error(at(value), "{}: {} expects true or false, got {}", owner, param.declaration(),
                        describe(value));
    case ValueKind::String:
      if (value.kind == TokenKind::String) {
        param.strings.push_back(value.text);
        return;
      }
      throw_scene_error(at(value), "{}: {} expects quoted strings, got {}", owner, param.declaration(),
                        describe(value));
    case ValueKind::Spectrum:
      // A named spectrum ("metal-Cu-eta") or (wavelength, value) pairs, not both.
      if (value.kind == TokenKind::String && param.numbers.empty()) {
        param.strings.push_back(value.text);
        return;
      }
      if (std::optional<double> number = is_word ? parse_number(value.text) : std::nullopt;
          number && param.strings.empty()) {
        param.numbers.push_back(*number);
        return;
      }
      throw_scene_error(at(value), "{}: {} expects one spectrum name or (wavelength, value) pairs, got {}", owner,
                        param.declaration(), describe(value));
  }
}

// ---------------------------------------------------------------- state checks

void PbrtParser::require_world(const Token& directive) const {
  if (section_ != Section::World)
    throw_scene_error(at(directive), "{} is not allowed before WorldBegin (it belongs in the world section)",
                      directive.text);
}

void PbrtParser::require_options(const Token& directive) const {
  if (section_ == Section::World)
    throw_scene_error(at(directive),
                      "{} is not allowed after WorldBegin (at {}); rendering options come before WorldBegin",
                      directive.text, world_begin_.to_string());
}

void PbrtParser::push_block(const Token& directive, BlockKind kind) {
  blocks_.push_back({kind, directive.text, at(directive), state_});
}

void PbrtParser::pop_block(const Token& directive, BlockKind kind) {
  std::string_view opener = kind == BlockKind::Object ? "ObjectBegin" : "AttributeBegin";
  if (blocks_.size() <= block_floor_) {
    if (block_floor_ > 0)
      throw_scene_error(at(directive), "{} without a matching {} in this imported file", directive.text, opener);
    throw_scene_error(at(directive), "{} without a matching {}", directive.text, opener);
  }
  const OpenBlock& open = blocks_.back();
  if (open.kind != kind)
    throw_scene_error(at(directive), "{} does not match the open {} at {}", directive.text, open.opener,
                      open.where.to_string());
  state_ = open.saved;
  blocks_.pop_back();
}

// ---------------------------------------------------------------- transform directives

void PbrtParser::scale(const Token& d) {
  Vec3 s = read_vec3(d);
  if (s.x == 0 || s.y == 0 || s.z == 0)
    throw_scene_error(at(d), "Scale: the factors must be non-zero, got {} {} {}", s.x, s.y, s.z);
  post_multiply_ctm(Transform::scale(s));
}

void PbrtParser::rotate(const Token& d) {
  float degrees = static_cast<float>(expect_number(d, 0, 4));
  Vec3 axis = read_vec3(d, 1, 4);
  if (axis == Vec3(0.0f)) throw_scene_error(at(d), "Rotate: the rotation axis must not be zero");
  post_multiply_ctm(Transform::rotate(degrees, axis));
}

void PbrtParser::look_at(const Token& d) {
  Point3 eye = read_vec3(d, 0, 9);
  Point3 target = read_vec3(d, 3, 9);
  Vec3 up = read_vec3(d, 6, 9);
  if (eye == target) throw_scene_error(at(d), "LookAt: the eye and the look-at point are the same");
  float sine = up == Vec3(0.0f) ? 0.0f : length(cross(normalize(up), normalize(target - eye)));
  if (!(sine >= 1e-6f))
    throw_scene_error(at(d), "LookAt: the up vector is zero or parallel to the viewing direction");
  post_multiply_ctm(Transform::look_at_pbrt(eye, target, up));
}

void PbrtParser::transform(const Token& d) {
  std::optional<Transform> t = Transform::from_matrix(read_bracketed_matrix(d));
  if (!t) throw_scene_error(at(d), "Transform: the matrix is singular (it has no inverse)");
  update_active_ctms([&](const Transform&) { return *t; });
}

void PbrtParser::concat_transform(const Token& d) {
  std::optional<Transform> t = Transform::from_matrix(read_bracketed_matrix(d));
  if (!t) throw_scene_error(at(d), "ConcatTransform: the matrix is singular (it has no inverse)");
  post_multiply_ctm(*t);
}

void PbrtParser::coordinate_system(const Token& d) {
  coordinate_systems_[expect_string(d, "a name").text] = state_.ctm;
}

void PbrtParser::coord_sys_transform(const Token& d) {
  Token name = expect_string(d, "a coordinate system name");
  auto system = coordinate_systems_.find(name.text);
  if (system == coordinate_systems_.end())
    throw_scene_error(at(name),
                      "CoordSysTransform: no coordinate system named \"{}\" (\"camera\" exists after Camera, "
                      "\"world\" after WorldBegin, others after CoordinateSystem)",
                      name.text);
  state_.ctm = system->second;
}

void PbrtParser::active_transform(const Token& d) {
  Token which = tokens_->next();
  bool is_word = which.kind == TokenKind::Word;
  if (is_word && which.text == "StartTime")
    state_.active_transforms = kStartTransform;
  else if (is_word && which.text == "EndTime")
    state_.active_transforms = kEndTransform;
  else if (is_word && which.text == "All")
    state_.active_transforms = kAllTransforms;
  else
    throw_scene_error(at(which), "{}: expected StartTime, EndTime or All, got {}", d.text, describe(which));
}

void PbrtParser::transform_times(const Token& d) {
  require_options(d);
  double start = expect_number(d, 0, 2), end = expect_number(d, 1, 2);
  // Shapes are interpolated between the two times, so they must span an interval.
  if (!(start < end))
    throw_scene_error(at(d), "TransformTimes: the start time must be less than the end time, got {} and {}", start,
                      end);
  scene_.transform_start_time = static_cast<float>(start);
  scene_.transform_end_time = static_cast<float>(end);
}

// ---------------------------------------------------------------- attribute blocks

void PbrtParser::attribute_begin(const Token& d) {
  require_world(d);
  push_block(d, BlockKind::Attribute);
}

void PbrtParser::attribute_end(const Token& d) {
  require_world(d);
  pop_block(d, BlockKind::Attribute);
}

// Attribute "target" params: defaults for the parameters of every following directive of that kind
// in this attribute block (pbrt-v4).
void PbrtParser::attribute(const Token& d) {
  require_world(d);
  Token target =
      expect_string(d, "the attribute target (\"shape\", \"light\", \"material\", \"medium\" or \"texture\")");
  AttributeTarget index = kAttributeTargets;
  if (target.text == "shape") index = kShapeAttributes;
  if (target.text == "light") index = kLightAttributes;
  if (target.text == "material") index = kMaterialAttributes;
  if (target.text == "medium") index = kMediumAttributes;
  if (target.text == "texture") index = kTextureAttributes;
  if (index == kAttributeTargets)
    throw_scene_error(at(target), "Attribute: unknown target \"{}\" (expected \"shape\", \"light\", \"material\", "
                      "\"medium\" or \"texture\")", target.text);
  std::vector<Param> params = read_param_vector(fmt::format("Attribute \"{}\"", target.text));
  if (index == kMediumAttributes && !params.empty())
    warn(at(d), "Attribute \"medium\" is ignored: participating media are not supported");
  std::vector<Param>& defaults = state_.attributes[index];
  for (Param& param : params) {
    auto same = std::find_if(defaults.begin(), defaults.end(), [&](const Param& p) { return p.name == param.name; });
    if (same != defaults.end())
      *same = std::move(param);
    else
      defaults.push_back(std::move(param));
  }
}

void PbrtParser::reverse_orientation(const Token& d) {
  require_world(d);
  state_.reverse_orientation = !state_.reverse_orientation;
}

// ---------------------------------------------------------------- rendering options

void PbrtParser::camera(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the camera type");
  if (type.text != "perspective")
    reject_type(at(type), "camera", type.text, {"perspective"}, {"orthographic", "realistic", "spherical"});
  ParamList params = read_params(d, "Camera \"perspective\"");
  float fov = params.get_float("fov", 90);
  if (!(fov > 0 && fov < 180)) params.fail("fov", "must be between 0 and 180 degrees, got {}", fov);
  float lens_radius = params.get_float("lensradius", 0);
  if (lens_radius < 0) params.fail("lensradius", "must not be negative, got {}", lens_radius);
  float focus_distance = params.get_float("focaldistance", 1e6f);
  if (!(focus_distance > 0)) params.fail("focaldistance", "must be positive, got {}", focus_distance);
  float shutter_open = params.get_float("shutteropen", 0);
  float shutter_close = params.get_float("shutterclose", 1);
  // pbrt swaps the two with a warning; candela has no warnings, so this is an error.
  if (shutter_close < shutter_open)
    params.fail("shutterclose", "must not be less than \"shutteropen\" ({}), got {}", shutter_open, shutter_close);
  params.reject_unused();
  if (state_.ctm.is_animated())
    throw_scene_error(at(d),
                      "Camera: the camera transform is animated (ActiveTransform made the start and end CTMs "
                      "differ); a moving camera is not supported");

  // The CTM maps world space to camera space here; pbrt names the inverse "camera".
  CameraDesc& camera = scene_.camera;
  camera.world_from_camera = state_.ctm.start.inverse();
  camera.fov_degrees = fov;
  camera.fov_axis = FovAxis::Smaller;
  camera.lens_radius = lens_radius;
  camera.focus_distance = focus_distance;
  camera.shutter_open = shutter_open;
  camera.shutter_close = shutter_close;
  coordinate_systems_["camera"] = {camera.world_from_camera, camera.world_from_camera};
}

void PbrtParser::film(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the film type");
  if (type.text != "rgb") reject_type(at(type), "film", type.text, {"rgb"}, {"gbuffer", "spectral"});
  ParamList params = read_params(d, "Film \"rgb\"");
  int width = params.get_int("xresolution", 1280);
  int height = params.get_int("yresolution", 720);
  if (width < 1 || width > kMaxResolutionPerSide)
    params.fail("xresolution", "must be between 1 and {}, got {}", kMaxResolutionPerSide, width);
  if (height < 1 || height > kMaxResolutionPerSide)
    params.fail("yresolution", "must be between 1 and {}, got {}", kMaxResolutionPerSide, height);
  if (int64_t{width} * height > kMaxPixels)
    throw_scene_error(params.where(params.has("yresolution") ? "yresolution" : "xresolution"),
                      "Film \"rgb\": {} x {} is too many pixels (at most 2^28 = {})", width, height, kMaxPixels);
  std::string filename = params.get_string("filename", "");
  params.get_bool("savefp16", true);  // the precision of the output file only
  ignore_param(params, "maxcomponentvalue", "candela does not clamp sample values (pbrt would, trading energy "
               "for fewer fireflies)");
  params.reject_unused();
  scene_.film.width = width;
  scene_.film.height = height;
  scene_.film.filename = filename;
}

void PbrtParser::sampler(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the sampler type");
  const std::string& name = type.text;
  // pbrt-v4's other low-discrepancy samplers become candela's zsobol with the same sample count.
  bool replaced = name == "sobol" || name == "halton" || name == "pmj02bn" || name == "paddedsobol";
  if (name != "independent" && name != "stratified" && name != "zsobol" && !replaced)
    reject_type(at(type), "sampler", name,
                {"independent", "stratified", "zsobol", "sobol", "halton", "paddedsobol", "pmj02bn"}, {});
  ParamList params = read_params(d, fmt::format("Sampler \"{}\"", name));
  SamplerDesc sampler;
  int64_t spp = 0;
  if (name == "independent") {
    sampler.type = SamplerType::Independent;
    spp = params.get_int("pixelsamples", 4);
  } else if (name == "stratified") {
    // The stratified sampler takes a grid of xsamples x ysamples per pixel instead of pixelsamples.
    sampler.type = SamplerType::Stratified;
    int x = params.get_int("xsamples", 4), y = params.get_int("ysamples", 4);
    if (x < 1) params.fail("xsamples", "must be positive, got {}", x);
    if (y < 1) params.fail("ysamples", "must be positive, got {}", y);
    sampler.jitter = params.get_bool("jitter", true);
    spp = int64_t{x} * y;
    if (spp > INT_MAX) params.fail("ysamples", "makes {} samples per pixel, too many", spp);
  } else {
    sampler.type = SamplerType::ZSobol;
    spp = params.get_int("pixelsamples", 16);
    // candela's ZSobol is always Owen-scrambled; the other choices only change the sample pattern.
    if (name != "pmj02bn") {
      std::string randomization = params.get_string("randomization", "fastowen");
      if (randomization != "none" && randomization != "permutedigits" && randomization != "fastowen" &&
          randomization != "owen")
        params.fail("randomization", "must be \"none\", \"permutedigits\", \"fastowen\" or \"owen\", got \"{}\"",
                    randomization);
    }
  }
  if (spp < 1) params.fail("pixelsamples", "must be positive, got {}", spp);
  int seed = params.get_int("seed", 0);
  if (seed < 0) params.fail("seed", "must not be negative, got {}", seed);
  params.reject_unused();
  if (name == "sobol")
    warn(at(type), "sobol: using candela's zsobol sampler (same Owen-scrambled Sobol' points, Morton-ordered)");
  else if (replaced)
    warn(at(type), "{}: using candela's zsobol sampler (Owen-scrambled Sobol' points, Morton-ordered; the same "
         "number of samples, a different pattern)", name);
  scene_.settings.sampler = sampler;
  // Metropolis light transport counts mutations per pixel (its own parameter), not pixel samples.
  if (scene_.settings.integrator != "mlt") scene_.settings.spp = static_cast<int>(spp);
  if (params.has("seed")) scene_.settings.seed = static_cast<uint64_t>(seed);
}

// Every pbrt-v4 integrator is rendered with candela's path tracer at the scene's "maxdepth"; the
// parameters the others have are accepted with a warning that they are ignored.
void PbrtParser::integrator(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the integrator type");
  static const std::map<std::string, std::vector<std::string_view>, std::less<>> kOwnParameters = {
      {"path", {}},
      {"volpath", {}},
      {"bdpt", {"visualizestrategies", "visualizeweights"}},
      {"mlt", {"bootstrapsamples", "chains", "mutationsperpixel", "largestepprobability", "sigma"}},
      {"sppm", {"photonsperiteration", "radius", "seed"}},
      {"lightpath", {}},
      {"randomwalk", {}},
      {"simplepath", {"samplelights", "samplebsdf"}},
      {"simplevolpath", {}},
  };
  // Ambient occlusion is a different image altogether, not another way to the same one.
  if (type.text == "ambientocclusion")
    throw_scene_error(at(type), "Integrator \"ambientocclusion\" is not supported: candela renders global "
                      "illumination, which would be a different image (use \"path\")");
  auto known = kOwnParameters.find(type.text);
  if (known == kOwnParameters.end())
    reject_type(at(type), "integrator", type.text,
                {"path", "volpath", "bdpt", "mlt", "sppm", "lightpath", "randomwalk",
                 "simplepath", "simplevolpath"},
                {});
  ParamList params = read_params(d, fmt::format("Integrator \"{}\"", type.text));
  int max_depth = params.get_int("maxdepth", 5);
  if (max_depth < 0) params.fail("maxdepth", "must not be negative, got {}", max_depth);
  if (type.text == "path" || type.text == "volpath" || type.text == "bdpt") read_light_sampler(params);
  if (type.text == "path" || type.text == "volpath" || type.text == "bdpt" || type.text == "mlt") {
    if (params.get_bool("regularize", false))
      warn(params.where("regularize"), "Integrator \"{}\": \"regularize\" is ignored: candela does not roughen "
           "near-specular surfaces (the image keeps the caustics pbrt would blur)", type.text);
  }
  std::string integrator = "path";
  if (type.text == "bdpt") {
    integrator = "bdpt";
    for (std::string_view name : known->second)
      ignore_param(params, name, "use candela's --bdpt-strategies DIR (and --bdpt-unweighted) instead");
  } else if (type.text == "mlt") {
    integrator = "mlt";
    RenderSettings& rs = scene_.settings;
    int mutations = params.get_int("mutationsperpixel", 100);
    if (mutations < 1) params.fail("mutationsperpixel", "must be positive, got {}", mutations);
    int bootstrap = params.get_int("bootstrapsamples", 100000);
    if (bootstrap < 1) params.fail("bootstrapsamples", "must be positive, got {}", bootstrap);
    int chains = params.get_int("chains", 1000);
    if (chains < 1) params.fail("chains", "must be positive, got {}", chains);
    float large_step = params.get_float("largestepprobability", 0.3f);
    if (!(large_step >= 0 && large_step <= 1))
      params.fail("largestepprobability", "must be in [0, 1], got {}", large_step);
    float sigma = params.get_float("sigma", 0.01f);
    if (!(sigma > 0 && sigma <= 1)) params.fail("sigma", "must be in (0, 1], got {}", sigma);
    rs.spp = mutations;
    rs.mlt.bootstrap = bootstrap;
    rs.mlt.chains = chains;
    rs.mlt.large_step = large_step;
    rs.mlt.sigma = sigma;
  } else {
    for (std::string_view name : known->second)
      ignore_param(params, name, "candela's path integrator has no such setting");
  }
  params.reject_unused();
  if (type.text == "volpath")
    warn(at(type), "Integrator \"volpath\": using candela's path integrator; without participating media (which "
         "candela does not render) it is the same integrator");
  else if (integrator == "path" && type.text != "path")
    warn(at(type), "Integrator \"{}\": using candela's path integrator with maxdepth {} (it converges to the "
         "same image, with different noise)", type.text, max_depth);
  scene_.settings.integrator = integrator;
  scene_.settings.max_depth = max_depth;
}

// pbrt's "power" chooses lights by power, as candela does. Its default "bvh" also weighs each light
// by its distance and orientation from the shading point; candela has no light BVH and uses "power"
// for it too, which changes only the noise.
void PbrtParser::read_light_sampler(ParamList& params) {
  std::string light_sampler = params.get_string("lightsampler", "bvh");
  if (light_sampler == "uniform" || light_sampler == "exhaustive")
    params.fail("lightsampler", "\"{}\" is not supported yet (supported: \"power\", \"bvh\")", light_sampler);
  if (light_sampler != "bvh" && light_sampler != "power")
    params.fail("lightsampler", "must be \"bvh\", \"power\", \"uniform\" or \"exhaustive\", got \"{}\"",
                light_sampler);
  scene_.settings.light_selection = LightSelection::Power;
}

void PbrtParser::pixel_filter(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the filter type");
  FilterDesc filter;
  if (type.text == "box")
    filter = default_filter(FilterType::Box);
  else if (type.text == "triangle")
    filter = default_filter(FilterType::Tent);
  else if (type.text == "gaussian")
    filter = default_filter(FilterType::Gaussian);
  else if (type.text == "mitchell")
    filter = default_filter(FilterType::Mitchell);
  else
    reject_type(at(type), "pixel filter", type.text, {"box", "triangle", "gaussian", "mitchell"}, {"sinc"});
  ParamList params = read_params(d, fmt::format("PixelFilter \"{}\"", type.text));
  filter.radius = {params.get_float("xradius", filter.radius.x), params.get_float("yradius", filter.radius.y)};
  for (auto [name, radius] : {std::pair{"xradius", filter.radius.x}, std::pair{"yradius", filter.radius.y}})
    if (!(radius > 0 && radius <= kMaxFilterRadius))
      params.fail(name, "must be in (0, {}] pixels, got {}", kMaxFilterRadius, radius);
  if (filter.type == FilterType::Gaussian) {
    filter.gaussian_sigma = params.get_float("sigma", filter.gaussian_sigma);
    if (!(filter.gaussian_sigma > 0)) params.fail("sigma", "must be positive, got {}", filter.gaussian_sigma);
  }
  if (filter.type == FilterType::Mitchell) {
    filter.mitchell_b = params.get_float("B", filter.mitchell_b);
    filter.mitchell_c = params.get_float("C", filter.mitchell_c);
  }
  params.reject_unused();
  scene_.settings.filter = filter;
}

void PbrtParser::option(const Token& d) {
  expect_string(d, "the option name");
  Token value = tokens_->next();
  if (value.kind != TokenKind::Word && value.kind != TokenKind::String)
    throw_scene_error(at(value), "Option: expected a value, got {}", describe(value));
}

void PbrtParser::color_space(const Token& d) {
  Token name = expect_string(d, "the colour space name");
  if (name.text != "srgb")
    warn(at(name), "ColorSpace \"{}\" is ignored: candela reads every colour as linear sRGB (Rec. 709 primaries)",
         name.text);
}

// The acceleration structure is Embree's whatever pbrt's choice; the image does not depend on it.
void PbrtParser::accelerator(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the accelerator type");
  if (type.text != "bvh" && type.text != "kdtree")
    reject_type(at(type), "accelerator", type.text, {"bvh", "kdtree"}, {});
  read_params(d, fmt::format("Accelerator \"{}\"", type.text));  // its parameters only tune the structure
}

void PbrtParser::world_begin(const Token& d) {
  require_options(d);
  section_ = Section::World;
  world_begin_ = at(d);
  state_.ctm = {};
  state_.active_transforms = kAllTransforms;
  coordinate_systems_["world"] = {};
}

// ---------------------------------------------------------------- spectra and textured parameters

using pbrt_spectra::Role;

// A "spectrum" parameter's value as RGB: a named spectrum or (wavelength, value) pairs.
RGB spectrum_rgb(const Param& p, const ParamList& params, Role role) {
  if (!p.strings.empty()) {
    params.expect_count(p, 1);
    const std::string& name = p.strings[0];
    std::optional<pbrt_spectra::NamedSpectrum> named = pbrt_spectra::find_named(name);
    if (!named) {
      std::string names;
      for (std::string_view n : pbrt_spectra::named_spectrum_names())
        names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", n);
      throw_scene_error(p.where,
                        "{}: {}: unknown named spectrum \"{}\" (spectrum files are not supported; the named spectra "
                        "are {})",
                        params.owner(), p.declaration(), name, names);
    }
    bool fits = role == Role::Illuminant ? named->kind == pbrt_spectra::NamedKind::Illuminant
                                         : named->kind != pbrt_spectra::NamedKind::Illuminant;
    if (!fits || role == Role::Reflectance)
      throw_scene_error(p.where, "{}: {}: \"{}\" is {} and does not fit here", params.owner(), p.declaration(), name,
                        named->kind == pbrt_spectra::NamedKind::Illuminant ? "an illuminant spectrum"
                        : named->kind == pbrt_spectra::NamedKind::Metal    ? "a conductor's optical constant"
                                                                           : "a glass's refractive index");
    return named->rgb;
  }
  params.expect_multiple(p, 2);
  for (size_t i = 0; i < p.numbers.size(); i += 2) {
    if (i > 0 && !(p.numbers[i] > p.numbers[i - 2]))
      throw_scene_error(p.where, "{}: {}: the wavelengths must increase ({} follows {})", params.owner(),
                        p.declaration(), p.numbers[i], p.numbers[i - 2]);
    if (p.numbers[i + 1] < 0)
      throw_scene_error(p.where, "{}: {}: the value at {} nm is negative ({})", params.owner(), p.declaration(),
                        p.numbers[i], p.numbers[i + 1]);
  }
  RGB rgb = pbrt_spectra::sampled_spectrum_rgb(p.numbers, role);
  for (int c = 0; c < 3; ++c) rgb[c] = std::max(rgb[c], 0.0f);
  if (role == Role::Reflectance)
    for (int c = 0; c < 3; ++c) rgb[c] = std::min(rgb[c], 1.0f);
  return rgb;
}

// A colour parameter of a material or texture: "rgb", "spectrum" or "texture" (a spectrum texture).
// `is_albedo` limits constant colours to [0, 1], as pbrt-v4 does for reflectances.
std::optional<ColorInput> PbrtParser::read_color(ParamList& params, std::string_view name, Role role) {
  Param* p = params.take(name, {"rgb", "spectrum", "texture"});
  if (!p) return std::nullopt;
  if (p->type == "rgb") return ColorInput(params.checked_rgb(*p, role == Role::Reflectance));
  if (p->type == "spectrum") return ColorInput(spectrum_rgb(*p, params, role));
  params.expect_count(*p, 1);
  auto texture = spectrum_textures_.find(p->strings[0]);
  if (texture == spectrum_textures_.end()) {
    bool is_float = float_textures_.contains(p->strings[0]);
    throw_scene_error(p->where, "{}: {}: no spectrum texture named \"{}\" is defined{}", params.owner(),
                      p->declaration(), p->strings[0],
                      is_float ? " (there is a \"float\" texture of that name; this parameter needs a \"spectrum\" one)"
                               : " (Texture must come first)");
  }
  return texture->second.color;
}

// A float parameter that may be textured: "float" or "texture" (a float texture).
std::optional<FloatInput> PbrtParser::read_float_texture(ParamList& params, std::string_view name) {
  Param* p = params.take(name, {"float", "texture"});
  if (!p) return std::nullopt;
  params.expect_count(*p, 1);
  if (p->type == "float") return FloatInput(static_cast<float>(p->numbers[0]));
  auto texture = float_textures_.find(p->strings[0]);
  if (texture == float_textures_.end()) {
    bool is_spectrum = spectrum_textures_.contains(p->strings[0]);
    throw_scene_error(p->where, "{}: {}: no float texture named \"{}\" is defined{}", params.owner(), p->declaration(),
                      p->strings[0],
                      is_spectrum
                          ? " (there is a \"spectrum\" texture of that name; this parameter needs a \"float\" one)"
                          : " (Texture must come first)");
  }
  return texture->second.value;
}

// A light's emission spectrum: "rgb", "spectrum" (named illuminant or pairs) or "blackbody" (a
// temperature in kelvin). Named and sampled spectra are normalised to luminance 1 as in pbrt-v4;
// RGB values are used as given (pbrt-v4 renders an RGB emission as that RGB).
std::optional<RGB> PbrtParser::read_emission(ParamList& params, std::string_view name) {
  Param* p = params.take(name, {"rgb", "spectrum", "blackbody"});
  if (!p) return std::nullopt;
  if (p->type == "rgb") return params.checked_rgb(*p, false);
  if (p->type == "spectrum") return spectrum_rgb(*p, params, Role::Illuminant);
  if (p->count() != 1)
    throw_scene_error(p->where, "{}: {} takes one value, the temperature in kelvin, got {} (pbrt-v3's second "
                      "\"scale\" value is not pbrt-v4 syntax)", params.owner(), p->declaration(), p->count());
  double kelvin = p->numbers[0];
  if (!(kelvin > 0))
    throw_scene_error(p->where, "{}: {}: the temperature must be positive, got {}", params.owner(), p->declaration(),
                      kelvin);
  return pbrt_spectra::blackbody_rgb(static_cast<float>(kelvin));
}

// A dielectric's index of refraction: "float", or a "spectrum" (a named glass or pairs) taken at
// 550 nm, since candela does not disperse light.
std::optional<float> PbrtParser::read_ior(ParamList& params, std::string_view name) {
  Param* p = params.take(name, {"float", "spectrum", "rgb"});
  if (!p) return std::nullopt;
  float ior = 0;
  if (p->type == "float") {
    params.expect_count(*p, 1);
    ior = static_cast<float>(p->numbers[0]);
  } else if (p->type == "rgb") {
    RGB rgb = params.checked_rgb(*p, false);
    ior = rgb.g;
    warn(p->where, "{}: {}: candela does not disperse light; the green value {} is the index of refraction",
         params.owner(), p->declaration(), ior);
  } else if (!p->strings.empty()) {
    params.expect_count(*p, 1);
    std::optional<pbrt_spectra::NamedSpectrum> named = pbrt_spectra::find_named(p->strings[0]);
    if (named && named->kind == pbrt_spectra::NamedKind::Glass)
      ior = named->ior_550nm;
    else
      throw_scene_error(p->where,
                        "{}: {}: \"{}\" is not one of pbrt-v4's glasses (\"glass-BK7\", \"glass-BAF10\", "
                        "\"glass-FK51A\", \"glass-LASF9\", \"glass-F5\", \"glass-F10\", \"glass-F11\")",
                        params.owner(), p->declaration(), p->strings[0]);
  } else {
    spectrum_rgb(*p, params, Role::Unbounded);  // validates the pairs
    ior = pbrt_spectra::sampled_spectrum_at(p->numbers, 550);
  }
  if (!(ior > 0)) throw_scene_error(p->where, "{}: \"{}\" must be positive, got {}", params.owner(), name, ior);
  return ior;
}

// pbrt-v4's microfacet roughness: "roughness" for both axes unless "uroughness"/"vroughness" are
// given; "remaproughness" (true) reads them as roughness and uses alpha = sqrt(roughness).
Roughness PbrtParser::read_roughness(ParamList& params) {
  Roughness roughness;
  FloatInput both = read_float_texture(params, "roughness").value_or(FloatInput(0.0f));
  roughness.u = read_float_texture(params, "uroughness").value_or(both);
  roughness.v = read_float_texture(params, "vroughness").value_or(both);
  roughness.remap = params.get_bool("remaproughness", true);
  for (auto [name, value] : {std::pair{"roughness", both}, std::pair{"uroughness", roughness.u},
                             std::pair{"vroughness", roughness.v}})
    if (value.is_constant() && value.value < 0) params.fail(name, "must not be negative, got {}", value.value);
  return roughness;
}

void PbrtParser::ignore_shading_params(ParamList& params) {
  ignore_param(params, "displacement", "displacement mapping is not supported");
  ignore_param(params, "normalmap", "normal maps are not supported");
}

int PbrtParser::add_texture(TextureDesc texture) {
  scene_.textures.push_back(std::move(texture));
  return static_cast<int>(scene_.textures.size()) - 1;
}

// ---------------------------------------------------------------- textures

UVMapping PbrtParser::read_uv_mapping(ParamList& params) {
  std::string mapping = params.get_string("mapping", "uv");
  if (mapping == "spherical" || mapping == "cylindrical" || mapping == "planar")
    params.fail("mapping", "\"{}\" is not supported (only \"uv\")", mapping);
  if (mapping != "uv")
    params.fail("mapping", "must be \"uv\", \"spherical\", \"cylindrical\" or \"planar\", got \"{}\"", mapping);
  UVMapping uv;
  uv.su = params.get_float("uscale", 1);
  uv.sv = params.get_float("vscale", 1);
  uv.du = params.get_float("udelta", 0);
  uv.dv = params.get_float("vdelta", 0);
  return uv;
}

ImageTexture PbrtParser::make_image_texture(ParamList& params) {
  ImageTexture texture;
  if (!params.has("filename")) params.fail("filename", "is required: name the image file");
  std::string name = params.get_string("filename", "");
  fs::path file = resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner()));
  texture.filename = file.string();

  std::string filter = params.get_string("filter", "bilinear");
  if (filter == "point") {
    texture.bilinear = false;
  } else if (filter == "trilinear" || filter == "ewa") {
    warn(params.where("filter"),
         "{}: filter \"{}\" is read as \"bilinear\": candela does not mipmap textures (minified textures alias "
         "where pbrt would blur them)",
         params.owner(), filter);
  } else if (filter != "bilinear") {
    params.fail("filter", "must be \"point\", \"bilinear\", \"trilinear\" or \"ewa\", got \"{}\"", filter);
  }
  params.get_float("maxanisotropy", 8);  // only for "ewa"

  std::string wrap = params.get_string("wrap", "repeat");
  if (wrap == "repeat")
    texture.wrap = TextureWrap::Repeat;
  else if (wrap == "black")
    texture.wrap = TextureWrap::Black;
  else if (wrap == "clamp")
    texture.wrap = TextureWrap::Clamp;
  else if (wrap == "octahedralsphere")
    params.fail("wrap", "\"octahedralsphere\" is not supported for image textures (only for environment maps)");
  else
    params.fail("wrap", "must be \"repeat\", \"black\", \"clamp\" or \"octahedralsphere\", got \"{}\"", wrap);

  texture.scale = params.get_float("scale", 1);
  texture.invert = params.get_bool("invert", false);

  // pbrt-v4's "encoding" defaults to "sRGB" for .png files and to "linear" for others, but it reads
  // every 8-bit format other than PNG (.tga, .jpg, ...) through stb_image as sRGB whatever the
  // parameter says: 8-bit files are sRGB, float files linear, which is ColorEncoding::Auto. (Checked
  // on veach-ajar's .tga textures against its pbrt-v4 reference render.) An explicit "encoding" is
  // honoured for every file.
  texture.encoding = ColorEncoding::Auto;
  if (params.has("encoding")) {
    std::string encoding = params.get_string("encoding", "");
    if (encoding == "sRGB") {
      texture.encoding = ColorEncoding::SRGB;
    } else if (encoding == "linear") {
      texture.encoding = ColorEncoding::Linear;
    } else if (encoding.starts_with("gamma ")) {
      std::optional<double> gamma = parse_number(std::string_view(encoding).substr(6));
      if (!gamma || !(*gamma > 0)) params.fail("encoding", "\"{}\" needs a positive gamma value", encoding);
      if (std::abs(*gamma - 1) < 1e-3) {
        texture.encoding = ColorEncoding::Linear;
      } else if (std::abs(*gamma - 2.2) <= 0.1) {
        texture.encoding = ColorEncoding::SRGB;
        warn(params.where("encoding"), "{}: \"encoding\" \"{}\" is read as sRGB (the closest curve candela has)",
             params.owner(), encoding);
      } else {
        params.fail("encoding", "\"{}\" is not supported (only \"sRGB\", \"linear\" and gammas near 1 or 2.2)",
                    encoding);
      }
    } else {
      params.fail("encoding", "must be \"sRGB\", \"linear\" or \"gamma <value>\", got \"{}\"", encoding);
    }
  }
  texture.mapping = read_uv_mapping(params);
  return texture;
}

// A texture's input: a spectrum texture's "rgb"/"spectrum"/"texture" or a float texture's
// "float"/"texture" (as a grey colour).
ColorInput PbrtParser::read_texture_input(ParamList& params, std::string_view name, bool is_float, RGB fallback) {
  if (!is_float) return read_color(params, name, Role::Unbounded).value_or(ColorInput(fallback));
  std::optional<FloatInput> value = read_float_texture(params, name);
  if (!value) return ColorInput(fallback);
  ColorInput color;
  if (value->is_constant())
    color.value = RGB(value->value);
  else
    color.texture = value->texture;
  return color;
}

void PbrtParser::texture(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the texture name");
  Token kind = expect_string(d, "the texture's value type (\"spectrum\" or \"float\")");
  if (kind.text != "spectrum" && kind.text != "float")
    throw_scene_error(at(kind), "Texture \"{}\": the value type must be \"spectrum\" or \"float\", got \"{}\"",
                      name.text, kind.text);
  bool is_float = kind.text == "float";
  Token type = expect_string(d, "the texture type");
  auto& table = is_float ? float_textures_ : spectrum_textures_;
  if (auto earlier = table.find(name.text); earlier != table.end())
    throw_scene_error(at(name), "Texture: {} texture \"{}\" is already defined at {}", kind.text, name.text,
                      earlier->second.where.to_string());
  ParamList params =
      read_params(d, fmt::format("Texture \"{}\" \"{}\" \"{}\"", name.text, kind.text, type.text), kTextureAttributes);

  NamedTexture named;
  named.where = at(name);
  if (type.text == "imagemap") {
    named.index = add_texture(make_image_texture(params));
  } else if (type.text == "checkerboard") {
    int dimension = params.get_int("dimension", 2);
    if (dimension == 3) params.fail("dimension", "3: solid (3D) checkerboards are not supported");
    if (dimension != 2) params.fail("dimension", "must be 2 or 3, got {}", dimension);
    CheckerboardTexture checkerboard;
    checkerboard.mapping = read_uv_mapping(params);
    checkerboard.tex1 = read_texture_input(params, "tex1", is_float, RGB(1.0f));
    checkerboard.tex2 = read_texture_input(params, "tex2", is_float, RGB(0.0f));
    named.index = add_texture(checkerboard);
  } else if (type.text == "scale") {
    ScaleTexture scale;
    scale.tex = read_texture_input(params, "tex", is_float, RGB(1.0f));
    scale.scale = read_float_texture(params, "scale").value_or(FloatInput(1.0f));
    named.index = add_texture(scale);
  } else if (type.text == "mix") {
    MixTexture mix;
    mix.tex1 = read_texture_input(params, "tex1", is_float, RGB(0.0f));
    mix.tex2 = read_texture_input(params, "tex2", is_float, RGB(1.0f));
    mix.amount = read_float_texture(params, "amount").value_or(FloatInput(0.5f));
    named.index = add_texture(mix);
  } else if (type.text == "constant") {
    // No texture at all: parameters that name it get its value.
    if (is_float) {
      named.value = FloatInput(params.get_float("value", 1));
      named.color = ColorInput(RGB(named.value.value));
    } else {
      named.color = read_color(params, "value", Role::Unbounded).value_or(ColorInput(RGB(1.0f)));
      named.value = FloatInput(named.color.value.average());
    }
  } else {
    reject_type(at(type), "texture", type.text, {"imagemap", "checkerboard", "scale", "mix", "constant"},
                {"bilerp", "directionmix", "dots", "fbm", "marble", "ptex", "windy", "wrinkled"},
                "candela has no such texture");
  }
  params.reject_unused();
  if (named.index >= 0) {
    named.color.texture = named.index;
    named.value.texture = named.index;
  }
  table[name.text] = named;
}

// ---------------------------------------------------------------- materials

// c * scale, with a ScaleTexture when c is a texture.
ColorInput scaled(ColorInput c, float scale, std::vector<TextureDesc>& textures) {
  if (scale == 1) return c;
  if (c.is_constant()) return ColorInput(c.value * scale);
  ScaleTexture t;
  t.tex = c;
  t.scale = FloatInput(scale);
  textures.push_back(t);
  ColorInput result;
  result.texture = static_cast<int>(textures.size()) - 1;
  return result;
}

MaterialDesc PbrtParser::make_material(const std::string& type, const SourceLocation& type_where,
                                       ParamList& params) {
  if (type == "diffuse") {
    DiffuseMaterial m;
    m.reflectance = read_color(params, "reflectance", Role::Reflectance).value_or(ColorInput(RGB(0.5f)));
    ignore_shading_params(params);
    return m;
  }
  if (type == "conductor") {
    ConductorMaterial m;  // pbrt-v4's default is copper, as ConductorMaterial's
    std::optional<ColorInput> eta = read_color(params, "eta", Role::Unbounded);
    std::optional<ColorInput> k = read_color(params, "k", Role::Unbounded);
    std::optional<ColorInput> reflectance = read_color(params, "reflectance", Role::Reflectance);
    if (reflectance && (eta || k))
      params.fail("reflectance", "cannot be given together with \"{}\" (as in pbrt-v4: the normal-incidence "
                  "reflectance replaces the optical constants)", eta ? "eta" : "k");
    if (eta) m.eta = *eta;
    if (k) m.k = *k;
    m.reflectance = reflectance;
    m.roughness = read_roughness(params);
    ignore_shading_params(params);
    return m;
  }
  if (type == "dielectric") {
    DielectricMaterial m;
    m.ior = read_ior(params, "eta").value_or(1.5f);
    m.roughness = read_roughness(params);
    ignore_shading_params(params);
    return m;
  }
  if (type == "coateddiffuse") {
    CoatedDiffuseMaterial m;
    m.reflectance = read_color(params, "reflectance", Role::Reflectance).value_or(ColorInput(RGB(0.5f)));
    m.roughness = read_roughness(params);
    m.ior = read_ior(params, "eta").value_or(1.5f);
    // candela's coat is the closed form of Mitsuba's plastic: an interface over a Lambertian base
    // with every internal bounce summed, no layer in between. pbrt-v4 simulates the layer.
    bool own_thickness = params.has_own("thickness");
    if (std::optional<FloatInput> thickness = read_float_texture(params, "thickness"); thickness && own_thickness)
      warn(params.where("thickness"),
           "{}: \"thickness\" is ignored: candela's coated diffuse has no layer between coat and base (the "
           "closed-form Mitsuba plastic model)",
           params.owner());
    std::optional<ColorInput> albedo = read_color(params, "albedo", Role::Reflectance);
    if (albedo && !(albedo->is_constant() && albedo->value.is_black()))
      warn(params.where("albedo"),
           "{}: \"albedo\" is ignored: candela's coated diffuse has no scattering medium between coat and base "
           "(the closed-form Mitsuba plastic model); the layer is rendered as if empty",
           params.owner());
    read_float_texture(params, "g");                  // only matters with an albedo
    int max_depth = params.get_int("maxdepth", 10);   // pbrt's random walk through the layer: candela
    int samples = params.get_int("nsamples", 1);      // sums the whole series in closed form
    if (max_depth < 1) params.fail("maxdepth", "must be positive, got {}", max_depth);
    if (samples < 1) params.fail("nsamples", "must be positive, got {}", samples);
    ignore_shading_params(params);
    return m;
  }
  if (type == "diffusetransmission") {
    DiffuseTransmissionMaterial m;
    ColorInput reflectance = read_color(params, "reflectance", Role::Reflectance).value_or(ColorInput(RGB(0.25f)));
    ColorInput transmittance = read_color(params, "transmittance", Role::Reflectance).value_or(ColorInput(RGB(0.25f)));
    float scale = params.get_float("scale", 1);
    if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
    // pbrt-v4 clamps scale * value to [0, 1].
    auto clamp01 = [](ColorInput c) {
      if (c.is_constant())
        for (int i = 0; i < 3; ++i) c.value[i] = std::clamp(c.value[i], 0.0f, 1.0f);
      return c;
    };
    m.reflectance = clamp01(scaled(reflectance, scale, scene_.textures));
    m.transmittance = clamp01(scaled(transmittance, scale, scene_.textures));
    ignore_shading_params(params);
    return m;
  }
  if (type == "interface" || type == "none" || type.empty()) return InterfaceMaterial{};
  if (type == "mix") {
    std::vector<std::string> names = params.get_strings("materials");
    if (names.size() != 2)
      params.fail("materials", "must name exactly two materials (made with MakeNamedMaterial), got {}", names.size());
    FloatInput amount = read_float_texture(params, "amount").value_or(FloatInput(0.5f));
    int chosen[2];
    for (int i = 0; i < 2; ++i) {
      if (names[i].empty() || names[i] == "none" || names[i] == "interface") {
        chosen[i] = -2;  // pbrt's "no material": an interface
        continue;
      }
      auto named = named_materials_.find(names[i]);
      if (named == named_materials_.end())
        params.fail("materials", "names \"{}\", which no MakeNamedMaterial before it defines", names[i]);
      chosen[i] = named->second.first;
    }
    // pbrt-v4 takes the first material where amount <= 0 and the second where amount >= 1.
    int pick = -1;
    if (chosen[0] == chosen[1])
      pick = 0;
    else if (amount.is_constant() && amount.value <= 0)
      pick = 0;
    else if (amount.is_constant() && amount.value >= 1)
      pick = 1;
    if (pick < 0)
      throw_scene_error(type_where,
                        "material type \"mix\" is not supported: candela cannot blend two materials (only a constant "
                        "\"amount\" of 0 or 1, which selects one of them, is read)");
    if (chosen[pick] == -2) return InterfaceMaterial{};
    return scene_.materials.at(chosen[pick]);
  }
  if (type == "thindielectric")
    throw_scene_error(type_where,
                      "material type \"thindielectric\" is not supported: candela has no thin-sheet BSDF, and a "
                      "\"dielectric\" in its place would bend the light that a thin sheet lets straight through");
  reject_type(type_where, "material", type,
              {"diffuse", "conductor", "dielectric", "coateddiffuse", "diffusetransmission", "interface", "mix"},
              {"coatedconductor", "hair", "measured", "subsurface"}, "candela has no BSDF for it");
}

void PbrtParser::material(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the material type");
  ParamList params = read_params(d, fmt::format("Material \"{}\"", type.text), kMaterialAttributes);
  MaterialDesc desc = make_material(type.text, at(type), params);
  params.reject_unused();
  state_.material = add_material(std::move(desc));
}

void PbrtParser::make_named_material(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the material name");
  if (auto earlier = named_materials_.find(name.text); earlier != named_materials_.end())
    throw_scene_error(at(name), "MakeNamedMaterial: \"{}\" is already defined at {}", name.text,
                      earlier->second.second.to_string());
  ParamList params = read_params(d, fmt::format("MakeNamedMaterial \"{}\"", name.text), kMaterialAttributes);
  if (!params.has("type"))
    throw_scene_error(at(d), "MakeNamedMaterial \"{}\": missing the \"string type\" parameter", name.text);
  std::string type = params.get_string("type", "");
  MaterialDesc desc = make_material(type, params.where("type"), params);
  params.reject_unused();
  named_materials_[name.text] = {add_material(std::move(desc)), at(name)};
}

void PbrtParser::named_material(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the material name");
  auto named = named_materials_.find(name.text);
  if (named == named_materials_.end())
    throw_scene_error(at(name),
                      "NamedMaterial: no material named \"{}\" is defined (MakeNamedMaterial must come first)",
                      name.text);
  state_.material = named->second.first;
}

// ---------------------------------------------------------------- lights

// "scale" multiplies the emission; pbrt-v4 first normalises a spectrum to one nit, which for an RGB
// emission leaves the RGB as it is (see read_emission).
RGB PbrtParser::read_light_scale(ParamList& params, RGB emitted) {
  float scale = params.get_float("scale", 1);
  if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
  return emitted * scale;
}

void PbrtParser::light_source(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the light type");
  ParamList params = read_params(d, fmt::format("LightSource \"{}\"", type.text), kLightAttributes);
  if (open_object_)
    throw_scene_error(at(d), "LightSource inside ObjectBegin \"{}\" (begun at {}): lights cannot be part of an "
                      "object definition", open_object_->name, open_object_->where.to_string());
  const Transform& ctm = state_.ctm.start;
  if (type.text == "point") {
    RGB intensity = read_light_scale(params, read_emission(params, "I").value_or(RGB(1.0f)));
    float power = params.get_float("power", -1);
    if (power > 0) intensity *= power / (4 * kPi);  // pbrt-v4: the power of an isotropic source
    Point3 from = params.get_point3("from", Point3(0.0f));
    params.reject_unused();
    if (state_.ctm.is_animated())
      throw_scene_error(at(d), "LightSource \"point\": lights must not move (the CTM is animated)");
    scene_.lights.push_back(PointLight{ctm.point(from), intensity});
  } else if (type.text == "spot") {
    RGB intensity = read_light_scale(params, read_emission(params, "I").value_or(RGB(1.0f)));
    float cone_angle = params.get_float("coneangle", 30);
    float cone_delta = params.get_float("conedeltaangle", 5);
    if (!(cone_angle > 0 && cone_angle <= 180))
      params.fail("coneangle", "must be in (0, 180] degrees, got {}", cone_angle);
    if (!(cone_delta >= 0 && cone_delta <= cone_angle))
      params.fail("conedeltaangle", "must be in [0, \"coneangle\" = {}] degrees, got {}", cone_angle, cone_delta);
    float power = params.get_float("power", -1);
    if (power > 0) {
      float cos_end = std::cos(cone_angle * kPi / 180), cos_start = std::cos((cone_angle - cone_delta) * kPi / 180);
      intensity *= power / (2 * kPi * ((1 - cos_start) + (cos_start - cos_end) / 2));
    }
    Point3 from = params.get_point3("from", Point3(0.0f));
    Point3 to = params.get_point3("to", Point3(0, 0, 1));
    if (from == to) params.fail("to", "must differ from \"from\" (the spot light points from \"from\" to \"to\")");
    params.reject_unused();
    if (state_.ctm.is_animated())
      throw_scene_error(at(d), "LightSource \"spot\": lights must not move (the CTM is animated)");
    scene_.lights.push_back(
        SpotLight{ctm.point(from), normalize(ctm.vector(to - from)), intensity, cone_angle, cone_delta});
  } else if (type.text == "distant") {
    RGB radiance = read_light_scale(params, read_emission(params, "L").value_or(RGB(1.0f)));
    float illuminance = params.get_float("illuminance", -1);
    if (illuminance > 0) radiance *= illuminance;  // pbrt-v4: the illuminance of a surface facing the light
    Point3 from = params.get_point3("from", Point3(0.0f));
    Point3 to = params.get_point3("to", Point3(0, 0, 1));
    if (from == to) params.fail("to", "must differ from \"from\" (the light travels from \"from\" to \"to\")");
    params.reject_unused();
    if (state_.ctm.is_animated())
      throw_scene_error(at(d), "LightSource \"distant\": lights must not move (the CTM is animated)");
    scene_.lights.push_back(DistantLight{normalize(ctm.vector(to - from)), radiance});
  } else if (type.text == "infinite") {
    if (params.has("L") && params.has("filename"))
      params.fail("filename", "cannot be given together with \"L\" (as in pbrt-v4)");
    if (params.has_own("portal")) {
      params.get_vec3_array("portal", "point3");
      warn(params.where("portal"),
           "{}: \"portal\" is ignored: the light is sampled over the whole sphere (the same image where the "
           "portal is the only opening, with more noise)",
           params.owner());
    } else {
      params.take_any("portal");
    }
    float scale = params.get_float("scale", 1);
    if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
    float illuminance = params.get_float("illuminance", -1);
    if (params.has("filename")) {
      if (illuminance > 0)
        params.fail("illuminance", "is not supported with an image (\"filename\"): it needs the image's "
                    "illuminance; give \"scale\" instead");
      std::string name = params.get_string("filename", "");
      fs::path file = resolve_path(name, params.where("filename"), fmt::format("{}: \"filename\"", params.owner()));
      params.reject_unused();
      if (state_.ctm.is_animated())
        throw_scene_error(at(d), "LightSource \"infinite\": lights must not move (the CTM is animated)");
      EnvironmentMap map;
      map.filename = file.string();
      map.mapping = EnvironmentMapping::EqualAreaOctahedral;
      map.scale = RGB(scale);
      map.to_world = ctm;
      scene_.lights.push_back(map);
    } else {
      RGB radiance = read_emission(params, "L").value_or(RGB(1.0f)) * scale;
      // pbrt-v4: the illuminance a uniform sky of radiance L gives an upward-facing surface is pi L.
      if (illuminance > 0) radiance *= illuminance / kPi;
      params.reject_unused();
      SkyLight sky;
      sky.zenith = sky.horizon = sky.ground = radiance;
      scene_.lights.push_back(sky);
    }
  } else {
    reject_type(at(type), "light", type.text, {"point", "spot", "distant", "infinite"}, {"goniometric", "projection"},
                "candela has no emitter shaped by an image");
  }
}

void PbrtParser::area_light_source(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the area light type");
  if (type.text != "diffuse") reject_type(at(type), "area light", type.text, {"diffuse"}, {});
  ParamList params = read_params(d, "AreaLightSource \"diffuse\"", kLightAttributes);
  if (params.has("filename")) params.fail("filename", "names an image: textured area lights are not supported");
  AreaLightSpec light;
  light.radiance = read_light_scale(params, read_emission(params, "L").value_or(RGB(1.0f)));
  light.two_sided = params.get_bool("twosided", false);
  float power = params.get_float("power", -1);
  if (power > 0) light.power = power;
  light.where = at(d);
  params.reject_unused();
  state_.area_light = light;
}

// ---------------------------------------------------------------- shapes

// pbrt clamps zmin/zmax to the radius and phimax to 360; anything less than the whole sphere is
// a partial sphere, which candela cannot represent.
BuiltGeometry PbrtParser::make_sphere(ParamList& params) {
  float radius = params.get_float("radius", 1);
  if (!(radius > 0)) params.fail("radius", "must be positive, got {}", radius);
  float z_min = params.get_float("zmin", -radius);
  float z_max = params.get_float("zmax", radius);
  float phi_max = params.get_float("phimax", 360);
  if (std::min(z_min, z_max) > -radius) params.fail("zmin", "cuts the sphere: partial spheres are not supported yet");
  if (std::max(z_min, z_max) < radius) params.fail("zmax", "cuts the sphere: partial spheres are not supported yet");
  if (phi_max < 360) params.fail("phimax", "cuts the sphere: partial spheres are not supported yet");
  BuiltGeometry built;
  built.geometry = SphereShape{Point3(0.0f), radius};
  built.object_area = 4 * kPi * radius * radius;
  return built;
}

BuiltGeometry PbrtParser::make_triangle_mesh(ParamList& params) {
  TriangleMesh mesh;
  mesh.positions = params.get_vec3_array("P", "point3");
  std::vector<int> indices = params.get_int_array("indices");
  mesh.normals = params.get_vec3_array("N", "normal");
  mesh.uvs = params.get_point2_array("uv");
  size_t n = mesh.positions.size();
  if (n == 0) params.fail("P", "is required: give the vertex positions as \"point3 P\"");
  if (indices.empty()) {
    if (n != 3) params.fail("indices", "is required unless \"P\" has exactly 3 points (it has {})", n);
    indices = {0, 1, 2};
  }
  if (indices.size() % 3 != 0)
    params.fail("indices", "has {} values, which is not a multiple of 3 (three per triangle)", indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || static_cast<size_t>(indices[i]) >= n)
      params.fail("indices", "value {} (number {}) is out of range: \"P\" has {} points", indices[i], i + 1, n);
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    params.fail("N", "has {} normals but \"P\" has {} points; give one normal per point", mesh.normals.size(), n);
  if (!mesh.uvs.empty() && mesh.uvs.size() != n)
    params.fail("uv", "has {} coordinates but \"P\" has {} points; give one per point", mesh.uvs.size(), n);
  ignore_param(params, "S", "candela derives the shading tangents itself");
  params.take_any("faceIndices");  // only for ptex textures
  mesh.indices.assign(indices.begin(), indices.end());
  return BuiltGeometry{MeshShape{std::move(mesh)}, {}, 0};
}

BuiltGeometry PbrtParser::make_ply_mesh(ParamList& params) {
  if (!params.has("filename")) params.fail("filename", "is required: name the .ply file");
  std::string name = params.get_string("filename", "");
  SourceLocation where = params.where("filename");
  fs::path file = resolve_path(name, where, fmt::format("{}: \"filename\"", params.owner()));
  ignore_param(params, "displacement", "displacement mapping is not supported");
  params.take_any("edgelength");  // the displacement's tessellation
  return BuiltGeometry{MeshShape{load_mesh_file(file, where)}, {}, 0};
}

// pbrt-v4's disk: radius, innerradius and phimax at z = height, facing +z; u = phi / phimax and
// v = (radius - r) / (radius - innerradius). Triangulated with kDiskSegmentsPerTurn segments per
// full turn, the rings pushed out by sqrt(dphi / sin dphi) so the polygon has exactly the disk's
// area (the outline then deviates from the circle by at most 0.02% of the radius).
BuiltGeometry PbrtParser::make_disk(ParamList& params) {
  float height = params.get_float("height", 0);
  float radius = params.get_float("radius", 1);
  float inner = params.get_float("innerradius", 0);
  float phi_max_degrees = params.get_float("phimax", 360);
  if (!(radius > 0)) params.fail("radius", "must be positive, got {}", radius);
  if (!(inner >= 0 && inner < radius))
    params.fail("innerradius", "must be in [0, \"radius\" = {}), got {}", radius, inner);
  if (!(phi_max_degrees > 0)) params.fail("phimax", "must be positive, got {}", phi_max_degrees);
  double phi_max = std::min(phi_max_degrees, 360.0f) * std::numbers::pi / 180;
  int segments = std::max(3, static_cast<int>(std::ceil(kDiskSegmentsPerTurn * phi_max / (2 * std::numbers::pi))));
  double dphi = phi_max / segments;
  double stretch = std::sqrt(dphi / std::sin(dphi));

  TriangleMesh mesh;
  auto add_vertex = [&](double r, double phi, float u, float v) {
    mesh.positions.emplace_back(static_cast<float>(stretch * r * std::cos(phi)),
                                static_cast<float>(stretch * r * std::sin(phi)), height);
    mesh.normals.emplace_back(0, 0, 1);
    mesh.uvs.emplace_back(u, v);
    return static_cast<uint32_t>(mesh.positions.size() - 1);
  };
  std::vector<uint32_t> outer_ring, inner_ring;
  for (int i = 0; i <= segments; ++i)
    outer_ring.push_back(add_vertex(radius, i * dphi, static_cast<float>(i) / segments, 0));
  if (inner > 0) {
    for (int i = 0; i <= segments; ++i)
      inner_ring.push_back(add_vertex(inner, i * dphi, static_cast<float>(i) / segments, 1));
    for (int i = 0; i < segments; ++i)
      mesh.indices.insert(mesh.indices.end(), {outer_ring[i], outer_ring[i + 1], inner_ring[i + 1], outer_ring[i],
                                               inner_ring[i + 1], inner_ring[i]});
  } else {
    for (int i = 0; i < segments; ++i) {
      uint32_t centre = add_vertex(0, 0, (i + 0.5f) / segments, 1);
      mesh.indices.insert(mesh.indices.end(), {centre, outer_ring[i], outer_ring[i + 1]});
    }
  }
  BuiltGeometry built{MeshShape{std::move(mesh)}, {}, 0};
  built.object_area = static_cast<float>(0.5 * phi_max * (double(radius) * radius - double(inner) * inner));
  return built;
}

// pbrt-v4's bilinear patches: four vertices (p00, p10, p01, p11) each, p(u, v) the bilinear
// interpolation. A planar patch becomes two triangles; any other is tessellated into
// kBilinearPatchTessellation^2 quads with bilinear positions, uvs and normals.
BuiltGeometry PbrtParser::make_bilinear_mesh(ParamList& params) {
  std::vector<Vec3> p = params.get_vec3_array("P", "point3");
  std::vector<int> indices = params.get_int_array("indices");
  std::vector<Vec3> normals = params.get_vec3_array("N", "normal");
  std::vector<Vec2> uvs = params.get_point2_array("uv");
  size_t n = p.size();
  if (n == 0) params.fail("P", "is required: give the vertex positions as \"point3 P\"");
  if (indices.empty()) {
    if (n != 4) params.fail("indices", "is required unless \"P\" has exactly 4 points (it has {})", n);
    indices = {0, 1, 2, 3};
  }
  if (indices.size() % 4 != 0)
    params.fail("indices", "has {} values, which is not a multiple of 4 (four per patch)", indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || static_cast<size_t>(indices[i]) >= n)
      params.fail("indices", "value {} (number {}) is out of range: \"P\" has {} points", indices[i], i + 1, n);
  if (!normals.empty() && normals.size() != n)
    params.fail("N", "has {} normals but \"P\" has {} points; give one normal per point", normals.size(), n);
  if (!uvs.empty() && uvs.size() != n)
    params.fail("uv", "has {} coordinates but \"P\" has {} points; give one per point", uvs.size(), n);
  ignore_param(params, "emissionfilename", "textured area lights are not supported");

  size_t patches = indices.size() / 4;
  auto corner = [&](size_t patch, int c) { return static_cast<size_t>(indices[4 * patch + c]); };
  auto is_planar = [&](size_t patch) {
    Vec3 p00 = p[corner(patch, 0)], p10 = p[corner(patch, 1)], p01 = p[corner(patch, 2)], p11 = p[corner(patch, 3)];
    Vec3 normal = cross(p10 - p00, p01 - p00);
    float size = length(p10 - p00) + length(p01 - p00) + length(p11 - p00);
    if (!(length(normal) > 0)) return false;
    return std::abs(dot(p11 - p00, normalize(normal))) <= 1e-5f * size;
  };
  std::vector<bool> planar(patches);
  bool all_planar = true;
  for (size_t i = 0; i < patches; ++i) {
    planar[i] = is_planar(i);
    all_planar = all_planar && planar[i];
  }

  BuiltGeometry built;
  TriangleMesh mesh;
  const Vec2 default_uv[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  for (size_t patch = 0; patch < patches; ++patch) {
    Vec3 q[4], nq[4];
    Vec2 t[4];
    for (int c = 0; c < 4; ++c) {
      q[c] = p[corner(patch, c)];
      t[c] = uvs.empty() ? default_uv[c] : uvs[corner(patch, c)];
      if (!normals.empty()) nq[c] = normals[corner(patch, c)];
    }
    auto lerp3 = [](float s, Vec3 a, Vec3 b) { return a * (1 - s) + b * s; };
    auto add_vertex = [&](float u, float v) {
      mesh.positions.push_back(lerp3(v, lerp3(u, q[0], q[1]), lerp3(u, q[2], q[3])));
      mesh.uvs.emplace_back((1 - v) * ((1 - u) * t[0].x + u * t[1].x) + v * ((1 - u) * t[2].x + u * t[3].x),
                            (1 - v) * ((1 - u) * t[0].y + u * t[1].y) + v * ((1 - u) * t[2].y + u * t[3].y));
      if (!normals.empty()) {
        mesh.normals.push_back(normalize(lerp3(v, lerp3(u, nq[0], nq[1]), lerp3(u, nq[2], nq[3]))));
      } else if (!all_planar) {
        Vec3 dpdu = lerp3(v, q[1] - q[0], q[3] - q[2]), dpdv = lerp3(u, q[2] - q[0], q[3] - q[1]);
        Vec3 normal = cross(dpdu, dpdv);
        mesh.normals.push_back(length(normal) > 0 ? normalize(normal) : Vec3(0, 0, 1));
      }
      return static_cast<uint32_t>(mesh.positions.size() - 1);
    };
    int steps = planar[patch] ? 1 : kBilinearPatchTessellation;
    uint32_t first = static_cast<uint32_t>(mesh.positions.size());
    for (int j = 0; j <= steps; ++j)
      for (int i = 0; i <= steps; ++i) add_vertex(static_cast<float>(i) / steps, static_cast<float>(j) / steps);
    auto vertex = [&](int i, int j) { return first + static_cast<uint32_t>(j * (steps + 1) + i); };
    for (int j = 0; j < steps; ++j)
      for (int i = 0; i < steps; ++i) {
        // (u, v) -> (u+1, v) -> (u+1, v+1) faces along dp/du x dp/dv, pbrt's patch normal.
        mesh.indices.insert(mesh.indices.end(), {vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j),
                                                 vertex(i + 1, j + 1), vertex(i, j + 1)});
        built.primitive_of_triangle.insert(built.primitive_of_triangle.end(), 2, static_cast<uint32_t>(patch));
      }
  }
  built.geometry = MeshShape{std::move(mesh)};
  return built;
}

// The triangles `triangles` of `mesh` as a mesh of their own.
TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<uint32_t>& triangles) {
  TriangleMesh out;
  std::vector<int64_t> remap(mesh.positions.size(), -1);
  for (uint32_t t : triangles)
    for (int c = 0; c < 3; ++c) {
      uint32_t v = mesh.indices[3 * t + c];
      if (remap[v] < 0) {
        remap[v] = static_cast<int64_t>(out.positions.size());
        out.positions.push_back(mesh.positions[v]);
        if (!mesh.normals.empty()) out.normals.push_back(mesh.normals[v]);
        if (!mesh.uvs.empty()) out.uvs.push_back(mesh.uvs[v]);
      }
      out.indices.push_back(static_cast<uint32_t>(remap[v]));
    }
  return out;
}

// An area light with "power": pbrt-v4 gives every primitive (a triangle, a bilinear patch, a sphere,
// a disk) the radiance L * scale * power / (pi * (twosided ? 2 : 1) * its area), so each primitive
// emits "power" (the RGB L is not normalised). Triangles whose primitives have the same area share
// a shape; others become shapes of their own.
void PbrtParser::add_emissive_shape(ShapeDesc shape, const BuiltGeometry& built, const Token& directive) {
  const AreaLightSpec& light = *state_.area_light;
  if (!light.power) {
    shape.emission = AreaEmission{light.radiance, light.two_sided};
    add_shape(std::move(shape), directive);
    return;
  }
  double sides = light.two_sided ? 2 : 1;
  auto radiance_for = [&](double area) {
    if (!(area > 0))
      throw_scene_error(at(directive), "Shape: the area light's \"power\" (at {}) cannot be spread over a "
                        "primitive of zero area", light.where.to_string());
    return light.radiance * static_cast<float>(*light.power / (std::numbers::pi * sides * area));
  };
  const auto* mesh_shape = std::get_if<MeshShape>(&shape.geometry);
  if (built.object_area > 0 || !mesh_shape) {
    shape.emission = AreaEmission{radiance_for(built.object_area), light.two_sided};
    add_shape(std::move(shape), directive);
    return;
  }
  const TriangleMesh& mesh = mesh_shape->mesh;
  size_t triangles = mesh.triangle_count();
  std::vector<double> triangle_area(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    Point3 a = shape.to_world.point(mesh.positions[mesh.indices[3 * t]]);
    Point3 b = shape.to_world.point(mesh.positions[mesh.indices[3 * t + 1]]);
    Point3 c = shape.to_world.point(mesh.positions[mesh.indices[3 * t + 2]]);
    triangle_area[t] = 0.5 * length(cross(b - a, c - a));
  }
  std::vector<double> area = triangle_area;  // of the primitive each triangle belongs to
  if (!built.primitive_of_triangle.empty()) {
    std::map<uint32_t, double> primitive_area;
    for (size_t t = 0; t < triangles; ++t) primitive_area[built.primitive_of_triangle[t]] += triangle_area[t];
    for (size_t t = 0; t < triangles; ++t) area[t] = primitive_area[built.primitive_of_triangle[t]];
  }
  std::vector<uint32_t> order(triangles);
  for (uint32_t t = 0; t < triangles; ++t) order[t] = t;
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return area[a] < area[b]; });
  std::vector<std::vector<uint32_t>> groups;
  for (uint32_t t : order) {
    if (groups.empty() || area[t] > area[groups.back().front()] * (1 + 1e-4)) groups.emplace_back();
    groups.back().push_back(t);
  }
  for (std::vector<uint32_t>& group : groups) {
    ShapeDesc part = shape;
    part.emission = AreaEmission{radiance_for(area[group.front()]), light.two_sided};
    if (groups.size() > 1) {
      std::sort(group.begin(), group.end());
      part.geometry = MeshShape{submesh(mesh, group)};
      part.name =
          fmt::format("{} (the {} triangles of primitive area {})", shape.name, group.size(), area[group.front()]);
    }
    add_shape(std::move(part), directive);
  }
}

void PbrtParser::add_shape(ShapeDesc shape, const Token& directive) {
  if (!open_object_) {
    scene_.shapes.push_back(std::move(shape));
    return;
  }
  if (shape.emission)
    throw_scene_error(at(directive),
                      "Shape inside ObjectBegin \"{}\": area lights in object instances are not supported (nor "
                      "are they in pbrt-v4)",
                      open_object_->name);
  open_object_->shapes.push_back(std::move(shape));
}

void PbrtParser::shape(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the shape type");
  ParamList params = read_params(d, fmt::format("Shape \"{}\"", type.text), kShapeAttributes);
  BuiltGeometry built;
  if (type.text == "sphere")
    built = make_sphere(params);
  else if (type.text == "trianglemesh")
    built = make_triangle_mesh(params);
  else if (type.text == "plymesh")
    built = make_ply_mesh(params);
  else if (type.text == "disk")
    built = make_disk(params);
  else if (type.text == "bilinearmesh")
    built = make_bilinear_mesh(params);
  else
    reject_type(at(type), "shape", type.text, {"sphere", "trianglemesh", "plymesh", "disk", "bilinearmesh"},
                {"curve", "cylinder", "loopsubdiv"}, "candela has no primitive or tessellation for it");
  if (Param* alpha = params.take("alpha", {"float", "texture"})) {
    params.expect_count(*alpha, 1);
    if (alpha->type == "texture")
      params.fail("alpha", "textures are not supported: an alpha texture cuts the surface out where it is "
                  "below 1, and candela's surfaces are opaque");
    if (alpha->numbers[0] < 1)
      params.fail("alpha", "below 1 is not supported: it makes the surface transparent, and candela's surfaces "
                  "are opaque");
  }
  params.reject_unused();
  ShapeDesc desc;
  desc.geometry = built.geometry;
  desc.to_world = state_.ctm.start;
  if (state_.ctm.is_animated()) {
    // Area lights are sampled at fixed positions.
    if (state_.area_light)
      throw_scene_error(at(d), "Shape: area lights must not move (the CTM is animated inside an AreaLightSource)");
    if (open_object_)
      throw_scene_error(at(d), "Shape inside ObjectBegin \"{}\": shapes of an object cannot move (the CTM is "
                        "animated); animate the ObjectInstance instead", open_object_->name);
    desc.to_world_end = state_.ctm.end;
  }
  desc.material = state_.material;
  desc.reverse_orientation = state_.reverse_orientation;
  desc.name = fmt::format("{} at {}", type.text, at(d).to_string());
  if (state_.area_light)
    add_emissive_shape(std::move(desc), built, d);
  else
    add_shape(std::move(desc), d);
}

// ---------------------------------------------------------------- object instancing

void PbrtParser::object_begin(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the object name");
  if (open_object_)
    throw_scene_error(at(d), "ObjectBegin inside the definition of \"{}\" (begun at {}); objects cannot nest",
                      open_object_->name, open_object_->where.to_string());
  if (auto earlier = objects_.find(name.text); earlier != objects_.end())
    throw_scene_error(at(name), "ObjectBegin: object \"{}\" is already defined at {}", name.text,
                      earlier->second.where.to_string());
  push_block(d, BlockKind::Object);
  open_object_ = ObjectDefinition{name.text, at(d), {}, -1};
}

void PbrtParser::object_end(const Token& d) {
  require_world(d);
  if (!open_object_) throw_scene_error(at(d), "ObjectEnd without a matching ObjectBegin");
  pop_block(d, BlockKind::Object);
  std::string name = open_object_->name;
  objects_.emplace(std::move(name), std::move(*open_object_));
  open_object_.reset();
}

// As in pbrt-v4, the shapes of an object keep the CTM they had at their definition (their
// to_world), and an instance places them with the CTM at ObjectInstance: world = instance.to_world *
// shape.to_world. The object goes into SceneDesc::objects when it is first instanced.
void PbrtParser::object_instance(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the object name");
  if (open_object_)
    throw_scene_error(at(d), "ObjectInstance inside the definition of \"{}\"; instances cannot nest",
                      open_object_->name);
  auto object = objects_.find(name.text);
  if (object == objects_.end())
    throw_scene_error(at(name), "ObjectInstance: no object named \"{}\" is defined (ObjectBegin must come first)",
                      name.text);
  ObjectDefinition& definition = object->second;
  if (definition.shapes.empty()) return;  // nothing to place
  if (definition.index < 0) {
    scene_.objects.push_back(ObjectDesc{definition.shapes, definition.name});
    definition.index = static_cast<int>(scene_.objects.size()) - 1;
  }
  InstanceDesc instance;
  instance.object = definition.index;
  instance.to_world = state_.ctm.start;
  if (state_.ctm.is_animated()) instance.to_world_end = state_.ctm.end;
  scene_.instances.push_back(instance);
}

// ---------------------------------------------------------------- participating media

void PbrtParser::make_named_medium(const Token& d) {
  Token name = expect_string(d, "the medium name");
  ParamList params = read_params(d, fmt::format("MakeNamedMedium \"{}\"", name.text), kMediumAttributes);
  warn(at(d), "MakeNamedMedium \"{}\": participating media are not supported; the medium is ignored", name.text);
}

void PbrtParser::medium_interface(const Token& d) {
  Token inside = expect_string(d, "the inside medium's name");
  std::string outside = inside.text;  // one name means the same medium on both sides
  if (tokens_->peek().kind == TokenKind::String) outside = tokens_->next().text;
  if (!inside.text.empty() || !outside.empty())
    warn(at(d), "MediumInterface \"{}\" \"{}\": participating media are not supported; everything is in vacuum",
         inside.text, outside);
}

// ---------------------------------------------------------------- other files

void PbrtParser::include(const Token& d) {
  Token name = expect_string(d, "a file name");
  SourceLocation where = at(name);
  parse_file(resolve_path(name.text, where, "Include"), &where);
}

// Like Include, but (as in pbrt-v4) only in the world section, and changes to the graphics state
// inside the imported file do not leak out of it.
void PbrtParser::import(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "a file name");
  SourceLocation where = at(name);
  fs::path file = resolve_path(name.text, where, "Import");
  GraphicsState saved = state_;
  size_t outer_floor = std::exchange(block_floor_, blocks_.size());
  parse_file(file, &where);
  if (blocks_.size() > block_floor_) {
    const OpenBlock& block = blocks_.back();
    throw_scene_error(block.where, "{} is never closed before the end of the imported file", block.opener);
  }
  block_floor_ = outer_floor;
  state_ = saved;
}

void PbrtParser::world_end(const Token& d) {
  throw_scene_error(at(d),
                    "WorldEnd is pbrt-v3 syntax; pbrt-v4 files simply end (\"pbrt --upgrade\" converts old files)");
}

}  // namespace

SceneDesc read_pbrt_scene(const std::filesystem::path& file, std::vector<std::string>& warnings) {
  return PbrtParser(warnings).parse(file);
}

SceneDesc read_pbrt_scene(const std::filesystem::path& file) {
  std::vector<std::string> warnings;
  try {
    SceneDesc scene = read_pbrt_scene(file, warnings);
    print_pbrt_warnings(warnings);
    return scene;
  } catch (const SceneError&) {
    print_pbrt_warnings(warnings);
    throw;
  }
}

void print_pbrt_warnings(const std::vector<std::string>& warnings, int per_kind) {
  std::map<std::string, int> seen;
  for (const std::string& warning : warnings) {
    size_t text = warning.find(": warning: ");
    std::string kind = text == std::string::npos ? warning : warning.substr(text);
    if (++seen[kind] <= per_kind) std::fprintf(stderr, "%s\n", warning.c_str());
  }
  for (const auto& [kind, count] : seen)
    if (count > per_kind)
      std::fprintf(stderr, "(%d more warnings like \"%s\")\n", count - per_kind, kind.substr(11).c_str());
}

}  // namespace candela
