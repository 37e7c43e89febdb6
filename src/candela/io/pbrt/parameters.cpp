#include "candela/io/pbrt/parameters.h"

#include <algorithm>
#include <optional>
#include <sstream>

#include "candela/base/nearest_name.h"

namespace candela::pbrt {

// ---------------------------------------------------------------- reading parameter lists

namespace {

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

void add_value(Param& param, const Token& value, const std::string& owner) {
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

Param read_param(Tokenizer& tokens, const Token& declaration, const std::string& owner) {
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

  Token first = tokens.next();
  if (first.kind == TokenKind::OpenBracket) {
    while (true) {
      Token value = tokens.next();
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

}  // namespace

std::vector<Param> read_parameter_list(Tokenizer& tokens, const std::string& owner) {
  std::vector<Param> params;
  while (tokens.peek().kind == TokenKind::String) {
    Token declaration = tokens.next();
    Param param = read_param(tokens, declaration, owner);
    for (const Param& earlier : params)
      if (earlier.name == param.name)
        throw_scene_error(param.where, "{}: parameter \"{}\" is given twice (first at {})", owner, param.name,
                          earlier.where.to_string());
    params.push_back(std::move(param));
  }
  return params;
}

std::string join_quoted(std::initializer_list<std::string_view> names, std::string_view last_separator) {
  std::string list;
  size_t i = 0;
  for (std::string_view name : names) {
    if (i > 0) list += i + 1 == names.size() ? std::string(last_separator) : std::string(", ");
    list += fmt::format("\"{}\"", name);
    ++i;
  }
  return list;
}

// ---------------------------------------------------------------- ParamList

namespace {

Vec3 to_vec3(const std::vector<double>& numbers, size_t i) {
  return {static_cast<float>(numbers[i]), static_cast<float>(numbers[i + 1]), static_cast<float>(numbers[i + 2])};
}

}  // namespace

ParamList::ParamList(std::string owner, SourceLocation directive, std::vector<Param> params,
                     std::vector<Param> defaults)
    : owner_(std::move(owner)),
      directive_(std::move(directive)),
      params_(std::move(params)),
      defaults_(std::move(defaults)) {
  for (const Param& p : params_) usage_.give(p.name, p.where);
}

SourceLocation ParamList::where(std::string_view name) const {
  if (const Param* p = find_in(params_, name)) return p->where;
  if (const Param* p = find_in(defaults_, name)) return p->where;
  return directive_;
}

const Param* ParamList::take(std::string_view name, std::initializer_list<std::string_view> types) {
  usage_.ask(name);
  const Param* p = find_in(params_, name);
  if (!p) p = find_in(defaults_, name);
  if (!p) return nullptr;
  if (std::find(types.begin(), types.end(), p->type) == types.end()) {
    if (p->type == "texture")
      throw_scene_error(p->where, "{}: {}: a texture is not accepted here; give {}", owner_, p->declaration(),
                        join_quoted(types));
    throw_scene_error(p->where, "{}: parameter \"{}\" must be of type {}, not \"{}\"", owner_, name,
                      join_quoted(types), p->type);
  }
  return p;
}

const Param* ParamList::take_any(std::string_view name) {
  usage_.ask(name);
  const Param* p = find_in(params_, name);
  return p ? p : find_in(defaults_, name);
}

void ParamList::expect_count(const Param& p, size_t count) const {
  if (p.count() != count)
    throw_scene_error(p.where, "{}: {} takes exactly {} value{}, got {}", owner_, p.declaration(), count,
                      count == 1 ? "" : "s", p.count());
}

void ParamList::expect_multiple(const Param& p, size_t per_item) const {
  if (p.count() % per_item != 0)
    throw_scene_error(p.where, "{}: {} needs a multiple of {} values, got {}", owner_, p.declaration(), per_item,
                      p.count());
}

float ParamList::get_float(std::string_view name, float fallback) {
  const Param* p = take_single(name, "float", 1);
  return p ? static_cast<float>(p->numbers[0]) : fallback;
}

int ParamList::get_int(std::string_view name, int fallback) {
  const Param* p = take_single(name, "integer", 1);
  return p ? static_cast<int>(p->numbers[0]) : fallback;
}

bool ParamList::get_bool(std::string_view name, bool fallback) {
  const Param* p = take_single(name, "bool", 1);
  return p ? p->bools[0] : fallback;
}

std::string ParamList::get_string(std::string_view name, std::string fallback) {
  const Param* p = take_single(name, "string", 1);
  return p ? p->strings[0] : std::move(fallback);
}

std::vector<std::string> ParamList::get_strings(std::string_view name) {
  const Param* p = take(name, {"string"});
  return p ? p->strings : std::vector<std::string>{};
}

Point3 ParamList::get_point3(std::string_view name, Point3 fallback) {
  const Param* p = take_single(name, "point3", 3);
  return p ? to_vec3(p->numbers, 0) : fallback;
}

Vec3 ParamList::get_vector3(std::string_view name, Vec3 fallback) {
  const Param* p = take_single(name, "vector3", 3);
  return p ? to_vec3(p->numbers, 0) : fallback;
}

std::vector<double> ParamList::get_floats(std::string_view name) {
  const Param* p = take(name, {"float"});
  return p ? p->numbers : std::vector<double>{};
}

RGB ParamList::get_rgb(std::string_view name, RGB fallback, bool is_reflectance) {
  const Param* p = take_single(name, "rgb", 3);
  return p ? checked_rgb(*p, is_reflectance) : fallback;
}

RGB ParamList::checked_rgb(const Param& p, bool is_reflectance) const {
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

std::vector<Vec3> ParamList::get_vec3_array(std::string_view name, std::string_view type) {
  const Param* p = take(name, {type});
  std::vector<Vec3> values;
  if (!p) return values;
  expect_multiple(*p, 3);
  values.reserve(p->numbers.size() / 3);
  for (size_t i = 0; i < p->numbers.size(); i += 3) values.push_back(to_vec3(p->numbers, i));
  return values;
}

std::vector<Vec2> ParamList::get_point2_array(std::string_view name) {
  const Param* p = take(name, {"point2"});
  std::vector<Vec2> values;
  if (!p) return values;
  expect_multiple(*p, 2);
  values.reserve(p->numbers.size() / 2);
  for (size_t i = 0; i < p->numbers.size(); i += 2)
    values.emplace_back(static_cast<float>(p->numbers[i]), static_cast<float>(p->numbers[i + 1]));
  return values;
}

std::vector<int> ParamList::get_int_array(std::string_view name) {
  const Param* p = take(name, {"integer"});
  std::vector<int> values;
  if (p)
    for (double v : p->numbers) values.push_back(static_cast<int>(v));
  return values;
}

void ParamList::reject_unused() const {
  const ParameterUsage::Parameter* unused = usage_.first_unused();
  if (!unused) return;
  std::string declaration = find_in(params_, unused->name)->declaration();
  std::string known = usage_.asked_list();
  if (known.empty())
    throw_scene_error(unused->where, "{}: unused parameter {} (it takes no parameters)", owner_, declaration);
  throw_scene_error(unused->where, "{}: unused parameter {}{} (parameters read here: {})", owner_, declaration,
                    usage_.did_you_mean(unused->name), known);
}

const Param* ParamList::find_in(const std::vector<Param>& params, std::string_view name) {
  for (const Param& p : params)
    if (p.name == name) return &p;
  return nullptr;
}

const Param* ParamList::take_single(std::string_view name, std::string_view type, size_t count) {
  const Param* p = take(name, {type});
  if (p) expect_count(*p, count);
  return p;
}

void reject_type(const SourceLocation& where, std::string_view what, std::string_view type,
                 std::initializer_list<std::string_view> supported,
                 std::initializer_list<std::string_view> known_unsupported, std::string_view why) {
  std::string list = join_quoted(supported, ", ");
  if (std::find(known_unsupported.begin(), known_unsupported.end(), type) != known_unsupported.end())
    throw_scene_error(where, "{} type \"{}\" is not supported{} (supported: {})", what, type,
                      why.empty() ? std::string(" yet") : fmt::format(": {}", why), list);
  std::vector<std::string_view> names(supported);
  names.insert(names.end(), known_unsupported.begin(), known_unsupported.end());
  throw_scene_error(where, "unknown {} type \"{}\"{} (supported: {})", what, type, did_you_mean(type, names), list);
}

}  // namespace candela::pbrt
