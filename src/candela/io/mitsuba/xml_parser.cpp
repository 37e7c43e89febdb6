// The first pass of the Mitsuba reader: XML to the object tree (object_tree.h).
#include <pugixml.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <set>
#include <utility>

#include "candela/io/mitsuba/object_tree.h"
#include "candela/io/spectrum_file.h"

namespace candela::mitsuba {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxIncludeDepth = 15;     // Mitsuba's MI_XML_INCLUDE_MAX_RECURSION
// Files included in all: 15 levels of files that each include the next ten times would read 10^15.
constexpr int kMaxIncludes = 100000;
// Objects inside objects (a bsdf in a bsdf...): parsed recursively, so a hostile file nesting them
// 100,000 deep would overflow the stack. Real scenes nest a handful.
constexpr int kMaxObjectDepth = 100;

bool is_object_tag(std::string_view tag) {
  static const std::set<std::string_view> tags = {"scene",   "bsdf",       "shape",   "emitter", "sensor",
                                                  "film",    "rfilter",    "sampler", "integrator",
                                                  "texture", "medium",     "phase",   "volume"};
  return tags.contains(tag);
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

// ---------------------------------------------------------------- XML to objects

class XmlParser {
 public:
  explicit XmlParser(const MitsubaReadOptions& options) {
    for (const auto& [name, value] : options.parameters) params_.emplace_back(name, value);
  }

  ObjectTree parse(std::string_view text, const std::string& file_name, const fs::path& base_dir) {
    tree_.search_paths.push_back(base_dir);
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
    tree_.root = scene;
    return std::move(tree_);
  }

 private:
  std::optional<fs::path> resolve(const std::string& name) const { return tree_.resolve(name); }
  std::string search_path_text() const { return tree_.search_path_text(); }

  struct Document {
    std::shared_ptr<pugi::xml_document> xml;
    std::shared_ptr<const std::string> file;
    std::vector<size_t> line_starts;
    fs::path dir;
    Where where(const pugi::xml_node& node) const {
      ptrdiff_t offset = node.offset_debug();  // an element's: of its name, after the '<'
      int line = 0, column = 0;
      if (offset >= 0) {
        line = int(std::upper_bound(line_starts.begin(), line_starts.end(), size_t(offset)) - line_starts.begin());
        column = std::max(1, int(size_t(offset) - line_starts[size_t(line) - 1]));
      }
      return {file, line, column};
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
    tree_.objects.push_back(std::make_unique<Object>());
    Object* o = tree_.objects.back().get();
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
      parent.add(std::move(p));
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
      if (depth > kMaxObjectDepth)
        throw_scene_error(where.loc(), "<{}> is nested more than {} objects deep", tag, kMaxObjectDepth);
      check_attributes(doc, node, {"type", "id", "name", "version"});
      Object* o = new_object(tag, required(doc, node, "type"), where);
      if (pugi::xml_attribute id = node.attribute("id")) {
        o->id = id.value();
        if (o->id.starts_with("_")) throw_scene_error(where.loc(), "ids starting with '_' are reserved");
        auto [it, inserted] = tree_.ids.emplace(o->id, o);
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
      tree_.search_paths.push_back(p.lexically_normal());
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
      auto it = tree_.ids.find(id);
      if (it == tree_.ids.end()) throw_scene_error(where.loc(), "<alias>: no object has the id \"{}\"", id);
      if (!tree_.ids.emplace(as, it->second).second) throw_scene_error(where.loc(), "duplicate id \"{}\"", as);
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

  // Mitsuba's spectrum files (io/spectrum_file.h): "wavelength value" pairs (nm), increasing. The
  // pairs then mean exactly what inline wavelength:value pairs mean.
  void read_spectrum_file(const Document& doc, const std::string& name, const Where& where, Property& p) {
    fs::path file = doc.dir / name;
    if (!fs::exists(file)) {
      std::optional<fs::path> found = resolve(name);
      if (!found) throw_scene_error(where.loc(), "<spectrum>: file \"{}\" not found (searched {})", name, search_path_text());
      file = *found;
    }
    std::vector<double> pairs = candela::read_spectrum_file(file);
    for (size_t i = 0; i < pairs.size(); i += 2) {
      p.wavelengths.push_back(pairs[i]);
      p.values.push_back(pairs[i + 1]);
    }
    if (p.wavelengths.size() < 2)
      throw_scene_error(where.loc(), "<spectrum>: \"{}\" holds fewer than two wavelength-value pairs", file.string());
  }

  void include(const Document& doc, pugi::xml_node node, Object& parent, int depth, const Where& where) {
    std::string name = required(doc, node, "filename");
    if (++include_depth_ > kMaxIncludeDepth)
      throw_scene_error(where.loc(), "more than {} nested <include>s (an include cycle?)", kMaxIncludeDepth);
    if (++includes_read_ > kMaxIncludes)
      throw_scene_error(where.loc(), "more than {} <include>s in all (a file included many times over?)", kMaxIncludes);
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

  ObjectTree tree_;
  std::vector<std::pair<std::string, std::string>> params_;
  int arg_counter_ = 0;
  int include_depth_ = 0;
  int includes_read_ = 0;
};

}  // namespace

ObjectTree parse_xml(std::string_view text, const std::string& file_name, const fs::path& base_dir,
                     const MitsubaReadOptions& options) {
  XmlParser parser(options);
  return parser.parse(text, file_name, base_dir);
}

}  // namespace candela::mitsuba
