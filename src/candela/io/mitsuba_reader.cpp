// Reader for Mitsuba 3 XML scenes (the subset in docs/mitsuba-format.md).
//
// Two passes. The first reads the XML (pugixml) into a tree of objects with their properties, as
// Mitsuba's parser does: $parameters substituted, <default>, <include> and <path> handled,
// transforms composed, nested objects and <ref>s kept by name. The second turns each object into
// candela's description, plugin by plugin, with Mitsuba's defaults; every property must be read by
// the plugin that owns it (an unknown parameter is an error, as in Mitsuba). What candela reads but
// cannot reproduce exactly is a warning; what would change the image materially is an error.
//
// The parts are in io/mitsuba/: object_tree.h and xml_parser.cpp (the first pass), converter.h and
// the files it names (the second).
#include "candela/io/mitsuba_reader.h"

#include <fstream>
#include <sstream>

#include "candela/io/mitsuba/converter.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

SceneDesc read(std::string_view text, const std::string& file_name, const fs::path& base_dir,
               Warnings& warnings, const MitsubaReadOptions& options) {
  const mitsuba::ObjectTree tree = mitsuba::parse_xml(text, file_name, base_dir, options);
  SceneDesc desc = mitsuba::Converter(tree, warnings).convert(*tree.root);
  desc.source_file = file_name;
  return desc;
}

}  // namespace

SceneDesc read_mitsuba_scene_text(std::string_view xml, const std::string& file_name,
                                  const std::filesystem::path& base_dir, Warnings& warnings,
                                  const MitsubaReadOptions& options) {
  return read(xml, file_name, base_dir, warnings, options);
}

SceneDesc read_mitsuba_scene(const std::filesystem::path& file, Warnings& warnings,
                             const MitsubaReadOptions& options) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_scene_error(SourceLocation{file.string(), 0, 0, {}}, "cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  fs::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  return read(text.str(), file.string(), dir, warnings, options);
}

SceneDesc read_mitsuba_scene(const std::filesystem::path& file, const MitsubaReadOptions& options) {
  return read_printing_warnings([&](Warnings& warnings) { return read_mitsuba_scene(file, warnings, options); });
}

}  // namespace candela
