#pragma once
// Typed, range-checked reads of JSON values, and CheckedObject: one JSON object read key by key,
// which rejects, once read, any key nobody asked for (a misspelt optional key would otherwise be
// silently ignored). Every failure is a SceneError naming the value by JSON pointer and line.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/base/enum_names.h"
#include "candela/base/nearest_name.h"
#include "candela/description/schema.h"
#include "candela/io/json/source_position.h"
#include "candela/io/parameter_usage.h"
#include "candela/math/color.h"
#include "candela/math/vec.h"

namespace candela::json {

using Json = nlohmann::ordered_json;  // ordered: materials keep the file's order

// What a value was instead of what was expected: its type, or its length for arrays.
std::string describe(const Json& value);

double read_double(const ErrorReporter& report, const Json& value, const std::string& pointer);

float read_float(const ErrorReporter& report, const Json& value, const std::string& pointer);

// Reads array[index] without building its pointer unless there is something to report (meshes
// have millions of coordinates).
float read_float_element(const ErrorReporter& report, const Json& array, size_t index, const std::string& pointer);

int64_t read_int64(const ErrorReporter& report, const Json& value, const std::string& pointer);

uint64_t read_uint64(const ErrorReporter& report, const Json& value, const std::string& pointer);

Vec3 read_vec3(const ErrorReporter& report, const Json& value, const std::string& pointer);

Vec2 read_vec2(const ErrorReporter& report, const Json& value, const std::string& pointer);

// Reflectances and albedos cannot exceed 1 without creating energy; emission can. Other colours (a
// conductor's k, the constants inside textures, which may be used anywhere) need only be >= 0.
enum class ColorKind { Albedo, Emission, NonNegative };

float read_color_component(const ErrorReporter& report, const Json& value, const std::string& pointer, ColorKind kind);

// [r, g, b], or one number for grey.
RGB read_rgb(const ErrorReporter& report, const Json& value, const std::string& pointer, ColorKind kind);

Vec3 read_direction(const ErrorReporter& report, const Json& value, const std::string& pointer);

bool read_bool(const ErrorReporter& report, const Json& value, const std::string& pointer);

std::string read_string(const ErrorReporter& report, const Json& value, const std::string& pointer);

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

// One of a closed set's names (base/enum_names.h), e.g. "bsdf" for DirectionSampling::Bsdf.
template <typename E>
E read_enum(const ErrorReporter& report, const Json& value, const std::string& pointer, std::string_view what) {
  std::string name = read_string(report, value, pointer);
  if (std::optional<E> e = enum_from_name<E>(name)) return *e;
  report.fail(pointer, "unknown {} \"{}\"; expected one of: {}", what, name, enum_names_list<E>());
}

void check_is_array(const ErrorReporter& report, const Json& value, const std::string& pointer,
                    std::string_view of_what);

// The ranges readers check numbers against (description/schema.h's ValueRange), by their old names.
struct Bound {
  static constexpr ValueRange Any = kAnyValue, Positive = kPositive, NonNegative = kNonNegative,
                              UnitInterval = kUnitInterval;
};

float check_bound(const ErrorReporter& report, float x, const ValueRange& bound, const std::string& pointer);

// One JSON object, read key by key with type checks. finish() reports the first key that no read
// asked for, listing the keys that were asked for (the object's schema, as far as it was read).
class CheckedObject {
 public:
  CheckedObject(const ErrorReporter& report, const Json& value, std::string pointer)
      : report_(report), value_(value), pointer_(std::move(pointer)) {
    if (!value_.is_object()) report_.fail(pointer_, "expected an object, got {}", describe(value_));
    for (auto it = value_.begin(); it != value_.end(); ++it)
      if (it.key() != "_comment") usage_.give(it.key(), SourceLocation{.key_path = pointer_of(it.key())});
  }

  const std::string& pointer() const { return pointer_; }
  std::string pointer_of(std::string_view key) const { return child_pointer(pointer_, key); }
  const ErrorReporter& report() const { return report_; }

  const Json* find(std::string_view key) {
    usage_.ask(key);
    auto it = value_.find(std::string(key));
    return it == value_.end() ? nullptr : &*it;
  }
  bool has(std::string_view key) { return find(key) != nullptr; }
  const Json& require(std::string_view key) {
    const Json* value = find(key);
    if (!value) report_.fail(pointer_, "missing required key \"{}\"", key);
    return *value;
  }

  float number(std::string_view key, const ValueRange& bound = kAnyValue) {
    return check_bound(report_, read_float(report_, require(key), pointer_of(key)), bound, pointer_of(key));
  }
  float number_or(std::string_view key, float fallback, const ValueRange& bound = kAnyValue) {
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

  // "_comment" may be given in any object and is never read.
  void finish() const {
    if (const ParameterUsage::Parameter* unused = usage_.first_unused()) {
      std::vector<std::string_view> asked(usage_.asked().begin(), usage_.asked().end());
      report_.fail(unused->where.key_path, "unknown key{}; expected one of: {}", did_you_mean(unused->name, asked),
                   usage_.asked_list());
    }
  }

 private:
  const ErrorReporter& report_;
  const Json& value_;
  std::string pointer_;
  ParameterUsage usage_;  // the keys given (all but "_comment") and the keys asked for
};

}  // namespace candela::json
