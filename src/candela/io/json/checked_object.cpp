#include "candela/io/json/checked_object.h"

#include <cfloat>
#include <cmath>

namespace candela::json {

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

float read_color_component(const ErrorReporter& report, const Json& value, const std::string& pointer, ColorKind kind) {
  float c = read_float(report, value, pointer);
  if (c < 0) report.fail(pointer, "colour components must be >= 0, got {}", c);
  if (kind == ColorKind::Albedo && c > 1)
    report.fail(pointer, "a reflectance must be <= 1 in each channel (more would create energy), got {}", c);
  return c;
}

RGB read_rgb(const ErrorReporter& report, const Json& value, const std::string& pointer, ColorKind kind) {
  if (value.is_number()) return RGB(read_color_component(report, value, pointer, kind));
  if (!value.is_array() || value.size() != 3)
    report.fail(pointer, "expected a colour, [r, g, b] or a single number, got {}", describe(value));
  auto channel = [&](int i) { return read_color_component(report, value[i], child_pointer(pointer, size_t(i)), kind); };
  return RGB(channel(0), channel(1), channel(2));
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

void check_is_array(const ErrorReporter& report, const Json& value, const std::string& pointer,
                    std::string_view of_what) {
  if (!value.is_array()) report.fail(pointer, "expected an array of {}, got {}", of_what, describe(value));
}

float check_bound(const ErrorReporter& report, float x, const ValueRange& bound, const std::string& pointer) {
  if (!bound.contains(x) && (bound.bounded_below() || bound.bounded_above()))
    report.fail(pointer, "expected {}, got {}", bound.expected(), x);
  return x;
}

}  // namespace candela::json
