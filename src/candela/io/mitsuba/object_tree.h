#pragma once
// The first pass of the Mitsuba reader: the XML (pugixml) read into a tree of objects with their
// properties, as Mitsuba's parser does: $parameters substituted, <default>, <include> and <path>
// handled, transforms composed, nested objects and <ref>s kept by name.
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mitsuba_reader.h"
#include "candela/io/parameter_usage.h"
#include "candela/math/transform.h"

namespace candela::mitsuba {

struct Where {
  std::shared_ptr<const std::string> file;
  int line = 0;
  int column = 0;  // of the element's '<'
  // For messages: file:line, as Mitsuba's parser names places.
  SourceLocation loc() const { return {file ? *file : std::string(), line, 0, {}}; }
  // The element's place with its column, for SceneDesc's source locations.
  SourceLocation place() const { return {file ? *file : std::string(), line, column, {}}; }
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
};

const char* kind_name(Property::Kind kind);

struct Object {
  std::string tag;   // scene, bsdf, shape, emitter, sensor, film, rfilter, sampler, integrator, texture, spectrum
  std::string type;  // the plugin
  std::string id;
  Where where;
  std::vector<Property> props;
  // Which of `props` the converter has read (in the same order): each must be, or the plugin
  // rejects the scene.
  mutable ParameterUsage usage;
  void add(Property p) {
    usage.give(p.name, p.where.loc());
    props.push_back(std::move(p));
  }
  std::string describe() const { return fmt::format("{} \"{}\"", tag, type); }
};

// The parsed scene: the objects (owned here; properties point to their nested ones), the ids
// they were given, and the folders files are looked up in.
struct ObjectTree {
  std::deque<std::unique_ptr<Object>> objects;
  std::unordered_map<std::string, Object*> ids;
  std::vector<std::filesystem::path> search_paths;  // the scene's folder, then each <path>
  const Object* root = nullptr;                      // the <scene>

  // Resolves a file name as Mitsuba's FileResolver: the <path> folders (latest first), then the
  // scene's folder.
  std::optional<std::filesystem::path> resolve(const std::string& name) const;
  std::string search_path_text() const;  // the folders resolve searches, for messages
};

// Reads the XML text of a scene; `file_name` names it in messages and relative paths resolve
// against `base_dir`. Throws SceneError for the first error.
ObjectTree parse_xml(std::string_view text, const std::string& file_name, const std::filesystem::path& base_dir,
                     const MitsubaReadOptions& options);

// ---------------------------------------------------------------- text helpers

std::string trim(std::string_view s);
// Mitsuba's tokenizer: commas and whitespace separate.
std::vector<std::string> tokenize(std::string_view s, std::string_view delimiters = ", \t\r\n");
std::optional<double> parse_double(std::string_view s);
std::string lower(std::string_view s);

}  // namespace candela::mitsuba
