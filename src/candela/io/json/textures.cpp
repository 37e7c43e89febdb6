#include "candela/io/json/reader.h"

namespace candela::json {

// ---- textures

std::vector<std::string> JsonSceneReader::collect_named(const Json& value, const std::string& pointer,
                                                        std::string_view kind, NamedEntries& entries) {
  if (!value.is_object())
    report_.fail(pointer, "expected an object mapping {} names to {}s, got {}", kind, kind, describe(value));
  std::vector<std::string> names;
  for (auto it = value.begin(); it != value.end(); ++it) {
    if (it.key() == "_comment") continue;
    names.push_back(it.key());
    entries[it.key()] = NamedEntry{&it.value(), child_pointer(pointer, it.key())};
  }
  return names;
}

JsonSceneReader::NamedEntry& JsonSceneReader::find_named(NamedEntries& entries, const std::string& name,
                                                         const std::string& pointer, std::string_view kind) {
  auto it = entries.find(name);
  if (it == entries.end()) {
    std::vector<std::string> names;
    for (const auto& entry : entries) names.push_back(entry.first);
    if (names.empty()) report_.fail(pointer, "unknown {} \"{}\" (\"{}s\" defines none)", kind, name, kind);
    report_.fail(pointer, "unknown {} \"{}\"; defined: {}", kind, name, fmt::join(names, ", "));
  }
  return it->second;  // std::map: stays valid while other entries are read
}

void JsonSceneReader::read_textures(const Json& value, const std::string& pointer) {
  for (const std::string& name : collect_named(value, pointer, "texture", named_textures_))
    named_texture(name, named_textures_[name].pointer);
}

// The index of a named texture, read first (with what it refers to) if it has not been yet.
// `pointer` is where the name was given.
int JsonSceneReader::named_texture(const std::string& name, const std::string& pointer) {
  NamedEntry& texture = find_named(named_textures_, name, pointer, "texture");
  if (texture.index >= 0) return texture.index;
  if (texture.reading) {
    std::vector<std::string> cycle(std::find(texture_stack_.begin(), texture_stack_.end(), name),
                                   texture_stack_.end());
    cycle.push_back(name);
    report_.fail(pointer, "textures refer to each other in a cycle: {}", fmt::join(cycle, " -> "));
  }
  texture.reading = true;
  texture_stack_.push_back(name);
  TextureDesc desc = read_texture(*texture.value, texture.pointer);
  texture_stack_.pop_back();
  texture.reading = false;
  texture.index = add_texture(std::move(desc), place(texture.pointer));
  return texture.index;
}

int JsonSceneReader::add_texture(TextureDesc texture, SourceLocation where) {
  scene_.textures.push_back(std::move(texture));
  scene_.places.textures.push_back(std::move(where));
  return int(scene_.textures.size()) - 1;
}

TextureDesc JsonSceneReader::read_texture(const Json& value, const std::string& pointer) {
  // Textures are read recursively: hostile nesting (inline, or a long chain of names) must not
  // exhaust the stack.
  if (texture_depth_ >= kMaxTextureDepth)
    report_.fail(pointer, "textures nest too deeply: more than {} levels of textures using textures",
                 kMaxTextureDepth);
  struct DepthGuard {
    int& depth;
    explicit DepthGuard(int& d) : depth(++d) {}
    ~DepthGuard() { --depth; }
  } guard(texture_depth_);
  CheckedObject t(report_, value, pointer);
  TextureDesc texture = default_of_named_type<TextureDesc>(t, "texture");
  read_schema_fields(t, texture);
  t.finish();
  return texture;
}

// "uv_scale": [su, sv] (or one number for both) and "uv_offset": [du, dv].
UVMapping JsonSceneReader::read_uv_mapping(CheckedObject& t) const {
  UVMapping mapping;
  if (const Json* matrix = t.find("uv_matrix")) {
    // [[su, s_from_v, du], [t_from_u, sv, dv]]: any affine map (rotations, shears).
    const std::string pointer = t.pointer_of("uv_matrix");
    if (t.find("uv_scale") || t.find("uv_offset"))
      report_.fail(pointer, "give either uv_matrix or uv_scale / uv_offset, not both");
    if (!matrix->is_array() || matrix->size() != 2 || !(*matrix)[0].is_array() || (*matrix)[0].size() != 3 ||
        !(*matrix)[1].is_array() || (*matrix)[1].size() != 3)
      report_.fail(pointer, "expected [[su, s_from_v, du], [t_from_u, sv, dv]], got {}", describe(*matrix));
    float m[2][3];
    for (size_t r = 0; r < 2; ++r)
      for (size_t c = 0; c < 3; ++c)
        m[r][c] = read_float(report_, (*matrix)[r][c], fmt::format("{}/{}/{}", pointer, r, c));
    if (m[0][0] * m[1][1] - m[0][1] * m[1][0] == 0)
      report_.fail(pointer, "the uv matrix is singular (it maps the surface onto a line)");
    mapping = {m[0][0], m[1][1], m[0][2], m[1][2], m[0][1], m[1][0]};
    read_projection(t, mapping);
    return mapping;
  }
  if (const Json* scale = t.find("uv_scale")) {
    std::string pointer = t.pointer_of("uv_scale");
    Vec2 s = scale->is_number() ? Vec2(read_float(report_, *scale, pointer), read_float(report_, *scale, pointer))
                                : read_vec2(report_, *scale, pointer);
    if (s.x == 0 || s.y == 0) report_.fail(pointer, "uv_scale factors must be non-zero, got [{}, {}]", s.x, s.y);
    mapping.su = s.x;
    mapping.sv = s.y;
  }
  if (const Json* offset = t.find("uv_offset")) {
    Vec2 d = read_vec2(report_, *offset, t.pointer_of("uv_offset"));
    mapping.du = d.x;
    mapping.dv = d.y;
  }
  read_projection(t, mapping);
  return mapping;
}

// "projection" (TextureProjection) and, for the projections from the hit point, the space they
// work in ("projection_transform") and the planar one's axes.
void JsonSceneReader::read_projection(CheckedObject& t, UVMapping& mapping) const {
  if (const Json* projection = t.find("projection"))
    mapping.projection = read_enum<TextureProjection>(report_, *projection, t.pointer_of("projection"),
                                                      "texture projection");
  if (mapping.projection == TextureProjection::Surface) return;
  if (const Json* transform = t.find("projection_transform"))
    mapping.to_world = read_transform(*transform, t.pointer_of("projection_transform"));
  if (mapping.projection != TextureProjection::Planar) return;
  mapping.planar_s = t.vec3_or("planar_s", mapping.planar_s);
  mapping.planar_t = t.vec3_or("planar_t", mapping.planar_t);
}

// A file named relative to the scene file's directory (as mesh files are). It must exist when the
// scene is read, so that a typo is reported with its place in the scene file.
std::string JsonSceneReader::existing_file(CheckedObject& object, std::string_view key, std::string_view what) const {
  std::string name = object.string(key);
  std::string pointer = object.pointer_of(key);
  if (name.empty()) report_.fail(pointer, "the {} file name is empty", what);
  fs::path path = base_dir_ / name;
  std::error_code error;
  fs::file_status status = fs::status(path, error);
  if (status.type() == fs::file_type::not_found)
    report_.fail(pointer, "cannot read {} '{}': no such file", what, path.string());
  if (error) report_.fail(pointer, "cannot read {} '{}': {}", what, path.string(), error.message());
  if (status.type() == fs::file_type::directory)
    report_.fail(pointer, "cannot read {} '{}': it is a directory, not a file", what, path.string());
  return path.string();
}

// ---- material and texture parameters: a constant, a texture name, or an inline texture object

std::optional<int> JsonSceneReader::texture_reference(const Json& value, const std::string& pointer) {
  if (value.is_string()) return named_texture(value.get<std::string>(), pointer);
  if (value.is_object()) return add_texture(read_texture(value, pointer), place(pointer));
  return std::nullopt;
}

ColorInput JsonSceneReader::read_color_input(const Json& value, const std::string& pointer, ColorKind kind) {
  ColorInput input;
  if (std::optional<int> texture = texture_reference(value, pointer))
    input.texture = *texture;
  else if (value.is_number() || value.is_array())
    input.value = read_rgb(report_, value, pointer, kind);
  else
    report_.fail(pointer,
                 "expected a colour, [r, g, b] or a single number, or a texture (a name or an object), got {}",
                 describe(value));
  return input;
}

ColorInput JsonSceneReader::color_input_or(CheckedObject& object, std::string_view key, ColorKind kind, ColorInput fallback) {
  const Json* value = object.find(key);
  return value ? read_color_input(*value, object.pointer_of(key), kind) : fallback;
}

FloatInput JsonSceneReader::read_float_input(const Json& value, const std::string& pointer, const ValueRange& bound) {
  FloatInput input;
  if (std::optional<int> texture = texture_reference(value, pointer))
    input.texture = *texture;
  else if (value.is_number())
    input.value = check_bound(report_, read_float(report_, value, pointer), bound, pointer);
  else
    report_.fail(pointer, "expected a number or a texture (a name or an object), got {}", describe(value));
  return input;
}

FloatInput JsonSceneReader::float_input_or(CheckedObject& object, std::string_view key, const ValueRange& bound, FloatInput fallback) {
  const Json* value = object.find(key);
  return value ? read_float_input(*value, object.pointer_of(key), bound) : fallback;
}

}  // namespace candela::json
