// Any scene type with a schema (description/schema.h), read field by field.
#include "candela/io/json/reader.h"

namespace candela::json {

void JsonSceneReader::read_fields(CheckedObject& m, const TypeSchema& schema, void* object) {
  for (const Field& f : schema.fields) {
    if (f.required) m.require(f.key);
    for (std::string_view other : {f.unless, f.unless_also})
      if (!other.empty() && m.has(f.key) && m.has(other))
        report_.fail(m.pointer_of(f.key), "give either \"{}\" or \"{}\", not both", f.key, other);
    // Colours bounded above are reflectances (<= 1); the others need only be >= 0.
    const ColorKind color_kind = f.range.bounded_above() ? ColorKind::Albedo : ColorKind::NonNegative;
    switch (f.kind) {
      case FieldKind::Color: {
        auto& color = field_value<ColorInput>(f, object);
        color = color_input_or(m, f.key, color_kind, color);
        break;
      }
      case FieldKind::OptionalColor:
        if (const Json* given = m.find(f.key))
          field_value<std::optional<ColorInput>>(f, object) = read_color_input(*given, m.pointer_of(f.key), color_kind);
        break;
      case FieldKind::Float: {
        auto& number = field_value<FloatInput>(f, object);
        number = float_input_or(m, f.key, f.range, number);
        break;
      }
      case FieldKind::Number: {
        auto& number = field_value<float>(f, object);
        number = m.number_or(f.key, number, f.range);
        break;
      }
      case FieldKind::NumberIfGiven:
        if (m.has(f.key)) {
          field_value<float>(f, object) = m.number(f.key, f.range);
          field_second<bool>(f, object) = true;
        }
        break;
      case FieldKind::Flag: {
        auto& flag = field_value<bool>(f, object);
        flag = m.boolean_or(f.key, flag);
        break;
      }
      case FieldKind::Roughness: field_value<Roughness>(f, object) = read_roughness(m, roughness_prefix(f)); break;
      case FieldKind::Material: field_value<int>(f, object) = wrapped_material(m, f.key); break;
      case FieldKind::MaterialPair: {
        std::array<int, 2> pair = material_pair(m, f.key);
        field_value<int>(f, object) = pair[0];
        field_second<int>(f, object) = pair[1];
        break;
      }
      case FieldKind::Texture:
        if (f.required || m.has(f.key)) field_value<int>(f, object) = texture_reference(m, f.key);
        break;
      case FieldKind::Rgb: {
        auto& rgb = field_value<RGB>(f, object);
        rgb = m.rgb_or(f.key, color_kind, rgb);
        break;
      }
      case FieldKind::Point: {
        auto& point = field_value<Point3>(f, object);
        point = m.vec3_or(f.key, point);
        break;
      }
      case FieldKind::Vector: {
        auto& vector = field_value<Vec3>(f, object);
        vector = m.direction_or(f.key, vector);  // not zero
        break;
      }
      case FieldKind::Direction: {
        auto& direction = field_value<Vec3>(f, object);
        direction = normalize(m.direction_or(f.key, direction));
        break;
      }
      case FieldKind::Transform:
        if (m.has(f.key)) field_value<Transform>(f, object) = read_transform_key(m);
        break;
      case FieldKind::Enum:
        if (const Json* given = m.find(f.key)) {
          std::string name = read_string(report_, *given, m.pointer_of(f.key));
          if (!f.names->set_by_name(f.member(object), name)) {
            const std::string list = f.names->list();
            std::vector<std::string_view> names;
            for (size_t at = 0; at < list.size();) {
              const size_t end = std::min(list.find(", ", at), list.size());
              names.push_back(std::string_view(list).substr(at, end - at));
              at = end + 2;
            }
            report_.fail(m.pointer_of(f.key), "unknown {} \"{}\"{}; expected one of: {}", f.key, name,
                         did_you_mean(name, names), list);
          }
        }
        break;
      case FieldKind::File:
        if (f.required || m.has(f.key)) field_value<std::string>(f, object) = existing_file(m, f.key, f.help);
        break;
      case FieldKind::Text:
        if (f.required || m.has(f.key)) field_value<std::string>(f, object) = m.string(f.key);
        break;
      case FieldKind::UvMapping: field_value<UVMapping>(f, object) = read_uv_mapping(m); break;
      case FieldKind::Integer: {
        auto& number = field_value<int>(f, object);
        number = m.integer_or(f.key, number, int64_t(std::max(f.range.lo, -2147483648.0)),
                              int64_t(std::min(f.range.hi, 2147483647.0)));
        break;
      }
      case FieldKind::ScalarVolume:
      case FieldKind::ColorVolume:
        if (m.has(f.key)) field_value<VolumeDesc>(f, object) = read_volume_or_constant(m, f);
        break;
      case FieldKind::OptionalScalarVolume:
        if (m.has(f.key)) field_value<std::optional<VolumeDesc>>(f, object) = read_volume_or_constant(m, f);
        break;
    }
  }
}

// A quantity over space: a grid (an object; read_volume) or a constant in the field's range.
VolumeDesc JsonSceneReader::read_volume_or_constant(CheckedObject& m, const Field& f) const {
  const Json& value = m.require(f.key);
  const std::string pointer = m.pointer_of(f.key);
  if (value.is_object()) return read_volume(value, pointer, f.key);
  VolumeDesc constant;
  if (f.kind == FieldKind::ColorVolume)
    constant.constant = read_rgb(report_, value, pointer, f.range.bounded_above() ? ColorKind::Albedo : ColorKind::NonNegative);
  else
    constant.constant = RGB(check_bound(report_, read_float(report_, value, pointer), f.range, pointer));
  return constant;
}

void JsonSceneReader::check_fields(CheckedObject& m, const TypeSchema& schema, const void* object) const {
  if (schema.check)
    if (std::optional<SchemaViolation> violation = schema.check(object))
      report_.fail(violation->key.empty() ? m.pointer() : m.pointer_of(violation->key), "{}", violation->message);
}

}  // namespace candela::json
