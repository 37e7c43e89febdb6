#pragma once
// One declaration of a scene type's parameters (Mitsuba 3's traverse(), pbrt-v4's
// ParameterDictionary): each material, light, texture, medium and shape geometry description
// lists its fields once, with the key scene files use, the kind of value, the member it lives in,
// the range it accepts and a line of help; the default is the struct's own member initializer.
// Everything that walks a type's parameters is generated from that list:
//   the JSON reader (io/json/schema_fields.cpp: read_fields) and writer (io/json_writer.cpp: write_fields),
//   so `candela convert` writes what the reader reads;
//   the editable scene parameters of the Python module (scene/parameters.cpp);
//   which inputs are constant and which materials a wrapper wraps (materials/material.cpp);
//   the "unknown key; did you mean" messages (base/nearest_name.h).
//
// A type declares:
//   template <> struct SchemaOf<DiffuseMaterial> {
//     static constexpr Field fields[] = {field<&DiffuseMaterial::reflectance>("reflectance", kAlbedo, "...")};
//     static constexpr TypeSchema schema{.name = "diffuse", .fields = fields};
//   };
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "candela/description/textured_input.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"
#include "candela/base/enum_names.h"

namespace candela {

// What a number, or each component of a colour, accepts (a scene type's field, a render option): lo <= x <= hi, or lo < x / x < hi where
// that end is open. NaN is never inside.
struct ValueRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  constexpr bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  constexpr bool bounded_above() const { return hi < std::numeric_limits<double>::infinity(); }
  constexpr bool bounded_below() const { return lo > -std::numeric_limits<double>::infinity(); }
  // "a positive number", "a number >= 0", "a number in [0, 1]": for "expected ..., got x".
  std::string expected() const {
    if (!bounded_below() && !bounded_above()) return "a number";
    if (lo == 0 && lo_open && !bounded_above()) return "a positive number";
    if (!bounded_above()) return fmt::format("a number {} {}", lo_open ? ">" : ">=", lo);
    if (!bounded_below()) return fmt::format("a number {} {}", hi_open ? "<" : "<=", hi);
    return fmt::format("a number in {}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
  }
  // "0 < fov < 180", "0 <= weight <= 1": the range as an inequality on `name`.
  std::string inequality(std::string_view name) const {
    std::string text(name);
    if (bounded_below()) text = fmt::format("{} {} {}", lo, lo_open ? "<" : "<=", text);
    if (bounded_above()) text += fmt::format(" {} {}", hi_open ? "<" : "<=", hi);
    return text;
  }
};

inline constexpr ValueRange kAnyValue{};
inline constexpr ValueRange kNonNegative{.lo = 0};
inline constexpr ValueRange kPositive{.lo = 0, .lo_open = true};
inline constexpr ValueRange kUnitInterval{.lo = 0, .hi = 1};
// Colours: reflectances and albedos cannot exceed 1 without creating energy; other colours (an
// index of refraction, emission) need only be >= 0.
inline constexpr ValueRange kAlbedo = kUnitInterval;

// The kind of value a field holds, which fixes the C++ type of its member.
enum class FieldKind {
  Color,          // ColorInput: [r, g, b], one number for grey, or a texture
  OptionalColor,  // std::optional<ColorInput>: as Color, absent unless given
  Float,          // FloatInput: a number or a texture
  Number,         // float
  NumberIfGiven,  // float, with a bool member (`flag`) that says whether it was given
  Flag,           // bool
  Roughness,      // Roughness: "roughness" or "alpha_u" + "alpha_v", "remap_roughness", "distribution"
                  // (each after the prefix of a key "<prefix>roughness": roughness_field_at)
  Material,       // int: the index of a material this one wraps (given by name or inline)
  MaterialPair,   // two ints (the member and `second`): the materials a blend mixes, as a list of two
  Texture,        // int: the index of a texture (given by name or inline); -1 = none where not required
  Rgb,            // RGB: [r, g, b] or one number for grey
  Point,          // Point3: [x, y, z]
  Direction,      // Vec3: [x, y, z], not zero, normalized when read
  Vector,         // Vec3: [x, y, z], not zero, kept as given (a rectangle's edge)
  Transform,      // Transform: a list of transform steps (the JSON key "transform")
  Enum,           // a closed set's enumerator, by its enum_name (base/enum_names.h)
  File,           // std::string: a file name, resolved against the scene's folder and checked to exist
  Text,           // std::string: a name (a mesh attribute's)
  Integer,        // int
  ScalarVolume,   // VolumeDesc (description/media.h): a number, or a grid of one channel (an object)
  ColorVolume,    // VolumeDesc: [r, g, b] or one number for grey, or a grid of one or three channels
  OptionalScalarVolume,  // std::optional<VolumeDesc>: as ScalarVolume, absent unless given
  UvMapping,      // UVMapping: "uv_scale" and "uv_offset", or "uv_matrix" (the field's own key is not used)
};
constexpr std::string_view enum_name(FieldKind v) {
  switch (v) {
    case FieldKind::Color: return "color";
    case FieldKind::OptionalColor: return "optional_color";
    case FieldKind::Float: return "float";
    case FieldKind::Number: return "number";
    case FieldKind::NumberIfGiven: return "number_if_given";
    case FieldKind::Flag: return "flag";
    case FieldKind::Roughness: return "roughness";
    case FieldKind::Material: return "material";
    case FieldKind::MaterialPair: return "material_pair";
    case FieldKind::Texture: return "texture";
    case FieldKind::Rgb: return "rgb";
    case FieldKind::Point: return "point";
    case FieldKind::Direction: return "direction";
    case FieldKind::Vector: return "vector";
    case FieldKind::Transform: return "transform";
    case FieldKind::Enum: return "enum";
    case FieldKind::File: return "file";
    case FieldKind::Text: return "text";
    case FieldKind::Integer: return "integer";
    case FieldKind::ScalarVolume: return "scalar_volume";
    case FieldKind::ColorVolume: return "color_volume";
    case FieldKind::OptionalScalarVolume: return "optional_scalar_volume";
    case FieldKind::UvMapping: return "uv_mapping";
  }
  return {};
}

// An Enum field's names: the enumerator's name, setting it by name, and the list for messages.
struct EnumNames {
  std::string_view (*name_of)(const void* member);
  bool (*set_by_name)(void* member, std::string_view name);
  std::string (*list)();
};

// One parameter of a scene type. `member` finds it inside an object of that type; `second` is the
// second index of a MaterialPair, or the "given" flag of a NumberIfGiven.
struct Field {
  std::string_view key;
  FieldKind kind;
  void* (*member)(void* object) = nullptr;
  void* (*second)(void* object) = nullptr;
  ValueRange range{};
  std::string_view help;
  // The key of another field that, where given, makes this one meaningless (a conductor's eta and k
  // where its reflectance is given): the two may not be given together, and it is not written then.
  // `unless_also`: a second such key (a hair's melanin concentrations, meaningless where either
  // sigma_a or reflectance is given).
  std::string_view unless;
  std::string_view unless_also;
  bool required = false;           // the readers fail without it; the writer always writes it
  const EnumNames* names = nullptr;  // Enum fields
  bool (*given)(const void* object) = nullptr;  // OptionalScalarVolume fields: whether it holds a value

  constexpr Field required_field() const {
    Field f = *this;
    f.required = true;
    return f;
  }
  constexpr Field ignored_where(std::string_view other) const {
    Field f = *this;
    f.unless = other;
    return f;
  }
  constexpr Field ignored_where(std::string_view other, std::string_view another) const {
    Field f = ignored_where(other);
    f.unless_also = another;
    return f;
  }
};

// A cross-field rule the fields' ranges cannot say (Phong's d + s + t <= 1). Returns what is wrong,
// with the key it is best reported at (empty: the object itself), or nothing.
struct SchemaViolation {
  std::string key;
  std::string message;
};
using SchemaCheck = std::optional<SchemaViolation> (*)(const void* object);

struct TypeSchema {
  std::string_view name;                          // the "type" scene files give
  std::span<const std::string_view> aliases = {};  // other names the readers accept ("glass")
  std::span<const Field> fields = {};
  SchemaCheck check = nullptr;
  std::string_view help;

  bool named(std::string_view type) const {
    if (type == name) return true;
    for (std::string_view alias : aliases)
      if (type == alias) return true;
    return false;
  }
};

// Each described type specialises SchemaOf with `static constexpr TypeSchema schema`.
template <typename T>
struct SchemaOf;

namespace schema_detail {

template <typename M>
struct MemberTraits;
template <typename C, typename V>
struct MemberTraits<V C::*> {
  using Class = C;
  using Value = V;
};

template <auto First, auto... Rest>
constexpr auto* follow(typename MemberTraits<decltype(First)>::Class* object) {
  auto* member = &(object->*First);
  if constexpr (sizeof...(Rest) == 0) return member;
  else return follow<Rest...>(member);
}

template <auto... Path>
struct Last;
template <auto Only>
struct Last<Only> {
  using Value = typename MemberTraits<decltype(Only)>::Value;
};
template <auto First, auto... Rest>
struct Last<First, Rest...> : Last<Rest...> {};

// The member at the end of Path (a chain of member pointers: &Outer::options, &Options::flag),
// from a pointer to the outer object.
template <auto First, auto... Rest>
void* member_at(void* object) {
  return follow<First, Rest...>(static_cast<typename MemberTraits<decltype(First)>::Class*>(object));
}

template <typename V>
constexpr FieldKind kind_of() {
  if constexpr (std::is_same_v<V, ColorInput>) return FieldKind::Color;
  else if constexpr (std::is_same_v<V, std::optional<ColorInput>>) return FieldKind::OptionalColor;
  else if constexpr (std::is_same_v<V, FloatInput>) return FieldKind::Float;
  else if constexpr (std::is_same_v<V, float>) return FieldKind::Number;
  else if constexpr (std::is_same_v<V, int>) return FieldKind::Integer;
  else if constexpr (std::is_same_v<V, bool>) return FieldKind::Flag;
  else if constexpr (std::is_same_v<V, RGB>) return FieldKind::Rgb;
  else if constexpr (std::is_same_v<V, Transform>) return FieldKind::Transform;
  else if constexpr (std::is_same_v<V, std::string>) return FieldKind::File;
  else static_assert(sizeof(V) == 0,
                     "no field kind for this member type (indices: material_ref, texture_ref; vectors: point_field, "
                     "direction_field; enums: enum_field)");
}

template <auto Member>
bool optional_has_value(const void* object) {
  return static_cast<const typename MemberTraits<decltype(Member)>::Value*>(member_at<Member>(const_cast<void*>(object)))
      ->has_value();
}

template <typename E>
inline constexpr EnumNames kEnumNames{
    .name_of = [](const void* member) { return enum_name(*static_cast<const E*>(member)); },
    .set_by_name = [](void* member, std::string_view name) {
      std::optional<E> e = enum_from_name<E>(name);
      if (e) *static_cast<E*>(member) = *e;
      return e.has_value();
    },
    .list = [] { return enum_names_list<E>(); },
};

}  // namespace schema_detail

// A field whose kind follows from its member's type (ColorInput, FloatInput, float, bool, ...).
template <auto... Path>
constexpr Field field(std::string_view key, ValueRange range = kAnyValue, std::string_view help = {}) {
  using V = typename schema_detail::Last<Path...>::Value;
  return Field{.key = key, .kind = schema_detail::kind_of<V>(), .member = &schema_detail::member_at<Path...>,
               .range = range, .help = help};
}
template <auto Member>
constexpr Field roughness_field(std::string_view help = {}) {
  return Field{.key = "roughness", .kind = FieldKind::Roughness, .member = &schema_detail::member_at<Member>,
               .range = kNonNegative, .help = help};
}
// A second roughness of one type (a coated conductor's conductor): `key` is "<prefix>roughness", and
// its other keys are the prefix followed by "alpha_u", "alpha_v", "remap_roughness", "distribution".
template <auto Member>
constexpr Field roughness_field_at(std::string_view key, std::string_view help = {}) {
  Field f = roughness_field<Member>(help);
  f.key = key;
  return f;
}
// The prefix of a Roughness field's keys: "" for "roughness", "conductor_" for "conductor_roughness".
constexpr std::string_view roughness_prefix(const Field& f) {
  constexpr std::string_view stem = "roughness";
  return f.key.ends_with(stem) ? f.key.substr(0, f.key.size() - stem.size()) : std::string_view{};
}
template <auto Member>
constexpr Field material_ref(std::string_view key, std::string_view help = {}) {
  static_assert(std::is_same_v<typename schema_detail::MemberTraits<decltype(Member)>::Value, int>);
  return Field{.key = key, .kind = FieldKind::Material, .member = &schema_detail::member_at<Member>, .help = help};
}
template <auto First, auto Second>
constexpr Field material_pair(std::string_view key, std::string_view help = {}) {
  return Field{.key = key, .kind = FieldKind::MaterialPair, .member = &schema_detail::member_at<First>,
               .second = &schema_detail::member_at<Second>, .help = help};
}
template <auto Member>
constexpr Field texture_ref(std::string_view key, std::string_view help = {}) {
  static_assert(std::is_same_v<typename schema_detail::MemberTraits<decltype(Member)>::Value, int>);
  return Field{.key = key, .kind = FieldKind::Texture, .member = &schema_detail::member_at<Member>, .help = help};
}
template <auto Member>
constexpr Field point_field(std::string_view key, std::string_view help = {}) {
  return Field{.key = key, .kind = FieldKind::Point, .member = &schema_detail::member_at<Member>, .help = help};
}
template <auto Member>
constexpr Field direction_field(std::string_view key, std::string_view help = {}) {
  return Field{.key = key, .kind = FieldKind::Direction, .member = &schema_detail::member_at<Member>, .help = help};
}
template <auto Member>
constexpr Field vector_field(std::string_view key, std::string_view help = {}) {
  return Field{.key = key, .kind = FieldKind::Vector, .member = &schema_detail::member_at<Member>, .help = help};
}
template <auto Member>
constexpr Field enum_field(std::string_view key, std::string_view help = {}) {
  using E = typename schema_detail::MemberTraits<decltype(Member)>::Value;
  return Field{.key = key, .kind = FieldKind::Enum, .member = &schema_detail::member_at<Member>, .help = help,
               .names = &schema_detail::kEnumNames<E>};
}
template <auto Member>
constexpr Field text_field(std::string_view key, std::string_view help = {}) {
  static_assert(std::is_same_v<typename schema_detail::MemberTraits<decltype(Member)>::Value, std::string>);
  return Field{.key = key, .kind = FieldKind::Text, .member = &schema_detail::member_at<Member>, .help = help};
}
// A texture's placement on the surface (description/textures.h): written and read as uv_scale and
// uv_offset, or uv_matrix.
template <auto Member>
constexpr Field uv_mapping_field(std::string_view help = {}) {
  return Field{.key = "uv_mapping", .kind = FieldKind::UvMapping, .member = &schema_detail::member_at<Member>,
               .help = help};
}
// A quantity over space (description/media.h): a constant or a grid. `color`: an RGB constant and
// grids of one or three channels; else a number and grids of one.
template <auto Member>
constexpr Field volume_field(std::string_view key, bool color, ValueRange range, std::string_view help = {}) {
  using V = typename schema_detail::MemberTraits<decltype(Member)>::Value;
  constexpr bool optional = requires { typename V::value_type; };  // std::optional<VolumeDesc>
  Field f{.key = key, .kind = color ? FieldKind::ColorVolume : FieldKind::ScalarVolume,
          .member = &schema_detail::member_at<Member>, .range = range, .help = help};
  if constexpr (optional) {
    f.kind = FieldKind::OptionalScalarVolume;
    f.given = &schema_detail::optional_has_value<Member>;
  }
  return f;
}
template <auto Value, auto Given>
constexpr Field number_if_given(std::string_view key, ValueRange range, std::string_view help = {}) {
  return Field{.key = key, .kind = FieldKind::NumberIfGiven, .member = &schema_detail::member_at<Value>,
               .second = &schema_detail::member_at<Given>, .range = range, .help = help};
}

// The field's member in `object` (V must be the C++ type of the field's kind), and the second
// member of a MaterialPair (int) or NumberIfGiven (bool).
template <typename V>
V& field_value(const Field& f, void* object) {
  return *static_cast<V*>(f.member(object));
}
template <typename V>
const V& field_value(const Field& f, const void* object) {
  return *static_cast<const V*>(f.member(const_cast<void*>(object)));
}
template <typename V>
V& field_second(const Field& f, void* object) {
  return *static_cast<V*>(f.second(object));
}
template <typename V>
const V& field_second(const Field& f, const void* object) {
  return *static_cast<const V*>(f.second(const_cast<void*>(object)));
}

// Whether the object's field `key` was given: an optional colour that is set, a number whose flag
// says so (other kinds always hold a value).
inline bool field_given(const TypeSchema& schema, std::string_view key, const void* object) {
  for (const Field& f : schema.fields)
    if (f.key == key) {
      if (f.kind == FieldKind::OptionalColor) return field_value<std::optional<ColorInput>>(f, object).has_value();
      if (f.kind == FieldKind::NumberIfGiven) return field_second<bool>(f, object);
      if (f.kind == FieldKind::OptionalScalarVolume) return f.given(object);
      return true;
    }
  return false;
}

// Whether another given field makes the object's field `f` meaningless (Field::unless), so that it
// is not written.
inline bool field_ignored(const TypeSchema& schema, const Field& f, const void* object) {
  return (!f.unless.empty() && field_given(schema, f.unless, object)) ||
         (!f.unless_also.empty() && field_given(schema, f.unless_also, object));
}

// The schema of the type a variant holds.
template <typename... Ts>
const TypeSchema& schema_of(const std::variant<Ts...>& value) {
  return std::visit([](const auto& v) -> const TypeSchema& { return SchemaOf<std::decay_t<decltype(v)>>::schema; },
                    value);
}

// The alternative of Variant whose schema is named `type` (or has it as an alias), default-constructed.
template <typename Variant>
std::optional<Variant> default_of_type(std::string_view type) {
  std::optional<Variant> out;
  [&]<size_t... I>(std::index_sequence<I...>) {
    ((!out && SchemaOf<std::variant_alternative_t<I, Variant>>::schema.named(type)
          ? void(out.emplace(std::in_place_index<I>))
          : void()),
     ...);
  }(std::make_index_sequence<std::variant_size_v<Variant>>());
  return out;
}

// Every type name (aliases included) of a variant's alternatives, in declaration order.
template <typename Variant>
std::vector<std::string_view> type_names_of() {
  std::vector<std::string_view> names;
  [&]<size_t... I>(std::index_sequence<I...>) {
    auto add = [&](const TypeSchema& s) {
      names.push_back(s.name);
      names.insert(names.end(), s.aliases.begin(), s.aliases.end());
    };
    (add(SchemaOf<std::variant_alternative_t<I, Variant>>::schema), ...);
  }(std::make_index_sequence<std::variant_size_v<Variant>>());
  return names;
}

// The object's violation of its type's cross-field rule, if any.
template <typename... Ts>
std::optional<SchemaViolation> check_schema(const std::variant<Ts...>& value) {
  return std::visit(
      [](const auto& v) -> std::optional<SchemaViolation> {
        const TypeSchema& s = SchemaOf<std::decay_t<decltype(v)>>::schema;
        return s.check ? s.check(&v) : std::nullopt;
      },
      value);
}

}  // namespace candela
