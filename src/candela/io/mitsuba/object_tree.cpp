#include "candela/io/mitsuba/object_tree.h"

#include <cctype>
#include <charconv>

namespace candela::mitsuba {

namespace fs = std::filesystem;

const char* kind_name(Property::Kind kind) {
  switch (kind) {
    case Property::Kind::Float: return "float";
    case Property::Kind::Integer: return "integer";
    case Property::Kind::Boolean: return "boolean";
    case Property::Kind::String: return "string";
    case Property::Kind::Vector: return "point/vector";
    case Property::Kind::RGB: return "rgb";
    case Property::Kind::Spectrum: return "spectrum";
    case Property::Kind::Transform: return "transform";
    case Property::Kind::Object: return "nested object";
    case Property::Kind::Ref: return "reference";
  }
  return "?";
}

std::optional<fs::path> ObjectTree::resolve(const std::string& name) const {
  fs::path p(name);
  if (p.is_absolute()) return fs::exists(p) ? std::optional(p) : std::nullopt;
  for (auto it = search_paths.rbegin(); it != search_paths.rend(); ++it) {
    fs::path candidate = *it / p;
    if (fs::exists(candidate)) return candidate.lexically_normal();
  }
  return std::nullopt;
}

std::string ObjectTree::search_path_text() const {
  std::string s;
  for (auto it = search_paths.rbegin(); it != search_paths.rend(); ++it) {
    if (!s.empty()) s += ", ";
    s += it->string();
  }
  return s;
}

// ---------------------------------------------------------------- text helpers

std::string trim(std::string_view s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

std::vector<std::string> tokenize(std::string_view s, std::string_view delimiters) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (delimiters.find(c) != std::string_view::npos) {
      if (!cur.empty()) out.push_back(std::move(cur)), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(std::move(cur));
  return out;
}

std::optional<double> parse_double(std::string_view s) {
  std::string t = trim(s);
  if (t.empty()) return std::nullopt;
  double v = 0;
  const char* begin = t.data();
  if (*begin == '+') ++begin;
  auto [end, ec] = std::from_chars(begin, t.data() + t.size(), v);
  if (ec != std::errc() || end != t.data() + t.size()) return std::nullopt;
  return v;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace candela::mitsuba
