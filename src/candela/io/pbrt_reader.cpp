// Reader for pbrt-v4 scene files (the subset in docs/pbrt-format.md).
//
// Three layers: a tokenizer that knows line:column, a parameter-list reader that checks types and
// counts, and a parser that keeps pbrt's graphics state (CTM, material, area light, orientation)
// and fills a SceneDesc. Every problem is one SceneError naming file:line:column; like pbrt itself,
// a parameter that nothing reads is an error rather than being silently ignored.
#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "candela/io/error.h"
#include "candela/io/mesh_io.h"
#include "candela/io/scene_reader.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

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

enum class ValueKind { Number, Integer, Bool, String };

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
  return std::nullopt;
}

// One "type name" [ values ] entry of a directive's parameter list.
struct Param {
  std::string type;  // canonical spelling
  std::string name;
  SourceLocation where;  // the "type name" string
  ValueKind kind = ValueKind::Number;
  std::vector<double> numbers;  // Number and Integer values
  std::vector<std::string> strings;
  std::vector<bool> bools;
  bool used = false;

  size_t count() const { return numbers.size() + strings.size() + bools.size(); }
  std::string declaration() const { return fmt::format("\"{} {}\"", type, name); }
};

// Lookups check a parameter's type and number of values and mark it used; reject_unused() then
// reports the first parameter nothing asked for, listing the ones this directive does read.
class ParamList {
 public:
  ParamList(std::string owner, SourceLocation directive, std::vector<Param> params)
      : owner_(std::move(owner)), directive_(std::move(directive)), params_(std::move(params)) {}

  const std::string& owner() const { return owner_; }

  bool has(std::string_view name) const {
    return std::any_of(params_.begin(), params_.end(), [&](const Param& p) { return p.name == name; });
  }

  // The parameter's place in the file, or the directive's when it was not given.
  SourceLocation where(std::string_view name) const {
    for (const Param& p : params_)
      if (p.name == name) return p.where;
    return directive_;
  }

  template <typename... Args>
  [[noreturn]] void fail(std::string_view name, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(where(name), "{}: \"{}\" {}", owner_, name, fmt::format(format, std::forward<Args>(args)...));
  }

  float get_float(std::string_view name, float fallback) {
    const Param* p = find_single(name, "float", 1);
    return p ? static_cast<float>(p->numbers[0]) : fallback;
  }

  int get_int(std::string_view name, int fallback) {
    const Param* p = find_single(name, "integer", 1);
    return p ? static_cast<int>(p->numbers[0]) : fallback;
  }

  bool get_bool(std::string_view name, bool fallback) {
    const Param* p = find_single(name, "bool", 1);
    return p ? p->bools[0] : fallback;
  }

  std::string get_string(std::string_view name, std::string fallback) {
    const Param* p = find_single(name, "string", 1);
    return p ? p->strings[0] : std::move(fallback);
  }

  Point3 get_point3(std::string_view name, Point3 fallback) {
    const Param* p = find_single(name, "point3", 3);
    return p ? to_vec3(p->numbers, 0) : fallback;
  }

  // Colours are never negative; reflectances (albedos) are at most 1, as pbrt-v4 requires.
  RGB get_rgb(std::string_view name, RGB fallback, bool is_reflectance) {
    const Param* p = find_single(name, "rgb", 3);
    if (!p) return fallback;
    RGB rgb(static_cast<float>(p->numbers[0]), static_cast<float>(p->numbers[1]),
            static_cast<float>(p->numbers[2]));
    if (rgb.min_component() < 0) fail(name, "has a negative component ({} {} {})", rgb.r, rgb.g, rgb.b);
    if (is_reflectance && rgb.max_component() > 1)
      fail(name, "is a reflectance and must not exceed 1 ({} {} {})", rgb.r, rgb.g, rgb.b);
    return rgb;
  }

  std::vector<Vec3> get_vec3_array(std::string_view name, std::string_view type) {
    const Param* p = find_array(name, type, 3);
    std::vector<Vec3> values;
    if (!p) return values;
    values.reserve(p->numbers.size() / 3);
    for (size_t i = 0; i < p->numbers.size(); i += 3) values.push_back(to_vec3(p->numbers, i));
    return values;
  }

  std::vector<Vec2> get_point2_array(std::string_view name) {
    const Param* p = find_array(name, "point2", 2);
    std::vector<Vec2> values;
    if (!p) return values;
    values.reserve(p->numbers.size() / 2);
    for (size_t i = 0; i < p->numbers.size(); i += 2)
      values.emplace_back(static_cast<float>(p->numbers[i]), static_cast<float>(p->numbers[i + 1]));
    return values;
  }

  std::vector<int> get_int_array(std::string_view name) {
    const Param* p = find_array(name, "integer", 1);
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

  Param* find(std::string_view name, std::string_view type) {
    if (std::find(queried_.begin(), queried_.end(), name) == queried_.end()) queried_.emplace_back(name);
    for (Param& p : params_) {
      if (p.name != name) continue;
      if (p.type == "texture")
        throw_scene_error(p.where, "{}: {}: textures are not supported yet; give a constant \"{} {}\"", owner_,
                          p.declaration(), type, name);
      if (p.type == "blackbody")
        throw_scene_error(p.where, "{}: {}: spectral values are not supported yet; give \"rgb {}\"", owner_,
                          p.declaration(), name);
      if (p.type != type)
        throw_scene_error(p.where, "{}: parameter \"{}\" must be of type \"{}\", not \"{}\"", owner_, name, type,
                          p.type);
      p.used = true;
      return &p;
    }
    return nullptr;
  }

  const Param* find_single(std::string_view name, std::string_view type, size_t count) {
    const Param* p = find(name, type);
    if (p && p->count() != count)
      throw_scene_error(p->where, "{}: {} takes exactly {} value{}, got {}", owner_, p->declaration(), count,
                        count == 1 ? "" : "s", p->count());
    return p;
  }

  const Param* find_array(std::string_view name, std::string_view type, size_t per_item) {
    const Param* p = find(name, type);
    if (p && p->count() % per_item != 0)
      throw_scene_error(p->where, "{}: {} needs a multiple of {} values, got {}", owner_, p->declaration(), per_item,
                        p->count());
    return p;
  }

  std::string owner_;
  SourceLocation directive_;
  std::vector<Param> params_;
  std::vector<std::string> queried_;
};

// "unknown shape type" for a misspelling, "not supported yet" for a pbrt-v4 type candela lacks;
// both list the types that are supported.
[[noreturn]] void reject_type(const SourceLocation& where, std::string_view what, std::string_view type,
                              std::initializer_list<std::string_view> supported,
                              std::initializer_list<std::string_view> known_unsupported) {
  std::string list;
  for (std::string_view name : supported) list += fmt::format("{}\"{}\"", list.empty() ? "" : ", ", name);
  if (std::find(known_unsupported.begin(), known_unsupported.end(), type) != known_unsupported.end())
    throw_scene_error(where, "{} type \"{}\" is not supported yet (supported: {})", what, type, list);
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

// pbrt's per-attribute-block state.
struct GraphicsState {
  TransformSet ctm;
  uint8_t active_transforms = kAllTransforms;
  int material = -1;  // -1: pbrt's default material, diffuse 0.5
  std::optional<AreaEmission> area_light;
  bool reverse_orientation = false;
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
};

enum class Section { Options, World };

class PbrtParser {
 public:
  SceneDesc parse(const fs::path& file);

 private:
  using Handler = void (PbrtParser::*)(const Token&);
  static const std::unordered_map<std::string_view, Handler>& handlers();

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
  ParamList read_params(const Token& directive, std::string owner);
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
  void reverse_orientation(const Token& d);
  void camera(const Token& d);
  void film(const Token& d);
  void sampler(const Token& d);
  void integrator(const Token& d);
  void pixel_filter(const Token& d);
  void read_light_sampler(ParamList& params);
  void option(const Token& d);
  void color_space(const Token& d);
  void world_begin(const Token& d);
  void material(const Token& d);
  void make_named_material(const Token& d);
  void named_material(const Token& d);
  void light_source(const Token& d);
  void area_light_source(const Token& d);
  void shape(const Token& d);
  void object_begin(const Token& d);
  void object_end(const Token& d);
  void object_instance(const Token& d);
  void include(const Token& d);
  void import(const Token& d);
  void unsupported(const Token& d);
  void world_end(const Token& d);

  // scene objects from parameter lists
  MaterialDesc make_material(const std::string& type, const SourceLocation& type_where, ParamList& params);
  ShapeGeometry make_sphere(ParamList& params);
  ShapeGeometry make_triangle_mesh(ParamList& params);
  ShapeGeometry make_ply_mesh(ParamList& params);
  RGB read_emission_scale(ParamList& params, std::string_view name, RGB emitted);
  void add_shape(ShapeDesc shape, const Token& directive);

  SceneDesc scene_;
  GraphicsState state_;
  Section section_ = Section::Options;
  SourceLocation world_begin_;
  std::vector<OpenBlock> blocks_;
  size_t block_floor_ = 0;  // blocks below this belong to the file that Imported the current one
  std::map<std::string, TransformSet> coordinate_systems_;
  std::map<std::string, std::pair<int, SourceLocation>> named_materials_;
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
      {"ReverseOrientation", &PbrtParser::reverse_orientation},
      {"Camera", &PbrtParser::camera},
      {"Film", &PbrtParser::film},
      {"Sampler", &PbrtParser::sampler},
      {"Integrator", &PbrtParser::integrator},
      {"PixelFilter", &PbrtParser::pixel_filter},
      {"Option", &PbrtParser::option},
      {"ColorSpace", &PbrtParser::color_space},
      {"WorldBegin", &PbrtParser::world_begin},
      {"Material", &PbrtParser::material},
      {"MakeNamedMaterial", &PbrtParser::make_named_material},
      {"NamedMaterial", &PbrtParser::named_material},
      {"LightSource", &PbrtParser::light_source},
      {"AreaLightSource", &PbrtParser::area_light_source},
      {"Shape", &PbrtParser::shape},
      {"ObjectBegin", &PbrtParser::object_begin},
      {"ObjectEnd", &PbrtParser::object_end},
      {"ObjectInstance", &PbrtParser::object_instance},
      {"Include", &PbrtParser::include},
      {"Import", &PbrtParser::import},
      {"Texture", &PbrtParser::unsupported},
      {"MakeNamedMedium", &PbrtParser::unsupported},
      {"MediumInterface", &PbrtParser::unsupported},
      {"Attribute", &PbrtParser::unsupported},
      {"ActiveTransform", &PbrtParser::active_transform},
      {"TransformTimes", &PbrtParser::transform_times},
      {"Accelerator", &PbrtParser::unsupported},
      {"WorldEnd", &PbrtParser::world_end},
  };
  return table;
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

ParamList PbrtParser::read_params(const Token& directive, std::string owner) {
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
  return ParamList(std::move(owner), at(directive), std::move(params));
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
  if (param.type == "spectrum")
    throw_scene_error(param.where,
                      "{}: {}: spectral values are not supported yet; give \"rgb {}\" for a colour or \"float {}\" "
                      "for a number",
                      owner, describe(declaration), name, name);
  std::optional<ValueKind> kind = value_kind_of(param.type);
  if (!kind)
    throw_scene_error(param.where,
                      "{}: unknown parameter type \"{}\" (expected integer, float, point2, vector2, point3, vector3, "
                      "normal, rgb, bool, string or texture)",
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
  params.reject_unused();
  scene_.film.width = width;
  scene_.film.height = height;
  scene_.film.filename = filename;
}

void PbrtParser::sampler(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the sampler type");
  if (type.text != "independent" && type.text != "stratified" && type.text != "zsobol")
    reject_type(at(type), "sampler", type.text, {"independent", "stratified", "zsobol"},
                {"halton", "paddedsobol", "pmj02bn", "sobol"});
  ParamList params = read_params(d, fmt::format("Sampler \"{}\"", type.text));
  SamplerDesc sampler;
  int64_t spp = 0;
  if (type.text == "independent") {
    sampler.type = SamplerType::Independent;
    spp = params.get_int("pixelsamples", 4);
  } else if (type.text == "stratified") {
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
    std::string randomization = params.get_string("randomization", "fastowen");
    if (randomization != "none" && randomization != "permutedigits" && randomization != "fastowen" &&
        randomization != "owen")
      params.fail("randomization", "must be \"none\", \"permutedigits\", \"fastowen\" or \"owen\", got \"{}\"",
                  randomization);
  }
  if (spp < 1) params.fail("pixelsamples", "must be positive, got {}", spp);
  int seed = params.get_int("seed", 0);
  if (seed < 0) params.fail("seed", "must not be negative, got {}", seed);
  params.reject_unused();
  scene_.settings.sampler = sampler;
  scene_.settings.spp = static_cast<int>(spp);
  if (params.has("seed")) scene_.settings.seed = static_cast<uint64_t>(seed);
}

void PbrtParser::integrator(const Token& d) {
  require_options(d);
  Token type = expect_string(d, "the integrator type");
  ParamList params = read_params(d, fmt::format("Integrator \"{}\"", type.text));
  int max_depth = params.get_int("maxdepth", 5);
  if (max_depth < 0) params.fail("maxdepth", "must not be negative, got {}", max_depth);
  if (type.text == "path") {
    if (params.get_bool("regularize", false)) params.fail("regularize", "is not supported yet");
    read_light_sampler(params);
  }
  params.reject_unused();
  // Other integrators are kept by name; the renderer decides which it can run.
  scene_.settings.integrator = type.text;
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

void PbrtParser::color_space(const Token& d) { expect_string(d, "the colour space name"); }

void PbrtParser::world_begin(const Token& d) {
  require_options(d);
  section_ = Section::World;
  world_begin_ = at(d);
  state_.ctm = {};
  state_.active_transforms = kAllTransforms;
  coordinate_systems_["world"] = {};
}

// ---------------------------------------------------------------- materials

MaterialDesc PbrtParser::make_material(const std::string& type, const SourceLocation& type_where,
                                       ParamList& params) {
  if (type == "diffuse") return DiffuseMaterial{params.get_rgb("reflectance", RGB(0.5f), true)};
  if (type == "dielectric") {
    float eta = params.get_float("eta", 1.5f);
    if (!(eta > 0)) params.fail("eta", "must be positive, got {}", eta);
    float roughness = params.get_float("roughness", 0);
    float u_roughness = params.get_float("uroughness", roughness);
    float v_roughness = params.get_float("vroughness", roughness);
    params.get_bool("remaproughness", true);  // no effect on a smooth surface
    if (u_roughness != 0 || v_roughness != 0) {
      std::string_view which = params.has("uroughness")   ? "uroughness"
                               : params.has("vroughness") ? "vroughness"
                                                          : "roughness";
      params.fail(which, "must be 0: only smooth dielectrics are supported yet");
    }
    return DielectricMaterial{eta};
  }
  if (type == "interface" || type == "none" || type.empty())
    throw_scene_error(type_where,
                      "material type \"{}\" is not supported: it only bounds participating media, which candela "
                      "does not render",
                      type);
  reject_type(type_where, "material", type, {"diffuse", "dielectric"},
              {"coateddiffuse", "coatedconductor", "conductor", "diffusetransmission", "hair", "measured", "mix",
               "subsurface", "thindielectric"});
}

void PbrtParser::material(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the material type");
  ParamList params = read_params(d, fmt::format("Material \"{}\"", type.text));
  MaterialDesc desc = make_material(type.text, at(type), params);
  params.reject_unused();
  scene_.materials.push_back(std::move(desc));
  state_.material = static_cast<int>(scene_.materials.size()) - 1;
}

void PbrtParser::make_named_material(const Token& d) {
  require_world(d);
  Token name = expect_string(d, "the material name");
  if (auto earlier = named_materials_.find(name.text); earlier != named_materials_.end())
    throw_scene_error(at(name), "MakeNamedMaterial: \"{}\" is already defined at {}", name.text,
                      earlier->second.second.to_string());
  ParamList params = read_params(d, fmt::format("MakeNamedMaterial \"{}\"", name.text));
  if (!params.has("type"))
    throw_scene_error(at(d), "MakeNamedMaterial \"{}\": missing the \"string type\" parameter", name.text);
  std::string type = params.get_string("type", "");
  MaterialDesc desc = make_material(type, params.where("type"), params);
  params.reject_unused();
  scene_.materials.push_back(std::move(desc));
  named_materials_[name.text] = {static_cast<int>(scene_.materials.size()) - 1, at(name)};
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

// pbrt-v4 normalises an RGB light colour so that it renders as that RGB; "scale" multiplies it.
RGB PbrtParser::read_emission_scale(ParamList& params, std::string_view name, RGB emitted) {
  float scale = params.get_float("scale", 1);
  if (scale < 0) params.fail("scale", "must not be negative, got {}", scale);
  if (params.has("power")) params.fail("power", "is not supported yet; give \"rgb {}\" and \"float scale\"", name);
  return emitted * scale;
}

void PbrtParser::light_source(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the light type");
  ParamList params = read_params(d, fmt::format("LightSource \"{}\"", type.text));
  if (type.text == "point") {
    RGB intensity = params.get_rgb("I", RGB(1.0f), false);
    intensity = read_emission_scale(params, "I", intensity);
    Point3 from = params.get_point3("from", Point3(0.0f));
    params.reject_unused();
    if (state_.ctm.is_animated())
      throw_scene_error(at(d), "LightSource \"point\": lights must not move (the CTM is animated)");
    scene_.lights.push_back(PointLight{state_.ctm.start.point(from), intensity});
  } else if (type.text == "infinite") {
    if (params.has("filename")) params.fail("filename", "names an image: environment maps are not supported yet");
    if (params.has("portal")) params.fail("portal", "is not supported yet");
    if (params.has("illuminance"))
      params.fail("illuminance", "is not supported yet; give \"rgb L\" and \"float scale\"");
    RGB radiance = params.get_rgb("L", RGB(1.0f), false);
    radiance = read_emission_scale(params, "L", radiance);
    params.reject_unused();
    SkyLight sky;
    sky.zenith = sky.horizon = sky.ground = radiance;
    scene_.lights.push_back(sky);
  } else {
    reject_type(at(type), "light", type.text, {"point", "infinite"}, {"distant", "goniometric", "projection", "spot"});
  }
}

void PbrtParser::area_light_source(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the area light type");
  if (type.text != "diffuse") reject_type(at(type), "area light", type.text, {"diffuse"}, {});
  ParamList params = read_params(d, "AreaLightSource \"diffuse\"");
  if (params.has("filename")) params.fail("filename", "names an image: textured area lights are not supported yet");
  RGB radiance = params.get_rgb("L", RGB(1.0f), false);
  radiance = read_emission_scale(params, "L", radiance);
  bool two_sided = params.get_bool("twosided", false);
  params.reject_unused();
  state_.area_light = AreaEmission{radiance, two_sided};
}

// ---------------------------------------------------------------- shapes

// pbrt clamps zmin/zmax to the radius and phimax to 360; anything less than the whole sphere is
// a partial sphere, which candela cannot represent.
ShapeGeometry PbrtParser::make_sphere(ParamList& params) {
  float radius = params.get_float("radius", 1);
  if (!(radius > 0)) params.fail("radius", "must be positive, got {}", radius);
  float z_min = params.get_float("zmin", -radius);
  float z_max = params.get_float("zmax", radius);
  float phi_max = params.get_float("phimax", 360);
  if (std::min(z_min, z_max) > -radius) params.fail("zmin", "cuts the sphere: partial spheres are not supported yet");
  if (std::max(z_min, z_max) < radius) params.fail("zmax", "cuts the sphere: partial spheres are not supported yet");
  if (phi_max < 360) params.fail("phimax", "cuts the sphere: partial spheres are not supported yet");
  return SphereShape{Point3(0.0f), radius};
}

ShapeGeometry PbrtParser::make_triangle_mesh(ParamList& params) {
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
  mesh.indices.assign(indices.begin(), indices.end());
  return MeshShape{std::move(mesh)};
}

ShapeGeometry PbrtParser::make_ply_mesh(ParamList& params) {
  if (!params.has("filename")) params.fail("filename", "is required: name the .ply file");
  std::string name = params.get_string("filename", "");
  SourceLocation where = params.where("filename");
  fs::path file = resolve_path(name, where, fmt::format("{}: \"filename\"", params.owner()));
  return MeshShape{load_mesh_file(file, where)};
}

void PbrtParser::add_shape(ShapeDesc shape, const Token& directive) {
  if (!open_object_) {
    scene_.shapes.push_back(std::move(shape));
    return;
  }
  if (shape.emission)
    throw_scene_error(at(directive),
                      "Shape inside ObjectBegin \"{}\": area lights in object instances are not supported",
                      open_object_->name);
  open_object_->shapes.push_back(std::move(shape));
}

void PbrtParser::shape(const Token& d) {
  require_world(d);
  Token type = expect_string(d, "the shape type");
  ParamList params = read_params(d, fmt::format("Shape \"{}\"", type.text));
  ShapeDesc desc;
  if (type.text == "sphere")
    desc.geometry = make_sphere(params);
  else if (type.text == "trianglemesh")
    desc.geometry = make_triangle_mesh(params);
  else if (type.text == "plymesh")
    desc.geometry = make_ply_mesh(params);
  else
    reject_type(at(type), "shape", type.text, {"sphere", "trianglemesh", "plymesh"},
                {"bilinearmesh", "curve", "cylinder", "disk", "loopsubdiv"});
  params.reject_unused();
  desc.to_world = state_.ctm.start;
  if (state_.ctm.is_animated()) {
    // Area lights are sampled at fixed positions.
    if (state_.area_light)
      throw_scene_error(at(d), "Shape: area lights must not move (the CTM is animated inside an AreaLightSource)");
    desc.to_world_end = state_.ctm.end;
  }
  desc.material = state_.material;
  desc.emission = state_.area_light;
  desc.reverse_orientation = state_.reverse_orientation;
  desc.name = fmt::format("{} at {}", type.text, at(d).to_string());
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
  open_object_ = ObjectDefinition{name.text, at(d), {}};
}

void PbrtParser::object_end(const Token& d) {
  require_world(d);
  if (!open_object_) throw_scene_error(at(d), "ObjectEnd without a matching ObjectBegin");
  pop_block(d, BlockKind::Object);
  std::string name = open_object_->name;
  objects_.emplace(std::move(name), std::move(*open_object_));
  open_object_.reset();
}

// Instances are expanded: each shape of the object is copied, placed by the CTM at the instance.
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
  for (const ShapeDesc& shape : object->second.shapes) {
    ShapeDesc copy = shape;
    TransformSet placed{state_.ctm.start * shape.to_world,
                        state_.ctm.end * shape.to_world_end.value_or(shape.to_world)};
    copy.to_world = placed.start;
    copy.to_world_end = placed.is_animated() ? std::optional(placed.end) : std::nullopt;
    copy.name = fmt::format("{} (instance of \"{}\" at {})", shape.name, name.text, at(d).to_string());
    scene_.shapes.push_back(std::move(copy));
  }
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

void PbrtParser::unsupported(const Token& d) {
  throw_scene_error(at(d), "the directive \"{}\" is not supported yet", d.text);
}

void PbrtParser::world_end(const Token& d) {
  throw_scene_error(at(d),
                    "WorldEnd is pbrt-v3 syntax; pbrt-v4 files simply end (\"pbrt --upgrade\" converts old files)");
}

}  // namespace

SceneDesc read_pbrt_scene(const std::filesystem::path& file) { return PbrtParser().parse(file); }

}  // namespace candela
