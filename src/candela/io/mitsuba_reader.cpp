// Reader for Mitsuba 3 XML scenes (the subset in docs/mitsuba-format.md).
//
// Two passes. The first reads the XML (pugixml) into a tree of objects with their properties, as
// Mitsuba's parser does: $parameters substituted, <default>, <include> and <path> handled,
// transforms composed, nested objects and <ref>s kept by name. The second turns each object into
// candela's description, plugin by plugin, with Mitsuba's defaults; every property must be read by
// the plugin that owns it (an unknown parameter is an error, as in Mitsuba). What candela reads but
// cannot reproduce exactly is a warning; what would change the image materially is an error.
#include "candela/io/mitsuba_reader.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "candela/geometry/sdf_grid.h"
#include "candela/base/error.h"
#include "candela/io/mesh_io.h"
#include "candela/io/named_spectra.h"

namespace candela {
namespace {

namespace fs = std::filesystem;
namespace ms = mitsuba_spectra;

constexpr int kMaxIncludeDepth = 15;     // Mitsuba's MI_XML_INCLUDE_MAX_RECURSION
constexpr int kUnboundedDepth = 1024;    // candela's max_depth for Mitsuba's max_depth = -1
// Mitsuba's default focal length, 50 mm, as a field of view on the diagonal of a 36 x 24 mm film.
constexpr float kDefaultFovDiagonal = 46.79139f;
float diagonal_fov_from_focal_length(double mm) {
  return float(2 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2 * mm)) * 180 / 3.14159265358979);
}

// ---------------------------------------------------------------- the object tree

struct Where {
  std::shared_ptr<const std::string> file;
  int line = 0;
  SourceLocation loc() const { return {file ? *file : std::string(), line, 0, {}}; }
};

struct Object;

struct Property {
  enum class Kind { Float, Integer, Boolean, String, Vector, RGB, Spectrum, Transform, Object, Ref };
  Kind kind = Kind::Float;
  std::string name;
  Where where;
  double number = 0;                 // Float, Integer, Spectrum with one value
  bool boolean = false;
  std::string text;                  // String; Ref: the id
  Vec3 vector{0.0f};                 // Vector (point / vector), RGB
  std::vector<double> wavelengths, values;  // Spectrum with wavelength:value pairs
  Transform transform;
  Object* object = nullptr;
  mutable bool used = false;
};

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

struct Object {
  std::string tag;   // scene, bsdf, shape, emitter, sensor, film, rfilter, sampler, integrator, texture, spectrum
  std::string type;  // the plugin
  std::string id;
  Where where;
  std::vector<Property> props;
  std::string describe() const { return fmt::format("{} \"{}\"", tag, type); }
};

bool is_object_tag(std::string_view tag) {
  static const std::set<std::string_view> tags = {"scene",   "bsdf",       "shape",   "emitter", "sensor",
                                                  "film",    "rfilter",    "sampler", "integrator",
                                                  "texture", "medium",     "phase",   "volume"};
  return tags.contains(tag);
}

// ---------------------------------------------------------------- parsing helpers

std::string trim(std::string_view s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

// Mitsuba's tokenizer: commas and whitespace separate.
std::vector<std::string> tokenize(std::string_view s, std::string_view delimiters = ", \t\r\n") {
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

Transform matrix_transform(const double m[4][4], const Where& where) {
  Matrix4 mat;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) mat.m[i][j] = m[i][j];
  std::optional<Transform> t = Transform::from_matrix(mat);
  if (!t) throw_scene_error(where.loc(), "the transform is singular");
  return *t;
}

// Mitsuba's look_at: camera-to-world with columns (left, up, direction, origin), left = up x dir.
Transform mitsuba_look_at(const Vec3& origin, const Vec3& target, Vec3 up, const Where& where) {
  Vec3 dir = target - origin;
  if (!(length(dir) > 0)) throw_scene_error(where.loc(), "lookat: origin and target are the same point");
  dir = normalize(dir);
  if (length_squared(up) == 0) {
    // Mitsuba's coordinate_system(dir).
    float sign = std::copysign(1.0f, dir.z);
    float a = -1.0f / (sign + dir.z), b = dir.x * dir.y * a;
    up = Vec3(b, sign + dir.y * dir.y * a, -dir.y);
  }
  Vec3 left = cross(up, dir);
  if (!(length(left) > 0)) throw_scene_error(where.loc(), "lookat: the up vector is parallel to the view direction");
  left = normalize(left);
  Vec3 new_up = cross(dir, left);
  double m[4][4] = {{left.x, new_up.x, dir.x, origin.x},
                    {left.y, new_up.y, dir.y, origin.y},
                    {left.z, new_up.z, dir.z, origin.z},
                    {0, 0, 0, 1}};
  return matrix_transform(m, where);
}

// ---------------------------------------------------------------- pass 1: XML to objects

class XmlParser {
 public:
  XmlParser(std::vector<std::string>& warnings, const MitsubaReadOptions& options) : warnings_(warnings) {
    for (const auto& [name, value] : options.parameters) params_.emplace_back(name, value);
  }

  template <typename... Args>
  void warn(const Where& where, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.push_back(
        fmt::format("{}: warning: {}", where.loc().to_string(), fmt::format(format, std::forward<Args>(args)...)));
  }

  Object* parse_root(std::string_view text, const std::string& file_name, const fs::path& base_dir) {
    search_paths_.push_back(base_dir);
    Document doc = load(text, file_name, base_dir, Where{});
    pugi::xml_node root = doc.xml->document_element();
    Where where = doc.where(root);
    if (std::string_view(root.name()) != "scene")
      throw_scene_error(where.loc(), "the root element is <{}>; a Mitsuba scene starts with <scene version=...>",
                        root.name());
    if (!root.attribute("version"))
      throw_scene_error(where.loc(), "<scene> has no version attribute (Mitsuba 3 scenes say version=\"3.0.0\")");
    check_version(root.attribute("version").value(), where);
    Object* scene = new_object("scene", "scene", where);
    for (pugi::xml_node child : root.children()) parse_child(doc, child, *scene, 1);
    return scene;
  }

  const std::unordered_map<std::string, Object*>& ids() const { return ids_; }
  const std::vector<fs::path>& search_paths() const { return search_paths_; }

  // Resolves a file name as Mitsuba's FileResolver: the <path> folders (latest first), then the
  // scene's folder.
  std::optional<fs::path> resolve(const std::string& name) const {
    fs::path p(name);
    if (p.is_absolute()) return fs::exists(p) ? std::optional(p) : std::nullopt;
    for (auto it = search_paths_.rbegin(); it != search_paths_.rend(); ++it) {
      fs::path candidate = *it / p;
      if (fs::exists(candidate)) return candidate.lexically_normal();
    }
    return std::nullopt;
  }

  std::string search_path_text() const {
    std::string s;
    for (auto it = search_paths_.rbegin(); it != search_paths_.rend(); ++it) {
      if (!s.empty()) s += ", ";
      s += it->string();
    }
    return s;
  }

 private:
  struct Document {
    std::shared_ptr<pugi::xml_document> xml;
    std::shared_ptr<const std::string> file;
    std::vector<size_t> line_starts;
    fs::path dir;
    Where where(const pugi::xml_node& node) const {
      ptrdiff_t offset = node.offset_debug();
      int line = 0;
      if (offset >= 0)
        line = int(std::upper_bound(line_starts.begin(), line_starts.end(), size_t(offset)) - line_starts.begin());
      return {file, line};
    }
  };

  Document load(std::string_view text, const std::string& file_name, const fs::path& dir, const Where& from) {
    Document doc;
    doc.xml = std::make_shared<pugi::xml_document>();
    doc.file = std::make_shared<const std::string>(file_name);
    doc.dir = dir;
    doc.line_starts.push_back(0);
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') doc.line_starts.push_back(i + 1);
    pugi::xml_parse_result result = doc.xml->load_buffer(text.data(), text.size(), pugi::parse_default);
    if (!result) {
      int line = int(std::upper_bound(doc.line_starts.begin(), doc.line_starts.end(), size_t(result.offset)) -
                     doc.line_starts.begin());
      std::string message = fmt::format("{}:{}: malformed XML: {}", file_name, line, result.description());
      if (from.file) message = from.loc().to_string() + ": in the included file: " + message;
      throw SceneError(message);
    }
    if (!doc.xml->document_element())
      throw_scene_error(Where{doc.file, 1}.loc(), "the file holds no XML element");
    return doc;
  }

  void check_version(const std::string& version, const Where& where) {
    std::vector<std::string> parts = tokenize(version, ". ");
    std::optional<double> major = parts.size() == 3 ? parse_double(parts[0]) : std::nullopt;
    if (!major) throw_scene_error(where.loc(), "could not read the version number \"{}\"", version);
    if (*major < 2)
      throw_scene_error(where.loc(), "scene version {} is Mitsuba 0.x's format; candela reads version 2.0.0 and later",
                        version);
  }

  Object* new_object(std::string tag, std::string type, const Where& where) {
    objects_.push_back(std::make_unique<Object>());
    Object* o = objects_.back().get();
    o->tag = std::move(tag);
    o->type = std::move(type);
    o->where = where;
    return o;
  }

  void substitute(const Document& doc, pugi::xml_node node) {
    for (pugi::xml_attribute attr : node.attributes()) {
      std::string value = attr.value();
      if (value.find('$') == std::string::npos) continue;
      std::vector<std::pair<std::string, std::string>> sorted = params_;
      std::stable_sort(sorted.begin(), sorted.end(),
                       [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
      for (const auto& [name, replacement] : sorted) {
        std::string key = "$" + name;
        for (size_t at = value.find(key); at != std::string::npos; at = value.find(key, at + replacement.size()))
          value.replace(at, key.size(), replacement);
      }
      if (value.find('$') != std::string::npos)
        throw_scene_error(doc.where(node).loc(), "undefined parameter in \"{}\" (no <default> and no value given)",
                          value);
      attr.set_value(value.c_str());
    }
  }

  static void check_attributes(const Document& doc, pugi::xml_node node, std::initializer_list<const char*> allowed) {
    for (pugi::xml_attribute attr : node.attributes()) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || std::strcmp(a, attr.name()) == 0;
      if (!ok)
        throw_scene_error(doc.where(node).loc(), "unexpected attribute \"{}\" in <{}>", attr.name(), node.name());
    }
  }

  static std::string required(const Document& doc, pugi::xml_node node, const char* attr) {
    pugi::xml_attribute a = node.attribute(attr);
    if (!a) throw_scene_error(doc.where(node).loc(), "<{}> needs a \"{}\" attribute", node.name(), attr);
    return a.value();
  }

  static double number(const Document& doc, pugi::xml_node node, const std::string& text) {
    std::optional<double> v = parse_double(text);
    if (!v) throw_scene_error(doc.where(node).loc(), "<{}>: could not read \"{}\" as a number", node.name(), text);
    return *v;
  }

  // x/y/z attributes or "value" with 1 or 3 numbers; missing components are `fill`.
  static Vec3 xyz(const Document& doc, pugi::xml_node node, float fill, bool one_value_fills = true) {
    if (pugi::xml_attribute v = node.attribute("value")) {
      if (node.attribute("x") || node.attribute("y") || node.attribute("z"))
        throw_scene_error(doc.where(node).loc(), "<{}>: give either \"value\" or \"x\"/\"y\"/\"z\", not both",
                          node.name());
      std::vector<std::string> list = tokenize(v.value());
      if (list.size() == 1 && one_value_fills) {
        float f = float(number(doc, node, list[0]));
        return Vec3(f);
      }
      if (list.size() != 3)
        throw_scene_error(doc.where(node).loc(), "<{}>: \"value\" must hold {}3 numbers", node.name(),
                          one_value_fills ? "1 or " : "");
      return {float(number(doc, node, list[0])), float(number(doc, node, list[1])), float(number(doc, node, list[2]))};
    }
    Vec3 r(fill);
    const char* names[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i)
      if (pugi::xml_attribute a = node.attribute(names[i])) r[i] = float(number(doc, node, a.value()));
    return r;
  }

  static Vec3 vector_attribute(const Document& doc, pugi::xml_node node, const char* name) {
    std::vector<std::string> list = tokenize(required(doc, node, name));
    if (list.size() != 3)
      throw_scene_error(doc.where(node).loc(), "<{}>: \"{}\" must hold 3 numbers", node.name(), name);
    return {float(number(doc, node, list[0])), float(number(doc, node, list[1])), float(number(doc, node, list[2]))};
  }

  Transform parse_transform(const Document& doc, pugi::xml_node node) {
    Transform t;
    for (pugi::xml_node op : node.children()) {
      if (op.type() != pugi::node_element) continue;
      substitute(doc, op);
      Where where = doc.where(op);
      std::string_view name = op.name();
      Transform step;
      if (name == "translate") {
        check_attributes(doc, op, {"x", "y", "z", "value"});
        step = Transform::translate(xyz(doc, op, 0, false));
      } else if (name == "scale") {
        check_attributes(doc, op, {"x", "y", "z", "value"});
        Vec3 s = xyz(doc, op, 1);
        if (s.x == 0 || s.y == 0 || s.z == 0) throw_scene_error(where.loc(), "<scale>: a factor is zero");
        step = Transform::scale(s);
      } else if (name == "rotate") {
        check_attributes(doc, op, {"x", "y", "z", "value", "angle"});
        Vec3 axis = xyz(doc, op, 0, false);
        if (length(axis) == 0) throw_scene_error(where.loc(), "<rotate>: the axis is zero");
        step = Transform::rotate(float(number(doc, op, required(doc, op, "angle"))), normalize(axis));
      } else if (name == "lookat") {
        check_attributes(doc, op, {"origin", "target", "up"});
        Vec3 up(0.0f);
        if (op.attribute("up")) up = vector_attribute(doc, op, "up");
        step = mitsuba_look_at(vector_attribute(doc, op, "origin"), vector_attribute(doc, op, "target"), up, where);
      } else if (name == "matrix") {
        check_attributes(doc, op, {"value"});
        std::vector<std::string> list = tokenize(required(doc, op, "value"));
        double m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
        if (list.size() == 16) {
          for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = number(doc, op, list[i]);
        } else if (list.size() == 9) {
          for (int i = 0; i < 9; ++i) m[i / 3][i % 3] = number(doc, op, list[i]);
        } else {
          throw_scene_error(where.loc(), "<matrix>: expected 16 or 9 values, got {}", list.size());
        }
        step = matrix_transform(m, where);
      } else {
        throw_scene_error(where.loc(), "<{}> cannot occur inside a <transform> (translate, rotate, scale, matrix, "
                                       "lookat can)",
                          name);
      }
      t = step * t;  // each operation left-multiplies
    }
    return t;
  }

  std::string auto_name() { return fmt::format("_arg_{}", arg_counter_++); }

  void parse_child(const Document& doc, pugi::xml_node node, Object& parent, int depth) {
    if (node.type() == pugi::node_comment || node.type() == pugi::node_declaration || node.type() == pugi::node_pi)
      return;
    Where where = doc.where(node);
    if (node.type() != pugi::node_element) {
      if (trim(node.value()).empty()) return;
      throw_scene_error(where.loc(), "unexpected text \"{}\"", trim(node.value()).substr(0, 40));
    }
    substitute(doc, node);
    std::string tag = node.name();
    auto add = [&](Property p) {
      p.where = where;
      parent.props.push_back(std::move(p));
    };
    auto named = [&](Property::Kind kind) {
      Property p;
      p.kind = kind;
      p.name = required(doc, node, "name");
      if (p.name.starts_with("_"))
        throw_scene_error(where.loc(), "parameter names starting with '_' are reserved");
      return p;
    };

    if (tag == "spectrum" && node.attribute("type")) tag = "texture";  // spectrum plugins are textures
    if (is_object_tag(tag)) {
      if (tag == "scene") throw_scene_error(where.loc(), "<scene> can only be the root element");
      check_attributes(doc, node, {"type", "id", "name", "version"});
      if (tag == "medium" || tag == "phase" || tag == "volume")
        throw_scene_error(where.loc(), "<{}>: participating media are not supported", tag);
      Object* o = new_object(tag, required(doc, node, "type"), where);
      if (pugi::xml_attribute id = node.attribute("id")) {
        o->id = id.value();
        if (o->id.starts_with("_")) throw_scene_error(where.loc(), "ids starting with '_' are reserved");
        auto [it, inserted] = ids_.emplace(o->id, o);
        if (!inserted)
          throw_scene_error(where.loc(), "duplicate id \"{}\" (first defined at {})", o->id,
                            it->second->where.loc().to_string());
      }
      for (pugi::xml_node child : node.children()) parse_child(doc, child, *o, depth + 1);
      Property p;
      p.kind = Property::Kind::Object;
      p.name = node.attribute("name") ? node.attribute("name").value() : auto_name();
      p.object = o;
      add(std::move(p));
      return;
    }
    if (tag == "ref") {
      check_attributes(doc, node, {"id", "name"});
      Property p;
      p.kind = Property::Kind::Ref;
      p.name = node.attribute("name") ? node.attribute("name").value() : auto_name();
      p.text = required(doc, node, "id");
      add(std::move(p));
      return;
    }
    if (tag == "default") {
      check_attributes(doc, node, {"name", "value"});
      std::string name = required(doc, node, "name");
      if (name.empty()) throw_scene_error(where.loc(), "<default> needs a non-empty name");
      bool known = std::any_of(params_.begin(), params_.end(), [&](const auto& kv) { return kv.first == name; });
      if (!known) params_.emplace_back(name, required(doc, node, "value"));
      return;
    }
    if (tag == "path") {
      check_attributes(doc, node, {"value"});
      if (depth != 1) throw_scene_error(where.loc(), "<path> can only be a child of <scene>");
      fs::path p(required(doc, node, "value"));
      if (!p.is_absolute()) {
        fs::path local = doc.dir / p;
        if (fs::exists(local)) p = local;
        else if (std::optional<fs::path> found = resolve(p.string())) p = *found;
        else p = local;
      }
      if (!fs::is_directory(p)) throw_scene_error(where.loc(), "<path>: folder \"{}\" not found", p.string());
      search_paths_.push_back(p.lexically_normal());
      return;
    }
    if (tag == "include") {
      check_attributes(doc, node, {"filename"});
      include(doc, node, parent, depth, where);
      return;
    }
    if (tag == "alias") {
      check_attributes(doc, node, {"id", "as"});
      std::string id = required(doc, node, "id"), as = required(doc, node, "as");
      auto it = ids_.find(id);
      if (it == ids_.end()) throw_scene_error(where.loc(), "<alias>: no object has the id \"{}\"", id);
      if (!ids_.emplace(as, it->second).second) throw_scene_error(where.loc(), "duplicate id \"{}\"", as);
      return;
    }
    if (tag == "float" || tag == "integer") {
      check_attributes(doc, node, {"name", "value"});
      Property p = named(tag == "float" ? Property::Kind::Float : Property::Kind::Integer);
      std::string value = required(doc, node, "value");
      p.number = number(doc, node, value);
      if (tag == "integer" && p.number != std::floor(p.number))
        throw_scene_error(where.loc(), "<integer>: \"{}\" is not an integer", value);
      add(std::move(p));
      return;
    }
    if (tag == "boolean") {
      check_attributes(doc, node, {"name", "value"});
      Property p = named(Property::Kind::Boolean);
      std::string value = lower(trim(required(doc, node, "value")));
      if (value != "true" && value != "false")
        throw_scene_error(where.loc(), "<boolean>: \"{}\" must be true or false", value);
      p.boolean = value == "true";
      add(std::move(p));
      return;
    }
    if (tag == "string") {
      check_attributes(doc, node, {"name", "value"});
      Property p = named(Property::Kind::String);
      p.text = required(doc, node, "value");
      add(std::move(p));
      return;
    }
    if (tag == "point" || tag == "vector") {
      check_attributes(doc, node, {"name", "value", "x", "y", "z"});
      Property p = named(Property::Kind::Vector);
      p.vector = xyz(doc, node, 0);
      add(std::move(p));
      return;
    }
    if (tag == "rgb" || tag == "color") {
      check_attributes(doc, node, {"name", "value"});
      Property p = named(Property::Kind::RGB);
      std::vector<std::string> list = tokenize(required(doc, node, "value"));
      if (list.size() == 1) list = {list[0], list[0], list[0]};
      if (list.size() != 3) throw_scene_error(where.loc(), "<rgb> needs one or three values");
      p.vector = {float(number(doc, node, list[0])), float(number(doc, node, list[1])), float(number(doc, node, list[2]))};
      add(std::move(p));
      return;
    }
    if (tag == "spectrum") {
      check_attributes(doc, node, {"name", "value", "filename"});
      Property p = named(Property::Kind::Spectrum);
      if (node.attribute("filename")) {
        if (node.attribute("value")) throw_scene_error(where.loc(), "<spectrum>: give a value or a filename, not both");
        read_spectrum_file(doc, node.attribute("filename").value(), where, p);
        add(std::move(p));
        return;
      }
      std::vector<std::string> list = tokenize(required(doc, node, "value"));
      if (list.empty()) throw_scene_error(where.loc(), "<spectrum>: empty value");
      if (list.size() == 1 && list[0].find(':') == std::string::npos) {
        p.number = number(doc, node, list[0]);
      } else {
        for (const std::string& token : list) {
          std::vector<std::string> pair = tokenize(token, ":");
          if (pair.size() != 2) throw_scene_error(where.loc(), "<spectrum>: expected wavelength:value pairs");
          double w = number(doc, node, pair[0]), v = number(doc, node, pair[1]);
          if (!p.wavelengths.empty() && w <= p.wavelengths.back())
            throw_scene_error(where.loc(), "<spectrum>: wavelengths must increase");
          p.wavelengths.push_back(w);
          p.values.push_back(v);
        }
        if (p.wavelengths.size() < 2) throw_scene_error(where.loc(), "<spectrum>: give at least two pairs");
      }
      add(std::move(p));
      return;
    }
    if (tag == "transform") {
      check_attributes(doc, node, {"name"});
      Property p = named(Property::Kind::Transform);
      p.transform = parse_transform(doc, node);
      add(std::move(p));
      return;
    }
    if (tag == "translate" || tag == "rotate" || tag == "scale" || tag == "lookat" || tag == "matrix")
      throw_scene_error(where.loc(), "<{}> can only occur inside a <transform>", tag);
    throw_scene_error(where.loc(), "unknown element <{}>", tag);
  }

  // Mitsuba's spectrum files: one "wavelength value" pair per line (nm), increasing; '#' starts a
  // comment. The pairs then mean exactly what inline wavelength:value pairs mean.
  void read_spectrum_file(const Document& doc, const std::string& name, const Where& where, Property& p) {
    fs::path file = doc.dir / name;
    if (!fs::exists(file)) {
      std::optional<fs::path> found = resolve(name);
      if (!found) throw_scene_error(where.loc(), "<spectrum>: file \"{}\" not found (searched {})", name, search_path_text());
      file = *found;
    }
    std::ifstream in(file);
    if (!in) throw_scene_error(where.loc(), "<spectrum>: cannot open \"{}\"", file.string());
    std::string line;
    for (int line_number = 1; std::getline(in, line); ++line_number) {
      if (size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
      std::vector<std::string> words = tokenize(line, " \t\r,");
      if (words.empty()) continue;
      double w = 0, v = 0;
      auto parse = [&](const std::string& word, double& out) {
        const char* end = word.data() + word.size();
        auto [stop, error] = std::from_chars(word.data(), end, out);
        return error == std::errc() && stop == end && std::isfinite(out);
      };
      if (words.size() != 2 || !parse(words[0], w) || !parse(words[1], v))
        throw_scene_error(SourceLocation{file.string(), line_number, 1, {}},
                          "expected \"wavelength value\" (two numbers), got \"{}\"", line);
      if (!p.wavelengths.empty() && w <= p.wavelengths.back())
        throw_scene_error(SourceLocation{file.string(), line_number, 1, {}}, "wavelengths must increase ({} after {})",
                          w, p.wavelengths.back());
      p.wavelengths.push_back(w);
      p.values.push_back(v);
    }
    if (p.wavelengths.size() < 2)
      throw_scene_error(where.loc(), "<spectrum>: \"{}\" holds fewer than two wavelength-value pairs", file.string());
  }

  void include(const Document& doc, pugi::xml_node node, Object& parent, int depth, const Where& where) {
    std::string name = required(doc, node, "filename");
    if (++include_depth_ > kMaxIncludeDepth)
      throw_scene_error(where.loc(), "more than {} nested <include>s (an include cycle?)", kMaxIncludeDepth);
    fs::path file = doc.dir / name;
    if (!fs::exists(file)) {
      std::optional<fs::path> found = resolve(name);
      if (!found) throw_scene_error(where.loc(), "included file \"{}\" not found", name);
      file = *found;
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) throw_scene_error(where.loc(), "cannot open the included file \"{}\"", file.string());
    std::ostringstream text;
    text << in.rdbuf();
    Document sub = load(text.str(), file.string(), file.parent_path(), where);
    pugi::xml_node root = sub.xml->document_element();
    substitute(sub, root);
    if (std::string_view(root.name()) == "scene") {
      if (root.attribute("version")) check_version(root.attribute("version").value(), sub.where(root));
      for (pugi::xml_node child : root.children()) parse_child(sub, child, parent, depth);
    } else {
      parse_child(sub, root, parent, depth);
    }
    --include_depth_;
  }

  std::vector<std::string>& warnings_;
  std::vector<std::pair<std::string, std::string>> params_;
  std::vector<fs::path> search_paths_;
  std::deque<std::unique_ptr<Object>> objects_;
  std::unordered_map<std::string, Object*> ids_;
  int arg_counter_ = 0;
  int include_depth_ = 0;
};

// ---------------------------------------------------------------- pass 2: objects to SceneDesc

// Mitsuba treats these names as unbounded spectra (no clamping to [0, 1]).
bool is_unbounded_name(std::string_view name) {
  return name == "eta" || name == "k" || name == "int_ior" || name == "ext_ior";
}

// How Mitsuba looks a texture up: for a colour (eval, eval_3) or for a float parameter (eval_1).
// The two differ for the checkerboard, so a texture object becomes one candela texture per lookup.
enum class TextureLookup { Color, Scalar };

class Converter {
 public:
  Converter(XmlParser& parser, std::vector<std::string>& warnings) : parser_(parser), warnings_(warnings) {}

  SceneDesc convert(const Object& scene) {
    desc_.settings.sampler.type = SamplerType::Independent;
    desc_.settings.spp = 4;  // Mitsuba's independent sampler default
    desc_.settings.max_depth = kUnboundedDepth;
    desc_.settings.integrator = "path";
    // Mitsuba picks the emitter of a shadow ray (and of a light path) uniformly.
    desc_.settings.light_selection = LightSelection::Uniform;
    desc_.settings.filter = gaussian_filter(0.5f);
    desc_.film.width = 768;
    desc_.film.height = 576;
    desc_.camera.fov_axis = FovAxis::Diagonal;
    desc_.camera.fov_degrees = kDefaultFovDiagonal;
    desc_.camera.near_clip = 0.01f;
    desc_.camera.world_from_camera = Transform::scale({-1, 1, 1});

    bool have_sensor = false, have_integrator = false;
    for (const Property& p : scene.props) {
      p.used = true;
      const Object* o = p.kind == Property::Kind::Object ? p.object : nullptr;
      if (p.kind == Property::Kind::Ref)
        throw_scene_error(p.where.loc(), "a <ref> directly inside <scene> has no effect; refer to \"{}\" from a "
                                         "shape or another object",
                          p.text);
      if (!o) throw_scene_error(p.where.loc(), "a {} property \"{}\" cannot occur directly inside <scene>",
                                kind_name(p.kind), p.name);
      if (o->tag == "sensor") {
        if (have_sensor) throw_scene_error(o->where.loc(), "more than one sensor; candela renders one camera");
        have_sensor = true;
        sensor(*o);
      } else if (o->tag == "integrator") {
        if (have_integrator) throw_scene_error(o->where.loc(), "more than one integrator");
        have_integrator = true;
        integrator(*o);
      } else if (o->tag == "shape") {
        if (o->type == "shapegroup") continue;  // instantiated where an instance refers to it
        shape(*o, nullptr);
      } else if (o->tag == "emitter") {
        emitter(*o);
      } else if (o->tag == "bsdf" || o->tag == "texture") {
        continue;  // used where referenced
      } else {
        throw_scene_error(o->where.loc(), "<{}> cannot occur directly inside <scene>", o->tag);
      }
    }
    if (!have_sensor)
      warn(scene.where, "the scene has no sensor: Mitsuba's default camera (at the origin looking along +z, 768 x "
                        "576) is used");
    return std::move(desc_);
  }

 private:
  // ------------------------------------------------ property access

  template <typename... Args>
  void warn(const Where& where, fmt::format_string<Args...> format, Args&&... args) {
    warnings_.push_back(
        fmt::format("{}: warning: {}", where.loc().to_string(), fmt::format(format, std::forward<Args>(args)...)));
  }

  static const Property* find(const Object& o, std::string_view name) {
    const Property* found = nullptr;
    for (const Property& p : o.props)
      if (p.name == name) {
        if (found) throw_scene_error(p.where.loc(), "{}: \"{}\" is given twice", o.describe(), name);
        found = &p;
      }
    if (found) found->used = true;
    return found;
  }

  [[noreturn]] static void wrong_kind(const Object& o, const Property& p, const char* expected) {
    throw_scene_error(p.where.loc(), "{}: \"{}\" must be {}, not a {}", o.describe(), p.name, expected,
                      kind_name(p.kind));
  }

  static float get_float(const Object& o, std::string_view name, float fallback) {
    const Property* p = find(o, name);
    if (!p) return fallback;
    if (p->kind == Property::Kind::Float || p->kind == Property::Kind::Integer) return float(p->number);
    wrong_kind(o, *p, "a float");
  }
  static int get_int(const Object& o, std::string_view name, int fallback) {
    const Property* p = find(o, name);
    if (!p) return fallback;
    if (p->kind == Property::Kind::Integer) return int(p->number);
    wrong_kind(o, *p, "an integer");
  }
  static bool get_bool(const Object& o, std::string_view name, bool fallback) {
    const Property* p = find(o, name);
    if (!p) return fallback;
    if (p->kind == Property::Kind::Boolean) return p->boolean;
    wrong_kind(o, *p, "a boolean");
  }
  static std::string get_string(const Object& o, std::string_view name, const std::string& fallback) {
    const Property* p = find(o, name);
    if (!p) return fallback;
    if (p->kind == Property::Kind::String) return p->text;
    wrong_kind(o, *p, "a string");
  }
  static std::optional<Vec3> get_vector(const Object& o, std::string_view name) {
    const Property* p = find(o, name);
    if (!p) return std::nullopt;
    if (p->kind == Property::Kind::Vector) return p->vector;
    wrong_kind(o, *p, "a point or vector");
  }
  static Transform get_transform(const Object& o, std::string_view name) {
    const Property* p = find(o, name);
    if (!p) return {};
    if (p->kind == Property::Kind::Transform) return p->transform;
    wrong_kind(o, *p, "a <transform>");
  }
  // Accepts a parameter that changes nothing candela can show.
  void ignore(const Object& o, std::string_view name, const char* why = nullptr) {
    const Property* p = find(o, name);
    if (p && why) warn(p->where, "{}: \"{}\" is ignored: {}", o.describe(), name, why);
  }

  // Every property must have been read by the plugin.
  static void check_all_used(const Object& o) {
    for (const Property& p : o.props)
      if (!p.used) {
        if (p.kind == Property::Kind::Object || p.kind == Property::Kind::Ref)
          throw_scene_error(p.where.loc(), "{}: unexpected nested {}", o.describe(),
                            p.kind == Property::Kind::Ref ? fmt::format("reference to \"{}\"", p.text)
                                                          : "<" + p.object->tag + ">");
        throw_scene_error(p.where.loc(), "{}: unknown parameter \"{}\"", o.describe(), p.name);
      }
  }

  const Object& deref(const Property& p) {
    if (p.kind == Property::Kind::Object) return *p.object;
    auto it = parser_.ids().find(p.text);
    if (it == parser_.ids().end()) throw_scene_error(p.where.loc(), "reference to an undefined id \"{}\"", p.text);
    return *it->second;
  }

  // The nested objects (and references) of `o` whose tag is `tag`, marked used.
  std::vector<std::pair<const Property*, const Object*>> nested(const Object& o, std::string_view tag) {
    std::vector<std::pair<const Property*, const Object*>> out;
    for (const Property& p : o.props) {
      if (p.kind != Property::Kind::Object && p.kind != Property::Kind::Ref) continue;
      const Object& target = deref(p);
      if (target.tag != tag) continue;
      p.used = true;
      out.emplace_back(&p, &target);
    }
    return out;
  }

  fs::path resolve_file(const Object& o, std::string_view name_param) {
    const Property* p = find(o, name_param);
    if (!p) throw_scene_error(o.where.loc(), "{}: \"{}\" is required", o.describe(), name_param);
    if (p->kind != Property::Kind::String) wrong_kind(o, *p, "a string");
    std::optional<fs::path> file = parser_.resolve(p->text);
    if (!file)
      throw_scene_error(p->where.loc(), "{}: file \"{}\" not found (searched {})", o.describe(), p->text,
                        parser_.search_path_text());
    return *file;
  }

  // ------------------------------------------------ colours and textures

  // Mitsuba's blackbody spectrum: Planck's law in W m^-2 sr^-1 nm^-1 (physical units: the scene
  // should be in metres), zero outside [lambda_min, lambda_max]. Mitsuba's RGB variants refuse it;
  // here it becomes the RGB a spectral variant's film would record, through the same CIE
  // integration as a tabulated spectrum (1 nm steps).
  RGB blackbody(const Object& t) {
    const Property* temperature = find(t, "temperature");
    if (!temperature) throw_scene_error(t.where.loc(), "blackbody: \"temperature\" (in kelvin) is required");
    const double kelvin = get_float(t, "temperature", 0);
    if (!(kelvin > 0)) throw_scene_error(temperature->where.loc(), "blackbody: the temperature must be positive");
    const double lo = get_float(t, "lambda_min", 360), hi = get_float(t, "lambda_max", 830);
    if (!(lo < hi)) throw_scene_error(t.where.loc(), "blackbody: lambda_min must be below lambda_max");
    constexpr double c = 2.99792458e8, h = 6.62607004e-34, k = 1.38064852e-23;  // Mitsuba's constants
    std::vector<double> wavelengths, values;
    for (double nm = std::floor(lo); nm <= std::ceil(hi); nm += 1) {
      const double l = nm * 1e-9;
      const double radiance = nm < lo || nm > hi ? 0.0 : 1e-9 * 2 * h * c * c / (std::pow(l, 5) * std::expm1(h * c / (l * k * kelvin)));
      wavelengths.push_back(nm);
      values.push_back(radiance * ms::kCieYNormalization);
    }
    return ms::spectrum_list_to_srgb(wavelengths, values, false);
  }

  RGB spectrum_rgb(const Property& p, bool within_emitter) {
    bool bounded = !(within_emitter || is_unbounded_name(p.name));
    if (p.wavelengths.empty()) return RGB(float(p.number));
    std::vector<double> v = p.values;
    for (double& x : v) x *= ms::kCieYNormalization;
    return ms::spectrum_list_to_srgb(p.wavelengths, v, bounded);
  }

  std::optional<ColorInput> color_input(const Object& o, std::string_view name, bool within_emitter = false,
                                        TextureLookup lookup = TextureLookup::Color) {
    const Property* p = find(o, name);
    if (!p) return std::nullopt;
    switch (p->kind) {
      case Property::Kind::RGB: return ColorInput(RGB(p->vector.x, p->vector.y, p->vector.z));
      case Property::Kind::Float:
      case Property::Kind::Integer: return ColorInput(RGB(float(p->number)));
      case Property::Kind::Spectrum: return ColorInput(spectrum_rgb(*p, within_emitter));
      case Property::Kind::Object:
      case Property::Kind::Ref: {
        const Object& t = deref(*p);
        if (t.tag != "texture") throw_scene_error(p->where.loc(), "{}: \"{}\" must be a texture, not a <{}>",
                                                  o.describe(), name, t.tag);
        if (t.type == "blackbody") return ColorInput(blackbody(t));  // a constant: no texture lookups
        ColorInput c;
        c.texture = texture(t, lookup);
        return c;
      }
      default: wrong_kind(o, *p, "a colour (rgb, spectrum, float or texture)");
    }
  }
  ColorInput color(const Object& o, std::string_view name, RGB fallback, bool within_emitter = false) {
    return color_input(o, name, within_emitter).value_or(ColorInput(fallback));
  }

  FloatInput float_input(const Object& o, std::string_view name, float fallback) {
    const Property* p = find(o, name);
    if (!p) return FloatInput(fallback);
    switch (p->kind) {
      case Property::Kind::Float:
      case Property::Kind::Integer: return FloatInput(float(p->number));
      case Property::Kind::Spectrum:
        if (p->wavelengths.empty()) return FloatInput(float(p->number));
        break;
      case Property::Kind::RGB:
        if (p->vector.x == p->vector.y && p->vector.y == p->vector.z) return FloatInput(p->vector.x);
        break;
      case Property::Kind::Object:
      case Property::Kind::Ref: {
        const Object& t = deref(*p);
        if (t.tag != "texture") throw_scene_error(p->where.loc(), "{}: \"{}\" must be a texture, not a <{}>",
                                                  o.describe(), name, t.tag);
        FloatInput f;
        f.texture = texture(t, TextureLookup::Scalar);
        return f;
      }
      default: break;
    }
    wrong_kind(o, *p, "a float or a texture");
  }

  int add_texture(TextureDesc t) {
    desc_.textures.push_back(std::move(t));
    return int(desc_.textures.size()) - 1;
  }

  // A constant colour as a texture (for parameters that must be textures).
  int constant_texture(RGB value) {
    ScaleTexture s;
    s.tex = ColorInput(value);
    s.scale = FloatInput(1.0f);
    return add_texture(s);
  }

  // Mitsuba's to_uv, an affine map of the texture coordinates (its 2D part; z is ignored):
  // uv' = (a00 u + a01 v + a03, a10 u + a11 v + a13).
  UVMapping to_uv(const Object& o) {
    const Property* p = find(o, "to_uv");
    UVMapping m;
    if (!p) return m;
    if (p->kind != Property::Kind::Transform) wrong_kind(o, *p, "a <transform>");
    const Matrix4& a = p->transform.matrix();
    m.su = float(a.m[0][0]);
    m.s_from_v = float(a.m[0][1]);
    m.du = float(a.m[0][3]);
    m.t_from_u = float(a.m[1][0]);
    m.sv = float(a.m[1][1]);
    m.dv = float(a.m[1][3]);
    return m;
  }

  int texture(const Object& t, TextureLookup lookup = TextureLookup::Color) {
    if (auto it = texture_memo_.find({&t, lookup}); it != texture_memo_.end()) return it->second;
    int index = -1;
    if (t.type == "bitmap") {
      ImageTexture img;
      img.filename = resolve_file(t, "filename").string();
      std::string filter = get_string(t, "filter_type", "bilinear");
      if (filter == "nearest") img.bilinear = false;
      else if (filter != "bilinear")
        throw_scene_error(t.where.loc(), "bitmap: filter_type \"{}\" (use bilinear or nearest)", filter);
      std::string wrap = get_string(t, "wrap_mode", "repeat");
      if (wrap == "repeat") img.wrap = TextureWrap::Repeat;
      else if (wrap == "mirror") img.wrap = TextureWrap::Mirror;
      else if (wrap == "clamp") img.wrap = TextureWrap::Clamp;
      else throw_scene_error(t.where.loc(), "bitmap: wrap_mode \"{}\" (use repeat, mirror or clamp)", wrap);
      if (get_bool(t, "raw", false)) img.encoding = ColorEncoding::Linear;
      UVMapping m = to_uv(t);
      // Mitsuba looks images up with v = 0 at the top row; candela's t = 0 is the bottom row, so
      // t' = 1 - v' (the surface's uvs are Mitsuba's).
      img.mapping = m;
      img.mapping.t_from_u = -m.t_from_u;
      img.mapping.sv = -m.sv;
      img.mapping.dv = 1 - m.dv;
      // A float parameter reads an RGB image's luminance (Mitsuba's eval_1 and eval_1_grad).
      img.luminance = lookup == TextureLookup::Scalar;
      ignore(t, "format");  // "variant" / "rgb": the channels are read as RGB either way
      ignore(t, "accel");
      index = add_texture(img);
    } else if (t.type == "checkerboard") {
      CheckerboardTexture c;
      c.tex1 = color_input(t, "color0", false, lookup).value_or(ColorInput(RGB(0.4f)));
      c.tex2 = color_input(t, "color1", false, lookup).value_or(ColorInput(RGB(0.2f)));
      // Mitsuba: color0 where (u mod 1 < 0.5) == (v mod 1 < 0.5), i.e. where floor(2u) + floor(2v) is even.
      // Its scalar lookup (eval_1: roughness, metallic, blend weights, ...) keeps a legacy convention
      // with the colours the other way round.
      if (lookup == TextureLookup::Scalar) std::swap(c.tex1, c.tex2);
      UVMapping m = to_uv(t);
      c.mapping = {2 * m.su, 2 * m.sv, 2 * m.du, 2 * m.dv, 2 * m.s_from_v, 2 * m.t_from_u};
      index = add_texture(c);
    } else if (t.type == "mesh_attribute") {
      std::string name = get_string(t, "name", "");
      MeshAttributeTexture a;
      if (name.starts_with("vertex_")) a.name = name.substr(7);
      else if (name.starts_with("face_")) {
        a.name = name.substr(5);
        a.per_face = true;
      }
      else
        throw_scene_error(t.where.loc(), "mesh_attribute: \"name\" must start with vertex_ or face_ (got \"{}\")", name);
      get_float(t, "scale", 1);  // Mitsuba's mesh_attribute has no scale; accepted when 1
      index = add_texture(a);
    } else if (t.type == "rawconstant" || t.type == "uniform" || t.type == "srgb") {
      RGB v(1.0f);
      if (std::optional<Vec3> vec = get_vector(t, "value"); vec) v = RGB(vec->x, vec->y, vec->z);
      else if (std::optional<ColorInput> c = color_input(t, t.type == "srgb" ? "color" : "value"); c) {
        if (!c->is_constant()) throw_scene_error(t.where.loc(), "{}: the value must be a constant", t.describe());
        v = c->value;
      }
      index = constant_texture(v);
    } else if (t.type == "blackbody") {
      index = constant_texture(blackbody(t));
    } else {
      throw_scene_error(t.where.loc(), "unknown texture type \"{}\" (supported: bitmap, checkerboard, "
                                       "mesh_attribute, rawconstant)",
                        t.type);
    }
    check_all_used(t);
    texture_memo_[{&t, lookup}] = index;
    return index;
  }

  // ------------------------------------------------ materials

  // bumpmap's and normalmap's two switches, on by default since Mitsuba 3.7.1.
  PerturbedNormalOptions perturbed_normal_options(const Object& b) {
    return {get_bool(b, "flip_invalid_normals", true), get_bool(b, "use_shadowing_function", true)};
  }

  int add_material(MaterialDesc m) {
    desc_.materials.push_back(std::move(m));
    return int(desc_.materials.size()) - 1;
  }
  // Mitsuba's opaque BSDFs are one-sided; candela's are two-sided.
  int one_sided(MaterialDesc m, bool two_sided) {
    int inner = add_material(std::move(m));
    if (two_sided) return inner;
    return add_material(OneSidedMaterial{inner});
  }

  float ior_value(const Object& o, std::string_view name, float fallback) {
    const Property* p = find(o, name);
    if (!p) return fallback;
    if (p->kind == Property::Kind::Float || p->kind == Property::Kind::Integer) return float(p->number);
    if (p->kind == Property::Kind::String) {
      std::optional<float> v = ms::named_ior(p->text);
      if (!v) {
        std::string names;
        for (std::string_view n : ms::named_ior_names()) names += (names.empty() ? "" : ", ") + std::string(n);
        throw_scene_error(p->where.loc(), "{}: unknown {} \"{}\" (known: {})", o.describe(), name, p->text, names);
      }
      return *v;
    }
    wrong_kind(o, *p, "a number or an IOR name");
  }
  float relative_ior(const Object& o, float int_default, float ext_default) {
    if (const Property* eta = find(o, "eta"); eta) {
      if (eta->kind != Property::Kind::Float && eta->kind != Property::Kind::Integer) wrong_kind(o, *eta, "a float");
      return float(eta->number);
    }
    return ior_value(o, "int_ior", int_default) / ior_value(o, "ext_ior", ext_default);
  }

  Roughness roughness(const Object& o, float alpha_default) {
    Roughness r;
    std::string dist = get_string(o, "distribution", "beckmann");
    if (dist == "beckmann") r.distribution = MicrofacetDistribution::Beckmann;
    else if (dist == "ggx") r.distribution = MicrofacetDistribution::GGXSeparable;
    else throw_scene_error(o.where.loc(), "{}: distribution \"{}\" (use beckmann or ggx)", o.describe(), dist);
    bool has_alpha = find(o, "alpha") != nullptr;
    if (has_alpha) {
      r.u = r.v = float_input(o, "alpha", alpha_default);
      if (find(o, "alpha_u") || find(o, "alpha_v"))
        throw_scene_error(o.where.loc(), "{}: give either alpha or alpha_u/alpha_v", o.describe());
    } else {
      r.u = float_input(o, "alpha_u", alpha_default);
      r.v = float_input(o, "alpha_v", alpha_default);
    }
    r.remap = false;
    ignore(o, "sample_visible");
    return r;
  }

  void conductor_ior(const Object& o, ConductorMaterial& c) {
    std::string material = get_string(o, "material", "none");
    bool has_eta = find(o, "eta") != nullptr, has_k = find(o, "k") != nullptr;
    if (has_eta || has_k || material == "none") {
      if ((has_eta || has_k) && material != "none")
        throw_scene_error(o.where.loc(), "{}: give either eta/k or material, not both", o.describe());
      c.eta = color(o, "eta", RGB(0.0f));
      c.k = color(o, "k", RGB(1.0f));
      return;
    }
    std::optional<ms::Conductor> named = ms::named_conductor(material);
    if (!named) {
      std::string names;
      for (std::string_view n : ms::named_conductor_names()) names += (names.empty() ? "" : ", ") + std::string(n);
      throw_scene_error(find(o, "material")->where.loc(), "{}: conductor material \"{}\" is not among the presets "
                                                          "candela knows ({}); give eta and k",
                        o.describe(), material, names);
    }
    c.eta = ColorInput(named->eta);
    c.k = ColorInput(named->k);
  }

  int single_nested_bsdf(const Object& o, bool two_sided, int expected = 1) {
    auto bsdfs = nested(o, "bsdf");
    if (int(bsdfs.size()) != expected)
      throw_scene_error(o.where.loc(), "{} needs exactly {} nested bsdf, got {}", o.describe(), expected, bsdfs.size());
    return bsdf(*bsdfs[0].second, two_sided);
  }

  int bsdf(const Object& b, bool two_sided) {
    auto key = std::make_pair(&b, two_sided);
    if (auto it = bsdf_memo_.find(key); it != bsdf_memo_.end()) return it->second;
    const std::string& type = b.type;
    int index = -1;
    if (type == "diffuse") {
      index = one_sided(DiffuseMaterial{color(b, "reflectance", RGB(0.5f))}, two_sided);
    } else if (type == "dielectric" || type == "roughdielectric" || type == "thindielectric") {
      DielectricMaterial d;
      d.ior = relative_ior(b, 1.5046f, 1.000277f);
      d.reflectance = color(b, "specular_reflectance", RGB(1.0f));
      d.transmittance = color(b, "specular_transmittance", RGB(1.0f));
      if (type == "roughdielectric") d.roughness = roughness(b, 0.1f);
      d.thin = type == "thindielectric";
      index = add_material(d);
    } else if (type == "conductor" || type == "roughconductor") {
      ConductorMaterial c;
      conductor_ior(b, c);
      c.specular_tint = color(b, "specular_reflectance", RGB(1.0f));
      if (type == "roughconductor") c.roughness = roughness(b, 0.1f);
      index = one_sided(c, two_sided);
    } else if (type == "plastic" || type == "roughplastic") {
      CoatedDiffuseMaterial c;
      c.reflectance = color(b, "diffuse_reflectance", RGB(0.5f));
      c.specular = color(b, "specular_reflectance", RGB(1.0f));
      c.ior = relative_ior(b, 1.49f, 1.000277f);
      c.nonlinear = get_bool(b, "nonlinear", false);
      if (type == "roughplastic") {
        c.roughness = roughness(b, 0.1f);
        if (!c.roughness.u.is_constant() || c.roughness.u.value != c.roughness.v.value)
          throw_scene_error(b.where.loc(), "roughplastic: Mitsuba's roughplastic is isotropic with a constant alpha");
        c.tabulated_coat = true;  // Mitsuba's tables of the rough coat
      }
      index = one_sided(c, two_sided);
    } else if (type == "twosided") {
      auto bsdfs = nested(b, "bsdf");
      if (bsdfs.empty() || bsdfs.size() > 2)
        throw_scene_error(b.where.loc(), "twosided needs one or two nested bsdfs, got {}", bsdfs.size());
      index = bsdf(*bsdfs[0].second, true);
      // Two BSDFs: the first for the front, the second for the back, each seen as from its front.
      if (bsdfs.size() == 2 && bsdfs[0].second != bsdfs[1].second)
        index = add_material(TwoSidedMaterial{index, bsdf(*bsdfs[1].second, true)});
    } else if (type == "mask") {
      MaskMaterial m;
      m.opacity = float_input(b, "opacity", 0.5f);
      m.material = single_nested_bsdf(b, two_sided);
      index = add_material(m);
    } else if (type == "normalmap") {
      NormalMapMaterial n;
      const Property* p = find(b, "normalmap");
      if (!p) throw_scene_error(b.where.loc(), "normalmap: the texture \"normalmap\" is required");
      if (p->kind != Property::Kind::Object && p->kind != Property::Kind::Ref)
        wrong_kind(b, *p, "a texture");
      n.normal_map = texture(deref(*p));
      if (auto* img = std::get_if<ImageTexture>(&desc_.textures[n.normal_map]); img)
        img->encoding = ColorEncoding::Linear;  // Mitsuba reads normal maps raw
      n.material = single_nested_bsdf(b, two_sided);
      n.options = perturbed_normal_options(b);
      index = add_material(n);
    } else if (type == "bumpmap") {
      BumpMapMaterial m;
      auto textures = nested(b, "texture");
      if (textures.size() != 1) throw_scene_error(b.where.loc(), "bumpmap needs exactly one nested texture");
      m.height = texture(*textures[0].second, TextureLookup::Scalar);  // Mitsuba's eval_1_grad
      m.scale = get_float(b, "scale", 1.0f);
      m.material = single_nested_bsdf(b, two_sided);
      m.options = perturbed_normal_options(b);
      index = add_material(m);
    } else if (type == "blendbsdf") {
      BlendMaterial m;
      m.weight = float_input(b, "weight", 0.5f);
      auto bsdfs = nested(b, "bsdf");
      if (bsdfs.size() != 2) throw_scene_error(b.where.loc(), "blendbsdf needs two nested bsdfs, got {}", bsdfs.size());
      m.material0 = bsdf(*bsdfs[0].second, two_sided);
      m.material1 = bsdf(*bsdfs[1].second, two_sided);
      index = add_material(m);
    } else if (type == "null") {
      index = add_material(InterfaceMaterial{});
    } else if (type == "principled" || type == "principledthin") {
      PrincipledMaterial p;
      p.thin = type == "principledthin";
      p.base_color = color(b, "base_color", RGB(0.5f));
      p.roughness = float_input(b, "roughness", 0.5f);
      p.anisotropic = float_input(b, "anisotropic", 0.0f);
      p.spec_trans = float_input(b, "spec_trans", 0.0f);
      p.specular_tint = float_input(b, "spec_tint", 0.0f);
      p.sheen = float_input(b, "sheen", 0.0f);
      p.sheen_tint = float_input(b, "sheen_tint", 0.0f);
      if (const Property* eta = find(b, "eta"); eta) {
        if (eta->kind != Property::Kind::Float && eta->kind != Property::Kind::Integer) wrong_kind(b, *eta, "a float");
        p.eta = float(eta->number);
        p.eta_given = true;
      }
      if (p.thin) {
        p.diff_trans = float_input(b, "diff_trans", 0.0f);
        p.flatness = float_input(b, "flatness", 0.0f);
        if (!p.eta_given) p.eta = 1.5f, p.eta_given = true;
      } else {
        p.metallic = float_input(b, "metallic", 0.0f);
        p.specular = float_input(b, "specular", 0.5f);
        p.clearcoat = float_input(b, "clearcoat", 0.0f);
        p.clearcoat_gloss = float_input(b, "clearcoat_gloss", 0.0f);
        ignore(b, "main_specular_sampling_rate");
        ignore(b, "clearcoat_sampling_rate");
        ignore(b, "diffuse_reflectance_sampling_rate");
      }
      ignore(b, "spec_trans_sampling_rate");
      ignore(b, "diffuse_transmittance_sampling_rate");
      // Mitsuba's principled scatters from both sides (its transmission lobes need the back), so
      // it is not wrapped in a OneSidedMaterial; the materials engineer implements its side rules.
      index = add_material(p);
    } else {
      throw_scene_error(b.where.loc(), "unknown bsdf type \"{}\"", type);
    }
    check_all_used(b);
    bsdf_memo_[key] = index;
    return index;
  }

  int default_material() {
    if (default_material_ < 0) default_material_ = one_sided(DiffuseMaterial{ColorInput(RGB(0.5f))}, false);
    return default_material_;
  }

  // ------------------------------------------------ shapes

  // The cube of Mitsuba's "cube": [-1, 1]^3 as 24 vertices (per-face normals and uvs), 12 triangles.
  static TriangleMesh cube_mesh() {
    static const float p[24][3] = {{1, -1, -1}, {1, -1, 1},  {-1, -1, 1}, {-1, -1, -1}, {1, 1, -1},  {-1, 1, -1},
                                   {-1, 1, 1},  {1, 1, 1},   {1, -1, -1}, {1, 1, -1},   {1, 1, 1},   {1, -1, 1},
                                   {1, -1, 1},  {1, 1, 1},   {-1, 1, 1},  {-1, -1, 1},  {-1, -1, 1}, {-1, 1, 1},
                                   {-1, 1, -1}, {-1, -1, -1}, {1, 1, -1}, {1, -1, -1},  {-1, -1, -1}, {-1, 1, -1}};
    static const float n[6][3] = {{0, -1, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}};
    static const float uv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    TriangleMesh m;
    for (int i = 0; i < 24; ++i) {
      m.positions.push_back({p[i][0], p[i][1], p[i][2]});
      m.normals.push_back({n[i / 4][0], n[i / 4][1], n[i / 4][2]});
      m.uvs.push_back({uv[i % 4][0], uv[i % 4][1]});
    }
    for (uint32_t f = 0; f < 6; ++f) {
      uint32_t b = 4 * f;
      for (uint32_t k : {b, b + 1, b + 2, b + 3, b, b + 2}) m.indices.push_back(k);
    }
    return m;
  }

  TriangleMesh mesh_file(const Object& s) {
    fs::path file = resolve_file(s, "filename");
    const Property* name = find(s, "filename");
    SourceLocation at = name->where.loc();
    std::string ext = lower(file.extension().string());
    if (s.type == "serialized" && ext != ".serialized")
      throw_scene_error(at, "shape \"serialized\": \"{}\" is not a .serialized file", file.string());
    if (s.type == "obj" && ext != ".obj")
      throw_scene_error(at, "shape \"obj\": \"{}\" is not an .obj file", file.string());
    if (s.type == "ply" && ext != ".ply")
      throw_scene_error(at, "shape \"ply\": \"{}\" is not a .ply file", file.string());
    const int shape_index = s.type == "serialized" ? get_int(s, "shape_index", 0) : 0;
    TriangleMesh mesh = load_mesh_file(file, at, shape_index);
    if (s.type == "obj") {
      // Mitsuba's OBJ loader flips v (flip_tex_coords, on by default) so that its images, looked
      // up with v = 0 at the top row, appear upright; candela keeps Mitsuba's uvs.
      if (get_bool(s, "flip_tex_coords", true))
        for (Vec2& t : mesh.uvs) t.y = 1 - t.y;
    }
    if (get_bool(s, "face_normals", false)) mesh.normals.clear();
    return mesh;
  }

  // Mitsuba's sdfgrid: a one-channel .vol file; any to_world is accepted (Mitsuba warns about
  // rotations, which its own intersection handles too).
  SdfGridShape sdf_grid(const Object& s) {
    const std::string normals = get_string(s, "normals", "smooth");
    if (normals != "smooth" && normals != "analytic")
      throw_scene_error(find(s, "normals")->where.loc(), "sdfgrid: normals \"{}\" must be \"smooth\" or \"analytic\"",
                        normals);
    const fs::path file = resolve_file(s, "filename");
    return read_sdf_grid_file(file, find(s, "filename")->where.loc(),
                              normals == "smooth" ? SdfNormals::Smooth : SdfNormals::Analytic);
  }

  void shape(const Object& s, ObjectDesc* group) {
    ShapeDesc out;
    out.name = s.id.empty() ? s.type : s.id;
    out.to_world = get_transform(s, "to_world");
    const std::string& type = s.type;
    if (type == "obj" || type == "ply" || type == "serialized") {
      out.geometry = MeshShape{mesh_file(s)};
    } else if (type == "sphere") {
      SphereShape sp;
      if (std::optional<Vec3> c = get_vector(s, "center"); c) sp.center = *c;
      sp.radius = get_float(s, "radius", 1.0f);
      if (!(sp.radius > 0)) throw_scene_error(s.where.loc(), "sphere: the radius must be positive");
      out.geometry = sp;
    } else if (type == "rectangle") {
      out.geometry = RectangleShape{};
    } else if (type == "cube") {
      out.geometry = MeshShape{cube_mesh()};
    } else if (type == "disk") {
      out.geometry = DiskShape{};
    } else if (type == "cylinder") {
      CylinderShape c;
      if (std::optional<Vec3> p0 = get_vector(s, "p0"); p0) c.p0 = *p0;
      if (std::optional<Vec3> p1 = get_vector(s, "p1"); p1) c.p1 = *p1;
      c.radius = get_float(s, "radius", 1.0f);
      if (!(c.radius > 0) || length(c.p1 - c.p0) == 0)
        throw_scene_error(s.where.loc(), "cylinder: needs a positive radius and p0 != p1");
      out.geometry = c;
    } else if (type == "sdfgrid") {
      out.geometry = sdf_grid(s);
    } else if (type == "instance") {
      if (group) throw_scene_error(s.where.loc(), "an instance cannot be inside a shapegroup");
      auto groups = nested(s, "shape");
      if (groups.size() != 1 || groups[0].second->type != "shapegroup")
        throw_scene_error(s.where.loc(), "instance needs exactly one reference to a shapegroup");
      InstanceDesc inst;
      inst.object = shapegroup(*groups[0].second);
      inst.to_world = out.to_world;
      check_all_used(s);
      desc_.instances.push_back(inst);
      return;
    } else if (type == "shapegroup") {
      throw_scene_error(s.where.loc(), "a shapegroup cannot be nested in another shape");
    } else {
      throw_scene_error(s.where.loc(), "unknown shape type \"{}\" (supported: obj, ply, serialized, sphere, rectangle, "
                                       "cube, disk, cylinder, sdfgrid, shapegroup, instance)",
                        type);
    }
    out.reverse_orientation = get_bool(s, "flip_normals", false);
    auto bsdfs = nested(s, "bsdf");
    if (bsdfs.size() > 1) throw_scene_error(bsdfs[1].first->where.loc(), "a shape can have only one bsdf");
    out.material = bsdfs.empty() ? default_material() : bsdf(*bsdfs[0].second, false);
    auto emitters = nested(s, "emitter");
    if (emitters.size() > 1) throw_scene_error(emitters[1].first->where.loc(), "a shape can have only one emitter");
    if (!emitters.empty()) {
      const Object& e = *emitters[0].second;
      if (e.type != "area")
        throw_scene_error(e.where.loc(), "emitter \"{}\" cannot be attached to a shape (only \"area\" can)", e.type);
      if (type == "sdfgrid")
        throw_scene_error(e.where.loc(), "an sdfgrid cannot be an area emitter (nor can it in Mitsuba)");
      if (group) throw_scene_error(e.where.loc(), "emitters inside a shapegroup are not supported");
      AreaEmission em;
      ColorInput radiance = color(e, "radiance", RGB(1.0f), true);
      if (radiance.is_constant()) {
        em.radiance = radiance.value;
      } else {
        em.radiance = RGB(1.0f);
        em.texture = radiance.texture;
      }
      check_all_used(e);
      out.emission = em;
    }
    check_all_used(s);
    if (group) group->shapes.push_back(std::move(out));
    else desc_.shapes.push_back(std::move(out));
  }

  int shapegroup(const Object& g) {
    if (auto it = group_memo_.find(&g); it != group_memo_.end()) return it->second;
    ObjectDesc obj;
    obj.name = g.id;
    for (const Property& p : g.props) {
      if (p.kind != Property::Kind::Object && p.kind != Property::Kind::Ref) continue;
      const Object& child = deref(p);
      if (child.tag != "shape") continue;
      p.used = true;
      if (child.type == "shapegroup" || child.type == "instance")
        throw_scene_error(child.where.loc(), "a shapegroup cannot hold a {}", child.type);
      shape(child, &obj);
    }
    check_all_used(g);
    if (obj.shapes.empty()) throw_scene_error(g.where.loc(), "the shapegroup holds no shapes");
    desc_.objects.push_back(std::move(obj));
    int index = int(desc_.objects.size()) - 1;
    group_memo_[&g] = index;
    return index;
  }

  // ------------------------------------------------ emitters

  static Vec3 origin_of(const Transform& t) { return t.point({0, 0, 0}); }

  void emitter(const Object& e) {
    const std::string& type = e.type;
    if (type == "point") {
      PointLight l;
      Transform t = get_transform(e, "to_world");
      l.position = origin_of(t);
      if (std::optional<Vec3> p = get_vector(e, "position"); p) {
        if (!t.is_identity()) throw_scene_error(e.where.loc(), "point: give either position or to_world");
        l.position = *p;
      }
      l.intensity = constant_color(e, "intensity", RGB(1.0f));
      desc_.lights.push_back(l);
    } else if (type == "constant") {
      SkyLight l;
      l.zenith = l.horizon = l.ground = constant_color(e, "radiance", RGB(1.0f));
      desc_.lights.push_back(l);
    } else if (type == "envmap") {
      EnvironmentMap l;
      l.filename = resolve_file(e, "filename").string();
      l.scale = RGB(get_float(e, "scale", 1.0f));
      l.to_world = get_transform(e, "to_world");
      l.mapping = EnvironmentMapping::EquirectangularPoleRows;
      l.mis_compensation = get_bool(e, "mis_compensation", false);
      ignore(e, "filter_type");
      desc_.lights.push_back(l);
    } else if (type == "directional") {
      DistantLight l;
      Transform t = get_transform(e, "to_world");
      l.direction = normalize(t.vector({0, 0, 1}));
      if (std::optional<Vec3> d = get_vector(e, "direction"); d) {
        if (!t.is_identity()) throw_scene_error(e.where.loc(), "directional: give either direction or to_world");
        if (length(*d) == 0) throw_scene_error(e.where.loc(), "directional: the direction is zero");
        l.direction = normalize(*d);
      }
      l.radiance = constant_color(e, "irradiance", RGB(1.0f));
      desc_.lights.push_back(l);
    } else if (type == "spot") {
      SpotLight l;
      Transform t = get_transform(e, "to_world");
      l.position = origin_of(t);
      l.direction = normalize(t.vector({0, 0, 1}));
      l.up = normalize(t.vector({0, 1, 0}));
      l.intensity = constant_color(e, "intensity", RGB(1.0f));
      float cutoff = get_float(e, "cutoff_angle", 20.0f);
      float beam = get_float(e, "beam_width", cutoff * 0.75f);
      if (!(cutoff > 0 && cutoff <= 90) || !(beam >= 0 && beam <= cutoff))
        throw_scene_error(e.where.loc(), "spot: needs 0 < beam_width <= cutoff_angle <= 90");
      l.cone_angle = cutoff;
      l.cone_delta = cutoff - beam;
      l.mitsuba_falloff = true;
      if (const Property* p = find(e, "texture"); p) {
        if (p->kind != Property::Kind::Object && p->kind != Property::Kind::Ref) wrong_kind(e, *p, "a texture");
        l.texture = texture(deref(*p));
      }
      desc_.lights.push_back(l);
    } else if (type == "projector") {
      ProjectorLight l;
      l.to_world = get_transform(e, "to_world");
      ColorInput irr = color(e, "irradiance", RGB(1.0f), true);
      l.irradiance = irr.is_constant() ? constant_texture(irr.value) : irr.texture;
      l.scale = RGB(get_float(e, "scale", 1.0f));
      std::string axis = get_string(e, "fov_axis", "x");
      if (!find(e, "fov")) axis = "diagonal";  // Mitsuba's default focal length of 50 mm
      float fov = get_float(e, "fov", kDefaultFovDiagonal);
      // Mitsuba's fov is on fov_axis of the image; candela's on the wider axis.
      auto [w, h] = texture_size(l.irradiance);
      float fov_x = fov, t = std::tan(radians(fov) / 2);
      if (axis == "y") fov_x = 2 * std::atan(t * float(w) / float(h)) * 180 / kPi;
      else if (axis == "diagonal") fov_x = 2 * std::atan(t * float(w) / std::hypot(float(w), float(h))) * 180 / kPi;
      else if (axis != "x") throw_scene_error(e.where.loc(), "projector: fov_axis \"{}\" (use x, y or diagonal)", axis);
      l.fov_degrees = w >= h ? fov_x : 2 * std::atan(std::tan(radians(fov_x) / 2) * float(h) / float(w)) * 180 / kPi;
      desc_.lights.push_back(l);
    } else if (type == "area") {
      throw_scene_error(e.where.loc(), "an area emitter must be inside the shape it lights");
    } else {
      throw_scene_error(e.where.loc(), "unknown emitter type \"{}\" (supported: area, point, spot, projector, "
                                       "directional, constant, envmap)",
                        type);
    }
    check_all_used(e);
  }

  RGB constant_color(const Object& o, std::string_view name, RGB fallback) {
    ColorInput c = color(o, name, fallback, true);
    if (!c.is_constant())
      throw_scene_error(find(o, name)->where.loc(), "{}: a textured \"{}\" is not supported", o.describe(), name);
    return c.value;
  }

  std::pair<int, int> texture_size(int index) {
    const auto* img = std::get_if<ImageTexture>(&desc_.textures[index]);
    if (!img) return {1, 1};
    auto in = OIIO::ImageInput::open(img->filename);
    if (!in) return {1, 1};
    const OIIO::ImageSpec& spec = in->spec();
    return {std::max(1, spec.width), std::max(1, spec.height)};
  }

  // ------------------------------------------------ sensor, film, sampler, integrator

  static FilterDesc gaussian_filter(float stddev) {
    FilterDesc f;
    f.type = FilterType::Gaussian;
    f.gaussian_sigma = stddev;
    f.radius = {4 * stddev, 4 * stddev};  // Mitsuba truncates its gaussian at 4 standard deviations
    return f;
  }

  void sensor(const Object& s) {
    CameraDesc& cam = desc_.camera;
    Transform to_world = get_transform(s, "to_world");
    // Mitsuba's camera space has +x to the image's left; candela's to its right.
    cam.world_from_camera = to_world * Transform::scale({-1, 1, 1});
    cam.near_clip = get_float(s, "near_clip", 0.01f);
    float far_clip = get_float(s, "far_clip", 10000.0f);
    if (!(cam.near_clip > 0) || !(far_clip > cam.near_clip))
      throw_scene_error(s.where.loc(), "{}: needs 0 < near_clip < far_clip", s.describe());
    if (far_clip < 1e3f * 0.999f)
      warn(s.where, "{}: far_clip {} is ignored: candela sees everything beyond near_clip", s.describe(), far_clip);
    for (const char* name : {"principal_point_offset_x", "principal_point_offset_y"})
      if (get_float(s, name, 0) != 0)
        throw_scene_error(s.where.loc(), "{}: {} is not supported", s.describe(), name);
    ignore(s, "shutter_open");
    ignore(s, "shutter_close");
    ignore(s, "srf", nullptr);
    if (s.type == "perspective" || s.type == "thinlens") {
      cam.projection = Projection::Perspective;
      std::string axis = get_string(s, "fov_axis", "x");
      if (axis == "x") cam.fov_axis = FovAxis::X;
      else if (axis == "y") cam.fov_axis = FovAxis::Y;
      else if (axis == "diagonal") cam.fov_axis = FovAxis::Diagonal;
      else if (axis == "smaller") cam.fov_axis = FovAxis::Smaller;
      else if (axis == "larger") cam.fov_axis = FovAxis::Larger;
      else throw_scene_error(s.where.loc(), "{}: fov_axis \"{}\" (use x, y, diagonal, smaller or larger)",
                             s.describe(), axis);
      const Property* fov = find(s, "fov");
      std::string focal = get_string(s, "focal_length", "");
      if (fov && !focal.empty()) throw_scene_error(s.where.loc(), "{}: give either fov or focal_length", s.describe());
      if (fov) {
        cam.fov_degrees = get_float(s, "fov", 0);
      } else {
        if (focal.empty()) focal = "50mm";
        std::string digits = focal.ends_with("mm") ? focal.substr(0, focal.size() - 2) : focal;
        std::optional<double> mm = parse_double(digits);
        if (!mm || !(*mm > 0)) throw_scene_error(s.where.loc(), "{}: focal_length \"{}\"", s.describe(), focal);
        // Mitsuba: the 35 mm film equivalent, on the film's diagonal.
        cam.fov_degrees = diagonal_fov_from_focal_length(*mm);
        cam.fov_axis = FovAxis::Diagonal;
      }
      if (!(cam.fov_degrees > 0 && cam.fov_degrees < 180))
        throw_scene_error(s.where.loc(), "{}: fov must be in (0, 180)", s.describe());
      if (s.type == "thinlens") {
        cam.lens_radius = get_float(s, "aperture_radius", 1.0f);
        cam.focus_distance = get_float(s, "focus_distance", 0);
        if (!(cam.focus_distance > 0)) throw_scene_error(s.where.loc(), "thinlens: focus_distance is required");
      }
    } else if (s.type == "orthographic") {
      cam.projection = Projection::Orthographic;
    } else {
      throw_scene_error(s.where.loc(), "unknown sensor type \"{}\" (supported: perspective, thinlens, orthographic)",
                        s.type);
    }
    for (auto& [prop, o] : nested(s, "film")) film(*o);
    for (auto& [prop, o] : nested(s, "sampler")) sampler(*o);
    check_all_used(s);
  }

  void film(const Object& f) {
    if (f.type != "hdrfilm" && f.type != "specfilm")
      throw_scene_error(f.where.loc(), "unknown film type \"{}\" (supported: hdrfilm)", f.type);
    desc_.film.width = get_int(f, "width", 768);
    desc_.film.height = get_int(f, "height", 576);
    if (desc_.film.width <= 0 || desc_.film.height <= 0 || desc_.film.width > 65536 || desc_.film.height > 65536)
      throw_scene_error(f.where.loc(), "hdrfilm: width and height must be in 1..65536");
    int cx = get_int(f, "crop_offset_x", 0), cy = get_int(f, "crop_offset_y", 0);
    int cw = get_int(f, "crop_width", desc_.film.width), ch = get_int(f, "crop_height", desc_.film.height);
    if (cx != 0 || cy != 0 || cw != desc_.film.width || ch != desc_.film.height)
      throw_scene_error(f.where.loc(), "hdrfilm: crop windows are not supported");
    std::string pixel_format = get_string(f, "pixel_format", "rgb");
    if (pixel_format != "rgb" && pixel_format != "rgba")
      warn(f.where, "hdrfilm: pixel_format \"{}\" is written as RGB", pixel_format);
    ignore(f, "component_format");
    ignore(f, "file_format");
    ignore(f, "banner");
    ignore(f, "rfilter");
    ignore(f, "compensate");
    ignore(f, "sample_border");
    for (auto& [prop, o] : nested(f, "rfilter")) rfilter(*o);
    check_all_used(f);
  }

  void rfilter(const Object& r) {
    FilterDesc& f = desc_.settings.filter;
    if (r.type == "box") {
      f = default_filter(FilterType::Box);
      float radius = get_float(r, "radius", 0.5f);
      f.radius = {radius, radius};
    } else if (r.type == "gaussian") {
      f = gaussian_filter(get_float(r, "stddev", 0.5f));
    } else if (r.type == "tent") {
      f = default_filter(FilterType::Tent);
      float radius = get_float(r, "radius", 1.0f);
      f.radius = {radius, radius};
    } else if (r.type == "mitchell" || r.type == "catmullrom") {
      f = default_filter(FilterType::Mitchell);
      f.mitchell_b = get_float(r, "B", r.type == "mitchell" ? 1.0f / 3 : 0.0f);
      f.mitchell_c = get_float(r, "C", r.type == "mitchell" ? 1.0f / 3 : 0.5f);
      f.radius = {2, 2};
    } else {
      throw_scene_error(r.where.loc(), "unknown rfilter type \"{}\" (supported: box, gaussian, tent, mitchell, "
                                       "catmullrom)",
                        r.type);
    }
    check_all_used(r);
  }

  void sampler(const Object& s) {
    RenderSettings& rs = desc_.settings;
    rs.spp = get_int(s, "sample_count", 4);
    if (rs.spp <= 0) throw_scene_error(s.where.loc(), "sampler: sample_count must be positive");
    rs.seed = uint64_t(get_int(s, "seed", 0));
    if (s.type == "independent") {
      rs.sampler.type = SamplerType::Independent;
    } else if (s.type == "stratified" || s.type == "multijitter" || s.type == "orthogonal") {
      rs.sampler.type = SamplerType::Stratified;
      rs.sampler.jitter = get_bool(s, "jitter", true);
      if (s.type == "orthogonal") ignore(s, "strength");
      warn(s.where, "sampler \"{}\": using candela's stratified sampler", s.type);
    } else if (s.type == "ldsampler") {
      rs.sampler.type = SamplerType::ZSobol;
      warn(s.where, "sampler \"ldsampler\": using candela's zsobol sampler");
    } else {
      throw_scene_error(s.where.loc(), "unknown sampler type \"{}\"", s.type);
    }
    check_all_used(s);
  }

  // Mitsuba's max_depth counts path segments (1: emitters seen directly, 2: direct lighting);
  // candela's counts scattering events.
  static int candela_depth(int mitsuba_depth) {
    if (mitsuba_depth < 0) return kUnboundedDepth;
    return std::max(0, mitsuba_depth - 1);
  }

  void integrator(const Object& i) {
    RenderSettings& rs = desc_.settings;
    if (i.type == "moment") {
      auto inner = nested(i, "integrator");
      if (inner.size() != 1) throw_scene_error(i.where.loc(), "moment needs one nested integrator");
      warn(i.where, "integrator \"moment\": rendering its nested integrator (candela's film keeps the second moments)");
      check_all_used(i);
      integrator(*inner[0].second);
      return;
    }
    if (i.type == "path" || i.type == "ptracer" || i.type == "volpath" || i.type == "volpathmis") {
      // A particle tracer's strength, paths from the lights connected to the camera, is BDPT's
      // t = 1 strategy: BDPT renders ptracer scenes with it (and the other strategies, under MIS).
      rs.integrator = i.type == "ptracer" ? "bdpt" : "path";
      rs.max_depth = candela_depth(get_int(i, "max_depth", -1));
      int rr = get_int(i, "rr_depth", 5);
      rs.rr_start_depth = std::max(1, rr - 1);
      rs.hide_emitters = get_bool(i, "hide_emitters", false);
      if (i.type == "ptracer")
        warn(i.where, "integrator \"ptracer\": rendering with candela's bidirectional path tracer (the same expectation)");
      if (i.type != "path" && i.type != "ptracer")
        warn(i.where, "integrator \"{}\": rendering with candela's path tracer (no participating media)", i.type);
      ignore(i, "samples_per_pass");
    } else if (i.type == "direct") {
      rs.integrator = "path";
      rs.max_depth = 1;
      int es = get_int(i, "emitter_samples", get_int(i, "shading_samples", 1));
      int bs = get_int(i, "bsdf_samples", find(i, "shading_samples") ? es : 1);
      if (es != 1 || bs != 1)
        warn(i.where, "integrator \"direct\": emitter_samples/bsdf_samples are ignored (one of each, with MIS)");
      rs.hide_emitters = get_bool(i, "hide_emitters", false);
    } else {
      throw_scene_error(i.where.loc(), "unknown integrator type \"{}\" (supported: path, direct, ptracer, moment)",
                        i.type);
    }
    check_all_used(i);
  }

  XmlParser& parser_;
  std::vector<std::string>& warnings_;
  SceneDesc desc_;
  // A texture once per way it is looked up (see TextureLookup).
  std::map<std::pair<const Object*, TextureLookup>, int> texture_memo_;
  std::map<std::pair<const Object*, bool>, int> bsdf_memo_;
  std::map<const Object*, int> group_memo_;
  int default_material_ = -1;
};

SceneDesc read(std::string_view text, const std::string& file_name, const fs::path& base_dir,
               std::vector<std::string>& warnings, const MitsubaReadOptions& options) {
  XmlParser parser(warnings, options);
  Object* scene = parser.parse_root(text, file_name, base_dir);
  Converter converter(parser, warnings);
  SceneDesc desc = converter.convert(*scene);
  desc.source_file = file_name;
  return desc;
}

}  // namespace

SceneDesc read_mitsuba_scene_text(std::string_view xml, const std::string& file_name,
                                  const std::filesystem::path& base_dir, std::vector<std::string>& warnings,
                                  const MitsubaReadOptions& options) {
  return read(xml, file_name, base_dir, warnings, options);
}

SceneDesc read_mitsuba_scene(const std::filesystem::path& file, std::vector<std::string>& warnings,
                             const MitsubaReadOptions& options) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_scene_error(SourceLocation{file.string(), 0, 0, {}}, "cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  fs::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  return read(text.str(), file.string(), dir, warnings, options);
}

SceneDesc read_mitsuba_scene(const std::filesystem::path& file) {
  std::vector<std::string> warnings;
  try {
    SceneDesc scene = read_mitsuba_scene(file, warnings);
    for (const std::string& w : warnings) std::cerr << w << "\n";
    return scene;
  } catch (...) {
    for (const std::string& w : warnings) std::cerr << w << "\n";
    throw;
  }
}

}  // namespace candela
