// The native JSON scene format (docs/scene-format.md) read into a SceneDesc.
//
// Every value is read through CheckedObject, which checks types and ranges as it reads and, once an
// object is done, rejects any key nobody asked for: a misspelt optional key would otherwise be
// silently ignored. Errors name the value by JSON pointer and, found again in the source text, by line.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/geometry/sdf_grid.h"
#include "candela/base/error.h"
#include "candela/io/mesh_io.h"
#include "candela/io/named_spectra.h"
#include "candela/io/scene_reader.h"

namespace candela {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;  // ordered: materials keep the file's order

constexpr int kMaxResolution = 65536;
constexpr int64_t kMaxPixels = int64_t(1) << 28;
constexpr float kMaxFilterRadius = 64;  // pixels; the filter is tabulated per unit of radius
constexpr int kMaxTextureDepth = 64;    // textures using textures

// ---------------------------------------------------------------- JSON pointers and source positions

// RFC 6901: '~' and '/' inside a key are written "~0" and "~1".
std::string escape_pointer_token(std::string_view key) {
  std::string token;
  for (char c : key) {
    if (c == '~')
      token += "~0";
    else if (c == '/')
      token += "~1";
    else
      token += c;
  }
  return token;
}

std::string child_pointer(const std::string& parent, std::string_view key) {
  return parent + "/" + escape_pointer_token(key);
}

std::string child_pointer(const std::string& parent, size_t index) { return parent + "/" + std::to_string(index); }

struct TextPosition {
  int line = 1, column = 1;
};

// 1-based line and (byte) column of `offset` in `text`.
TextPosition position_of(std::string_view text, size_t offset) {
  offset = std::min(offset, text.size());
  std::string_view before = text.substr(0, offset);
  size_t line_start = before.rfind('\n');
  int line = 1 + int(std::count(before.begin(), before.end(), '\n'));
  size_t column = line_start == std::string_view::npos ? offset + 1 : offset - line_start;
  return {line, int(column)};
}

// nlohmann::json keeps no source positions, so this walks the text (already validated by
// nlohmann) again: to find where the value at a JSON pointer starts, for messages, and to find keys
// repeated within one object, which nlohmann would silently collapse to the last one.
class SourceScanner {
 public:
  explicit SourceScanner(std::string_view text) : text_(text) {}

  // Offset of the value at `target`; for an object member, of its key.
  std::optional<size_t> offset_of(const std::string& target) {
    restart();
    if (target.empty()) {
      skip_whitespace();
      return pos_;
    }
    std::optional<size_t> found;
    std::string pointer;
    walk_value(pointer, [&](const std::string& entry, size_t offset) {
      if (entry == target) {
        found = offset;
        stop_ = true;
        return false;
      }
      return target.size() > entry.size() && target.starts_with(entry) && target[entry.size()] == '/';
    });
    return found;
  }

  struct Duplicate {
    std::string pointer;
    size_t offset;
  };
  std::optional<Duplicate> first_duplicate_key() {
    restart();
    check_duplicates_ = true;
    std::string pointer;
    walk_value(pointer, [](const std::string&, size_t) { return true; });
    return duplicate_;
  }

 private:
  // Deeper nesting is skipped without recursing, so hostile input cannot exhaust the stack.
  static constexpr int kMaxDepth = 256;

  void restart() {
    pos_ = text_.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // nlohmann accepts a UTF-8 byte order mark
    depth_ = 0;
    stop_ = false;
  }
  bool at(char c) const { return pos_ < text_.size() && text_[pos_] == c; }
  void skip_whitespace() {
    while (pos_ < text_.size() && std::string_view(" \t\r\n").find(text_[pos_]) != std::string_view::npos) ++pos_;
  }
  void skip_string() {
    ++pos_;  // opening quote
    while (pos_ < text_.size()) {
      char c = text_[pos_++];
      if (c == '\\')
        ++pos_;
      else if (c == '"')
        return;
    }
  }
  std::string read_string() {
    size_t start = pos_;
    skip_string();
    std::string_view raw = text_.substr(start, pos_ - start);
    if (raw.find('\\') == std::string_view::npos) return std::string(raw.substr(1, raw.size() - 2));
    return Json::parse(raw.begin(), raw.end()).get<std::string>();  // let nlohmann decode the escapes
  }
  void skip_scalar() {
    while (pos_ < text_.size() && std::string_view(",]} \t\r\n").find(text_[pos_]) == std::string_view::npos) ++pos_;
  }
  void skip_value() {
    skip_whitespace();
    if (at('"')) return skip_string();
    if (!at('{') && !at('[')) return skip_scalar();
    int depth = 0;
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == '"') {
        skip_string();
        continue;
      }
      ++pos_;
      if (c == '{' || c == '[')
        ++depth;
      else if ((c == '}' || c == ']') && --depth == 0)
        return;
    }
  }

  // `enter(pointer, offset)` sees every member and element and says whether to walk into it.
  template <class Enter>
  void walk_value(std::string& pointer, const Enter& enter) {
    skip_whitespace();
    if (depth_ >= kMaxDepth || (!at('{') && !at('['))) return skip_value();
    ++depth_;
    if (at('{'))
      walk_object(pointer, enter);
    else
      walk_array(pointer, enter);
    --depth_;
  }

  template <class Enter>
  void walk_object(std::string& pointer, const Enter& enter) {
    ++pos_;  // '{'
    std::set<std::string> keys;
    for (skip_whitespace(); !stop_ && pos_ < text_.size() && !at('}'); skip_whitespace()) {
      size_t key_offset = pos_;
      std::string key = read_string();
      skip_whitespace();
      ++pos_;  // ':'
      size_t parent_length = pointer.size();
      pointer += '/' + escape_pointer_token(key);
      if (check_duplicates_ && !keys.insert(key).second) {
        duplicate_ = Duplicate{pointer, key_offset};
        stop_ = true;
        return;
      }
      if (enter(pointer, key_offset))
        walk_value(pointer, enter);
      else
        skip_value();
      pointer.resize(parent_length);
      skip_whitespace();
      if (at(',')) ++pos_;
    }
    ++pos_;  // '}'
  }

  template <class Enter>
  void walk_array(std::string& pointer, const Enter& enter) {
    ++pos_;  // '['
    size_t index = 0;
    for (skip_whitespace(); !stop_ && pos_ < text_.size() && !at(']'); skip_whitespace(), ++index) {
      size_t parent_length = pointer.size();
      pointer += '/' + std::to_string(index);
      if (enter(pointer, pos_))
        walk_value(pointer, enter);
      else
        skip_value();
      pointer.resize(parent_length);
      skip_whitespace();
      if (at(',')) ++pos_;
    }
    ++pos_;  // ']'
  }

  std::string_view text_;
  size_t pos_ = 0;
  int depth_ = 0;
  bool stop_ = false;
  bool check_duplicates_ = false;
  std::optional<Duplicate> duplicate_;
};

// Builds the SourceLocation of a JSON pointer and throws the SceneError.
class ErrorReporter {
 public:
  ErrorReporter(std::string_view text, std::string file_name) : text_(text), file_name_(std::move(file_name)) {}

  const std::string& file_name() const { return file_name_; }

  SourceLocation location_of_offset(size_t offset, std::string pointer = {}) const {
    TextPosition position = position_of(text_, offset);
    return {file_name_, position.line, position.column, std::move(pointer)};
  }

  // The text is scanned again only when a location is needed (an error, or a mesh file that may
  // report one), so reading a correct scene stays a single pass over its values.
  SourceLocation location(const std::string& pointer) const {
    if (auto offset = SourceScanner(text_).offset_of(pointer)) return location_of_offset(*offset, pointer);
    return {file_name_, 0, 0, pointer};
  }

  template <typename... Args>
  [[noreturn]] void fail(const std::string& pointer, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(location(pointer), format, std::forward<Args>(args)...);
  }

 private:
  std::string_view text_;
  std::string file_name_;
};

// ---------------------------------------------------------------- typed values

// What a value was instead of what was expected: its type, or its length for arrays.
std::string describe(const Json& value) {
  if (value.is_array()) return fmt::format("an array of {} element{}", value.size(), value.size() == 1 ? "" : "s");
  return value.type_name();
}

double read_double(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (!value.is_number()) report.fail(pointer, "expected a number, got {}", describe(value));
  double x = value.get<double>();
  if (!std::isfinite(x)) report.fail(pointer, "expected a finite number, got {}", x);
  return x;
}

float read_float(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  double x = read_double(report, value, pointer);
  if (std::abs(x) > double(FLT_MAX)) report.fail(pointer, "{} is out of range for a 32-bit float", x);
  return float(x);
}

// Reads array[index] without building its pointer unless there is something to report (meshes
// have millions of coordinates).
float read_float_element(const ErrorReporter& report, const Json& array, size_t index, const std::string& pointer) {
  const Json& value = array[index];
  if (value.is_number()) {
    double x = value.get<double>();
    if (std::isfinite(x) && std::abs(x) <= double(FLT_MAX)) return float(x);
  }
  return read_float(report, value, child_pointer(pointer, index));  // fails with the reason
}

int64_t read_int64(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (!value.is_number()) report.fail(pointer, "expected an integer, got {}", describe(value));
  if (value.is_number_unsigned()) {
    uint64_t u = value.get<uint64_t>();
    if (u > uint64_t(std::numeric_limits<int64_t>::max())) report.fail(pointer, "integer {} is too large", u);
    return int64_t(u);
  }
  if (value.is_number_integer()) return value.get<int64_t>();
  double x = read_double(report, value, pointer);  // JSON does not distinguish 3 from 3.0
  if (x != std::floor(x)) report.fail(pointer, "expected an integer, got {}", x);
  if (std::abs(x) > 9.0e18) report.fail(pointer, "integer {} is too large", x);
  return int64_t(x);
}

uint64_t read_uint64(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (value.is_number_unsigned()) return value.get<uint64_t>();
  int64_t n = read_int64(report, value, pointer);
  if (n < 0) report.fail(pointer, "expected a non-negative integer, got {}", n);
  return uint64_t(n);
}

Vec3 read_vec3(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (!value.is_array() || value.size() != 3)
    report.fail(pointer, "expected an array of 3 numbers, got {}", describe(value));
  Vec3 v;
  for (size_t i = 0; i < 3; ++i) v[int(i)] = read_float_element(report, value, i, pointer);
  return v;
}

Vec2 read_vec2(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (!value.is_array() || value.size() != 2)
    report.fail(pointer, "expected an array of 2 numbers, got {}", describe(value));
  return {read_float_element(report, value, 0, pointer), read_float_element(report, value, 1, pointer)};
}

// Reflectances and albedos cannot exceed 1 without creating energy; emission can. Other colours (a
// conductor's k, the constants inside textures, which may be used anywhere) need only be >= 0.
enum class ColorKind { Albedo, Emission, NonNegative };

float read_color_component(const ErrorReporter& report, const Json& value, const std::string& pointer, ColorKind kind) {
  float c = read_float(report, value, pointer);
  if (c < 0) report.fail(pointer, "colour components must be >= 0, got {}", c);
  if (kind == ColorKind::Albedo && c > 1)
    report.fail(pointer, "a reflectance must be <= 1 in each channel (more would create energy), got {}", c);
  return c;
}

// [r, g, b], or one number for grey.
RGB read_rgb(const ErrorReporter& report, const Json& value, const std::string& pointer, ColorKind kind) {
  if (value.is_number()) return RGB(read_color_component(report, value, pointer, kind));
  if (!value.is_array() || value.size() != 3)
    report.fail(pointer, "expected a colour, [r, g, b] or a single number, got {}", describe(value));
  RGB rgb;
  for (int i = 0; i < 3; ++i) rgb[i] = read_color_component(report, value[i], child_pointer(pointer, size_t(i)), kind);
  return rgb;
}

Vec3 read_direction(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  Vec3 v = read_vec3(report, value, pointer);
  if (length_squared(v) == 0 || !is_finite(normalize(v)))
    report.fail(pointer, "expected a non-zero vector, got [{}, {}, {}]", v.x, v.y, v.z);
  return v;
}

bool read_bool(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (!value.is_boolean()) report.fail(pointer, "expected true or false, got {}", describe(value));
  return value.get<bool>();
}

std::string read_string(const ErrorReporter& report, const Json& value, const std::string& pointer) {
  if (!value.is_string()) report.fail(pointer, "expected a string, got {}", describe(value));
  return value.get<std::string>();
}

// One of a fixed set of names, e.g. "bsdf" for DirectionSampling::Bsdf.
template <typename E>
E read_name(const ErrorReporter& report, const Json& value, const std::string& pointer, std::string_view what,
            std::initializer_list<std::pair<std::string_view, E>> names) {
  std::string name = read_string(report, value, pointer);
  for (const auto& [known, result] : names)
    if (name == known) return result;
  std::vector<std::string_view> known;
  for (const auto& entry : names) known.push_back(entry.first);
  report.fail(pointer, "unknown {} \"{}\"; expected one of: {}", what, name, fmt::join(known, ", "));
}

void check_is_array(const ErrorReporter& report, const Json& value, const std::string& pointer,
                    std::string_view of_what) {
  if (!value.is_array()) report.fail(pointer, "expected an array of {}, got {}", of_what, describe(value));
}

enum class Bound { Any, Positive, NonNegative, UnitInterval };

float check_bound(const ErrorReporter& report, float x, Bound bound, const std::string& pointer) {
  if (bound == Bound::Positive && !(x > 0)) report.fail(pointer, "expected a positive number, got {}", x);
  if (bound == Bound::NonNegative && !(x >= 0)) report.fail(pointer, "expected a number >= 0, got {}", x);
  if (bound == Bound::UnitInterval && !(x >= 0 && x <= 1))
    report.fail(pointer, "expected a number in [0, 1], got {}", x);
  return x;
}

// ---------------------------------------------------------------- metal presets

// A conductor's "metal": the complex index of refraction eta + i k of a measured metal, as RGB.
struct MetalPreset {
  std::string_view name;
  RGB eta, k;
};

// Metals that pbrt-v4's named spectra (named_spectra.h: Ag, Al, Au, Cu, CuZn, ...) lack, from the
// same source as those: the published RGB values of Tungsten's ComplexIorData.hpp (also Mitsuba's
// conductor presets). Na, Ni and V are that table's "_palik" entries, the only ones it has for them.
constexpr MetalPreset kMoreMetals[] = {
    {"Be", {4.1850592788f, 3.1850604423f, 2.7840913457f}, {3.8354398268f, 3.0101260162f, 2.8690088743f}},
    {"Cr", {4.3696828663f, 2.9167024892f, 1.6547005413f}, {5.2064337956f, 4.2313645277f, 3.7549467933f}},
    {"Hg", {2.3989314904f, 1.4400254917f, 0.9095512090f}, {6.3276269444f, 4.3719414152f, 3.4217899270f}},
    {"Ir", {3.0864098394f, 2.0821938440f, 1.6178866805f}, {5.5921510077f, 4.0671757150f, 3.2672611269f}},
    {"K", {0.0640493070f, 0.0464100621f, 0.0381842017f}, {2.1042155920f, 1.3489364357f, 0.9132113889f}},
    {"Li", {0.2657871942f, 0.1956102432f, 0.2209198538f}, {3.5401743407f, 2.3111306542f, 1.6685930000f}},
    {"Mo", {4.4837010280f, 3.5254578255f, 2.7760769438f}, {4.1111307988f, 3.4208716252f, 3.1506031404f}},
    {"Na", {0.0602665320f, 0.0561412435f, 0.0619909494f}, {3.1792906496f, 2.1124800781f, 1.5790940266f}},
    {"Nb", {3.4201353595f, 2.7901921379f, 2.3955856658f}, {3.4413817900f, 2.7376437930f, 2.5799132708f}},
    {"Ni", {2.3672753521f, 1.6633583302f, 1.4670554172f}, {4.4988329911f, 3.0501643957f, 2.3454274399f}},
    {"Rh", {2.5857954933f, 1.8601866068f, 1.5544279524f}, {6.7822927110f, 4.7029501026f, 3.9760892461f}},
    {"Ta", {2.0625846607f, 2.3930915569f, 2.6280684948f}, {2.4080467973f, 1.7413705864f, 1.9470377016f}},
    {"TiN", {1.6484691607f, 1.1504482522f, 1.3797795097f}, {3.3684596226f, 1.9434888540f, 1.1020123347f}},
    {"V", {4.2775126218f, 3.5131538236f, 2.7611257461f}, {3.4911844504f, 2.8893580874f, 3.1116965117f}},
    {"W", {4.3707029924f, 3.3002972445f, 2.9982666528f}, {3.5006778591f, 2.6048652781f, 2.2731930614f}},
};

struct ComplexIor {
  RGB eta, k;
};

// "Au" is pbrt-v4's "metal-Au-eta" and "metal-Au-k", or one of kMoreMetals.
std::optional<ComplexIor> find_metal(std::string_view name) {
  std::string prefix = fmt::format("metal-{}-", name);
  auto eta = pbrt_spectra::find_named(prefix + "eta"), k = pbrt_spectra::find_named(prefix + "k");
  if (eta && k && eta->kind == pbrt_spectra::NamedKind::Metal) return ComplexIor{eta->rgb, k->rgb};
  for (const MetalPreset& metal : kMoreMetals)
    if (metal.name == name) return ComplexIor{metal.eta, metal.k};
  return std::nullopt;
}

// Every name find_metal() knows, sorted.
std::vector<std::string> metal_names() {
  std::vector<std::string> names;
  for (std::string_view spectrum : pbrt_spectra::named_spectrum_names())
    if (spectrum.starts_with("metal-") && spectrum.ends_with("-eta"))
      names.emplace_back(spectrum.substr(6, spectrum.size() - 6 - 4));
  for (const MetalPreset& metal : kMoreMetals) names.emplace_back(metal.name);
  std::sort(names.begin(), names.end());
  return names;
}

// ---------------------------------------------------------------- CheckedObject

// One JSON object, read key by key with type checks. finish() reports the first key that no read
// asked for, listing the keys that were asked for (the object's schema, as far as it was read).
class CheckedObject {
 public:
  CheckedObject(const ErrorReporter& report, const Json& value, std::string pointer)
      : report_(report), value_(value), pointer_(std::move(pointer)) {
    if (!value_.is_object()) report_.fail(pointer_, "expected an object, got {}", describe(value_));
  }

  const std::string& pointer() const { return pointer_; }
  std::string pointer_of(std::string_view key) const { return child_pointer(pointer_, key); }
  const ErrorReporter& report() const { return report_; }

  const Json* find(std::string_view key) {
    if (std::find(asked_.begin(), asked_.end(), key) == asked_.end()) asked_.emplace_back(key);
    auto it = value_.find(std::string(key));
    return it == value_.end() ? nullptr : &*it;
  }
  bool has(std::string_view key) { return find(key) != nullptr; }
  const Json& require(std::string_view key) {
    const Json* value = find(key);
    if (!value) report_.fail(pointer_, "missing required key \"{}\"", key);
    return *value;
  }

  float number(std::string_view key, Bound bound = Bound::Any) {
    return check_bound(report_, read_float(report_, require(key), pointer_of(key)), bound, pointer_of(key));
  }
  float number_or(std::string_view key, float fallback, Bound bound = Bound::Any) {
    return has(key) ? number(key, bound) : fallback;
  }
  int integer_or(std::string_view key, int fallback, int64_t min, int64_t max) {
    const Json* value = find(key);
    if (!value) return fallback;
    int64_t n = read_int64(report_, *value, pointer_of(key));
    if (n < min || n > max) {
      if (max == std::numeric_limits<int>::max())
        report_.fail(pointer_of(key), "expected an integer >= {}, got {}", min, n);
      report_.fail(pointer_of(key), "expected an integer in [{}, {}], got {}", min, max, n);
    }
    return int(n);
  }
  Vec3 vec3(std::string_view key) { return read_vec3(report_, require(key), pointer_of(key)); }
  Vec3 vec3_or(std::string_view key, Vec3 fallback) { return has(key) ? vec3(key) : fallback; }
  Vec3 direction(std::string_view key) { return read_direction(report_, require(key), pointer_of(key)); }
  Vec3 direction_or(std::string_view key, Vec3 fallback) { return has(key) ? direction(key) : fallback; }
  RGB rgb(std::string_view key, ColorKind kind) { return read_rgb(report_, require(key), pointer_of(key), kind); }
  RGB rgb_or(std::string_view key, ColorKind kind, RGB fallback) { return has(key) ? rgb(key, kind) : fallback; }
  std::optional<RGB> optional_rgb(std::string_view key, ColorKind kind) {
    return has(key) ? std::optional(rgb(key, kind)) : std::nullopt;
  }
  bool boolean_or(std::string_view key, bool fallback) {
    const Json* value = find(key);
    return value ? read_bool(report_, *value, pointer_of(key)) : fallback;
  }
  std::string string(std::string_view key) { return read_string(report_, require(key), pointer_of(key)); }
  std::string string_or(std::string_view key, std::string fallback) {
    return has(key) ? string(key) : std::move(fallback);
  }

  void finish() const {
    for (auto it = value_.begin(); it != value_.end(); ++it) {
      const std::string& key = it.key();
      if (key == "_comment" || std::find(asked_.begin(), asked_.end(), key) != asked_.end()) continue;
      report_.fail(pointer_of(key), "unknown key; expected one of: {}", fmt::join(asked_, ", "));
    }
  }

 private:
  const ErrorReporter& report_;
  const Json& value_;
  std::string pointer_;
  std::vector<std::string> asked_;
};

// ---------------------------------------------------------------- the reader

class JsonSceneReader {
 public:
  JsonSceneReader(std::string_view text, const std::string& file_name, const fs::path& base_dir)
      : text_(text), report_(text, file_name), base_dir_(base_dir) {}

  SceneDesc read() {
    Json document = parse_document();
    reject_duplicate_keys();
    CheckedObject root(report_, document, "");
    const Json empty = Json::object();  // absent sections still get their defaults
    const Json* camera = root.find("camera");
    read_camera(camera ? *camera : empty, root.pointer_of("camera"));
    const Json* render = root.find("render");
    read_render(render ? *render : empty, root.pointer_of("render"));
    if (const Json* textures = root.find("textures")) read_textures(*textures, root.pointer_of("textures"));
    if (const Json* materials = root.find("materials")) read_materials(*materials, root.pointer_of("materials"));
    if (const Json* objects = root.find("objects")) read_objects(*objects, root.pointer_of("objects"));
    if (const Json* shapes = root.find("shapes")) read_shapes(*shapes, root.pointer_of("shapes"));
    if (const Json* lights = root.find("lights")) read_lights(*lights, root.pointer_of("lights"));
    root.finish();
    scene_.source_file = report_.file_name();
    return std::move(scene_);
  }

 private:
  Json parse_document() const {
    try {
      return Json::parse(text_.begin(), text_.end());
    } catch (const Json::parse_error& e) {
      size_t offset = e.byte == 0 ? 0 : e.byte - 1;  // e.byte is 1-based: the last byte read
      throw_scene_error(report_.location_of_offset(offset), "malformed JSON: {}", parse_error_reason(e.what()));
    } catch (const Json::out_of_range& e) {
      throw_number_overflow(e.what());
    }
  }

  // nlohmann rejects numbers beyond double's range ("number overflow parsing '1e999'") without a
  // position; the literal itself is found in the text instead.
  [[noreturn]] void throw_number_overflow(std::string_view what) const {
    size_t open = what.find('\''), close = what.rfind('\'');
    std::string_view literal = open < close ? what.substr(open + 1, close - open - 1) : std::string_view();
    size_t offset = literal.empty() ? std::string_view::npos : text_.find(literal);
    SourceLocation where = offset == std::string_view::npos ? SourceLocation{report_.file_name(), 0, 0, {}}
                                                            : report_.location_of_offset(offset);
    throw_scene_error(where, "number {} is out of range", literal);
  }

  // nlohmann's message repeats its own position: keep only the reason after it.
  static std::string parse_error_reason(std::string_view what) {
    size_t start = what.find("parse error");
    size_t colon = what.find(": ", start == std::string_view::npos ? 0 : start);
    return std::string(colon == std::string_view::npos ? what : what.substr(colon + 2));
  }

  void reject_duplicate_keys() const {
    if (auto duplicate = SourceScanner(text_).first_duplicate_key())
      throw_scene_error(report_.location_of_offset(duplicate->offset, duplicate->pointer),
                        "duplicate key (each key may appear only once in an object)");
  }

  // ---- camera and render settings

  void read_camera(const Json& value, const std::string& pointer) {
    CheckedObject camera(report_, value, pointer);
    const Json* transform = camera.find("transform");
    if (transform && (camera.has("position") || camera.has("look_at") || camera.has("up")))
      report_.fail(camera.pointer_of("transform"),
                   "a camera takes either \"transform\" or \"position\"/\"look_at\"/\"up\", not both");
    Point3 position = camera.vec3_or("position", {0, 0, 0});
    Point3 look_at = camera.vec3_or("look_at", {0, 0, 1});
    Vec3 up = camera.direction_or("up", {0, 1, 0});
    float fov = camera.number_or("fov", 40);
    if (!(fov > 0 && fov < 180))
      report_.fail(camera.pointer_of("fov"), "the field of view must be in (0, 180) degrees, got {}", fov);
    if (const Json* axis = camera.find("fov_axis"))
      scene_.camera.fov_axis = read_name<FovAxis>(report_, *axis, camera.pointer_of("fov_axis"), "field of view axis",
                                                  {{"x", FovAxis::X},
                                                   {"y", FovAxis::Y},
                                                   {"smaller", FovAxis::Smaller},
                                                   {"larger", FovAxis::Larger},
                                                   {"diagonal", FovAxis::Diagonal}});
    else
      scene_.camera.fov_axis = FovAxis::Y;
    if (const Json* projection = camera.find("projection"))
      scene_.camera.projection =
          read_name<Projection>(report_, *projection, camera.pointer_of("projection"), "projection",
                                {{"perspective", Projection::Perspective}, {"orthographic", Projection::Orthographic}});
    scene_.camera.near_clip = camera.number_or("near_clip", scene_.camera.near_clip, Bound::NonNegative);
    scene_.film.width = camera.integer_or("width", scene_.film.width, 1, kMaxResolution);
    scene_.film.height = camera.integer_or("height", scene_.film.height, 1, kMaxResolution);
    read_lens_and_shutter(camera);
    camera.finish();
    if (int64_t(scene_.film.width) * scene_.film.height > kMaxPixels)
      report_.fail(pointer, "{} x {} pixels exceeds the limit of 2^28 pixels", scene_.film.width, scene_.film.height);
    if (transform) {
      // Camera space: +x image right, +y image up, +z the view direction.
      scene_.camera.world_from_camera = read_transform(*transform, camera.pointer_of("transform"));
    } else {
      check_view_direction(camera, position, look_at, up);
      scene_.camera.world_from_camera = Transform::look_at_right_handed(position, look_at, up);
    }
    scene_.camera.fov_degrees = fov;
  }

  void read_lens_and_shutter(CheckedObject& camera) {
    CameraDesc& desc = scene_.camera;
    desc.lens_radius = camera.number_or("lens_radius", desc.lens_radius, Bound::NonNegative);
    desc.focus_distance = camera.number_or("focus_distance", desc.focus_distance, Bound::Positive);
    if (const Json* shutter = camera.find("shutter")) {
      Vec2 open_close = read_vec2(report_, *shutter, camera.pointer_of("shutter"));
      if (!(open_close.x <= open_close.y))
        report_.fail(camera.pointer_of("shutter"), "the shutter must not close before it opens, got [{}, {}]",
                     open_close.x, open_close.y);
      desc.shutter_open = open_close.x;
      desc.shutter_close = open_close.y;
    }
  }

  void check_view_direction(const CheckedObject& camera, Point3 position, Point3 look_at, Vec3 up) const {
    Vec3 forward = look_at - position;
    if (length_squared(forward) == 0 || !is_finite(normalize(forward)))
      report_.fail(camera.pointer_of("look_at"), "look_at must differ from position (it sets the view direction)");
    if (length(cross(normalize(forward), normalize(up))) < 1e-6f)
      report_.fail(camera.pointer_of("up"), "up is parallel to the view direction, so the image has no defined up");
  }

  void read_render(const Json& value, const std::string& pointer) {
    CheckedObject render(report_, value, pointer);
    constexpr int64_t kIntMax = std::numeric_limits<int>::max();
    RenderSettings& settings = scene_.settings;
    settings.spp = render.integer_or("spp", settings.spp, 1, kIntMax);
    settings.max_depth = render.integer_or("max_depth", settings.max_depth, 1, kIntMax);
    if (const Json* seed = render.find("seed")) settings.seed = read_uint64(report_, *seed, render.pointer_of("seed"));
    settings.integrator = render.string_or("integrator", settings.integrator);
    if (settings.integrator.empty()) report_.fail(render.pointer_of("integrator"), "the integrator name is empty");
    scene_.film.filename = render.string_or("output", "");
    settings.rr_start_depth = render.integer_or("rr_start_depth", settings.rr_start_depth, 0, kIntMax);
    if (const Json* times = render.find("transform_times"))
      read_transform_times(*times, render.pointer_of("transform_times"));
    if (const Json* sampler = render.find("sampler"))
      settings.sampler = read_sampler(*sampler, render.pointer_of("sampler"));
    else
      settings.sampler.type = SamplerType::ZSobol;  // the most efficient measured (docs/performance.md)
    if (const Json* filter = render.find("filter")) settings.filter = read_filter(*filter, render.pointer_of("filter"));
    read_integrator_strategies(render, settings);
    if (const Json* adaptive = render.find("adaptive"))
      read_adaptive(*adaptive, render.pointer_of("adaptive"), settings);
    if (const Json* mlt = render.find("mlt")) read_mlt(*mlt, render.pointer_of("mlt"), settings);
    render.finish();
  }

  // Metropolis light transport's parameters (integrator "mlt").
  void read_mlt(const Json& value, const std::string& pointer, RenderSettings& settings) const {
    CheckedObject object(report_, value, pointer);
    constexpr int64_t kIntMax = std::numeric_limits<int>::max();
    settings.mlt.bootstrap = object.integer_or("bootstrap", settings.mlt.bootstrap, 1, kIntMax);
    settings.mlt.chains = object.integer_or("chains", settings.mlt.chains, 1, kIntMax);
    settings.mlt.sigma = object.number_or("sigma", settings.mlt.sigma, Bound::Positive);
    if (settings.mlt.sigma > 1) report_.fail(object.pointer_of("sigma"), "sigma must be at most 1, got {}", settings.mlt.sigma);
    settings.mlt.large_step = object.number_or("large_step", settings.mlt.large_step, Bound::UnitInterval);
    settings.mlt.lens = object.number_or("lens", settings.mlt.lens, Bound::UnitInterval);
    settings.mlt.caustic = object.number_or("caustic", settings.mlt.caustic, Bound::UnitInterval);
    if (settings.mlt.large_step + settings.mlt.lens + settings.mlt.caustic > 1)
      report_.fail(pointer, "large_step + lens + caustic must be at most 1, got {}",
                   settings.mlt.large_step + settings.mlt.lens + settings.mlt.caustic);
    object.finish();
  }

  void read_transform_times(const Json& value, const std::string& pointer) {
    Vec2 times = read_vec2(report_, value, pointer);
    // Shapes are interpolated between the two times, so they must span an interval.
    if (!(times.x < times.y))
      report_.fail(pointer, "the start time must be less than the end time, got [{}, {}]", times.x, times.y);
    scene_.transform_start_time = times.x;
    scene_.transform_end_time = times.y;
  }

  SamplerDesc read_sampler(const Json& value, const std::string& pointer) const {
    CheckedObject object(report_, value, pointer);
    SamplerDesc sampler;
    sampler.type = read_name<SamplerType>(report_, object.require("type"), object.pointer_of("type"), "sampler type",
                                          {{"independent", SamplerType::Independent},
                                           {"stratified", SamplerType::Stratified},
                                           {"poisson", SamplerType::Poisson},
                                           {"zsobol", SamplerType::ZSobol}});
    if (sampler.type == SamplerType::Stratified) sampler.jitter = object.boolean_or("jitter", sampler.jitter);
    object.finish();
    return sampler;
  }

  // Each type starts from pbrt-v4's defaults; only the keys of that type's parameters are allowed.
  FilterDesc read_filter(const Json& value, const std::string& pointer) const {
    CheckedObject object(report_, value, pointer);
    FilterType type = read_name<FilterType>(report_, object.require("type"), object.pointer_of("type"), "filter type",
                                            {{"box", FilterType::Box},
                                             {"tent", FilterType::Tent},
                                             {"gaussian", FilterType::Gaussian},
                                             {"mitchell", FilterType::Mitchell}});
    FilterDesc filter = default_filter(type);
    if (const Json* radius = object.find("radius"))
      filter.radius = read_filter_radius(*radius, object.pointer_of("radius"));
    if (type == FilterType::Gaussian)
      filter.gaussian_sigma = object.number_or("sigma", filter.gaussian_sigma, Bound::Positive);
    if (type == FilterType::Mitchell) {
      filter.mitchell_b = object.number_or("b", filter.mitchell_b);
      filter.mitchell_c = object.number_or("c", filter.mitchell_c);
    }
    object.finish();
    return filter;
  }

  // One number for both axes, or [x, y].
  Vec2 read_filter_radius(const Json& value, const std::string& pointer) const {
    Vec2 radius = value.is_number() ? Vec2(read_float(report_, value, pointer), read_float(report_, value, pointer))
                                    : read_vec2(report_, value, pointer);
    for (float r : {radius.x, radius.y})
      if (!(r > 0 && r <= kMaxFilterRadius))
        report_.fail(pointer, "a filter radius must be in (0, {}] pixels, got {}", kMaxFilterRadius, r);
    return radius;
  }

  void read_integrator_strategies(CheckedObject& render, RenderSettings& settings) const {
    if (const Json* value = render.find("direction_sampling"))
      settings.path.direction_sampling = read_name<DirectionSampling>(
          report_, *value, render.pointer_of("direction_sampling"), "direction sampling",
          {{"bsdf", DirectionSampling::Bsdf}, {"cosine", DirectionSampling::Cosine},
           {"uniform", DirectionSampling::Uniform}});
    settings.path.mis = render.boolean_or("mis", settings.path.mis);
    settings.hide_emitters = render.boolean_or("hide_emitters", settings.hide_emitters);
    settings.spectral = render.boolean_or("spectral", settings.spectral);
    if (const Json* value = render.find("light_selection"))
      settings.light_selection =
          read_name<LightSelection>(report_, *value, render.pointer_of("light_selection"), "light selection",
                                    {{"power", LightSelection::Power}, {"paper", LightSelection::Paper}, {"uniform", LightSelection::Uniform}});
    settings.path.shadow_rays = render.integer_or("shadow_rays", settings.path.shadow_rays, 1, std::numeric_limits<int>::max());
    if (const Json* value = render.find("bvh"))
      settings.bvh = read_name<BvhLayout>(report_, *value, render.pointer_of("bvh"), "BVH layout",
                                          {{"fast", BvhLayout::Fast}, {"compact", BvhLayout::Compact}});
  }

  // Present = on (RenderSettings): a threshold on the pixels' relative error, a budget of samples
  // per pixel on average, or both.
  void read_adaptive(const Json& value, const std::string& pointer, RenderSettings& settings) const {
    CheckedObject adaptive(report_, value, pointer);
    constexpr int64_t kIntMax = std::numeric_limits<int>::max();
    settings.adaptive_threshold = adaptive.number_or("threshold", 0, Bound::Positive);
    settings.adaptive_spp = adaptive.integer_or("spp", 0, 1, kIntMax);
    if (!settings.adaptive()) report_.fail(pointer, "expected \"threshold\", \"spp\" or both");
    settings.adaptive_batch = adaptive.integer_or("batch", settings.adaptive_batch, 1, kIntMax);
    // Batches of a power of two keep every sampler's stratification within a batch.
    if ((settings.adaptive_batch & (settings.adaptive_batch - 1)) != 0)
      report_.fail(adaptive.pointer_of("batch"), "expected a power of two, got {}", settings.adaptive_batch);
    if (settings.adaptive_spp > 0 && settings.adaptive_spp < settings.adaptive_batch)
      report_.fail(adaptive.pointer_of("spp"), "spp ({}) must be at least the batch size ({})", settings.adaptive_spp,
                   settings.adaptive_batch);
    settings.adaptive_max_spp = adaptive.integer_or("max_spp", 0, 1, kIntMax);
    if (settings.adaptive_max_spp > 0 && settings.adaptive_max_spp < settings.adaptive_batch)
      report_.fail(adaptive.pointer_of("max_spp"), "max_spp ({}) must be at least the batch size ({})",
                   settings.adaptive_max_spp, settings.adaptive_batch);
    if (settings.adaptive_max_spp > 0 && settings.adaptive_max_spp < settings.adaptive_spp)
      report_.fail(adaptive.pointer_of("max_spp"), "max_spp ({}) must be at least spp ({})", settings.adaptive_max_spp,
                   settings.adaptive_spp);
    adaptive.finish();
  }

  // ---- textures

  // Named textures may refer to each other in any order. Each is read when first needed, so that
  // SceneDesc::textures lists every texture after the textures it refers to.
  struct NamedTexture {
    const Json* value = nullptr;
    std::string pointer;
    bool reading = false;  // on the stack of textures being read: meeting it again is a cycle
    int index = -1;        // in SceneDesc::textures, once read
  };

  void read_textures(const Json& value, const std::string& pointer) {
    if (!value.is_object())
      report_.fail(pointer, "expected an object mapping texture names to textures, got {}", describe(value));
    std::vector<std::string> names;  // in the file's order
    for (auto it = value.begin(); it != value.end(); ++it) {
      if (it.key() == "_comment") continue;
      names.push_back(it.key());
      named_textures_[it.key()] = NamedTexture{&it.value(), child_pointer(pointer, it.key())};
    }
    for (const std::string& name : names) named_texture(name, named_textures_[name].pointer);
  }

  // The index of a named texture, read first (with what it refers to) if it has not been yet.
  // `pointer` is where the name was given.
  int named_texture(const std::string& name, const std::string& pointer) {
    auto it = named_textures_.find(name);
    if (it == named_textures_.end()) {
      std::vector<std::string> names;
      for (const auto& entry : named_textures_) names.push_back(entry.first);
      if (names.empty()) report_.fail(pointer, "unknown texture \"{}\" (\"textures\" defines none)", name);
      report_.fail(pointer, "unknown texture \"{}\"; defined: {}", name, fmt::join(names, ", "));
    }
    NamedTexture& texture = it->second;  // std::map: stays valid while other textures are read
    if (texture.index >= 0) return texture.index;
    if (texture.reading) {
      std::vector<std::string> cycle(std::find(texture_stack_.begin(), texture_stack_.end(), name),
                                     texture_stack_.end());
      cycle.push_back(name);
      report_.fail(pointer, "textures refer to each other in a cycle: {}", fmt::join(cycle, " -> "));
    }
    texture.reading = true;
    texture_stack_.push_back(name);
    TextureDesc desc = read_texture(*texture.value, texture.pointer);
    texture_stack_.pop_back();
    texture.reading = false;
    texture.index = add_texture(std::move(desc));
    return texture.index;
  }

  int add_texture(TextureDesc texture) {
    scene_.textures.push_back(std::move(texture));
    return int(scene_.textures.size()) - 1;
  }

  TextureDesc read_texture(const Json& value, const std::string& pointer) {
    // Textures are read recursively: hostile nesting (inline, or a long chain of names) must not
    // exhaust the stack.
    if (texture_depth_ >= kMaxTextureDepth)
      report_.fail(pointer, "textures nest too deeply: more than {} levels of textures using textures",
                   kMaxTextureDepth);
    struct DepthGuard {
      int& depth;
      explicit DepthGuard(int& d) : depth(++d) {}
      ~DepthGuard() { --depth; }
    } guard(texture_depth_);
    CheckedObject t(report_, value, pointer);
    std::string type = t.string("type");
    TextureDesc texture;
    // A texture may be used in any parameter, so the constants inside it are only checked to be >= 0.
    constexpr ColorKind kAny = ColorKind::NonNegative;
    if (type == "image") {
      texture = read_image_texture(t);
    } else if (type == "checkerboard") {
      CheckerboardTexture checkerboard;
      checkerboard.tex1 = color_input_or(t, "tex1", kAny, checkerboard.tex1);
      checkerboard.tex2 = color_input_or(t, "tex2", kAny, checkerboard.tex2);
      checkerboard.mapping = read_uv_mapping(t);
      texture = checkerboard;
    } else if (type == "scale") {
      ScaleTexture scale;
      scale.tex = color_input_or(t, "tex", kAny, scale.tex);
      scale.scale = float_input_or(t, "scale", Bound::NonNegative, scale.scale);
      texture = scale;
    } else if (type == "mix") {
      MixTexture mix;
      mix.tex1 = color_input_or(t, "tex1", kAny, mix.tex1);
      mix.tex2 = color_input_or(t, "tex2", kAny, mix.tex2);
      mix.amount = float_input_or(t, "amount", Bound::UnitInterval, mix.amount);
      texture = mix;
    } else if (type == "mesh_attribute") {
      texture = MeshAttributeTexture{t.string("name"), t.boolean_or("per_face", false)};
    } else {
      report_.fail(t.pointer_of("type"),
                   "unknown texture type \"{}\"; expected one of: image, checkerboard, scale, mix, mesh_attribute",
                   type);
    }
    t.finish();
    return texture;
  }

  ImageTexture read_image_texture(CheckedObject& t) const {
    ImageTexture image;
    image.filename = existing_file(t, "filename", "image");
    if (const Json* wrap = t.find("wrap"))
      image.wrap = read_name<TextureWrap>(report_, *wrap, t.pointer_of("wrap"), "wrap mode",
                                          {{"repeat", TextureWrap::Repeat},
                                           {"clamp", TextureWrap::Clamp},
                                           {"black", TextureWrap::Black},
                                           {"mirror", TextureWrap::Mirror}});
    if (const Json* encoding = t.find("encoding"))
      image.encoding = read_name<ColorEncoding>(
          report_, *encoding, t.pointer_of("encoding"), "colour encoding",
          {{"auto", ColorEncoding::Auto}, {"srgb", ColorEncoding::SRGB}, {"linear", ColorEncoding::Linear}});
    if (const Json* filter = t.find("filter"))
      image.bilinear = read_name<bool>(report_, *filter, t.pointer_of("filter"), "texture filter",
                                       {{"bilinear", true}, {"nearest", false}});
    image.scale = t.number_or("scale", image.scale, Bound::NonNegative);
    image.invert = t.boolean_or("invert", image.invert);
    image.luminance = t.boolean_or("luminance", image.luminance);
    image.mapping = read_uv_mapping(t);
    return image;
  }

  // "uv_scale": [su, sv] (or one number for both) and "uv_offset": [du, dv].
  UVMapping read_uv_mapping(CheckedObject& t) const {
    UVMapping mapping;
    if (const Json* matrix = t.find("uv_matrix")) {
      // [[su, s_from_v, du], [t_from_u, sv, dv]]: any affine map (rotations, shears).
      const std::string pointer = t.pointer_of("uv_matrix");
      if (t.find("uv_scale") || t.find("uv_offset"))
        report_.fail(pointer, "give either uv_matrix or uv_scale / uv_offset, not both");
      if (!matrix->is_array() || matrix->size() != 2 || !(*matrix)[0].is_array() || (*matrix)[0].size() != 3 ||
          !(*matrix)[1].is_array() || (*matrix)[1].size() != 3)
        report_.fail(pointer, "expected [[su, s_from_v, du], [t_from_u, sv, dv]], got {}", describe(*matrix));
      float m[2][3];
      for (size_t r = 0; r < 2; ++r)
        for (size_t c = 0; c < 3; ++c)
          m[r][c] = read_float(report_, (*matrix)[r][c], fmt::format("{}/{}/{}", pointer, r, c));
      if (m[0][0] * m[1][1] - m[0][1] * m[1][0] == 0)
        report_.fail(pointer, "the uv matrix is singular (it maps the surface onto a line)");
      mapping = {m[0][0], m[1][1], m[0][2], m[1][2], m[0][1], m[1][0]};
      return mapping;
    }
    if (const Json* scale = t.find("uv_scale")) {
      std::string pointer = t.pointer_of("uv_scale");
      Vec2 s = scale->is_number() ? Vec2(read_float(report_, *scale, pointer), read_float(report_, *scale, pointer))
                                  : read_vec2(report_, *scale, pointer);
      if (s.x == 0 || s.y == 0) report_.fail(pointer, "uv_scale factors must be non-zero, got [{}, {}]", s.x, s.y);
      mapping.su = s.x;
      mapping.sv = s.y;
    }
    if (const Json* offset = t.find("uv_offset")) {
      Vec2 d = read_vec2(report_, *offset, t.pointer_of("uv_offset"));
      mapping.du = d.x;
      mapping.dv = d.y;
    }
    return mapping;
  }

  // A file named relative to the scene file's directory (as mesh files are). It must exist when the
  // scene is read, so that a typo is reported with its place in the scene file.
  std::string existing_file(CheckedObject& object, std::string_view key, std::string_view what) const {
    std::string name = object.string(key);
    std::string pointer = object.pointer_of(key);
    if (name.empty()) report_.fail(pointer, "the {} file name is empty", what);
    fs::path path = base_dir_ / name;
    std::error_code error;
    fs::file_status status = fs::status(path, error);
    if (status.type() == fs::file_type::not_found)
      report_.fail(pointer, "cannot read {} '{}': no such file", what, path.string());
    if (error) report_.fail(pointer, "cannot read {} '{}': {}", what, path.string(), error.message());
    if (status.type() == fs::file_type::directory)
      report_.fail(pointer, "cannot read {} '{}': it is a directory, not a file", what, path.string());
    return path.string();
  }

  // ---- material and texture parameters: a constant, a texture name, or an inline texture object

  ColorInput read_color_input(const Json& value, const std::string& pointer, ColorKind kind) {
    ColorInput input;
    if (value.is_string())
      input.texture = named_texture(value.get<std::string>(), pointer);
    else if (value.is_object())
      input.texture = add_texture(read_texture(value, pointer));
    else if (value.is_number() || value.is_array())
      input.value = read_rgb(report_, value, pointer, kind);
    else
      report_.fail(pointer,
                   "expected a colour, [r, g, b] or a single number, or a texture (a name or an object), got {}",
                   describe(value));
    return input;
  }

  ColorInput color_input_or(CheckedObject& object, std::string_view key, ColorKind kind, ColorInput fallback) {
    const Json* value = object.find(key);
    return value ? read_color_input(*value, object.pointer_of(key), kind) : fallback;
  }

  FloatInput read_float_input(const Json& value, const std::string& pointer, Bound bound) {
    FloatInput input;
    if (value.is_string())
      input.texture = named_texture(value.get<std::string>(), pointer);
    else if (value.is_object())
      input.texture = add_texture(read_texture(value, pointer));
    else if (value.is_number())
      input.value = check_bound(report_, read_float(report_, value, pointer), bound, pointer);
    else
      report_.fail(pointer, "expected a number or a texture (a name or an object), got {}", describe(value));
    return input;
  }

  FloatInput float_input_or(CheckedObject& object, std::string_view key, Bound bound, FloatInput fallback) {
    const Json* value = object.find(key);
    return value ? read_float_input(*value, object.pointer_of(key), bound) : fallback;
  }

  // ---- materials

  // Named materials may wrap (one_sided, mask, blend, normal_map, bump_map) materials named anywhere
  // in the file: each is read when first needed, after what it wraps, as named textures are.
  void read_materials(const Json& value, const std::string& pointer) {
    if (!value.is_object())
      report_.fail(pointer, "expected an object mapping material names to materials, got {}", describe(value));
    std::vector<std::string> names;  // in the file's order
    for (auto it = value.begin(); it != value.end(); ++it) {
      if (it.key() == "_comment") continue;
      names.push_back(it.key());
      named_materials_[it.key()] = NamedMaterial{&it.value(), child_pointer(pointer, it.key())};
    }
    for (const std::string& name : names) material_by_name(name, named_materials_[name].pointer);
  }

  struct NamedMaterial {
    const Json* value = nullptr;
    std::string pointer;
    bool reading = false;
    int index = -1;
  };

  int add_material(MaterialDesc material) {
    scene_.materials.push_back(std::move(material));
    return int(scene_.materials.size()) - 1;
  }

  MaterialDesc read_material(const Json& value, const std::string& pointer) {
    CheckedObject m(report_, value, pointer);
    std::string type = m.string("type");
    MaterialDesc material;
    if (type == "diffuse")
      material = DiffuseMaterial{color_input_or(m, "reflectance", ColorKind::Albedo, DiffuseMaterial{}.reflectance)};
    else if (type == "phong")
      material = read_phong(m);
    else if (type == "mirror")
      material = MirrorMaterial{color_input_or(m, "reflectance", ColorKind::Albedo, MirrorMaterial{}.reflectance)};
    else if (type == "conductor")
      material = read_conductor(m);
    else if (type == "dielectric" || type == "glass")
      material = read_dielectric(m);
    else if (type == "coated_diffuse" || type == "plastic")
      material = read_coated_diffuse(m);
    else if (type == "diffuse_transmission")
      material = read_diffuse_transmission(m);
    else if (type == "interface" || type == "null")
      material = InterfaceMaterial{};
    else if (type == "black")
      material = BlackMaterial{};
    else if (type == "principled")
      material = read_principled(m);
    else if (type == "one_sided")
      material = OneSidedMaterial{wrapped_material(m, "material")};
    else if (type == "two_sided")
      material = TwoSidedMaterial{wrapped_material(m, "front"), wrapped_material(m, "back")};
    else if (type == "mask") {
      MaskMaterial mask;
      mask.opacity = float_input_or(m, "opacity", Bound::UnitInterval, mask.opacity);
      mask.material = wrapped_material(m, "material");
      material = mask;
    } else if (type == "blend")
      material = read_blend(m);
    else if (type == "normal_map") {
      NormalMapMaterial map;
      map.normal_map = texture_reference(m, "normal_map");
      map.material = wrapped_material(m, "material");
      map.options = read_perturbed_normal_options(m);
      material = map;
    } else if (type == "bump_map") {
      BumpMapMaterial map;
      map.height = texture_reference(m, "height");
      map.scale = m.number_or("scale", map.scale);
      map.material = wrapped_material(m, "material");
      map.options = read_perturbed_normal_options(m);
      material = map;
    } else
      report_.fail(m.pointer_of("type"),
                   "unknown material type \"{}\"; expected one of: diffuse, phong, mirror, conductor, dielectric, "
                   "glass, coated_diffuse, plastic, diffuse_transmission, interface, null, black, principled, "
                   "one_sided, two_sided, mask, blend, normal_map, bump_map",
                   type);
    m.finish();
    return material;
  }

  PhongMaterial read_phong(CheckedObject& m) {
    PhongMaterial p;
    p.diffuse = color_input_or(m, "diffuse", ColorKind::Albedo, p.diffuse);
    p.specular = color_input_or(m, "specular", ColorKind::Albedo, p.specular);
    p.exponent = m.number_or("exponent", p.exponent, Bound::NonNegative);
    p.transmission = color_input_or(m, "transmission", ColorKind::Albedo, p.transmission);
    p.ior = m.number_or("ior", p.ior, Bound::Positive);
    p.d = m.number_or("d", p.d, Bound::UnitInterval);
    p.s = m.number_or("s", p.s, Bound::UnitInterval);
    p.t = m.number_or("t", p.t, Bound::UnitInterval);
    // The probabilities of Russian roulette's diffuse, specular and transmitted choices.
    double sum = double(p.d) + p.s + p.t;
    if (sum > 1 + 1e-6)
      report_.fail(m.pointer(), "d + s + t must be <= 1 (the rest is absorbed), got {} + {} + {} = {}", p.d, p.s, p.t,
                   float(sum));
    return p;
  }

  // GGX alpha (Roughness::remap = false): "roughness" for both axes, or "alpha_u" and "alpha_v".
  Roughness read_roughness(CheckedObject& m) {
    Roughness roughness;
    roughness.remap = false;
    const Json* isotropic = m.find("roughness");
    const Json* alpha_u = m.find("alpha_u");
    const Json* alpha_v = m.find("alpha_v");
    if (isotropic && (alpha_u || alpha_v))
      report_.fail(m.pointer_of(alpha_u ? "alpha_u" : "alpha_v"),
                   "give either \"roughness\" or \"alpha_u\" and \"alpha_v\", not both");
    if (bool(alpha_u) != bool(alpha_v))
      report_.fail(m.pointer(), "missing required key \"{}\" (an anisotropic roughness needs alpha_u and alpha_v)",
                   alpha_u ? "alpha_v" : "alpha_u");
    if (isotropic) {
      roughness.u = roughness.v = read_float_input(*isotropic, m.pointer_of("roughness"), Bound::NonNegative);
    } else if (alpha_u) {
      roughness.u = read_float_input(*alpha_u, m.pointer_of("alpha_u"), Bound::NonNegative);
      roughness.v = read_float_input(*alpha_v, m.pointer_of("alpha_v"), Bound::NonNegative);
    }
    // pbrt-v4's remaproughness: the values are pbrt's "roughness", alpha = sqrt(roughness).
    roughness.remap = m.boolean_or("remap_roughness", false);
    if (const Json* distribution = m.find("distribution"))
      roughness.distribution = read_name<MicrofacetDistribution>(
          report_, *distribution, m.pointer_of("distribution"), "microfacet distribution",
          {{"ggx", MicrofacetDistribution::GGX},
           {"ggx_separable", MicrofacetDistribution::GGXSeparable},
           {"beckmann", MicrofacetDistribution::Beckmann}});
    return roughness;
  }

  // eta and k (default copper), or a named metal's, or the artist-friendly normal-incidence reflectance.
  ConductorMaterial read_conductor(CheckedObject& m) {
    ConductorMaterial c;
    bool has_ior = m.has("eta") || m.has("k");
    if (int(has_ior) + int(m.has("reflectance")) + int(m.has("metal")) > 1)
      report_.fail(m.pointer(), "a conductor takes only one of: \"eta\"/\"k\", \"reflectance\", \"metal\"");
    if (const Json* metal = m.find("metal")) {
      ComplexIor preset = read_metal(*metal, m.pointer_of("metal"));
      c.eta = preset.eta;
      c.k = preset.k;
    }
    if (const Json* eta = m.find("eta")) {
      c.eta = read_color_input(*eta, m.pointer_of("eta"), ColorKind::NonNegative);
      check_positive_color(c.eta, *eta, m.pointer_of("eta"));
    }
    c.k = color_input_or(m, "k", ColorKind::NonNegative, c.k);
    if (const Json* reflectance = m.find("reflectance"))
      c.reflectance = read_color_input(*reflectance, m.pointer_of("reflectance"), ColorKind::Albedo);
    c.specular_tint = color_input_or(m, "specular_tint", ColorKind::Albedo, c.specular_tint);
    c.roughness = read_roughness(m);
    return c;
  }

  ComplexIor read_metal(const Json& value, const std::string& pointer) const {
    std::string name = read_string(report_, value, pointer);
    if (std::optional<ComplexIor> preset = find_metal(name)) return *preset;
    report_.fail(pointer, "unknown metal \"{}\"; expected one of: {}", name, fmt::join(metal_names(), ", "));
  }

  // A conductor's eta must be >= 0 in each channel (0 with k > 0 is a perfect mirror, Mitsuba's
  // "none"); constants only, textures are not checked.
  void check_positive_color(const ColorInput& input, const Json& value, const std::string& pointer) const {
    if (!input.is_constant()) return;
    for (int i = 0; i < 3; ++i)
      if (!(input.value[i] >= 0))
        report_.fail(value.is_array() ? child_pointer(pointer, size_t(i)) : pointer,
                     "an index of refraction must be >= 0 in each channel, got {}", input.value[i]);
  }

  DielectricMaterial read_dielectric(CheckedObject& m) {
    DielectricMaterial d;
    d.ior = m.number_or("ior", d.ior, Bound::Positive);
    d.reflectance = color_input_or(m, "reflectance", ColorKind::Albedo, d.reflectance);
    d.transmittance = color_input_or(m, "transmittance", ColorKind::Albedo, d.transmittance);
    d.roughness = read_roughness(m);
    d.thin = m.boolean_or("thin", d.thin);
    return d;
  }

  CoatedDiffuseMaterial read_coated_diffuse(CheckedObject& m) {
    CoatedDiffuseMaterial c;
    c.reflectance = color_input_or(m, "reflectance", ColorKind::Albedo, c.reflectance);
    c.specular = color_input_or(m, "specular", ColorKind::Albedo, c.specular);
    c.ior = m.number_or("ior", c.ior, Bound::Positive);
    c.roughness = read_roughness(m);
    c.nonlinear = m.boolean_or("nonlinear", c.nonlinear);
    c.tabulated_coat = m.boolean_or("tabulated_coat", c.tabulated_coat);
    if (c.tabulated_coat && !(c.roughness.u.is_constant() && c.roughness.v.is_constant()))
      m.report().fail(m.pointer_of("tabulated_coat"), "a tabulated coat needs a constant roughness");
    return c;
  }

  DiffuseTransmissionMaterial read_diffuse_transmission(CheckedObject& m) {
    static constexpr const char* kChannelNames[] = {"red", "green", "blue"};
    DiffuseTransmissionMaterial d;
    d.reflectance = color_input_or(m, "reflectance", ColorKind::Albedo, d.reflectance);
    d.transmittance = color_input_or(m, "transmittance", ColorKind::Albedo, d.transmittance);
    // Together they may not exceed 1 (checked for constants; textures are the scene's responsibility).
    if (d.reflectance.is_constant() && d.transmittance.is_constant())
      for (int i = 0; i < 3; ++i)
        if (double(d.reflectance.value[i]) + d.transmittance.value[i] > 1 + 1e-6)
          report_.fail(m.pointer(),
                       "reflectance + transmittance must be <= 1 in each channel (more would create energy), got "
                       "{} + {} in the {} channel",
                       d.reflectance.value[i], d.transmittance.value[i], kChannelNames[i]);
    return d;
  }

  int material_by_name(const std::string& name, const std::string& pointer) {
    auto it = named_materials_.find(name);
    if (it == named_materials_.end()) {
      std::vector<std::string> names;
      for (const auto& entry : named_materials_) names.push_back(entry.first);
      if (names.empty()) report_.fail(pointer, "unknown material \"{}\" (\"materials\" defines none)", name);
      report_.fail(pointer, "unknown material \"{}\"; defined: {}", name, fmt::join(names, ", "));
    }
    NamedMaterial& material = it->second;
    if (material.index >= 0) return material.index;
    if (material.reading) report_.fail(pointer, "material \"{}\" wraps itself (a cycle of wrapping materials)", name);
    material.reading = true;
    MaterialDesc desc = read_material(*material.value, material.pointer);
    material.reading = false;
    material.index = add_material(std::move(desc));
    return material.index;
  }

  // The material a wrapper wraps: a name or an inline material object, read (and added) before it.
  int wrapped_material(CheckedObject& m, std::string_view key) {
    const Json& value = m.require(key);
    std::string pointer = m.pointer_of(key);
    int index = -1;
    if (value.is_string()) index = material_by_name(value.get<std::string>(), pointer);
    else if (value.is_object()) index = add_material(read_material(value, pointer));
    else report_.fail(pointer, "expected a material name or a material object, got {}", describe(value));
    if (std::holds_alternative<TwoSidedMaterial>(scene_.materials[size_t(index)]))
      report_.fail(pointer, "a two_sided material cannot be wrapped (it picks its side per hit, so it must be outermost)");
    return index;
  }

  // A texture given by name or inline object (not a constant): normal and bump maps.
  int texture_reference(CheckedObject& m, std::string_view key) {
    const Json& value = m.require(key);
    std::string pointer = m.pointer_of(key);
    if (value.is_string()) return named_texture(value.get<std::string>(), pointer);
    if (value.is_object()) return add_texture(read_texture(value, pointer));
    report_.fail(pointer, "expected a texture (a name or an object), got {}", describe(value));
  }

  PrincipledMaterial read_principled(CheckedObject& m) {
    PrincipledMaterial p;
    p.base_color = color_input_or(m, "base_color", ColorKind::Albedo, p.base_color);
    auto unit = [&](std::string_view key, FloatInput& input) { input = float_input_or(m, key, Bound::UnitInterval, input); };
    unit("roughness", p.roughness);
    unit("metallic", p.metallic);
    unit("specular", p.specular);
    unit("specular_tint", p.specular_tint);
    unit("anisotropic", p.anisotropic);
    unit("sheen", p.sheen);
    unit("sheen_tint", p.sheen_tint);
    unit("clearcoat", p.clearcoat);
    unit("clearcoat_gloss", p.clearcoat_gloss);
    unit("spec_trans", p.spec_trans);
    if (m.has("eta")) {
      p.eta = m.number("eta", Bound::Positive);
      p.eta_given = true;
    }
    p.thin = m.boolean_or("thin", p.thin);
    unit("diff_trans", p.diff_trans);
    unit("flatness", p.flatness);
    return p;
  }

  static PerturbedNormalOptions read_perturbed_normal_options(CheckedObject& m) {
    PerturbedNormalOptions o;
    o.flip_invalid_normals = m.boolean_or("flip_invalid_normals", o.flip_invalid_normals);
    o.shadowing_function = m.boolean_or("shadowing_function", o.shadowing_function);
    return o;
  }

  BlendMaterial read_blend(CheckedObject& m) {
    BlendMaterial b;
    b.weight = float_input_or(m, "weight", Bound::UnitInterval, b.weight);
    const Json& list = m.require("materials");
    std::string pointer = m.pointer_of("materials");
    if (!list.is_array() || list.size() != 2)
      report_.fail(pointer, "expected two materials [weight 0, weight 1], got {}", describe(list));
    int index[2];
    for (size_t i = 0; i < 2; ++i) {
      std::string item = child_pointer(pointer, i);
      if (list[i].is_string()) index[i] = material_by_name(list[i].get<std::string>(), item);
      else if (list[i].is_object()) index[i] = add_material(read_material(list[i], item));
      else report_.fail(item, "expected a material name or a material object, got {}", describe(list[i]));
    }
    b.material0 = index[0];
    b.material1 = index[1];
    return b;
  }

  int black_material() {
    if (!black_material_) black_material_ = add_material(BlackMaterial{});
    return *black_material_;
  }

  // ---- shapes

  void read_shapes(const Json& value, const std::string& pointer) {
    check_is_array(report_, value, pointer, "shapes");
    for (size_t i = 0; i < value.size(); ++i) {
      if (is_instance(value[i]))
        scene_.instances.push_back(read_instance(value[i], child_pointer(pointer, i)));
      else
        scene_.shapes.push_back(read_shape(value[i], child_pointer(pointer, i)));
    }
  }

  ShapeDesc read_shape(const Json& value, const std::string& pointer) {
    CheckedObject s(report_, value, pointer);
    ShapeDesc shape;
    shape.geometry = read_geometry(s);
    shape.material = read_shape_material(s);
    if (const Json* emission = s.find("emission")) shape.emission = read_emission(*emission, s.pointer_of("emission"));
    if (shape.emission && std::holds_alternative<SdfGridShape>(shape.geometry))
      report_.fail(s.pointer_of("emission"), "an sdfgrid cannot emit light (as in Mitsuba: it has no area to sample)");
    shape.to_world = read_transform_key(s);
    if (const Json* end = s.find("transform_end")) shape.to_world_end = read_moving_transform(*end, s, shape);
    shape.name = s.string_or("name", "");
    shape.reverse_orientation = s.boolean_or("reverse_orientation", false);
    s.finish();
    return shape;
  }

  ShapeGeometry read_geometry(CheckedObject& s) {
    std::string type = s.string("type");
    if (type == "sphere") return read_sphere(s);
    if (type == "plane") return PlaneShape{s.vec3("point"), normalize(s.direction("normal"))};
    if (type == "box") return read_box(s);
    if (type == "rectangle") return read_rectangle(s);
    if (type == "mesh") return read_mesh(s);
    if (type == "disk") return DiskShape{};
    if (type == "cylinder") {
      CylinderShape c{s.vec3_or("p0", {0, 0, 0}), s.vec3_or("p1", {0, 0, 1}), s.number_or("radius", 1, Bound::Positive)};
      if (length_squared(c.p1 - c.p0) == 0) report_.fail(s.pointer_of("p1"), "p1 must differ from p0 (the axis)");
      return c;
    }
    if (type == "sdfgrid") return read_sdf_grid(s);
    report_.fail(s.pointer_of("type"),
                 "unknown shape type \"{}\"; expected one of: sphere, plane, box, rectangle, mesh, disk, cylinder, "
                 "sdfgrid, instance",
                 type);
  }

  // A Mitsuba .vol file, or the samples inline (as `candela convert` writes a grid made in memory).
  SdfGridShape read_sdf_grid(CheckedObject& s) const {
    const std::string normals = s.string_or("normals", "smooth");
    if (normals != "smooth" && normals != "analytic")
      report_.fail(s.pointer_of("normals"), "expected \"smooth\" or \"analytic\", got \"{}\"", normals);
    const SdfNormals mode = normals == "smooth" ? SdfNormals::Smooth : SdfNormals::Analytic;
    const bool from_file = s.has("filename"), inline_data = s.has("values") || s.has("resolution");
    if (from_file == inline_data)
      report_.fail(s.pointer(), "an sdfgrid takes either \"filename\" or inline \"resolution\" and \"values\", {}",
                   from_file ? "not both" : "and has neither");
    if (from_file)
      return read_sdf_grid_file(existing_file(s, "filename", "SDF grid"), report_.location(s.pointer_of("filename")),
                                mode);
    SdfGridShape grid;
    grid.normals = mode;
    const Json& resolution = s.require("resolution");
    const std::string resolution_pointer = s.pointer_of("resolution");
    if (!resolution.is_array() || resolution.size() != 3)
      report_.fail(resolution_pointer, "expected an array of 3 integers, got {}", describe(resolution));
    for (size_t i = 0; i < 3; ++i) {
      const int64_t n = read_int64(report_, resolution[i], child_pointer(resolution_pointer, i));
      if (n < 2 || n > std::numeric_limits<int>::max())
        report_.fail(child_pointer(resolution_pointer, i), "expected an integer >= 2 (a voxel needs 2 samples), got {}", n);
      grid.resolution[i] = int(n);
    }
    const Json& values = s.require("values");
    const std::string values_pointer = s.pointer_of("values");
    check_is_array(report_, values, values_pointer, "SDF values");
    const double expected = double(grid.resolution[0]) * grid.resolution[1] * grid.resolution[2];
    if (double(values.size()) != expected)
      report_.fail(values_pointer, "expected {} values (x fastest, then y, then z), got {}", expected, values.size());
    std::vector<float> samples(values.size());
    for (size_t k = 0; k < values.size(); ++k) samples[k] = read_float_element(report_, values, k, values_pointer);
    grid.values = std::make_shared<const std::vector<float>>(std::move(samples));
    if (std::string problem = sdf_grid_problem(grid); !problem.empty()) report_.fail(s.pointer(), "{}", problem);
    return grid;
  }

  static SphereShape read_sphere(CheckedObject& s) { return {s.vec3("center"), s.number("radius", Bound::Positive)}; }

  BoxShape read_box(CheckedObject& s) const {
    BoxShape box{s.vec3("min"), s.vec3("max")};
    for (int axis = 0; axis < 3; ++axis)
      if (!(box.lo[axis] < box.hi[axis]))
        report_.fail(s.pointer_of("max"), "max must exceed min on every axis; on axis {} min is {} and max is {}",
                     "xyz"[axis], box.lo[axis], box.hi[axis]);
    return box;
  }

  RectangleShape read_rectangle(CheckedObject& s) const {
    RectangleShape r{s.vec3("corner"), s.direction("edge_u"), s.direction("edge_v")};
    if (length(cross(r.edge_u, r.edge_v)) <= 1e-6f * length(r.edge_u) * length(r.edge_v))
      report_.fail(s.pointer_of("edge_v"), "edge_u and edge_v are parallel, so the rectangle has no area");
    return r;
  }

  int read_shape_material(CheckedObject& s) {
    const Json* material = s.find("material");
    if (!material) return -1;  // the default diffuse 0.5
    std::string pointer = s.pointer_of("material");
    if (material->is_string()) return material_by_name(material->get<std::string>(), pointer);
    if (material->is_object()) return add_material(read_material(*material, pointer));
    report_.fail(pointer, "expected a material name or a material object, got {}", describe(*material));
  }

  AreaEmission read_emission(const Json& value, const std::string& pointer) {
    CheckedObject e(report_, value, pointer);
    AreaEmission emission{e.rgb("radiance", ColorKind::Emission), e.boolean_or("two_sided", false)};
    if (e.has("texture")) emission.texture = texture_reference(e, "texture");
    e.finish();
    return emission;
  }

  // ---- objects and instances

  static bool is_instance(const Json& shape) {
    if (!shape.is_object()) return false;
    auto type = shape.find("type");
    return type != shape.end() && *type == "instance";
  }

  void read_objects(const Json& value, const std::string& pointer) {
    if (!value.is_object())
      report_.fail(pointer, "expected an object mapping object names to objects, got {}", describe(value));
    for (auto it = value.begin(); it != value.end(); ++it) {
      if (it.key() == "_comment") continue;
      ObjectDesc object = read_object(it.value(), child_pointer(pointer, it.key()));
      object.name = it.key();
      object_index_[it.key()] = int(scene_.objects.size());
      scene_.objects.push_back(std::move(object));
    }
  }

  // An object's shapes are in its own space; they may not emit, move or be instances themselves.
  ObjectDesc read_object(const Json& value, const std::string& pointer) {
    CheckedObject o(report_, value, pointer);
    const Json& shapes = o.require("shapes");
    std::string shapes_pointer = o.pointer_of("shapes");
    check_is_array(report_, shapes, shapes_pointer, "shapes");
    if (shapes.empty()) report_.fail(shapes_pointer, "an object needs at least one shape");
    ObjectDesc object;
    for (size_t i = 0; i < shapes.size(); ++i) {
      std::string shape_pointer = child_pointer(shapes_pointer, i);
      if (is_instance(shapes[i]))
        report_.fail(child_pointer(shape_pointer, "type"), "an object cannot contain instances (objects do not nest)");
      ShapeDesc shape = read_shape(shapes[i], shape_pointer);
      if (shape.emission)
        report_.fail(child_pointer(shape_pointer, "emission"),
                     "a shape in an object cannot emit light (instanced area lights are not supported); put it in "
                     "the top-level \"shapes\"");
      if (shape.to_world_end)
        report_.fail(child_pointer(shape_pointer, "transform_end"),
                     "a shape in an object cannot move; give the instance a transform_end instead");
      object.shapes.push_back(std::move(shape));
    }
    o.finish();
    return object;
  }

  InstanceDesc read_instance(const Json& value, const std::string& pointer) const {
    CheckedObject s(report_, value, pointer);
    s.string("type");
    InstanceDesc instance;
    instance.object = object_by_name(s.string("object"), s.pointer_of("object"));
    instance.to_world = read_transform_key(s);
    if (const Json* end = s.find("transform_end")) {
      const ObjectDesc& object = scene_.objects[size_t(instance.object)];
      for (const ShapeDesc& shape : object.shapes)
        if (std::holds_alternative<PlaneShape>(shape.geometry))
          report_.fail(s.pointer_of("transform_end"),
                       "an infinite plane must not move: object \"{}\" contains one, so its instances cannot have "
                       "transform_end",
                       object.name);
      instance.to_world_end = read_transform(*end, s.pointer_of("transform_end"));
    }
    s.finish();
    return instance;
  }

  int object_by_name(const std::string& name, const std::string& pointer) const {
    auto it = object_index_.find(name);
    if (it != object_index_.end()) return it->second;
    std::vector<std::string> names;
    for (const auto& entry : object_index_) names.push_back(entry.first);
    if (names.empty()) report_.fail(pointer, "unknown object \"{}\" (\"objects\" defines none)", name);
    report_.fail(pointer, "unknown object \"{}\"; defined: {}", name, fmt::join(names, ", "));
  }

  // ---- meshes

  MeshShape read_mesh(CheckedObject& s) const {
    bool from_file = s.has("file"), inline_data = s.has("positions");
    if (from_file && inline_data)
      report_.fail(s.pointer(), "a mesh takes either \"file\" or inline \"positions\", not both");
    if (from_file) return {read_mesh_file(s)};
    if (!inline_data) report_.fail(s.pointer(), "a mesh needs either \"file\" or inline \"positions\"");
    return {read_inline_mesh(s)};
  }

  TriangleMesh read_mesh_file(CheckedObject& s) const {
    for (std::string_view key : {"indices", "normals", "uvs", "attributes"})
      if (s.has(key)) report_.fail(s.pointer_of(key), "inline mesh data cannot be combined with \"file\"");
    std::string file = s.string("file");
    if (file.empty()) report_.fail(s.pointer_of("file"), "the mesh file name is empty");
    return load_mesh_file(base_dir_ / file, report_.location(s.pointer_of("file")));
  }

  TriangleMesh read_inline_mesh(CheckedObject& s) const {
    TriangleMesh mesh;
    mesh.positions = read_vec3_list(s.require("positions"), s.pointer_of("positions"), "positions [x, y, z]");
    if (mesh.positions.size() < 3)
      report_.fail(s.pointer_of("positions"), "a mesh needs at least 3 positions, got {}", mesh.positions.size());
    if (const Json* indices = s.find("indices"))
      mesh.indices = read_indices(*indices, s.pointer_of("indices"), mesh.positions.size());
    else if (mesh.positions.size() == 3)
      mesh.indices = {0, 1, 2};
    else
      report_.fail(s.pointer(),
                   "missing required key \"indices\" (only a single triangle of 3 positions may leave it out)");
    if (const Json* normals = s.find("normals")) {
      mesh.normals = read_vec3_list(*normals, s.pointer_of("normals"), "normals [x, y, z]");
      check_per_vertex_count(mesh.normals.size(), mesh.positions.size(), s.pointer_of("normals"));
      check_nonzero_normals(mesh.normals, s.pointer_of("normals"));
    }
    if (const Json* uvs = s.find("uvs")) {
      mesh.uvs = read_vec2_list(*uvs, s.pointer_of("uvs"));
      check_per_vertex_count(mesh.uvs.size(), mesh.positions.size(), s.pointer_of("uvs"));
    }
    if (const Json* attributes = s.find("attributes")) read_mesh_attributes(*attributes, s.pointer_of("attributes"), mesh);
    return mesh;
  }

  // [{"name": ..., "per_face": bool, "channels": 1 or 3, "values": [...]}, ...]
  void read_mesh_attributes(const Json& value, const std::string& pointer, TriangleMesh& mesh) const {
    check_is_array(report_, value, pointer, "mesh attributes");
    for (size_t i = 0; i < value.size(); ++i) {
      CheckedObject a(report_, value[i], child_pointer(pointer, i));
      TriangleMesh::Attribute attribute;
      attribute.name = a.string("name");
      attribute.per_face = a.boolean_or("per_face", false);
      attribute.channels = a.integer_or("channels", 1, 1, 3);
      if (attribute.channels == 2) report_.fail(a.pointer_of("channels"), "an attribute has 1 or 3 channels, got 2");
      const Json& values = a.require("values");
      check_is_array(report_, values, a.pointer_of("values"), "attribute values");
      size_t count = attribute.per_face ? mesh.triangle_count() : mesh.positions.size();
      if (values.size() != count * size_t(attribute.channels))
        report_.fail(a.pointer_of("values"), "expected {} values ({} per {}), got {}", count * attribute.channels,
                     attribute.channels, attribute.per_face ? "triangle" : "position", values.size());
      attribute.values.reserve(values.size());
      for (size_t k = 0; k < values.size(); ++k)
        attribute.values.push_back(read_float(report_, values[k], child_pointer(a.pointer_of("values"), k)));
      a.finish();
      mesh.attributes.push_back(std::move(attribute));
    }
  }

  std::vector<Vec3> read_vec3_list(const Json& value, const std::string& pointer, std::string_view of_what) const {
    check_is_array(report_, value, pointer, of_what);
    std::vector<Vec3> list;
    list.reserve(value.size());
    for (size_t i = 0; i < value.size(); ++i) list.push_back(read_vec3(report_, value[i], child_pointer(pointer, i)));
    return list;
  }

  std::vector<Vec2> read_vec2_list(const Json& value, const std::string& pointer) const {
    check_is_array(report_, value, pointer, "uvs [u, v]");
    std::vector<Vec2> list;
    list.reserve(value.size());
    for (size_t i = 0; i < value.size(); ++i) list.push_back(read_vec2(report_, value[i], child_pointer(pointer, i)));
    return list;
  }

  std::vector<uint32_t> read_indices(const Json& value, const std::string& pointer, size_t vertex_count) const {
    check_is_array(report_, value, pointer, "vertex indices");
    if (value.empty() || value.size() % 3 != 0)
      report_.fail(pointer, "expected a non-zero multiple of 3 indices (three per triangle), got {}", value.size());
    std::vector<uint32_t> indices;
    indices.reserve(value.size());
    for (size_t i = 0; i < value.size(); ++i) {
      int64_t index = read_int64(report_, value[i], child_pointer(pointer, i));
      if (index < 0 || uint64_t(index) >= vertex_count)
        report_.fail(child_pointer(pointer, i), "index {} is out of range: the mesh has {} positions", index,
                     vertex_count);
      indices.push_back(uint32_t(index));
    }
    return indices;
  }

  void check_per_vertex_count(size_t count, size_t vertex_count, const std::string& pointer) const {
    if (count != vertex_count)
      report_.fail(pointer, "expected one entry per position ({}), got {}", vertex_count, count);
  }

  void check_nonzero_normals(const std::vector<Normal3>& normals, const std::string& pointer) const {
    for (size_t i = 0; i < normals.size(); ++i)
      if (length_squared(normals[i]) == 0) report_.fail(child_pointer(pointer, i), "a normal must be non-zero");
  }

  // ---- transforms

  // A moving shape's transform at the end time (render.transform_times); lights and infinite planes
  // cannot move.
  Transform read_moving_transform(const Json& value, CheckedObject& s, const ShapeDesc& shape) const {
    std::string pointer = s.pointer_of("transform_end");
    if (shape.emission) report_.fail(pointer, "area lights must not move: an emissive shape cannot have transform_end");
    if (std::holds_alternative<PlaneShape>(shape.geometry))
      report_.fail(pointer, "an infinite plane must not move: it cannot have transform_end");
    return read_transform(value, pointer);
  }

  Transform read_transform_key(CheckedObject& object) const {
    const Json* steps = object.find("transform");
    return steps ? read_transform(*steps, object.pointer_of("transform")) : Transform();
  }

  // Steps apply in the order listed: the first one acts on the object first.
  Transform read_transform(const Json& value, const std::string& pointer) const {
    check_is_array(report_, value, pointer, "transform steps such as {\"translate\": [x, y, z]}");
    Transform to_world;
    for (size_t i = 0; i < value.size(); ++i)
      to_world = read_transform_step(value[i], child_pointer(pointer, i)) * to_world;
    return to_world;
  }

  Transform read_transform_step(const Json& value, const std::string& pointer) const {
    CheckedObject step(report_, value, pointer);
    std::vector<std::string_view> operations;
    for (std::string_view op : {"translate", "rotate", "scale", "matrix"})
      if (step.has(op)) operations.push_back(op);
    if (operations.size() != 1) {
      step.finish();  // a misspelt operation is best reported as such
      report_.fail(pointer, "a transform step needs exactly one of: translate, rotate, scale, matrix; got {}",
                   operations.empty() ? std::string("none") : fmt::format("{}", fmt::join(operations, ", ")));
    }
    Transform transform;
    std::string op_pointer = step.pointer_of(operations[0]);
    if (operations[0] == "translate")
      transform = Transform::translate(step.vec3("translate"));
    else if (operations[0] == "rotate")
      transform = read_rotation(step.require("rotate"), op_pointer);
    else if (operations[0] == "scale")
      transform = read_scale(step.require("scale"), op_pointer);
    else
      transform = read_matrix(step.require("matrix"), op_pointer);
    step.finish();
    return transform;
  }

  Transform read_rotation(const Json& value, const std::string& pointer) const {
    CheckedObject rotation(report_, value, pointer);
    float degrees = rotation.number("angle");
    Vec3 axis = rotation.direction("axis");
    rotation.finish();
    return Transform::rotate(degrees, axis);
  }

  Transform read_scale(const Json& value, const std::string& pointer) const {
    Vec3 factors = value.is_number() ? Vec3(read_float(report_, value, pointer)) : read_vec3(report_, value, pointer);
    if (factors.x == 0 || factors.y == 0 || factors.z == 0)
      report_.fail(pointer, "scale factors must be non-zero, got [{}, {}, {}]", factors.x, factors.y, factors.z);
    return Transform::scale(factors);
  }

  Transform read_matrix(const Json& value, const std::string& pointer) const {
    if (!value.is_array() || value.size() != 16)
      report_.fail(pointer, "expected 16 numbers (a 4x4 matrix, row by row), got {}", describe(value));
    Matrix4 m;
    for (size_t i = 0; i < 16; ++i) m.m[i / 4][i % 4] = read_double(report_, value[i], child_pointer(pointer, i));
    // Normals, bounds and instancing assume affine maps: no projective bottom row.
    if (m.m[3][0] != 0 || m.m[3][1] != 0 || m.m[3][2] != 0 || m.m[3][3] != 1)
      report_.fail(pointer, "the matrix must be affine: its last row must be [0, 0, 0, 1]");
    std::optional<Transform> transform = Transform::from_matrix(m);
    if (!transform) report_.fail(pointer, "the matrix is singular (not invertible)");
    return *transform;
  }

  // ---- lights

  void read_lights(const Json& value, const std::string& pointer) {
    check_is_array(report_, value, pointer, "lights");
    for (size_t i = 0; i < value.size(); ++i) read_light(value[i], child_pointer(pointer, i));
  }

  void read_light(const Json& value, const std::string& pointer) {
    CheckedObject light(report_, value, pointer);
    std::string type = light.string("type");
    if (type == "point")
      scene_.lights.push_back(PointLight{light.vec3("position"), light.rgb("intensity", ColorKind::Emission)});
    else if (type == "spot")
      scene_.lights.push_back(read_spot(light));
    else if (type == "distant")
      scene_.lights.push_back(
          DistantLight{normalize(light.direction("direction")), light.rgb("radiance", ColorKind::Emission)});
    else if (type == "sky")
      scene_.lights.push_back(read_sky(light));
    else if (type == "environment")
      scene_.lights.push_back(read_environment(light));
    else if (type == "sphere")
      scene_.shapes.push_back(read_shape_light(light, read_sphere(light)));
    else if (type == "rectangle")
      scene_.shapes.push_back(read_shape_light(light, read_rectangle(light)));
    else if (type == "projector")
      scene_.lights.push_back(read_projector(light));
    else
      report_.fail(light.pointer_of("type"),
                   "unknown light type \"{}\"; expected one of: point, spot, distant, sky, environment, sphere, "
                   "rectangle, projector",
                   type);
    light.finish();
  }

  // Sphere and rectangle lights are emitting shapes that reflect nothing.
  ShapeDesc read_shape_light(CheckedObject& light, ShapeGeometry geometry) {
    ShapeDesc shape;
    shape.geometry = std::move(geometry);
    shape.material = black_material();
    shape.emission = AreaEmission{light.rgb("radiance", ColorKind::Emission), light.boolean_or("two_sided", false)};
    shape.to_world = read_transform_key(light);
    return shape;
  }

  // Either one constant "radiance", or a gradient where a missing horizon takes the zenith's value,
  // a missing zenith the horizon's, and a missing ground the horizon's.
  SkyLight read_sky(CheckedObject& light) const {
    SkyLight sky;
    bool constant = light.has("radiance");
    std::optional<RGB> zenith = light.optional_rgb("zenith", ColorKind::Emission);
    std::optional<RGB> horizon = light.optional_rgb("horizon", ColorKind::Emission);
    std::optional<RGB> ground = light.optional_rgb("ground", ColorKind::Emission);
    if (constant && (zenith || horizon || ground))
      report_.fail(light.pointer(), "a sky takes either \"radiance\" or \"zenith\"/\"horizon\"/\"ground\", not both");
    if (constant) {
      sky.zenith = sky.horizon = sky.ground = light.rgb("radiance", ColorKind::Emission);
    } else {
      if (!zenith && !horizon)
        report_.fail(light.pointer(), "a sky needs \"radiance\", or a gradient with \"zenith\" and/or \"horizon\"");
      sky.zenith = zenith.value_or(horizon.value_or(RGB()));
      sky.horizon = horizon.value_or(sky.zenith);
      sky.ground = ground.value_or(sky.horizon);
    }
    sky.up = normalize(light.direction_or("up", sky.up));
    return sky;
  }

  // Mitsuba's projector: an image projected from the origin of "transform" along its +z.
  ProjectorLight read_projector(CheckedObject& light) {
    ProjectorLight projector;
    projector.to_world = read_transform_key(light);
    projector.fov_degrees = light.number_or("fov", projector.fov_degrees);
    if (!(projector.fov_degrees > 0 && projector.fov_degrees < 180))
      report_.fail(light.pointer_of("fov"), "the field of view must be in (0, 180) degrees, got {}",
                   projector.fov_degrees);
    projector.irradiance = texture_reference(light, "irradiance");
    projector.scale = light.rgb_or("scale", ColorKind::Emission, projector.scale);
    return projector;
  }

  SpotLight read_spot(CheckedObject& light) {
    SpotLight spot;
    spot.position = light.vec3("position");
    bool has_direction = light.has("direction"), has_look_at = light.has("look_at");
    if (has_direction && has_look_at)
      report_.fail(light.pointer_of("look_at"), "a spot light takes either \"direction\" or \"look_at\", not both");
    if (has_direction) {
      spot.direction = normalize(light.direction("direction"));
    } else if (has_look_at) {
      Vec3 direction = light.vec3("look_at") - spot.position;
      if (length_squared(direction) == 0 || !is_finite(normalize(direction)))
        report_.fail(light.pointer_of("look_at"), "look_at must differ from position (it sets the light's direction)");
      spot.direction = normalize(direction);
    } else {
      report_.fail(light.pointer(), "a spot light needs \"direction\" or \"look_at\"");
    }
    spot.intensity = light.rgb("intensity", ColorKind::Emission);
    spot.cone_angle = light.number_or("cone_angle", spot.cone_angle);
    if (!(spot.cone_angle > 0 && spot.cone_angle <= 180))
      report_.fail(light.pointer_of("cone_angle"), "the cone angle must be in (0, 180] degrees, got {}",
                   spot.cone_angle);
    spot.cone_delta = light.number_or("cone_delta", std::min(spot.cone_delta, spot.cone_angle));
    if (!(spot.cone_delta >= 0 && spot.cone_delta <= spot.cone_angle))
      report_.fail(light.pointer_of("cone_delta"), "cone_delta must be in [0, cone_angle] = [0, {}] degrees, got {}",
                   spot.cone_angle, spot.cone_delta);
    if (const Json* falloff = light.find("falloff"))
      spot.mitsuba_falloff = read_name<bool>(report_, *falloff, light.pointer_of("falloff"), "spot falloff",
                                             {{"smoothstep", false}, {"linear", true}});
    if (light.has("texture")) spot.texture = texture_reference(light, "texture");
    spot.up = normalize(light.direction_or("up", spot.up));
    return spot;
  }

  EnvironmentMap read_environment(CheckedObject& light) const {
    EnvironmentMap environment;
    environment.filename = existing_file(light, "filename", "environment map");
    if (const Json* mapping = light.find("mapping"))
      environment.mapping =
          read_name<EnvironmentMapping>(report_, *mapping, light.pointer_of("mapping"), "environment mapping",
                                        {{"equirectangular", EnvironmentMapping::Equirectangular},
                                         {"equirectangular_pole_rows", EnvironmentMapping::EquirectangularPoleRows},
                                         {"equal_area", EnvironmentMapping::EqualAreaOctahedral}});
    environment.scale = light.rgb_or("scale", ColorKind::Emission, environment.scale);
    environment.mis_compensation = light.boolean_or("mis_compensation", environment.mis_compensation);
    environment.to_world = read_environment_orientation(light, environment.mapping);
    return environment;
  }

  // Either "up" (where the map's own up axis points) and "rotate" (degrees about it), or a "transform".
  Transform read_environment_orientation(CheckedObject& light, EnvironmentMapping mapping) const {
    bool has_up = light.has("up"), has_rotate = light.has("rotate");
    if (const Json* steps = light.find("transform")) {
      std::string pointer = light.pointer_of("transform");
      if (has_up || has_rotate)
        report_.fail(pointer, "an environment map takes either \"transform\" or \"up\"/\"rotate\", not both");
      Transform transform = read_transform(*steps, pointer);
      check_rotation(transform, pointer);
      return transform;
    }
    Vec3 local_up = mapping == EnvironmentMapping::EqualAreaOctahedral ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    Vec3 up = normalize(light.direction_or("up", local_up));
    float degrees = light.number_or("rotate", 0);
    Transform spin = degrees == 0 ? Transform() : Transform::rotate(degrees, local_up);
    return rotation_between(local_up, up) * spin;
  }

  // The rotation taking unit vector `from` to unit vector `to` about their common perpendicular.
  static Transform rotation_between(Vec3 from, Vec3 to) {
    float cosine = std::clamp(dot(from, to), -1.0f, 1.0f);
    if (cosine >= 1 - 1e-7f) return {};
    Vec3 axis = cross(from, to);
    // Opposite vectors: any perpendicular axis will do; x is perpendicular to both possible local ups.
    if (length(axis) < 1e-6f) return Transform::rotate(180, {1, 0, 0});
    return Transform::rotate(std::acos(cosine) * (180 / kPi), axis);
  }

  // Light from infinitely far away depends on directions only: its transform may only rotate or mirror.
  void check_rotation(const Transform& transform, const std::string& pointer) const {
    const Matrix4& m = transform.matrix();
    if (m.m[0][3] != 0 || m.m[1][3] != 0 || m.m[2][3] != 0)
      report_.fail(pointer, "an environment map's transform may only rotate (or mirror) it, not translate it");
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double column_dot = m.m[0][i] * m.m[0][j] + m.m[1][i] * m.m[1][j] + m.m[2][i] * m.m[2][j];
        if (std::abs(column_dot - (i == j ? 1 : 0)) > 1e-4)
          report_.fail(pointer, "an environment map's transform may only rotate (or mirror) it, not scale or shear it");
      }
  }

  std::string_view text_;
  ErrorReporter report_;
  fs::path base_dir_;
  SceneDesc scene_;
  std::map<std::string, NamedTexture> named_textures_;
  std::vector<std::string> texture_stack_;  // the named textures being read, outermost first
  int texture_depth_ = 0;                   // textures being read, named or inline
  std::map<std::string, NamedMaterial> named_materials_;
  std::map<std::string, int> object_index_;
  std::optional<int> black_material_;
};

}  // namespace

SceneDesc read_json_scene(std::string_view text, const std::string& file_name, const std::filesystem::path& base_dir) {
  return JsonSceneReader(text, file_name, base_dir).read();
}

}  // namespace candela
