#pragma once
// The second layer of the pbrt-v4 reader: a directive's parameter list ("type name" [ values ]),
// read with its types and counts checked. Like pbrt-v4's ReportUnused, a parameter that nothing
// reads is an error rather than being silently ignored (ParameterUsage keeps that account).
#include <fmt/format.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/parameter_usage.h"
#include "candela/io/pbrt/tokenizer.h"
#include "candela/description/scene_desc.h"

namespace candela::pbrt {

enum class ValueKind { Number, Integer, Bool, String, Spectrum };

// One "type name" [ values ] entry of a directive's parameter list.
struct Param {
  std::string type;  // canonical spelling
  std::string name;
  SourceLocation where;  // the "type name" string
  ValueKind kind = ValueKind::Number;
  std::vector<double> numbers;  // Number and Integer values, and a spectrum's pairs
  std::vector<std::string> strings;
  std::vector<bool> bools;

  size_t count() const { return numbers.size() + strings.size() + bools.size(); }
  std::string declaration() const { return fmt::format("\"{} {}\"", type, name); }
};

// Reads the "type name" [ values ] entries that follow a directive, up to the next directive.
// `owner` names the directive in messages.
std::vector<Param> read_parameter_list(Tokenizer& tokens, const std::string& owner);

// "a", "b" or "c" (with `last_separator` before the last name).
std::string join_quoted(std::initializer_list<std::string_view> names, std::string_view last_separator = " or ");

// Lookups check a parameter's type and number of values and mark it used; reject_unused() then
// reports the first parameter nothing asked for, listing the ones this directive does read.
// `defaults` are the parameters an Attribute directive set for this kind of directive: they are
// found when the directive itself does not give the parameter, and are never reported as unused
// (they apply to every directive of the kind, and only some read each one), as in pbrt-v4.
class ParamList {
 public:
  ParamList(std::string owner, SourceLocation directive, std::vector<Param> params, std::vector<Param> defaults = {});

  const std::string& owner() const { return owner_; }
  const SourceLocation& directive() const { return directive_; }

  bool has(std::string_view name) const { return find_in(params_, name) || find_in(defaults_, name); }
  bool has_own(std::string_view name) const { return usage_.was_given(name); }

  // The parameter's place in the file, or the directive's when it was not given.
  SourceLocation where(std::string_view name) const;

  template <typename... Args>
  [[noreturn]] void fail(std::string_view name, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(where(name), "{}: \"{}\" {}", owner_, name, fmt::format(format, std::forward<Args>(args)...));
  }

  // The parameter `name` if given (by the directive or an Attribute), after checking that its type
  // is one of `types`; marks it used. nullptr when it is not given.
  const Param* take(std::string_view name, std::initializer_list<std::string_view> types);

  // Marks `name` read whatever its type (for parameters that are accepted and ignored).
  const Param* take_any(std::string_view name);

  void expect_count(const Param& p, size_t count) const;
  void expect_multiple(const Param& p, size_t per_item) const;

  float get_float(std::string_view name, float fallback);
  int get_int(std::string_view name, int fallback);
  bool get_bool(std::string_view name, bool fallback);
  std::string get_string(std::string_view name, std::string fallback);
  std::vector<std::string> get_strings(std::string_view name);
  Point3 get_point3(std::string_view name, Point3 fallback);
  Vec3 get_vector3(std::string_view name, Vec3 fallback);
  std::vector<double> get_floats(std::string_view name);

  // Colours are never negative; reflectances (albedos) are at most 1, as pbrt-v4 requires.
  RGB get_rgb(std::string_view name, RGB fallback, bool is_reflectance);
  RGB checked_rgb(const Param& p, bool is_reflectance) const;

  std::vector<Vec3> get_vec3_array(std::string_view name, std::string_view type);
  std::vector<Vec2> get_point2_array(std::string_view name);
  std::vector<int> get_int_array(std::string_view name);

  void reject_unused() const;

 private:
  static const Param* find_in(const std::vector<Param>& params, std::string_view name);
  const Param* take_single(std::string_view name, std::string_view type, size_t count);

  std::string owner_;
  SourceLocation directive_;
  std::vector<Param> params_;
  std::vector<Param> defaults_;
  ParameterUsage usage_;  // of params_: the defaults are never reported unused
};

// "unknown shape type" for a misspelling, "not supported" for a pbrt-v4 type candela lacks;
// both list the types that are supported.
[[noreturn]] void reject_type(const SourceLocation& where, std::string_view what, std::string_view type,
                              std::initializer_list<std::string_view> supported,
                              std::initializer_list<std::string_view> known_unsupported,
                              std::string_view why = "");

}  // namespace candela::pbrt
