// The document: parsed by nlohmann, checked for repeated keys, its sections read in order.
#include "candela/io/json/reader.h"

namespace candela::json {

SceneDesc JsonSceneReader::read() {
  Json document = parse_document();
  reject_duplicate_keys();
  CheckedObject root(report_, document, "");
  const Json empty = Json::object();  // absent sections still get their defaults
  if (const Json* media = root.find("media")) read_media(*media, root.pointer_of("media"));
  // Before the camera and the shapes, which name its nodes and deformations.
  if (const Json* animation = root.find("animation")) read_animation(*animation, root.pointer_of("animation"));
  const Json* camera = root.find("camera");
  read_camera(camera ? *camera : empty, root.pointer_of("camera"));
  const Json* render = root.find("render");
  read_render(render ? *render : empty, root.pointer_of("render"));
  if (const Json* textures = root.find("textures")) read_textures(*textures, root.pointer_of("textures"));
  if (const Json* materials = root.find("materials")) read_materials(*materials, root.pointer_of("materials"));
  if (const Json* objects = root.find("objects")) read_objects(*objects, root.pointer_of("objects"));
  if (const Json* shapes = root.find("shapes")) read_shapes(*shapes, root.pointer_of("shapes"));
  if (const Json* lights = root.find("lights")) read_lights(*lights, root.pointer_of("lights"));
  root.finish();
  // Each part was checked where it was read; this is the model's own check of the whole.
  if (std::string problem = scene_.animation.problem(); !problem.empty())
    report_.fail(root.pointer_of("animation"), "{}", problem);
  scene_.source_file = report_.file_name();
  locate_places();
  return std::move(scene_);
}

SourceLocation JsonSceneReader::place(const std::string& pointer) const {
  return {report_.file_name(), 0, 0, pointer};
}

// The entries' places were recorded as JSON pointers while reading; their lines and columns are
// found in one more walk over the text (ErrorReporter::locate).
void JsonSceneReader::locate_places() {
  std::vector<SourceLocation*> places;
  auto add = [&](SourceLocation& where) {
    if (!where.file.empty()) places.push_back(&where);
  };
  for (std::vector<SourceLocation>* list : {&scene_.places.textures, &scene_.places.materials, &scene_.places.lights})
    for (SourceLocation& where : *list) add(where);
  for (ShapeDesc& shape : scene_.shapes) add(shape.where);
  for (ObjectDesc& object : scene_.objects) {
    add(object.where);
    for (ShapeDesc& shape : object.shapes) add(shape.where);
  }
  for (InstanceDesc& instance : scene_.instances) add(instance.where);
  for (MediumDesc& medium : scene_.media) add(medium.where);
  report_.locate(places);
}

Json JsonSceneReader::parse_document() const {
  try {
    return Json::parse(text_.begin(), text_.end());
  } catch (const Json::parse_error& e) {
    size_t offset = e.byte == 0 ? 0 : e.byte - 1;  // e.byte is 1-based: the last byte read
    throw_scene_error(report_.location_of_offset(offset), "malformed JSON: {}", parse_error_reason(e.what()));
  } catch (const Json::out_of_range& e) {
    throw_number_overflow(e.what());
  }
}

// nlohmann rejects numbers beyond double's range ("number overflow parsing '1e999'") without a
// position; the literal itself is found in the text instead.
void JsonSceneReader::throw_number_overflow(std::string_view what) const {
  size_t open = what.find('\''), close = what.rfind('\'');
  std::string_view literal = open < close ? what.substr(open + 1, close - open - 1) : std::string_view();
  size_t offset = literal.empty() ? std::string_view::npos : text_.find(literal);
  SourceLocation where = offset == std::string_view::npos ? SourceLocation{report_.file_name(), 0, 0, {}}
                                                          : report_.location_of_offset(offset);
  throw_scene_error(where, "number {} is out of range", literal);
}

// nlohmann's message repeats its own position: keep only the reason after it.
std::string JsonSceneReader::parse_error_reason(std::string_view what) {
  size_t start = what.find("parse error");
  size_t colon = what.find(": ", start == std::string_view::npos ? 0 : start);
  return std::string(colon == std::string_view::npos ? what : what.substr(colon + 2));
}

void JsonSceneReader::reject_duplicate_keys() const {
  if (auto duplicate = first_duplicate_key(text_))
    throw_scene_error(report_.location_of_offset(duplicate->offset, duplicate->pointer),
                      "duplicate key (each key may appear only once in an object)");
}

}  // namespace candela::json
